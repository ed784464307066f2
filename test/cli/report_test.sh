#!/usr/bin/env bash
# clfractal report end to end: the page and its JSON on a synthetic volume (and on a real
# MRI in NIfTI when ../shared/data is there), checked by report_check.py (structure, inline
# PNGs, no network, numbers equal to the JSON) and report_check (every recommended isovalue
# clean by the plain reference curve); bad input fails with one line and leaves nothing.
# usage: report_test.sh CLFRACTAL REPORT_CHECK PYTHON3 REPORT_CHECK_PY WORKDIR SHARED_DATA
set -u
cli=$1 check=$2 py=$3 check_py=$4 work=$5 data=$6
here=$(dirname "$0")
source "$here/cli_lib.sh"
rm -rf "$work" && mkdir -p "$work"

report() {  # report NAME VOLUME: report, then both checks
  local name=$1 volume=$2
  local out rc
  out=$("$cli" -q report "$volume" -o "$work/$name.html" --json "$work/$name.json" 2>&1)
  rc=$?
  if [ $rc -ne 0 ]; then fail "report $volume exited $rc: $out"; return; fi
  grep -q "wrote .*$name.html" <<<"$out" && pass || fail "report $volume: no 'wrote' line: $out"
  "$py" "$check_py" "$work/$name.html" "$work/$name.json" && pass || fail "report_check.py $name"
  "$check" curve "$volume" "$work/$name.json" && pass || fail "report_check curve $name"
}

# A noisy sphere: clean where the noise is small, rough where it grows (both views).
report sphere synthetic:noisy-sphere:72
"$py" - "$work/sphere.json" <<'PY' && pass || fail "sphere: expected a clean band and a noisiest view"
import json, sys
j = json.load(open(sys.argv[1]))
assert len(j["recommended"]) >= 1 and j["noisiest"] is not None and len(j["views"]) == 2, j
assert j["noisiest"]["fd"] > j["recommended"][0]["fd"]
PY

# No clean isovalue (heavy noise): the report still says which isovalue to use, and which
# denoising makes the scan clean, with the command.
"$cli" -q gen noisy-sphere --size 48 --noise 30 -o "$work/rough.nrrd" >/dev/null
report rough "$work/rough.nrrd"
"$py" - "$work/rough.json" "$work/rough.html" <<'PY' && pass || fail "rough: an answer and a denoising that makes it clean"
import json, sys
j = json.load(open(sys.argv[1]))
page = open(sys.argv[2]).read()
assert not j["clean"] and j["recommended"] and j["recommended"][0]["verdict"] in ("rough", "noisy"), j["recommended"]
tried = j["denoise"]["attempts"]
assert tried and tried[-1]["clean"] and tried[-1]["recommended"][0]["verdict"] == "clean", tried
assert "No isovalue is clean" in page and "The cleanest: isovalue" in page, "no answer line"
assert "After the " + tried[-1]["filter"] in page and tried[-1]["command"].replace("&", "&amp;") in page, "no denoising line"
PY

# A real MRI through the NIfTI reader (the path every command reads with).
nifti="$data/formats/avg152T1_RL_nifti.nii.gz"
if [ -f "$nifti" ]; then report mri "$nifti"; else echo "skip: $nifti not found"; fi

# Degenerate grids (no cube; one value everywhere): a page that says so, still checked.
printf '\x00\x10' > "$work/line_2x1x1_uint8.raw"
head -c 210 /dev/zero | tr '\0' '\003' > "$work/const_7x6x5_uint8.raw"
report line "$work/line_2x1x1_uint8.raw"
report const "$work/const_7x6x5_uint8.raw"

# Bad input: one error line naming the file, exit 2, no output left behind.
expect 2 "clfractal: error: .*no-such.nrrd" -- "$cli" -q report "$work/no-such.nrrd" -o "$work/bad.html"
[ ! -e "$work/bad.html" ] && pass || fail "bad input left $work/bad.html"
expect 2 "clfractal: error: .*missing-dir" -- "$cli" -q report synthetic:sphere:16 -o "$work/missing-dir/r.html"
expect 2 "clfractal: error: .*--window" -- "$cli" -q report synthetic:sphere:16 -o "$work/w.html" --window 3
[ ! -e "$work/w.html" ] && pass || fail "bad window left $work/w.html"

echo "report: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
