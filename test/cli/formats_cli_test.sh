#!/usr/bin/env bash
# The file formats through the command line: every command reads DICOM series, NIfTI, TIFF
# and MetaImage; --stream gives the in-core curve; -o x.nii[.gz] writes NIfTI; bad inputs
# are one error line, exit code 2, nothing written.
# Usage: formats_cli_test.sh CLFRACTAL CLFRACTAL_FIXTURES WORKDIR [SHARED_FORMATS_DIR]
set -u
bin=$1
fixtures=$2
work=$3
shared=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
source "$here/cli_lib.sh"

# same A B WHAT: files A and B are identical
same() { cmp -s "$1" "$2" && pass || fail "$3: $1 and $2 differ"; }
# bad_input PATTERN -- command...: exit 2, exactly one line 'clfractal: error: ...PATTERN', no out.nrrd
bad_input() {
  local pattern=$1
  shift 2
  local out rc
  rm -f out.nrrd
  out=$("$@" -o out.nrrd 2>&1)
  rc=$?
  if [ "$rc" -ne 2 ]; then fail "'$*' exited $rc, expected 2: $out"; return; fi
  if [ "$(wc -l <<<"$out")" -ne 1 ] || ! grep -qE -- "^clfractal: error: .*$pattern" <<<"$out"; then
    fail "'$*' is not one error line matching '$pattern': $out"; return
  fi
  if ls out.nrrd* >/dev/null 2>&1; then fail "'$*' left an output behind"; return; fi
  pass
}

# Sources: a uint16 volume (values 0..4095 after the noise), and a uint8 one.
"$bin" -q gen noisy-sphere --size 23 --noise 6 --type uint16 -o u16.nrrd || fail "gen uint16"
"$bin" -q gen noisy-sphere --size 19 --noise 4 -o u8.nrrd || fail "gen uint8"
"$bin" -q fd u8.nrrd --csv u8.csv >/dev/null || fail "fd u8"
"$bin" -q fd u16.nrrd --csv u16.csv >/dev/null || fail "fd u16"

# DICOM series (GDCM writes it, files in shuffled order, intercept 0): the same curve as
# the source; --stream the same; info lists the series.
"$fixtures" dicom u16.nrrd dcm 1.2.826.0.1.1 0 || fail "fixture dicom"
expect 0 'DICOM series' -- "$bin" info dcm
expect 0 '\* 1\.2\.826\.0\.1\.1 +23 files +23x23' -- "$bin" info dcm
expect 0 'spacing +0\.75 0\.5 3' -- "$bin" info dcm
expect 0 'mean FD' -- "$bin" -q fd dcm --csv dcm.csv
same dcm.csv u16.csv "DICOM curve vs its source"
expect 0 'mean FD' -- "$bin" -q fd dcm --stream --csv dcm_stream.csv
same dcm_stream.csv u16.csv "streamed DICOM curve"
expect 0 'mean FD' -- "$bin" -q fd dcm/1.2.826.0.1.1_4.dcm --csv dcm_one.csv
same dcm_one.csv u16.csv "DICOM series named by one file"
# Rescale intercept -1024: int16 values, every isovalue shifted.
"$fixtures" dicom u16.nrrd dcm_hu 1.2.826.0.1.2 -1024 || fail "fixture dicom hu"
expect 0 'type +int16' -- "$bin" info dcm_hu
# Streaming LD on the series equals the in-core field, and NIfTI keeps the geometry.
expect 0 'defined' -- "$bin" -q local dcm_hu --iso -900 -o ld_core.nii
expect 0 'defined' -- "$bin" -q local dcm_hu --iso -900 --stream -o ld_stream.nii
same ld_core.nii ld_stream.nii "streamed LD field (NIfTI)"
expect 0 'spacing +0\.75 0\.5 3' -- "$bin" info ld_core.nii
expect 0 'orientation sform' -- "$bin" info ld_core.nii

# TIFF: multi-page (LZW strips) and a directory of tiled slices; --stream on both.
"$fixtures" tiff u16.nrrd stack.tif || fail "fixture tiff"
"$fixtures" tiffdir u8.nrrd slices || fail "fixture tiffdir"
expect 0 'format +TIFF$' -- "$bin" info stack.tif
expect 0 'mean FD' -- "$bin" -q fd stack.tif --csv tif.csv
same tif.csv u16.csv "multi-page TIFF curve"
expect 0 'mean FD' -- "$bin" -q fd stack.tif --stream --csv tif_stream.csv
same tif_stream.csv u16.csv "streamed multi-page TIFF curve"
expect 0 'mean FD' -- "$bin" -q fd slices --csv dir.csv
same dir.csv u8.csv "TIFF directory curve"
expect 0 'mean FD' -- "$bin" -q fd slices --stream --csv dir_stream.csv
same dir_stream.csv u8.csv "streamed TIFF directory curve"

# NIfTI written by every volume output, read back by every command.
expect 0 '' -- "$bin" -q gen noisy-sphere --size 19 --noise 4 -o gen.nii.gz
expect 0 'mean FD' -- "$bin" -q fd gen.nii.gz --csv nii.csv
same nii.csv u8.csv "NIfTI written by gen"
expect 0 'format +NIfTI' -- "$bin" info gen.nii.gz
expect 0 'changed' -- "$bin" -q filter u8.nrrd --median -o med.nii
expect 0 'changed' -- "$bin" -q filter u8.nrrd --median -o med.nrrd
"$bin" -q fd med.nii --csv med_nii.csv >/dev/null && "$bin" -q fd med.nrrd --csv med_nrrd.csv >/dev/null
same med_nii.csv med_nrrd.csv "filtered volume as NIfTI and NRRD"
expect 0 'vertices' -- "$bin" -q smooth gen.nii.gz --iso 100 --threshold 2.4 -o smooth.nii.gz
expect 0 'uint8' -- "$bin" info smooth.nii.gz
expect 0 'components' -- "$bin" -q components gen.nii.gz
expect 0 'mean FD' -- "$bin" -q fd slices --components

# MetaImage: a header written here over the NRRD's raw data.
tail -c 6859 u8.nrrd > u8.raw
printf 'ObjectType = Image\nNDims = 3\nDimSize = 19 19 19\nElementType = MET_UCHAR\nElementSpacing = 1 1 1\nElementDataFile = u8.raw\n' > u8.mhd
expect 0 'format +MetaImage' -- "$bin" info u8.mhd
expect 0 'mean FD' -- "$bin" -q fd u8.mhd --csv mhd.csv
same mhd.csv u8.csv "MetaImage curve"

# Bad inputs: one line naming the file, exit 2, nothing written.
head -c 2000 gen.nii.gz > cut.nii.gz
bad_input 'cut\.nii\.gz: ' -- "$bin" -q filter cut.nii.gz --median
cp -r dcm dcm_gap && rm dcm_gap/1.2.826.0.1.1_4.dcm
bad_input 'dcm_gap: uneven slice spacing: 6 between .*1 slice\(s\) missing' -- "$bin" -q filter dcm_gap --median
mkdir -p dcm_mixed && cp dcm/*.dcm dcm_mixed/
"$fixtures" dicom u16.nrrd dcm_mixed 1.2.826.0.1.3 0 || fail "fixture mixed"
bad_input 'dcm_mixed: 2 DICOM series of 23 files each; choose one with --series UID' -- "$bin" -q filter dcm_mixed --median
expect 0 'changed' -- "$bin" -q filter dcm_mixed --series 1.2.826.0.1.3 --median -o mixed.nrrd
expect 2 '  1\.2\.826\.0\.1\.3 +23 files' -- "$bin" info dcm_mixed
expect 0 '\* 1\.2\.826\.0\.1\.3 +23 files' -- "$bin" info dcm_mixed --series 1.2.826.0.1.3
cp -r dcm dcm_text && echo "scanner notes" > dcm_text/notes.dcm
bad_input 'notes\.dcm: not a readable DICOM file' -- "$bin" -q filter dcm_text --median
cp -r slices slices_bad && "$fixtures" tiffdir u16.nrrd slices_u16 && cp slices_u16/slice5.tif slices_bad/slice99.tif
bad_input 'slice99\.tif: slice is 23x23 uint16, but slice1\.tif is 19x19 uint8' -- "$bin" -q filter slices_bad --median
head -c 3000 stack.tif > cut.tif
bad_input 'cut\.tif: page [0-9]+ cannot be read \(truncated\?\)' -- "$bin" -q filter cut.tif --median
cp -r dcm dcm_cut && head -c 700 dcm/1.2.826.0.1.1_0.dcm > dcm_cut/1.2.826.0.1.1_0.dcm
# (GDCM's generated UIDs vary in length: the cut may fall between two elements.)
bad_input 'dcm_cut/1\.2\.826\.0\.1\.1_0\.dcm: .*truncated' -- "$bin" -q filter dcm_cut --median
# Cut anywhere (in the file meta information, the data set, the pixel data): one line, exit 2.
cut_ok=1
for n in 0 100 132 140 200 300 400 500 600 800 1000 1500 1900; do
  head -c $n dcm/1.2.826.0.1.1_3.dcm > dcm_cut/1.2.826.0.1.1_0.dcm
  out=$("$bin" info dcm_cut 2>&1 >/dev/null)
  rc=$?
  if [ $rc -ne 2 ] || [ "$(wc -l <<<"$out")" -ne 1 ]; then cut_ok=0; fail "DICOM slice cut at $n bytes: exit $rc: $out"; fi
done
[ $cut_ok -eq 1 ] && pass
# (Each of these errors is thrown inside the DICOM module, libclfractal_dicom.so, and caught
# by the tool as bad input.)
# Without the modules: the binary and its libraries copied to a directory that lacks them (the
# copies loaded instead of the build tree's, checked with ldd). Reading DICOM is one error
# line naming the file, exit 2, by every reading path; the other formats still read; a fit of
# more than two levels, which needs the CLBlast module, is one error line naming it, exit 1.
mkdir -p nodicom
cp "$bin" nodicom/
for lib in $(ldd "$bin" | awk '$3 ~ /libclfractal/ {print $3}'); do cp "$lib" "nodicom/$(basename "$lib")"; done
if [ -e nodicom/libclfractal_dicom.so ] || [ -e nodicom/libclfractal_blas.so ] ||
  ! ls nodicom/libclfractal_io.so* nodicom/libclfractal_core.so* >/dev/null 2>&1; then
  fail "nodicom: the copy holds a module or lacks libclfractal_io or libclfractal_core"
elif ! LD_LIBRARY_PATH="$work/nodicom" ldd nodicom/$(basename "$bin") | grep -q "=> $work/nodicom/libclfractal_io"; then
  fail "nodicom: the copy's libclfractal_io is not the one loaded"
else
  nodicom="env LD_LIBRARY_PATH=$work/nodicom $work/nodicom/$(basename "$bin")"
  missing='dcm: cannot read DICOM: DICOM support is missing \(.*libclfractal_dicom\.so: cannot open shared object file'
  # error_line PATTERN -- command...: exit 2, stderr exactly the line 'clfractal: error: ...PATTERN'
  error_line() {
    local pattern=$1 out rc
    shift 2
    out=$("$@" 2>&1 >/dev/null)
    rc=$?
    if [ "$rc" -ne 2 ]; then fail "'$*' exited $rc, expected 2: $out"; return; fi
    if [ "$(wc -l <<<"$out")" -ne 1 ] || ! grep -qE -- "^clfractal: error: $pattern" <<<"$out"; then
      fail "'$*' is not one error line matching '$pattern': $out"; return
    fi
    pass
  }
  bad_input "$missing" -- $nodicom -q filter dcm --median
  error_line "$missing" -- $nodicom -q fd dcm --stream
  error_line "$missing" -- $nodicom info dcm
  error_line "dcm/1\.2\.826\.0\.1\.1_4\.dcm: cannot read DICOM: DICOM support is missing" \
    -- $nodicom -q fd dcm/1.2.826.0.1.1_4.dcm
  expect 0 'mean FD' -- $nodicom -q fd u16.nrrd --csv nodicom_u16.csv
  same nodicom_u16.csv u16.csv "NRRD curve without the DICOM module"
  out=$($nodicom -q fd u16.nrrd --levels 3 2>&1 >/dev/null)
  rc=$?
  if [ $rc -ne 1 ] || [ "$(wc -l <<<"$out")" -ne 1 ] ||
    ! grep -qE '^clfractal: error: dense linear algebra \(CLBlast\) is missing: .*libclfractal_blas\.so' <<<"$out"; then
    fail "fd --levels 3 without the CLBlast module: exit $rc: $out"
  else
    pass
  fi
fi
# The CLBlast module is loaded by what needs it only: fd --levels 3 (the least-squares fit),
# not fd (two levels) nor info (the loader's own account, LD_DEBUG=files).
loads_blas() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -c 'file=.*libclfractal_blas\.so'; }
if [ "$(loads_blas "$bin" -q fd u16.nrrd)" -ne 0 ] || [ "$(loads_blas "$bin" info u16.nrrd)" -ne 0 ] ||
  [ "$(loads_blas "$bin" -q fd u16.nrrd --levels 3)" -eq 0 ]; then
  fail "the CLBlast module: loaded by fd or info, or not by fd --levels 3"
else
  pass
fi
printf 'ObjectType = Image\nNDims = 3\nDimSize = 19 19 19\nElementType = MET_UCHAR\nElementDataFile = gone.raw\n' > gone.mhd
bad_input "gone\.mhd: data file '.*gone\.raw' does not exist" -- "$bin" -q filter gone.mhd --median
# Headers claiming more data than their files hold: refused before anything that size is
# allocated; special files refused, not opened.
printf 'ObjectType = Image\nNDims = 3\nDimSize = 1000 1000 1000\nElementType = MET_UCHAR\nElementDataFile = u8.raw\n' > claim.mhd
bad_input 'claim\.mhd: truncated: the MetaImage data \(1000x1000x1000 uint8\) is 1000000000 bytes, but only 6859 are there' \
  -- "$bin" -q filter claim.mhd --median
cp med.nii claim.nii && printf '\x00\x08\x00\x08\x00\x08' | dd of=claim.nii bs=1 seek=42 conv=notrunc 2>/dev/null
bad_input 'claim\.nii: truncated: the NIfTI header and data \(2048x2048x2048 uint8\) is 8589934944 bytes' \
  -- "$bin" -q filter claim.nii --median
mkfifo fifo.nii
bad_input 'fifo\.nii: not a regular file' -- "$bin" -q filter fifo.nii --median
expect 2 '^clfractal: error: out\.mha: cannot write \.mha files' -- "$bin" -q gen sphere --size 9 -o out.mha
[ ! -e out.mha ] && pass || fail "gen -o out.mha wrote a file"

# Real files, when ../shared/data/formats is at hand.
if [ -n "$shared" ] && [ -d "$shared/dicom_ct_phantom" ]; then
  expect 0 'STD BRAIN 5MM' -- "$bin" info "$shared/dicom_ct_phantom"
  expect 0 'mean FD' -- "$bin" -q fd "$shared/dicom_ct_phantom" --csv ct.csv
  expect 0 'mean FD' -- "$bin" -q fd "$shared/dicom_ct_phantom" --stream --csv ct_stream.csv
  same ct.csv ct_stream.csv "real CT series streamed"
  expect 0 'mean FD' -- "$bin" -q fd "$shared/dicom_ct_phantom_512x512x28_int16.raw" --csv ct_raw.csv
  same ct.csv ct_raw.csv "real CT series vs its reference decoding"
else
  echo "skipped: ../shared/data/formats is absent"
fi

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
