#!/usr/bin/env bash
# clfractal-mpi with 2 and 3 ranks gives exactly the single-process `clfractal fd` CSV,
# `clfractal-mpi fd --json` on 1 to 4 ranks the analysis of `clfractal fd --stream --json`, and
# `clfractal-mpi components` exactly the `clfractal components` CSV and JSON.
# Usage: mpi_test.sh MPIEXEC CLFRACTAL_MPI CLFRACTAL WORKDIR [SHARED_DATA]
set -u
mpiexec=$1
mpi=$2
bin=$3
work=$4
data=${5:-}
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
failures=0
check() {  # check NP ARGS...: the CSVs of NP ranks and of one process are identical
  local np=$1
  shift
  if ! "$mpiexec" --allow-run-as-root --oversubscribe -np "$np" "$mpi" "$@" --csv mpi.csv >mpi.out 2>&1; then
    echo "FAIL: mpirun -np $np $*: $(cat mpi.out)"; failures=$((failures + 1)); return
  fi
  "$bin" -q fd "$@" --csv one.csv >/dev/null
  if ! cmp -s mpi.csv one.csv; then
    echo "FAIL: -np $np $* differs from one process"; diff mpi.csv one.csv | head -5; failures=$((failures + 1))
  else
    echo "ok: -np $np $*"
  fi
}
check_components() {  # check_components NP ARGS...: as check, for the component curve (CSV and JSON)
  local np=$1
  shift
  rm -f mpi.csv mpi.json one.csv one.json
  if ! "$mpiexec" --allow-run-as-root --oversubscribe -np "$np" "$mpi" components "$@" --csv mpi.csv --json mpi.json \
      >mpi.out 2>&1; then
    echo "FAIL: mpirun -np $np components $*: $(cat mpi.out)"; failures=$((failures + 1)); return
  fi
  "$bin" -q components "$@" --csv one.csv --json one.json >/dev/null
  if ! cmp -s mpi.csv one.csv || ! cmp -s mpi.json one.json; then
    echo "FAIL: -np $np components $* differs from one process"; diff mpi.csv one.csv | head -5
    diff mpi.json one.json | head -5
    failures=$((failures + 1))
  else
    echo "ok: -np $np components $*"
  fi
}
check_fd_json() {  # check_fd_json NP ARGS...: the analysis JSON of NP ranks equals `fd --stream --json`'s
  local np=$1
  shift
  rm -f mpi.json one.json
  if ! "$mpiexec" --allow-run-as-root --oversubscribe -np "$np" "$mpi" fd "$@" --json mpi.json >mpi.out 2>&1; then
    echo "FAIL: mpirun -np $np fd $*: $(cat mpi.out)"; failures=$((failures + 1)); return
  fi
  "$bin" -q fd --stream "$@" --json one.json >/dev/null
  # The facts of one run (device, times, slabs, ranks) apart, byte for byte.
  if ! /usr/bin/python3 - mpi.json one.json <<'PY'
import json, sys
run = {"device", "slabs", "ranks", "parts"}
def analysis(path):
    j = json.load(open(path))
    assert j["recommended"], path + ": no recommendation to compare"
    assert all("components" in e for e in j["recommended"]), path + ": a recommendation without components"
    return json.dumps({k: v for k, v in j.items() if k not in run and not k.startswith("seconds")}, indent=1)
a, b = analysis(sys.argv[1]), analysis(sys.argv[2])
if a != b:
    import difflib
    print("".join(list(difflib.unified_diff(a.splitlines(1), b.splitlines(1)))[:12]))
    sys.exit(1)
PY
  then
    echo "FAIL: -np $np fd $* --json differs from fd --stream --json"; failures=$((failures + 1))
  else
    echo "ok: -np $np fd $* --json"
  fi
}
check 2 synthetic:noisy-sphere:48
check 3 synthetic:noisy-sphere:37 --edge --levels 3
check 2 synthetic:marschner-lobb:41 --levels 3
check 3 synthetic:torus:5
# Files: each rank reads only its own z-part (raw NRRD through mmap, gzip NRRD decompressed up to it).
"$bin" -q gen marschner-lobb --size 45 --type uint16 -o ml.nrrd >/dev/null
check 3 ml.nrrd --levels 3
/usr/bin/python3 - <<'PY'
import gzip
raw = open("ml.nrrd", "rb").read()
head, data = raw.split(b"\n\n", 1)
head = head.replace(b"encoding: raw", b"encoding: gzip")
open("ml_gz.nrrd", "wb").write(head + b"\n\n" + gzip.compress(data))
PY
check 2 ml_gz.nrrd --edge
# fd's analysis (recommendations and their components, bands, skipped ladder) from 1 to 4 ranks.
for np in 1 2 3 4; do check_fd_json $np synthetic:noisy-sphere:40; done
check_fd_json 3 ml.nrrd --levels 3
check_fd_json 2 synthetic:marschner-lobb:33 --bins 64 --clean-fd 2.1
check_components 1 synthetic:noisy-sphere:30
check_components 2 synthetic:noisy-sphere:30
check_components 4 synthetic:noisy-sphere:30 --isovalues 100:102:1
# The plot (gnuplot draws it from the curve and the cube counts, which ranks count in parts):
# the same PNG from 1 to 4 ranks as from one process.
if command -v gnuplot >/dev/null; then
  "$bin" -q components synthetic:noisy-sphere:29 --plot one.png >/dev/null
  for np in 1 2 3 4; do
    rm -f mpi.png
    if "$mpiexec" --allow-run-as-root --oversubscribe -np "$np" "$mpi" components synthetic:noisy-sphere:29 \
        --plot mpi.png >mpi.out 2>&1 && [ -s one.png ] && cmp -s mpi.png one.png; then
      echo "ok: -np $np components --plot"
    else
      echo "FAIL: -np $np components --plot differs from one process: $(cat mpi.out)"; failures=$((failures + 1))
    fi
  done
else
  echo "no gnuplot: the plots are not compared"
fi
check_components 3 synthetic:noisy-sphere:30 --connectivity freudenthal
check_components 3 ml.nrrd
# More ranks than a 3-slice volume has parts (two): the others count nothing.
check_components 3 synthetic:torus:3
if [ -n "$data" ] && [ -f "$data/MANIFEST.tsv" ]; then
  check 2 "$data/fuel_cropped_64x33x32_uint8.raw" --edge
  check 2 "$data/hydrogen_3d_orbital_64x64x64_float32.raw" --levels 3
  check 3 "$(ls "$data"/*_uint16.raw | head -1)" --levels 3
  check_components 2 "$data/fuel_cropped_64x33x32_uint8.raw"
  check_fd_json 3 "$data/fuel_cropped_64x33x32_uint8.raw"
  check_fd_json 2 "$data/hydrogen_3d_orbital_64x64x64_float32.raw"
  check_fd_json 4 "$(ls "$data"/*_uint16.raw | head -1)"
  check_components 3 "$data/fuel_cropped_64x33x32_uint8.raw" --connectivity freudenthal
  check_components 3 "$data/hydrogen_3d_orbital_64x64x64_float32.raw" --bins 100
  check_components 2 "$(ls "$data"/*_uint16.raw | head -1)"
else
  echo "no shared data: real volumes skipped"
fi
# Bad input: exit 2 with one error line, from rank 0 only.
"$mpiexec" --allow-run-as-root --oversubscribe -np 2 "$mpi" /nonexistent.nrrd >err.out 2>&1
rc=$?
if [ "$rc" -ne 2 ] || [ "$(grep -c 'clfractal-mpi: error: /nonexistent.nrrd' err.out)" -ne 1 ]; then
  echo "FAIL: bad input: exit $rc: $(cat err.out)"; failures=$((failures + 1))
fi
# Components of a volume larger than the nodes have room for: one error line naming the file
# and the size, exit 2, before any read, no CSV written.
rm -f big.csv
CLFRACTAL_MEMORY_LIMIT=300M "$mpiexec" --allow-run-as-root --oversubscribe -np 3 -x CLFRACTAL_MEMORY_LIMIT \
  "$mpi" components ml.nrrd --csv big.csv >err.out 2>&1
rc=$?
if [ "$rc" -ne 2 ] || [ "$(grep -c 'clfractal-mpi: error: ml.nrrd: clfractal-mpi components needs about' err.out)" -ne 1 ] ||
   [ -e big.csv ]; then
  echo "FAIL: memory check: exit $rc: $(cat err.out)"; failures=$((failures + 1))
else
  echo "ok: components beyond the memory limit refused before work (exit 2)"
fi
# fd's analysis on nodes without the room for the recommendations' components: the curve and
# its analysis all the same, the components null and `skipped` saying why.
rm -f small.json
if CLFRACTAL_MEMORY_LIMIT=300M "$mpiexec" --allow-run-as-root --oversubscribe -np 3 -x CLFRACTAL_MEMORY_LIMIT \
    "$mpi" fd ml.nrrd --json small.json >err.out 2>&1 && /usr/bin/python3 - small.json <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["recommended"] and all(e["components"] is None for e in j["recommended"]), j["recommended"]
assert any(s.startswith("components: ml.nrrd: clfractal-mpi fd's components needs about") for s in j["skipped"]), j["skipped"]
PY
then
  echo "ok: fd without room for the components: the analysis, components skipped"
else
  echo "FAIL: fd beyond the memory limit: $(cat err.out)"; failures=$((failures + 1))
fi
[ "$failures" -eq 0 ]
