"""Arrays as users hold them: every dtype, views, non-contiguous and big-endian arrays,
conversions, bad shapes; errors as Python exceptions; the extension in a fresh process; the
GIL released during device work."""
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import clfractal
import references as ref
from conftest import noisy_sphere


def counts(v):
    return clfractal.fd_curve(v).counts


@pytest.mark.parametrize("dtype", list(clfractal.VALUE_TYPES))
def test_every_value_type_is_taken_as_it_is(dtype):
    v = noisy_sphere((10, 9, 11), dtype)
    c = clfractal.fd_curve(v)
    iso = ref.default_isovalues(v)
    np.testing.assert_array_equal(c.isovalues, iso)
    assert c.isovalues.dtype == (np.int64 if dtype.kind in "iu" else dtype)
    np.testing.assert_array_equal(c.counts, ref.span_counts(v, iso))
    assert clfractal.median(v).dtype == dtype


@pytest.mark.parametrize("make_view", [
    lambda v: v[::2, 1:, ::-1],            # strided, negative stride
    lambda v: v.transpose(2, 0, 1),        # not C order
    lambda v: np.asfortranarray(v),        # Fortran order
    lambda v: v[1:-1, 2:-3, 1:],           # a window of a larger array
    lambda v: np.broadcast_to(v[:1], v.shape),  # zero stride, read-only
], ids=["strided", "transposed", "fortran", "window", "broadcast"])
def test_views_equal_their_contiguous_copies(make_view):
    v = noisy_sphere((14, 13, 12), np.uint8)
    view = make_view(v)
    copy = np.ascontiguousarray(view)
    np.testing.assert_array_equal(counts(view), counts(copy))
    np.testing.assert_array_equal(clfractal.median(view), clfractal.median(copy))
    np.testing.assert_array_equal(clfractal.local_fd(view, 100, 4), clfractal.local_fd(copy, 100, 4))


@pytest.mark.parametrize("dtype", ["uint16", "int16", "int32", "float32", "float64"])
def test_big_endian_arrays(dtype):
    v = noisy_sphere((9, 10, 11), dtype)
    big = v.astype(np.dtype(dtype).newbyteorder(">"))
    assert not big.dtype.isnative
    np.testing.assert_array_equal(counts(big), counts(v))
    out = clfractal.median(big)
    assert out.dtype == np.dtype(dtype) and out.dtype.isnative
    np.testing.assert_array_equal(out, clfractal.median(v))


@pytest.mark.parametrize("source,target", [
    (np.bool_, np.uint8), (np.float16, np.float32),
])
def test_lossless_conversions_by_dtype(source, target):
    v = noisy_sphere((8, 9, 10), np.int16) % 100 - 50
    a = (v > 0) if source is np.bool_ else v.astype(source)
    np.testing.assert_array_equal(counts(a), counts(a.astype(target)))
    assert clfractal.median(a).dtype == np.dtype(target)


def test_lossless_conversions_by_value():
    v = noisy_sphere((8, 9, 10), np.uint8)
    np.testing.assert_array_equal(counts(v.astype(np.int64)), counts(v))     # fits uint8
    np.testing.assert_array_equal(counts(v.astype(np.uint32) * 200), counts(v.astype(np.uint16) * 200))
    f = v.astype(np.float32) / 4
    np.testing.assert_array_equal(counts(f.astype(np.float64)), counts(f))  # exact in float32
    assert clfractal.median(np.int64(v) - 300).dtype == np.int16


@pytest.mark.parametrize("array,match", [
    (np.full((4, 4, 4), 2**40, dtype=np.int64), "int64 .*precision loss"),
    (np.full((4, 4, 4), np.longdouble(1) / 10, dtype=np.longdouble), "float128 .*precision loss"),
    (np.zeros((4, 4, 4), dtype=np.complex64), "complex64"),
    (np.zeros((4, 4), dtype=np.uint8), r"3D array .*\(4, 4\)"),
    (np.zeros((0, 4, 4), dtype=np.uint8), "empty axis"),
    (np.zeros((4, 4, 4, 1), dtype=np.uint8), "3D array"),
])
def test_unsupported_arrays_raise_value_error(array, match):
    for call in (counts, clfractal.median, lambda a: clfractal.local_fd(a, 1),
                 lambda a: clfractal.components(a), lambda a: clfractal.mesh(a, 1)):
        with pytest.raises(ValueError, match=match):
            call(array)


def test_float_data_with_nan_is_rejected():
    v = noisy_sphere((6, 6, 6), np.float32)
    v[2, 3, 4] = np.nan
    with pytest.raises(ValueError, match="NaN|finite"):
        clfractal.fd_curve(v)
    with pytest.raises(ValueError, match="NaN|finite"):
        clfractal.median(v)


def test_one_vertex_and_thin_volumes():
    one = np.full((1, 1, 1), 7, dtype=np.uint8)
    c = clfractal.fd_curve(one)  # one isovalue, no cube: counts 0, D undefined
    np.testing.assert_array_equal(c.isovalues, [7])
    np.testing.assert_array_equal(c.counts, [[0], [0]])
    assert np.isnan(c.fd).all() and c.summary["defined"] == 0 and np.isnan(c.summary["mean"])
    np.testing.assert_array_equal(clfractal.median(one), one)
    assert np.isnan(clfractal.local_fd(one, 7)).all()
    iso, comp = clfractal.components(one)
    np.testing.assert_array_equal(comp, [0])
    verts, faces, _ = clfractal.mesh(one, 7)
    assert verts.shape == (0, 3) and faces.shape == (0, 3)
    thin = noisy_sphere((1, 6, 7), np.float32)  # a single slice: no cubes, edges in x and y
    e = clfractal.fd_curve(thin, kind="edge")
    np.testing.assert_array_equal(e.counts, ref.span_counts(thin, e.isovalues, "edge"))
    assert e.counts[0].sum() > 0


def test_results_own_their_memory():
    v = noisy_sphere((8, 8, 8), np.uint8)
    out = clfractal.median(v)
    assert out.flags.c_contiguous and out.base is not None
    del v
    assert int(out.sum()) > 0  # still valid after the input is gone
    out[0, 0, 0] = 1           # writable


def test_one_context_per_device_for_the_process():
    v = noisy_sphere((12, 12, 12), np.uint8)
    default = next(d for d in clfractal.devices() if d["default"])
    for device in (None, default["name"], default["platform"][:4].upper()):
        clfractal.fd_curve(v, device=device)
        clfractal.median(v, device=device)
        clfractal.local_fd(v, 100, device=device)
    assert clfractal._clfractal.context_count() == 1
    first = clfractal.fd_curve(v).summary["seconds_compile"]
    # No program is built again: only first launches (a 2x2x2 warm-up grid) count after that.
    assert clfractal.fd_curve(v).summary["seconds_compile"] - first < 0.05


def test_a_second_import_in_a_subprocess():
    code = ("import numpy as np, clfractal, clfractal as again\n"
            "v = np.zeros((5, 5, 5), np.uint8); v[2, 2, 2] = 9\n"
            "c = again.fd_curve(v)\n"
            "print(clfractal.components(v)[1][-1], int(c.counts[0][-1]), clfractal.device_description())\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=os.environ)
    assert r.returncode == 0, r.stderr
    comp, cubes, device = r.stdout.split(" ", 2)
    assert (comp, cubes) == ("1", "8") and device.strip() == clfractal.device_description()


def test_the_gil_is_released_during_device_work():
    v = noisy_sphere((96, 96, 96), np.uint8)
    clfractal.local_fd(v, 100)  # compiled already
    ticks = 0
    worker = threading.Thread(target=lambda: [clfractal.local_fd(v, 100) for _ in range(3)])
    worker.start()
    while worker.is_alive():
        ticks += 1
    worker.join()
    assert ticks > 1000


def test_errors_never_crash():
    v = noisy_sphere((6, 6, 6), np.uint8)
    with pytest.raises(ValueError, match="(?i)sigma"):
        clfractal.bilateral(v, 0.0, 1.0)
    with pytest.raises(ValueError, match="variant|plain"):
        clfractal.smooth(v, 100, 2.5, variant="blocky")
    with pytest.raises(ValueError, match="spacing"):
        clfractal.mesh(v, 100, spacing=(1, 0, 1))
    with pytest.raises(ValueError, match="mc|mt|method"):
        clfractal.mesh(v, 100, method="dc")
    with pytest.raises(TypeError):
        clfractal.local_fd(v, None)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16, np.float32])
def test_c_contiguous_arrays_are_read_in_place(dtype):
    from clfractal import _clfractal
    v = noisy_sphere((11, 12, 13), dtype, seed=8)
    v.flags.writeable = False  # read in place, never written
    iso = float(np.median(v))
    before = _clfractal.host_copies()
    curve, ld, med = clfractal.fd_curve(v), clfractal.local_fd(v, iso, window=4), clfractal.median(v)
    smoothed = clfractal.smooth(v, iso, 2.3, window=4).volume
    targeted = clfractal.targeted_filter(v, iso, 2.3, window=4).volume
    assert _clfractal.host_copies() == before  # no copy of any of them
    # A view of the same values (z reversed twice: not C-contiguous) is copied, with equal results.
    clfractal.median(v[:, :, ::2])
    assert _clfractal.host_copies() == before + 1
    F = np.asfortranarray(v)
    np.testing.assert_array_equal(clfractal.fd_curve(F).counts, curve.counts)
    np.testing.assert_array_equal(clfractal.local_fd(F, iso, window=4), ld)
    np.testing.assert_array_equal(clfractal.median(F), med)
    np.testing.assert_array_equal(clfractal.smooth(F, iso, 2.3, window=4).volume, smoothed)
    np.testing.assert_array_equal(clfractal.targeted_filter(F, iso, 2.3, window=4).volume, targeted)
    assert _clfractal.host_copies() == before + 6
    np.testing.assert_array_equal(med, ref_median(v))


def ref_median(v):
    from scipy import ndimage
    return ndimage.median_filter(v, size=3, mode="nearest")
