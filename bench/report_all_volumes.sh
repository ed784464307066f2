#!/usr/bin/env bash
# `clfractal report` on every volume of a MANIFEST.tsv (../shared/data), each page opened in
# headless Chromium (test/cli/report_browser.py --load-only: at most 8 MB, it loads, the 3D view
# renders, the isovalue switch works, no console error, no request leaving the page) and its
# structure checked by test/cli/report_check.py. Prints one row per volume: the page's size, the
# report's time and the result; exits 1 when one fails, 77 when chromium, the websocket client
# or the data is not there.
# usage: report_all_volumes.sh CLFRACTAL REPORT_CHECK PYTHON WORKDIR DATA [MAX_BYTES]
#   PYTHON: the build's venv (websocket-client, numpy, Pillow); MAX_BYTES: only the volumes whose
#   file is at most this large (the ctest entry takes the smallest few).
set -u
if [ $# -lt 5 ]; then
  echo "usage: report_all_volumes.sh CLFRACTAL REPORT_CHECK PYTHON WORKDIR DATA [MAX_BYTES]" >&2; exit 2
fi
cli=$1 check=$2 py=$3 work=$4 data=$5 max=${6:-}
here=$(cd "$(dirname "$0")" && pwd)
driver="$here/../test/cli/report_browser.py" structure="$here/../test/cli/report_check.py"
[ -f "$data/MANIFEST.tsv" ] || { echo "skip: $data/MANIFEST.tsv not found"; exit 77; }
browser=$(command -v chromium || command -v chromium-browser || true)
[ -n "$browser" ] || { echo "skip: chromium is not installed (setup.sh installs it)"; exit 77; }
"$py" -c "import websocket, numpy, PIL" 2>/dev/null || { echo "skip: $py lacks websocket-client, numpy or Pillow"; exit 77; }
rm -rf "$work" && mkdir -p "$work" || exit 2

failed=0 pages=() rows=()
while IFS=$'\t' read -r file name dims _; do
  [ "$file" = file ] && continue
  path="$data/$file"
  [ -f "$path" ] || { echo "note: $path not found"; continue; }
  bytes=$(stat -c %s "$path")
  if [ -n "$max" ] && [ "$bytes" -gt "$max" ]; then continue; fi
  t0=$(date +%s.%N)
  out=$("$cli" -q report "$path" -o "$work/$name.html" --json "$work/$name.json" 2>&1)
  rc=$? t=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.1f", b - a}')
  if [ $rc -ne 0 ]; then
    echo "FAIL: report $file exited $rc: $out"; failed=1; rows+=("$name $dims - $t report-exit-$rc"); continue
  fi
  if ! "$py" "$structure" "$work/$name.html" "$work/$name.json" >"$work/$name.structure" 2>&1; then
    echo "FAIL: report_check.py $name: $(tail -3 "$work/$name.structure")"; failed=1
  fi
  pages+=("$work/$name.html") rows+=("$name $dims $(stat -c %s "$work/$name.html") $t")
done <"$data/MANIFEST.tsv"
[ ${#pages[@]} -gt 0 ] || { echo "FAIL: no volume reported"; exit 1; }

timeout $((60 + 20 * ${#pages[@]})) "$py" "$driver" --load-only "$browser" "$check" "$work/devtools" "${pages[@]}" \
  >"$work/browser.log" 2>&1
brc=$?
cat "$work/browser.log"
[ $brc -eq 0 ] || failed=1
printf '%-22s %-12s %10s %9s  %s\n' volume dims "page MiB" "report s" browser
for r in "${rows[@]}"; do
  read -r name dims size t result <<<"$r"
  if [ -n "${result:-}" ]; then verdict=$result
  elif grep -q "^FAIL: $name: " "$work/browser.log"; then verdict=FAIL
  elif [ $brc -ne 0 ] && ! grep -q "/$name.html: checked" "$work/browser.log"; then verdict="not checked"
  else verdict=ok; fi
  mb=$( [ "$size" = - ] && echo - || awk -v s="$size" 'BEGIN{printf "%.2f", s / 1048576}')
  printf '%-22s %-12s %10s %9s  %s\n' "$name" "$dims" "$mb" "$t" "$verdict"
done
exit $failed
