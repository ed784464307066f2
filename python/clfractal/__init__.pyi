# Type stubs of the clfractal package (docstrings: help(clfractal.NAME)).
from os import PathLike
from typing import Any, Literal, NamedTuple, overload

import numpy as np
import numpy.typing as npt

__version__: str
VALUE_TYPES: dict[np.dtype[Any], str]
OPENCL_DRIVERS: str

_Device = str | None
_Isovalues = npt.ArrayLike | None

class DeviceVolume:
    dtype: np.dtype[Any]
    shape: tuple[int, int, int]
    @property
    def zero_copy(self) -> bool: ...
    def __init__(self, volume: npt.ArrayLike, device: _Device = None) -> None: ...

_Volume = npt.ArrayLike | DeviceVolume

def uploads(device: _Device = None) -> int: ...

class FdCurve:
    isovalues: npt.NDArray[np.int64] | npt.NDArray[np.floating[Any]]
    counts: npt.NDArray[np.uint64]
    fd: npt.NDArray[np.float64]
    fd_fit: npt.NDArray[np.float64] | None
    summary: dict[str, Any]
    kind: Literal["box", "edge"]
    levels: int
    def __len__(self) -> int: ...
    def to_dict(self) -> dict[str, Any]: ...
    def to_pandas(self) -> Any: ...

def fd_curve(volume: _Volume, kind: Literal["box", "edge"] = "box", levels: int = 2,
             isovalues: _Isovalues = None, bins: int = 256, min_count: int = 0,
             device: _Device = None) -> FdCurve: ...
class SliceStream:
    dtype: np.dtype[Any]
    kind: Literal["box", "edge"]
    levels: int
    def __init__(self, shape: tuple[int, int], dtype: npt.DTypeLike, isovalues: npt.ArrayLike, levels: int = 2,
                 kind: Literal["box", "edge"] = "box", device: _Device = None) -> None: ...
    @property
    def slices(self) -> int: ...
    def push(self, slices: npt.ArrayLike) -> None: ...
    def curve(self) -> FdCurve: ...

def local_fd(volume: _Volume, iso: float, window: int = 8,
             device: _Device = None) -> npt.NDArray[np.float32]: ...
class _Record:
    def to_dict(self) -> dict[str, Any]: ...

class Fd4(_Record):
    q: float
    vmin: float
    i4_l0: int
    i4_l1: int
    d4: float

def fd4(volume: _Volume, q: float = 0.0, device: _Device = None) -> Fd4: ...
def local4(volume: _Volume, q: float = 0.0, window: int = 8,
           device: _Device = None) -> npt.NDArray[np.float32]: ...

class Components(NamedTuple):
    isovalues: npt.NDArray[Any]
    counts: npt.NDArray[np.int64]

def components(volume: _Volume, connectivity: Literal["cube", "freudenthal"] = "cube",
               isovalues: _Isovalues = None, bins: int = 256,
               device: _Device = None) -> Components: ...

class ComponentsStream:
    dtype: np.dtype[Any]
    def __init__(self, shape: tuple[int, int], dtype: npt.DTypeLike, isovalues: npt.ArrayLike,
                 connectivity: Literal["cube", "freudenthal"] = "cube") -> None: ...
    @property
    def slices(self) -> int: ...
    def push(self, slices: npt.ArrayLike) -> None: ...
    def counts(self) -> Components: ...

def median(volume: _Volume, device: _Device = None) -> npt.NDArray[Any]: ...
def gaussian(volume: _Volume, sigma: float, device: _Device = None) -> npt.NDArray[Any]: ...
def bilateral(volume: _Volume, sigma_s: float, sigma_r: float,
              device: _Device = None) -> npt.NDArray[Any]: ...
class Filtered(_Record):
    volume: npt.NDArray[Any]
    selected: int
    changed: int
    selected_share: float
    changed_share: float

def targeted_filter(volume: _Volume, iso: float | None, threshold: float,
                    method: Literal["median", "gaussian", "bilateral"] = "median", window: int = 8,
                    sigma: float = 1.0, sigma_s: float = 1.0, sigma_r: float = 1.0,
                    mask: Literal["ld", "ld4"] = "ld", q: float = 0.0, device: _Device = None) -> Filtered: ...
def ld_guided_filter(volume: _Volume, iso: float, sigma_s: float = 1.0, sigma_r: float = 1.0,
                     window: int = 8, device: _Device = None) -> Filtered: ...

class Smoothed(_Record):
    volume: npt.NDArray[Any]
    high_vertices: int
    initial_edges: int
    edges_processed: int
    edges_lowered: int
    vertices_changed: int

class SmallComponents(_Record):
    volume: npt.NDArray[Any]
    isovalue: float
    positive_before: int
    negative_before: int
    positive_removed: int
    negative_removed: int
    positive_after: int
    negative_after: int
    changed: int
    changed_share: float

def small_components(volume: _Volume, iso: float, k: int,
                     connectivity: Literal["cube", "six"] = "cube") -> SmallComponents: ...
def smooth(volume: _Volume, iso: float, threshold: float, window: int = 8,
           variant: Literal["plain", "gaussian"] = "plain", tau: float = 1.0,
           device: _Device = None) -> Smoothed: ...

class Mesh(NamedTuple):
    vertices: npt.NDArray[np.float32]
    faces: npt.NDArray[np.int32]
    ld: npt.NDArray[np.float32] | None

def mesh(volume: _Volume, iso: float, method: Literal["mc", "mt"] = "mc",
         color_by_ld: bool = False, window: int = 8,
         spacing: tuple[float, float, float] = (1.0, 1.0, 1.0), device: _Device = None) -> Mesh: ...
def write_ply(path: str | PathLike[str], vertices: npt.ArrayLike, faces: npt.ArrayLike,
              ld: npt.ArrayLike | None = None) -> None: ...

class NoiseLevel(_Record):
    sigma: float
    sigma_white: float
    correlation: tuple[float, float, float]
    sigma_strides: tuple[int, int, int]
    spread: tuple[float, float, float]
    variation: float
    notes: list[str]
    flat_share: float
    block: int
    blocks: int
    blocks_usable: int
    blocks_flat: int
    typical_variance: float
    seconds: float
    map_cell: int
    map: npt.NDArray[np.float32]

def noise_level(volume: _Volume, block: int = 0, map_block: int = 32, clip: float = 3.0,
                device: _Device = None) -> NoiseLevel: ...
class Recommendation(_Record):
    isovalue: float
    fd: float
    count: int
    count_sub: int
    components: int | None
    verdict: Literal["clean", "rough", "noisy", "undefined"]
    first: float
    last: float
    boundary: float
    basis: str

class Analysis(_Record):
    clean: bool
    recommended: list[Recommendation]
    noisiest: Recommendation | None
    noise_sigma: float
    clean_bands: list[dict[str, Any]]
    denoise: list[dict[str, Any]]
    json: dict[str, Any]
    @property
    def best(self) -> Recommendation: ...
    def to_dict(self) -> dict[str, Any]: ...
    def _repr_html_(self) -> str: ...

def analyse(volume: npt.ArrayLike, clean_fd: float = 2.2, noisy_fd: float = 2.5, clean_share: float = 0.01,
            bins: int = 256, components: Literal["none", "recommended", "curve"] = "curve",
            noise_level: bool = True, fd4: bool = True, denoise: bool = True, window: int = 8,
            device: _Device = None) -> Analysis: ...
def report(volume: npt.ArrayLike | VolumeFile | str | PathLike[str], path: str | PathLike[str],
           json_path: str | PathLike[str] | None = None, clean_fd: float = 2.2, clean_share: float = 0.01,
           window: int = 8, bins: int = 0, mesh_triangles: int = 50000, static: bool = False,
           name: str | None = None, spacing: tuple[float, float, float] | None = None, progress: bool = False,
           device: _Device = None, **read_options: Any) -> dict[str, Any]: ...
@overload
def noise_dimension(mu: float, gamma: float = 1.0, kind: Literal["uniform", "gaussian"] = "uniform") -> float: ...
@overload
def noise_dimension(mu: npt.NDArray[Any], gamma: float = 1.0,
                    kind: Literal["uniform", "gaussian"] = "uniform") -> npt.NDArray[np.float64]: ...
class VolumeFile(NamedTuple):
    volume: npt.NDArray[Any]
    spacing: tuple[float, float, float]

_Type = npt.DTypeLike | str | None

def read_volume(path: str | PathLike[str], dims: tuple[int, int, int] | None = None, dtype: _Type = None,
                endian: Literal["little", "big"] = "little", spacing: tuple[float, float, float] | None = None,
                series: str | None = None, scaled: bool = False, as_type: _Type = None) -> VolumeFile: ...
class Orientation(NamedTuple):
    origin: tuple[float, float, float]
    axes: tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]

def write_volume(path: str | PathLike[str], volume: npt.ArrayLike,
                 spacing: tuple[float, float, float] = (1.0, 1.0, 1.0),
                 orientation: Orientation | tuple[Any, Any] | None = None) -> None: ...

class VolumeInfo(_Record):
    path: str
    header: list[str]
    shape: tuple[int, int, int]
    dtype: str
    spacing: tuple[float, float, float]
    min: float
    max: float
    nan: int
    inf: int
    orientation: Orientation | None

def info(path: str | PathLike[str], dims: tuple[int, int, int] | None = None, dtype: _Type = None,
         endian: Literal["little", "big"] = "little", spacing: tuple[float, float, float] | None = None,
         series: str | None = None, scaled: bool = False, as_type: _Type = None) -> VolumeInfo: ...
def devices() -> list[dict[str, Any]]: ...
def device_description(device: _Device = None) -> str: ...
