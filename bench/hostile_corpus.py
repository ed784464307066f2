#!/usr/bin/python3
"""A held-out hostile corpus through every reading command of clfractal.

Generates malformed and edge-case inputs into a temporary folder from the real files of
the shared data folder (NAME_XxYxZ_TYPE.raw volumes, formats/: NIfTI, MetaImage, DICOM):
truncations at many offsets, bit flips, absurd sizes and dimensions, wrong types, huge
header lines, many key/value lines, detached headers naming missing files, FIFOs, folders,
devices and huge sparse files, gzip/zlib mismatches, CR-only headers, NaN/Inf data, field
mutations of each format, zero-length files, folders, FIFOs and /dev/zero as inputs,
names with control characters and paths of over 1000 characters. Each input goes through
every subcommand that reads a volume, `timeout` seconds each, every output into a fresh
folder, and each run is classified:

  crash    killed by a signal, exit status >= 128, or a sanitizer report on stderr
  hang     still running after the timeout twice (a run past it runs once more, its kernels cached)
  partial  a file left in the output folder after a non-zero exit
  message  a failed run whose stderr is not one line naming the input (or holds control
           characters)
  exit     an exit status other than 0 and 2
  inject   a command in the input's name was run (a name holds `touch $CLF_HOSTILE_MARK`)

Prints a table by command and class and every failure; exits 1 when there is any.
Standard library only: run it with /usr/bin/python3.

  bench/hostile_corpus.py --clfractal build/clfractal --data ../shared/data [--jobs 2]
  bench/hostile_corpus.py ... --sample 60 --commands info,fd     (the ctest entry)
"""
import argparse
import collections
import concurrent.futures
import gzip
import json
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

# --------------------------------------------------------------------------- the corpus


class Corpus:
    """Cases as (label, input path); each case has its own folder under root."""

    def __init__(self, root, data):
        self.root = root
        self.data = data
        self.cases = []
        self.rng = random.Random(17)

    def folder(self, label):
        d = os.path.join(self.root, "%04d" % len(self.cases))
        os.makedirs(d)
        return d

    def add(self, label, name, content=None, extra=None):
        """A case whose input is the file `name` (bytes `content`) in a fresh folder;
        `extra` maps other file names of that folder to bytes."""
        d = self.folder(label)
        path = os.path.join(d, name)
        if content is not None:
            with open(path, "wb") as f:
                f.write(content)
        for other, b in (extra or {}).items():
            with open(os.path.join(d, other), "wb") as f:
                f.write(b)
        self.cases.append((label, path))
        return d, path

    def add_path(self, label, path):
        self.cases.append((label, path))


def read(path):
    with open(path, "rb") as f:
        return f.read()


def truncations(b, n, rng, head=0):
    """n cut lengths of b: every few bytes of the first `head`, then spread over the rest."""
    cuts = set([0, 1, len(b) - 1])
    if head:
        for i in range(0, min(head, len(b)), max(1, head // (n // 2))):
            cuts.add(i)
    while len(cuts) < n:
        cuts.add(rng.randrange(len(b)))
    return sorted(c for c in cuts if c < len(b))


def bit_flips(b, n, rng, lo=0, hi=None):
    hi = len(b) if hi is None else hi
    out = []
    for _ in range(n):
        m = bytearray(b)
        i = rng.randrange(lo, hi)
        m[i] ^= 1 << rng.randrange(8)
        out.append((i, bytes(m)))
    return out


# --- NRRD and raw

def crop(raw, dims, vs, sub):
    """The sub-box sub = (nx, ny, nz) at the origin of a raw volume of dims, value size vs."""
    nx, ny, _ = dims
    out = bytearray()
    for z in range(sub[2]):
        for y in range(sub[1]):
            o = ((z * ny + y) * nx) * vs
            out += raw[o:o + sub[0] * vs]
    return bytes(out)


def nrrd_header(fields, keys=()):
    lines = ["NRRD0004"] + ["%s: %s" % kv for kv in fields] + ["%s:=%s" % kv for kv in keys]
    return ("\n".join(lines) + "\n\n").encode()


def nrrd_cases(c):
    d = c.data
    bucky = read(os.path.join(d, "bucky_32x32x32_uint8.raw"))
    small = crop(bucky, (32, 32, 32), 1, (12, 10, 9))
    base = [("type", "uint8"), ("dimension", "3"), ("sizes", "12 10 9"), ("encoding", "raw"),
            ("spacings", "1 1 1")]
    good = nrrd_header(base) + small
    c.add("nrrd: valid attached (reference)", "ok.nrrd", good)
    hdr_len = len(nrrd_header(base))
    for cut in truncations(good, 16, c.rng, head=hdr_len):
        c.add("nrrd: cut at %d" % cut, "cut.nrrd", good[:cut])
    for i, m in bit_flips(good, 12, c.rng, 0, hdr_len):
        c.add("nrrd: header bit flip at %d" % i, "flip.nrrd", m)
    for i, m in bit_flips(good, 2, c.rng, hdr_len):
        c.add("nrrd: data bit flip at %d" % i, "flip.nrrd", m)

    def field(label, key, value, data=small, name="f.nrrd"):
        fields = [(k, value if k == key else v) for k, v in base]
        if key not in dict(base):
            fields.append((key, value))
        c.add("nrrd: %s" % label, name, nrrd_header(fields) + data)

    for v in ["0 10 9", "-1 10 9", "2147483648 2 2", "1e30 1 1", "a b c", "12 10", "12 10 9 1", "12 10 9.5",
              "99999999999999999999 1 1", "1099511627776 1024 1024", "12 10 90", " ", "4294967297 1 1",
              "12 10 9 " + "1 " * 2000]:
        field("sizes %r" % v[:40], "sizes", v)
    for v in ["0", "2", "4", "100", "-3", "x", "16"]:
        field("dimension %s" % v, "dimension", v)
    for v in ["block", "bogus", "double", "float", "short", "long long", "unsigned long long", ""]:
        field("type %r" % v, "type", v)
    for v in ["gzip", "bzip2", "hex", "text", "zstd", "bogus", ""]:
        field("encoding %r (raw data)" % v, "encoding", v)
    for v in ["nan 1 1", "inf 1 1", "0 0 0", "-1 -1 -1", "1 1", "1e400 1 1"]:
        field("spacings %r" % v, "spacings", v)
    for v in ["-1", "99999999999999999", "1e9", "x"]:
        field("byte skip %s" % v, "byte skip", v)
    for v in ["99999999", "-5"]:
        field("line skip %s" % v, "line skip", v)
    field("endian bogus", "endian", "middle")
    field("space directions x1000", "space directions", " ".join(["(1,0,0)"] * 1000))
    field("space directions nan", "space directions", "(nan,0,0) (0,1,0) (0,0,1)")
    field("kinds bogus", "kinds", "domain bogus ???")
    field("content with control characters", "content", "a\x1b[31mred\x07")
    field("1 MB sizes value", "sizes", "12 " * 350000)
    field("float32 with NaN and Inf", "type", "float",
          struct.pack("<%df" % (12 * 10 * 9), *[[float("nan"), float("inf"), -float("inf"), 1.5][i % 4]
                                                 for i in range(12 * 10 * 9)]))
    field("float32 all NaN", "type", "float", struct.pack("<f", float("nan")) * (12 * 10 * 9))
    field("float64 denormals and huge", "type", "double",
          struct.pack("<%dd" % (12 * 10 * 9), *[[5e-324, 1.7e308, -1.7e308, 0.0][i % 4] for i in range(12 * 10 * 9)]))
    field("int32 extremes", "type", "int", struct.pack("<%di" % (12 * 10 * 9),
                                                        *[[-2**31, 2**31 - 1][i % 2] for i in range(12 * 10 * 9)]))
    field("uint8 constant", "type", "uint8", b"\x07" * (12 * 10 * 9))
    field("1x1x1 grid", "sizes", "1 1 1", small[:1])
    field("2x2x2 grid", "sizes", "2 2 2", small[:8])
    field("1x1x1000 grid", "sizes", "1 1 1000", bucky[:1000])
    # whole-header shapes
    h = nrrd_header(base)
    c.add("nrrd: CR-only header", "cr.nrrd", h.replace(b"\n", b"\r") + small)
    c.add("nrrd: CRLF header", "crlf.nrrd", h.replace(b"\n", b"\r\n") + small)
    c.add("nrrd: NUL in a header line", "nul.nrrd", h.replace(b"uint8", b"ui\x00nt8") + small)
    c.add("nrrd: no blank line", "noblank.nrrd", h[:-1] + small)
    c.add("nrrd: header only", "hdr.nrrd", h)
    c.add("nrrd: magic only", "magic.nrrd", b"NRRD0004\n")
    for magic in [b"NRRD0009", b"NRRD0001", b"NRRD", b"nrrd0004", b"\x89NRRD0004"]:
        c.add("nrrd: magic %r" % magic, "m.nrrd", magic + h[8:] + small)
    c.add("nrrd: 1 MiB header line", "long.nrrd", h[:-1] + b"# " + b"x" * (1 << 20) + b"\n\n" + small)
    c.add("nrrd: 100000 key/value lines", "kv.nrrd",
          nrrd_header(base, [("k%d" % i, "v") for i in range(100000)]) + small)
    c.add("nrrd: 20000 comment lines", "comments.nrrd", h[:-1] + b"# c\n" * 20000 + b"\n" + small)
    c.add("nrrd: duplicate sizes", "dup.nrrd", nrrd_header(base + [("sizes", "2 2 2")]) + small)
    c.add("nrrd: unknown field", "unk.nrrd", nrrd_header(base + [("wobble", "1")]) + small)
    c.add("nrrd: field without colon", "nocolon.nrrd", h[:-1] + b"sizes 12 10 9\n\n" + small)
    c.add("nrrd: 9 GB claim in 74 bytes", "claim.nrrd",
          nrrd_header([("type", "uint8"), ("dimension", "3"), ("sizes", "2147483648 2 2"), ("encoding", "raw")]))
    # gzip and zlib
    gz = gzip.compress(small)
    zl = zlib.compress(small)
    gzf = [(k, "gzip" if k == "encoding" else v) for k, v in base]
    gzh = nrrd_header(gzf)
    c.add("nrrd gzip: valid", "gz.nrrd", gzh + gz)
    c.add("nrrd gzip: zlib data declared gzip", "zl.nrrd", gzh + zl)
    c.add("nrrd gzip: raw deflate data", "defl.nrrd", gzh + zl[2:-4])
    c.add("nrrd gzip: two members", "two.nrrd", gzh + gzip.compress(small[:500]) + gzip.compress(small[500:]))
    c.add("nrrd gzip: trailing garbage", "trail.nrrd", gzh + gz + b"garbage" * 10)
    c.add("nrrd gzip: bad CRC", "crc.nrrd", gzh + gz[:-8] + b"\0\0\0\0" + gz[-4:])
    c.add("nrrd gzip: too short for the sizes", "short.nrrd", gzh + gzip.compress(small[:100]))
    for cut in truncations(gz, 8, c.rng):
        c.add("nrrd gzip: cut at %d" % cut, "gzcut.nrrd", gzh + gz[:cut])
    for i, m in bit_flips(gz, 4, c.rng):
        c.add("nrrd gzip: bit flip at %d" % i, "gzflip.nrrd", gzh + m)
    bomb = gzip.compress(b"\0" * (1 << 22))
    c.add("nrrd gzip: 10^12 values claimed", "bomb.nrrd",
          nrrd_header([("type", "uint8"), ("dimension", "3"), ("sizes", "10000 10000 10000"), ("encoding", "gzip")])
          + bomb)
    c.add("nrrd gzip: 4 MiB of zeros for 1080 values", "bomb2.nrrd", gzh + bomb)
    # hex and text encodings
    hexf = [(k, "hex" if k == "encoding" else v) for k, v in base]
    c.add("nrrd hex: valid", "hex.nrrd", nrrd_header(hexf) + small.hex().encode())
    c.add("nrrd hex: odd digit", "hexodd.nrrd", nrrd_header(hexf) + small.hex().encode()[:-1])
    c.add("nrrd hex: not hex", "hexbad.nrrd", nrrd_header(hexf) + b"zz" * len(small))
    txf = [(k, "text" if k == "encoding" else v) for k, v in base]
    c.add("nrrd text: valid", "txt.nrrd", nrrd_header(txf) + " ".join(str(x) for x in small).encode())
    c.add("nrrd text: words", "txtbad.nrrd", nrrd_header(txf) + b"one two three " * 400)
    c.add("nrrd text: too few", "txtfew.nrrd", nrrd_header(txf) + b"1 2 3")
    c.add("nrrd text: 1e999", "txtbig.nrrd", nrrd_header(txf) + b"1e999 " * 1080)

    # detached headers
    real = os.path.join(d, "bucky_32x32x32_uint8.raw")
    det = [("type", "uint8"), ("dimension", "3"), ("sizes", "32 32 32"), ("encoding", "raw")]

    def detached(label, datafile, fields=det, extra=None, setup=None):
        folder, path = c.add("nhdr: " + label, "h.nhdr", nrrd_header(fields + [("data file", datafile)]), extra)
        if setup:
            setup(folder)

    detached("valid, absolute data file", real)
    detached("missing data file", "missing.raw")
    detached("data file is a folder", "sub", setup=lambda f: os.mkdir(os.path.join(f, "sub")))
    detached("data file is a FIFO", "fifo.raw", setup=lambda f: os.mkfifo(os.path.join(f, "fifo.raw")))
    detached("data file /dev/zero", "/dev/zero")
    detached("data file /dev/null", "/dev/null")
    detached("data file /dev/urandom", "/dev/urandom")
    detached("data file a dangling symlink", "dangling.raw",
             setup=lambda f: os.symlink("/nonexistent/x", os.path.join(f, "dangling.raw")))
    detached("data file a symlink to /dev/zero", "z.raw", setup=lambda f: os.symlink("/dev/zero", os.path.join(f, "z.raw")))

    def sparse(f, name="huge.raw", size=10 << 30):
        with open(os.path.join(f, name), "wb") as h:
            h.truncate(size)

    detached("data file a 10 GiB sparse file (32^3 claimed)", "huge.raw", setup=sparse)
    detached("data file the header itself", "h.nhdr")
    detached("data file shorter than claimed", "short.raw", extra={"short.raw": bucky[:1000]})
    detached("data file 1000-character name", "x" * 1000 + ".raw")
    detached("data file 240-character name", "y" * 240 + ".raw")
    detached("data file with control characters", "a\x1b[2Jb.raw")
    detached("data file empty name", "")
    detached("pattern with 2 of 3 pieces", "s%d.raw 0 2 1", [("type", "uint8"), ("dimension", "3"),
                                                             ("sizes", "32 32 3"), ("encoding", "raw")],
             extra={"s0.raw": bucky[:1024], "s1.raw": bucky[1024:2048]})
    piece = {"s%d.raw" % i: bucky[i * 1024:(i + 1) * 1024] for i in range(3)}
    p3 = [("type", "uint8"), ("dimension", "3"), ("sizes", "32 32 3"), ("encoding", "raw")]
    detached("pattern valid", "s%d.raw 0 2 1", p3, extra=piece)
    detached("pattern step 0", "s%d.raw 0 2 0", p3, extra=piece)
    detached("pattern huge range", "s%d.raw 0 999999999 1", p3, extra=piece)
    detached("pattern %n", "%n%n%n%n 0 2 1", p3, extra=piece)
    detached("pattern %s", "%s%s%s 0 2 1", p3, extra=piece)
    detached("pattern %1000000d", "%1000000d 0 2 1", p3, extra=piece)
    detached("pattern negative step", "s%d.raw 2 0 -1", p3, extra=piece)
    folder, path = c.add("nhdr: LIST with a missing piece", "h.nhdr",
                         nrrd_header(p3 + [("data file", "LIST")])[:-1] + b"s0.raw\nmissing.raw\ns2.raw\n", piece)
    c.add("nhdr: LIST of 100000 names", "h.nhdr", nrrd_header(p3 + [("data file", "LIST")])[:-1] +
          b"s0.raw\n" * 100000, piece)
    c.add("nhdr: LIST empty", "h.nhdr", nrrd_header(p3 + [("data file", "LIST")])[:-1])
    gzd = [(k, "gzip" if k == "encoding" else v) for k, v in det]
    detached("gzip declared, raw data file", real, gzd)
    detached("gzip declared, zlib data file", "d.gz", gzd, extra={"d.gz": zlib.compress(bucky)})
    detached("gzip valid", "d.gz", gzd, extra={"d.gz": gzip.compress(bucky)})
    detached("gzip, data file a FIFO", "f.gz", gzd, setup=lambda f: os.mkfifo(os.path.join(f, "f.gz")))
    detached("gzip, 10^12 claimed", "d.gz", [("type", "uint8"), ("dimension", "3"), ("sizes", "10000 10000 10000"),
                                             ("encoding", "gzip")], extra={"d.gz": bomb})
    detached("byte skip -1 with gzip", "d.gz", gzd + [("byte skip", "-1")], extra={"d.gz": gzip.compress(bucky)})
    detached("byte skip past the end", real, det + [("byte skip", "40000")])
    detached("byte skip -1 raw", real, det + [("byte skip", "-1")])
    detached("sizes 4096^3 against the 10 GiB sparse file",
             "huge.raw", [("type", "uint8"), ("dimension", "3"), ("sizes", "4096 4096 4096"), ("encoding", "raw")],
             setup=lambda f: sparse(f, size=1 << 30))

    # NAME_XxYxZ_TYPE.raw
    def raw(label, name, content):
        c.add("raw: " + label, name, content)

    raw("valid 12x10x9", "v_12x10x9_uint8.raw", small)
    raw("one byte short", "v_12x10x9_uint8.raw", small[:-1])
    raw("one byte long", "v_12x10x9_uint8.raw", small + b"\0")
    raw("empty", "v_12x10x9_uint8.raw", b"")
    raw("0x0x0", "v_0x0x0_uint8.raw", b"")
    raw("1x1x1", "v_1x1x1_uint8.raw", b"\x05")
    raw("huge dims", "v_100000x100000x100000_uint8.raw", small)
    raw("2^64 dims", "v_18446744073709551616x1x1_uint8.raw", small)
    raw("unknown type", "v_12x10x9_uint128.raw", small)
    raw("float32 NaN/Inf", "v_12x10x9_float32.raw",
        struct.pack("<%df" % 1080, *[[float("nan"), float("inf"), -1.0, 2.0][i % 4] for i in range(1080)]))
    raw("float64 wrong size", "v_12x10x9_float64.raw", small)
    raw("int16 odd size", "v_12x10x9_int16.raw", small + b"\0")
    raw("negative dims", "v_-12x10x9_uint8.raw", small)
    raw("no dims", "v_uint8.raw", small)
    raw("dims with spaces", "v_12 x10x9_uint8.raw", small)
    folder, _ = c.add("raw: a folder named like a raw volume", "sub", None)
    os.mkdir(os.path.join(folder, "sub"))
    c.cases[-1] = ("raw: a folder named like a raw volume", os.path.join(folder, "d_2x2x2_uint8.raw"))
    os.mkdir(c.cases[-1][1])
    folder, path = c.add("raw: a FIFO named like a raw volume", "f_2x2x2_uint8.raw")
    os.mkfifo(path)
    folder, path = c.add("raw: a symlink to /dev/zero", "z_64x64x64_uint8.raw")
    os.symlink("/dev/zero", path)
    folder, path = c.add("raw: a symlink loop", "loop_2x2x2_uint8.raw")
    os.symlink(path, path)
    folder, path = c.add("raw: a dangling symlink", "dang_2x2x2_uint8.raw")
    os.symlink("/nonexistent", path)
    folder, path = c.add("raw: a 1 GiB sparse file, 2048^3 claimed", "s_2048x2048x2048_uint8.raw")
    sparse(folder, os.path.basename(path), 1 << 30)
    # other real raw volumes, cut
    for name in ["hydrogen_3d_orbital_64x64x64_float32.raw", "walnut_128x96x114_uint16.raw",
                 "m4_totaldensity_31x22x25_float32.raw", "fuel_cropped_64x33x32_uint8.raw"]:
        b = read(os.path.join(d, name))
        for cut in [0, 3, len(b) // 2 + 1, len(b) - 2]:
            raw("%s cut at %d" % (name, cut), name, b[:cut])


# --- NIfTI

def nifti_cases(c):
    d = os.path.join(c.data, "formats")
    nii = gzip.decompress(read(os.path.join(d, "engine.nii.gz")))
    off = int(struct.unpack_from("<f", nii, 108)[0])
    # avg152T1 is big-endian: a small big-endian volume too.
    be = gzip.decompress(read(os.path.join(d, "avg152T1_RL_nifti.nii.gz")))
    be_hdr = bytearray(be[:352])
    struct.pack_into(">8h", be_hdr, 40, 3, 12, 10, 9, 1, 1, 1, 1)
    c.add("nifti: valid small big-endian", "be.nii", bytes(be_hdr) + be[352:352 + 1080])
    for cut in [100, 348, 352, 900]:
        c.add("nifti: big-endian cut at %d" % cut, "be.nii", (bytes(be_hdr) + be[352:352 + 1080])[:cut])
    struct.pack_into(">4h", be_hdr, 40, 3, 32767, 32767, 32767)
    c.add("nifti: big-endian 35 TB claimed", "be.nii", bytes(be_hdr) + be[352:352 + 1080])
    hdr = bytearray(nii[:off])
    # A small valid volume: the same header, dims 12 10 9, the first values of the data.
    struct.pack_into("<8h", hdr, 40, 3, 12, 10, 9, 1, 1, 1, 1)
    vs = struct.unpack_from("<h", hdr, 72)[0] // 8
    small = bytes(hdr) + nii[off:off + 1080 * vs]
    c.add("nifti: valid small (reference)", "ok.nii", small)
    c.add("nifti: valid small .nii.gz", "ok.nii.gz", gzip.compress(small))
    for cut in truncations(small, 14, c.rng, head=352):
        c.add("nifti: cut at %d" % cut, "cut.nii", small[:cut])
    for i, m in bit_flips(small, 12, c.rng, 0, 352):
        c.add("nifti: header bit flip at %d" % i, "flip.nii", m)

    def patch(label, fmt, at, *values, data=small, name="p.nii"):
        m = bytearray(data)
        struct.pack_into(fmt, m, at, *values)
        c.add("nifti: " + label, name, bytes(m))

    for dims in [(0, 12, 10, 9), (8, 12, 10, 9), (-1, 12, 10, 9), (3, 0, 10, 9), (3, -12, 10, 9),
                 (3, 32767, 32767, 32767), (4, 12, 10, 9), (1, 1080, 1, 1), (2, 36, 30, 1), (3, 1, 1, 1)]:
        patch("dim %s" % (dims,), "<4h", 40, *dims)
    patch("dim[4] = 2 (4D)", "<5h", 40, 4, 12, 10, 9, 2)
    for dt, bp in [(0, 8), (128, 24), (2304, 32), (1536, 128), (32, 64), (255, 8), (16, 8), (64, 8), (1, 1),
                   (-1, 8), (2048, 8), (512, 16)]:
        patch("datatype %d bitpix %d" % (dt, bp), "<2h", 70, dt, bp)
    for vo in [-1.0, 0.0, 100.0, 351.0, 353.0, 1e30, float("nan"), float("inf"), 3.5, 1e9]:
        patch("vox_offset %r" % vo, "<f", 108, vo)
    for sz in [0, 347, 540, 1 << 30, -348]:
        patch("sizeof_hdr %d" % sz, "<i", 0, sz)
    for magic in [b"ni1\0", b"n+2\0", b"xxxx", b"\0\0\0\0"]:
        patch("magic %r" % magic, "4s", 344, magic)
    for slope, inter in [(float("nan"), 0.0), (float("inf"), 0.0), (0.0, float("nan")), (1e38, 1e38)]:
        patch("scl %r %r" % (slope, inter), "<2f", 112, slope, inter)
        m = bytearray(small)
        struct.pack_into("<2f", m, 112, slope, inter)
        c.add("nifti: scl %r %r (the path with --scaled)" % (slope, inter), "scaled.nii", bytes(m))
    for px in [(float("nan"),) * 3, (0.0,) * 3, (-1.0,) * 3, (float("inf"),) * 3]:
        patch("pixdim %r" % (px,), "<3f", 80, *px)
    patch("extension flag with a huge esize", "<4b2i", 348, 1, 0, 0, 0, 1 << 30, 4)
    patch("extension flag with esize 0", "<4b2i", 348, 1, 0, 0, 0, 0, 4)
    big = bytearray(small)
    for at, fmt in [(0, "i"), (40, "8h"), (70, "2h")]:
        vals = struct.unpack_from("<" + fmt, big, at)
        struct.pack_into(">" + fmt, big, at, *vals)
    c.add("nifti: partly byte-swapped header", "swap.nii", bytes(big))
    # .nii.gz and .hdr/.img
    gz = gzip.compress(small)
    for cut in truncations(gz, 8, c.rng):
        c.add("nifti gz: cut at %d" % cut, "cut.nii.gz", gz[:cut])
    for i, m in bit_flips(gz, 6, c.rng):
        c.add("nifti gz: bit flip at %d" % i, "flip.nii.gz", m)
    c.add("nifti gz: zlib, not gzip", "z.nii.gz", zlib.compress(small))
    c.add("nifti gz: plain .nii named .nii.gz", "plain.nii.gz", small)
    c.add("nifti: gzip named .nii", "g.nii", gz)
    m = bytearray(small)
    struct.pack_into("<4h", m, 40, 3, 32767, 32767, 32767)
    c.add("nifti gz: 35 TB claimed", "claim.nii.gz", gzip.compress(bytes(m)))
    pair = bytearray(small[:348])
    struct.pack_into("<f", pair, 108, 0.0)
    struct.pack_into("4s", pair, 344, b"ni1\0")
    img = small[off:]
    c.add("nifti pair: valid", "p.hdr", bytes(pair), {"p.img": img})
    c.add("nifti pair: missing .img", "p.hdr", bytes(pair))
    c.add("nifti pair: short .img", "p.hdr", bytes(pair), {"p.img": img[:100]})
    folder, _ = c.add("nifti pair: .img a FIFO", "p.hdr", bytes(pair))
    os.mkfifo(os.path.join(folder, "p.img"))
    folder, _ = c.add("nifti pair: .img a folder", "p.hdr", bytes(pair))
    os.mkdir(os.path.join(folder, "p.img"))
    folder, _ = c.add("nifti pair: .img -> /dev/zero", "p.hdr", bytes(pair))
    os.symlink("/dev/zero", os.path.join(folder, "p.img"))
    c.add("nifti pair: .img named, .hdr missing", "p.img", img)
    # the real files, cut
    for name in ["engine.nii.gz", "avg152T1_RL_nifti.nii.gz"]:
        b = read(os.path.join(d, name))
        for cut in [10, 200, len(b) // 3, len(b) - 9]:
            c.add("nifti gz: %s cut at %d" % (name, cut), name, b[:cut])


# --- MetaImage

def metaimage_cases(c):
    d = os.path.join(c.data, "formats")
    mha = read(os.path.join(d, "3DCT_lung_baseline_small.mha"))
    end = mha.index(b"ElementDataFile = LOCAL\n") + len(b"ElementDataFile = LOCAL\n")
    header, payload = mha[:end].decode(), mha[end:]
    voxels = zlib.decompress(payload)
    # A small valid volume: 12 x 10 x 9 int16.
    small_vals = crop(voxels, (57, 78, 64), 2, (12, 10, 9))

    def mh(fields, data, name="m.mha", label=None, extra=None):
        text = "".join("%s = %s\n" % kv for kv in fields)
        c.add("metaimage: " + (label or name), name, text.encode() + data, extra)

    base = [("ObjectType", "Image"), ("NDims", "3"), ("BinaryData", "True"), ("BinaryDataByteOrderMSB", "False"),
            ("CompressedData", "False"), ("ElementSpacing", "1 1 1"), ("DimSize", "12 10 9"),
            ("ElementType", "MET_SHORT"), ("ElementDataFile", "LOCAL")]

    def with_(key, value, fields=None):
        fields = list(fields or base)
        keys = [k for k, _ in fields]
        if key in keys:
            fields[keys.index(key)] = (key, value)
        else:
            fields.insert(len(fields) - 1, (key, value))
        return fields

    mh(base, small_vals, label="valid small (reference)")
    good = "".join("%s = %s\n" % kv for kv in base).encode() + small_vals
    for cut in truncations(good, 10, c.rng, head=200):
        c.add("metaimage: cut at %d" % cut, "cut.mha", good[:cut])
    for i, m in bit_flips(good, 8, c.rng, 0, 200):
        c.add("metaimage: header bit flip at %d" % i, "flip.mha", m)
    for v in ["0 10 9", "-12 10 9", "12 10", "1e10 1e10 1e10", "4294967296 1 1", "x y z", "12 10 9 2", "2147483647 2 2"]:
        mh(with_("DimSize", v), small_vals, label="DimSize %r" % v)
    for v in ["MET_BOGUS", "MET_CHAR_ARRAY", "MET_STRING", "MET_LONG_LONG", "MET_DOUBLE", "MET_FLOAT", ""]:
        mh(with_("ElementType", v), small_vals, label="ElementType %r" % v)
    for v in ["0", "2", "4", "-1", "1000000"]:
        mh(with_("NDims", v), small_vals, label="NDims %s" % v)
    mh(with_("ElementNumberOfChannels", "3"), small_vals, label="3 channels")
    mh(with_("BinaryDataByteOrderMSB", "True"), small_vals, label="big endian")
    mh(with_("BinaryData", "False"), b"1 2 3 " * 360, label="ASCII data")
    mh(with_("ElementSpacing", "nan nan nan"), small_vals, label="NaN spacing")
    for v in ["-1", "1e300", "99999999999", "x", "-2"]:
        mh(with_("HeaderSize", v), small_vals, label="HeaderSize %s" % v)
    zl = zlib.compress(small_vals)
    comp = with_("CompressedData", "True")
    mh(comp, zl, label="zlib valid")
    mh(with_("CompressedDataSize", str(len(zl)), comp), zl, label="zlib with CompressedDataSize")
    mh(with_("CompressedDataSize", "99999999999", comp), zl, label="CompressedDataSize huge")
    mh(with_("CompressedDataSize", "-5", comp), zl, label="CompressedDataSize negative")
    mh(with_("CompressedDataSize", "1.5", comp), zl, label="CompressedDataSize 1.5")
    mh(comp, small_vals, label="raw data declared compressed")
    mh(comp, gzip.compress(small_vals), label="gzip data declared compressed")
    mh(comp, zl[:len(zl) // 2], label="zlib cut")
    mh(with_("DimSize", "5000 5000 5000", comp), zlib.compress(b"\0" * (1 << 22)), label="zlib bomb claim")
    mh(base, small_vals[:100], label="short data")
    mh(base[:-1] + [("ElementDataFile", "LOCAL")] + [("Extra", "x")], small_vals, label="field after the data file")
    mh([("ObjectType", "Image")] + [("K%d" % i, "v") for i in range(20000)] + base[1:], small_vals,
       label="20000 lines")
    mh(with_("Comment", "x" * (1 << 20)), small_vals, label="1 MiB line")
    mh(with_("Comment", "a\x1b[31mb\x07"), small_vals, label="control characters")
    text = "".join("%s = %s\n" % kv for kv in base)
    c.add("metaimage: CR-only header", "cr.mha", text.replace("\n", "\r").encode() + small_vals)
    c.add("metaimage: CRLF header", "crlf.mha", text.replace("\n", "\r\n").encode() + small_vals)
    c.add("metaimage: no '='", "noeq.mha", text.replace(" = ", " ").encode() + small_vals)
    # detached .mhd
    det = base[:-1]

    def mhd(label, datafile, fields=det, extra=None, setup=None):
        text = "".join("%s = %s\n" % kv for kv in fields + [("ElementDataFile", datafile)])
        folder, _ = c.add("mhd: " + label, "m.mhd", text.encode(), extra)
        if setup:
            setup(folder)

    mhd("valid", "d.raw", extra={"d.raw": small_vals})
    mhd("missing data file", "missing.raw")
    mhd("data file a folder", "sub", setup=lambda f: os.mkdir(os.path.join(f, "sub")))
    mhd("data file a FIFO", "f.raw", setup=lambda f: os.mkfifo(os.path.join(f, "f.raw")))
    mhd("data file /dev/zero", "/dev/zero")
    mhd("data file itself", "m.mhd")
    mhd("data file short", "d.raw", extra={"d.raw": small_vals[:10]})
    mhd("data file 1000-character name", "q" * 1000)
    mhd("LIST", "LIST", extra={"d.raw": small_vals})
    mhd("pattern", "s%03d.raw 1 9 1", extra={"s001.raw": small_vals[:240]})
    mhd("pattern %n", "%n%n 1 9 1")
    mhd("huge sparse data file", "h.raw", with_("DimSize", "4096 4096 4096", det),
        setup=lambda f: open(os.path.join(f, "h.raw"), "wb").truncate(1 << 30))
    # the real file, cut and flipped
    for cut in [50, end - 5, end + 10, len(mha) // 2, len(mha) - 3]:
        c.add("metaimage: real file cut at %d" % cut, "lung.mha", mha[:cut])
    for i, m in bit_flips(mha, 4, c.rng, end, end + 400):
        c.add("metaimage: real file zlib bit flip at %d" % i, "lung.mha", m)


# --- DICOM

def dicom_elements(b):
    """(offset, group, element, vr, header, length) of the explicit-VR LE elements of a Part 10 file."""
    out, p = [], 132
    while p + 8 <= len(b):
        g, e = struct.unpack_from("<HH", b, p)
        vr = b[p + 4:p + 6]
        if vr in (b"OB", b"OW", b"SQ", b"UN", b"UT", b"OF"):
            h, ln = 12, struct.unpack_from("<I", b, p + 8)[0]
        else:
            h, ln = 8, struct.unpack_from("<H", b, p + 6)[0]
        out.append((p, g, e, vr, h, ln))
        if ln == 0xFFFFFFFF:
            break
        p += h + ln
    return out


def dicom_cases(c):
    d = os.path.join(c.data, "formats", "dicom_ct_phantom")
    files = sorted(f for f in os.listdir(d) if not f.startswith("."))
    full = read(os.path.join(d, files[0]))
    els = dicom_elements(full)

    def find(g, e):
        return next(x for x in els if x[1] == g and x[2] == e)

    # A small slice: Rows = Columns = 16, the first 512 bytes of the pixel data.
    def shrink(b, n=16):
        es = dicom_elements(b)
        m = bytearray(b)
        for (p, g, e, vr, h, ln) in es:
            if (g, e) in ((0x0028, 0x0010), (0x0028, 0x0011)):
                struct.pack_into("<H", m, p + 8, n)
        p, g, e, vr, h, ln = next(x for x in es if x[1] == 0x7FE0)
        struct.pack_into("<I", m, p + 8, n * n * 2)
        return bytes(m[:p + h + n * n * 2])

    small = shrink(full)
    c.add("dicom: valid small slice (reference)", "s.dcm", small)
    series = {"s%d.dcm" % i: shrink(read(os.path.join(d, f))) for i, f in enumerate(files[:3]) if f.startswith("I")}
    folder, _ = c.add("dicom: valid small series (reference)", "s0.dcm", None, series)
    c.add_path("dicom: valid small series, the folder", folder)
    for cut in truncations(small, 20, c.rng, head=2000):
        c.add("dicom: cut at %d" % cut, "cut.dcm", small[:cut])
    for i, m in bit_flips(small, 12, c.rng, 128, len(small) - 512):
        c.add("dicom: header bit flip at %d" % i, "flip.dcm", m)
    for i, m in bit_flips(small, 2, c.rng, len(small) - 512):
        c.add("dicom: pixel bit flip at %d" % i, "flip.dcm", m)
    sm_els = dicom_elements(small)

    def patch(label, g, e, value, data=small, name="p.dcm"):
        p, _, _, vr, h, ln = next(x for x in dicom_elements(data) if x[1] == g and x[2] == e)
        m = bytearray(data)
        if isinstance(value, int):
            struct.pack_into("<H", m, p + h, value)
        else:
            v = value + (b" " if len(value) % 2 else b"")
            m[p + h:p + h + ln] = v
            if h == 8:
                struct.pack_into("<H", m, p + 6, len(v))
            else:
                struct.pack_into("<I", m, p + 8, len(v))
        c.add("dicom: " + label, name, bytes(m))

    for rows in [0, 1, 17, 512, 65535]:
        patch("Rows %d" % rows, 0x0028, 0x0010, rows)
    for cols in [0, 65535]:
        patch("Columns %d" % cols, 0x0028, 0x0011, cols)
    for bits in [0, 1, 7, 8, 12, 32, 64, 65535]:
        patch("BitsAllocated %d" % bits, 0x0028, 0x0100, bits)
    for bits in [0, 17, 40]:
        patch("BitsStored %d" % bits, 0x0028, 0x0101, bits)
    for hb in [16, 200]:
        patch("HighBit %d" % hb, 0x0028, 0x0102, hb)
    for spp in [0, 3, 4, 5, 65535]:
        patch("SamplesPerPixel %d" % spp, 0x0028, 0x0002, spp)
    for pr in [1, 2, 65535]:
        patch("PixelRepresentation %d" % pr, 0x0028, 0x0103, pr)
    for photo in [b"RGB", b"PALETTE COLOR", b"YBR_FULL", b"\x1b[31m"]:
        patch("PhotometricInterpretation %r" % photo, 0x0028, 0x0004, photo)
    for slope in [b"nan", b"inf", b"0", b"1e400", b"abc", b"-1e38"]:
        patch("RescaleSlope %r" % slope, 0x0028, 0x1053, slope)
    for ts in [b"1.2.840.10008.1.2", b"1.2.840.10008.1.2.2", b"1.2.840.10008.1.2.1.99", b"1.2.840.10008.1.2.4.50",
               b"1.2.840.10008.1.2.4.90", b"1.2.840.10008.1.2.5", b"9.9.9", b"", b"1.2.840.10008.1.2.4.70"]:
        patch("transfer syntax %r" % ts, 0x0002, 0x0010, ts + b"\0")
    for pos in [b"nan\\nan\\nan", b"", b"1\\2", b"1e400\\0\\0"]:
        patch("ImagePositionPatient %r" % pos, 0x0020, 0x0032, pos)
    for ori in [b"0\\0\\0\\0\\0\\0", b"nan\\0\\0\\0\\1\\0", b"1\\0\\0\\1\\0\\0"]:
        patch("ImageOrientationPatient %r" % ori, 0x0020, 0x0037, ori)
    patch("NumberOfFrames 1000", 0x0020, 0x0013, b"1")  # instance number (kept) ...
    m = bytearray(small)
    p = find(0x0028, 0x0010)[0]
    # Insert NumberOfFrames (0028,0008) IS "1000" before Rows.
    m[p:p] = struct.pack("<HH2sH", 0x0028, 0x0008, b"IS", 4) + b"1000"
    c.add("dicom: NumberOfFrames 1000", "frames.dcm", bytes(m))
    # element length fields
    for (p, g, e, vr, h, ln) in sm_els[::4]:
        for newlen in ([0xFFFFFFFF, 0x7FFFFFFF, ln + 1] if h == 12 else [0xFFFF, ln + 1]):
            m = bytearray(small)
            if h == 12:
                struct.pack_into("<I", m, p + 8, newlen)
            else:
                struct.pack_into("<H", m, p + 6, newlen)
            c.add("dicom: (%04x,%04x) length %d" % (g, e, newlen), "len.dcm", bytes(m))
    for (p, g, e, vr, h, ln) in sm_els[1::7]:
        for newvr in [b"ZZ", b"\0\0", b"SQ", b"OB"]:
            m = bytearray(small)
            m[p + 4:p + 6] = newvr
            c.add("dicom: (%04x,%04x) VR %r" % (g, e, newvr), "vr.dcm", bytes(m))
    m = bytearray(small)
    struct.pack_into("<H", m, 132, 0x0028)
    c.add("dicom: first meta element in group 0028", "g.dcm", bytes(m))
    m = bytearray(small)
    m[128:132] = b"DICX"
    c.add("dicom: no DICM preamble", "nop.dcm", bytes(m))
    c.add("dicom: data set without preamble", "raw.dcm", small[132:])
    c.add("dicom: preamble only", "pre.dcm", small[:132])
    slow = "/work/notes/fuzz2_slow_dicom.dcm"
    if os.path.exists(slow):
        c.add("dicom: implicit VR read as explicit (0.8 GB scan)", "slow.dcm", read(slow))
    # implicit VR data set: the transfer syntax says implicit, the data stay explicit
    # series shapes
    a, b2, c3 = [series[k] for k in sorted(series)]
    c.add("dicom series: one file cut", "s0.dcm", None, {"s0.dcm": a, "s1.dcm": b2[:700], "s2.dcm": c3})
    c.add_path("dicom series: one file cut, the folder", os.path.dirname(c.cases[-1][1]))
    mb = bytearray(b2)
    struct.pack_into("<H", mb, next(x for x in dicom_elements(b2) if x[2] == 0x0010 and x[1] == 0x28)[0] + 8, 8)
    folder, _ = c.add("dicom series: Rows differ", "s0.dcm", None, {"s0.dcm": a, "s1.dcm": bytes(mb), "s2.dcm": c3})
    c.add_path("dicom series: Rows differ, the folder", folder)
    folder, _ = c.add("dicom series: two equal positions", "s0.dcm", None, {"s0.dcm": a, "s1.dcm": a, "s2.dcm": c3})
    c.add_path("dicom series: duplicate slice, the folder", folder)
    folder, _ = c.add("dicom series: a FIFO among the files", "s0.dcm", None, series)
    os.mkfifo(os.path.join(folder, "fifo.dcm"))
    c.add_path("dicom series: a FIFO among the files, the folder", folder)
    folder, _ = c.add("dicom series: a folder named .dcm", "s0.dcm", None, series)
    os.mkdir(os.path.join(folder, "sub.dcm"))
    folder, _ = c.add("dicom series: junk .dcm among the files", "s0.dcm", None, dict(series, **{"junk.dcm": b"x" * 300}))
    c.add_path("dicom series: junk .dcm, the folder", folder)
    folder = c.folder("dicom: empty folder")
    c.add_path("dicom: empty folder", folder)
    # the real slice, cut
    for cut in [140, 2000, len(full) // 2, len(full) - 1]:
        c.add("dicom: real slice cut at %d" % cut, "real.dcm", full[:cut])


# --- TIFF (written here from the real bucky volume: libtiff's own layout)

def tiff_bytes(pages, w, h, order="<", bits=8, compression=1, extra=None, override=None):
    """A multi-page greyscale TIFF of `pages` (each w*h*bits/8 bytes), one strip per page."""
    out = bytearray(b"II*\0" if order == "<" else b"MM\0*")
    out += struct.pack(order + "I", 0)
    ifd_at = []
    offs = []
    for p in pages:
        offs.append(len(out))
        out += p
        if len(out) % 2:
            out += b"\0"
    for i, p in enumerate(pages):
        tags = {256: (4, w), 257: (4, h), 258: (3, bits), 259: (3, compression), 262: (3, 1), 273: (4, offs[i]),
                277: (3, 1), 278: (4, h), 279: (4, len(p)), 284: (3, 1)}
        tags.update(extra or {})
        if override:
            tags.update(override(i))
        ifd_at.append(len(out))
        out += struct.pack(order + "H", len(tags))
        for tag in sorted(tags):
            typ, val = tags[tag]
            if typ == 3:
                out += struct.pack(order + "HHIHH", tag, 3, 1, val & 0xFFFF, 0)
            else:
                out += struct.pack(order + "HHII", tag, typ, 1, val & 0xFFFFFFFF)
        out += struct.pack(order + "I", 0)
    struct.pack_into(order + "I", out, 4, ifd_at[0])
    for i in range(len(ifd_at) - 1):
        n = struct.unpack_from(order + "H", out, ifd_at[i])[0]
        struct.pack_into(order + "I", out, ifd_at[i] + 2 + 12 * n, ifd_at[i + 1])
    return bytes(out), ifd_at


def tiff_cases(c):
    bucky = read(os.path.join(c.data, "bucky_32x32x32_uint8.raw"))
    vol = crop(bucky, (32, 32, 32), 1, (12, 10, 9))
    pages = [vol[z * 120:(z + 1) * 120] for z in range(9)]
    good, ifds = tiff_bytes(pages, 12, 10)
    c.add("tiff: valid 9 pages (reference)", "ok.tif", good)
    c.add("tiff: valid big-endian", "mm.tif", tiff_bytes(pages, 12, 10, ">")[0])
    for cut in truncations(good, 10, c.rng):
        c.add("tiff: cut at %d" % cut, "cut.tif", good[:cut])
    for i, m in bit_flips(good, 10, c.rng, ifds[0] - 8, len(good)):
        c.add("tiff: IFD bit flip at %d" % i, "flip.tif", m)
    for tag, val in [(256, 0), (256, 0xFFFFFFFF), (257, 0), (257, 1 << 30), (258, 3), (258, 64), (258, 0),
                     (259, 5), (259, 7), (259, 8), (259, 32773), (259, 34712), (259, 50000), (262, 2),
                     (273, 0xFFFFFF00), (279, 0xFFFFFFF0), (279, 0), (277, 3), (277, 0), (278, 0),
                     (284, 2), (339, 3), (339, 9)]:
        c.add("tiff: tag %d = %d" % (tag, val), "t.tif", tiff_bytes(pages, 12, 10, extra={tag: (3 if val < 65536 and
                                                                                                 tag in (258, 259, 262, 277, 284, 339) else 4, val)})[0])
    c.add("tiff: tiles larger than the page", "tile.tif",
          tiff_bytes(pages, 12, 10, extra={322: (4, 1 << 20), 323: (4, 1 << 20), 324: (4, 8), 325: (4, 120)})[0])
    c.add("tiff: pages of different sizes", "diff.tif",
          tiff_bytes(pages, 12, 10, override=lambda i: {256: (4, 6)} if i == 3 else {})[0])
    c.add("tiff: float32 NaN pages", "f.tif",
          tiff_bytes([struct.pack("<120f", *([float("nan"), float("inf")] * 60))] * 4, 12, 10, bits=32,
                     extra={339: (3, 3)})[0])
    loop = bytearray(good)
    n = struct.unpack_from("<H", loop, ifds[1])[0]
    struct.pack_into("<I", loop, ifds[1] + 2 + 12 * n, ifds[0])  # page 2 -> page 1: a cycle
    c.add("tiff: IFD cycle", "loop.tif", bytes(loop))
    self_loop = bytearray(good)
    n = struct.unpack_from("<H", self_loop, ifds[0])[0]
    struct.pack_into("<I", self_loop, ifds[0] + 2 + 12 * n, ifds[0])
    c.add("tiff: IFD pointing at itself", "self.tif", bytes(self_loop))
    many = bytearray(good)
    struct.pack_into("<H", many, ifds[0], 65535)
    c.add("tiff: 65535 IFD entries", "many.tif", bytes(many))
    c.add("tiff: first IFD past the end", "past.tif", good[:4] + struct.pack("<I", 1 << 30) + good[8:])
    c.add("tiff: BigTIFF magic", "big.tif", b"II+\0" + good[4:])
    c.add("tiff: LZW data that is raw", "lzw.tif", tiff_bytes(pages, 12, 10, compression=5)[0])
    c.add("tiff: deflate bomb claim", "bomb.tif",
          tiff_bytes([zlib.compress(b"\0" * 200000)], 100000, 100000, compression=8)[0])
    folder, _ = c.add("tiff: a folder of slices", "s0.tif", None,
                      {"s%d.tif" % z: tiff_bytes([pages[z]], 12, 10)[0] for z in range(9)})
    c.add_path("tiff: a folder of slices, the folder", folder)
    folder, _ = c.add("tiff: a folder of slices, one cut", "s0.tif", None,
                      dict({"s%d.tif" % z: tiff_bytes([pages[z]], 12, 10)[0] for z in range(9)},
                           **{"s4.tif": tiff_bytes([pages[4]], 12, 10)[0][:50]}))
    c.add_path("tiff: a folder of slices, one cut, the folder", folder)


# --- special files and names

def special_cases(c):
    bucky = read(os.path.join(c.data, "bucky_32x32x32_uint8.raw"))
    small = crop(bucky, (32, 32, 32), 1, (12, 10, 9))
    for ext in [".nrrd", ".nhdr", ".nii", ".nii.gz", ".hdr", ".mha", ".mhd", ".dcm", ".tif", ".tiff",
                "_4x4x4_uint8.raw", ".raw", "", ".txt", ".img"]:
        c.add("zero-length file %r" % ext, "empty" + ext, b"")
    for ext in [".nrrd", ".nii", ".nii.gz", ".mha", ".dcm", ".tif", "_4x4x4_uint8.raw", ""]:
        folder, path = c.add("FIFO as input %r" % ext, "fifo" + ext)
        os.mkfifo(path)
    for ext in [".nrrd", ".nii", ".mha", ".tif", ".dcm"]:
        folder, path = c.add("folder as input %r" % ext, "dir" + ext)
        os.mkdir(path)
    c.add_path("/dev/zero as input", "/dev/zero")
    c.add_path("/dev/null as input", "/dev/null")
    c.add_path("/dev/urandom as input", "/dev/urandom")
    c.add_path("missing file", os.path.join(c.root, "no", "such_4x4x4_uint8.raw"))
    c.add_path("empty name", "")
    for ext in [".nrrd", ".nii", ".mha", ".tif"]:
        c.add("random bytes %s" % ext, "rand" + ext, bytes(c.rng.randrange(256) for _ in range(3000)))
        c.add("text file named %s" % ext, "text" + ext, b"hello world\n" * 100)
    good = nrrd_header([("type", "uint8"), ("dimension", "3"), ("sizes", "12 10 9"), ("encoding", "raw")]) + small
    names = ["a\nb.nrrd", "\x1b[31mred\x1b[0m.nrrd", "tab\there.nrrd", "x`touch $CLF_HOSTILE_MARK`.nrrd",
             "a\rb.nrrd", "bell\x07.nrrd",
             "-starts-with-dash.nrrd", "sp ace.nrrd", "quote\"'.nrrd", "\u00e9t\u00e9.nrrd", "back\\slash.nrrd"]
    for i, name in enumerate(names):
        if i < 4:
            c.add("name %r (valid NRRD)" % name, name, good)
        c.add("name %r (cut NRRD)" % name, name, good[:40])
    # paths of 1000+ characters
    for label, content in [("valid NRRD", good), ("cut NRRD", good[:40]), ("raw, short", small[:5])]:
        folder = c.folder("long path")
        p = folder
        for i in range(5):
            p = os.path.join(p, chr(ord("a") + i) * 220)
        os.makedirs(p)
        name = "v_12x10x9_uint8.raw" if label.startswith("raw") else "v.nrrd"
        path = os.path.join(p, name)
        with open(path, "wb") as f:
            f.write(content)
        c.add_path("path of %d characters (%s)" % (len(path), label), path)
    # synthetic specs
    for spec in ["synthetic:", "synthetic:bogus", "synthetic:sphere:0", "synthetic:sphere:99999999",
                 "synthetic:sphere:-5", "synthetic:sphere:abc"]:
        c.add_path("spec %r" % spec, spec)


def build_corpus(root, data):
    c = Corpus(root, data)
    for gen in (nrrd_cases, nifti_cases, metaimage_cases, dicom_cases, tiff_cases, special_cases):
        gen(c)
    return c.cases


# --------------------------------------------------------------------------- the runs

COMMANDS = collections.OrderedDict([
    ("info", lambda v, o: ["info", v]),
    ("fd", lambda v, o: ["fd", v, "--csv", o + "/a.csv", "--json", o + "/a.json", "--plot", o + "/a.png"]),
    ("fd-stream", lambda v, o: ["fd", v, "--stream", "--csv", o + "/a.csv", "--json", o + "/a.json"]),
    ("components", lambda v, o: ["components", v, "--csv", o + "/c.csv", "--plot", o + "/c.png"]),
    ("components-stream", lambda v, o: ["components", v, "--stream", "--isovalues", "100:101:1", "--csv", o + "/c.csv"]),
    ("local", lambda v, o: ["local", v, "--iso", "100", "-o", o + "/l.nrrd", "--mesh", o + "/l.ply"]),
    ("local-stream", lambda v, o: ["local", v, "--iso", "100", "--stream", "-o", o + "/l.nrrd"]),
    ("filter", lambda v, o: ["filter", v, "--median", "-o", o + "/f.nrrd", "--json", o + "/f.json"]),
    ("filter-stream", lambda v, o: ["filter", v, "--median", "--fractal", "--iso", "100", "--threshold", "2.3",
                                    "--stream", "-o", o + "/f.nrrd"]),
    ("smooth", lambda v, o: ["smooth", v, "--iso", "100", "--threshold", "2.3", "-o", o + "/s.nrrd"]),
    ("mesh", lambda v, o: ["mesh", v, "--iso", "100", "-o", o + "/m.ply", "--preview", o + "/m.png"]),
    ("noise", lambda v, o: ["noise", "--volume", v, "--iso", "100", "--mu", "0,2", "--box-samples", "200",
                            "--json", o + "/n.json", "--plot", o + "/n.png"]),
    ("report", lambda v, o: ["report", v, "-o", o + "/r.html", "--json", o + "/r.json"]),
    ("fd4", lambda v, o: ["fd4", v, "--json", o + "/d.json"]),
    ("local4", lambda v, o: ["local4", v, "-o", o + "/l4.nrrd"]),
    ("survey", lambda v, o: ["survey", v, "--csv", o + "/s.csv"]),
])

SANITIZER = re.compile(r"AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|ThreadSanitizer|runtime error:")
CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def printable(s):
    return CONTROL.sub("?", s)


def names_input(message, path):
    """Whether a message names the input: its path or file name (control characters as
    '?'), or for a folder or a file of a DICOM series the folder."""
    if not path:
        return True
    cands = [path, os.path.basename(path.rstrip("/"))]
    if os.path.isdir(path) or path.endswith(".dcm"):
        cands.append(os.path.dirname(path) if path.endswith(".dcm") else path)
    msg = message
    for cand in cands:
        if cand and (cand in msg or printable(cand) in msg):
            return True
    return False


def capi_child(lib, path):
    """The C ABI's reader on one input, in its own process: clf_volume_read, then the
    dimensions of what it read. Exit 0 (read), 2 (refused, clf_last_error() on stderr) or
    1 (a failure the caller reports)."""
    import ctypes
    so = ctypes.CDLL(lib)
    so.clf_last_error.restype = ctypes.c_char_p
    vol = ctypes.c_void_p()
    st = so.clf_volume_read(path.encode("utf-8", "surrogateescape"), ctypes.byref(vol))
    if st != 0:
        sys.stderr.write((so.clf_last_error() or b"").decode("utf-8", "replace") + "\n")
        return 2 if not vol.value else 1
    dims = (ctypes.c_size_t * 3)()
    so.clf_volume_dims(vol, dims)
    so.clf_volume_destroy(vol)
    return 0 if dims[0] * dims[1] * dims[2] > 0 else 1


def run_one(binary, env, command, label, path, timeout, outroot, index, retried=False):
    if command == "survey" and path.startswith(outroot.rsplit("/", 1)[0]) and not os.path.isdir(path):
        path = os.path.dirname(path)  # survey reads a folder: the input's own
    out = os.path.join(outroot, "%06d" % index)
    os.makedirs(out)
    if command == "capi":  # binary: the library
        argv = [sys.executable, os.path.abspath(__file__), "--capi-child", binary, path]
    else:
        argv = [binary, "-q"] + COMMANDS[command](path, out)
    t0 = time.monotonic()
    mark = out + ".injected"
    p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         env=dict(env, CLF_HOSTILE_MARK=mark), start_new_session=True, cwd=out)
    try:
        so, se = p.communicate(timeout=timeout)
        hung = False
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        so, se = p.communicate()
        hung = True
    seconds = time.monotonic() - t0
    if hung and not retried:
        # A first run on a cold program cache compiles its kernels (seconds each on a loaded
        # machine); a run past the timeout is run once more, with them cached, and only a
        # second run past it is a hang.
        shutil.rmtree(out, ignore_errors=True)
        return run_one(binary, env, command, label, path, timeout, outroot, index, retried=True)
    rc = p.returncode
    err = se.decode("utf-8", "replace")
    classes = []
    if os.path.exists(mark):
        classes.append("inject")
        os.remove(mark)
    if hung:
        classes.append("hang")
    elif rc < 0 or rc >= 128 or SANITIZER.search(err):
        classes.append("crash")
    else:
        if rc not in (0, 2):
            classes.append("exit")
        if rc != 0:
            left = sorted(os.listdir(out))
            if left:
                classes.append("partial")
            body = err[:-1] if err.endswith("\n") else err
            if "\n" in body or not body or CONTROL.search(body) or not names_input(body, path):
                classes.append("message")
    shutil.rmtree(out, ignore_errors=True)
    return dict(command=command, label=label, path=path, rc=rc, seconds=seconds, classes=classes,
                stderr=err[-600:])


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--capi-child":
        return capi_child(sys.argv[2], sys.argv[3])
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--clfractal", required=True, help="the clfractal binary")
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data"),
                    help="the shared data folder (NAME_XxYxZ_TYPE.raw files and formats/)")
    ap.add_argument("--commands", default=",".join(COMMANDS), help="subcommands to run (default: all)")
    ap.add_argument("--sample", type=int, default=0, help="run an evenly spread sample of this many inputs")
    ap.add_argument("--match", help="run only the inputs whose label matches this regular expression")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--keep", help="generate the corpus into this folder and keep it")
    ap.add_argument("--list", action="store_true", help="list the inputs and stop")
    ap.add_argument("--log", help="write every run as a JSON line to this file")
    ap.add_argument("--capi", help="also read every input through the C ABI of this libclfractal.so")
    a = ap.parse_args()
    if not os.path.isdir(os.path.join(a.data, "formats")):
        print("hostile_corpus: no shared data at %s: skipped" % a.data)
        return 77
    commands = [x for x in a.commands.split(",") if x]
    for x in commands:
        if x not in COMMANDS:
            ap.error("unknown command %s (known: %s)" % (x, ", ".join(COMMANDS)))
    t_start = time.monotonic()
    root = a.keep or tempfile.mkdtemp(prefix="clfractal-hostile-")
    os.makedirs(root, exist_ok=True)
    try:
        corpus = os.path.join(root, "corpus")
        outroot = os.path.join(root, "out")
        shutil.rmtree(corpus, ignore_errors=True)
        shutil.rmtree(outroot, ignore_errors=True)
        cases = build_corpus(corpus, a.data)
        total = len(cases)
        if a.match:
            cases = [(label, path) for label, path in cases if re.search(a.match, label)]
        if a.sample and a.sample < len(cases):
            step = len(cases) / a.sample
            cases = [cases[int(i * step)] for i in range(a.sample)]
        if a.list:
            for label, path in cases:
                print("%-60s %s" % (label[:60], printable(path)))
            return 0
        env = dict(os.environ)
        cache = os.path.join(os.path.dirname(os.path.abspath(a.clfractal)), "pocl-cache")
        if "POCL_CACHE_DIR" not in env and os.path.isdir(cache):
            env["POCL_CACHE_DIR"] = cache
        env.setdefault("ASAN_OPTIONS", "detect_leaks=0")
        jobs = [(cmd, label, path) for label, path in cases for cmd in commands]
        if a.capi:
            commands.append("capi")
            jobs += [("capi", label, path) for label, path in cases]
        print("hostile corpus: %d inputs generated, %d run through %d commands = %d runs (timeout %g s, %d jobs)"
              % (total, len(cases), len(commands), len(jobs), a.timeout, a.jobs), flush=True)
        results = []
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
            futs = [pool.submit(run_one, os.path.abspath(a.capi if cmd == "capi" else a.clfractal), env, cmd, label,
                                path, a.timeout, outroot, i)
                    for i, (cmd, label, path) in enumerate(jobs)]
            for f in futs:
                results.append(f.result())
        if a.log:
            with open(a.log, "w") as f:
                for r in results:
                    f.write(json.dumps(r) + "\n")
        # the table
        kinds = ["ok", "refused", "crash", "hang", "partial", "message", "exit", "inject"]
        table = collections.OrderedDict((cmd, collections.Counter()) for cmd in commands)
        slowest = collections.OrderedDict((cmd, 0.0) for cmd in commands)
        for r in results:
            t = table[r["command"]]
            t["ok" if r["rc"] == 0 else "refused"] += 1
            for k in r["classes"]:
                t[k] += 1
            slowest[r["command"]] = max(slowest[r["command"]], r["seconds"])
        print("\n%-14s" % "command" + "".join("%9s" % k for k in kinds) + "  slowest s")
        for cmd, t in table.items():
            print("%-14s" % cmd + "".join("%9d" % t[k] for k in kinds) + "%11.2f" % slowest[cmd])
        failures = [r for r in results if r["classes"]]
        by_class = collections.Counter(k for r in failures for k in r["classes"])
        print("\n%d inputs, %d runs, %d failing runs %s, %.0f s" %
              (len(cases), len(results), len(failures), dict(by_class), time.monotonic() - t_start))
        for r in failures:
            print("FAIL %s [%s] %s: %s (rc %s, %.1f s)\n     stderr: %s" %
                  ("/".join(r["classes"]), r["command"], r["label"], printable(r["path"])[-120:], r["rc"],
                   r["seconds"], printable(r["stderr"].strip())[:400]))
        return 1 if failures else 0
    finally:
        if not a.keep:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
