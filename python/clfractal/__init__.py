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

Results: arrays are NumPy arrays; a result that is a fixed sequence of arrays is a named
tuple that unpacks like ``skimage.measure.marching_cubes`` (``Components``, ``Mesh``,
``VolumeFile``); a record of numbers (with its arrays) is a frozen dataclass with
``to_dict()`` (``Analysis``, ``Recommendation``, ``SmallComponents``, ``Fd4``, ``Filtered``, ``Smoothed``, ``NoiseLevel``, ``VolumeInfo``), and
the curve ``FdCurve`` a class with the same ``to_dict()`` and ``to_pandas()``; ``to_dict()``
gives plain JSON values (``json.dumps`` takes them) under the command line's ``--json`` keys.
``report`` writes the page ``clfractal report`` writes; an ``Analysis`` shows its answer in a
notebook (``_repr_html_``).
"""
from __future__ import annotations

import dataclasses
import glob
import json
import importlib.util
import os
from typing import NamedTuple, Optional

import numpy as np


def _wheel_pocl() -> str | None:
    """The PoCL library of the ``pocl-binary-distribution`` wheel (``clfractal[cpu]``), or None."""
    spec = importlib.util.find_spec("pocl_binary_distribution")
    if spec is None or not spec.origin:
        return None
    site = os.path.dirname(os.path.dirname(spec.origin))
    for libs in ("pocl_binary_distribution/.libs", "pyopencl/.libs"):
        found = sorted(glob.glob(os.path.join(site, libs, "libpocl*.so*")))
        if found:
            return found[0]
    return None


def _llvm14_unknown_cpu(cpuinfo: str) -> str | None:
    """Why the LLVM 14 of ``pocl-binary-distribution`` (PoCL 3.0, the one on PyPI) cannot build
    kernels for the CPU ``cpuinfo`` (the text of ``/proc/cpuinfo``) describes, or None when it
    can. LLVM 14 names AMD CPUs up to family 25 (Zen 3, Zen 4 as znver3) and guesses unknown
    Intel family 6 models from their features; any other family it names "generic", which it
    then rejects as a target CPU ("unknown target CPU 'generic'", pocl/pocl#1049). PoCL 3.0
    has no override of the CPU name (POCL_LLVM_CPU_NAME came later), so no setting helps."""
    fields = {}
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        if not line.strip():
            break  # the first processor is enough
        fields.setdefault(key.strip(), value.strip())
    vendor, family = fields.get("vendor_id", ""), fields.get("cpu family", "")
    if not family.isdigit():
        return None
    f = int(family)
    if (vendor == "AuthenticAMD" and f > 25) or (vendor == "GenuineIntel" and f not in (6, 15)):
        return f"{vendor} family {f} ({fields.get('model name', 'unknown model')})"
    return None


#: What to install when the PyPI PoCL cannot serve this CPU.
_CPU_DRIVER_HINT = ("install a CPU OpenCL driver with a newer LLVM (Debian 12 or Ubuntu 24.04: "
                    "sudo apt install pocl-opencl-icd; conda: conda install -c conda-forge pocl) "
                    "or a GPU vendor's OpenCL driver")


def _choose_opencl_drivers(cpuinfo_path: str = "/proc/cpuinfo") -> str:
    """Where the OpenCL ICD loader (bundled in the wheel, or the system's) finds drivers.

    Decided once, before the loader starts: the user's ``OCL_ICD_VENDORS`` or
    ``OPENCL_VENDOR_PATH`` when set; else the system's registered drivers
    (``/etc/OpenCL/vendors/*.icd``: vendor GPU drivers, a system PoCL) when there are any;
    else the PoCL of ``clfractal[cpu]``, by setting ``OCL_ICD_VENDORS`` to its library."""
    for variable in ("OCL_ICD_VENDORS", "OPENCL_VENDOR_PATH"):
        if os.environ.get(variable):
            return f"{variable}={os.environ[variable]}"
    registered = sorted(glob.glob("/etc/OpenCL/vendors/*.icd"))
    if registered:
        return "system: " + ", ".join(registered)
    pocl = _wheel_pocl()
    if pocl is None:
        return "none (no /etc/OpenCL/vendors/*.icd and no pocl-binary-distribution)"
    try:
        with open(cpuinfo_path) as f:
            unknown = _llvm14_unknown_cpu(f.read())
    except OSError:
        unknown = None
    if unknown:
        # Left unregistered: every kernel build would fail on it.
        return (f"none (pocl-binary-distribution's PoCL 3.0 cannot build kernels for {unknown}: its LLVM 14 "
                f"names the CPU 'generic', pocl/pocl#1049; {_CPU_DRIVER_HINT})")
    os.environ["OCL_ICD_VENDORS"] = pocl
    return "pocl-binary-distribution: " + pocl


#: Where the OpenCL drivers come from (see ``devices()``).
OPENCL_DRIVERS = _choose_opencl_drivers()

from . import _clfractal  # noqa: E402  (after the drivers are chosen: the loader reads them once)

#: The library's version (the one of ``clfractal --version`` and ``clf_version()``).
__version__ = _clfractal.__version__

__all__ = [
    "VALUE_TYPES", "DeviceVolume", "uploads", "FdCurve", "fd_curve", "local_fd", "SliceStream", "Fd4", "fd4", "local4",
    "Components", "components", "ComponentsStream", "median", "gaussian", "bilateral", "Filtered", "targeted_filter",
    "ld_guided_filter", "Smoothed", "smooth", "Mesh", "mesh", "write_ply", "NoiseLevel", "noise_level",
    "noise_dimension", "SmallComponents", "small_components", "Recommendation", "Analysis", "analyse", "report", "VolumeFile", "read_volume", "Orientation", "write_volume", "VolumeInfo", "info",
    "devices", "device_description", "OPENCL_DRIVERS",
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
    ``uploaded``, a DeviceVolume is passed on as it is; else its array. A VolumeFile (what
    ``read_volume`` returns) gives its volume (the measures use the stored grid)."""
    if isinstance(volume, DeviceVolume):
        return (volume if uploaded else volume._array), volume._type_name
    if isinstance(volume, VolumeFile):
        volume = volume.volume
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

    def to_dict(self) -> dict:
        """The attributes as plain JSON values (arrays as lists, NaN as None)."""
        return _plain({"isovalues": self.isovalues, "counts": self.counts, "fd": self.fd, "fd_fit": self.fd_fit,
                       "summary": dict(self.summary), "kind": self.kind, "levels": self.levels})

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


def _slice_stack(slices, dtype: np.dtype, who: str) -> np.ndarray:
    """A (ny, nx) slice or (k, ny, nx) stack as a C-contiguous (k, ny, nx) array of `dtype`
    (converted only when that holds every value exactly)."""
    a = np.asarray(slices)
    if a.ndim == 2:
        a = a[None]
    if a.ndim != 3:
        raise ValueError(f"{who}.push: expected a (ny, nx) slice or (k, ny, nx) stack, got shape {a.shape}")
    if a.dtype != dtype:
        with np.errstate(all="ignore"):
            b = a.astype(dtype)
        if not np.array_equal(b, a):
            raise ValueError(f"{who}.push: {a.dtype} values do not fit the stream's {dtype}")
        a = b
    return np.ascontiguousarray(a)


def _stream_dtype(dtype, who: str) -> np.dtype:
    d = np.dtype(dtype)
    if d not in VALUE_TYPES:
        raise ValueError(f"{who}: {d} is not a value type ({', '.join(VALUE_TYPES.values())})")
    return d


class _SlicePush:
    """What both slice streams take: slices in z order (``_stream``, ``dtype``)."""

    @property
    def slices(self) -> int:
        """Slices pushed so far."""
        return int(self._stream.slices)

    def push(self, slices) -> None:
        """Adds a (ny, nx) slice or a (k, ny, nx) stack, in z order (converted to the
        stream's dtype only when it holds every value exactly)."""
        self._stream.push(_slice_stack(slices, self.dtype, type(self).__name__))


class SliceStream(_SlicePush):
    """FD curves of a volume that arrives slice by slice (a scanner), memory for a few slices.

    The library's ``SpanStream`` (include/clfractal/stream.hpp): ``push`` (ny, nx) slices,
    or (k, ny, nx) stacks of them, in z order; ``curve()`` at any time gives the FD curve
    of the slices so far, equal to ``fd_curve`` of the volume they make (the isovalues must
    be given: the value range is not known ahead).

    Parameters
    ----------
    shape : (ny, nx)
        The slice shape.
    dtype : numpy dtype
        The slices' value type (a key of ``VALUE_TYPES``).
    isovalues : array_like
        Increasing isovalues (integers for integer data).
    levels : int, optional
        Pyramid levels (2: eq. 2.5).
    kind : {"box", "edge"}, optional
    device : str, optional

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.random.default_rng(0).integers(0, 50, (9, 10, 11), dtype=np.uint8)
    >>> stream = clfractal.SliceStream(v.shape[1:], v.dtype, isovalues=np.arange(1, 50))
    >>> for z in range(v.shape[0]):
    ...     stream.push(v[z])
    >>> bool((stream.curve().counts == clfractal.fd_curve(v, isovalues=np.arange(1, 50)).counts).all())
    True
    """

    def __init__(self, shape, dtype, isovalues, levels: int = 2, kind: str = "box", device: str | None = None):
        ny, nx = (int(n) for n in shape)
        self.dtype = _stream_dtype(dtype, "SliceStream")
        self.kind, self.levels = kind, int(levels)
        self._stream = _clfractal.SliceStream(ny, nx, VALUE_TYPES[self.dtype], _isovalues(isovalues),
                                              self.levels, kind, device)

    def curve(self) -> FdCurve:
        """The FD curve of the slices so far, as ``fd_curve`` gives it."""
        return FdCurve(self._stream.curve(), self.kind, self.levels, self.dtype)


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


def _plain(x):
    """``x`` as plain JSON values (what ``json.dumps`` takes, as the command line's ``--json``
    writes them): records as their ``to_dict()``, arrays and tuples as lists, NumPy scalars as
    Python numbers, NaN and infinities as None (JSON's null)."""
    if isinstance(x, (_Record, FdCurve)):
        return x.to_dict()
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


class _Record:
    """Frozen dataclass results: ``to_dict()`` gives the fields as plain JSON values
    (``json.dumps(r.to_dict())`` works; arrays become lists, NaN null), under the keys of the
    command line's ``--json`` where it writes the same record."""

    def to_dict(self) -> dict:
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}


@dataclasses.dataclass(frozen=True)
class Fd4(_Record):
    """The 4D fractal dimension of a volume (``fd4``); the keys of ``clfractal fd4 --json``.

    Attributes
    ----------
    q : float
        The bin width of the value axis at level 0.
    vmin : float
        The smallest value, where the bins start.
    i4_l0, i4_l1 : int
        ``I4(G, q)`` and ``I4(G', 2q)``.
    d4 : float
        ``log2(i4_l0 / i4_l1)``, NaN where either is 0.
    """
    q: float
    vmin: float
    i4_l0: int
    i4_l1: int
    d4: float


def fd4(volume, q: float = 0.0, device: str | None = None) -> Fd4:
    """The 4D fractal dimension of the graph of the volume (thesis 6.4): one number, no isovalue.

    A cube with span ``[a, b]`` meets ``floor((b - vmin)/q) - floor((a - vmin)/q) + 1`` bins of
    width ``q`` (``vmin`` the smallest value); ``I4(G, q)`` sums them over the cubes of the grid,
    ``I4(G', 2q)`` over those of level 1 with bins twice as wide, and ``D4 = log2(I4(G, q) /
    I4(G', 2q))`` (NaN where either is 0): 3 for a smooth field, towards 4 for noise.

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    q : float, optional
        The bin width; 0: 1 for integer data, ``(vmax - vmin) / 256`` for float data.
    device : str, optional
        A substring of a device name (``devices()``).

    Returns
    -------
    Fd4
        ``q``, ``vmin``, ``i4_l0``, ``i4_l1``, ``d4``.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> r = clfractal.fd4(np.zeros((4, 4, 4), np.uint8) + np.arange(4, dtype=np.uint8))
    >>> r.q, r.i4_l0, r.i4_l1
    (1.0, 54, 2)
    """
    a, type_name = _volume(volume)
    return Fd4(**dict(_clfractal.fd4(a, type_name, float(q), device)))


def local4(volume, q: float = 0.0, window: int = 8, device: str | None = None) -> np.ndarray:
    """The local 4D fractal dimension field ``LD4(v) = log2(I4_W / I4_W')`` (thesis 6.4).

    ``I4`` as in ``fd4`` (bins of width ``q`` at level 0, ``2q`` at level 1) over the windows
    of ``local_fd`` (``window`` even), NaN where ``I4_W'`` is 0: a noise map that needs no
    isovalue (``clfractal local4``).

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    q : float, optional
        The bin width; 0 as in ``fd4``.
    window : int, optional
        The even window ``k`` (default 8).
    device : str, optional

    Returns
    -------
    ndarray of float32
        The field, of the volume's shape.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> clfractal.local4(np.zeros((5, 6, 7), np.uint8), window=4).shape
    (5, 6, 7)
    """
    a, type_name = _volume(volume)
    return _array(_clfractal.local4(a, type_name, float(q), int(window), device))


class Components(NamedTuple):
    """The isosurface component counts of every isovalue (``components``).

    Attributes
    ----------
    isovalues : ndarray
        int64 for integer data, else the data's float type.
    counts : ndarray of int64
        ``components(s)`` per isovalue.
    """
    isovalues: np.ndarray
    counts: np.ndarray


def components(volume, connectivity: str = "cube", isovalues=None, bins: int = 256,
               device: str | None = None) -> Components:
    """Connected components of the isosurface at every isovalue (thesis §3.1).

    With ``A = {f < s}`` and ``C = {f >= s}``: ``components(s) = b0(A) + b0(C) - 1`` (0 when
    either set is empty), ``b0`` counting connected pieces. ``connectivity="cube"`` (marching
    cubes): A 6-connected, C 26-connected. ``"freudenthal"`` (marching tetrahedra, the
    piecewise-linear function): both 14-connected (offsets ±x, ±y, ±z, ±(x+y), ±(y+z),
    ±(x+z), ±(x+y+z)). Isovalues as in ``fd_curve``. Up to 32 given isovalues are labelled
    one by one (one pass over the volume each, memory O(slice)); more, or the default set, take
    one sort and two union-find sweeps that give every isovalue at once.

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    connectivity : {"cube", "freudenthal"}, optional
    isovalues : array_like, optional
        Increasing isovalues (default: as ``fd_curve``).
    bins : int, optional
        Float data: the number of uniform isovalues.
    device : str, optional

    Returns
    -------
    Components
        ``(isovalues, counts)``.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.zeros((5, 5, 5), np.uint8); v[1, 1, 1] = v[3, 3, 3] = 2
    >>> c = clfractal.components(v)
    >>> c.isovalues.tolist(), c.counts.tolist()
    ([0, 1, 2], [0, 2, 2])
    """
    a, type_name = _volume(volume, uploaded=True)
    iso, counts = _clfractal.components(a, type_name, connectivity, _isovalues(isovalues), int(bins), device)
    return Components(_isovalue_array(iso, a.dtype), np.asarray(counts))


class ComponentsStream(_SlicePush):
    """Isosurface component counts at a few isovalues of a volume that arrives slice by slice
    (a scanner, a file larger than memory), memory O(slice) an isovalue.

    The library's ``ComponentsAtStream`` (include/clfractal/components.hpp): ``push`` (ny, nx)
    slices, or (k, ny, nx) stacks of them, in z order; ``counts()`` at any time gives the
    component counts of the slices so far, equal to ``components(volume, isovalues=...)`` of
    the volume they make. Each stack is labelled in z-chunks on every core and joined to the
    slices before it at one seam; runs on the host, no device.

    Parameters
    ----------
    shape : (ny, nx)
        The shape of each slice.
    dtype : numpy dtype
        Their value type (a key of ``VALUE_TYPES``).
    isovalues : array_like
        Increasing isovalues (integers for integer data), a few: each is labelled on its own.
    connectivity : {"cube", "freudenthal"}, optional
        As in ``components``.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.random.default_rng(0).integers(0, 9, (9, 10, 11), dtype=np.uint8)
    >>> stream = clfractal.ComponentsStream(v.shape[1:], v.dtype, isovalues=[3, 4, 5])
    >>> for z in range(0, 9, 4):
    ...     stream.push(v[z:z + 4])
    >>> stream.counts().counts.tolist() == clfractal.components(v, isovalues=[3, 4, 5]).counts.tolist()
    True
    """

    def __init__(self, shape, dtype, isovalues, connectivity: str = "cube"):
        ny, nx = (int(n) for n in shape)
        self.dtype = _stream_dtype(dtype, "ComponentsStream")
        self._stream = _clfractal.ComponentsStream(ny, nx, VALUE_TYPES[self.dtype], _isovalues(isovalues),
                                                   connectivity)

    def counts(self) -> Components:
        """The component counts of the slices so far, as ``components`` gives them."""
        iso, counts = self._stream.counts()
        return Components(_isovalue_array(iso, self.dtype), np.asarray(counts))


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


@dataclasses.dataclass(frozen=True)
class Filtered(_Record):
    """The result of a masked filter (``targeted_filter``, ``ld_guided_filter``).

    Attributes
    ----------
    volume : ndarray
        The filtered volume, of the input's type.
    selected : int
        Vertices the mask selected (``field > threshold``; LD > 2 for the LD-guided filter).
    changed : int
        Vertices whose value differs from the input.
    selected_share, changed_share : float
        ``selected`` and ``changed`` over all vertices.
    """
    volume: np.ndarray
    selected: int
    changed: int
    selected_share: float
    changed_share: float


def _filtered(out) -> Filtered:
    volume, counts = out
    return Filtered(_array(volume), **dict(counts))


def targeted_filter(volume, iso: float | None, threshold: float, method: str = "median", window: int = 8,
                    sigma: float = 1.0, sigma_s: float = 1.0, sigma_r: float = 1.0, mask: str = "ld",
                    q: float = 0.0, device: str | None = None) -> Filtered:
    """The fractal-targeted filter (thesis §4.3): the filter's value only where the mask field
    exceeds ``threshold`` (NaN never qualifies), the input value elsewhere.

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    iso : float or None
        The isovalue of the LD field (``mask="ld"``); unused (None) with ``mask="ld4"``.
    threshold : float
        ``h``: filtered where the field is ``> h``.
    method : {"median", "gaussian", "bilateral"}, optional
    window : int, optional
        The even window of the field.
    sigma : float, optional
        The Gaussian's sigma.
    sigma_s, sigma_r : float, optional
        The bilateral filter's spatial (voxels) and range (value units) sigmas.
    mask : {"ld", "ld4"}, optional
        The field: ``local_fd(volume, iso, window)``, or ``local4(volume, q, window)``
        (``clfractal filter --fractal4``).
    q : float, optional
        The bin width of ``local4`` (``mask="ld4"``).
    device : str, optional

    Returns
    -------
    Filtered
        ``volume``, ``selected``, ``changed``, ``selected_share``, ``changed_share``.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.random.default_rng(0).integers(0, 200, (12, 12, 12), dtype=np.uint8)
    >>> r = clfractal.targeted_filter(v, 100, threshold=2.5, window=4)
    >>> r.volume.shape, 0 <= r.changed_share <= r.selected_share <= 1
    ((12, 12, 12), True)
    """
    if mask == "ld" and iso is None:
        raise ValueError("targeted_filter: mask='ld' needs an isovalue iso")
    a, type_name = _volume(volume)
    return _filtered(_clfractal.targeted_filter(a, type_name, mask, float(iso if iso is not None else 0.0), float(q),
                                                float(threshold), method, int(window), float(sigma),
                                                float(sigma_s), float(sigma_r), device))


def ld_guided_filter(volume, iso: float, sigma_s: float = 1.0, sigma_r: float = 1.0, window: int = 8,
                     device: str | None = None) -> Filtered:
    """The LD-guided bilateral filter (thesis §6.3; ``clfractal filter --bilateral --ld-guided``).

    The bilateral filter with the range scale ``sigma_r * min(LD(v) - 2, 1)`` where the local
    fractal dimension ``LD(v) = local_fd(volume, iso, window)`` exceeds 2; ``f(v)`` where LD is
    at most 2 or undefined.

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    iso : float
        The isovalue of the LD field.
    sigma_s, sigma_r : float, optional
        The spatial (voxels) and full range (value units) sigmas.
    window : int, optional
    device : str, optional

    Returns
    -------
    Filtered
        ``selected`` counts the vertices with LD > 2.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.random.default_rng(0).integers(0, 200, (12, 12, 12), dtype=np.uint8)
    >>> r = clfractal.ld_guided_filter(v, 100, sigma_s=1.0, sigma_r=30.0, window=4)
    >>> r.volume.dtype
    dtype('uint8')
    """
    a, type_name = _volume(volume)
    return _filtered(_clfractal.ld_guided_filter(a, type_name, float(iso), float(sigma_s), float(sigma_r),
                                                 int(window), device))


@dataclasses.dataclass(frozen=True)
class Smoothed(_Record):
    """The result of ``smooth``: the volume and the work Algorithm 2 did.

    Attributes
    ----------
    volume : ndarray
        The smoothed volume, of the input's type.
    high_vertices : int
        Vertices with LD > threshold.
    initial_edges, edges_processed, edges_lowered : int
        High-fractal edges queued first, popped, and lowered.
    vertices_changed : int
        Vertices whose value changed.
    """
    volume: np.ndarray
    high_vertices: int
    initial_edges: int
    edges_processed: int
    edges_lowered: int
    vertices_changed: int


@dataclasses.dataclass(frozen=True)
class SmallComponents(_Record):
    """The small-components filter's result: the filtered ``volume`` (input type), the isovalue
    in the data's type, the components of ``{f >= s}`` (positive) and ``{f < s}`` (negative)
    before, removed and after, and the vertices ``changed`` (``changed_share`` of all)."""
    volume: np.ndarray
    isovalue: float
    positive_before: int
    negative_before: int
    positive_removed: int
    negative_removed: int
    positive_after: int
    negative_after: int
    changed: int
    changed_share: float


def small_components(volume, iso: float, k: int, connectivity: str = "cube") -> SmallComponents:
    """The small-components filter (Zhao & Wenger 2025) at isovalue ``iso``.

    Every component of ``{f >= s}`` with at most ``k`` vertices gets the largest value of the
    type below ``s``, then every component of ``{f < s}`` with at most ``k`` vertices gets the
    smallest value at or above ``s`` (``s`` in the data's type: ``ceil(iso)`` for integer data);
    every other vertex keeps its value.

    Parameters
    ----------
    volume : (z, y, x) array
    iso : float
    k : int
        The largest component size removed (>= 0).
    connectivity : {"cube", "six"}, optional
        ``"cube"``: ``{f >= s}`` 26-connected, ``{f < s}`` 6-connected (marching cubes);
        ``"six"``: both 6-connected (the paper's variant).

    Returns
    -------
    SmallComponents

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> a = np.zeros((5, 5, 5), np.uint8); a[2, 2, 2] = 9
    >>> r = clfractal.small_components(a, 5, 1)
    >>> int(r.volume.max()), r.positive_removed, r.changed
    (4, 1, 1)
    """
    if int(k) < 0:
        raise ValueError(f"k: must be >= 0, got {k}")
    a, type_name = _volume(volume)
    out, info = _clfractal.small_components(a, type_name, float(iso), int(k), connectivity)
    return SmallComponents(_array(out), **dict(info))


def smooth(volume, iso: float, threshold: float, window: int = 8, variant: str = "plain", tau: float = 1.0,
           device: str | None = None) -> Smoothed:
    """Smooth isosurface construction (thesis chapter 5, Algorithm 2).

    LD is computed once on the input. A grid edge is high fractal when it is intersected
    (``a < iso <= b``) and LD > ``threshold`` at either end. Each high-fractal edge ``(v, u)``
    with ``f(v) > f(u)`` that is still intersected gets ``f(v) := f(u)``; edges around changed
    vertices that become intersected and high fractal are queued, until none is left. Variant
    ``"gaussian"`` also lowers the 26 neighbours ``w`` of ``v`` by
    ``(f(v) - f(u)) * exp(-d(v, w)**2 / (2 tau**2))``. Values only decrease.

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    iso : float
    threshold : float
        ``h``.
    window : int, optional
    variant : {"plain", "gaussian"}, optional
    tau : float, optional
        The Gaussian variant's spread.
    device : str, optional

    Returns
    -------
    Smoothed

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.random.default_rng(0).integers(0, 200, (12, 12, 12), dtype=np.uint8)
    >>> r = clfractal.smooth(v, 100, threshold=2.2, window=4)
    >>> bool((r.volume <= v).all()), r.vertices_changed == int((r.volume != v).sum())
    (True, True)
    """
    a, type_name = _volume(volume, uploaded=True)
    out, info = _clfractal.smooth(a, type_name, float(iso), float(threshold), int(window), variant, float(tau),
                                  device)
    return Smoothed(_array(out), **dict(info))


class Mesh(NamedTuple):
    """A triangle mesh (``mesh``), always these three items.

    Attributes
    ----------
    vertices : (n, 3) ndarray of float32
        In ``(z, y, x)`` order times the spacing.
    faces : (m, 3) ndarray of int32
        Vertex indices, normals towards lower values.
    ld : (n,) ndarray of float32 or None
        The local fractal dimension per vertex (``color_by_ld=True``), else None.
    """
    vertices: np.ndarray
    faces: np.ndarray
    ld: Optional[np.ndarray]


def mesh(volume, iso: float, method: str = "mc", color_by_ld: bool = False, window: int = 8,
         spacing=(1.0, 1.0, 1.0), device: str | None = None):
    """The isosurface ``f = iso`` as a triangle mesh, one vertex per intersected grid edge.

    ``method="mc"``: marching cubes separating negative vertices (``f < iso``), so the mesh has
    ``components(volume)`` pieces and ``E(iso)`` vertices; ``"mt"``: marching tetrahedra on the
    Freudenthal triangulation. Returns a ``Mesh`` ``(vertices, faces, ld)``, ``ld`` None
    unless ``color_by_ld``: vertices ``(n, 3)`` float32 in ``(z, y, x)`` order times ``spacing``
    ``(dz, dy, dx)`` (the array's axes, as scikit-image and napari use them), faces ``(m, 3)``
    int32 with normals towards lower values, ``ld`` float32 per vertex (the local fractal
    dimension interpolated along its grid edge; NaN where undefined). Ready for
    ``napari.layers.Surface((vertices, faces, ld))`` or ``trimesh.Trimesh(vertices[:, ::-1],
    faces[:, ::-1])``.

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> v = np.zeros((3, 3, 3), np.uint8); v[1, 1, 1] = 2
    >>> m = clfractal.mesh(v, 1)
    >>> m.vertices.shape, m.faces.shape, m.ld
    ((6, 3), (8, 3), None)
    """
    a, type_name = _volume(volume, uploaded=True)
    verts, faces, ld = _clfractal.mesh(a, type_name, float(iso), method, bool(color_by_ld), int(window),
                                       [float(s) for s in spacing], device)
    verts = np.asarray(verts).reshape(-1, 3)
    faces = np.asarray(faces).reshape(-1, 3)
    return Mesh(verts, faces, None if ld is None else np.asarray(ld))


def write_ply(path, vertices, faces, ld=None) -> None:
    """Writes a mesh as ``mesh`` returns it to a binary PLY file (``clfractal local --mesh``).

    Parameters
    ----------
    path : str or PathLike
    vertices : (n, 3) array_like of float
        ``(z, y, x)`` positions (written as x, y, z).
    faces : (m, 3) array_like of int
        Vertex indices, as ``mesh`` returns them.
    ld : (n,) array_like of float, optional
        Per-vertex local fractal dimension: written with the thesis colour map (blue at
        2.2 or less, red from 2.5, grey where NaN).

    Examples
    --------
    >>> import numpy as np, clfractal, tempfile, os
    >>> v = np.zeros((3, 3, 3), np.uint8); v[1, 1, 1] = 2
    >>> path = os.path.join(tempfile.mkdtemp(), "m.ply")
    >>> clfractal.write_ply(path, *clfractal.mesh(v, 1))
    >>> open(path, "rb").read(3)
    b'ply'
    """
    verts = np.ascontiguousarray(vertices, dtype=np.float32)
    tris = np.ascontiguousarray(faces, dtype=np.int64)
    if verts.ndim != 2 or tris.ndim != 2:
        raise ValueError(f"{path}: vertices and faces must be (n, 3) and (m, 3) arrays")
    values = None if ld is None else np.ascontiguousarray(ld, dtype=np.float32).ravel()
    _clfractal.write_ply(str(path), verts, tris, values)


@dataclasses.dataclass(frozen=True)
class NoiseLevel(_Record):
    """The noise level of a volume (``noise_level``; ``clfractal fd --noise-level --json``).

    Attributes
    ----------
    sigma : float
        The noise's standard deviation in grey values, correlation allowed for: what a
        uniform region shows.
    sigma_white : float
        Its white (vertex-to-vertex) part: the pooled residual of the flat blocks.
    correlation : tuple of float
        The correlation model's width along x, y, z in voxels (the Gaussian smoothing whose
        correlation the noise's matches; 0: white; NaN: n/a).
    sigma_strides : tuple of int
        The taps spacing along x, y, z sigma was read at.
    texture : bool
        Whether the residuals at the wider taps rise or vary from block to block beyond what
        noise gives (texture or structure): the correlation is then refused and sigma is
        sigma_white.
    spread : tuple of float
        The map's 10th, 50th and 90th percentiles.
    variation : float
        The 90th percentile over the 10th.
    notes : list of str
        Plain statements: how much the noise varies, whether it is correlated.
    flat_share : float
        The flat blocks' voxels over all voxels.
    block, blocks, blocks_usable, blocks_flat : int
        The block edge and the block counts.
    typical_variance : float
    seconds : float
    map_cell : int
        The edge of a map cell.
    map : ndarray of float32
        sigma per cell, (z, y, x), NaN where a cell has no usable block.
    """
    sigma: float
    sigma_white: float
    correlation: tuple
    sigma_strides: tuple
    texture: bool
    spread: tuple
    variation: float
    notes: list
    flat_share: float
    block: int
    blocks: int
    blocks_usable: int
    blocks_flat: int
    typical_variance: float
    seconds: float
    map_cell: int
    map: np.ndarray

    def to_dict(self) -> dict:
        """The object ``clfractal fd --noise-level --json`` writes under ``noise``: the spread as
        ``{"p10", "p50", "p90"}``, the map as ``{"cell", "dims": [nx, ny, nz], "sigma": [x
        fastest, null where no block is usable]}``."""
        d = {k: _plain(getattr(self, k)) for k in ("sigma", "sigma_white", "correlation", "sigma_strides",
                                                   "texture", "variation", "notes", "flat_share", "block", "blocks",
                                                   "blocks_usable", "blocks_flat", "seconds")}
        d["spread"] = dict(zip(("p10", "p50", "p90"), _plain(self.spread)))
        nz, ny, nx = self.map.shape
        d["map"] = {"cell": self.map_cell, "dims": [nx, ny, nz], "sigma": _plain(self.map.astype(np.float64).ravel())}
        return d


def noise_level(volume, block: int = 0, map_block: int = 32, clip: float = 3.0,
                device: str | None = None) -> NoiseLevel:
    """The standard deviation of the volume's noise in grey values, from the flat parts of the
    volume (include/clfractal/noise_level.hpp; ``clfractal fd --noise-level``).

    At every interior vertex the residual ``R`` is the product of the second differences
    ``[1, -2, 1]`` along the three axes; ``R**2 / 216`` estimates the noise variance for every
    noise distribution, and is 0 on fields that are at most quadratic along any one axis. Per
    block of ``block**3`` vertices (0: 8, or 4 for volumes that hold fewer than 64 blocks of
    8), blocks that read the volume's smallest or largest value (clipping) are left out; the
    centre is the shorth of ``log(v) / 3`` over the block variances ``v``, the flat blocks lie
    within ``clip`` white-noise spreads of it, and their pooled mean is ``sigma_white**2`` (0
    when no usable block has any residual, NaN when no block is usable): the noise's white
    part. Residuals with the taps 2, 4 and 8 apart along one axis fit a model of white noise
    plus noise smoothed by a Gaussian of width ``correlation`` (x, y, z) voxels, and ``sigma``
    is read at taps two apart along the correlated axes: the noise's standard deviation,
    correlated or not (docs/definitions.md, section 34).

    Parameters
    ----------
    volume : (z, y, x) array or DeviceVolume
    block : int, optional
        The block edge (0: automatic).
    map_block : int, optional
        The edge of a map cell.
    clip : float, optional
        How many white-noise spreads from the centre a flat block may lie.
    device : str, optional

    Returns
    -------
    NoiseLevel

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> ramp = np.broadcast_to(np.arange(32, dtype=np.uint8)[:, None, None], (32, 16, 16))
    >>> clfractal.noise_level(ramp).sigma  # no residual: a linear field has no noise
    0.0
    """
    a, type_name = _volume(volume, uploaded=True)
    r = dict(_clfractal.noise_level(a, type_name, int(block), int(map_block), float(clip), device))
    r["map"] = np.asarray(r["map"]).reshape(r.pop("map_shape"))
    return NoiseLevel(**r)


@dataclasses.dataclass(frozen=True)
class Recommendation(_Record):
    """One recommended isovalue (``analyse``): ``isovalue``, ``fd``, ``count``, ``count_sub``,
    ``components`` (None when not computed), ``verdict`` ("clean", "rough", "noisy",
    "undefined"), the band ``first``..``last`` it stands for, ``boundary`` (the mean gradient of
    its surfaces in cubes per vertex) and ``basis`` ("clean band", "cleanest quarter" or
    "largest surface")."""
    isovalue: float
    fd: float
    count: int
    count_sub: int
    components: Optional[int]
    verdict: str
    first: float
    last: float
    boundary: float
    basis: str


def _recommendation(e: dict) -> Recommendation:
    return Recommendation(e["isovalue"], float("nan") if e["fd"] is None else e["fd"], e["count"], e["count_sub"],
                          e["components"], e["verdict"], e["first"], e["last"], e["boundary"], e["basis"])


@dataclasses.dataclass(frozen=True)
class Analysis(_Record):
    """The answer ``analyse`` gives: which isovalue to use, how noisy the scan is, what
    denoising helps.

    ``clean`` says whether a well-populated isovalue is clean; ``recommended`` (a list of
    ``Recommendation``, best first) is never empty when a cube is intersected; ``noisiest``
    the well-populated isovalue with the largest D (or None); ``noise_sigma`` the noise's
    standard deviation in grey values (NaN when not computed or no block is usable);
    ``denoise`` the attempts of the denoising ladder (dicts with ``filter``, ``threshold``,
    ``changed_share``, ``clean``, ``recommended``, ``command``), empty when the scan is clean;
    ``json`` the whole analysis as ``clfractal fd --json`` writes its shared part.
    """
    clean: bool
    recommended: list
    noisiest: Optional[Recommendation]
    noise_sigma: float
    clean_bands: list
    denoise: list
    json: dict

    @property
    def best(self) -> Recommendation:
        """The isovalue to use: the first recommendation."""
        return self.recommended[0]

    def to_dict(self) -> dict:
        """The analysis as ``clfractal fd --json`` and ``clfractal report --json`` write it (a
        copy of ``json``): plain JSON values."""
        return json.loads(json.dumps(self.json))

    def _repr_html_(self) -> str:
        """The answer in a notebook: the isovalue to use, the recommendations, the noise and
        the curve D(s) (an inline SVG; ``report`` writes the whole page)."""
        return _analysis_html(self)


def analyse(volume, clean_fd: float = 2.2, noisy_fd: float = 2.5, clean_share: float = 0.01, bins: int = 256,
            components: str = "curve", noise_level: bool = True, fd4: bool = True, denoise: bool = True,
            window: int = 8, device: str | None = None) -> Analysis:
    """Which isovalue gives a clean surface, how noisy the scan is, and what to do about it.

    The same analysis ``clfractal fd`` and ``clfractal report`` print (docs/definitions.md
    §33): the curve D(s), verdicts (clean ``D <= clean_fd``, noisy ``D >= noisy_fd``, rough
    between), the clean bands, recommendations at the material boundaries of each band (never
    empty: when nothing is clean, the cleanest quarter of the well-populated isovalues), the
    noise level, and, when nothing is clean, the fractal-targeted median (LD > 2.5, then > 2.2)
    and the median, each re-analysed until one leaves a clean isovalue. The defaults compute
    what ``clfractal report`` computes (the whole component curve, the noise level, D4, the
    denoising ladder within 4x the volume + 256 MiB), so ``to_dict()`` equals its ``--json``
    apart from the page's own entries (volume, device, views, explore, seconds).

    Parameters
    ----------
    volume : (z, y, x) array
    clean_fd, noisy_fd : float, optional
        The verdicts' thresholds.
    clean_share : float, optional
        Well-populated: ``I(s) >= clean_share * max I``.
    bins : int, optional
        Uniform isovalues of float and wide integer data.
    components : {"none", "recommended", "curve"}, optional
        Isosurface components at the recommended isovalues, over the whole curve, or none.
    noise_level, fd4, denoise : bool, optional
        Compute the noise level (and Theorem 1 inverted per isovalue), the 4D dimension, the
        denoising ladder.
    window : int, optional
        The LD window of the targeted filter (even).
    device : str, optional
        A substring of a device name (``devices()``).

    Returns
    -------
    Analysis

    Examples
    --------
    >>> import numpy as np, clfractal
    >>> z, y, x = np.mgrid[:32, :32, :32]
    >>> sphere = np.clip(200 - 12 * np.sqrt((x - 15.5) ** 2 + (y - 15.3) ** 2 + (z - 15.7) ** 2), 0, 255)
    >>> a = clfractal.analyse(sphere.astype(np.uint8), noise_level=False)
    >>> a.clean, a.best.verdict, a.best.components
    (True, 'clean', 1)
    >>> import json; json.loads(json.dumps(a.to_dict()))["recommended"][0]["verdict"]
    'clean'
    """
    a, type_name = _volume(volume)
    j = json.loads(_clfractal.analyse(a, type_name, float(clean_fd), float(noisy_fd), float(clean_share), int(bins),
                                      components, bool(noise_level), bool(fd4), bool(denoise), int(window), device))
    sigma = j.get("noise", {}).get("sigma")
    return Analysis(j["clean"], [_recommendation(e) for e in j["recommended"]],
                    _recommendation(j["noisiest"]) if j["noisiest"] else None,
                    float("nan") if sigma is None else float(sigma), j["clean_bands"], j["denoise"]["attempts"], j)


def _curve_svg(curve: list, clean_fd: float, noisy_fd: float, width: int = 480, height: int = 200) -> str:
    """D(s) of the analysis JSON's curve as an inline SVG line plot, the verdicts' thresholds
    dashed."""
    pts = [(c["isovalue"], c["fd"]) for c in curve if c["fd"] is not None]
    if not pts:
        return "<p>D(s) is undefined at every isovalue.</p>"
    x0, x1 = min(p[0] for p in pts), max(p[0] for p in pts)
    y0, y1 = min(1.5, min(p[1] for p in pts)), max(3.0, max(p[1] for p in pts))
    sx = lambda x: 40 + (width - 50) * (0.5 if x1 == x0 else (x - x0) / (x1 - x0))  # noqa: E731
    sy = lambda y: 10 + (height - 40) * (y1 - y) / (y1 - y0)  # noqa: E731
    line = " ".join(f"{sx(x):.1f},{sy(y):.1f}" for x, y in pts)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" role="img" '
           f'aria-label="fractal dimension curve">',
           f'<rect x="40" y="10" width="{width - 50}" height="{height - 40}" fill="none" stroke="#999"/>']
    for t, colour in ((clean_fd, "#2e7d32"), (noisy_fd, "#c62828")):
        out.append(f'<line x1="40" x2="{width - 10}" y1="{sy(t):.1f}" y2="{sy(t):.1f}" stroke="{colour}" '
                   f'stroke-dasharray="4 3"/><text x="{width - 12}" y="{sy(t) - 3:.1f}" font-size="10" '
                   f'text-anchor="end" fill="{colour}">{t:g}</text>')
    out.append(f'<polyline points="{line}" fill="none" stroke="#1565c0" stroke-width="1.5"/>')
    out.append(f'<text x="40" y="{height - 14}" font-size="10">{x0:g}</text>'
               f'<text x="{width - 10}" y="{height - 14}" font-size="10" text-anchor="end">{x1:g}</text>'
               f'<text x="{(width + 30) / 2}" y="{height - 2}" font-size="11" text-anchor="middle">isovalue s</text>'
               f'<text x="4" y="{sy(y1) + 10:.1f}" font-size="10">{y1:g}</text>'
               f'<text x="4" y="{sy(y0):.1f}" font-size="10">{y0:g}</text>'
               f'<text x="4" y="{height / 2}" font-size="11">D(s)</text></svg>')
    return "".join(out)


def _analysis_html(a: Analysis) -> str:
    import html
    j = a.json
    num = lambda x, d=4: "n/a" if x is None else (f"{x:.{d}g}" if isinstance(x, float) else str(x))  # noqa: E731
    rows = "".join(f"<tr><td>{num(e['isovalue'], 8)}</td><td>{html.escape(e['verdict'])}</td><td>{num(e['fd'])}</td>"
                   f"<td>{e['count']}</td><td>{num(e['components'])}</td><td>{num(e['first'], 8)} .. "
                   f"{num(e['last'], 8)}</td><td>{html.escape(e['basis'])}</td></tr>" for e in j["recommended"])
    if not j["recommended"]:
        answer = "No surface: no cube is intersected at any isovalue."
    else:
        b = j["recommended"][0]
        answer = (f"Use isovalue {num(b['isovalue'], 8)} ({b['verdict']}, D = {num(b['fd'])})." if j["clean"] else
                  f"No isovalue is clean; the cleanest is {num(b['isovalue'], 8)} ({b['verdict']}, D = "
                  f"{num(b['fd'])}).")
    noise = j.get("noise", {})
    parts = [f"<div class=\"clfractal-analysis\"><p><b>{html.escape(answer)}</b></p>"]
    if "sigma" in noise:
        parts.append(f"<p>Noise: &sigma; = {num(noise['sigma'])} grey values, white part "
                     f"{num(noise['sigma_white'])} (flat share {num(noise['flat_share'], 3)}).</p>")
        parts.extend(f"<p>{html.escape(note)}</p>" for note in noise.get("notes", []))
    tried = [t for t in a.denoise if t["clean"] and t["recommended"]]
    if tried:
        parts.append(f"<p>Denoising: <code>{html.escape(tried[0]['command'])}</code> leaves isovalue "
                     f"{num(tried[0]['recommended'][0]['isovalue'], 8)} clean.</p>")
    if "fd4" in j:
        parts.append(f"<p>D4 = {num(j['fd4']['d4'], 5)}.</p>")
    parts.append("<table><tr><th>isovalue</th><th>verdict</th><th>D</th><th>cubes</th><th>components</th>"
                 f"<th>band</th><th>basis</th></tr>{rows}</table>")
    parts.append(_curve_svg(j["curve"], j["advice"]["clean_fd"], j["advice"]["noisy_fd"]))
    parts.append("</div>")
    return "".join(parts)


def report(volume, path, json_path=None, clean_fd: float = 2.2, clean_share: float = 0.01, window: int = 8,
           bins: int = 0, mesh_triangles: int = 50000, static: bool = False, name: str | None = None,
           spacing=None, progress: bool = False, device: str | None = None, **read_options) -> dict:
    """Writes the page ``clfractal report`` writes: one self-contained HTML file answering
    which isovalues are clean and how noisy the scan is, with the curves, the clean bands, the
    noise, D4 and pictures of the recommended and the noisiest isovalue.

    Parameters
    ----------
    volume : (z, y, x) array, VolumeFile, or a file path (str or PathLike)
        A path is read as the command line reads it (``read_options`` as for ``read_volume``),
        and the page is then the command's page byte for byte apart from its time.
    path : str or PathLike
        The HTML page to write.
    json_path : str or PathLike, optional
        Also write the page's numbers as JSON (``--json``).
    clean_fd, clean_share, window, bins, mesh_triangles, static
        As ``clfractal report``'s options (``static``: ``--static``).
    name : str, optional
        The page's "file" line for an array (default "array").
    spacing : (dz, dy, dx), optional
        An array's spacing (a ``VolumeFile`` carries its own).
    progress : bool, optional
        Progress lines on stderr, as the command prints them.
    device : str, optional

    Returns
    -------
    dict
        The page's numbers (what ``json_path`` receives).

    Both files are written whole or not at all (a link, a pipe or ``-`` is written through).
    The pictures need gnuplot (Debian's ``gnuplot-nox``), the 3D view Debian's ``libjs-three``
    (else the page says so and stays static).
    """
    _out = lambda p: "" if p is None else os.fspath(p)  # noqa: E731
    if isinstance(volume, (str, os.PathLike)):
        js = _clfractal.report_file(os.fspath(path), _out(json_path), str(volume), _raw_options(**{"dims": None, "dtype": None, "endian": "little",
                                                                      "spacing": None, "series": None,
                                                                      "scaled": False, "as_type": None,
                                                                      **read_options}),
                                          float(clean_fd), float(clean_share), int(window), int(bins),
                                          int(mesh_triangles), bool(static), bool(progress), device)
    else:
        if read_options:
            raise TypeError("report: read options apply to a file path: " + ", ".join(sorted(read_options)))
        if isinstance(volume, VolumeFile):
            volume, spacing = volume.volume, spacing or volume.spacing
        a, type_name = _volume(volume)
        js = _clfractal.report_array(os.fspath(path), _out(json_path), a, type_name, name or "array",
                                           [float(x) for x in (spacing or (1.0, 1.0, 1.0))], float(clean_fd),
                                           float(clean_share), int(window), int(bins), int(mesh_triangles),
                                           bool(static), bool(progress), device)
    return json.loads(js)


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


class VolumeFile(NamedTuple):
    """A volume read from a file (``read_volume``).

    Attributes
    ----------
    volume : ndarray
        ``(z, y, x)``, the stored voxel order.
    spacing : tuple of float
        ``(dz, dy, dx)``.
    """
    volume: np.ndarray
    spacing: tuple


def _raw_options(dims, dtype, endian, spacing, series, scaled, as_type):
    """The library's read options; dims and spacing given in (z, y, x) order."""
    name = lambda t: None if t is None else (VALUE_TYPES[np.dtype(t)] if not isinstance(t, str) else t)  # noqa: E731
    return _clfractal.raw_options(None if dims is None else [int(n) for n in dims][::-1], name(dtype), endian,
                                  None if spacing is None else [float(x) for x in spacing][::-1], series or "",
                                  bool(scaled), name(as_type))


def read_volume(path, dims=None, dtype=None, endian: str = "little", spacing=None, series: str | None = None,
                scaled: bool = False, as_type=None) -> VolumeFile:
    """Reads a volume file the library reads, the format told by the content.

    NRRD, NIfTI, DICOM (a file or a series directory), TIFF (multi-page or a directory of
    slices), MetaImage, raw files (named ``NAME_XxYxZ_TYPE.raw``, or with ``dims`` and
    ``dtype``), or ``synthetic:NAME[:N]``. Float data with NaN (an LD field) is read as it is;
    the computing calls reject it. Options as the command line's.

    Parameters
    ----------
    path : str or PathLike
    dims : (nz, ny, nx), optional
        Raw files: the grid (``--dims``, given there as X,Y,Z).
    dtype : numpy dtype or type name, optional
        Raw files: the value type (``--type``).
    endian : {"little", "big"}, optional
        Raw files: the byte order.
    spacing : (dz, dy, dx), optional
        Raw files: the spacing.
    series : str, optional
        DICOM directories: the series instance UID to read.
    scaled : bool, optional
        NIfTI: apply ``scl_slope``/``scl_inter``.
    as_type : numpy dtype or type name, optional
        Convert the values on read (may round; saturates to the type's range).

    Returns
    -------
    VolumeFile
        ``(volume, spacing)``; the computing calls take it as they take its ``volume``.

    Raises
    ------
    ValueError
        Naming the file and the problem (missing, truncated, unknown format, ...).

    Examples
    --------
    >>> import clfractal
    >>> v, spacing = clfractal.read_volume("synthetic:sphere:16")
    >>> v.shape, spacing
    ((16, 16, 16), (1.0, 1.0, 1.0))
    """
    out, sp = _clfractal.read_volume(str(path), _raw_options(dims, dtype, endian, spacing, series, scaled, as_type))
    return VolumeFile(_array(out), tuple(sp))


class Orientation(NamedTuple):
    """Where a grid lies in the patient's LPS space (docs/definitions.md §27): NIfTI sform
    (else qform, RAS converted), NRRD space directions, DICOM and MetaImage positions.

    Attributes
    ----------
    origin : tuple of float
        The LPS position ``(L, P, S)`` in mm of voxel ``[0, 0, 0]``.
    axes : tuple of three tuples of float
        The unit LPS direction of each array axis, rows in ``(z, y, x)`` order (a voxel step
        along axis ``i`` moves ``spacing[i] * axes[i]``).
    """
    origin: tuple
    axes: tuple


def write_volume(path, volume, spacing=(1.0, 1.0, 1.0), orientation=None) -> None:
    """Writes a ``(z, y, x)`` array as NIfTI (``.nii``, ``.nii.gz``) or NRRD (any other name),
    with its spacing and orientation; atomically (a temporary file renamed into place). NaN and
    Inf are written as they are (LD fields).

    Parameters
    ----------
    path : str or PathLike
    volume : (z, y, x) array of a supported type
    spacing : (dz, dy, dx), optional
    orientation : Orientation or (origin, axes), optional
        Written as the NIfTI sform and qform (RAS) or the NRRD space origin and directions
        (LPS); ``axes`` are normalised. None: spacing only (NIfTI pixdim, NRRD spacings).
        ``info(path).orientation`` reads it back.

    Examples
    --------
    >>> import numpy as np, clfractal, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "v.nii")
    >>> clfractal.write_volume(path, np.arange(24, dtype=np.int16).reshape(2, 3, 4), spacing=(3.0, 2.0, 0.5),
    ...                        orientation=((10.0, -4.0, 2.5), ((0, 0, 1), (0, -1, 0), (1, 0, 0))))
    >>> clfractal.read_volume(path).spacing
    (3.0, 2.0, 0.5)
    >>> clfractal.info(path).orientation.origin
    (10.0, -4.0, 2.5)
    """
    a = np.asarray(volume)
    if a.ndim != 3:
        raise ValueError(f"{path}: expected a 3D array in (z, y, x) order, got shape {a.shape}")
    native = a.dtype.newbyteorder("=")
    if native not in VALUE_TYPES:
        raise ValueError(f"{path}: {a.dtype} is not a type the writers store ({', '.join(VALUE_TYPES.values())})")
    a = a.astype(native, copy=False)
    origin = axes = None
    if orientation is not None:
        origin, axes = orientation
        origin = [float(x) for x in np.asarray(origin, dtype=np.float64).ravel()]
        axes = [float(x) for x in np.asarray(axes, dtype=np.float64).ravel()]
    _clfractal.write_volume(a, VALUE_TYPES[native], str(path), [float(x) for x in spacing], origin, axes)


@dataclasses.dataclass(frozen=True)
class VolumeInfo(_Record):
    """What ``clfractal info`` tells of a volume file (``info``).

    Attributes
    ----------
    path : str
    header : list of str
        The format and header facts the array does not carry, one line each.
    shape : tuple of int
        ``(nz, ny, nx)``.
    dtype : str
        The library's type name.
    spacing : tuple of float
        ``(dz, dy, dx)``.
    min, max : float
        The smallest and largest finite value.
    nan, inf : int
        NaN and Inf counts.
    orientation : Orientation or None
        The file's LPS origin and axis directions; None when it carries none.
    """
    path: str
    header: list
    shape: tuple
    dtype: str
    spacing: tuple
    min: float
    max: float
    nan: int
    inf: int
    orientation: Optional[Orientation]


def info(path, dims=None, dtype=None, endian: str = "little", spacing=None, series: str | None = None,
         scaled: bool = False, as_type=None) -> VolumeInfo:
    """The format, grid and value range of a volume file (``clfractal info``).

    Parameters
    ----------
    path : str or PathLike
    dims, dtype, endian, spacing, series, scaled, as_type
        As for ``read_volume``.

    Returns
    -------
    VolumeInfo

    Examples
    --------
    >>> import clfractal
    >>> i = clfractal.info("synthetic:sphere:16")
    >>> i.shape, i.dtype
    ((16, 16, 16), 'uint8')
    """
    r = dict(_clfractal.info(str(path), _raw_options(dims, dtype, endian, spacing, series, scaled, as_type)))
    r["header"], r["shape"], r["spacing"] = list(r["header"]), tuple(r["shape"]), tuple(r["spacing"])
    if r["orientation"] is not None:
        origin, axes = r["orientation"]
        r["orientation"] = Orientation(tuple(origin), tuple(tuple(a) for a in axes))
    return VolumeInfo(**r)


def devices() -> list[dict]:
    """Every OpenCL device: platform, name, type, global_mem, max_alloc, compute_units,
    ``default`` (the one used without a ``device`` argument) and ``drivers`` (where the
    OpenCL drivers were found, ``OPENCL_DRIVERS``). An empty list when there is no device:
    ``pip install 'clfractal[cpu]'`` gives a CPU device (PoCL from PyPI), a GPU vendor's
    OpenCL driver a GPU."""
    return [dict(d, drivers=OPENCL_DRIVERS) for d in _clfractal.devices()]


def device_description(device: str | None = None) -> str:
    """``"platform / device"`` of the device a call with this ``device`` argument runs on."""
    return _clfractal.device_description(device)
