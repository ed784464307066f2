#!/usr/bin/env bash
# End to end: `clfractal fd FILE` and `clfractal fd FILE --stream` against bench/fd_peer_omp
# (a plain OpenMP program that reads the file and counts levels 0 and 1 once), interleaved
# A B C A B C, on a hot uint8 file; process wall time and peak RSS from /usr/bin/time, medians
# of the runs; the programs' counts must be equal (exit 1 otherwise). Then fd's own account of
# its work from its JSON (medians): the value range and isovalue histogram, the counting, the
# component labelling of its entries and the whole analysis, which the peer does not do but
# the counting.
#
#   bench/fd_bench.sh [--build DIR] [--size N] [--runs R] [--file F.nrrd]
#
# Default: build/, N = 768, R = 5, the file generated (noisy sphere, clfractal gen) into
# /tmp/clfractal-bench/noisy_sphere_N.nrrd when missing.
set -euo pipefail
build=build size=768 runs=5 file=
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --file) file=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--size N] [--runs R] [--file F.nrrd]" >&2; exit 2 ;;
  esac
done
clf=$build/clfractal peer=$build/fd_peer_omp
work=${TMPDIR:-/tmp}/clfractal-bench
mkdir -p "$work"
if [ -z "$file" ]; then
  file=$work/noisy_sphere_$size.nrrd
  [ -f "$file" ] || "$clf" gen noisy-sphere --size "$size" --noise 8 -o "$file" >/dev/null
fi
bytes=$(stat -c %s "$file")
cat "$file" >/dev/null  # hot: in the page cache
# One timed run: prints "wall_s rss_kib".
timed() { /usr/bin/time -f "%e %M" -o "$work/time.txt" "$@" >/dev/null 2>"$work/stderr.txt" || {
  cat "$work/stderr.txt" >&2; exit 1; }; cat "$work/time.txt"; }
# fd's JSON: seconds_prepare seconds_compute seconds_components seconds_analysis
parts() { python3 -c 'import json, sys; j = json.load(open(sys.argv[1]))
print(j["seconds_prepare"], j["seconds_compute"], j["seconds_components"], j["seconds_analysis"])' "$1"; }
declare -a cw cr sw sr pw pr jp jc jl ja
for ((i = 0; i < runs; i++)); do
  read -r w r < <(timed "$clf" fd "$file" --csv "$work/clfractal.csv" --json "$work/clfractal.json"); cw+=("$w"); cr+=("$r")
  read -r p c l a < <(parts "$work/clfractal.json"); jp+=("$p"); jc+=("$c"); jl+=("$l"); ja+=("$a")
  read -r w r < <(timed "$clf" fd "$file" --stream --csv "$work/stream.csv"); sw+=("$w"); sr+=("$r")
  read -r w r < <(timed "$peer" "$file" --csv "$work/peer.csv"); pw+=("$w"); pr+=("$r")
done
# The counts of both programs, isovalue by isovalue.
cut -d, -f1-3 "$work/clfractal.csv" | tail -n +2 > "$work/a.txt"
tail -n +2 "$work/peer.csv" > "$work/b.txt"
if ! cmp -s "$work/a.txt" "$work/b.txt"; then echo "fd_bench: the counts differ" >&2; exit 1; fi
if ! cmp -s "$work/clfractal.csv" "$work/stream.csv"; then echo "fd_bench: fd --stream's CSV differs from fd's" >&2; exit 1; fi
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
mcw=$(median "${cw[@]}") mcr=$(median "${cr[@]}") msw=$(median "${sw[@]}") msr=$(median "${sr[@]}")
mpw=$(median "${pw[@]}") mpr=$(median "${pr[@]}")
echo "file               $file ($bytes bytes), $runs runs each, interleaved; counts equal"
echo "clfractal fd       wall ${cw[*]} s (median $mcw), peak RSS median $((mcr / 1024)) MiB"
echo "clfractal --stream wall ${sw[*]} s (median $msw), peak RSS median $((msr / 1024)) MiB"
echo "fd_peer_omp        wall ${pw[*]} s (median $mpw), peak RSS median $((mpr / 1024)) MiB"
awk -v a="$mcw" -v s="$msw" -v b="$mpw" -v r="$mcr" -v q="$msr" -v f="$bytes" 'BEGIN {
  printf "peer / clfractal wall: fd %.2fx, fd --stream %.2fx (>= 1: clfractal at least as fast)\n", b / a, b / s
  printf "peak RSS: fd %.2fx the file, fd --stream %d MiB\n", r * 1024 / f, q / 1024 }'
printf 'fd from its JSON, medians: value range and histogram %.3f s, counting %.3f s, components of its entries %.3f s; analysis in all %.3f s\n' \
  "$(median "${jp[@]}")" "$(median "${jc[@]}")" "$(median "${jl[@]}")" "$(median "${ja[@]}")"
