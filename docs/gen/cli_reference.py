#!/usr/bin/env python3
"""Writes the command-line reference (docs/reference/cli.md) from the tool's own help:
`clfractal --help` and `clfractal SUB --help` for every subcommand it lists, and
`clfractal-mpi --help` (and its subcommands') when given.

    docs/gen/cli_reference.py BUILD/clfractal [--mpi BUILD/clfractal-mpi] > docs/reference/cli.md
    docs/gen/cli_reference.py BUILD/clfractal [--mpi ...] --check docs/reference/cli.md
"""
import os
import re
import subprocess
import sys

import page

HEADER = """# Command-line reference

This page is generated from the tool's own help by `docs/gen/cli_reference.py` (the ctest
entry `docs_cli_reference` fails when it differs from `clfractal --help` and
`clfractal SUB --help`), so it describes exactly the options of this version. The
[user guide](../guide/isovalue.md) explains what the commands are for.

Options shared by the subcommands behave the same everywhere: `-q`/`--quiet` before or after
the subcommand; `--dims`, `--type`, `--endian` and `--spacing` for headerless raw files;
`--as`, `--series` and `--scaled` for any volume (see [file formats](../formats.md)). Exit
codes: 0 success, 2 bad input or arguments (one line `clfractal: error: ...`, no output
left behind), 1 a runtime failure.
"""


def help_text(binary, *args):
    """The help text, with the binary's path written as its name."""
    out = subprocess.run([binary, *args, "--help"], capture_output=True, text=True, check=True).stdout
    name = os.path.basename(binary)
    return out.replace(binary, name).rstrip() + "\n"


def subcommands(top_help):
    """The subcommand names under CLI11's SUBCOMMANDS: heading, in its order."""
    names, inside = [], False
    for line in top_help.splitlines():
        if line.strip().upper().startswith("SUBCOMMANDS"):
            inside = True
            continue
        if inside:
            m = re.match(r"\s+([a-z][a-z0-9_-]*)\b", line)
            if m:
                names.append(m.group(1))
            elif line.strip():
                inside = False
    return names


def section(title, text):
    return f"\n## {title}\n\n```text\n{text}```\n"


def main():
    ap = page.arguments(__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("--mpi", help="clfractal-mpi, documented too when given")
    a = ap.parse_args()
    top = help_text(a.binary)
    subs = subcommands(top)
    if not subs:
        raise SystemExit(f"cli_reference: no subcommands found in {a.binary} --help")
    text = HEADER + section("clfractal", top)
    for sub in subs:
        text += section(f"clfractal {sub}", help_text(a.binary, sub))
    if a.mpi:
        mpi_top = help_text(a.mpi)
        text += section("clfractal-mpi", mpi_top)
        for sub in subcommands(mpi_top):
            text += section(f"clfractal-mpi {sub}", help_text(a.mpi, sub))
    return page.emit(text, a.check, "docs/gen/cli_reference.py BUILD/clfractal --mpi BUILD/clfractal-mpi"
                     " > docs/reference/cli.md")


if __name__ == "__main__":
    sys.exit(main())
