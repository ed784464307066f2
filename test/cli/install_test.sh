#!/usr/bin/env bash
# The installed package: `cmake --install` into a fresh prefix, then the examples built
# outside the tree against it, once with find_package(clfractal) and once with pkg-config,
# and run.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR WORKDIR [CLFRACTAL_FIXTURES]
set -eu
build=$1
src=$2
work=$3
fixtures=${4:-}
rm -rf "$work" && mkdir -p "$work"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
for f in include/clfractal/clfractal.h include/clfractal/span.hpp bin/clfractal; do
  [ -e "$prefix/$f" ] || { echo "FAIL: $f not installed"; exit 1; }
done
libdir=$(dirname "$(find "$prefix" -name 'libclfractal.so' | head -1)")
[ -n "$libdir" ] || { echo "FAIL: libclfractal.so not installed"; exit 1; }
[ -f "$libdir/cmake/clfractal/clfractalConfig.cmake" ] || { echo "FAIL: no CMake package config"; exit 1; }
[ -f "$libdir/pkgconfig/clfractal.pc" ] || { echo "FAIL: no pkg-config file"; exit 1; }
# Nothing of the build or source tree may leak into the installed package.
if grep -rqs -- "$src\|$build" "$libdir/cmake" "$libdir/pkgconfig"; then
  echo "FAIL: the installed package refers to the build or source tree"; exit 1
fi

# 1. find_package(clfractal): the examples directory as a project of its own.
cmake -S "$src/examples" -B "$work/examples-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/examples-build" -j2 >/dev/null
for e in c_api library_call; do
  "$work/examples-build/$e" | grep -q "mean" || { echo "FAIL: example $e (find_package)"; exit 1; }
done
# The core library needs OpenCL and no imaging library; the scanner pipeline links it alone.
core_deps=$(ldd "$libdir/libclfractal_core.so")
echo "$core_deps" | grep -q 'libOpenCL' || { echo "FAIL: libclfractal_core does not link OpenCL"; exit 1; }
if echo "$core_deps" | grep -Eq 'gdcm|teem|nifti|znz|tiff|png'; then
  echo "FAIL: libclfractal_core links an imaging library:"; echo "$core_deps"; exit 1
fi
needed=$(readelf -d "$work/examples-build/scanner_pipeline" | sed -n 's/.*(NEEDED).*\[\(libclfractal[^]]*\)\].*/\1/p' | tr '\n' ' ')
[ "$needed" = "libclfractal_core.so.0 " ] || { echo "FAIL: scanner_pipeline needs '$needed', not libclfractal_core alone"; exit 1; }
"$work/examples-build/scanner_pipeline" 32 | grep -q "noisy isovalues" || { echo "FAIL: example scanner_pipeline (find_package)"; exit 1; }

# The DICOM module beside the libraries: the one installed file that links GDCM, and the
# installed tool reads a DICOM series through it.
[ -f "$libdir/libclfractal_dicom.so" ] || { echo "FAIL: libclfractal_dicom.so not installed in $libdir"; exit 1; }
ldd "$libdir/libclfractal_dicom.so" | grep -q 'libgdcmMSFF' || { echo "FAIL: the DICOM module does not link GDCM"; exit 1; }
for f in "$prefix/bin/clfractal" "$libdir"/libclfractal*.so.0; do
  if LD_LIBRARY_PATH=$libdir ldd "$f" | grep -q gdcm; then echo "FAIL: $f links GDCM"; exit 1; fi
done
if [ -n "$fixtures" ]; then
  LD_LIBRARY_PATH=$libdir "$prefix/bin/clfractal" -q gen noisy-sphere --size 9 --noise 4 --type uint16 -o "$work/u16.nrrd"
  "$fixtures" dicom "$work/u16.nrrd" "$work/dcm" 1.2.826.0.1.9 0
  LD_LIBRARY_PATH=$libdir "$prefix/bin/clfractal" info "$work/dcm" | grep -q 'DICOM series' \
    || { echo "FAIL: the installed clfractal does not read DICOM"; exit 1; }
fi

# 2. pkg-config: a C compiler and nothing else; the scanner pipeline with clfractal-core.
export PKG_CONFIG_PATH=$libdir/pkgconfig
cc -o "$work/c_api_pc" "$src/examples/c_api.c" $(pkg-config --cflags --libs clfractal) -lm
LD_LIBRARY_PATH=$libdir "$work/c_api_pc" | grep -q "mean" || { echo "FAIL: example_c_api (pkg-config)"; exit 1; }
c++ -std=c++17 -o "$work/scanner_pc" "$src/examples/scanner_pipeline.cpp" $(pkg-config --cflags --libs clfractal-core)
LD_LIBRARY_PATH=$libdir "$work/scanner_pc" 32 | grep -q "noisy isovalues" || { echo "FAIL: example scanner_pipeline (pkg-config)"; exit 1; }
echo "install test: passed ($prefix)"
