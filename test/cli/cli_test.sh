#!/usr/bin/env bash
# End-to-end checks of the clfractal tool: outputs, exit codes and error lines.
# Usage: cli_test.sh CLFRACTAL WORKDIR
set -u
bin=$1
work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
source "$here/cli_lib.sh"

expect 0 '\*' -- "$bin" devices
expect 0 'mean FD' -- "$bin" -q fd synthetic:noisy-sphere:48
# The denoising's suggested output is named after the synthetic volume, with no "synthetic:".
expect 0 'run: clfractal filter synthetic:noisy-sphere .* -o noisy-sphere-denoised\.nrrd$' -- "$bin" -q fd synthetic:noisy-sphere
expect 0 'dims +40x40x40' -- "$bin" info synthetic:sphere:40
# OpenMP waits passively in the tool unless the user chose otherwise: libgomp, which prints
# its spin count with OMP_DISPLAY_ENV=verbose, counts 0 (another OpenMP runtime: not checked).
if OMP_DISPLAY_ENV=verbose "$bin" --version 2>&1 | grep -q 'GOMP_SPINCOUNT'; then
  OMP_DISPLAY_ENV=verbose "$bin" --version 2>&1 | grep -q "GOMP_SPINCOUNT = '0'" && pass ||
    fail "libgomp spins in clfractal: $(OMP_DISPLAY_ENV=verbose "$bin" --version 2>&1 | grep SPINCOUNT)"
  OMP_WAIT_POLICY=active OMP_DISPLAY_ENV=verbose "$bin" --version 2>&1 | grep -q "GOMP_SPINCOUNT = '0'" &&
    fail "OMP_WAIT_POLICY=active is not kept" || pass
fi

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

# local: the LD field as a float32 NRRD, NaN where LD is undefined. `info` reads it and
# reports the NaN count and the range of the rest; the counting commands refuse it.
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
expect 0 'NaN +[1-9][0-9]* \(' -- "$bin" info ld.nrrd
expect 0 'range +[0-9.]+ \.\. [0-9.]+ \(finite values\)' -- "$bin" info ld.nrrd
expect 2 'clfractal: error: ld.nrrd: float data contains [0-9]+ NaN values \(the first, NaN, at vertex \(0,0,0\)\)' -- "$bin" fd ld.nrrd
expect 2 'clfractal: error: ld.nrrd.*NaN.*vertex \(0,0,0\)' -- "$bin" fd ld.nrrd --stream
expect 2 'clfractal: error: .*window' -- "$bin" local synthetic:sphere:20 --iso 100 --window 5 -o bad_ld.nrrd
expect 2 'clfractal: error: .*window' -- "$bin" local synthetic:sphere:20 --iso 100 --window 0 -o bad_ld.nrrd
[ ! -e bad_ld.nrrd ] && pass || fail "an LD file was written for a bad window"
expect 2 'clfractal: error: .*iso' -- "$bin" local synthetic:sphere:20 -o bad_ld.nrrd
# Arguments are checked before any work: no progress line (the volume read, the device
# started) precedes the error; an isovalue outside the values is a warning before the work.
for cmd in "local synthetic:sphere:20 --iso 100 --window 7 -o w7.nrrd" \
           "smooth synthetic:sphere:20 --iso 100 --threshold 2.2 --window 3 -o w7.nrrd" \
           "filter synthetic:sphere:20 --median --fractal --iso 100 --threshold 2.5 --window 5 -o w7.nrrd" \
           "mesh synthetic:sphere:20 --iso 100 --color-by-ld --window 1 -o w7.ply" \
           "local synthetic:sphere:20 --iso inf -o w7.nrrd"; do
  out=$("$bin" $cmd 2>&1); rc=$?
  [ "$rc" -eq 2 ] && [ "$(wc -l <<<"$out")" -eq 1 ] && grep -qE '^clfractal: error: --(window|iso)' <<<"$out" \
    && pass || fail "'$cmd' exited $rc or did work before the argument error: $out"
done
[ ! -e w7.nrrd ] && [ ! -e w7.ply ] && pass || fail "an output was written for a bad argument"
expect 0 'warning: isovalue 1000 is outside \(0, [0-9]+\], the values of synthetic:sphere:20' -- "$bin" local synthetic:sphere:20 --iso 1000 -o w.nrrd

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

# smooth: Algorithm 2 writes a volume of the input's type; a threshold above every LD changes
# nothing; meshes and previews of the result; bad arguments exit 2 and write nothing.
expect 0 'edges +[0-9]+ high fractal at the start, [0-9]+ processed' -- "$bin" -q smooth synthetic:noisy-sphere:40 --iso 128 --threshold 2.5 -o sm.nrrd
expect 0 'type +uint8' -- "$bin" info sm.nrrd
expect 0 'cubes +([0-9]+) -> \1 intersected' -- "$bin" -q smooth synthetic:noisy-sphere:40 --iso 128 --threshold 50 -o same.nrrd
expect 0 'vertices +0 changed' -- "$bin" -q smooth synthetic:noisy-sphere:40 --iso 128 --threshold 50 -o same.nrrd
expect 0 'sm.ply \([0-9]+ vertices' -- "$bin" -q smooth synthetic:noisy-sphere:40 --iso 128 --threshold 2.4 --variant gaussian --tau 1.5 --window 6 -o smg.nrrd --mesh sm.ply --preview sm.png
grep -aq '^property float ld' sm.ply && pass || fail "smooth --mesh PLY carries no ld property"
[ -s sm.png ] && [ "$(head -c 4 sm.png | tail -c 3)" = "PNG" ] && pass || fail "smooth preview is not a PNG"
expect 0 'variant gaussian' -- "$bin" -q smooth ml.nrrd --iso 0.5 --threshold 2.2 --variant gaussian -o smf.nrrd
expect 0 'type +float32' -- "$bin" info smf.nrrd
expect 2 'clfractal: error: .*variant' -- "$bin" smooth synthetic:sphere:20 --iso 100 --threshold 2.5 --variant blocky -o bad_sm.nrrd
expect 2 'clfractal: error: .*window' -- "$bin" smooth synthetic:sphere:20 --iso 100 --threshold 2.5 --window 5 -o bad_sm.nrrd
expect 2 'clfractal: error: .*tau' -- "$bin" smooth synthetic:sphere:20 --iso 100 --threshold 2.5 --variant gaussian --tau 0 -o bad_sm.nrrd
expect 2 'clfractal: error: .*threshold' -- "$bin" smooth synthetic:sphere:20 --iso 100 -o bad_sm.nrrd
expect 2 'clfractal: error: .*threshold' -- "$bin" smooth synthetic:sphere:20 --iso 100 --threshold inf -o bad_sm.nrrd
expect 2 'clfractal: error: .*output' -- "$bin" smooth synthetic:sphere:20 --iso 100 --threshold 2.5
[ ! -e bad_sm.nrrd ] && pass || fail "a volume was written for bad smooth arguments"
expect 2 'clfractal: error: .*cannot write' -- "$bin" -q smooth synthetic:sphere:20 --iso 100 --threshold 2.5 -o no/such/dir/sm.nrrd

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
expect 2 'clfractal: error: .*nan_3x3x3_float32.raw: float data contains 1 NaN value \(the first, NaN, at vertex \(1,1,1\)\)' -- "$bin" fd nan_3x3x3_float32.raw
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: gzip\n\nnot gzip at all' > corrupt.nrrd
expect 2 'clfractal: error: .*corrupt.nrrd' -- "$bin" info corrupt.nrrd
expect 2 'clfractal: error: .*synthetic' -- "$bin" fd synthetic:no-such-shape
expect 2 'clfractal: error: .*levels' -- "$bin" fd synthetic:sphere:20 --levels 1
expect 2 'clfractal: error: .*bins' -- "$bin" fd synthetic:sphere:20 --bins 10
expect 2 'clfractal: error:' -- "$bin" fd
expect 2 'clfractal: error:' -- "$bin" frobnicate
expect 2 'clfractal: error: .*cannot write' -- "$bin" -q fd synthetic:sphere:20 --csv no/such/dir/x.csv

# fd --stream: the file read slice by slice gives the same curve (raw via mmap, gzip NRRD).
python3 - <<'PY'
import gzip, random
random.seed(3)
data = bytes(random.choice([0, 0, 40, 90, 200]) for _ in range(21 * 17 * 29))
open('st_21x17x29_uint8.raw', 'wb').write(data)
hdr = b'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 21 17 29\nencoding: gzip\n\n'
open('st.nrrd', 'wb').write(hdr + gzip.compress(data))
open('st_cut.nrrd', 'wb').write(hdr + gzip.compress(data)[:300])
open('st_plain.nrrd', 'wb').write(hdr + data)
open('st2_13x11x9_uint8.raw', 'wb').write(bytes(random.randint(30, 90) for _ in range(13 * 11 * 9)))
# Signed 8- and 16-bit data, streamed in one counting pass over every value of the type and
# cropped to the value range (-100 .. 90 and -1500 .. 2500 here, both ends present).
import struct
def signed(fmt, lo, hi, n):
    v = [random.choice([lo, hi, random.randint(lo, hi), random.randint(lo, hi) // 8]) for _ in range(n)]
    return struct.pack('<%d%s' % (n, fmt), *v)
open('st8_19x15x13_int8.raw', 'wb').write(signed('b', -100, 90, 19 * 15 * 13))
open('st16_19x15x13_int16.raw', 'wb').write(signed('h', -1500, 2500, 19 * 15 * 13))
PY
expect 0 'mean FD' -- "$bin" -q fd st_21x17x29_uint8.raw --levels 3 --csv whole.csv
expect 0 'streamed, mmap' -- "$bin" -q fd st_21x17x29_uint8.raw --levels 3 --stream --csv streamed.csv
cmp -s whole.csv streamed.csv && pass || fail "fd --stream CSV differs from fd"
expect 0 'streamed, gzip' -- "$bin" -q fd st.nrrd --levels 3 --stream --csv streamed_gz.csv
cmp -s whole.csv streamed_gz.csv && pass || fail "fd --stream on gzip NRRD differs from fd"
expect 0 'streamed, memory' -- "$bin" -q fd synthetic:sphere:20 --edge --stream
# uint8 is streamed in one pass and cropped to the value range (30 .. 90 here).
expect 0 'isovalues +61 \(30 \.\. 90\)' -- "$bin" -q fd st2_13x11x9_uint8.raw --edge --stream --csv st2_stream.csv
expect 0 'mean FD' -- "$bin" -q fd st2_13x11x9_uint8.raw --edge --csv st2_whole.csv
cmp -s st2_whole.csv st2_stream.csv && pass || fail "fd --stream (one pass, cropped) CSV differs from fd"
# The whole answer streamed, as in core: the entries with their component counts (a second
# pass over the file) and the boundary strength from the streamed histogram; the same text and
# JSON but for the times (both without the denoising ladder, which a stream cannot try and,
# when nothing is clean, names in `skipped`).
# (ns324: 34 MB, read in one part a core, the device started after the read.)
"$bin" -q gen noisy-sphere --size 40 --noise 6 -o ns40.nrrd >/dev/null 2>&1 || fail "gen noisy-sphere"
"$bin" -q gen noisy-sphere --size 324 --noise 6 -o ns324.nrrd >/dev/null 2>&1 || fail "gen noisy-sphere 324"
for f in st_21x17x29_uint8.raw st.nrrd ns40.nrrd ns324.nrrd st8_19x15x13_int8.raw st16_19x15x13_int16.raw; do
  "$bin" -q fd "$f" --no-denoise --json whole.json 2>&1 | grep -v '^time' > whole.txt
  "$bin" -q fd "$f" --stream --no-denoise --json streamed.json 2>&1 | grep -v '^time' > streamed.txt
  grep -q '^recommended.* [0-9][0-9]* components' streamed.txt && cmp -s whole.txt streamed.txt && pass ||
    fail "fd --stream on $f: not the in-core answer: $(diff whole.txt streamed.txt | head -4)"
  python3 - whole.json streamed.json <<'PY' && pass || fail "fd --stream --json on $f differs from fd --json"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for j in (a, b):  # the times, and how many device slabs each way took
    for k in [k for k in j if k.startswith("seconds_") or k == "slabs"]: del j[k]
sys.exit(a != b or b["recommended"][0]["components"] is None)
PY
done
# Nothing clean in st.nrrd: the stream says the ladder was not tried, in the text and the JSON.
expect 0 '^skipped +denoise: nothing is clean, but the ladder filters the whole volume' -- \
  "$bin" -q fd st.nrrd --stream --json st_skipped.json
grep -q '"denoise: nothing is clean, but the ladder' st_skipped.json && pass || fail "fd --stream --json: no skipped ladder"
expect 2 'clfractal: error: .*st_cut.nrrd.*gzip data truncated' -- "$bin" -q fd st_cut.nrrd --stream
expect 2 'clfractal: error: .*st_plain.nrrd.*not gzip' -- "$bin" -q fd st_plain.nrrd --stream
expect 2 'clfractal: error: .*short_10x10x10_uint8.raw.*truncated' -- "$bin" fd short_10x10x10_uint8.raw --stream
expect 2 'clfractal: error: .*--slab' -- "$bin" fd synthetic:sphere:20 --stream --slab 4
# noise: measured dimensions beside the formula, JSON shape, plot, real-volume mode, errors.
expect 0 'max \|edge FD - formula\|' -- "$bin" -q noise --size 40 --mu 0,1,2 --box-samples 2000 --json noise.json --plot noise.png
python3 - <<'PY' && pass || fail "noise json"
import json, math
j = json.load(open("noise.json"))
pts = j["points"]
assert [p["mu"] for p in pts] == [0, 1, 2], pts
for p in pts:
    for k in ["mu", "r", "measured_edge_fd", "measured_box_fd", "formula", "model_box_fd", "isovalues"]:
        assert k in p, k
    assert p["r"] == p["mu"] and abs(p["measured_edge_fd"] - p["formula"]) < 0.1, p
assert pts[0]["formula"] == 2 and abs(pts[1]["formula"] - math.log2(39 / 7)) < 1e-12
assert j["noise"] == "uniform" and j["gamma"] == 1 and j["dims"] == [40, 40, 40]
PY
[ -s noise.png ] && [ "$(head -c 4 noise.png | tail -c 3)" = "PNG" ] && pass || fail "noise plot is not a PNG"
expect 0 'Gaussian' -- "$bin" -q noise --size 24 --mu 0:1:0.5 --noise gaussian --box-samples 1000
expect 0 'tori' -- "$bin" -q noise --size 24 --shape circle --mu 1 --isovalues 4,5 --box-samples 1000
expect 0 '' -- "$bin" -q gen points --size 33 -o pts.nrrd
expect 0 'gamma +(0\.9[5-9]|1\.0)[0-9]* +\(estimated' -- "$bin" -q noise --volume pts.nrrd --iso 6 --mu 0,1 --box-samples 1000
expect 0 'gamma +2($|[^.0-9])' -- "$bin" -q noise --volume pts.nrrd --iso 6 --gamma 2 --box-samples 1000
expect 2 'clfractal: error: .*--mu' -- "$bin" noise --mu 0,abc
expect 2 'clfractal: error: .*--mu' -- "$bin" noise --mu=-1
expect 2 'clfractal: error: .*--iso' -- "$bin" noise --iso 5
expect 2 'clfractal: error: .*--volume.*--iso' -- "$bin" noise --volume pts.nrrd
expect 2 'clfractal: error: .*--noise' -- "$bin" noise --noise pink
expect 2 'clfractal: error: .*--size' -- "$bin" noise --size 4
expect 2 'clfractal: error: .*shape' -- "$bin" noise --shape cube
expect 2 'clfractal: error: .*no edge' -- "$bin" noise --volume pts.nrrd --iso 1000

# local --stream: the field read and written slice by slice is the same file's data.
expect 0 'mean LD' -- "$bin" -q local st_21x17x29_uint8.raw --iso 60 --window 4 -o ld_whole.nrrd
expect 0 'streamed, gzip' -- "$bin" -q local st.nrrd --iso 60 --window 4 --stream -o ld_stream.nrrd
cmp -s ld_whole.nrrd ld_stream.nrrd && pass || fail "local --stream wrote other bytes than local"
expect 2 'clfractal: error: .*--mesh' -- "$bin" -q local st.nrrd --iso 60 --stream -o x.nrrd --mesh x.ply
expect 2 'clfractal: error: .*window' -- "$bin" -q local st.nrrd --iso 60 --window 3 --stream -o x.nrrd
[ ! -e x.nrrd ] && pass || fail "local --stream left an output after an error"
# filter: output in the input's type, before/after at the isovalue, targeted share, errors.
expect 0 'changed' -- "$bin" -q filter synthetic:noisy-sphere:24 --median -o med.nrrd
expect 0 'uint8' -- "$bin" info med.nrrd
expect 0 'FD' -- "$bin" -q filter synthetic:noisy-sphere:24 --gaussian 1 --iso 128 -o gauss.nrrd
expect 0 'selected .*LD > 2.4' -- "$bin" -q filter synthetic:noisy-sphere:24 --median --fractal --iso 128 --threshold 2.4 --window 4 -o frac.nrrd
expect 0 'changed +0 vertices' -- "$bin" -q filter synthetic:noisy-sphere:24 --median --fractal --iso 128 --threshold 1000 -o none.nrrd
expect 0 'components +[0-9]+ +[0-9]+' -- "$bin" -q filter synthetic:noisy-sphere:24 --median --iso 128 -o comp.nrrd
expect 0 'components +[0-9]+ -> [0-9]+' -- "$bin" -q smooth synthetic:noisy-sphere:24 --iso 128 --threshold 2.4 -o sm_comp.nrrd
expect 0 'LD-guided' -- "$bin" -q filter synthetic:noisy-sphere:24 --bilateral 1,20 --ld-guided --iso 128 -o ldb.nrrd
# The before/after reports read the input uploaded once (CLFRACTAL_UPLOADS prints the count):
# filter: the input once (reports and filter); targeted: the input once (reports, LD and
# filter), the result once; smooth: the input once, the result once.
expect 0 'clfractal: uploads 1$' -- env CLFRACTAL_UPLOADS=1 "$bin" -q filter synthetic:noisy-sphere:24 --median --iso 128 -o up.nrrd
expect 0 'clfractal: uploads 2$' -- env CLFRACTAL_UPLOADS=1 "$bin" -q filter synthetic:noisy-sphere:24 --median --fractal --iso 128 --threshold 2.4 -o up.nrrd
expect 0 'clfractal: uploads 2$' -- env CLFRACTAL_UPLOADS=1 "$bin" -q smooth synthetic:noisy-sphere:24 --iso 128 --threshold 2.4 -o up.nrrd
expect 0 'float32' -- "$bin" -q filter ml.nrrd --bilateral 1,0.2 -o mlb.nrrd
expect 0 'float32' -- "$bin" info mlb.nrrd
# filter --small-components: counts before/after, the new values, the bad inputs.
expect 0 'removed +[0-9]+ components of \{f >= s\}' -- "$bin" -q filter synthetic:noisy-sphere:24 --small-components 5 --iso 128 -o small.nrrd
expect 0 'components +[0-9]+ +[0-9]+' -- "$bin" -q filter synthetic:noisy-sphere:24 --small-components 5 --iso 128 --connectivity six -o small6.nrrd
expect 0 'changed +0 vertices' -- "$bin" -q filter synthetic:noisy-sphere:24 --small-components 0 --iso 128 -o small0.nrrd
expect 2 'clfractal: error: .*--small-components needs --iso' -- "$bin" filter synthetic:sphere:20 --small-components 5 -o bad.nrrd
expect 2 'clfractal: error: .*K must be >= 0' -- "$bin" filter synthetic:sphere:20 --small-components -1 --iso 100 -o bad.nrrd
expect 2 'clfractal: error: .*not with --median' -- "$bin" filter synthetic:sphere:20 --small-components 5 --median --iso 100 -o bad.nrrd
expect 2 'clfractal: error: .*expected one of cube, six' -- "$bin" filter synthetic:sphere:20 --small-components 5 --iso 100 --connectivity 18 -o bad.nrrd
expect 2 'clfractal: error: synthetic:sphere:20: .*no uint8 value at or above' -- "$bin" filter synthetic:sphere:20 --small-components 5 --iso 256 -o bad.nrrd
expect 2 'clfractal: error: .*--connectivity: only with --small-components' -- "$bin" filter synthetic:sphere:20 --median --connectivity six -o bad.nrrd
expect 2 'clfractal: error: .*exactly one' -- "$bin" filter synthetic:sphere:20 -o bad.nrrd
expect 2 'clfractal: error: .*exactly one' -- "$bin" filter synthetic:sphere:20 --median --gaussian 1 -o bad.nrrd
expect 2 'clfractal: error: .*--gaussian' -- "$bin" filter synthetic:sphere:20 --gaussian -1 -o bad.nrrd
expect 2 'clfractal: error: .*--bilateral' -- "$bin" filter synthetic:sphere:20 --bilateral 1 -o bad.nrrd
expect 2 'clfractal: error: .*--iso' -- "$bin" filter synthetic:sphere:20 --median --fractal --threshold 2.3 -o bad.nrrd
expect 2 'clfractal: error: .*--threshold' -- "$bin" filter synthetic:sphere:20 --median --fractal --iso 100 -o bad.nrrd
expect 2 'clfractal: error: .*window' -- "$bin" filter synthetic:sphere:20 --median --fractal --iso 100 --threshold 2.3 --window 3 -o bad.nrrd
expect 2 'clfractal: error: .*--ld-guided' -- "$bin" filter synthetic:sphere:20 --median --ld-guided --iso 100 -o bad.nrrd
expect 2 'clfractal: error: .*short_10x10x10_uint8.raw' -- "$bin" filter short_10x10x10_uint8.raw --median -o bad.nrrd
[ ! -e bad.nrrd ] && pass || fail "a NRRD was written for bad filter arguments"
# filter --fractal --stream: slice by slice, the same values as the whole-volume run.
"$bin" -q gen noisy-sphere --size 30 -o ns30.nrrd >/dev/null
expect 0 'streamed 30 slices' -- "$bin" -q filter ns30.nrrd --median --fractal --iso 128 --threshold 2.4 -o fs.nrrd --stream
"$bin" -q filter ns30.nrrd --median --fractal --iso 128 --threshold 2.4 -o fw.nrrd >fw.out
cmp -s fs.nrrd fw.nrrd && pass || fail "filter --stream wrote other bytes than the whole-volume filter"
[ "$(stat -c %s fw.nrrd)" -gt $((30 ** 3)) ] && pass || fail "filter output too short"
expect 2 'clfractal: error: --stream: only with --fractal' -- "$bin" filter ns30.nrrd --median --stream -o x.nrrd
expect 2 'clfractal: error: filter radius 3 exceeds k/2 = 2' -- "$bin" filter ns30.nrrd --gaussian 1 --fractal --iso 128 --threshold 2 --window 4 --stream -o x.nrrd
[ ! -e x.nrrd ] && pass || fail "a NRRD was written for a refused --stream"
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
# components --stream: a few isovalues labelled as the file is read slice by slice (raw by
# mmap, gzip NRRD, float data), the in-core CSV exactly.
"$bin" -q gen torus --size 18 -o torus18.nrrd >/dev/null 2>&1 || fail "gen torus"
for spec in "ns40.nrrd 2:9:1" "st_21x17x29_uint8.raw 38:42:1" "st.nrrd 85:95:1" "torus18.nrrd 0.1,0.35,0.5"; do
  set -- $spec
  expect 0 'most +[0-9]+ components' -- "$bin" -q components "$1" --isovalues "$2" --csv comp_whole.csv
  expect 0 'read and labelled \(streamed' -- "$bin" -q components "$1" --isovalues "$2" --stream --csv comp_stream.csv
  cmp -s comp_whole.csv comp_stream.csv && pass || fail "components --stream on $1 at $2 differs from in core"
done
# components in z-parts (--slab N, or by itself when the in-core sweep does not fit): the
# in-core curve exactly, every isovalue.
for f in ns40.nrrd st.nrrd torus18.nrrd; do
  "$bin" -q components "$f" --csv comp_whole.csv >/dev/null 2>&1 || fail "components $f"
  for k in 2 5 41; do
    expect 0 'sort and sweep [0-9]+ z-parts' -- "$bin" -q components "$f" --slab "$k" --csv comp_slab.csv
    cmp -s comp_whole.csv comp_slab.csv && pass || fail "components --slab $k on $f differs from in core"
  done
done
python3 -c "
import random; random.seed(5)
open('big_64x64x512_uint16.raw', 'wb').write(bytes(b for _ in range(64 * 64 * 512) for b in (random.randrange(40), 0)))"
"$bin" -q components big_64x64x512_uint16.raw --csv comp_whole.csv >/dev/null 2>&1 || fail "components big"
expect 0 'counting in z-parts' -- env CLFRACTAL_MEMORY_LIMIT=266M "$bin" components big_64x64x512_uint16.raw --csv comp_slab.csv
cmp -s comp_whole.csv comp_slab.csv && pass || fail "components in z-parts by itself differs from in core"
# Neither in core nor in parts: the in-core check's one line; --slab N that does not fit: its own.
expect 2 'components needs about .* \(4x the 4.0 MiB volume \+ 256 MiB\), but 200.0 MiB' -- env CLFRACTAL_MEMORY_LIMIT=200M "$bin" components big_64x64x512_uint16.raw
expect 2 'components needs about .* \(z-parts of 2 slices' -- env CLFRACTAL_MEMORY_LIMIT=200M "$bin" components big_64x64x512_uint16.raw --slab 2
expect 2 'clfractal: error: --slab 1: z-parts share a slice' -- "$bin" components ns40.nrrd --slab 1
expect 2 'clfractal: error: --verify: not with slabs' -- "$bin" components ns40.nrrd --slab 4 --verify
expect 2 'clfractal: error: --stream: give the isovalues' -- "$bin" components ns40.nrrd --stream
expect 2 'clfractal: error: --stream: 33 isovalues; at most 32' -- "$bin" components ns40.nrrd --stream --isovalues 0:32:1
expect 2 'clfractal: error: --verify: not with --stream' -- "$bin" components ns40.nrrd --stream --isovalues 3:4:1 --verify
expect 2 'clfractal: error: --plot: not with --stream' -- "$bin" components ns40.nrrd --stream --isovalues 3:4:1 --plot c.png
expect 2 'clfractal: error: .*short_10x10x10_uint8.raw.*truncated' -- "$bin" components short_10x10x10_uint8.raw --stream --isovalues 1:2:1
expect 2 'components --stream --isovalues A,B,... labels a few isovalues within 512 MiB' -- env CLFRACTAL_MEMORY_LIMIT=1M "$bin" components ns40.nrrd
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
expect 2 'clfractal: error: /dev/zero: not a regular file' -- timeout 20 "$bin" survey /dev/zero

# Isovalue advice: clean bands in fd (text and JSON), the noise level, --iso auto.
expect 0 'best 1 \.\. [0-9]+ .* use [0-9]+' -- "$bin" -q fd synthetic:sphere:40 --json adv.json --noise-level
expect 0 'clean bands none' -- "$bin" -q fd synthetic:noisy-sphere:64 --clean-fd 2.0
expect 0 '' -- "$bin" -q gen sphere --size 32 --noise 60 -o rough.nrrd
expect 0 'uniform r [0-9.]+ \(\+-[0-9.]+ grey values' -- "$bin" -q fd rough.nrrd --noise-level --json rough.json
# The noise level: uniform noise +-6 on a uint8 sphere, rounded (std sqrt(12 + 1/12) = 3.476).
expect 0 '' -- "$bin" -q gen sphere --size 64 --noise 6 -o grainy.nrrd
expect 0 'noise sigma 3\.[0-9]+ grey levels \(estimated on [0-9.]+% of voxels; white part 3\.[0-9]+\)' -- "$bin" -q fd grainy.nrrd --noise-level --json grainy.json
python3 - <<'PY' && pass || fail "fd JSON clean_bands/noise"
import json
j = json.load(open("adv.json"))
b = j["clean_bands"]
assert len(b) == 1 and b[0]["first"] <= b[0]["isovalue"] <= b[0]["last"] and b[0]["max_fd"] <= 2.2, b
rows = {r["isovalue"]: r for r in j["curve"]}
for s in range(int(b[0]["first"]), int(b[0]["last"]) + 1):
    assert rows[s]["fd"] is not None and rows[s]["fd"] <= 2.2, (s, rows[s])
r = json.load(open("rough.json"))
assert r["clean_bands"] == [], r["clean_bands"]
# uniform noise +-60 added to the clean sphere: Theorem 1 inverted per isovalue gives it within 10%
surface = r["noise"]["surface"]
assert abs(surface["amplitude"] - 60) <= 6, surface["amplitude"]
assert j["noise"]["surface"]["amplitude"] is None or j["noise"]["surface"]["amplitude"] < surface["amplitude"] / 10
assert surface["sigma_gaussian"] > 0 and all("ratio_gaussian" in p for p in surface["per_isovalue"]), surface
# the clean sphere's noise level is its rounding; the grainy one's the added noise within 3%
assert j["noise"]["sigma"] < 0.5, j["noise"]
g = json.load(open("grainy.json"))["noise"]
assert abs(g["sigma"] / (12 + 1 / 12) ** 0.5 - 1) < 0.03, g
assert 0 < g["flat_share"] <= 1 and g["block"] == 8 and g["map"]["dims"] == [2, 2, 2] and len(g["map"]["sigma"]) == 8, g
PY
expect 0 'clfractal: --iso auto: isovalue [0-9]+ \(clean, D [0-9.]+\), the first recommendation, from the clean band [0-9]+ \.\. [0-9]+: the first clean band.s representative' -- "$bin" local synthetic:sphere:40 --iso auto -o auto_ld.nrrd
# Nothing clean: --iso auto still answers, with the cleanest isovalue, its verdict and why,
# as a warning.
expect 0 'clfractal: warning: --iso auto: isovalue [0-9]+ \((rough|noisy), D [0-9.]+\), the first recommendation, from the cleanest quarter [0-9]+ \.\. [0-9]+: no well-populated isovalue of rough.nrrd is clean \(D <= 2.2\), so this is the cleanest; its surface is (rough|noisy)' -- "$bin" mesh rough.nrrd --iso auto -o auto.ply
[ -s auto.ply ] && pass || fail "--iso auto on a rough volume wrote no mesh"
# Constant volume: no surface anywhere, so auto has nothing to choose.
head -c 210 /dev/zero | tr '\0' '\003' > flat_7x6x5_uint8.raw
expect 2 'clfractal: error: --iso auto: .*flat_7x6x5_uint8.raw has no surface at any isovalue' -- "$bin" -q mesh flat_7x6x5_uint8.raw --iso auto -o flat.ply
[ ! -e flat.ply ] && pass || fail "--iso auto on a constant volume wrote a mesh"
expect 0 'recommended none: no cube is intersected' -- "$bin" -q fd flat_7x6x5_uint8.raw
# The recommendations: never empty, verdicts, the denoising ladder when nothing is clean, and
# the C ABI's analysis (clf_analyse, a C program) gives exactly fd --json's.
expect 0 'recommended 1\. isovalue [0-9]+  (rough|noisy)' -- "$bin" -q fd rough.nrrd --json rough_adv.json
if [ -z "${CLF_ANALYSE:-}" ]; then fail "CLF_ANALYSE (the C program clf_analyse) is not set"; else
  "$CLF_ANALYSE" rough.nrrd > rough_capi.json && pass || fail "clf_analyse rough.nrrd"
  "$CLF_ANALYSE" synthetic:sphere:40 > sphere_capi.json && pass || fail "clf_analyse sphere"
  expect 0 '' -- "$bin" -q fd synthetic:sphere:40 --json sphere_adv.json
  python3 - <<'PY' && pass || fail "fd --json and the C ABI: the same recommendations"
import json
for cli, c in [("rough_adv.json", "rough_capi.json"), ("sphere_adv.json", "sphere_capi.json")]:
    a, b = json.load(open(cli)), json.load(open(c))
    assert a["recommended"] == b["recommended"] and a["noisiest"] == b["noisiest"], (cli, a["recommended"], b["recommended"])
    assert a["clean"] == b["clean"] and a["clean_bands"] == b["clean_bands"], cli
    assert [t["command"] for t in a["denoise"]["attempts"]] == [t["command"] for t in b["denoise"]["attempts"]], cli
r = json.load(open("rough_adv.json"))
assert not r["clean"] and r["recommended"] and r["denoise"]["needed"], r["recommended"]
for e in r["recommended"]:
    assert e["verdict"] in ("rough", "noisy") and e["basis"] == "cleanest quarter" and e["components"] >= 1, e
s = json.load(open("sphere_adv.json"))
assert s["clean"] and s["recommended"][0]["verdict"] == "clean" and s["denoise"]["attempts"] == [], s["recommended"]
PY
fi

# Value types of revision 2: an int32 raw file over a wide range (uniform float64 isovalues)
# and a float64 NRRD whose values float32 cannot tell apart, counted against the definition
# in plain Python (a < s <= b in double, every cube of G and G'); CSV isovalues round-trip
# (17 significant digits for float64); --as float32 converts on read.
python3 - <<'PY' || fail "writing the int32 and float64 fixtures"
import struct
n = 9 * 8 * 7
vals = [((i * 2654435761) % 4294967291) - 2147483645 for i in range(n)]
vals[0], vals[1] = -2147483648, 2147483647
open("w_9x8x7_int32.raw", "wb").write(struct.pack("<%di" % n, *vals))
d = [1 + ((i * 7919) % 41) * 2.0 ** -40 + (i % 3) * 0.125 for i in range(n)]
open("f64.nrrd", "wb").write(b"NRRD0004\ntype: double\ndimension: 3\nsizes: 9 8 7\nendian: little\nencoding: raw\n\n"
                            + struct.pack("<%dd" % n, *d))
PY
expect 0 'int32' -- "$bin" info w_9x8x7_int32.raw
expect 0 'uniform float64 list' -- "$bin" info w_9x8x7_int32.raw
expect 0 'float64' -- "$bin" info f64.nrrd
expect 0 'mean FD' -- "$bin" -q fd w_9x8x7_int32.raw --csv w.csv
expect 0 'mean FD' -- "$bin" -q fd f64.nrrd --csv f64.csv
expect 0 'mean FD' -- "$bin" -q fd f64.nrrd --as float32 --csv f64as32.csv
expect 0 'float32' -- "$bin" info f64.nrrd --as float32
python3 - <<'PY' && pass || fail "int32 / float64 / --as float32 CSV against the definition"
import struct
def read(path, fmt, size, skip=0):
    data = open(path, "rb").read()[skip:]
    return list(struct.unpack("<%d%s" % (len(data) // size, fmt), data))
def level(v, dims):
    nx, ny, nz = dims
    m = [(n - 1) // 2 + 1 for n in dims]
    return [v[2 * x + nx * (2 * y + ny * 2 * z)] for z in range(m[2]) for y in range(m[1]) for x in range(m[0])], m
def cube_counts(v, dims, iso):
    nx, ny, nz = dims
    out = [0] * len(iso)
    for z in range(nz - 1):
        for y in range(ny - 1):
            for x in range(nx - 1):
                c = [v[x + i + nx * (y + j + ny * (z + k))] for i in (0, 1) for j in (0, 1) for k in (0, 1)]
                a, b = min(c), max(c)
                for s in range(len(iso)):
                    if a < iso[s] <= b:
                        out[s] += 1
    return out
def uniform(lo, hi, k=256):
    s = []
    for j in range(k):
        x = lo + (j + 1) * (hi - lo) / k
        if not s or s[-1] < x:
            s.append(x)
    return s
def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]
def check(csv, v, iso, digits):
    rows = [r.split(",") for r in open(csv).read().splitlines()[1:]]
    assert len(rows) == len(iso), (csv, len(rows), len(iso))
    back = (lambda x: f32(x)) if digits == 9 else (lambda x: x)  # 9 digits: float32 round trip
    assert [back(float(r[0])) for r in rows] == iso, csv
    assert all(len(r[0].replace("-", "").replace(".", "").split("e")[0].lstrip("0")) <= digits for r in rows), csv
    dims = (9, 8, 7)
    sub, sdims = level(v, dims)
    assert [int(r[1]) for r in rows] == cube_counts(v, dims, iso), csv
    assert [int(r[2]) for r in rows] == cube_counts(sub, sdims, iso), csv
    assert sum(int(r[1]) for r in rows) > 0, csv
w = read("w_9x8x7_int32.raw", "i", 4)
check("w.csv", w, uniform(min(w), max(w)), 17)
header = open("f64.nrrd", "rb").read().index(b"\n\n") + 2
d = read("f64.nrrd", "d", 8, header)
check("f64.csv", d, uniform(min(d), max(d)), 17)
assert any(len(r.split(",")[0]) > 12 for r in open("f64.csv").read().splitlines()[1:])  # 17 digits printed
d32 = [f32(x) for x in d]
iso32 = []
for x in uniform(min(d32), max(d32)):
    if not iso32 or iso32[-1] < f32(x):
        iso32.append(f32(x))
check("f64as32.csv", d32, iso32, 9)
PY
expect 0 'streamed, mmap' -- "$bin" -q fd w_9x8x7_int32.raw --stream --csv w_stream.csv
cmp -s w.csv w_stream.csv && pass || fail "int32 streamed CSV differs from the in-core CSV"
expect 0 'mean FD' -- "$bin" -q fd w_9x8x7_int32.raw --isovalues -2147483648:2147483647:1073741823.5 --csv w_list.csv
[ "$(wc -l < w_list.csv)" -eq 6 ] && pass || fail "int32 float64 isovalue range rows: $(wc -l < w_list.csv)"
expect 0 'float64' -- "$bin" -q filter f64.nrrd --median -o f64_median.nrrd
expect 0 'float64' -- "$bin" info f64_median.nrrd
expect 0 'compared as float64' -- "$bin" -q local f64.nrrd --iso 1.2 --window 4 -o f64_ld.nrrd
expect 0 'int32' -- "$bin" -q smooth w_9x8x7_int32.raw --iso 0.5 --threshold 2.2 -o w_smooth.nrrd
expect 0 'every isovalue equals' -- "$bin" -q components f64.nrrd --bins 16 --verify
expect 2 "clfractal: error: unknown value type 'int64'" -- "$bin" fd f64.nrrd --as int64
head -c 64 /dev/zero > z_2x2x2_int64.raw
expect 2 "clfractal: error: .*z_2x2x2_int64.raw.*unknown value type 'int64'" -- "$bin" fd z_2x2x2_int64.raw

# fd4: the 4D dimension as text and JSON; for integer data with q = 1, I4(G, 1) is the sum of
# the span curve plus the cubes (docs/definitions.md §24). local4: the LD4 field. filter
# --fractal4.
expect 0 'D4 +3\.' -- "$bin" -q fd4 synthetic:sphere:20 --json fd4.json
expect 0 'mean FD' -- "$bin" -q fd synthetic:sphere:20 --csv fd4_curve.csv
python3 - <<'PY' && pass || fail "fd4 json fields / identity"
import json, math
j = json.load(open("fd4.json"))
for k in ["volume", "dims", "type", "q", "i4_l0", "i4_l1", "d4"]:
    assert k in j, k
assert j["dims"] == [20, 20, 20] and j["type"] == "uint8" and j["q"] == 1
counts = sum(int(r.split(",")[1]) for r in open("fd4_curve.csv").read().splitlines()[1:])
assert j["i4_l0"] == counts + 19 ** 3, (j["i4_l0"], counts)
assert abs(j["d4"] - math.log2(j["i4_l0"] / j["i4_l1"])) < 1e-12
PY
expect 0 'D4 +' -- "$bin" -q fd4 synthetic:marschner-lobb:24 --q 0.01
expect 2 'clfractal: error: .*--q' -- "$bin" fd4 synthetic:sphere:20 --q -1
expect 2 'clfractal: error: .*--q' -- "$bin" fd4 synthetic:sphere:20 --q 0
expect 2 'clfractal: error: .*--q' -- "$bin" fd4 synthetic:sphere:20 --q abc
expect 2 'clfractal: error: .*--q 1e-300.*too small' -- "$bin" fd4 synthetic:sphere:20 --q 1e-300
expect 2 'clfractal: error: .*no_such.nrrd' -- "$bin" fd4 no_such.nrrd
expect 0 'mean LD4 +3\.' -- "$bin" -q local4 synthetic:noisy-sphere:24 --window 6 -o ld4.nrrd
expect 0 'float32' -- "$bin" info ld4.nrrd
expect 2 'clfractal: error: .*--window' -- "$bin" local4 synthetic:sphere:20 --window 5 -o bad.nrrd
[ ! -e bad.nrrd ] && pass || fail "local4 with a bad window wrote a file"
expect 2 'clfractal: error: .*--q' -- "$bin" local4 synthetic:sphere:20 --q -2 -o bad.nrrd
expect 0 'with LD4 > 3.5' -- "$bin" -q filter synthetic:noisy-sphere:24 --median --fractal4 --threshold 3.5 --iso 128 -o f4.nrrd
expect 2 'clfractal: error: .*--fractal4 needs --threshold' -- "$bin" filter synthetic:sphere:20 --median --fractal4 -o f4.nrrd
expect 2 'clfractal: error: .*--q: only with --fractal4' -- "$bin" filter synthetic:sphere:20 --median --q 2 -o f4.nrrd
expect 2 'clfractal: error: .*exclude each other' -- "$bin" filter synthetic:sphere:20 --median --fractal4 --fractal --iso 3 --threshold 3 -o f4.nrrd

# Outputs: a symlink keeps its link, a FIFO feeds its reader, "-" is stdout, every output
# is checked before any work, and a failed run leaves nothing behind.
mkdir -p out_target && rm -f out_link.csv && ln -s out_target/real.csv out_link.csv
expect 0 'mean FD' -- "$bin" -q fd synthetic:sphere:20 --csv out_link.csv
[ -L out_link.csv ] && [ "$(head -1 out_target/real.csv)" = "isovalue,count,count_sub,fd" ] && pass || fail "symlinked output lost its link"
expect 0 'mean FD' -- "$bin" -q fd synthetic:sphere:20 --csv out_link.csv --json out_link_check.json
[ -L out_link.csv ] && [ -z "$(ls out_target | grep tmp)" ] && pass || fail "second write through the symlink"
rm -f out.fifo && mkfifo out.fifo
(head -1 < out.fifo > fifo_first_line.txt) &
reader=$!
expect 0 'mean FD' -- "$bin" -q fd synthetic:sphere:20 --csv out.fifo
wait $reader
[ -p out.fifo ] && [ "$(cat fifo_first_line.txt)" = "isovalue,count,count_sub,fd" ] && pass || fail "FIFO output: $(cat fifo_first_line.txt)"
out=$("$bin" -q fd synthetic:sphere:20 --csv - 2>/dev/null)
[ "$(head -1 <<<"$out")" = "isovalue,count,count_sub,fd" ] && [ ! -e ./- ] && pass || fail "--csv - is not stdout: $(head -2 <<<"$out")"
"$bin" -q fd synthetic:sphere:20 --csv - 2>&1 >/dev/null | grep -q 'mean FD' && pass || fail "--csv -: the report is not on stderr"
expect 2 'clfractal: error: no_dir/p.png: cannot write: folder .no_dir. does not exist' -- "$bin" -q fd synthetic:sphere:20 --csv nb.csv --json nb.json --plot no_dir/p.png
[ ! -e nb.csv ] && [ ! -e nb.json ] && pass || fail "a failed run left outputs behind"
expect 2 'clfractal: error: .*named as two outputs' -- "$bin" -q fd synthetic:sphere:20 --csv same.csv --json same.csv
expect 2 'clfractal: error: out_target: cannot write: is a folder' -- "$bin" -q local synthetic:sphere:20 --iso 100 -o out_target
expect 2 'clfractal: error: no_dir/m.ply: cannot write' -- "$bin" -q local synthetic:sphere:20 --iso 100 -o ok_ld.nrrd --mesh no_dir/m.ply
[ ! -e ok_ld.nrrd ] && pass || fail "local -o written although --mesh cannot be"
# A failed input leaves no output and no temporary.
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\nabc' > out_cut.nrrd
expect 2 'clfractal: error: out_cut.nrrd: truncated' -- "$bin" -q fd out_cut.nrrd --csv cut.csv --json cut.json
[ -z "$(ls | grep -E '^cut\.|tmp-')" ] && pass || fail "outputs or temporaries left: $(ls | grep -E '^cut\.|tmp-')"
# Stopped by SIGTERM while writing: the temporary is removed.
"$bin" -q local synthetic:noisy-sphere:320 --iso 128 -o term.nrrd --stream >/dev/null 2>&1 &
writer=$!
seen=0
for i in $(seq 1 200); do
  if ls | grep -q '^term\.nrrd\.tmp-'; then seen=1; kill -TERM $writer; break; fi
  sleep 0.1
done
wait $writer
[ $seen -eq 1 ] && [ -z "$(ls | grep '^term\.nrrd')" ] && pass || fail "SIGTERM: seen=$seen, left: $(ls | grep '^term')"
"$bin" -q local synthetic:sphere:20 --iso 100 -o - --stream > ld_stdout.nrrd 2>/dev/null && pass || fail "local -o - --stream"
"$bin" -q local synthetic:sphere:20 --iso 100 -o - > ld_stdout2.nrrd 2>/dev/null && pass || fail "local -o -"
for f in ld_stdout.nrrd ld_stdout2.nrrd; do
  [ "$(head -c 4 $f)" = "NRRD" ] && [ "$(stat -c %s $f)" -gt 32000 ] && pass || fail "$f: not the LD NRRD"
done

# A volume's name reaches gnuplot's titles as text only: a backquoted command in it is not
# run, a newline in it does not end the title's command.
"$bin" -q gen sphere --size 12 -o plain.nrrd
evil=$'x`touch injected.mark`\ny.nrrd'
cp plain.nrrd "$evil"
for sub in "fd --plot evil_fd.png" "components --plot evil_c.png" "mesh --iso 100 -o evil.ply --preview evil_m.png"; do
  rm -f injected.mark
  "$bin" -q ${sub%% *} "$evil" ${sub#* } > /dev/null 2> evil.err && [ ! -e injected.mark ] && [ ! -s evil.err ] &&
    pass || fail "gnuplot title from the name ($sub): $(ls injected.mark 2>/dev/null) $(head -c 300 evil.err)"
done

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
