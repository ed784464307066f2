#!/usr/bin/env bash
# Start-up and end to end on small volumes: `clfractal fd FILE` from process start to exit,
# split into its parts, against bench/fd_peer_omp (a plain OpenMP program that reads the file
# and counts levels 0 and 1 once). Per volume, files hot in the page cache, after one untimed
# run of each program, interleaved R times:
#   clfractal --version                       process start alone (no OpenCL)
#   clfractal devices                         process start and the OpenCL platforms' start-up
#   clfractal fd FILE --csv C --json J        wall and peak RSS; J's seconds_compute (counting),
#                                             seconds_compile and seconds_analysis
#   fd_peer_omp FILE --csv P                  wall and peak RSS
# and once, R times, bench/cl_start (a bare C program that creates an OpenCL context and queue
# on the first device: what any OpenCL program pays before its first byte of work).
# With Wenger's ijkscalarinfo (--ijk PATH, or on PATH; how to build it: bench/components_peer.sh),
# also, interleaved with the others:
#   ijkscalarinfo -box_dim -plot FILE         the same box dimension curve (its table written as
#                                             fd writes its CSV), wall; 8-bit volumes, read
#                                             through a detached NRRD header for raw files
# and its curve must equal fd's to its 4 digits (its row t is fd's isovalue t + 1,
# docs/definitions.md §32; it clamps to [0, 3]), exit 1 otherwise.
# Walls from bash's EPOCHREALTIME around /usr/bin/time (which gives the peak RSS); medians of
# the runs. The rest of fd (read, context, output, exit) is fd's wall less the devices wall
# and the analysis; fd reads its input and computes the value range and isovalue histogram
# while the platform starts (on another thread), so the read counts there only for what
# outlasts the start, and the range and histogram count in seconds_analysis though they
# overlap it. The counts of fd and the peer must be equal (exit 1 otherwise).
#
#   bench/startup_bench.sh [--build DIR] [--runs R] [--data DIR] [--work DIR] [--ijk PATH]
#                          [--volume PATH [--dims XxYxZ] [--type T]]... [--smoke]
#
# Default: build/, R = 5, the uint8 volumes bonsai_256x256x256, engine_256x256x128,
# seg3d_mr_160x232x160 and boston_teapot_256x256x178 of DIR (../shared/data beside the
# repository; one missing is skipped, said so) and a noisy sphere (clfractal gen noisy-sphere
# --size 256 --noise 2) generated into the work folder (/tmp/clfractal-bench/startup) when
# missing. --volume replaces that list (--dims and --type: the raw layout of the --volume
# before them). --smoke: one 32^3 noisy sphere, one run (ctest startup_bench_smoke).
set -euo pipefail
export LC_ALL=C  # EPOCHREALTIME and awk with a decimal point
root=$(cd "$(dirname "$0")/.." && pwd)
build=build runs=5 data=$root/../shared/data work=${TMPDIR:-/tmp}/clfractal-bench/startup smoke=0
ijk=$(command -v ijkscalarinfo || true)
declare -a files=() dims=() types=()
usage() {
  echo "usage: $0 [--build DIR] [--runs R] [--data DIR] [--work DIR] [--ijk PATH]" \
    "[--volume PATH [--dims XxYxZ] [--type T]]..." \
    "[--smoke]" >&2
  exit 2
}
last() { [ ${#files[@]} -gt 0 ] || { echo "startup_bench: $1 before any --volume" >&2; usage; }; }
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --data) data=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --ijk) ijk=$2; shift 2 ;;
    --volume) files+=("$2"); dims+=(""); types+=(""); shift 2 ;;
    --dims) last --dims; dims[${#files[@]} - 1]=$2; shift 2 ;;
    --type) last --type; types[${#files[@]} - 1]=$2; shift 2 ;;
    --smoke) smoke=1; shift ;;
    *) usage ;;
  esac
done
[[ $runs =~ ^[1-9][0-9]*$ ]] || { echo "startup_bench: --runs $runs: a positive integer" >&2; exit 2; }
clf=$build/clfractal peer=$build/fd_peer_omp
for p in "$clf" "$peer" /usr/bin/time; do [ -x "$p" ] || { echo "startup_bench: $p: missing" >&2; exit 2; }; done
mkdir -p "$work"

# The generated noisy sphere of size $1 (uint8), written once into the work folder.
sphere() {
  local f=$work/noisy_sphere_$1_noise2.nrrd
  [ -f "$f" ] || "$clf" -q gen noisy-sphere --size "$1" --noise 2 -o "$f"
  echo "$f"
}
if [ "$smoke" = 1 ]; then
  runs=1 files=("$(sphere 32)") dims=("") types=("")
elif [ ${#files[@]} -eq 0 ]; then
  for name in bonsai_256x256x256 engine_256x256x128 seg3d_mr_160x232x160 boston_teapot_256x256x178; do
    if [ -f "$data/${name}_uint8.raw" ]; then
      files+=("$data/${name}_uint8.raw"); dims+=("${name##*_}"); types+=(uint8)
    else
      echo "skipped    ${name}_uint8.raw: not in $data"
    fi
  done
  files+=("$(sphere 256)"); dims+=(""); types+=("")
fi

# One timed run of "$@": sets wall (seconds, from EPOCHREALTIME) and rss (KiB); exit 1 when
# the program fails.
timed() {
  local t0 t1
  t0=$EPOCHREALTIME
  if ! /usr/bin/time -f %M -o "$work/rss.txt" "$@" > "$work/stdout.txt" 2> "$work/stderr.txt"; then
    cat "$work/stderr.txt" >&2
    echo "startup_bench: failed: $*" >&2
    exit 1
  fi
  t1=$EPOCHREALTIME
  wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f", b - a}')
  rss=$(tail -n 1 "$work/rss.txt")
}
# One timed run of ijkscalarinfo on $1 in $work/ijk, where -plot writes its table.
ijk_run() {
  pushd "$work/ijk" > /dev/null
  timed "$ijk" -box_dim -plot "$1"
  popd > /dev/null
}
# Whether ijkscalarinfo's box dimension table $1 equals fd's CSV $2: its row t against fd's
# isovalue t + 1, to its 4 significant digits, where fd's D is defined and inside (0, 3) (it
# clamps); exit 1 when a row differs or none is compared.
same_curve() {
  python3 - "$1" "$2" <<'PY'
import csv, sys
ijk = {}
for line in open(sys.argv[1]):
    if line.strip() and not line.startswith("#"):
        t, d = line.split()[:2]
        ijk[int(float(t))] = float(d)
compared, differ = 0, []
for r in csv.DictReader(open(sys.argv[2])):
    if not r["fd"]:
        continue
    s, d = int(float(r["isovalue"])), float(r["fd"])
    if not 0 < d < 3:
        continue
    compared += 1
    if s - 1 not in ijk or abs(ijk[s - 1] - d) > 0.00051 * max(1.0, abs(d)):
        differ.append((s, d, ijk.get(s - 1)))
if differ or not compared:
    sys.exit(f"startup_bench: ijkscalarinfo's curve differs from fd's at {len(differ)} of {compared} isovalues "
             f"(isovalue, fd, ijkscalarinfo at isovalue - 1): {differ[:5]}")
print(f"its curve equals fd's at {compared} isovalues (4 digits)")
PY
}
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
# fd's JSON: seconds_analysis seconds_compute seconds_compile, the denoising attempts' seconds
# (their compilation included) and their number.
json_seconds() {
  python3 -c 'import json, sys
j = json.load(open(sys.argv[1]))
a = j["denoise"]["attempts"]
print(j["seconds_analysis"], j["seconds_compute"], j["seconds_compile"], sum(x["seconds"] for x in a), len(a))' "$1"
}
# One line of a volume's table: the part, its median in seconds and its share of fd's wall.
row() { awk -v n="$1" -v s="$2" -v w="$3" -v x="${4:-}" 'BEGIN {printf "  %-62s %8.4f %6.1f%%%s\n", n, s, 100 * s / w, x}'; }

# Measures volume $1 (raw layout: --dims $2 --type $3 when given), prints its table and
# appends its summary line to $work/summary.txt.
measure() {
  local file=$1 raw=() i
  [ -f "$file" ] || { echo "startup_bench: $file: no such file" >&2; exit 2; }
  [ -n "$2" ] && raw+=(--dims "$2")
  [ -n "$3" ] && raw+=(--type "$3")
  cat "$file" > /dev/null  # hot: in the page cache
  timed "$clf" fd "$file" "${raw[@]}"  # untimed warm-up: the program caches, the libraries
  timed "$peer" "$file" "${raw[@]}"
  # ijkscalarinfo's input: the NRRD itself, or a detached header naming the raw 8-bit file.
  local input=
  if [ -n "$ijk" ]; then
    if [[ $file == *.nrrd || $file == *.nhdr ]]; then
      input=$file
    elif [ -n "$2" ] && [ "${3:-uint8}" = uint8 ]; then
      input=$work/ijk/$(basename "${file%.*}").nhdr
      mkdir -p "$work/ijk"
      printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: %s\nencoding: raw\ndata file: %s\n' \
        "${2//x/ }" "$(realpath "$file")" > "$input"
    fi
    mkdir -p "$work/ijk"
    [ -n "$input" ] && ijk_run "$input"  # untimed warm-up
  fi
  local -a vw dw fw fr pw pr an co cm dn kw kr
  local nd=0
  for ((i = 0; i < runs; i++)); do
    timed "$clf" --version; vw+=("$wall")
    timed "$clf" devices; dw+=("$wall")
    timed "$clf" fd "$file" "${raw[@]}" --csv "$work/fd.csv" --json "$work/fd.json"; fw+=("$wall"); fr+=("$rss")
    cp "$work/stdout.txt" "$work/fd.txt"
    read -r a c m d nd < <(json_seconds "$work/fd.json"); an+=("$a"); co+=("$c"); cm+=("$m"); dn+=("$d")
    timed "$peer" "$file" "${raw[@]}" --csv "$work/peer.csv"; pw+=("$wall"); pr+=("$rss")
    if [ -n "$input" ]; then ijk_run "$input"; kw+=("$wall"); kr+=("$rss"); fi
  done
  # The counts of both programs, isovalue by isovalue.
  cut -d, -f1-3 "$work/fd.csv" | tail -n +2 > "$work/a.txt"
  tail -n +2 "$work/peer.csv" > "$work/b.txt"
  if ! cmp -s "$work/a.txt" "$work/b.txt"; then echo "startup_bench: $file: the counts differ" >&2; exit 1; fi
  local v d f a c m p dd
  v=$(median "${vw[@]}") d=$(median "${dw[@]}") f=$(median "${fw[@]}") a=$(median "${an[@]}")
  c=$(median "${co[@]}") m=$(median "${cm[@]}") p=$(median "${pw[@]}") dd=$(median "${dn[@]}")
  local layout
  layout=$(sed -n 's/^volume *[^ ]* *//p' "$work/fd.txt")
  echo
  echo "$(basename "$file"): $layout, $(awk -v b="$(stat -c %s "$file")" 'BEGIN {printf "%.2f", b / 1048576}') MiB," \
    "$(wc -l < "$work/b.txt") isovalues, $runs run(s) interleaved, counts equal"
  printf '  %-62s %8s %7s\n' "median of the runs" "s" "of fd"
  row "clfractal fd (wall, process start to exit)" "$f" "$f" "   peak RSS $(($(median "${fr[@]}") / 1024)) MiB"
  row "  process start (clfractal --version)" "$v" "$f"
  row "  OpenCL platforms (devices - --version)" "$(awk -v d="$d" -v v="$v" 'BEGIN {print d - v}')" "$f"
  row "  counting (seconds_compute)" "$c" "$f"
  row "  kernel compilation (seconds_compile)" "$m" "$f"
  row "  rest of the analysis (seconds_analysis - the two)" "$(awk -v a="$a" -v c="$c" -v m="$m" 'BEGIN {print a - c - m}')" "$f"
  [ "$nd" -gt 0 ] && row "    of which the denoising ladder ($nd attempts)" "$dd" "$f"
  row "  rest: read, context, output, exit (fd - devices - analysis)" \
    "$(awk -v f="$f" -v d="$d" -v a="$a" 'BEGIN {print f - d - a}')" "$f"
  row "fd_peer_omp (wall, process start to exit)" "$p" "$f" "   peak RSS $(($(median "${pr[@]}") / 1024)) MiB"
  echo "  clfractal fd walls ${fw[*]} s; fd_peer_omp walls ${pw[*]} s"
  local k=
  if [ -n "$input" ]; then
    k=$(median "${kw[@]}")
    row "ijkscalarinfo -box_dim -plot (wall, process start to exit)" "$k" "$f" \
      "   peak RSS $(($(median "${kr[@]}") / 1024)) MiB"
    local same
    same=$(same_curve "$work/ijk/$(basename "${input%.*}").box_dim.gplt" "$work/fd.csv") || exit 1
    echo "  ijkscalarinfo walls ${kw[*]} s; $same"
  elif [ -n "$ijk" ]; then
    echo "  ijkscalarinfo: not run (an 8-bit NRRD, or a raw file with --dims and --type uint8)"
  fi
  awk -v n="$(basename "$file")" -v f="$f" -v p="$p" -v k="$k" 'BEGIN {
    printf "%-36s %10.4f %10.4f %9.3fx", n, f, p, p / f
    if (k != "") printf " %10.4f %9.1fx", k, k / f
    printf "\n" }' >> "$work/summary.txt"
}

: > "$work/summary.txt"
echo "clfractal  $("$clf" --version), $(sed -n 's/^\* //p' < <("$clf" devices))"
echo "peer       bench/fd_peer_omp, OMP_NUM_THREADS ${OMP_NUM_THREADS:-unset} ($(nproc) CPUs)"
declare -a bare=()
for ((i = 0; i < runs; i++)); do timed "$build/cl_start"; bare+=("$wall"); done
echo "floor      bench/cl_start (OpenCL platform, device, context, queue; process start to exit):" \
  "median $(median "${bare[@]}") s of ${bare[*]} s"
for ((k = 0; k < ${#files[@]}; k++)); do measure "${files[k]}" "${dims[k]}" "${types[k]}"; done
echo
printf '%-36s %10s %10s %10s' "volume (medians)" "fd wall s" "peer wall s" "peer / fd"
[ -n "$ijk" ] && printf ' %10s %10s' "ijk wall s" "ijk / fd"
printf '\n'
cat "$work/summary.txt"
echo "(peer / fd >= 1: clfractal fd at least as fast as the plain program, end to end)"
[ -n "$ijk" ] && echo "(ijk: $ijk -box_dim -plot, the same curve; ijk / fd: how many times fd is as fast)"
true
