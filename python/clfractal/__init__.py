"""clfractal: the isosurface fractal dimension of 3D volumes, on OpenCL devices.

Volumes are 3D NumPy arrays in ``(z, y, x)`` order (C order, x fastest), as nibabel,
tifffile, imageio and scikit-image hold them. Every value type the library computes in is
taken as it is (see ``VALUE_TYPES``); other dtypes are converted once when that loses
nothing (bool -> uint8, float16 -> float32, or integer/float values that all
fit a supported type exactly), and rejected with ValueError otherwise. Views, transposes and
big-endian arrays are fine.

Definitions (the library's, from "The Nature of the Isosurface Fractal Dimension"):

- A cube (8 vertices) or grid edge (2 vertices) with span ``[a, b]`` (its min and max) is
  intersected by isovalue ``s`` iff ``a < s <= b``; ``I(s)`` counts intersected cubes,
  ``E(s)`` intersected edges, for every isovalue at once.
- Pyramid level ``l`` keeps the vertices whose coordinates are multiples of ``2**l``;
  ``G'`` is level 1.
- Box span dimension (eq. 2.5) ``D(s) = log2(I_G(s) / I_G'(s))``; edge span dimension
  (eq. 3.1) the same with ``E``; NaN where either count is 0.

The OpenCL device is chosen by the ``device`` argument (a substring of "platform / device"
as ``devices()`` lists them) or, without it, by the environment variables
``CLFRACTAL_DEVICE`` (the same substring) and ``CLFRACTAL_DEVICE_TYPE``
(cpu|gpu|accelerator|all); by default the
first GPU, else the first device. Contexts and compiled kernels are kept for the life of the
process. Device work runs with the GIL released. Bad input raises ValueError with the
library's message; device failures raise RuntimeError.
"""
from __future__ import annotations

import numpy as np

from . import _clfractal

__version__ = "0.1.0"

__all__ = [
    "VALUE_TYPES", "DeviceVolume", "uploads", "FdCurve", "fd_curve", "local_fd", "fd4", "components", "median", "gaussian",
    "bilateral", "targeted_filter", "small_components", "smooth", "mesh", "noise_dimension", "noise_level", "read_volume",
    "devices", "device_description",
]

#: NumPy dtype -> the library's value type, one line per type it computes in. The order is
#: the order of preference when a dtype is converted (the first type that holds it exactly).
VALUE_TYPES = {
    np.dtype(np.uint8): "uint8",
    np.dtype(np.int8): "int8",
    np.dtype(np.uint16): "uint16",
    np.dtype(np.int16): "int16",
    np.dtype(np.uint32): "uint32",
    np.dtype(np.int32): "int32",
    np.dtype(np.float32): "float32",
    np.dtype(np.float64): "float64",
}
_DTYPES = {name: dtype for dtype, name in VALUE_TYPES.items()}


def _lossless_type(a: np.ndarray) -> np.dtype:
    """The first value type that holds every value of ``a`` exactly, by dtype, else by value."""
    kind = a.dtype.kind
    for dtype in VALUE_TYPES:  # integers stay integers, floats floats
        if np.can_cast(a.dtype, dtype, "safe") and (dtype.kind == "f") == (kind == "f"):
            return dtype
    if kind in "iu":
        lo, hi = int(a.min()), int(a.max())
        for dtype in VALUE_TYPES:
            if dtype.kind in "iu" and np.iinfo(dtype).min <= lo and hi <= np.iinfo(dtype).max:
                return dtype
    elif kind == "f":
        for dtype in VALUE_TYPES:
            if dtype.kind == "f" and dtype.itemsize < a.dtype.itemsize:
                with np.errstate(over="ignore", invalid="ignore"):
                    if np.array_equal(a.astype(dtype).astype(a.dtype), a, equal_nan=True):
                        return dtype
    supported = ", ".join(VALUE_TYPES.values())
    raise ValueError(
        f"volume: {a.dtype} values cannot be converted to a supported type ({supported}) without "
        f"precision loss; convert explicitly, e.g. volume.astype(np.float32)")


class DeviceVolume(_clfractal.Uploaded):
    """A volume uploaded to the device once, for several calls.

    ``fd_curve``, ``local_fd``, ``components``, ``median``, ``gaussian``, ``bilateral``,
    ``smooth`` and ``mesh`` take it in place of the array and read the device copy (no
    upload; zero-copy where the device shares host memory); ``fd4`` and ``targeted_filter``
    take it too but upload its array again. The array is converted as for every call, and
    copied once: later changes to it are not seen. ``device`` as for every call; a call given
    a DeviceVolume runs on its device.

    Attributes: ``dtype`` and ``shape`` (of the converted array), ``zero_copy`` (whether the
    device reads the host copy in place).
    """

    def __init__(self, volume, device: str | None = None):
        a, type_name = _volume(volume)
        super().__init__(a, type_name, device)
        self._array, self._type_name = a, type_name
        self.dtype, self.shape = a.dtype, a.shape


def uploads(device: str | None = None) -> int:
    """How many volumes went to the device so far (a DeviceVolume counts one; each call
    given an array, at least one)."""
    return int(_clfractal.uploads(device))


def _volume(volume, uploaded: bool = False):
    """The array as the extension takes it: 3D, native byte order, a supported dtype. With
    ``uploaded``, a DeviceVolume is passed on as it is; else its array."""
    if isinstance(volume, DeviceVolume):
        return (volume if uploaded else volume._array), volume._type_name
    a = np.asarray(volume)
    if a.ndim != 3:
        raise ValueError(f"volume: expected a 3D array in (z, y, x) order, got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"volume: shape {a.shape} has an empty axis; every axis needs at least 1 vertex")
    if a.dtype.kind not in "biuf":
        raise ValueError(f"volume: {a.dtype} arrays are not supported (numbers only)")
    native = a.dtype.newbyteorder("=")
    target = native if native in VALUE_TYPES else _lossless_type(a)
    if a.dtype != target:
        a = a.astype(target)  # the one conversion: byte order and/or type
    return a, VALUE_TYPES[target]


def _array(out) -> np.ndarray:
    """A (bytes, type name, shape) result of the extension as a (z, y, x) array, no copy."""
    data, type_name, shape = out
    return np.asarray(data).view(_DTYPES[type_name]).reshape(shape)


def _isovalue_array(values, value_type: np.dtype) -> np.ndarray:
    """Isovalues as int64 for integer data, else in the data's float type (the values compared)."""
    return np.asarray(values).astype(np.int64 if value_type.kind in "iu" else value_type)


def _isovalues(isovalues):
    if isovalues is None:
        return None
    s = np.asarray(isovalues, dtype=np.float64).ravel()
    return s.tolist()


class FdCurve:
    """A fractal dimension curve: one value per isovalue.

    Attributes:
        isovalues: the isovalues (int64 for integer data; the data's float type otherwise,
            exactly the values compared).
        counts: ``(levels, K)`` uint64, ``counts[l, j]`` = intersected cubes (``kind="box"``)
            or grid edges (``kind="edge"``) of pyramid level ``l`` at isovalue ``j``.
        fd: float64, ``D(s) = log2(counts[0] / counts[1])``, NaN where either is 0.
        fd_fit: float64 (``levels > 2``, else None), minus the least-squares slope through
            ``(l, log2 counts[l])`` for ``l = 0..levels-1``, NaN where any count is 0.
        summary: dict with ``mean`` and ``std`` (population) of ``fd`` where defined (and
            ``counts[1] >= min_count``), ``weighted_mean`` (weighted by ``counts[0]``),
            ``kappa = mean / 3`` (growth exponent, ``I ~ N**kappa``), ``defined`` (how many
            isovalues enter), ``kind``, ``levels``, ``min_count``, ``device``,
            ``seconds_compute`` (device time of the counting) and ``seconds_compile``.
        kind: "box" or "edge".
    """

    def __init__(self, raw: dict, kind: str, levels: int, value_type: np.dtype):
        self.isovalues = _isovalue_array(raw["isovalues"], value_type)
        self.counts = np.asarray(raw["counts"]).reshape(levels, len(self.isovalues))
        self.fd = np.asarray(raw["fd"])
        self.fd_fit = np.asarray(raw["fd_fit"]) if levels > 2 else None
        self.summary = dict(raw["summary"])
        self.kind = kind
        self.levels = levels

    def __len__(self) -> int:
        return len(self.isovalues)

    def __repr__(self) -> str:
        s = self.summary
        return (f"FdCurve(kind={self.kind!r}, levels={self.levels}, isovalues={len(self)}, "
                f"defined={s['defined']}, mean={s['mean']:.4f}, std={s['std']:.4f})")

    def to_pandas(self):
        """The curve as a pandas DataFrame: isovalue, count, count_sub, count_l2..., fd, fd_fit."""
        import pandas as pd
        columns = {"isovalue": self.isovalues}
        for level in range(self.levels):
            name = "count" if level == 0 else "count_sub" if level == 1 else f"count_l{level}"
            columns[name] = self.counts[level]
        columns["fd"] = self.fd
        if self.fd_fit is not None:
            columns["fd_fit"] = self.fd_fit
        return pd.DataFrame(columns)


def fd_curve(volume, kind: str = "box", levels: int = 2, isovalues=None, bins: int = 256,
             min_count: int = 0, device: str | None = None) -> FdCurve:
    """The fractal span dimension of every isovalue (thesis eq. 2.5 / 3.1).

    A cube (``kind="box"``) or grid edge (``kind="edge"``) with span ``[a, b]`` is intersected
    by ``s`` iff ``a < s <= b``. ``I_l(s)`` counts them at pyramid level ``l`` (vertices whose
    coordinates are multiples of ``2**l``, ``n_l = (n_{l-1} - 1) // 2 + 1`` per axis), and
    ``D(s) = log2(I_0(s) / I_1(s))``, NaN where either is 0. With ``levels > 2`` also
    ``fd_fit``, minus the least-squares slope through ``(l, log2 I_l(s))``.

    Isovalues: integer data, every integer of the value range (``isovalues`` may list any
    increasing integers instead); float data, ``bins`` uniform values
    ``vmin + (j + 1)(vmax - vmin) / bins``, rounded to the data's type (or an increasing
    ``isovalues`` list, rounded the same way). ``min_count`` restricts the summary to
    isovalues with ``I_1(s) >= min_count``.
    """
    a, type_name = _volume(volume, uploaded=True)
    raw = _clfractal.fd_curve(a, type_name, kind, int(levels), _isovalues(isovalues), int(bins),
                              int(min_count), device)
    return FdCurve(raw, kind, int(levels), a.dtype)


def local_fd(volume, iso: float, window: int = 8, device: str | None = None) -> np.ndarray:
    """The local fractal dimension field (thesis eq. 2.6) for isovalue ``iso``.

    At vertex ``v`` and even window ``k``, per axis with coordinate ``x``, ``n`` vertices in
    the grid G and ``n' = (n - 1) // 2 + 1`` in G' (level 1): the window ``W'`` of G' holds
    cubes ``[b0, b1) = [max(0, c0), min(n' - 1, c0 + k/2))`` with ``c0 = (x - k/2) // 2``,
    the window ``W`` of G cubes ``[2 b0, 2 b1)`` (the same region, centred on ``v`` to within
    one cube), and ``LD(v) = log2(I_W / I_W')`` counts the intersected cubes
    (``a < iso <= b``) in each; NaN where either count is 0. Integer data compares with
    ``iso`` as given; float data with ``iso`` rounded to float32. Returns a float32 array of
    the volume's shape. A smooth surface gives LD near 2, noise LD towards 3.
    """
    a, type_name = _volume(volume, uploaded=True)
    return _array(_clfractal.local_fd(a, type_name, float(iso), int(window), device))


def fd4(volume, q: float = 0.0, device: str | None = None) -> dict:
    """The 4D fractal dimension of the graph of the volume (thesis 6.4): one number, no isovalue.

    A cube with span ``[a, b]`` meets ``floor((b - vmin)/q) - floor((a - vmin)/q) + 1`` bins of
    width ``q`` (``vmin`` the smallest value); ``I4(G, q)`` sums them over the cubes of the grid,
    ``I4(G', 2q)`` over those of level 1 with bins twice as wide, and ``D4 = log2(I4(G, q) /
    I4(G', 2q))`` (NaN where either is 0): 3 for a smooth field, towards 4 for noise. ``q = 0``:
    1 for integer data, ``(vmax - vmin) / 256`` for float data. Returns ``{"q", "vmin",
    "i4_l0", "i4_l1", "d4"}``, the keys of ``clfractal fd4 --json``.
    """
    a, type_name = _volume(volume)
    return dict(_clfractal.fd4(a, type_name, float(q), device))


def components(volume, connectivity: str = "cube", isovalues=None, bins: int = 256,
               device: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Connected components of the isosurface at every isovalue (thesis §3.1).

    With ``A = {f < s}`` and ``C = {f >= s}``: ``components(s) = b0(A) + b0(C) - 1`` (0 when
    either set is empty), ``b0`` counting connected pieces. ``connectivity="cube"`` (marching
    cubes): A 6-connected, C 26-connected. ``"freudenthal"`` (marching tetrahedra, the
    piecewise-linear function): both 14-connected (offsets ±x, ±y, ±z, ±(x+y), ±(y+z),
    ±(x+z), ±(x+y+z)). Isovalues as in ``fd_curve``. Returns ``(isovalues, counts)``, counts
    int64.
    """
    a, type_name = _volume(volume, uploaded=True)
    iso, counts = _clfractal.components(a, type_name, connectivity, _isovalues(isovalues), int(bins), device)
    return _isovalue_array(iso, a.dtype), np.asarray(counts)


def median(volume, device: str | None = None) -> np.ndarray:
    """The median of the 3x3x3 neighbourhood of every vertex, clamp-to-edge at the borders.

    Equal to ``scipy.ndimage.median_filter(volume, size=3, mode="nearest")``. Returns a new
    array of the (converted) input type.
    """
    a, type_name = _volume(volume, uploaded=True)
    return _array(_clfractal.filter(a, type_name, "median", 1.0, 1.0, 1.0, device))


def gaussian(volume, sigma: float, device: str | None = None) -> np.ndarray:
    """The separable Gaussian filter: radius ``ceil(3 sigma)``, normalised weights
    ``exp(-i**2 / (2 sigma**2))``, clamp-to-edge, float32 accumulation; integer outputs rounded
    to nearest and clamped to the type's range."""
    a, type_name = _volume(volume, uploaded=True)
    return _array(_clfractal.filter(a, type_name, "gaussian", float(sigma), 1.0, 1.0, device))


def bilateral(volume, sigma_s: float, sigma_r: float, device: str | None = None) -> np.ndarray:
    """The bilateral filter over the cube of radius ``ceil(2 sigma_s)``: weights
    ``exp(-|w - v|**2 / (2 sigma_s**2)) * exp(-(f(w) - f(v))**2 / (2 sigma_r**2))``,
    clamp-to-edge; integer outputs rounded and clamped as for the Gaussian."""
    a, type_name = _volume(volume, uploaded=True)
    return _array(_clfractal.filter(a, type_name, "bilateral", 1.0, float(sigma_s), float(sigma_r), device))


def targeted_filter(volume, iso: float, threshold: float, method: str = "median", window: int = 8,
                    sigma: float = 1.0, device: str | None = None) -> tuple[np.ndarray, float]:
    """The fractal-targeted filter (thesis §4.3): the median (or Gaussian of ``sigma``) value
    only where the local fractal dimension ``local_fd(volume, iso, window) > threshold`` (NaN
    never qualifies), the input value elsewhere. Returns ``(filtered, fraction changed)``.
    """
    a, type_name = _volume(volume)
    out, info = _clfractal.targeted_filter(a, type_name, float(iso), float(threshold), method, int(window),
                                           float(sigma), 1.0, 1.0, device)
    return _array(out), float(info["changed_share"])


def small_components(volume, iso: float, k: int, connectivity: str = "cube") -> tuple[np.ndarray, dict]:
    """The small-components filter (Zhao & Wenger 2025) at isovalue ``iso``: every component
    of ``{f >= s}`` with at most ``k`` vertices gets the largest value of the type below ``s``,
    then every component of ``{f < s}`` with at most ``k`` vertices gets the smallest value at
    or above ``s`` (``s`` in the data's type: ``ceil(iso)`` for integer data). Connectivity
    ``"cube"``: ``{f >= s}`` 26-connected, ``{f < s}`` 6-connected; ``"six"``: both 6-connected.
    Returns ``(filtered, info)``: the components of both sets before and after, those removed,
    and the vertices changed (``changed``, ``changed_share``).
    """
    if int(k) < 0:
        raise ValueError(f"k: must be >= 0, got {k}")
    a, type_name = _volume(volume)
    out, info = _clfractal.small_components(a, type_name, float(iso), int(k), connectivity)
    return _array(out), dict(info)


def smooth(volume, iso: float, threshold: float, window: int = 8, variant: str = "plain", tau: float = 1.0,
           device: str | None = None) -> tuple[np.ndarray, dict]:
    """Smooth isosurface construction (thesis chapter 5, Algorithm 2).

    LD is computed once on the input. A grid edge is high fractal when it is intersected
    (``a < iso <= b``) and LD > ``threshold`` at either end. Each high-fractal edge ``(v, u)``
    with ``f(v) > f(u)`` that is still intersected gets ``f(v) := f(u)``; edges around changed
    vertices that become intersected and high fractal are queued, until none is left. Variant
    ``"gaussian"`` also lowers the 26 neighbours ``w`` of ``v`` by
    ``(f(v) - f(u)) * exp(-d(v, w)**2 / (2 tau**2))``. Values only decrease. Returns
    ``(smoothed, info)``, info counting high vertices, edges processed and lowered, and
    vertices changed.
    """
    a, type_name = _volume(volume, uploaded=True)
    out, info = _clfractal.smooth(a, type_name, float(iso), float(threshold), int(window), variant, float(tau),
                                  device)
    return _array(out), dict(info)


def mesh(volume, iso: float, method: str = "mc", color_by_ld: bool = False, window: int = 8,
         spacing=(1.0, 1.0, 1.0), device: str | None = None):
    """The isosurface ``f = iso`` as a triangle mesh, one vertex per intersected grid edge.

    ``method="mc"``: marching cubes separating negative vertices (``f < iso``), so the mesh has
    ``components(volume)`` pieces and ``E(iso)`` vertices; ``"mt"``: marching tetrahedra on the
    Freudenthal triangulation. Returns ``(vertices, faces)``, or ``(vertices, faces, ld)`` with
    ``color_by_ld``: vertices ``(n, 3)`` float32 in ``(z, y, x)`` order times ``spacing``
    ``(dz, dy, dx)`` (the array's axes, as scikit-image and napari use them), faces ``(m, 3)``
    int32 with normals towards lower values, ``ld`` float32 per vertex (the local fractal
    dimension interpolated along its grid edge; NaN where undefined). Ready for
    ``napari.layers.Surface((vertices, faces, ld))`` or ``trimesh.Trimesh(vertices[:, ::-1],
    faces[:, ::-1])``.
    """
    a, type_name = _volume(volume, uploaded=True)
    verts, faces, ld = _clfractal.mesh(a, type_name, float(iso), method, bool(color_by_ld), int(window),
                                       [float(s) for s in spacing], device)
    verts = np.asarray(verts).reshape(-1, 3)
    faces = np.asarray(faces).reshape(-1, 3)
    return (verts, faces) if ld is None else (verts, faces, np.asarray(ld))


def noise_level(volume, block: int = 0, map_block: int = 32, clip: float = 3.0,
                device: str | None = None) -> dict:
    """The standard deviation of the volume's noise in grey values, from the flat parts of the
    volume (include/clfractal/noise_level.hpp; ``clfractal fd --noise-level``).

    At every interior vertex the residual ``R`` is the product of the second differences
    ``[1, -2, 1]`` along the three axes; ``R**2 / 216`` estimates the noise variance for every
    noise distribution, and is 0 on fields that are at most quadratic along any one axis. Per
    block of ``block**3`` vertices (0: 8, or 4 for volumes that hold fewer than 64 blocks of
    8), blocks that read the volume's smallest or largest value (clipping) are left out; the
    centre is the shorth of ``log(v) / 3`` over the block variances ``v``, the flat blocks lie
    within ``clip`` white-noise spreads of it, and ``sigma**2`` is their pooled mean (0 when no
    usable block has any residual, NaN when no block is usable). Returns
    ``{"sigma", "flat_share" (the flat blocks' voxels over all voxels), "block", "blocks",
    "blocks_usable", "blocks_flat", "typical_variance", "seconds", "map_cell", "map"}``;
    ``map`` is the residual's RMS per cell of ``map_block**3`` vertices, a (z, y, x) float32
    array, NaN where a cell has no usable block.
    """
    a, type_name = _volume(volume, uploaded=True)
    r = dict(_clfractal.noise_level(a, type_name, int(block), int(map_block), float(clip), device))
    r["map"] = np.asarray(r["map"]).reshape(r.pop("map_shape"))
    return r


def noise_dimension(mu, gamma: float = 1.0, kind: str = "uniform"):
    """The expected fractal edge span dimension of a field with gradient ``gamma`` plus noise
    of amplitude ``mu`` (thesis Theorem 1), with ``r = mu / gamma``:

    - ``r >= 1``: ``log2((32 r**3 + 8 r - 1) / (4 r**3 + 4 r - 1))``
    - ``1/2 <= r <= 1``: ``log2((32 r**3 + 8 r - 1) / (r**4 + 6 r**2))``
    - ``r < 1/2``: ``log2(8 (2 r**2 + 3) / (r**2 + 6))``

    for uniform noise on ``[-mu, mu]``; ``kind="gaussian"`` (``mu`` the standard deviation)
    integrates the same edge model numerically. 2 without noise, rising to 3. ``mu`` may be an
    array; returns a float or a float64 array of its shape.
    """
    r = np.asarray(mu, dtype=np.float64) / float(gamma)
    out = np.array([_clfractal.noise_dimension(float(x), kind) for x in r.ravel()]).reshape(r.shape)
    return float(out) if out.ndim == 0 else out


def read_volume(path: str) -> tuple[np.ndarray, tuple[float, float, float]]:
    """Reads a volume file the library reads, the format told by the content: NRRD, NIfTI,
    DICOM (a file or a series directory), TIFF (multi-page or a directory of slices),
    MetaImage, raw files named ``NAME_XxYxZ_TYPE.raw``, or ``synthetic:NAME[:N]``. Returns
    ``(array, spacing)``: the array in ``(z, y, x)`` order (the stored voxel order) and the
    spacing ``(dz, dy, dx)``. Float data with NaN (an LD field) is read as it is; the
    computing calls reject it."""
    out, spacing = _clfractal.read_volume(str(path))
    return _array(out), tuple(spacing)


def devices() -> list[dict]:
    """Every OpenCL device: platform, name, type, global_mem, max_alloc, compute_units, and
    ``default`` (the one used without a ``device`` argument)."""
    return [dict(d) for d in _clfractal.devices()]


def device_description(device: str | None = None) -> str:
    """``"platform / device"`` of the device a call with this ``device`` argument runs on."""
    return _clfractal.device_description(device)
