#!/usr/bin/env python3
"""Lists the functions longer than a limit (default 70 lines) in the given source folders.

Function extents come from Universal Ctags (package universal-ctags): its JSON output gives
each function's first and last line. Lambdas count towards the function that holds them.
Usage: bench/function_lengths.py [--limit N] [DIR ...]   (default: host tools/clfractal)
Exit status 1 when a function is over the limit.
"""
import argparse
import json
import pathlib
import subprocess
import sys


def functions(folder):
    files = sorted(str(p) for p in pathlib.Path(folder).rglob("*") if p.suffix in (".cpp", ".hpp", ".h", ".cc"))
    if not files:
        return []
    out = subprocess.run(["ctags", "--languages=C++", "--kinds-C++=f", "--fields=+ne", "--output-format=json",
                          "-o", "-"] + files, check=True, capture_output=True, text=True).stdout
    found = []
    for line in out.splitlines():
        tag = json.loads(line)
        if tag.get("_type") != "tag" or "end" not in tag or tag["name"].startswith("__anon"):
            continue
        scope = tag.get("scope", "")
        name = (scope + "::" if scope else "") + tag["name"]
        found.append((tag["end"] - tag["line"] + 1, tag["path"], tag["line"], name))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=70)
    parser.add_argument("dirs", nargs="*", default=["host", "tools/clfractal"])
    args = parser.parse_args()
    over = sorted((f for d in args.dirs for f in functions(d) if f[0] > args.limit), reverse=True)
    for length, path, line, name in over:
        print(f"{length:5d}  {path}:{line}  {name}")
    print(f"{len(over)} function(s) over {args.limit} lines in {', '.join(args.dirs)}")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
