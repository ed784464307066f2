#!/usr/bin/env bash
# Every subcommand on a second OpenCL implementation: Oclgrind, a simulated GPU-type device
# (1 compute unit, 128 MiB, small local memory) that checks every kernel for data races,
# invalid memory accesses and barrier misuse. With only Oclgrind registered, each command
# must exit 0, Oclgrind must report nothing, and stdout and every output file must equal
# what PoCL (the CPU device) writes, apart from the device and time lines.
# Usage: oclgrind_test.sh CLFRACTAL WORKDIR        (exit 77: Oclgrind is not installed)
set -u
bin=$(realpath "$1")
work=$2
icd_lib=/usr/lib/oclgrind/liboclgrind-rt-icd.so
[ -f "$icd_lib" ] || { echo "skip: oclgrind is not installed (setup.sh installs it)"; exit 77; }
rm -rf "$work" && mkdir -p "$work/vendors" "$work/oclgrind" "$work/pocl" || exit 1
echo "$icd_lib" > "$work/vendors/oclgrind.icd"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

v=synthetic:noisy-sphere:20
commands=(
  "devices|devices"
  "info|info $v"
  "fd_box|fd $v --json fd_box.json --csv fd_box.csv"
  "fd_edge|fd $v --edge --levels 3"
  "fd_noise|fd $v --noise-level"
  "local|local $v --iso 100 -o ld.nrrd --mesh ld.ply"
  "local4|local4 $v -o ld4.nrrd"
  "fd4|fd4 $v"
  "median|filter $v --median -o median.nrrd"
  "gaussian|filter $v --gaussian 1.0 -o gaussian.nrrd"
  "targeted|filter $v --median --fractal --iso 100 --threshold 2.2 -o targeted.nrrd"
  "components|components $v --csv components.csv"
  "freudenthal|components $v --connectivity freudenthal"
  "components_at|components $v --isovalues 1:7:1 --csv components_at.csv"
  "smooth|smooth $v --iso 100 --threshold 2.2 -o smooth.nrrd"
  "mesh|mesh $v --iso 100 -o mesh.ply"
  "noise|noise --size 16 --points 3 --mu 0,1"
  "gen|gen sphere --size 16 -o gen.nrrd"
  "report|report $v -o report.html"
)
# Lines that name the device or report times differ between the implementations.
scrub() { grep -vE '^(device|time)\b|compiled in|seconds|"device"|GB/s' "$1"; }
races='[Dd]ata race|Invalid (read|write)|[Dd]ivergence|[Uu]ninitiali[sz]ed|Oclgrind - |out of bounds|barrier'
for entry in "${commands[@]}"; do
  name=${entry%%|*}
  read -r -a args <<< "${entry#*|}"
  start=$(date +%s.%N)
  (cd "$work/oclgrind" && OCL_ICD_VENDORS="$work/vendors" OCLGRIND_DATA_RACES=1 OCLGRIND_CHECK_API=1 \
    CLFRACTAL_DEVICE_TYPE=gpu timeout 600 "$bin" -q "${args[@]}" > "$name.out" 2> "$name.err")
  rc=$?
  seconds=$(echo "$(date +%s.%N) - $start" | bc)
  (cd "$work/pocl" && env -u OCL_ICD_VENDORS CLFRACTAL_DEVICE_TYPE=cpu "$bin" -q "${args[@]}" > "$name.out" 2> "$name.err")
  printf '%-12s exit %d on Oclgrind in %5.1f s\n' "$name" "$rc" "$seconds"
  [ "$rc" -eq 0 ] || fail "$name: exit $rc on Oclgrind: $(tail -3 "$work/oclgrind/$name.err")"
  if grep -Eq "$races" "$work/oclgrind/$name.err"; then
    fail "$name: Oclgrind reports: $(grep -E "$races" "$work/oclgrind/$name.err" | head -3)"
  fi
  [ "$name" = devices ] && continue
  diff -q <(scrub "$work/oclgrind/$name.out") <(scrub "$work/pocl/$name.out") > /dev/null ||
    fail "$name: stdout differs from PoCL's: $(diff <(scrub "$work/oclgrind/$name.out") <(scrub "$work/pocl/$name.out") | head -4)"
done
# Every output file, byte for byte (the report page embeds times and the device: skipped).
for f in "$work/pocl"/*.{nrrd,ply,csv}; do
  [ -e "$f" ] || continue
  cmp -s "$f" "$work/oclgrind/$(basename "$f")" || fail "$(basename "$f") differs from PoCL's"
done
grep -q '^\* Oclgrind' "$work/oclgrind/devices.out" || fail "Oclgrind is not the chosen device: $(cat "$work/oclgrind/devices.out")"
echo "oclgrind: ${#commands[@]} commands, $failures failures"
[ "$failures" -eq 0 ]
