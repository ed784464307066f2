#!/usr/bin/env python3
"""Checks the code of a markdown page: a fenced block right after a line
`<!-- excerpt: PATH -->` must consist of lines of PATH (compared without leading and
trailing blanks), in PATH's order (the examples are built and run by ctest, so an excerpt
that passes is code that works); a block after `<!-- run: python -->` is run with --python
(in a fresh folder) and must exit 0.

    docs/gen/check_snippets.py [--python PY] ROOT README.md [PAGE.md ...]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

MARK = re.compile(r"<!-- (excerpt|run): (\S+) -->")


def excerpts(text):
    """(path, lines of the fenced block) for every marked block."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = MARK.fullmatch(line.strip())
        if not m:
            continue
        if i + 1 >= len(lines) or not lines[i + 1].startswith("```"):
            yield m.group(1), m.group(2), None
            continue
        j = i + 2
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        yield m.group(1), m.group(2), lines[i + 2:j]


def in_order(block, source):
    """The first block line not found in `source` after the previous one, or None."""
    src = [l.strip() for l in source.splitlines()]
    k = 0
    for line in block:
        want = line.strip()
        if not want:
            continue
        while k < len(src) and src[k] != want:
            k += 1
        if k == len(src):
            return line
        k += 1
    return None


def run(block, python):
    """Runs the block with `python` in a fresh folder: None when it exits 0, else why not."""
    with tempfile.TemporaryDirectory() as tmp:
        exe = os.path.abspath(python) if os.sep in python else python
        r = subprocess.run([exe, "-c", "\n".join(block)], cwd=tmp, capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        return f"exit {r.returncode}: {r.stderr.strip()[-1500:]}"
    print("   " + "\n   ".join(r.stdout.strip().splitlines()))
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--python", help="runs the `run: python` blocks (else they are listed as not run)")
    ap.add_argument("root")
    ap.add_argument("pages", nargs="+")
    a = ap.parse_args()
    failures = checked = 0
    for page in a.pages:
        for kind, path, block in excerpts(open(os.path.join(a.root, page)).read()):
            checked += 1
            if block is None:
                print(f"{page}: the {kind} block of {path} is not followed by a fenced block")
                failures += 1
                continue
            if kind == "run":
                if not a.python:
                    print(f"{page}: a {path} block, not run (no --python)")
                    continue
                problem = run(block, a.python)
                print(f"{page}: {path} block of {len(block)} lines: " + (problem or "ran"))
                failures += problem is not None
                continue
            missing = in_order(block, open(os.path.join(a.root, path)).read())
            if missing is not None:
                print(f"{page}: excerpt of {path}: {missing.strip()!r} is not in {path} (in this order)")
                failures += 1
            else:
                print(f"{page}: excerpt of {path}: {len(block)} lines found")
    if checked == 0:
        print("check_snippets: no excerpts found")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
