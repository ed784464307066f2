#!/usr/bin/env bash
# End-to-end checks of the clfractal tool: outputs, exit codes and error lines.
# Usage: cli_test.sh CLFRACTAL WORKDIR
set -u
bin=$1
work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
passes=0
pass() { passes=$((passes + 1)); }
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect CODE PATTERN -- command...: exit code CODE and stderr+stdout matching PATTERN
expect() {
  local code=$1 pattern=$2
  shift 3
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$code" ]; then fail "'$*' exited $rc, expected $code: $out"; return; fi
  if ! grep -qE -- "$pattern" <<<"$out"; then fail "'$*' output does not match '$pattern': $out"; return; fi
  pass
}

expect 0 '\*' -- "$bin" devices
expect 0 'mean FD' -- "$bin" -q fd synthetic:noisy-sphere:48
expect 0 'dims +40x40x40' -- "$bin" info synthetic:sphere:40

# fd outputs: exact CSV header, JSON fields, plot.
expect 0 'mean FD' -- "$bin" -q fd synthetic:sphere:40 --csv fd.csv --json fd.json --plot fd.png
[ "$(head -1 fd.csv)" = "isovalue,count,count_sub,fd" ] && pass || fail "csv header: $(head -1 fd.csv)"
python3 - <<'PY' && pass || fail "json fields"
import json
j = json.load(open("fd.json"))
for k in ["volume", "dims", "type", "kind", "levels", "mean_fd", "std_fd", "weighted_mean_fd",
          "isovalues_defined", "device", "seconds_compute"]:
    assert k in j, k
assert j["dims"] == [40, 40, 40] and j["type"] == "uint8" and j["kind"] == "box" and j["levels"] == 2
assert 1.8 < j["mean_fd"] < 2.3
rows = open("fd.csv").read().splitlines()
assert len(rows) == 1 + j["isovalues_total"] == 1 + len(j["curve"]), len(rows)
# integer data: one row per integer of the value range, in order
assert [int(r.split(",")[0]) for r in rows[1:]] == list(range(0, j["isovalues_total"]))
PY
[ -s fd.png ] && [ "$(head -c 4 fd.png | tail -c 3)" = "PNG" ] && pass || fail "plot is not a PNG"
expect 0 'mean FD' -- "$bin" -q fd synthetic:torus:33 --levels 4 --edge --csv fd4.csv
[ "$(head -1 fd4.csv)" = "isovalue,count,count_sub,fd,count_l2,count_l3,fd_fit" ] && pass || fail "levels csv header: $(head -1 fd4.csv)"

# Slabs give the same CSV as the in-core run.
expect 0 'slabs' -- "$bin" -q fd synthetic:noisy-sphere:37 --slab 5 --csv slab.csv
expect 0 'mean FD' -- "$bin" -q fd synthetic:noisy-sphere:37 --csv whole.csv
cmp -s slab.csv whole.csv && pass || fail "slab CSV differs from the in-core CSV"

# gen + raw + NRRD round trip through the tool.
expect 0 '' -- "$bin" -q gen marschner-lobb --size 21 -o ml.nrrd
expect 0 'float32' -- "$bin" info ml.nrrd
expect 0 'mean FD' -- "$bin" -q fd ml.nrrd --isovalues 0.1:0.9:0.1 --csv ml.csv
[ "$(wc -l < ml.csv)" -eq 10 ] && pass || fail "isovalue range rows: $(wc -l < ml.csv)"
head -c 1000 /dev/urandom > noise_10x10x10_uint8.raw
expect 0 'mean FD' -- "$bin" -q fd noise_10x10x10_uint8.raw
expect 0 'mean FD' -- "$bin" -q fd noise_10x10x10_uint8.raw --dims 10,10,10 --type uint8

# local: the LD field as a float32 NRRD, NaN where LD is undefined. `info` rejects NaN like
# any analysis input, so the field it reads back has a window wider than the grid (LD is
# then defined everywhere); the NaN of a normal window are checked in the file itself.
expect 0 'mean LD' -- "$bin" -q local synthetic:noisy-sphere:40 --iso 128 -o ld.nrrd
expect 0 'ld_mesh.ply \([0-9]+ vertices, [0-9]+ triangles, coloured by LD' -- "$bin" -q local synthetic:noisy-sphere:40 --iso 128 -o ld2.nrrd --mesh ld_mesh.ply
head -c 400 ld_mesh.ply | grep -aq 'property float ld' && pass || fail "local --mesh PLY carries no ld property"
python3 - <<'PY' && pass || fail "ld.nrrd: header, NaN pattern or values"
import struct
head, body = open("ld.nrrd", "rb").read().split(b"\n\n", 1)
head = head.decode()
assert "type: float" in head and "sizes: 40 40 40" in head and "endian: little" in head, head
ld = struct.unpack("<%df" % 40**3, body)
defined = [v for v in ld if v == v]
assert 0 < len(defined) < len(ld), len(defined)
assert 1.8 < sum(defined) / len(defined) < 2.6, sum(defined) / len(defined)
PY
expect 0 'defined +13824 of 13824' -- "$bin" -q local synthetic:sphere:24 --iso 100 --window 64 -o ld_all.nrrd
expect 0 'type +float32' -- "$bin" info ld_all.nrrd
expect 2 'clfractal: error: .*window' -- "$bin" local synthetic:sphere:20 --iso 100 --window 5 -o bad_ld.nrrd
expect 2 'clfractal: error: .*window' -- "$bin" local synthetic:sphere:20 --iso 100 --window 0 -o bad_ld.nrrd
[ ! -e bad_ld.nrrd ] && pass || fail "an LD file was written for a bad window"
expect 2 'clfractal: error: .*iso' -- "$bin" local synthetic:sphere:20 -o bad_ld.nrrd

# mesh: a binary PLY with one vertex per intersected edge (its count is E(s) of `fd --edge`),
# a preview PNG, both methods, LD colours; bad arguments exit 2 and write nothing.
expect 0 'triangles' -- "$bin" -q mesh synthetic:sphere:24 --iso 128 -o m.ply --preview m.png
[ "$(head -c 36 m.ply)" = "$(printf 'ply\nformat binary_little_endian 1.0\n')" ] && pass || fail "mesh is not a binary PLY"
[ -s m.png ] && [ "$(head -c 4 m.png | tail -c 3)" = "PNG" ] && pass || fail "preview is not a PNG"
expect 0 'mean FD' -- "$bin" -q fd synthetic:sphere:24 --edge --isovalues 128:128:1 --csv e.csv
[ "$(grep -a -m1 '^element vertex' m.ply | cut -d' ' -f3)" = "$(tail -1 e.csv | cut -d, -f2)" ] && pass \
  || fail "PLY vertex count is not E(s)"
expect 0 'marching tetrahedra' -- "$bin" -q mesh synthetic:torus:24 --iso 3 --method mt -o t.ply
expect 0 '% red' -- "$bin" -q mesh synthetic:noisy-sphere:32 --iso 128 --color-by-ld --window 6 -o c.ply --preview c.png
grep -aq '^property uchar red' c.ply && grep -aq '^property float ld' c.ply && pass || fail "coloured PLY lacks red/ld"
expect 0 'no surface' -- "$bin" -q mesh synthetic:sphere:24 --iso 300 -o empty.ply
expect 2 'clfractal: error: .*method' -- "$bin" mesh synthetic:sphere:24 --iso 128 --method dual -o bad.ply
expect 2 'clfractal: error: .*window' -- "$bin" mesh synthetic:sphere:24 --iso 128 --window 8 -o bad.ply
expect 2 'clfractal: error: .*window' -- "$bin" mesh synthetic:sphere:24 --iso 128 --color-by-ld --window 5 -o bad.ply
expect 2 'clfractal: error: .*iso' -- "$bin" mesh synthetic:sphere:24 -o bad.ply
[ ! -e bad.ply ] && pass || fail "a PLY was written for bad arguments"
expect 2 'clfractal: error: .*cannot write' -- "$bin" -q mesh synthetic:sphere:24 --iso 128 -o no/such/dir/m.ply

# Bad input: one error line naming the file, exit 2, no output file left behind.
head -c 999 /dev/urandom > short_10x10x10_uint8.raw
expect 2 'clfractal: error: .*short_10x10x10_uint8.raw.*truncated' -- "$bin" fd short_10x10x10_uint8.raw --csv bad.csv
[ ! -e bad.csv ] && pass || fail "a CSV was written for bad input"
expect 2 'clfractal: error: .*nope.nrrd' -- "$bin" fd nope.nrrd
expect 2 'clfractal: error: .*unknown' -- "$bin" fd x.raw --dims 2,2,2 --type complex128
expect 2 'clfractal: error: .*dims' -- "$bin" fd x.raw --dims 2,2 --type uint8
expect 2 'clfractal: error: .*(exceed|overflow)' -- "$bin" fd x.raw --dims 100000000,100000000,100000000 --type uint8
python3 -c "
import struct; open('nan_3x3x3_float32.raw','wb').write(struct.pack('<27f', *([1.0]*13 + [float('nan')] + [2.0]*13)))"
expect 2 'clfractal: error: .*nan_3x3x3_float32.raw.*NaN' -- "$bin" fd nan_3x3x3_float32.raw
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: gzip\n\nnot gzip at all' > corrupt.nrrd
expect 2 'clfractal: error: .*corrupt.nrrd' -- "$bin" info corrupt.nrrd
expect 2 'clfractal: error: .*synthetic' -- "$bin" fd synthetic:no-such-shape
expect 2 'clfractal: error: .*levels' -- "$bin" fd synthetic:sphere:20 --levels 1
expect 2 'clfractal: error: .*bins' -- "$bin" fd synthetic:sphere:20 --bins 10
expect 2 'clfractal: error:' -- "$bin" fd
expect 2 'clfractal: error:' -- "$bin" frobnicate
expect 2 'clfractal: error: .*cannot write' -- "$bin" -q fd synthetic:sphere:20 --csv no/such/dir/x.csv

# components: exact CSV header, counts of known shapes, --verify, plot; fd --components.
expect 0 'every isovalue equals' -- "$bin" -q components synthetic:sphere:24 --csv comp.csv --plot comp.png --verify
[ "$(head -1 comp.csv)" = "isovalue,components" ] && pass || fail "components csv header: $(head -1 comp.csv)"
[ -s comp.png ] && pass || fail "components plot missing"
# The sphere: one component at every isovalue strictly inside the range.
awk -F, 'NR > 2 && $2 != 1 && $1 < 255 { bad = 1 } END { exit bad }' comp.csv && pass || fail "sphere components != 1"
expect 0 'freudenthal' -- "$bin" -q components synthetic:torus:20 --connectivity freudenthal --bins 16 --csv compf.csv
[ "$(wc -l < compf.csv)" -eq 17 ] && pass || fail "float --bins 16 rows: $(wc -l < compf.csv)"
expect 2 'clfractal: error: .*connectivity' -- "$bin" components synthetic:sphere:16 --connectivity six
expect 2 'clfractal: error: .*nope.nrrd' -- "$bin" components nope.nrrd
expect 2 'clfractal: error: .*cannot write' -- "$bin" -q components synthetic:sphere:16 --csv no/such/dir/c.csv
expect 0 'corr\(D, components' -- "$bin" -q fd synthetic:noisy-sphere:32 --components --csv fdc.csv --json fdc.json --plot fdc.png
[ "$(head -1 fdc.csv)" = "isovalue,count,count_sub,fd,components" ] && pass || fail "fd --components csv header: $(head -1 fdc.csv)"
[ -s fdc.png ] && pass || fail "fd --components plot missing"
python3 - <<'PY' && pass || fail "fd --components json fields"
import json
j = json.load(open("fdc.json"))
assert "corr_components" in j and "corr_components_per_area" in j, j.keys()
assert j["corr_components"] is None or -1 <= j["corr_components"] <= 1
assert all("components" in r for r in j["curve"])
PY

# survey: a manifest of two small volumes written here, and a plain directory.
mkdir -p survey_dir
"$bin" -q gen noisy-sphere --size 20 -o survey_dir/a.nrrd && "$bin" -q gen torus --size 18 -o survey_dir/b.nrrd
printf 'file\tname\tdims\tdtype\tcategory\na.nrrd\ta\t20x20x20\tuint8\tmedical\nb.nrrd\tb\t18x18x18\tfloat32\tsynthetic\n' > survey_dir/MANIFEST.tsv
expect 0 'medical +1' -- "$bin" -q survey survey_dir/MANIFEST.tsv --markdown survey.md --csv survey.csv --histogram survey.png
grep -q '^| all | 2 |' survey.md && pass || fail "survey markdown: $(cat survey.md)"
[ "$(wc -l < survey.csv)" -eq 3 ] && pass || fail "survey csv rows"
[ -s survey.png ] && pass || fail "survey histogram missing"
expect 0 '\[2/2\]' -- "$bin" survey survey_dir
mkdir -p plain_dir && cp survey_dir/a.nrrd plain_dir/
expect 0 'uncategorized' -- "$bin" -q survey plain_dir
printf 'file\tname\n' > bad.tsv
expect 2 "clfractal: error: .*bad.tsv.*column 'dims'" -- "$bin" survey bad.tsv
expect 2 'clfractal: error: .*no_such_dir' -- "$bin" survey no_such_dir
mkdir -p empty_dir
expect 2 'clfractal: error: .*empty_dir' -- "$bin" survey empty_dir

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
