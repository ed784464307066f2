#!/usr/bin/env python3
"""One version number: CMake's project(clfractal VERSION ...), the command-line tools'
--version, the C ABI's clf_version(), the Python package's __version__, the version
pyproject.toml gives the wheel and the newest entry of CHANGELOG.md must all agree.

    version_check.py --source DIR --version X.Y.Z --cli BIN --capi LIB [--mpi BIN] [--python-path DIR]
"""
import argparse
import ctypes
import os
import re
import subprocess
import sys
import tomllib


def tool_version(binary, name):
    out = subprocess.run([binary, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    prefix = name + " "
    if not out.startswith(prefix):
        raise SystemExit(f"version_check: {binary} --version printed {out!r}, not '{prefix}X.Y.Z'")
    return out[len(prefix):]


def pyproject_version(source):
    with open(os.path.join(source, "pyproject.toml"), "rb") as f:
        project = tomllib.load(f)
    if "version" in project["project"]:
        return project["project"]["version"]
    rule = project["tool"]["scikit-build"]["metadata"]["version"]
    with open(os.path.join(source, rule["input"])) as f:
        m = re.search(rule["regex"], f.read())
    if not m:
        raise SystemExit(f"version_check: pyproject.toml's version regex matches nothing in {rule['input']}")
    return m.group("value")


def changelog_version(source):
    with open(os.path.join(source, "CHANGELOG.md")) as f:
        for line in f:
            m = re.match(r"## \[?(\d+\.\d+\.\d+)\]?", line)
            if m:
                return m.group(1)
    raise SystemExit("version_check: CHANGELOG.md has no '## X.Y.Z' entry")


def python_version(path):
    code = "import clfractal, sys; sys.stdout.write(clfractal.__version__)"
    env = dict(os.environ, PYTHONPATH=path)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          check=True).stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source", required=True)
    ap.add_argument("--version", required=True, help="CMake's PROJECT_VERSION")
    ap.add_argument("--cli", required=True)
    ap.add_argument("--capi", required=True, help="libclfractal.so")
    ap.add_argument("--mpi")
    ap.add_argument("--python-path")
    a = ap.parse_args()
    lib = ctypes.CDLL(a.capi)
    lib.clf_version.restype = ctypes.c_char_p
    found = {
        "clfractal --version": tool_version(a.cli, "clfractal"),
        "clf_version()": lib.clf_version().decode(),
        "pyproject.toml": pyproject_version(a.source),
        "CHANGELOG.md": changelog_version(a.source),
    }
    if a.mpi:
        found["clfractal-mpi --version"] = tool_version(a.mpi, "clfractal-mpi")
    if a.python_path:
        found["clfractal.__version__"] = python_version(a.python_path)
    for where, v in found.items():
        print(f"{where:26s} {v}")
    wrong = {k: v for k, v in found.items() if v != a.version}
    if wrong:
        print(f"version_check: CMake's project version is {a.version}; these differ: {wrong}")
        return 1
    print(f"version_check: all {len(found)} agree with CMake's {a.version}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
