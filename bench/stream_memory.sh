#!/usr/bin/env bash
# Peak resident memory of `clfractal fd --stream` on a generated uint16 volume with a wide
# value range (every integer isovalue counted), as the file grows: the first N/4, N/2 and
# all N slices of one N^3 noisy sphere, each run alone under /usr/bin/time. A streamed run
# must stay within the bound whatever the number of batches and isovalues (exit 1 when a
# run fails or passes it).
#
#   bench/stream_memory.sh [--build DIR] [--size N] [--noise MU] [--limit MIB] [--work DIR]
#
# Default: build/, N = 640, MU = 60000 (values 0 .. 60000: 60001 isovalues), 512 MiB, the
# volume generated (clfractal gen) into /tmp/clfractal-bench when missing; the shallower
# files are raw copies of its first slices.
set -euo pipefail
build=build size=640 noise=60000 limit=512 work=${TMPDIR:-/tmp}/clfractal-bench
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --noise) noise=$2; shift 2 ;;
    --limit) limit=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--size N] [--noise MU] [--limit MIB] [--work DIR]" >&2; exit 2 ;;
  esac
done
clf=$build/clfractal
mkdir -p "$work"
volume=$work/wide_uint16_$size.nrrd
[ -f "$volume" ] || "$clf" -q gen noisy-sphere --size "$size" --noise "$noise" --type uint16 -o "$volume"
slice=$((size * size * 2))
data=$((size * slice))
offset=$(($(stat -c %s "$volume") - data))  # the attached header's bytes
echo "volume     $(basename "$volume") (${size}^3 uint16, noise $noise), bound $limit MiB"
printf '%-22s %10s %8s %9s %10s %8s  %s\n' file MiB slabs isovalues "MiB/file" "wall s" within
failed=0
for nz in $((size / 4)) $((size / 2)) "$size"; do
  if [ "$nz" = "$size" ]; then
    file=$volume
  else
    file=$work/wide_${size}x${size}x${nz}_uint16.raw
    [ -f "$file" ] || dd if="$volume" of="$file" iflag=skip_bytes,count_bytes skip="$offset" count=$((nz * slice)) \
      status=none
  fi
  if ! /usr/bin/time -f "%e %M" -o "$work/time.txt" "$clf" fd "$file" --stream > "$work/out.txt" 2> "$work/err.txt"; then
    cat "$work/err.txt" >&2
    echo "stream_memory: fd --stream failed on $file" >&2
    exit 1
  fi
  read -r wall kib < "$work/time.txt"
  mib=$((kib / 1024))
  slabs=$(sed -n 's/^time .*(streamed, [a-z]*, \([0-9]*\) slabs*).*/\1/p' "$work/out.txt")
  isovalues=$(awk '$1 == "isovalues" {print $2}' "$work/out.txt")
  ok=yes
  if [ "$mib" -gt "$limit" ]; then ok=NO failed=1; fi
  printf '%-22s %10d %8s %9s %10.2f %8s  %s\n' "${size}x${size}x$nz" "$mib" "$slabs" "$isovalues" \
    "$(awk -v k="$kib" -v b="$((nz * slice))" 'BEGIN {print k * 1024 / b}')" "$wall" "$ok"
done
exit $failed
