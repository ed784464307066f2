import os
import pathlib
import subprocess

import numpy as np
import pytest

import clfractal


def pytest_report_header(config):
    return f"clfractal {clfractal.__version__} on {clfractal.device_description()}"


@pytest.fixture(scope="session")
def cli():
    """Runs the clfractal command-line tool (the C++ results); skips when it is not built."""
    path = os.environ.get("CLFRACTAL_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("CLFRACTAL_CLI is not set (run through ctest)")

    def run(*args):
        r = subprocess.run([path, "-q", *map(str, args)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        return r.stdout
    return run


def gnuplot_runs():
    """Whether gnuplot is installed and draws a PNG here (the report's pictures need it; the
    wheel's test hides the system's libpng, which gnuplot loads)."""
    try:
        r = subprocess.run(["gnuplot"], input="set terminal png\nset output '/dev/null'\nplot x\n",
                           capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return r.returncode == 0


@pytest.fixture(scope="session")
def gnuplot():
    """Skips a test of a page with pictures where gnuplot cannot draw them."""
    if not gnuplot_runs():
        pytest.skip("gnuplot cannot draw a PNG here (not installed, or its libraries hidden)")


@pytest.fixture(scope="session")
def shared_data():
    path = pathlib.Path(os.environ.get("CLFRACTAL_SHARED_DATA", pathlib.Path(__file__).parents[3] / "shared" / "data"))
    if not path.is_dir():
        pytest.skip(f"real data not found at {path}")
    return path


def write_raw(directory, name, a):
    """Writes `a` as NAME_XxYxZ_TYPE.raw, the naming convention the CLI reads."""
    nz, ny, nx = a.shape
    path = pathlib.Path(directory) / f"{name}_{nx}x{ny}x{nz}_{clfractal.VALUE_TYPES[a.dtype]}.raw"
    np.ascontiguousarray(a).tofile(path)
    return path


def read_nrrd(path):
    """A NRRD the CLI wrote (attached header, raw encoding) as a (z, y, x) array, with NumPy
    only (independent of the library's reader)."""
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"\n\n") + 2
    fields = dict(line.split(": ", 1) for line in data[:end].decode().splitlines()[1:] if ": " in line)
    assert fields["encoding"] == "raw"
    types = {"uint8": "u1", "unsigned char": "u1", "uint16": "u2", "unsigned short": "u2", "int16": "i2",
             "short": "i2", "float": "f4", "float32": "f4"}
    order = ">" if fields.get("endian") == "big" else "<"
    nx, ny, nz = map(int, fields["sizes"].split())
    return np.frombuffer(data[end:], dtype=order + types[fields["type"]]).reshape(nz, ny, nx)


def noisy_sphere(shape, dtype, seed=1, amplitude=6.0, radius=None):
    """A ball (bright inside) plus uniform noise, in the value range of `dtype`."""
    rng = np.random.default_rng(seed)
    grid = np.meshgrid(*[np.arange(n) - (n - 1) / 2 for n in shape], indexing="ij")
    r = np.sqrt(sum(g * g for g in grid))
    radius = radius or min(shape) / 3
    f = 100.0 + 10.0 * (radius - r) + rng.uniform(-amplitude, amplitude, shape)
    if np.dtype(dtype).kind == "f":
        return f.astype(dtype)
    info = np.iinfo(dtype)
    return np.clip(np.rint(f), info.min, info.max).astype(dtype)
