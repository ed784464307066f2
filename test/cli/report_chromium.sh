#!/usr/bin/env bash
# The report in a real browser: headless Chromium (SwiftShader WebGL, file://, no network)
# screenshots the page of report_test.sh and report_check decodes it (libpng) to check it is
# not blank; then report_browser.py drives Chromium over the DevTools protocol through the
# interactive view of the sphere's and the MRI's pages (the canvas's LD colours, the
# isovalue switch, the linked second view, the curves' hover, no console error, no request
# leaving the page); the MRI's page, a held-out head, is held to the acceptance as written
# (red and blue on the first canvas).
# Exits 77 (skipped) only when chromium, or the websocket client of the build's Python venv,
# is not installed.
# usage: report_chromium.sh REPORT_CHECK PYTHON REPORT_BROWSER_PY WORKDIR PAGE.html [[--held-out] PAGE.html ...]
set -u
check=$1 py=$2 driver=$3 work=$4
shift 4
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then echo "skip: chromium is not installed (setup.sh installs it)"; exit 77; fi
if ! "$py" -c "import websocket" 2>/dev/null; then
  echo "skip: $py has no websocket client (cmake/python_venv.cmake installs websocket-client)"; exit 77
fi
pages=() args=() flag=()
for p in "$@"; do
  if [ "$p" = --held-out ]; then flag=(--held-out); continue; fi
  if [ -f "$p" ]; then pages+=("$p") args+=("${flag[@]}" "$p")
  else echo "note: $p not found (the report test makes it when its volume is there)"; fi
  flag=()
done
if [ ${#pages[@]} -eq 0 ]; then echo "FAIL: no page found (the report test makes them)"; exit 1; fi
rm -rf "$work" && mkdir -p "$work/home"
shot="$work/report.png"
# Its own HOME and profile in the build tree; a timeout so that a stuck browser fails.
HOME="$work/home" timeout 60 "$browser" --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
  --hide-scrollbars --user-data-dir="$work/profile" --screenshot="$shot" --window-size=1200,2400 \
  "file://$(realpath "${pages[0]}")" >"$work/chromium.log" 2>&1
rc=$?
if [ $rc -ne 0 ] || [ ! -s "$shot" ]; then
  echo "FAIL: chromium exited $rc without a screenshot:"; tail -5 "$work/chromium.log"; exit 1
fi
"$check" screenshot "$shot" || exit 1
timeout 90 "$py" "$driver" "$browser" "$check" "$work/devtools" "${args[@]}"
