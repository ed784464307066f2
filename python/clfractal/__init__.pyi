# Type stubs of the clfractal package (docstrings: help(clfractal.NAME)).
from os import PathLike
from typing import Any, Literal, overload

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
    def to_pandas(self) -> Any: ...

def fd_curve(volume: _Volume, kind: Literal["box", "edge"] = "box", levels: int = 2,
             isovalues: _Isovalues = None, bins: int = 256, min_count: int = 0,
             device: _Device = None) -> FdCurve: ...
def local_fd(volume: _Volume, iso: float, window: int = 8,
             device: _Device = None) -> npt.NDArray[np.float32]: ...
def fd4(volume: _Volume, q: float = 0.0, device: _Device = None) -> dict[str, float | int]: ...
def components(volume: _Volume, connectivity: Literal["cube", "freudenthal"] = "cube",
               isovalues: _Isovalues = None, bins: int = 256,
               device: _Device = None) -> tuple[npt.NDArray[Any], npt.NDArray[np.int64]]: ...
def median(volume: _Volume, device: _Device = None) -> npt.NDArray[Any]: ...
def gaussian(volume: _Volume, sigma: float, device: _Device = None) -> npt.NDArray[Any]: ...
def bilateral(volume: _Volume, sigma_s: float, sigma_r: float,
              device: _Device = None) -> npt.NDArray[Any]: ...
def targeted_filter(volume: _Volume, iso: float, threshold: float,
                    method: Literal["median", "gaussian"] = "median", window: int = 8,
                    sigma: float = 1.0, device: _Device = None) -> tuple[npt.NDArray[Any], float]: ...
def smooth(volume: _Volume, iso: float, threshold: float, window: int = 8,
           variant: Literal["plain", "gaussian"] = "plain", tau: float = 1.0,
           device: _Device = None) -> tuple[npt.NDArray[Any], dict[str, int]]: ...
@overload
def mesh(volume: _Volume, iso: float, method: Literal["mc", "mt"] = "mc",
         color_by_ld: Literal[False] = False, window: int = 8,
         spacing: tuple[float, float, float] = (1.0, 1.0, 1.0),
         device: _Device = None) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.int32]]: ...
@overload
def mesh(volume: _Volume, iso: float, method: Literal["mc", "mt"] = "mc", *,
         color_by_ld: Literal[True], window: int = 8,
         spacing: tuple[float, float, float] = (1.0, 1.0, 1.0), device: _Device = None
         ) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.int32], npt.NDArray[np.float32]]: ...
def noise_level(volume: _Volume, block: int = 0, map_block: int = 32, clip: float = 3.0,
                device: _Device = None) -> dict[str, Any]: ...
@overload
def noise_dimension(mu: float, gamma: float = 1.0, kind: Literal["uniform", "gaussian"] = "uniform") -> float: ...
@overload
def noise_dimension(mu: npt.NDArray[Any], gamma: float = 1.0,
                    kind: Literal["uniform", "gaussian"] = "uniform") -> npt.NDArray[np.float64]: ...
def read_volume(path: str | PathLike[str]) -> tuple[npt.NDArray[Any], tuple[float, float, float]]: ...
def devices() -> list[dict[str, Any]]: ...
def device_description(device: _Device = None) -> str: ...
