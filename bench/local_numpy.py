#!/usr/bin/env python3
"""The local fractal dimension field (docs/definitions.md §13, thesis eq. 2.6) with numpy: the
peer of `clfractal local` in the benchmark (bench/local_bench.py).

The same definition, written the way a careful numpy user would: the cube spans from the
eight corner views, the 0/1 indicator zero-padded in front on every axis, three cumsums for
the summed-area table, and the box counts of all vertices as separable differences of
`take`s along each axis (no per-vertex Python).

    local_numpy.py VOLUME.nrrd --iso S [--window K] [--repeats R] [--compare LD.nrrd]

times the field (best of R, file reading excluded) and, with --compare, checks a field
written by `clfractal local` against it: the same NaN pattern and values within 1e-6.
"""
import argparse
import json
import math
import sys
import time

import numpy as np

NRRD_TYPES = {"uchar": np.uint8, "unsigned char": np.uint8, "uint8": np.uint8,
              "ushort": np.uint16, "unsigned short": np.uint16, "uint16": np.uint16,
              "short": np.int16, "int16": np.int16, "float": np.float32}


def read_nrrd(path):
    """A NRRD with an attached header and raw encoding (what `clfractal gen` and
    `clfractal local` write) as a (nz, ny, nx) array."""
    with open(path, "rb") as f:
        data = f.read()
    head, body = data.split(b"\n\n", 1)
    fields = {}
    for line in head.decode().splitlines()[1:]:
        if ":" in line and not line.startswith("#"):
            key, value = line.split(":", 1)
            fields[key.strip()] = value.strip()
    if fields.get("encoding", "raw") != "raw":
        raise SystemExit(f"{path}: only raw NRRD encoding is read here")
    dtype = np.dtype(NRRD_TYPES[fields["type"]])
    dtype = dtype.newbyteorder("<" if fields.get("endian", "little") == "little" else ">")
    nx, ny, nz = (int(s) for s in fields["sizes"].split())
    return np.frombuffer(body, dtype=dtype, count=nx * ny * nz).astype(dtype.newbyteorder("="))\
        .reshape(nz, ny, nx)


def padded_sat(f, s):
    """Summed-area table of the 'cube intersected' indicator of grid f (a < s <= b), padded
    with a zero plane in front on every axis: shape (nz, ny, nx), like the device tables."""
    nz, ny, nx = f.shape
    corners = [f[dz:nz - 1 + dz, dy:ny - 1 + dy, dx:nx - 1 + dx]
               for dz in (0, 1) for dy in (0, 1) for dx in (0, 1)]
    lo = corners[0].copy()
    hi = corners[0].copy()
    for c in corners[1:]:
        np.minimum(lo, c, out=lo)
        np.maximum(hi, c, out=hi)
    # Counts wrap modulo 2^32 (or 2^64) like the device tables; box counts stay exact.
    dtype = np.uint32 if (nx - 1) * (ny - 1) * (nz - 1) <= 0xFFFFFFFF else np.uint64
    table = np.zeros(f.shape, dtype=dtype)
    np.logical_and(lo < s, s <= hi, out=table[1:, 1:, 1:], casting="unsafe")
    for axis in range(3):
        np.cumsum(table, axis=axis, out=table)
    return table


def windows(n, m, k):
    """Per coordinate of one axis: W = [lo, hi) in G and W' = [lo', hi') in G'
    (docs/definitions.md §13, revision 2: W' first, W exactly its region in G), as indices of
    the padded tables."""
    h = k // 2
    c0 = np.floor_divide(np.arange(n) - h, 2)
    lo_sub = np.maximum(0, c0)
    hi_sub = np.maximum(lo_sub, np.minimum(m - 1, c0 + h))
    return 2 * lo_sub, 2 * hi_sub, lo_sub, hi_sub


def box_counts(table, bounds):
    """Counts of the boxes [lo, hi) of every vertex: the differences along x, y, z."""
    q = table
    for axis, (lo, hi) in zip((2, 1, 0), bounds):
        q = q.take(hi, axis=axis) - q.take(lo, axis=axis)
    return q


def local_dimension(f, iso, k=8):
    """LD of every vertex of f (nz, ny, nx) for isovalue iso and even window k, float32 with
    NaN where undefined. Integer data compares with the integer ceil(iso), clamped past the
    16-bit ranges (exactly the cubes a < iso <= b selects, and numpy then compares exactly);
    float data with float32(iso)."""
    if k < 2 or k % 2:
        raise ValueError("the window must be even and at least 2")
    s = np.float32(iso) if f.dtype == np.float32 else int(min(max(math.ceil(iso), -65537), 65537))
    g = f[::2, ::2, ::2]
    nz, ny, nx = f.shape
    mz, my, mx = g.shape
    wz, wy, wx = windows(nz, mz, k), windows(ny, my, k), windows(nx, mx, k)
    a = box_counts(padded_sat(f, s), [(wx[0], wx[1]), (wy[0], wy[1]), (wz[0], wz[1])])
    b = box_counts(padded_sat(g, s), [(wx[2], wx[3]), (wy[2], wy[3]), (wz[2], wz[3])])
    ld = np.full(f.shape, np.nan, dtype=np.float32)
    defined = (a > 0) & (b > 0)
    ld[defined] = np.log2(a[defined].astype(np.float64) / b[defined])
    return ld


def best_of(repeats, fn):
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def compare(ours, theirs):
    """(NaN pattern equal, max |difference| where both are defined)."""
    nan_ours, nan_theirs = np.isnan(ours), np.isnan(theirs)
    both = ~nan_ours & ~nan_theirs
    err = float(np.max(np.abs(ours[both].astype(np.float64) - theirs[both]))) if both.any() else 0.0
    return bool(np.array_equal(nan_ours, nan_theirs)), err


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("volume")
    p.add_argument("--iso", type=float, required=True)
    p.add_argument("--window", type=int, default=8)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--compare", help="an LD field written by `clfractal local`")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON line")
    a = p.parse_args()
    f = read_nrrd(a.volume)
    seconds, ld = best_of(a.repeats, lambda: local_dimension(f, a.iso, a.window))
    result = {"volume": a.volume, "voxels": int(f.size), "seconds": seconds,
              "gvoxels_per_s": f.size / seconds / 1e9, "defined": int((~np.isnan(ld)).sum())}
    ok = True
    if a.compare:
        same_nan, err = compare(read_nrrd(a.compare), ld)
        ok = same_nan and err <= 1e-6
        result.update({"nan_pattern_equal": same_nan, "max_abs_difference": err, "agree": ok})
    if a.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:20s} {value}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
