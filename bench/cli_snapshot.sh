#!/usr/bin/env bash
# Runs every clfractal subcommand with its main outputs (stdout, stderr, exit code, CSV,
# JSON, Markdown, NRRD, NIfTI, PLY, PNG) on the small and medium real volumes, a few files
# of other formats and synthetic inputs, into OUTDIR, so that two builds can be compared:
#
#   bench/cli_snapshot.sh /tmp/before build-old/clfractal
#   bench/cli_snapshot.sh /tmp/after  build/clfractal
#   diff -r /tmp/before /tmp/after
#
# Wall-clock figures are replaced by "<t>" (the "time" lines, kernel compile times, JSON
# keys with seconds or rates, survey's seconds column). Inputs are named by relative paths
# (data/..., formats/...), outputs written from inside OUTDIR, so the files do not depend on
# where the data or OUTDIR lie. Data: $CLFRACTAL_SHARED_DATA, default ../shared/data beside
# the repository. Takes about two minutes on one core.
set -u
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 OUTDIR [CLFRACTAL_BINARY]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
out=$1
bin=$(realpath "${2:-$here/../build/clfractal}")
data=$(realpath "${CLFRACTAL_SHARED_DATA:-$here/../../shared/data}")
[ -x "$bin" ] || { echo "$0: $bin: not an executable" >&2; exit 2; }
[ -f "$data/MANIFEST.tsv" ] || { echo "$0: $data: no MANIFEST.tsv (set CLFRACTAL_SHARED_DATA)" >&2; exit 2; }

rm -rf "$out" && mkdir -p "$out" || exit 2
out=$(realpath "$out")
inputs=$(mktemp -d)
trap 'rm -rf "$inputs"' EXIT
ln -s "$data" "$inputs/data"
ln -s "$data/formats" "$inputs/formats"
mkdir "$inputs/syn" "$inputs/survey"
cd "$inputs" || exit 2
export OMP_NUM_THREADS=1

# Wall-clock figures out of text outputs.
scrub() {
  sed -E -e 's/^time( +).*/time\1<t>/' \
         -e 's/kernels compiled in [0-9.e+-]+ s/kernels compiled in <t> s/g' \
         -e 's/\(([0-9.e+-]+) s\)$/(<t> s)/' \
         -e 's/^( *"[a-z_0-9]*(seconds|per_s|roofline|speedup)[a-z_0-9]*": )[^,]*(,?)$/\1"<t>"\3/'
}

# run NAME ARGS...: runs the binary from the inputs folder (inputs data/..., formats/...,
# syn/...; outputs o/..., which is OUTDIR); stdout, stderr and the exit code to o/NAME.out,
# NAME.err, NAME.rc.
run() {
  local name=$1
  shift
  "$bin" "$@" >"o/$name.out" 2>"o/$name.err"
  echo $? >"o/$name.rc"
  for f in "o/$name.out" "o/$name.err"; do scrub <"$f" >"$f.tmp" && mv "$f.tmp" "$f"; done
}
ln -s "$out" o

small="bucky_32x32x32_uint8 fuel_cropped_64x33x32_uint8 m4_totaldensity_31x22x25_float32 nucleon_41x41x41_uint8
neghip_slc_66x66x66_uint8 ironprot_68x68x68_uint8 hydrogen_3d_orbital_64x64x64_float32 mni_avg152t1_91x109x91_uint8"
medium="walnut_128x96x114_uint16 niivue_ct_pitch_175x248x58_uint8 lobster_301x324x56_uint8
seg3d_mr_160x232x160_uint8 engine_256x256x128_uint8 stent_128x128x256_int16"
formats="3DCT_lung_baseline_small.mha avg152T1_RL_nifti.nii.gz engine.nii.gz"

# ---- synthetic inputs (gen writes NRRD and NIfTI; the files are outputs too)
run gen_sphere gen sphere --size 40 -o o/gen_sphere.nrrd
run gen_noisy_sphere gen noisy-sphere --size 48 --noise 20 --seed 3 -o o/gen_noisy_sphere.nrrd
run gen_torus gen torus --size 33 --type float32 -o o/gen_torus.nii.gz
run gen_points gen points --size 36 --points 7 --seed 5 -o o/gen_points.nrrd
run gen_ml gen marschner-lobb --size 31 -o o/gen_ml.nii
run gen_sphere16 gen sphere --size 24 --type int16 -o o/gen_sphere16.nrrd
cp o/gen_noisy_sphere.nrrd syn/noisy.nrrd
cp o/gen_torus.nii.gz syn/torus.nii.gz
head -c 1000 /dev/zero | tr '\0' '\7' >syn/flat_10x10x10_uint8.raw
python3 -c "
import struct, math
n = 20
v = [math.sin(x / 3.0) * math.cos(y / 4.0) + z / 10.0 for z in range(n) for y in range(n) for x in range(n)]
open('syn/wave_20x20x20_float64.raw', 'wb').write(struct.pack('<%dd' % len(v), *v))
open('syn/wave_be.raw', 'wb').write(struct.pack('>%dd' % len(v), *v))
"
synthetic="syn/noisy.nrrd syn/torus.nii.gz syn/wave_20x20x20_float64.raw synthetic:noisy-sphere:32 synthetic:marschner-lobb:24"

# ---- info and fd on every input
for v in $small $medium; do
  run "info_$v" info "data/$v.raw"
  run "fd_$v" fd "data/$v.raw" --csv "o/fd_$v.csv" --json "o/fd_$v.json"
done
for v in $formats; do
  run "info_$v" info "formats/$v"
  run "fd_$v" fd "formats/$v" --csv "o/fd_$v.csv" --json "o/fd_$v.json"
done
run info_dicom info formats/dicom_ct_phantom
run fd_dicom fd formats/dicom_ct_phantom --json o/fd_dicom.json
n=0
for v in $synthetic; do
  n=$((n + 1))
  run "info_syn$n" info "$v"
  run "fd_syn$n" fd "$v" --csv "o/fd_syn$n.csv"
done
run info_raw_options info syn/wave_be.raw --dims 20,20,20 --type float64 --endian big
run info_as info data/walnut_128x96x114_uint16.raw --as uint8
run info_scaled info formats/avg152T1_RL_nifti.nii.gz --scaled

# ---- fd options
for v in bucky_32x32x32_uint8 hydrogen_3d_orbital_64x64x64_float32 walnut_128x96x114_uint16; do
  run "fd_plot_$v" fd "data/$v.raw" --plot "o/fd_plot_$v.png"
  run "fd_edge_levels_$v" fd "data/$v.raw" --edge --levels 4 --csv "o/fd_edge_levels_$v.csv" --json "o/fd_edge_levels_$v.json"
  run "fd_components_$v" fd "data/$v.raw" --components --noise-level --csv "o/fd_components_$v.csv" --json "o/fd_components_$v.json"
  run "fd_stream_$v" fd "data/$v.raw" --stream --csv "o/fd_stream_$v.csv"
done
run fd_slab fd data/engine_256x256x128_uint8.raw --slab 17 --csv o/fd_slab.csv
run fd_isovalues fd data/hydrogen_3d_orbital_64x64x64_float32.raw --isovalues 0.1:0.9:0.05 --csv o/fd_isovalues.csv
run fd_isovalues_int fd data/stent_128x128x256_int16.raw --isovalues 100:1500:1 --min-count 50 --json o/fd_isovalues_int.json
run fd_bins fd data/m4_totaldensity_31x22x25_float32.raw --bins 64 --clean-fd 2.3 --clean-share 0.05 --json o/fd_bins.json
run fd_stream_float fd syn/wave_20x20x20_float64.raw --stream --isovalues -0.5:2.5:0.25 --csv o/fd_stream_float.csv
run fd_stdout fd data/nucleon_41x41x41_uint8.raw --csv -

# ---- local (LD field), mesh, smooth
for v in bucky_32x32x32_uint8 neghip_slc_66x66x66_uint8 hydrogen_3d_orbital_64x64x64_float32; do
  run "local_$v" local "data/$v.raw" --iso auto -o "o/local_$v.nrrd" --mesh "o/local_$v.ply"
  run "mesh_$v" mesh "data/$v.raw" --iso auto -o "o/mesh_$v.ply" --preview "o/mesh_$v.png"
  run "mesh_mt_$v" mesh "data/$v.raw" --iso auto --method mt --color-by-ld --window 4 -o "o/mesh_mt_$v.ply"
  run "smooth_$v" smooth "data/$v.raw" --iso auto --threshold 2.2 -o "o/smooth_$v.nrrd" --mesh "o/smooth_$v.ply"
done
run local_nii local data/ironprot_68x68x68_uint8.raw --iso 100 --window 6 -o o/local_nii.nii.gz
run local_stream local data/walnut_128x96x114_uint16.raw --iso 4000 --stream -o o/local_stream.nrrd
run local_syn local syn/noisy.nrrd --iso 128 -o o/local_syn.nrrd
run mesh_engine mesh data/engine_256x256x128_uint8.raw --iso 100 -o o/mesh_engine.ply
run mesh_lung mesh formats/3DCT_lung_baseline_small.mha --iso -500 -o o/mesh_lung.ply
run mesh_raw mesh syn/wave_20x20x20_float64.raw --iso 1 -o o/mesh_raw.ply
run mesh_outside mesh data/bucky_32x32x32_uint8.raw --iso 300 -o o/mesh_outside.ply
run smooth_gauss smooth syn/noisy.nrrd --iso 128 --threshold 2.3 --variant gaussian --tau 1.5 -o o/smooth_gauss.nii --preview o/smooth_gauss.png

# ---- filter
run filter_median filter data/neghip_slc_66x66x66_uint8.raw --median -o o/filter_median.nrrd
run filter_gaussian filter data/hydrogen_3d_orbital_64x64x64_float32.raw --gaussian 1.2 --iso 0.3 -o o/filter_gaussian.nrrd
run filter_bilateral filter data/walnut_128x96x114_uint16.raw --bilateral 1.5,400 -o o/filter_bilateral.nrrd
run filter_fractal filter syn/noisy.nrrd --median --fractal --iso 128 --threshold 2.4 -o o/filter_fractal.nrrd
run filter_fractal_stream filter syn/noisy.nrrd --median --fractal --iso 128 --threshold 2.4 --stream -o o/filter_fractal_stream.nrrd
run filter_fractal4 filter data/ironprot_68x68x68_uint8.raw --gaussian 1 --fractal4 --threshold 3.2 -o o/filter_fractal4.nii.gz
run filter_ld_guided filter data/nucleon_41x41x41_uint8.raw --bilateral 1,20 --ld-guided --iso 100 --window 4 -o o/filter_ld_guided.nrrd

# ---- components
for v in bucky_32x32x32_uint8 fuel_cropped_64x33x32_uint8 m4_totaldensity_31x22x25_float32 walnut_128x96x114_uint16; do
  run "components_$v" components "data/$v.raw" --csv "o/components_$v.csv"
done
run components_plot components data/neghip_slc_66x66x66_uint8.raw --connectivity freudenthal --plot o/components_plot.png --csv o/components_plot.csv
run components_verify components data/nucleon_41x41x41_uint8.raw --verify --isovalues 10:60:1
run components_bins components data/hydrogen_3d_orbital_64x64x64_float32.raw --bins 32 --csv o/components_bins.csv

# ---- noise
run noise_points noise --size 32 --mu 0:2:0.5 --box-samples 4096 --json o/noise_points.json --plot o/noise_points.png
run noise_circle noise --size 32 --shape circle --isovalues 3,4 --mu 0,1 --noise gaussian --seed 2 --box-samples 4096
run noise_volume noise --volume data/neghip_slc_66x66x66_uint8.raw --iso 120 --mu 0:4:1 --box-samples 4096 --json o/noise_volume.json

# ---- fd4, local4
for v in bucky_32x32x32_uint8 hydrogen_3d_orbital_64x64x64_float32 walnut_128x96x114_uint16; do
  run "fd4_$v" fd4 "data/$v.raw" --json "o/fd4_$v.json"
done
run fd4_q fd4 syn/noisy.nrrd --q 4
run local4 local4 data/fuel_cropped_64x33x32_uint8.raw --window 4 -o o/local4.nrrd
run local4_q local4 syn/torus.nii.gz --q 0.05 -o o/local4_q.nii

# ---- survey over a folder of small volumes (the "seconds" CSV column scrubbed)
for v in $small; do ln -s "../data/$v.raw" "survey/$v.raw"; done
run survey survey survey --markdown o/survey.md --csv o/survey.csv --histogram o/survey.png
sed -E -i 's/,[0-9.e+-]+$/,<t>/' o/survey.csv

# ---- bench: only the counts check (the figures are timings)
run bench bench --size 12 --repeats 1
grep -E '^  [a-z]' o/bench.out | awk '{print $1, $2, $3, $NF}' >o/bench.out.tmp && mv o/bench.out.tmp o/bench.out

# ---- errors: one line naming the file, exit 2
run err_missing fd data/no_such_file.raw
run err_dims fd syn/wave_be.raw
run err_type fd syn/wave_be.raw --dims 20,20,20 --type uint7
run err_truncated info syn/wave_be.raw --dims 20,20,21 --type float64
run err_flat fd syn/flat_10x10x10_uint8.raw --isovalues 9:3:1
run err_window local data/bucky_32x32x32_uint8.raw --iso 100 --window 5 -o o/err_window.nrrd
run err_subcommand nosuchcommand

# Wall-clock figures out of the JSON outputs too.
for f in o/*.json; do scrub <"$f" >"$f.tmp" && mv "$f.tmp" "$f"; done
