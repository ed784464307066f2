#!/usr/bin/env bash
# Gathers, on a Debian 12 machine with apt, the .deb files bench/gpu_check.sh unpacks on a
# machine without a package registry (a GPU machine with a CUDA image): what the build, the
# tests and the benchmarks need that such an image lacks — cmake, the OpenCL ICD loader and
# headers, CLBlast, teem, nifticlib, GDCM, libtiff, CLI11, nlohmann-json, doctest, zlib and
# libpng headers, pkg-config, gnuplot (the --plot checks) — and the shared libraries they
# depend on, minus Debian's base system (priority required or important, and the C/C++
# runtimes: the image has its own). The compiler (g++ with OpenMP) is the image's.
# Downloads with `apt-get download` (no root needed) and prints the count and total size.
# Usage: bench/gpu_debs.sh [OUT_DIR (gpu-debs)] [EXTRA_PACKAGE...]
set -euo pipefail
out=${1:-gpu-debs}
shift $(( $# > 0 ? 1 : 0 ))
packages=(cmake cmake-data pkg-config pkgconf pkgconf-bin
  ocl-icd-libopencl1 ocl-icd-opencl-dev opencl-c-headers opencl-clhpp-headers
  libclblast1 libclblast-dev libteem2 libteem-dev
  libnifti2-2 libnifti2-dev libniftiio2 libniftiio-dev libnifticdf2 libnifticdf-dev libznz3 libznz-dev
  libgdcm3.0 libgdcm-dev libtiff6 libtiffxx6 libtiff-dev
  libcli11-dev nlohmann-json3-dev doctest-dev zlib1g-dev libpng-dev libpng16-16 gnuplot-nox gnuplot-data "$@")
# Every package the list depends on, recursively (no recommends or suggests), by name.
mapfile -t closure < <(apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
    --no-replaces --no-enhances "${packages[@]}" | grep -v '^ ' | grep -v '^<' | sort -u)
# Keep the list itself, and of the dependencies the libraries (not -dev, -doc or tools) that
# are not part of the base system.
declare -A wanted=()
for p in "${packages[@]}"; do wanted[$p]=1; done
priority() { apt-cache show --no-all-versions "$1" 2>/dev/null | awk '/^Priority:/ {print $2; exit}'; }
keep=()
for p in "${closure[@]}"; do
  if [ -n "${wanted[$p]:-}" ]; then keep+=("$p"); continue; fi
  case $p in *-dev|*-doc|*-bin|*-common|*-data|dpkg|debconf*|perl*|*-perl|libperl*|python*|gcc*|cpp*|g++*|*:i386) continue ;; esac
  # The C and C++ runtimes and what every image's own tools link: never shadowed by a copy.
  case $p in libc6|libstdc++6|libgcc-s1|libcrypt1|libselinux1|libsystemd0|libelogind0|libcap2|libgcrypt20|\
    libgpg-error0|libpcre2-8-0|libmd0|libtinfo6|libncursesw6|libacl1|libdb5.3|libgdbm*|libzstd1|liblzma5|\
    libbz2-1.0|libuuid1|libudev1|libaudit1|libpam*) continue ;; esac
  case $(priority "$p") in required|important) continue ;; esac
  case $p in lib*) keep+=("$p") ;; esac
done
mkdir -p "$out"
cd "$out"
echo "gpu_debs: downloading ${#keep[@]} packages into $out" >&2
apt-get download "${keep[@]}" >/dev/null
ls -1 ./*.deb | wc -l | xargs echo "gpu_debs: .deb files:" >&2
du -sh . | awk '{print "gpu_debs: total " $1}' >&2
