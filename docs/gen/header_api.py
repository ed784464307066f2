#!/usr/bin/env python3
"""Writes the C API reference (docs/reference/c.md) from include/clfractal/clfractal.h, or
the C++ API reference (docs/reference/cpp.md) from the public headers in include/clfractal/:
each header's opening comment, then every declaration it makes (types, enums, functions,
constants) with the comment written before or beside it, parsed by libclang (Debian:
python3-clang-14).

    docs/gen/header_api.py c include [--build-include build/include] > docs/reference/c.md
    docs/gen/header_api.py cpp include --build-include build/include > docs/reference/cpp.md
    ... --check docs/reference/cpp.md
"""
import glob
import os
import re
import sys

import page

# libclang's loader is the one of bench/function_lengths.py.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench"))
try:
    import clang.cindex as ci
except ImportError:  # a python3 other than Debian's: its packages' folder
    sys.path.append("/usr/lib/python3/dist-packages")
    try:
        import clang.cindex as ci
    except ImportError:
        print("header_api: libclang's Python bindings are not installed (apt-get install python3-clang-14)")
        sys.exit(77)
from function_lengths import load_libclang  # noqa: E402

HEADERS = {
    "c": """# C API

This page is generated from `include/clfractal/clfractal.h` by `docs/gen/header_api.py` (the
ctest entry `docs_c_api` fails when it differs from the header). Link with
`$(pkg-config --cflags --libs clfractal)` or CMake's `clfractal::clfractal`; see
[From C++ and C](../guide/library.md) for a worked example.
""",
    "cpp": """# C++ API

This page is generated from the public headers in `include/clfractal/` by
`docs/gen/header_api.py` (the ctest entry `docs_cpp_api` fails when it differs from them):
each header's purpose, then its declarations in namespace `clfractal` with their comments.
Every definition they cite is stated in [Definitions](../definitions.md); see
[From C++ and C](../guide/library.md) for how to build against the installed package.
""",
}

DECLS = {
    ci.CursorKind.FUNCTION_DECL, ci.CursorKind.FUNCTION_TEMPLATE, ci.CursorKind.STRUCT_DECL,
    ci.CursorKind.CLASS_DECL, ci.CursorKind.CLASS_TEMPLATE, ci.CursorKind.ENUM_DECL,
    ci.CursorKind.TYPEDEF_DECL, ci.CursorKind.TYPE_ALIAS_DECL, ci.CursorKind.VAR_DECL,
    ci.CursorKind.UNION_DECL,
}
NESTING = {ci.CursorKind.NAMESPACE, ci.CursorKind.UNEXPOSED_DECL, ci.CursorKind.LINKAGE_SPEC}


def opening_comment(source):
    """The comment block the header starts with, as prose."""
    lines = []
    for line in source.splitlines():
        s = line.strip()
        if s.startswith("//"):
            lines.append(s[2:].lstrip("/")[1:] if s[2:].lstrip("/").startswith(" ") else s[2:].lstrip("/"))
        elif s.startswith("/*") or (lines and not s.startswith("#") and s.startswith("*")):
            lines.append(re.sub(r"^/?\*+/?\s?", "", s).rstrip("*/").rstrip())
        else:
            break
    return "\n".join(lines).strip()


def prose(text):
    """Comment text as markdown that shows it as written: outside `code` spans, the
    characters markdown would take as markup (<, *, _, #, backslash) are escaped."""
    out = []
    for line in text.splitlines():
        parts = line.split("`")
        for k in range(0, len(parts), 2):  # even parts are outside code spans
            p = parts[k].replace("\\", "\\\\").replace("<", "&lt;").replace("*", "\\*").replace("_", "\\_")
            parts[k] = p
        line = "`".join(parts) if len(parts) % 2 == 1 else line.replace("<", "&lt;")
        out.append("\\" + line if line.lstrip().startswith("#") else line)
    return "\n".join(out)


def comment_text(raw):
    """A raw comment (//, ///, ///<, /* */) as plain text lines."""
    out = []
    for line in raw.splitlines():
        s = line.strip()
        s = re.sub(r"^(///<|//!<|///|//!|//|/\*\*<|/\*!<|/\*\*|/\*!|/\*)\s?", "", s)
        s = re.sub(r"\s*\*/$", "", s)
        s = re.sub(r"^\*\s?", "", s)
        out.append(s)
    return "\n".join(out).strip()


def declaration_text(cursor, source_bytes):
    """The declaration as written, without the body of an inline function."""
    start, end = cursor.extent.start.offset, cursor.extent.end.offset
    if cursor.kind in (ci.CursorKind.FUNCTION_DECL, ci.CursorKind.FUNCTION_TEMPLATE):
        for child in cursor.get_children():
            if child.kind == ci.CursorKind.COMPOUND_STMT:
                end = child.extent.start.offset
                break
    text = source_bytes[start:end].decode().rstrip()
    # Indentation relative to the declaration's first line.
    col = cursor.extent.start.column - 1
    lines = text.splitlines()
    lines = [lines[0]] + [l[col:] if l[:col].strip() == "" else l for l in lines[1:]]
    return "\n".join(lines).rstrip().rstrip("{").rstrip() + ";"


def walk(cursor, path):
    for c in cursor.get_children():
        if c.location.file is None or os.path.realpath(c.location.file.name) != path:
            continue
        if c.kind in NESTING:
            yield from walk(c, path)
        elif c.kind in DECLS and c.spelling and (c.is_definition() or c.kind not in (
                ci.CursorKind.STRUCT_DECL, ci.CursorKind.CLASS_DECL)):
            yield c


def parse(files, args, index):
    """One translation unit including every header (one parse for all of them)."""
    unit = "all_headers.c" if "c" in args[1:2] else "all_headers.cpp"
    code = "".join(f'#include "{os.path.abspath(f)}"\n' for f in files)
    tu = index.parse(unit, args=args, unsaved_files=[(unit, code)])
    errors = [d for d in tu.diagnostics if d.severity >= ci.Diagnostic.Error]
    if errors:
        raise SystemExit(f"header_api: {errors[0]}")
    return tu


def header_page(tu, path, name):
    source = open(path, "rb").read()
    real = os.path.realpath(path)
    text = f"\n## `{name}`\n\n"
    intro = opening_comment(source.decode())
    if intro:
        text += prose(intro) + "\n"
    found = list(walk(tu.cursor, real))
    spans = [(c.extent.start.offset, c.extent.end.offset) for c in found]
    for c, (b, e) in zip(found, spans):
        # A declaration inside another (the enum of `typedef enum {...} name;`) is shown by it.
        if any(b2 <= b and e <= e2 and (b2, e2) != (b, e) for b2, e2 in spans):
            continue
        decl = declaration_text(c, source)
        comment = comment_text(c.raw_comment) if c.raw_comment else ""
        text += f"\n### `{c.spelling}`\n\n```{'c' if name.endswith('.h') else 'cpp'}\n{decl}\n```\n"
        if comment and comment not in intro:
            text += "\n" + prose(comment) + "\n"
    return text


def main():
    ap = page.arguments(__doc__.splitlines()[0])
    ap.add_argument("language", choices=["c", "cpp"])
    ap.add_argument("include", help="the include folder (holding clfractal/)")
    ap.add_argument("--build-include", help="the build tree's include folder (the generated version.hpp)")
    a = ap.parse_args()
    load_libclang()
    index = ci.Index.create()
    includes = ["-I" + a.include] + (["-I" + a.build_include] if a.build_include else [])
    if a.language == "c":
        files = [os.path.join(a.include, "clfractal", "clfractal.h")]
        args = ["-x", "c", "-std=c11", "-fparse-all-comments"] + includes
    else:
        files = sorted(glob.glob(os.path.join(a.include, "clfractal", "*.hpp")))
        if a.build_include:
            files.append(os.path.join(a.build_include, "clfractal", "version.hpp"))
        args = ["-x", "c++", "-std=c++17", "-fparse-all-comments"] + includes
    text = HEADERS[a.language]
    tu = parse(files, args, index)
    for f in files:
        text += header_page(tu, f, "clfractal/" + os.path.basename(f))
    regenerate = f"docs/gen/header_api.py {a.language} include --build-include build/include > docs/reference/{a.language}.md"
    return page.emit(text, a.check, regenerate)


if __name__ == "__main__":
    sys.exit(main())
