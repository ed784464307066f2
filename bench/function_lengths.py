#!/usr/bin/env python3
"""Lengths of the C++ function bodies in the given directories, longest first.

    bench/function_lengths.py [--max N] [--top K] DIR...

Parses every .cpp/.hpp/.h file with libclang (Debian: python3-clang-14) and lists each
function, method, constructor or function template defined in it, with its length in lines
from the signature to the closing brace (lambdas count towards the function around them).
Prints the K longest (default 15); with --max N, exits 1 when one is longer than N lines.
"""
import argparse
import glob
import os
import sys

try:
    import clang.cindex as ci
except ImportError:  # a python3 other than Debian's: its packages' folder
    sys.path.append("/usr/lib/python3/dist-packages")
    import clang.cindex as ci

KINDS = {
    ci.CursorKind.FUNCTION_DECL,
    ci.CursorKind.CXX_METHOD,
    ci.CursorKind.CONSTRUCTOR,
    ci.CursorKind.DESTRUCTOR,
    ci.CursorKind.FUNCTION_TEMPLATE,
    ci.CursorKind.CONVERSION_FUNCTION,
}


def load_libclang():
    for path in sorted(glob.glob("/usr/lib/llvm-*/lib/libclang.so*")) + sorted(
            glob.glob("/usr/lib/x86_64-linux-gnu/libclang-*.so*")):
        try:
            ci.Config.set_library_file(path)
            ci.Index.create()
            return
        except Exception:  # try the next one
            ci.Config.loaded = False
    ci.Index.create()  # let the bindings find it, or raise


def functions(index, path, args):
    tu = index.parse(path, args=args)
    real = os.path.realpath(path)
    out = []

    def walk(cursor):
        for c in cursor.get_children():
            loc = c.location.file
            if loc is None or os.path.realpath(loc.name) != real:
                continue
            if c.kind in KINDS and c.is_definition():
                first, last = c.extent.start.line, c.extent.end.line
                name = c.semantic_parent.spelling + "::" + c.spelling if c.kind != ci.CursorKind.FUNCTION_DECL \
                    else c.spelling
                out.append((last - first + 1, path, first, name))
                continue  # nested lambdas and local classes count towards this one
            walk(c)

    walk(tu.cursor)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--max", type=int, default=0, help="exit 1 when a function is longer than this")
    ap.add_argument("--top", type=int, default=15, help="how many of the longest to list")
    ap.add_argument("-I", dest="includes", action="append", default=[], help="include directory")
    a = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    includes = a.includes + [os.path.join(root, d) for d in ("include", "host", "tools/clfractal", "bench", "test")]
    args = ["-x", "c++", "-std=c++17"] + ["-I" + d for d in includes]
    load_libclang()
    index = ci.Index.create()
    found = []
    for d in a.dirs:
        for dirpath, _, names in os.walk(d):
            for n in sorted(names):
                if n.endswith((".cpp", ".hpp", ".h")):
                    found += functions(index, os.path.join(dirpath, n), args)
    found.sort(key=lambda f: (-f[0], f[1], f[2]))
    for length, path, line, name in found[:a.top]:
        print(f"{length:5d}  {path}:{line}  {name}")
    print(f"{len(found)} functions in {', '.join(a.dirs)}; longest {found[0][0] if found else 0} lines")
    if a.max and found and found[0][0] > a.max:
        print(f"over {a.max} lines: {sum(1 for f in found if f[0] > a.max)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
