#!/usr/bin/env bash
# The options every subcommand shares, tried as a new user would: -q before or after the
# subcommand, --dims X,Y,Z or XxYxZ, --spacing on raw files (it reaches meshes and outputs),
# isovalue lists A:B:STEP or A,B,..., and defaults in every help line.
# Usage: cli_options_test.sh CLFRACTAL WORKDIR
set -u
source "$(dirname "$0")/cli_lib.sh"
bin=$1
enter_workdir "$2"

# ---- -q anywhere: before the subcommand, after it, after the volume; progress otherwise.
for args in "-q fd synthetic:sphere:20" "fd -q synthetic:sphere:20" "fd synthetic:sphere:20 -q" \
            "info --quiet synthetic:sphere:20" "mesh synthetic:sphere:20 --iso 100 -o q.ply -q"; do
  # shellcheck disable=SC2086
  "$bin" $args >q.out 2>q.err
  rc=$?
  [ $rc -eq 0 ] && [ ! -s q.err ] && [ -s q.out ] && pass || fail "'$args': rc $rc, stderr: $(cat q.err)"
done
"$bin" fd synthetic:sphere:20 2>&1 >/dev/null | grep -q '^clfractal: counting' && pass || fail "fd without -q: no progress"
expect 2 'clfractal: error: .*--nope' -- "$bin" fd synthetic:sphere:20 --nope

# ---- --dims X,Y,Z and XxYxZ read the same; a mixed or short form is one clear error.
python3 -c "
import random
random.seed(4)
open('plain.raw', 'wb').write(bytes(random.randrange(256) for _ in range(48 * 62 * 42)))
" || fail "python3 could not write plain.raw"
"$bin" -q fd plain.raw --dims 48x62x42 --type uint8 --csv dims_x.csv >dims_x.out 2>&1 && pass || fail "--dims 48x62x42: $(cat dims_x.out)"
"$bin" -q fd plain.raw --dims 48,62,42 --type uint8 --csv dims_c.csv >dims_c.out 2>&1 && pass || fail "--dims 48,62,42: $(cat dims_c.out)"
grep -q 'plain.raw  48x62x42 uint8' dims_x.out && pass || fail "--dims 48x62x42 not used: $(head -1 dims_x.out)"
cmp -s dims_x.csv dims_c.csv && pass || fail "--dims 48x62x42 and 48,62,42 give different curves"
expect 2 "clfractal: error: --dims '48x62,42': expected three positive integers" -- "$bin" info plain.raw --dims 48x62,42 --type uint8
expect 2 "clfractal: error: --dims '48x62': expected three positive integers" -- "$bin" info plain.raw --dims 48x62 --type uint8
expect 2 "clfractal: error: plain.raw: too long" -- "$bin" info plain.raw --dims 4x4x4 --type uint8

# ---- --spacing: in info, in the mesh's extent, in an output's header (also streamed).
"$bin" -q gen sphere --size 24 -o sp.nrrd || fail "gen sp.nrrd"
python3 -c "
body = open('sp.nrrd', 'rb').read().split(b'\n\n', 1)[1]
open('sp_24x24x24_uint8.raw', 'wb').write(body)
" || fail "sp.nrrd: no raw body"
expect 0 'spacing +1 1 1$' -- "$bin" info sp_24x24x24_uint8.raw
expect 0 'spacing +0.5 1 2.5$' -- "$bin" info sp_24x24x24_uint8.raw --spacing 0.5,1,2.5
"$bin" -q mesh sp_24x24x24_uint8.raw --iso 100 -o unit.ply >/dev/null 2>&1 || fail "mesh without --spacing"
"$bin" -q mesh sp_24x24x24_uint8.raw --iso 100 --spacing 0.5,1,2.5 -o spaced.ply >/dev/null 2>&1 || fail "mesh --spacing"
python3 - <<'PY' && pass || fail "--spacing does not scale the mesh"
import struct
def extent(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    n = int(head.split(b"element vertex ")[1].split(b"\n")[0])
    xyz = [struct.unpack_from("<3f", body, 12 * i) for i in range(n)]
    return [(min(p[a] for p in xyz), max(p[a] for p in xyz)) for a in range(3)]
u, s = extent("unit.ply"), extent("spaced.ply")
for a, k in enumerate((0.5, 1.0, 2.5)):
    for j in range(2):
        assert abs(s[a][j] - k * u[a][j]) < 1e-4 * (1 + abs(u[a][j])), (a, u, s)
assert u[2][1] - u[2][0] > 5, u
PY
for stream in "" "--stream"; do
  # shellcheck disable=SC2086
  "$bin" -q local sp_24x24x24_uint8.raw --iso 100 --spacing 0.5,1,2.5 $stream -o "ld$stream.nrrd" >/dev/null 2>&1 || fail "local $stream --spacing"
  expect 0 'spacing +0.5 1 2.5$' -- "$bin" info "ld$stream.nrrd"
done
expect 2 'clfractal: error: --spacing 1,2: expected three numbers' -- "$bin" info sp_24x24x24_uint8.raw --spacing 1,2
expect 2 'clfractal: error: --spacing 1,0,2: spacings must be > 0' -- "$bin" info sp_24x24x24_uint8.raw --spacing 1,0,2
expect 2 "clfractal: error: --spacing 1,x,2: 'x' is not a number" -- "$bin" info sp_24x24x24_uint8.raw --spacing 1,x,2

# ---- isovalue lists: A:B:STEP and A,B,... in fd (in core and streamed), components, noise.
"$bin" -q gen marschner-lobb --size 21 -o ml.nrrd || fail "gen ml.nrrd"
"$bin" -q fd ml.nrrd --isovalues 0.25:0.75:0.25 --csv range.csv >/dev/null 2>&1 || fail "fd A:B:STEP"
"$bin" -q fd ml.nrrd --isovalues 0.75,0.25,0.5 --csv list.csv >/dev/null 2>&1 || fail "fd A,B,C"
"$bin" -q fd ml.nrrd --isovalues 0.25,0.5,0.75 --stream --csv list_stream.csv >/dev/null 2>&1 || fail "fd --stream A,B,C"
[ "$(cut -d, -f1 list.csv | tr '\n' ' ')" = "isovalue 0.25 0.5 0.75 " ] && pass || fail "fd list rows: $(cut -d, -f1 list.csv | tr '\n' ' ')"
cmp -s range.csv list.csv && cmp -s list.csv list_stream.csv && pass || fail "A:B:STEP, A,B,C and --stream curves differ"
"$bin" -q components ml.nrrd --isovalues 0.25:0.75:0.25 --csv c_range.csv >/dev/null 2>&1 || fail "components A:B:STEP"
"$bin" -q components ml.nrrd --isovalues 0.25,0.5,0.75 --csv c_list.csv >/dev/null 2>&1 || fail "components A,B,C"
[ "$(wc -l <c_list.csv)" -eq 4 ] && cmp -s c_range.csv c_list.csv && pass || fail "components list: $(cat c_list.csv)"
# Integer data counts every integer of a range at once: consecutive integers, or A:B:1.
"$bin" -q fd sp.nrrd --isovalues 100:103:1 --csv i_range.csv >/dev/null 2>&1 || fail "fd integer A:B:1"
"$bin" -q fd sp.nrrd --isovalues 101,100,103,102 --csv i_list.csv >/dev/null 2>&1 || fail "fd integer list"
[ "$(wc -l <i_list.csv)" -eq 5 ] && cmp -s i_range.csv i_list.csv && pass || fail "integer list differs from A:B:1"
expect 2 "clfractal: error: --isovalues '100,110': uint8 data takes consecutive integers \(or A:B:1\)" -- "$bin" fd sp.nrrd --isovalues 100,110
expect 2 "clfractal: error: --isovalues 0.1,zz: 'zz' is not a number" -- "$bin" fd ml.nrrd --isovalues 0.1,zz
expect 0 'isovalues +0.5 1 \(' -- "$bin" -q noise --size 16 --isovalues 0.5,1 --mu 0 --box-samples 64
expect 0 'isovalues +0.5 1 \(' -- "$bin" -q noise --size 16 --isovalues 0.5:1:0.5 --mu 0 --box-samples 64

# ---- defaults in help: every option with a number shows its default (or says what
# happens without it); the shared options are the same in every command that reads a volume.
for c in devices info fd local gen mesh bench smooth noise filter components survey fd4 local4; do
  "$bin" "$c" --help >"help_$c.txt" 2>&1 || fail "$c --help"
  # Help lines of options: "  --name TYPE=DEFAULT  text", wrapped lines joined.
  missing=$(awk '/^  -/ { if (line != "") print line; line = $0; next } /^   / { line = line " " $0; next }
                 END { if (line != "") print line }' "help_$c.txt" |
            grep -E '^ +(-[a-z],)?--[a-z0-9-]+ (INT|UINT|FLOAT)' | grep -vE '=|REQUIRED|default|needed by|with --' || true)
  [ -z "$missing" ] && pass || fail "$c --help: options without a default: $missing"
done
grep -qE -- '--levels INT=2 ' help_fd.txt && grep -qE -- '--clean-fd FLOAT=2.2 ' help_fd.txt && pass || fail "fd --help: $(cat help_fd.txt)"
grep -qE -- '--window INT:EVEN>=2=8 ' help_local.txt && grep -qE -- '--size UINT=128 ' help_gen.txt && pass || fail "defaults missing in local/gen help"
grep -qE -- '--tau FLOAT=1 ' help_smooth.txt && grep -qE -- '--size UINT=256 ' help_bench.txt && pass || fail "defaults missing in smooth/bench help"
for c in info fd local mesh smooth filter components fd4 local4; do
  grep -qE -- '--dims TEXT +raw file dimensions X,Y,Z or XxYxZ' "help_$c.txt" &&
    grep -qE -- '--spacing TEXT=1,1,1' "help_$c.txt" && pass || fail "$c --help lacks the shared raw options"
done

# ---- The memory check before work: a volume whose command would need more memory than is
# available is one error line naming the file, the command and the sizes, exit 2, no output;
# before reading where the header states the size (raw), once read otherwise (synthetic:).
python3 -c "open('mem_64x64x64_uint16.raw', 'wb').write(bytes(64 * 64 * 64 * 2))" || fail "python3 could not write the raw file"
for cmd in "fd" "components" "local --iso 1 -o mem_out.nrrd" "smooth --iso 1 --threshold 2.5 -o mem_out.nrrd" \
           "filter --median -o mem_out.nrrd" "mesh --iso 1 -o mem_out.ply" "report -o mem_out.html" "fd4"; do
  # shellcheck disable=SC2086
  set -- $cmd
  name=$1
  shift
  rm -f mem_out.*
  out=$(CLFRACTAL_MEMORY_LIMIT=200M "$bin" "$name" mem_64x64x64_uint16.raw "$@" 2>&1)
  rc=$?
  [ $rc -eq 2 ] && [ "$(wc -l <<<"$out")" -eq 1 ] &&
    grep -qE "^clfractal: error: mem_64x64x64_uint16.raw: clfractal $name needs about [0-9.]+ MiB of memory \([0-9.]+x the 512.0 KiB volume \+ 256 MiB\), but 200.0 MiB is available" <<<"$out" &&
    ! ls mem_out.* >/dev/null 2>&1 && pass || fail "$name under CLFRACTAL_MEMORY_LIMIT=200M: rc $rc: $out"
done
expect 2 'synthetic:sphere:40: clfractal components needs about 256.2 MiB of memory \(4x the 62.5 KiB volume \+ 256 MiB\), but 1.1 MiB is available' -- \
  env CLFRACTAL_MEMORY_LIMIT=1M "$bin" components synthetic:sphere:40
expect 2 'fd --stream counts within 512 MiB' -- env CLFRACTAL_MEMORY_LIMIT=1M "$bin" fd mem_64x64x64_uint16.raw
expect 0 'mem_64x64x64_uint16.raw' -- env CLFRACTAL_MEMORY_LIMIT=1M "$bin" fd --stream mem_64x64x64_uint16.raw
expect 2 'CLFRACTAL_MEMORY_LIMIT: expected a byte count' -- env CLFRACTAL_MEMORY_LIMIT=lots "$bin" fd mem_64x64x64_uint16.raw
expect 0 'mem_64x64x64_uint16.raw' -- env CLFRACTAL_MEMORY_LIMIT=1T "$bin" fd mem_64x64x64_uint16.raw
expect 0 'mem_64x64x64_uint16.raw' -- env CLFRACTAL_MEMORY_LIMIT=off "$bin" fd mem_64x64x64_uint16.raw

# ---- The device is created while the input is read: its error when the command needs it,
# the input's error (exit 2) when the input fails first; never both, never a crash.
expect 1 'clfractal: error: .*no-such-device-xyz' -- env CLFRACTAL_DEVICE=no-such-device-xyz "$bin" fd mem_64x64x64_uint16.raw
expect 2 'clfractal: error: missing_64x64x64_uint8.raw: no such file' -- \
  env CLFRACTAL_DEVICE=no-such-device-xyz "$bin" fd missing_64x64x64_uint8.raw
CLFRACTAL_DEVICE=no-such-device-xyz "$bin" fd missing_64x64x64_uint8.raw 2>&1 | grep -q no-such-device \
  && fail "an input error also reported the device's" || pass

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
