#!/usr/bin/env bash
# A longer fuzz campaign than ctest's: each libFuzzer target for SECONDS, from the seed corpus
# in fuzz/corpus/<target> plus what earlier runs kept in BUILD/fuzz-corpus/<target>, at the
# lowest priority. Prints per target the CPU seconds, executions, corpus size and findings
# (crash, leak, timeout or out-of-memory inputs, saved in BUILD/fuzz-findings/<target>/);
# exits 1 if there is any finding. FUZZ_NICE sets the niceness (19 by default).
# Usage: bench/fuzz_campaign.sh [BUILD_DIR (build-fuzz)] [SECONDS per target (600)] [TARGET...]
# The build: CC=clang-14 CXX=clang++-14 cmake -S . -B build-fuzz -DCLFRACTAL_FUZZ=ON
#            cmake --build build-fuzz --target nrrd_fuzz raw_name_fuzz capi_fuzz nifti_fuzz dicom_fuzz \
#              tiff_fuzz metaimage_fuzz detect_fuzz
set -u
cd "$(dirname "$0")/.."
build=${1:-build-fuzz}
seconds=${2:-600}
shift $(( $# < 2 ? $# : 2 ))
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(nrrd raw_name capi nifti dicom tiff metaimage detect components)
total_cpu=0 total_execs=0 total_findings=0
printf '%-10s %10s %14s %8s %9s\n' target cpu_s executions corpus findings
for t in "${targets[@]}"; do
  bin=$build/fuzz/${t}_fuzz
  [ -x "$bin" ] || { echo "$bin: not built (see the usage above)" >&2; exit 2; }
  mkdir -p "$build/fuzz-corpus/$t" "$build/fuzz-findings/$t"
  log=$build/fuzz-findings/$t.log
  TIMEFORMAT='%U %S'
  cpu=$( { time ASAN_OPTIONS=allocator_may_return_null=1 nice -n "${FUZZ_NICE:-19}" "$bin" -max_total_time="$seconds" -timeout=20 \
      -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/fuzz-findings/$t/" \
      "$build/fuzz-corpus/$t" "fuzz/corpus/$t" >"$log" 2>&1; } 2>&1 | awk '{printf "%.0f", $1 + $2}')
  execs=$(awk '/stat::number_of_executed_units/ {print $2}' "$log")
  findings=$(find "$build/fuzz-findings/$t" -type f | wc -l)
  corpus=$(find "$build/fuzz-corpus/$t" -type f | wc -l)
  printf '%-10s %10s %14s %8s %9s\n' "$t" "$cpu" "${execs:-0}" "$corpus" "$findings"
  total_cpu=$((total_cpu + cpu)) total_execs=$((total_execs + ${execs:-0})) total_findings=$((total_findings + findings))
done
printf '%-10s %10s %14s %8s %9s\n' total "$total_cpu" "$total_execs" "" "$total_findings"
[ "$total_findings" -eq 0 ]
