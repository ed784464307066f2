#!/usr/bin/env bash
# Runs the napari plugin's tests (test_napari.py) in a real viewer under Xvfb and Mesa
# (QT_QPA_PLATFORM=offscreen does not render the canvas):
#   bash python/tests/run_napari.sh PYTHON [pytest arguments]
# PYTHON: an interpreter with napari, a Qt binding, pytest-qt, npe2 and matplotlib (.ci/run
# makes build/napari-venv). Exits 77 (ctest: skipped) when PYTHON lacks them.
set -euo pipefail
python=${1:?usage: run_napari.sh PYTHON [pytest arguments]}
shift
if ! [ -x "$python" ] || ! "$python" -c "import napari, npe2, pytestqt, matplotlib" 2>/dev/null; then
  echo "napari: $python has no napari, npe2, pytest-qt and matplotlib: skipped (.ci/run installs them)"
  exit 77
fi
if ! command -v xvfb-run >/dev/null; then
  echo "napari: xvfb-run not found (setup.sh installs the Debian package xvfb)" >&2
  exit 1
fi
unset QT_QPA_PLATFORM
exec xvfb-run -a -s "-screen 0 1280x1024x24" "$python" -m pytest -q -p no:cacheprovider "$@"
