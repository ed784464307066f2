#!/usr/bin/env bash
# The project on a GPU in one call, on a machine with no package registry (an NVIDIA
# machine with a CUDA image): unpacks the Debian 12 .deb files that bench/gpu_debs.sh
# gathered (on a machine with apt) into a prefix, registers the NVIDIA OpenCL driver with
# the ICD loader if no ICD file names it, builds the project against the prefix only
# (/usr and /usr/local are ignored by CMake's searches), runs ctest and every benchmark on
# the GPU, and prints one table: stage, GB/s, fraction of the copy bandwidth measured in the
# same run (kernels/copy.cl, `clfractal bench`).
#
# Usage: bench/gpu_check.sh [--debs DIR (gpu-debs)] [--prefix DIR (gpu-prefix)]
#                           [--build DIR (gpu-build)] [--size N (256)] [--cpu] [--no-tests]
#   --cpu       the CPU device instead (a rehearsal on PoCL, whose ICD file must be there)
#   --no-tests  build and benchmark only
# Needs: bash, a C++17 compiler with OpenMP (g++), dpkg-deb or ar+tar, and the .deb files
# (their libraries are Debian 12's: glibc 2.36 or newer). Writes gpu-check.log and the
# benchmarks' JSON into the build folder. Exit status: 0 when the build, the tests and the
# benchmarks all passed.
set -uo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
debs=gpu-debs prefix=gpu-prefix build=gpu-build size=256 device=gpu tests=1
while [ $# -gt 0 ]; do
  case $1 in
    --debs) debs=$2; shift ;;
    --prefix) prefix=$2; shift ;;
    --build) build=$2; shift ;;
    --size) size=$2; shift ;;
    --cpu) device=cpu ;;
    --no-tests) tests=0 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "gpu_check: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$prefix" "$build"
prefix=$(cd "$prefix" && pwd) build=$(cd "$build" && pwd)
log=$build/gpu-check.log
: >"$log"
say() { echo "gpu_check: $*" | tee -a "$log" >&2; }
fail() { say "FAILED: $*"; exit 1; }
status=0

# ---- 1. the prefix: every .deb unpacked, absolute links and .pc files pointed into it
if ls "$debs"/*.deb >/dev/null 2>&1; then
  say "unpacking $(ls "$debs"/*.deb | wc -l) .deb files from $debs into $prefix"
  rm -rf "$prefix" && mkdir -p "$prefix"
  for d in "$debs"/*.deb; do
    case $(basename "$d") in libc6_*|libstdc++6_*|libgcc-s1_*) continue ;; esac  # the image's own
    if command -v dpkg-deb >/dev/null; then
      dpkg-deb -x "$d" "$prefix" || fail "cannot unpack $d"
    else
      t=$(mktemp -d) && (cd "$t" && ar x "$d" && tar -xf data.tar.* -C "$prefix") || fail "cannot unpack $d"
      rm -rf "$t"
    fi
  done
  # A link to /lib/x86_64-linux-gnu/libz.so.1.2.13 means the prefix's copy, or else the
  # image's library of that name (any version of its soname).
  find "$prefix" -type l | while read -r l; do
    t=$(readlink "$l")
    case $t in /*) ;; *) continue ;; esac
    if [ -e "$prefix$t" ]; then ln -sfn "$prefix$t" "$l"; continue; fi
    base=$(basename "$t") soname=${base%.so*}.so
    for dir in /lib/x86_64-linux-gnu /usr/lib/x86_64-linux-gnu /lib64 /usr/lib64 "$(dirname "$t")"; do
      found=$(ls "$dir/$soname".* 2>/dev/null | head -1)
      [ -n "$found" ] && { ln -sfn "$found" "$l"; break; }
    done
  done
  find "$prefix" -name '*.pc' -exec sed -i "s|^prefix=/usr\$|prefix=$prefix/usr|" {} +
else
  [ -d "$prefix/usr" ] || fail "no .deb files in $debs and no prefix in $prefix (run bench/gpu_debs.sh on a machine with apt)"
  say "using the prefix $prefix as it is (no .deb files in $debs)"
fi
usr=$prefix/usr
libdirs=$usr/lib/x86_64-linux-gnu:$prefix/lib/x86_64-linux-gnu:$usr/lib
export PATH=$usr/bin:$PATH
export LD_LIBRARY_PATH=$libdirs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export CMAKE_PREFIX_PATH=$usr LIBRARY_PATH=$libdirs CPATH=$usr/include:$usr/include/x86_64-linux-gnu
export PKG_CONFIG_PATH=$usr/lib/x86_64-linux-gnu/pkgconfig:$usr/share/pkgconfig
cmake=$(command -v cmake) || fail "no cmake (in the prefix or the image)"
say "cmake: $cmake ($("$cmake" --version | head -1))"

# ---- 2. the OpenCL driver: an ICD file naming libnvidia-opencl.so.1 if none does
if [ "$device" = gpu ]; then
  nv=$( (ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}'; \
         ls /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 /usr/lib64/libnvidia-opencl.so.1 \
            /usr/local/nvidia/lib64/libnvidia-opencl.so.1 2>/dev/null) | head -1)
  if [ -z "$nv" ]; then
    say "no libnvidia-opencl.so.1 on this machine: the NVIDIA OpenCL driver is missing"
  elif grep -qs nvidia /etc/OpenCL/vendors/*.icd; then
    say "NVIDIA OpenCL driver: $nv (registered in /etc/OpenCL/vendors)"
  elif mkdir -p /etc/OpenCL/vendors 2>/dev/null && echo "$nv" >/etc/OpenCL/vendors/nvidia.icd 2>/dev/null; then
    say "NVIDIA OpenCL driver: $nv (registered now: /etc/OpenCL/vendors/nvidia.icd)"
  else
    mkdir -p "$prefix/etc/OpenCL/vendors" && echo "$nv" >"$prefix/etc/OpenCL/vendors/nvidia.icd"
    export OCL_ICD_VENDORS=$prefix/etc/OpenCL/vendors
    say "NVIDIA OpenCL driver: $nv (/etc is read-only: OCL_ICD_VENDORS=$OCL_ICD_VENDORS)"
  fi
fi
export CLFRACTAL_DEVICE_TYPE=$device

# ---- 3. build against the prefix only
say "configuring $src in $build"
"$cmake" -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCLFRACTAL_PYTHON=OFF -DCLFRACTAL_MPI=OFF \
  -DCLFRACTAL_TEST_DEVICE_TYPE="$device" -DCMAKE_PREFIX_PATH="$usr" "-DCMAKE_IGNORE_PREFIX_PATH=/usr;/usr/local" \
  >>"$log" 2>&1 || fail "cmake configure (see $log)"
outside=$(grep -E '^[A-Za-z_]*(LIBRARY|INCLUDE_DIR)[A-Za-z_]*:[A-Z]*=/' "$build/CMakeCache.txt" | grep -v "=$prefix" |
  grep -v -- '-NOTFOUND' | cut -d= -f2 | sort -u | tr '\n' ' ')
say "libraries and headers found outside the prefix: ${outside:-none}"
say "building with $(nproc) jobs"
"$cmake" --build "$build" -j"$(nproc)" >>"$log" 2>&1 || fail "build (see $log)"
say "$build/clfractal links: $(ldd "$build/clfractal" | awk '/=>/ {print $3}' | grep -c "^$prefix") libraries from the prefix, $(ldd "$build/clfractal" | awk '/=>/ {print $3}' | grep -vc "^$prefix") from the image"
"$build/clfractal" devices 2>&1 | tee -a "$log"

# ---- 4. tests on the chosen device
if [ "$tests" = 1 ]; then
  say "ctest on the $device device"
  t0=$(date +%s)
  if ctest --test-dir "$build" -j"$(nproc)" --output-on-failure >>"$log" 2>&1; then ok=passed; else ok=FAILED; status=1; fi
  say "ctest $ok in $(( $(date +%s) - t0 )) s: $(grep -E 'tests passed' "$log" | tail -1)"
  # The bounded subset CI runs on Oclgrind (every kernel family and variant on tiny volumes),
  # here on the real device: its assertions and the variants the device's limits shrank.
  if "$build/test/clfractal_tests" --test-suite=portable >>"$log" 2>&1; then ok=passed; else ok=FAILED; status=1; fi
  say "portable suite $ok on $device: $(grep -E '^\[doctest\] assertions' "$log" | tail -1)"
fi

# ---- 5. every benchmark on the chosen device
bench() {  # name, command...
  local name=$1; shift
  say "benchmark $name: $*"
  "$@" >"$build/bench_$name.out" 2>>"$log" || { say "benchmark $name FAILED"; status=1; }
}
small=$(( size / 2 ))
bench span "$build/clfractal" bench --size "$size" --json "$build/bench_span.json"
bench local "$build/clfractal_local_bench" --size "$size"
bench filter "$build/clfractal_filter_bench" --size "$size"
bench components "$build/clfractal_components_bench" --size "$small" --size "$size" --uint16-size "$small" \
  --json "$build/bench_components.json"
bench stream "$build/clfractal_stream_bench" --size $(( size * 2 ))

# ---- 6. one table: stage, GB/s (bytes of the input per second), fraction of the copy bandwidth
copy=$(awk -F'[:,]' '/"copy_gb_per_s"/ {gsub(/ /, "", $2); print $2; exit}' "$build/bench_span.json" 2>/dev/null)
{
  echo
  echo "device: $(awk -F'"' '/"device"/ {print $4; exit}' "$build/bench_span.json" 2>/dev/null)"
  printf '%-44s %10s %12s\n' stage GB/s of_copy
  # JSON as nlohmann dumps it (one key per line, keys sorted): the keys of each object are
  # kept and its row printed at its closing brace.
  awk -v copy="${copy:-0}" '
    function bpv(label) { return label ~ /float64/ ? 8 : label ~ /float32|int32/ ? 4 : label ~ /16/ ? 2 : 1 }
    function row(stage, gbs) { printf "%-44s %10.3f %11.1f%%\n", stage, gbs, (copy > 0 ? 100 * gbs / copy : 0) }
    FNR == 1 { file = FILENAME; sub(/.*bench_/, "", file); sub(/\.[a-z]*$/, "", file); split("", f) }
    /^ *[}\]]/ {
      label = f["volume"] f["case"]
      if (file == "span" && "device_gb_per_s" in f) row("span curve, levels 0+1, " label, f["device_gb_per_s"])
      if (file == "local" && "device_gb_per_s" in f) row("local LD field, " label, f["device_gb_per_s"])
      if (file == "filter" && "median_gb_per_s" in f) row("median 3^3, " label, f["median_gb_per_s"])
      if (file == "filter" && "gaussian_gvoxels_per_s" in f) row("Gaussian, " label, f["gaussian_gvoxels_per_s"] * bpv(label))
      if (file == "components" && "sweep_mvoxel_per_s" in f)
        row("components curve, " label, f["sweep_mvoxel_per_s"] * bpv(label) / 1000)
      # count_components_at at path_isovalues isovalues: one read of the volume each.
      if (file == "components" && "device_labelling_seconds" in f) {
        bytes = f["vertices"] * bpv(label) * f["path_isovalues"]
        row("labelling at " f["path_isovalues"] " iso, device, " label, bytes / f["device_labelling_seconds"] / 1e9)
        row("labelling at " f["path_isovalues"] " iso, host, " label, bytes / f["host_labelling_seconds"] / 1e9)
      }
      split("", f)
      next
    }
    /^ *"/ {
      line = $0; gsub(/^ +|,$/, "", line); n = index(line, "\":")
      key = substr(line, 2, n - 2); value = substr(line, n + 2); gsub(/^ +|"/, "", value); f[key] = value
      if (file == "span" && key == "copy_gb_per_s") row("copy (kernels/copy.cl, read + write)", value)
    }
    file == "stream" && /^volume/ { n = $2; sub(/\^3/, "", n) }
    file == "stream" && /^stream / { row("fd --stream counting, " n "^3 uint8", n * n * n / $2 / 1e9) }
    file == "stream" && /^in-core / { row("fd in core, " n "^3 uint8", n * n * n / $2 / 1e9) }
  ' "$build/bench_span.json" "$build/bench_local.out" "$build/bench_filter.out" "$build/bench_components.json" \
    "$build/bench_stream.out" 2>/dev/null
} | tee -a "$log"
[ "$status" = 0 ] && say "all passed" || say "some steps FAILED (see $log)"
exit $status
