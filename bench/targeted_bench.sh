#!/usr/bin/env bash
# The fractal-targeted median against the full median on a real volume, interleaved A B A B:
# `clfractal filter --json` compute times (seconds_compute: no file I/O, no compilation) and
# their parts, medians of the runs; the ratio of the medians and the median of the ratios of
# the interleaved pairs (steadier on a loaded machine).
#
#   bench/targeted_bench.sh [--build DIR] [--volume F] [--iso S] [--threshold H] [--runs R]
#
# Default: build/, ../shared/data/seg3d_mr_160x232x160_uint8.raw (an MRI head), iso 60,
# h = 2.5, R = 5.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=build volume=$here/../shared/data/seg3d_mr_160x232x160_uint8.raw iso=60 threshold=2.5 runs=5
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --volume) volume=$2; shift 2 ;;
    --iso) iso=$2; shift 2 ;;
    --threshold) threshold=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--volume F] [--iso S] [--threshold H] [--runs R]" >&2; exit 2 ;;
  esac
done
[ -e "$volume" ] || { echo "targeted_bench: $volume is missing" >&2; exit 2; }
clf=$build/clfractal work=${TMPDIR:-/tmp}/clfractal-bench
mkdir -p "$work"
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }
declare -a full targeted ld filt
for ((i = 0; i < runs; i++)); do
  "$clf" -q filter "$volume" --median -o "$work/full.nrrd" --json "$work/full.json" >/dev/null
  full+=("$(field "$work/full.json" seconds_compute)")
  "$clf" -q filter "$volume" --median --fractal --iso "$iso" --threshold "$threshold" -o "$work/targeted.nrrd" \
    --json "$work/targeted.json" >/dev/null
  targeted+=("$(field "$work/targeted.json" seconds_compute)")
  ld+=("$(field "$work/targeted.json" seconds_ld)")
  filt+=("$(field "$work/targeted.json" seconds_filter)")
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
mf=$(median "${full[@]}") mt=$(median "${targeted[@]}")
echo "volume           $volume, iso $iso, h $threshold, $runs runs each, interleaved"
echo "full median      seconds_compute ${full[*]} (median $mf)"
echo "targeted median  seconds_compute ${targeted[*]} (median $mt; LD $(median "${ld[@]}"), masked filter $(median "${filt[@]}"))"
echo "selected $(field "$work/targeted.json" fraction_selected), changed $(field "$work/targeted.json" fraction_changed)"
pairs=()
for ((i = 0; i < runs; i++)); do pairs+=("$(awk -v a="${targeted[i]}" -v b="${full[i]}" 'BEGIN { print a / b }')"); done
awk -v a="$mt" -v b="$mf" -v p="$(median "${pairs[@]}")" \
  'BEGIN { printf "targeted / full: %.2f (median of the pairs %.2f; target <= 0.5)\n", a / b, p }'
