#!/usr/bin/env bash
# clfractal report end to end: the page and its JSON on a synthetic volume (and on a real
# MRI in NIfTI when ../shared/data is there), checked by report_check.py (structure, inline
# PNGs and scripts, no network, numbers equal to the JSON) and report_check (every recommended
# isovalue clean by the plain reference curve); the interactive view's meshes and size,
# --static, the page without three.js; bad input fails with one line and leaves nothing.
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

# The interactive view: a 3D view of each choice (at least the noisiest and the recommended),
# its meshes within the budget, the page within 8 MB.
"$py" - "$work/sphere.json" "$work/sphere.html" <<'PY' && pass || fail "sphere: the interactive view"
import json, os, sys
j = json.load(open(sys.argv[1]))
c = j["explore"]["choices"]
# The switched view opens on the noisiest (where the noise is), the recommended one beside it.
assert len(c) >= 2 and c[0]["isovalue"] == j["noisiest"]["isovalue"] and c[1]["isovalue"] == j["recommended"][0]["isovalue"], c
assert all(0 < e["triangles"] <= 50000 for e in c), c
assert os.path.getsize(sys.argv[2]) <= 8 << 20
PY
# --mesh-triangles bounds each mesh (clustered when the surface is larger).
"$cli" -q report synthetic:noisy-sphere:48 -o "$work/small.html" --json "$work/small.json" --mesh-triangles 2000 >/dev/null &&
"$py" - "$work/small.json" <<'PY' && pass || fail "--mesh-triangles 2000: meshes of at most 2000 triangles, clustered"
import json, sys
c = json.load(open(sys.argv[1]))["explore"]["choices"]
assert all(e["triangles"] <= 2000 for e in c) and any(e["cell"] > 0 and e["triangles_full"] > 2000 for e in c), c
PY
# A surface of more than 2^20 cubes is clustered as it is extracted (definitions §37): a
# gyroid of period 10 on 128^3 (about 2 million triangles at mid-range isovalues).
"$py" -c "
import math
n = 128
s = [math.sin(2 * math.pi * i / 10) for i in range(n)]
c = [math.cos(2 * math.pi * i / 10) for i in range(n)]
out = bytearray()
for z in range(n):
    for y in range(n):
        out += bytes(min(255, max(0, round(127.5 + 80 * (s[x] * c[y] + s[y] * c[z] + s[z] * c[x])))) for x in range(n))
open('$work/gyroid_128x128x128_uint8.raw', 'wb').write(out)" &&
"$cli" -q report "$work/gyroid_128x128x128_uint8.raw" -o "$work/gyroid.html" --json "$work/gyroid.json" \
  --mesh-triangles 5000 >/dev/null &&
"$py" - "$work/gyroid.json" <<'PY' && pass || fail "gyroid 128^3: large surfaces clustered within the budget"
import json, sys
c = json.load(open(sys.argv[1]))["explore"]["choices"]
big = [e for e in c if e["triangles_full"] > 1500000]
assert big and all(0 < e["triangles"] <= 5000 for e in c), c
assert all(e["cell"] > 0 and e["vertices"] > 100 for e in big), big
PY
"$py" "$check_py" "$work/gyroid.html" "$work/gyroid.json" && pass || fail "report_check.py gyroid"
# --static: today's page, no script; without three.js the same, with a warning and a note.
out=$("$cli" -q report synthetic:noisy-sphere:48 -o "$work/static.html" --json "$work/static.json" --static 2>&1)
[ $? -eq 0 ] && ! grep -qi "<script" "$work/static.html" && pass || fail "--static: $out"
"$py" "$check_py" "$work/static.html" "$work/static.json" && pass || fail "report_check.py static"
out=$(CLFRACTAL_THREE_DIR="$work/no-three" "$cli" -q report synthetic:noisy-sphere:48 -o "$work/nothree.html" \
  --json "$work/nothree.json" 2>&1)
[ $? -eq 0 ] && grep -q "warning: three.js .*libjs-three" <<<"$out" && ! grep -qi "<script" "$work/nothree.html" &&
  grep -q "No interactive view" "$work/nothree.html" && pass || fail "without three.js: $out"
"$py" "$check_py" "$work/nothree.html" "$work/nothree.json" && pass || fail "report_check.py nothree"
# The structure check fails on an external reference, in a script or in an element.
sed 's|<body>|<body><img src="https://example.org/x.png" alt="x">|' "$work/sphere.html" > "$work/bad-img.html"
sed 's|<script id="report-script">|<script id="report-script">var u = "https://example.org/x.js";|' "$work/sphere.html" \
  > "$work/bad-script.html"
sed 's|<script id="report-script">|<script src="x.js"></script><script id="report-script">|' "$work/sphere.html" \
  > "$work/bad-src.html"
for bad in bad-img bad-script bad-src; do
  "$py" "$check_py" "$work/$bad.html" "$work/sphere.json" >/dev/null && fail "report_check.py passes $bad" || pass
done

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
expect 2 "clfractal: error: .*--mesh-triangles" -- "$cli" -q report synthetic:sphere:16 -o "$work/w.html" --mesh-triangles 0
expect 2 "clfractal: error: .*--mesh-triangles" -- "$cli" -q report synthetic:sphere:16 -o "$work/w.html" \
  --mesh-triangles 300001
[ ! -e "$work/w.html" ] && pass || fail "bad window left $work/w.html"

echo "report: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
