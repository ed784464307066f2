#!/usr/bin/env bash
# Tests the wheel that python/build_wheel.sh wrote into WHEEL_DIR as a user without the
# system's OpenCL or imaging libraries would install it:
#   bash python/test_wheel.sh WHEEL_DIR
# In a private mount namespace (unshare -m; -rm without root) the system OpenCL ICD loader,
# its vendor files (/etc/OpenCL/vendors), PoCL, CLBlast, teem, GDCM, nifticlib, libtiff,
# libpng and the codecs they pull in are hidden behind empty mounts. There a fresh venv of
# /usr/bin/python3 installs the wheel with its `cpu` (PoCL from PyPI) and `test` extras, and
# 1. the extension resolves every library outside the manylinux policy inside the wheel;
# 2. with no OpenCL driver registered, the package chooses the PoCL of `clfractal[cpu]`
#    (python/wheel_check.py: its device, FD curves of real volumes against the reference);
#    a user's OCL_ICD_VENDORS is kept, and with no device the error names what to install;
# 3. with the system's PoCL registered again (a vendor driver through its ICD file; the
#    loader and the imaging libraries still hidden), python/tests pass (the checks against
#    the command-line tool skip: it needs the hidden libraries).
# Prints the wheel's size and the install and test times; exits non-zero on any failure.
set -euo pipefail
dir=${1:?usage: bash python/test_wheel.sh WHEEL_DIR}
root=$(cd "$(dirname "$0")/.." && pwd)
dir=$(cd "$dir" && pwd)
if [ -z "${CLFRACTAL_WHEEL_HIDDEN:-}" ]; then
  if [ "$(id -u)" -eq 0 ]; then ns=(-m); else ns=(-r -m); fi
  exec unshare "${ns[@]}" --propagation private env CLFRACTAL_WHEEL_HIDDEN=1 bash "$0" "$dir"
fi

# ---- hide the system's OpenCL and imaging libraries (this namespace only)
pocl_mounts=()
for d in /etc/OpenCL/vendors /usr/lib/x86_64-linux-gnu/pocl /usr/share/pocl; do
  if [ -d "$d" ]; then mount -t tmpfs none "$d"; pocl_mounts+=("$d"); fi
done
hidden=0
for pattern in libOpenCL libpocl libclblast libteem libgdcm libnifti libznz libtiff libpng16 libjpeg libwebp \
  libopenjp2 libcharls libLerc libjbig libdeflate libjson-c libgomp; do
  for f in /usr/lib/x86_64-linux-gnu/"$pattern"*.so* /usr/lib/"$pattern"*.so*; do
    if [ -f "$f" ] && [ ! -L "$f" ]; then
      mount --bind /dev/null "$f"
      hidden=$((hidden + 1))
      [ "$pattern" != libpocl ] || pocl_mounts+=("$f")
    fi
  done
done
echo "test_wheel: $hidden system libraries hidden"
if /usr/bin/python3 -c 'import ctypes; ctypes.CDLL("libOpenCL.so.1")' 2>/dev/null; then
  echo "test_wheel: the system OpenCL loader is still visible" >&2
  exit 1
fi

# ---- a fresh venv, the wheel with its cpu and test extras
wheel=("$dir"/clfractal-*-manylinux*.whl)
[ -f "${wheel[0]}" ] || { echo "test_wheel: no manylinux wheel in $dir" >&2; exit 1; }
venv=$(mktemp -d)/venv
trap 'rm -rf "$(dirname "$venv")"' EXIT
start=$(date +%s)
/usr/bin/python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "${wheel[0]}[cpu,test]"
installed=$(date +%s)

# ---- every library the extension loads is in the wheel or allowed by the manylinux policy
site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["platlib"])')
allowed='^(linux-vdso|ld-linux-x86-64|libc|libm|libdl|librt|libpthread|libstdc\+\+|libgcc_s|libz|libexpat)\.so'
bad=0
for ext in "$site"/clfractal/*.so*; do
  while read -r name _ path _; do
    case "$path" in "$site"/*) continue ;; esac
    [[ "$name" =~ $allowed ]] || { echo "test_wheel: $(basename "$ext") needs $name -> $path" >&2; bad=1; }
  done < <(ldd "$ext" | grep '=>')
done
[ "$bad" -eq 0 ] || exit 1

# ---- no OpenCL driver registered: the PoCL of clfractal[cpu]
cd "$(dirname "$venv")"
export CLFRACTAL_SHARED_DATA=${CLFRACTAL_SHARED_DATA:-$root/../shared/data}
PYTHONPATH=$root/python/tests "$venv/bin/python" -P "$root/python/wheel_check.py"

# ---- the user's OCL_ICD_VENDORS is kept; with no device, the error names what to install
OCL_ICD_VENDORS=$(dirname "$venv")/no-drivers "$venv/bin/python" -c 'import clfractal, numpy as np
assert clfractal.OPENCL_DRIVERS.startswith("OCL_ICD_VENDORS="), clfractal.OPENCL_DRIVERS
assert clfractal.devices() == []
try:
    clfractal.fd_curve(np.zeros((3, 3, 3), np.uint8))
    raise SystemExit("no error without a device")
except RuntimeError as e:
    assert "clfractal[cpu]" in str(e), e
    print("test_wheel: no device:", e)'

# ---- the system PoCL registered again, the loader and imaging libraries still hidden
for m in "${pocl_mounts[@]}"; do umount "$m"; done
"$venv/bin/python" -c 'import clfractal
assert clfractal.OPENCL_DRIVERS.startswith("system"), clfractal.OPENCL_DRIVERS
print("test_wheel: system driver:", clfractal.device_description())'
"$venv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests"
done_at=$(date +%s)
echo "test_wheel: $(basename "${wheel[0]}") ($(du -h "${wheel[0]}" | cut -f1)): install $((installed - start)) s," \
  "tests $((done_at - installed)) s"
