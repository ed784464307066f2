"""clfractal.small_components against an independent implementation of the definition on
scipy.ndimage.label: random grids of every dtype, awkward shapes, K from 0 to beyond the grid,
both connectivities."""
import numpy as np
import pytest
from scipy import ndimage

import clfractal

CUBE26 = np.ones((3, 3, 3), dtype=bool)
CROSS6 = ndimage.generate_binary_structure(3, 1)


def across(dtype, s):
    """(the value at or above s, the largest value below s) in the dtype."""
    if np.dtype(dtype).kind in "iu":
        t = int(np.ceil(s))
        return dtype(t), dtype(t - 1)
    t = np.dtype(dtype).type(s)
    return t, np.nextafter(t, np.dtype(dtype).type(-np.inf))


def small_mask(member, structure, k):
    labels, count = ndimage.label(member, structure=structure)
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    small = sizes <= k
    small[0] = False
    return small[labels], count, int(small[1:].sum())


def reference(a, s, k, connectivity):
    at, below = across(a.dtype.type, s)
    positive_structure = CUBE26 if connectivity == "cube" else CROSS6
    g = a.copy()
    mask, positive_before, positive_removed = small_mask(g >= at, positive_structure, k)
    g[mask] = below
    mask, _, negative_removed = small_mask(g < at, CROSS6, k)
    g[mask] = at
    return g, {
        "positive_before": ndimage.label(a >= at, structure=positive_structure)[1],
        "negative_before": ndimage.label(a < at, structure=CROSS6)[1],
        "positive_removed": positive_removed,
        "negative_removed": negative_removed,
        "positive_after": ndimage.label(g >= at, structure=positive_structure)[1],
        "negative_after": ndimage.label(g < at, structure=CROSS6)[1],
        "changed": int((g != a).sum()),
    }


DTYPES = [np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.float32, np.float64]
SHAPES = [(1, 1, 1), (7, 1, 1), (13, 1, 2), (2, 2, 1), (2, 3, 5), (13, 11, 7), (19, 2, 17)]


@pytest.mark.parametrize("dtype", DTYPES)
def test_small_components_equals_scipy_labelling(dtype):
    rng = np.random.default_rng(np.dtype(dtype).num)
    for shape in SHAPES:
        values = rng.integers(0, 7, size=shape)
        a = (values / 2).astype(dtype) if np.dtype(dtype).kind == "f" else values.astype(dtype)
        n = a.size
        for s in ([3, 3.5] if np.dtype(dtype).kind in "iu" else [1.5, 1.6]):
            for k in [0, 1, 2, 5, 20, n - 1, n, n + 1, 10**9]:
                for connectivity in ["cube", "six"]:
                    r = clfractal.small_components(a, s, k, connectivity)
                    got, info = r.volume, r.to_dict()
                    want, counts = reference(a, s, k, connectivity)
                    assert got.dtype == a.dtype and got.shape == a.shape
                    np.testing.assert_array_equal(got, want, err_msg=f"{shape} s={s} k={k} {connectivity}")
                    for key, value in counts.items():
                        assert info[key] == value, (key, shape, s, k, connectivity)
                    assert info["changed_share"] == pytest.approx(counts["changed"] / n)


def test_small_components_refuses_bad_input():
    a = np.zeros((3, 3, 3), np.uint8)
    with pytest.raises(ValueError, match="no uint8 value below"):
        clfractal.small_components(a, 0, 5)
    with pytest.raises(ValueError, match="expected one of cube, six"):
        clfractal.small_components(a, 1, 5, connectivity="18")
    with pytest.raises(ValueError, match="k: must be >= 0"):
        clfractal.small_components(a, 1, -1)


@pytest.mark.parametrize("name,iso", [("mni_avg152t1", 40.5), ("walnut", 20000), ("stent", 500),
                                      ("m4_totaldensity", 0.3)])
def test_small_components_cli_on_real_volumes_of_four_types(cli, shared_data, tmp_path, name, iso):
    """`clfractal filter --small-components` on held-out volumes of four types equals the
    scipy reference vertex for vertex, and leaves no component of either set of <= K vertices."""
    path = next(shared_data.glob(f"{name}_*x*x*_*.raw"))
    a, _ = clfractal.read_volume(path)
    for k in [5, 20]:
        out = tmp_path / f"{name}_{k}.nrrd"
        cli("filter", path, "--small-components", k, "--iso", iso, "-o", out)
        got, _ = clfractal.read_volume(out)
        want, _ = reference(a, iso, k, "cube")
        assert got.dtype == a.dtype
        np.testing.assert_array_equal(got, want)
        assert (want != a).any()  # the isovalue has small components to remove
        at, _ = across(a.dtype.type, iso)
        for member, structure in [(got >= at, CUBE26), (got < at, CROSS6)]:
            labels, count = ndimage.label(member, structure=structure)
            assert (np.bincount(labels.ravel())[1:] > k).all()
