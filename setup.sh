#!/usr/bin/env bash
# Installs the Debian 12 packages clfractal needs to build, test and benchmark (ccache: every
# build tree and the wheel share compiled objects; chromium:
# the headless render test of `clfractal report`; libjs-three: the report's 3D view; mkdocs:
# the documentation site; xvfb, Mesa and the X libraries of PyPI's Qt: the napari plugin's test
# in a real viewer).
# Does nothing when they are already there. Run as root (or with sudo available).
set -euo pipefail
packages=(build-essential cmake pkg-config git ccache
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers clinfo libclblast-dev
  doctest-dev libteem-dev zlib1g-dev libpng-dev libcli11-dev nlohmann-json3-dev gnuplot-nox
  chromium libjs-three
  python3 python3-numpy python3-venv python3-dev openmpi-bin libopenmpi-dev
  libgdcm-dev libnifti2-dev libtiff-dev
  clang-14 libfuzzer-14-dev libomp-14-dev python3-clang-14 oclgrind
  xvfb xauth libgl1-mesa-dri libglx-mesa0 libegl1 libfontconfig1 libdbus-1-3 libxkbcommon-x11-0
  libxcb-icccm4 libxcb-keysyms1 libxcb-xinerama0 libxcb-image0 libxcb-render-util0 libxcb-randr0
  libxcb-shape0 libxcb-xfixes0 libxcb-cursor0 mkdocs)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing ${missing[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
