"""Real volumes from ../shared/data, loaded with NumPy alone, against the independent
references: FD counts and curves, components, median and the local dimension."""
import re

import numpy as np
import pytest
from scipy import ndimage

import clfractal
import references as ref

# Small and mid-sized volumes of every stored type (the suite stays fast on 2 cores).
VOLUMES = ["bucky_32x32x32_uint8.raw", "nucleon_41x41x41_uint8.raw", "fuel_cropped_64x33x32_uint8.raw",
           "m4_totaldensity_31x22x25_float32.raw", "hydrogen_3d_orbital_64x64x64_float32.raw",
           "walnut_128x96x114_uint16.raw"]


def load(shared_data, name):
    """The raw file as a (z, y, x) array, with NumPy only."""
    path = shared_data / name
    if not path.exists():
        pytest.skip(f"{path} not found")
    nx, ny, nz, dtype = re.match(r".*_(\d+)x(\d+)x(\d+)_(\w+)\.raw$", name).groups()
    return np.fromfile(path, dtype=np.dtype(dtype).newbyteorder("<")).reshape(int(nz), int(ny), int(nx))


@pytest.mark.parametrize("name", VOLUMES)
def test_fd_curve_and_median_on_real_volumes(shared_data, name):
    v = load(shared_data, name)
    c = clfractal.fd_curve(v, kind="box")
    iso = ref.default_isovalues(v)
    np.testing.assert_array_equal(c.isovalues, iso)
    counts = ref.span_counts(v, iso, "box")
    np.testing.assert_array_equal(c.counts, counts)
    fd = ref.dimension(counts)
    np.testing.assert_array_equal(np.isnan(c.fd), np.isnan(fd))
    np.testing.assert_allclose(c.fd[~np.isnan(fd)], fd[~np.isnan(fd)], rtol=1e-12)
    assert c.summary["mean"] == pytest.approx(ref.summary(fd, counts)["mean"], rel=1e-12)
    np.testing.assert_array_equal(clfractal.median(v), ndimage.median_filter(v, size=3, mode="nearest"))


@pytest.mark.parametrize("name,connectivity,every", [
    ("nucleon_41x41x41_uint8.raw", "cube", 4), ("bucky_32x32x32_uint8.raw", "freudenthal", 3),
    ("m4_totaldensity_31x22x25_float32.raw", "cube", 4), ("walnut_128x96x114_uint16.raw", "cube", 0),
])
def test_components_on_real_volumes(shared_data, name, connectivity, every):
    v = load(shared_data, name)
    if every:
        iso, comp = clfractal.components(v, connectivity=connectivity)
        iso, comp = iso[::every], comp[::every]
    else:  # 16-bit: a spread of isovalues over the range
        pick = np.unique(np.linspace(int(v.min()) + 1, int(v.max()), 10).astype(np.int64))
        iso, comp = clfractal.components(v, connectivity=connectivity, isovalues=pick)
        np.testing.assert_array_equal(iso, pick)
    np.testing.assert_array_equal(comp, [ref.components(v, s, connectivity) for s in iso])
    assert comp.max() > 1


@pytest.mark.parametrize("name,iso", [("bucky_32x32x32_uint8.raw", 60), ("nucleon_41x41x41_uint8.raw", 100.5),
                                      ("m4_totaldensity_31x22x25_float32.raw", 0.1)])
def test_local_fd_on_real_volumes(shared_data, name, iso):
    v = load(shared_data, name)
    ld = clfractal.local_fd(v, iso)
    expected = ref.local_fd(v, iso, 8, revision=2)
    np.testing.assert_array_equal(np.isnan(ld), np.isnan(expected))
    # log2 in float on the device: within 1e-6 (distinct count ratios differ by > 4e-5).
    np.testing.assert_allclose(ld[~np.isnan(ld)], expected[~np.isnan(expected)], rtol=1e-6)


def test_dicom_series_read_through_the_module(shared_data, tmp_path):
    """The DICOM module (loaded on first use) decodes the CT series as its reference decoding;
    a cut file of it is a ValueError naming the file, raised inside the module."""
    series = shared_data / "formats" / "dicom_ct_phantom"
    if not series.is_dir():
        pytest.skip(f"{series} not found")
    a, _ = clfractal.read_volume(series)
    np.testing.assert_array_equal(a, load(shared_data / "formats", "dicom_ct_phantom_512x512x28_int16.raw"))
    first = sorted(series.iterdir())[0]
    (tmp_path / "cut.dcm").write_bytes(first.read_bytes()[:700])
    with pytest.raises(ValueError, match=r"cut\.dcm: truncated DICOM file"):
        clfractal.read_volume(tmp_path / "cut.dcm")
