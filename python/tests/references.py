"""Independent NumPy/SciPy implementations of the definitions of docs/definitions.md, written
from the definitions alone (not from the library's algorithms): sorted-span counting instead of the
difference histogram, scipy.ndimage.label instead of union-find sweeps, direct window sums
instead of the library's summed-area tables."""
import itertools

import numpy as np
from scipy import ndimage


# ------------------------------------------------------------------ spans, I(s), E(s), D(s)

def level(v, l):
    """Pyramid level l: the vertices whose coordinates are multiples of 2**l."""
    step = 2 ** l
    return v[::step, ::step, ::step]


def cube_spans(v):
    """(min, max) of the 8 vertices of every cube, flattened."""
    nz, ny, nx = v.shape
    corners = [v[dz:nz - 1 + dz, dy:ny - 1 + dy, dx:nx - 1 + dx]
               for dz, dy, dx in itertools.product((0, 1), repeat=3)]
    return np.minimum.reduce(corners).ravel(), np.maximum.reduce(corners).ravel()


def edge_spans(v):
    """(min, max) of the 2 vertices of every grid edge along x, y and z, flattened."""
    lo, hi = [], []
    for axis in range(3):
        n = v.shape[axis]
        a, b = np.take(v, range(n - 1), axis=axis), np.take(v, range(1, n), axis=axis)
        lo.append(np.minimum(a, b).ravel())
        hi.append(np.maximum(a, b).ravel())
    return np.concatenate(lo), np.concatenate(hi)


def intersected(lo, hi, isovalues):
    """#{a < s <= b} for every s: #{a < s} - #{b < s} by binary search in the sorted spans."""
    lo, hi = np.sort(lo), np.sort(hi)
    s = np.asarray(isovalues).astype(lo.dtype) if lo.dtype.kind == "f" else np.asarray(isovalues)
    return (np.searchsorted(lo, s, side="left") - np.searchsorted(hi, s, side="left")).astype(np.uint64)


def default_isovalues(v, bins=256):
    """Every integer of the range (integer data holding at most 65,536 of them), else bins
    uniform values vmin + (j+1)(vmax-vmin)/bins computed in double, in the data's own
    isovalue type (float32 for float32 data, float64 otherwise), duplicates dropped."""
    if v.dtype.kind in "iu" and int(v.max()) - int(v.min()) < 65536:
        return np.arange(int(v.min()), int(v.max()) + 1, dtype=np.int64)
    vmin, vmax = float(v.min()), float(v.max())
    s = (vmin + (np.arange(bins) + 1.0) * (vmax - vmin) / bins)
    s = s.astype(np.float32 if v.dtype == np.float32 else np.float64)
    keep = np.concatenate([[True], s[1:] > np.maximum.accumulate(s)[:-1]])
    return s[keep]


def span_counts(v, isovalues, kind="box", levels=2):
    """(levels, K) counts of intersected cubes (box) or grid edges (edge)."""
    spans = cube_spans if kind == "box" else edge_spans
    return np.stack([intersected(*spans(level(v, l)), isovalues) for l in range(levels)])


def dimension(counts):
    """D(s) = log2(I_0 / I_1), NaN where either count is 0."""
    c0, c1 = counts[0].astype(np.float64), counts[1].astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where((c0 > 0) & (c1 > 0), np.log2(c0 / c1), np.nan)


def dimension_fit(counts):
    """-slope of the least-squares line through (l, log2 I_l), NaN where any count is 0."""
    levels = np.arange(counts.shape[0], dtype=np.float64)
    out = np.full(counts.shape[1], np.nan)
    ok = (counts > 0).all(axis=0)
    if ok.any():
        out[ok] = -np.polyfit(levels, np.log2(counts[:, ok].astype(np.float64)), 1)[0]
    return out


def summary(fd, counts, min_count=0):
    used = ~np.isnan(fd) & (counts[1] >= min_count)
    d, w = fd[used], counts[0][used].astype(np.float64)
    return {"defined": int(used.sum()), "mean": d.mean(), "std": d.std(),
            "weighted_mean": (d * w).sum() / w.sum(), "kappa": d.mean() / 3}


# ------------------------------------------------------------------ components

_A6 = ndimage.generate_binary_structure(3, 1)
_C26 = np.ones((3, 3, 3), dtype=bool)
_F14 = np.zeros((3, 3, 3), dtype=bool)
_F14[1, 1, 1] = True
for _dz, _dy, _dx in [(0, 0, 1), (0, 1, 0), (1, 0, 0), (0, 1, 1), (1, 1, 0), (1, 0, 1), (1, 1, 1)]:
    _F14[1 + _dz, 1 + _dy, 1 + _dx] = _F14[1 - _dz, 1 - _dy, 1 - _dx] = True
STRUCTURES = {"cube": (_A6, _C26), "freudenthal": (_F14, _F14)}


def components(v, s, connectivity="cube"):
    """b0(A) + b0(C) - 1 with A = {f < s}, C = {f >= s} labelled by scipy (0 if one is empty)."""
    s = np.float32(s) if v.dtype == np.float32 else s
    a, c = v < s, v >= s
    if not a.any() or not c.any():
        return 0
    sa, sc = STRUCTURES[connectivity]
    return ndimage.label(a, structure=sa)[1] + ndimage.label(c, structure=sc)[1] - 1


# ------------------------------------------------------------------ local fractal dimension

def windows(n, k, revision=2):
    """Per axis, for every vertex coordinate x: the cube ranges [lo, hi) of W in G and of W'
    in G' (docs/definitions.md §13; revision 1 centred W on x with its own clamping)."""
    n1 = (n - 1) // 2 + 1
    x = np.arange(n)
    c0 = (x - k // 2) // 2                       # floor division
    b0, b1 = np.maximum(0, c0), np.minimum(n1 - 1, c0 + k // 2)
    if revision == 2:
        w = (2 * b0, 2 * b1)
    else:
        w = (np.maximum(0, x - k // 2), np.minimum(n - 1, x + k // 2))
    return w, (b0, b1)


def cube_indicator(v, s):
    """1 where the cube is intersected (a < s <= b), shape (nz-1, ny-1, nx-1)."""
    shape = tuple(max(n - 1, 0) for n in v.shape)
    if 0 in shape:
        return np.zeros(shape, dtype=np.int64)
    lo, hi = cube_spans(v)
    s = np.float32(s) if v.dtype == np.float32 else s
    return ((lo < s) & (s <= hi)).reshape(shape).astype(np.int64)


def _box_sums(ind, ranges):
    """Sum of `ind` over the box ranges[z] x ranges[y] x ranges[x] for every vertex, through
    an inclusive-prefix table with a zero border."""
    t = np.zeros(tuple(n + 1 for n in ind.shape), dtype=np.int64)
    t[1:, 1:, 1:] = ind.cumsum(0).cumsum(1).cumsum(2)
    (z0, z1), (y0, y1), (x0, x1) = [(np.maximum(lo, 0), np.maximum(hi, lo)) for lo, hi in ranges]
    total = np.zeros((len(z0), len(y0), len(x0)), dtype=np.int64)
    for sz, zz in ((1, z1), (-1, z0)):
        for sy, yy in ((1, y1), (-1, y0)):
            for sx, xx in ((1, x1), (-1, x0)):
                total += sz * sy * sx * t[np.ix_(zz, yy, xx)]
    return total


def local_fd(v, s, k=8, revision=2):
    """LD(v) = log2(I_W / I_W') (float32), NaN where either count is 0."""
    per_axis = [windows(n, k, revision) for n in v.shape]
    i_w = _box_sums(cube_indicator(v, s), [w for w, _ in per_axis])
    i_w1 = _box_sums(cube_indicator(level(v, 1), s), [w1 for _, w1 in per_axis])
    with np.errstate(divide="ignore", invalid="ignore"):
        ld = np.where((i_w > 0) & (i_w1 > 0), np.log2(i_w / np.maximum(i_w1, 1)), np.nan)
    return ld.astype(np.float32)


def local_fd_brute_force(v, s, k=8, revision=2):
    """The same, one vertex at a time with plain slices (checks the table version above)."""
    ind, ind1 = cube_indicator(v, s), cube_indicator(level(v, 1), s)
    per_axis = [windows(n, k, revision) for n in v.shape]
    out = np.full(v.shape, np.nan, dtype=np.float32)
    for z, y, x in itertools.product(*[range(n) for n in v.shape]):
        w = [per_axis[a][0] for a in range(3)]
        w1 = [per_axis[a][1] for a in range(3)]
        idx = (z, y, x)
        box = tuple(slice(w[a][0][idx[a]], max(w[a][0][idx[a]], w[a][1][idx[a]])) for a in range(3))
        box1 = tuple(slice(w1[a][0][idx[a]], max(w1[a][0][idx[a]], w1[a][1][idx[a]])) for a in range(3))
        i_w, i_w1 = ind[box].sum(), ind1[box1].sum()
        if i_w > 0 and i_w1 > 0:
            out[idx] = np.log2(i_w / i_w1)
    return out


# ------------------------------------------------------------------ filters, mesh, noise

def bilateral(v, sigma_s, sigma_r):
    """The bilateral filter of include/clfractal/filter.hpp in float64, clamp-to-edge."""
    r = int(np.ceil(2 * sigma_s))
    f = v.astype(np.float64)
    p = np.pad(f, r, mode="edge")
    num, den = np.zeros_like(f), np.zeros_like(f)
    nz, ny, nx = f.shape
    for dz, dy, dx in itertools.product(range(-r, r + 1), repeat=3):
        w = p[r + dz:r + dz + nz, r + dy:r + dy + ny, r + dx:r + dx + nx]
        weight = np.exp(-(dz * dz + dy * dy + dx * dx) / (2 * sigma_s ** 2)) * np.exp(-(w - f) ** 2 / (2 * sigma_r ** 2))
        num += weight * w
        den += weight
    return num / den


def edge_points(v, s):
    """The interpolation points u + t (w - u), t = (s - f(u)) / (f(w) - f(u)), of every
    intersected grid edge, as (n, 3) float64 in (z, y, x) order."""
    s = float(np.float32(s)) if v.dtype == np.float32 else float(s)
    f = v.astype(np.float64)
    grid = np.stack(np.meshgrid(*[np.arange(n) for n in v.shape], indexing="ij"), axis=-1).astype(np.float64)
    points = []
    for axis in range(3):
        n = v.shape[axis]
        fu, fw = np.take(f, range(n - 1), axis=axis), np.take(f, range(1, n), axis=axis)
        gu = np.take(grid, range(n - 1), axis=axis)
        hit = (np.minimum(fu, fw) < s) & (s <= np.maximum(fu, fw))
        t = (s - fu[hit]) / (fw[hit] - fu[hit])
        p = gu[hit].copy()
        p[:, axis] += t
        points.append(p)
    return np.concatenate(points)


def theorem1(r):
    """Thesis Theorem 1, eqs. 3.2-3.4."""
    r = np.asarray(r, dtype=np.float64)
    high = np.log2((32 * r ** 3 + 8 * r - 1) / (4 * r ** 3 + 4 * r - 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        mid = np.log2((32 * r ** 3 + 8 * r - 1) / (r ** 4 + 6 * r ** 2))
    low = np.log2(8 * (2 * r ** 2 + 3) / (r ** 2 + 6))
    return np.where(r >= 1, high, np.where(r >= 0.5, mid, low))


def noise_level(v, block, clip=3.0):
    """The noise level of include/clfractal/noise_level.hpp in NumPy: R, the product of
    [1, -2, 1] along the three axes at every interior vertex; per block of block**3 vertices
    the sum of R**2 / 216, the count and the range of the values read; blocks reading the
    volume's extremes or with fewer than min(block**3 / 8, the largest count) residuals left
    out, and those whose residuals are all 0; the shorth of log(v) / 3 and the pooled mean within clip white-noise
    spreads. Returns (sigma_white, flat_share, usable blocks, flat blocks)."""
    f = v.astype(np.float64)
    nz, ny, nx = f.shape
    w = {-1: 1.0, 0: -2.0, 1: 1.0}
    r = np.zeros((nz - 2, ny - 2, nx - 2))
    lo, hi = np.full(r.shape, np.inf), np.full(r.shape, -np.inf)
    for dz in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                s = f[1 + dz:nz - 1 + dz, 1 + dy:ny - 1 + dy, 1 + dx:nx - 1 + dx]
                r += w[dz] * w[dy] * w[dx] * s
                lo, hi = np.minimum(lo, s), np.maximum(hi, s)
    # Block index of every interior vertex (coordinates 1..n-2 of the volume).
    gz, gy, gx = [-(-n // block) for n in (nz, ny, nx)]
    iz, iy, ix = np.meshgrid(*[np.arange(1, n - 1) // block for n in (nz, ny, nx)], indexing="ij")
    index = ((iz * gy + iy) * gx + ix).ravel()
    nblocks = gz * gy * gx
    sums = np.bincount(index, weights=(r ** 2).ravel() / 216, minlength=nblocks)
    count = np.bincount(index, minlength=nblocks)
    low = np.full(nblocks, np.inf)
    high = np.full(nblocks, -np.inf)
    np.minimum.at(low, index, lo.ravel())
    np.maximum.at(high, index, hi.ravel())
    min_count = max(1, min(block ** 3 // 8, count.max()))
    usable = (count >= min_count) & (low > f.min()) & (high < f.max())
    use = usable & (sums > 0)
    if not use.any():  # sigma 0 on blocks whose residuals are all 0, NaN without usable blocks
        n = int(usable.sum())
        return (0.0 if n else float("nan")), float(count[usable].sum() / f.size), n, n
    y = np.log(sums[use] / count[use]) / 3
    ys = np.sort(y)
    h = (len(ys) + 1) // 2
    widths = ys[h - 1:] - ys[:len(ys) - h + 1]
    best = int(np.argmin(widths))
    centre = (ys[best + (h - 1) // 2] + ys[best + h // 2]) / 2
    spread = np.sqrt(2 * (70 / 36) ** 3 / count[use]) / 3
    flat = np.abs(y - centre) <= clip * spread
    total = count[use][flat].sum()
    return float(np.sqrt(sums[use][flat].sum() / total)), float(total / f.size), int(usable.sum()), int(flat.sum())
