#!/usr/bin/env bash
# The report renders in a real browser: headless Chromium screenshots the page of
# report_test.sh (file://, no network) and report_check decodes it (libpng) to check it is
# not blank. Exits 77 (skipped) only when chromium is not installed.
# usage: report_chromium.sh REPORT_CHECK PAGE.html WORKDIR
set -u
check=$1 page=$2 work=$3
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then echo "skip: chromium is not installed (setup.sh installs it)"; exit 77; fi
if [ ! -f "$page" ]; then echo "FAIL: $page not found (the report test makes it)"; exit 1; fi
rm -rf "$work" && mkdir -p "$work/home"
shot="$work/report.png"
# Its own HOME and profile in the build tree; a timeout so that a stuck browser fails.
HOME="$work/home" timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
  --user-data-dir="$work/profile" --screenshot="$shot" --window-size=1200,2400 "file://$(realpath "$page")" \
  >"$work/chromium.log" 2>&1
rc=$?
if [ $rc -ne 0 ] || [ ! -s "$shot" ]; then
  echo "FAIL: chromium exited $rc without a screenshot:"; tail -5 "$work/chromium.log"; exit 1
fi
"$check" screenshot "$shot"
