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

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
