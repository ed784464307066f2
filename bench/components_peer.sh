#!/usr/bin/env bash
# The component curve end to end: `clfractal components FILE` (process wall), and Wenger's
# `ijkscalarinfo -components` on the same data when it is installed, interleaved A B A B,
# medians; then both curves are compared count for count (ijkscalarinfo's row t counts the
# crossings of [t, t+1), clfractal's isovalue t+1).
# ijkscalarinfo is not a Debian package. It builds from github.com/isojenkode/ijk (LGPL; v0.6.0
# at commit fe430f8, and as it is at 9d37798): src/ijkscalarinfo/ijkscalarinfo.cpp with include/ (ijk.tpp and the grid,
# coord, cube, contour-tree, data-table, interpolate, print and nrrd templates), against teem:
#   printf '#include <teem/nrrd.h>\n' > shim/NrrdIO.h
#   g++ -O3 -march=native -std=c++20 -Iinclude -Ishim src/ijkscalarinfo/ijkscalarinfo.cpp \
#     -o bin/ijkscalarinfo -lteem -lz
#
#   bench/components_peer.sh [--build DIR] [--volume F] [--ijk PATH] [--runs R]
#
# Default: build/, ../shared/data/bonsai_256x256x256_uint8.raw, R = 5. ijkscalarinfo reads
# NRRD: a raw volume named NAME_XxYxZ_TYPE.raw gets a detached header (.nhdr) naming it, in
# the work folder; clfractal reads the raw file itself.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=build volume=$here/../shared/data/bonsai_256x256x256_uint8.raw ijk=$(command -v ijkscalarinfo || true) runs=5
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --volume) volume=$2; shift 2 ;;
    --ijk) ijk=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--volume F] [--ijk PATH] [--runs R]" >&2; exit 2 ;;
  esac
done
[ -e "$volume" ] || { echo "components_peer: $volume is missing" >&2; exit 2; }
clf=$build/clfractal work=${TMPDIR:-/tmp}/clfractal-bench
mkdir -p "$work"
timed() { /usr/bin/time -f "%e" -o "$work/time.txt" "$@" >/dev/null 2>"$work/stderr.txt" || {
  cat "$work/stderr.txt" >&2; exit 1; }; cat "$work/time.txt"; }
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
peer_volume=$volume
if [[ -n "$ijk" && $volume =~ _([0-9]+)x([0-9]+)x([0-9]+)_([a-z0-9]+)\.raw$ ]]; then
  peer_volume=$work/peer_volume.nhdr
  printf 'NRRD0004\ntype: %s\ndimension: 3\nsizes: %s %s %s\nendian: little\nencoding: raw\ndata file: %s\n' \
    "${BASH_REMATCH[4]}" "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" "${BASH_REMATCH[3]}" "$(realpath "$volume")" > "$peer_volume"
fi
declare -a ours peer
for ((i = 0; i < runs; i++)); do
  ours+=("$(timed "$clf" -q components "$volume" --csv "$work/components.csv")")
  [ -z "$ijk" ] || peer+=("$(timed "$ijk" -components "$peer_volume")")
done
echo "volume                  $volume, $runs runs, interleaved"
echo "clfractal components    wall ${ours[*]} s (median $(median "${ours[@]}"))"
if [ -n "$ijk" ]; then
  echo "ijkscalarinfo           wall ${peer[*]} s (median $(median "${peer[@]}"))"
  awk -v a="$(median "${ours[@]}")" -v b="$(median "${peer[@]}")" 'BEGIN { printf "ijkscalarinfo / clfractal: %.1fx\n", b / a }'
  (cd "$work" && rm -f ./*.num_components.gplt && "$ijk" -components -plot "$peer_volume" >/dev/null)
  awk -F'[ ,]+' 'FNR == 1 { file++; next } file == 1 { ijk[$1 + 1] = $2; next }
    ($1 in ijk) { n++; if (ijk[$1] != $2) { bad++; if (bad <= 5) print "  differs at isovalue " $1 ": " ijk[$1] " vs " $2 } }
    END { printf "counts: %d isovalues compared, %d differ\n", n, bad; exit (n == 0 || bad > 0) }' \
    "$work"/*.num_components.gplt "$work/components.csv"
else
  echo "ijkscalarinfo           not installed (pass --ijk PATH): clfractal only"
fi
