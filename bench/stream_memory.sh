#!/usr/bin/env bash
# Peak resident memory of `clfractal fd --stream` on a generated uint16 volume with a wide
# value range (every integer isovalue counted), as the file grows: the first N/4, N/2 and
# all N slices of one N^3 noisy sphere, each run alone under /usr/bin/time. A streamed run
# must stay within the bound whatever the number of batches and isovalues (exit 1 when a
# run fails or passes it). With --form-only the bound is printed but not judged (exit 1 only
# when a run fails or its peak cannot be read): the smoke test in ctest, where a cold program
# cache or a loaded machine moves the absolute peak.
#
#   bench/stream_memory.sh [--build DIR] [--size N] [--noise MU] [--limit MIB] [--work DIR] [--form-only]
#
# Default: build/, N = 640, MU = 60000 (values 0 .. 60000: 60001 isovalues), 512 MiB, the
# volume generated (clfractal gen) into /tmp/clfractal-bench when missing; the shallower
# files are raw copies of its first slices.
set -euo pipefail
build=build size=640 noise=60000 limit=512 work=${TMPDIR:-/tmp}/clfractal-bench judge=1
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --noise) noise=$2; shift 2 ;;
    --limit) limit=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --form-only) judge=0; shift ;;
    *) echo "usage: $0 [--build DIR] [--size N] [--noise MU] [--limit MIB] [--work DIR] [--form-only]" >&2; exit 2 ;;
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
  if ! [[ "$kib" =~ ^[0-9]+$ ]] || [ "$kib" -le 0 ]; then
    echo "stream_memory: no peak read for $file" >&2
    exit 1
  fi
  mib=$((kib / 1024))
  slabs=$(sed -n 's/^time .*(streamed, [a-z]*, \([0-9]*\) slabs*).*/\1/p' "$work/out.txt")
  isovalues=$(awk '$1 == "isovalues" {print $2}' "$work/out.txt")
  ok=yes
  if [ "$mib" -gt "$limit" ]; then
    if [ "$judge" = 1 ]; then ok=NO failed=1; else ok="over (not judged)"; fi
  fi
  printf '%-22s %10d %8s %9s %10.2f %8s  %s\n' "${size}x${size}x$nz" "$mib" "$slabs" "$isovalues" \
    "$(awk -v k="$kib" -v b="$((nz * slice))" 'BEGIN {print k * 1024 / b}')" "$wall" "$ok"
done
exit $failed
