"""Shared by the page generators in docs/gen: write a generated page, or check that the
committed one equals it (the drift tests in test/docs/CMakeLists.txt)."""
import argparse
import difflib
import sys


def arguments(description):
    """The generators' common options: --check FILE compares instead of printing."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--check", metavar="PAGE", help="exit 1 (with a diff) when PAGE differs from the generated text")
    return ap


def emit(text, check, regenerate):
    """Prints `text`, or with `check` compares it with that file: 0 when equal, else a
    unified diff, the command that regenerates the page, and 1."""
    if not check:
        sys.stdout.write(text)
        return 0
    with open(check, encoding="utf-8") as f:
        committed = f.read()
    if committed == text:
        print(f"{check}: up to date")
        return 0
    sys.stdout.writelines(difflib.unified_diff(committed.splitlines(True), text.splitlines(True),
                                               check, "generated", n=2))
    print(f"\n{check} differs from what it documents; regenerate it: {regenerate}")
    return 1
