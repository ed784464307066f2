"""Every function of the package against independent NumPy/SciPy references (references.py)
and against the C++ results of the command-line tool on the same data."""
import json
import os
import subprocess

import numpy as np
import pytest
from scipy import ndimage

import clfractal
import references as ref
from conftest import noisy_sphere, read_nrrd, write_raw


def read_csv(path):
    return np.genfromtxt(path, delimiter=",", names=True, dtype=np.float64, missing_values="", filling_values=np.nan)


def assert_same_nan(a, b, **tol):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
    np.testing.assert_allclose(a[~np.isnan(a)], b[~np.isnan(b)], **tol)


# Awkward sizes: odd and even axes, one axis of 3 vertices (2 in G').
@pytest.fixture(scope="module", params=[(np.uint8, (13, 11, 17)), (np.uint16, (9, 3, 12)),
                                        (np.int16, (10, 15, 7)), (np.float32, (12, 13, 11))],
                ids=lambda p: f"{np.dtype(p[0]).name}" if isinstance(p, tuple) else str(p))
def volume(request):
    dtype, shape = request.param
    v = noisy_sphere(shape, dtype, seed=3)
    if dtype == np.int16:
        v = (v.astype(np.int32) * 37 - 4000).astype(np.int16)  # negative values and a wide range
    return v


# ------------------------------------------------------------------ fd_curve

@pytest.mark.parametrize("kind", ["box", "edge"])
def test_fd_curve_matches_the_definition(volume, kind):
    levels = 3
    c = clfractal.fd_curve(volume, kind=kind, levels=levels)
    iso = ref.default_isovalues(volume)
    np.testing.assert_array_equal(c.isovalues, iso)
    assert c.counts.dtype == np.uint64 and c.counts.shape == (levels, len(iso))
    counts = ref.span_counts(volume, iso, kind, levels)
    np.testing.assert_array_equal(c.counts, counts)
    fd = ref.dimension(counts)
    assert_same_nan(c.fd, fd, rtol=1e-12)
    assert_same_nan(c.fd_fit, ref.dimension_fit(counts), rtol=1e-6, atol=1e-9)
    s = ref.summary(fd, counts)
    assert c.summary["defined"] == s["defined"] > 0
    for key in ("mean", "std", "weighted_mean", "kappa"):
        assert c.summary[key] == pytest.approx(s[key], rel=1e-9, abs=1e-12), key
    assert c.summary["kind"] == kind and c.summary["levels"] == levels


def test_fd_curve_options_and_cli(volume, cli, tmp_path):
    path = write_raw(tmp_path, "v", volume)
    c = clfractal.fd_curve(volume, kind="edge")
    cli("fd", path, "--edge", "--csv", tmp_path / "fd.csv")
    table = read_csv(tmp_path / "fd.csv")
    np.testing.assert_array_equal(c.isovalues, table["isovalue"].astype(c.isovalues.dtype))
    np.testing.assert_array_equal(c.counts[0], table["count"])
    np.testing.assert_array_equal(c.counts[1], table["count_sub"])
    assert_same_nan(c.fd, table["fd"], rtol=1e-5)  # the CSV prints 6 digits
    assert c.fd_fit is None
    # A chosen isovalue list, min_count, and bins for float data.
    pick = c.isovalues[::3]
    sub = clfractal.fd_curve(volume, kind="edge", isovalues=pick, min_count=5)
    np.testing.assert_array_equal(sub.isovalues, pick)
    np.testing.assert_array_equal(sub.counts, c.counts[:, ::3])
    s = ref.summary(ref.dimension(sub.counts), sub.counts, min_count=5)
    assert sub.summary["defined"] == s["defined"] and sub.summary["mean"] == pytest.approx(s["mean"])
    if volume.dtype == np.float32:
        few = clfractal.fd_curve(volume, bins=17)
        np.testing.assert_array_equal(few.isovalues, ref.default_isovalues(volume, 17))


def test_fd_curve_to_pandas(volume):
    pd = pytest.importorskip("pandas")
    c = clfractal.fd_curve(volume, levels=3)
    df = c.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == ["isovalue", "count", "count_sub", "count_l2", "fd", "fd_fit"]
    d = c.to_dict()
    assert d["summary"] == c.summary and d["counts"] == c.counts.tolist() and d["levels"] == 3
    assert d["fd"] == [None if np.isnan(x) else x for x in c.fd] and json.dumps(d, allow_nan=False)
    np.testing.assert_array_equal(df["count_l2"], c.counts[2])


def test_fd_curve_bad_arguments(volume):
    with pytest.raises(ValueError, match="kind"):
        clfractal.fd_curve(volume, kind="cubes")
    with pytest.raises(ValueError, match="levels"):
        clfractal.fd_curve(volume, levels=1)
    with pytest.raises(ValueError, match="increasing"):
        clfractal.fd_curve(volume, isovalues=[5, 3])
    with pytest.raises(ValueError, match="empty"):
        clfractal.fd_curve(volume, isovalues=[])
    if volume.dtype != np.float32:
        with pytest.raises(ValueError, match="integer"):
            clfractal.fd_curve(volume, isovalues=[10.5])


# ------------------------------------------------------------------ components

@pytest.mark.parametrize("connectivity", ["cube", "freudenthal"])
def test_components_match_labelling(volume, connectivity, cli, tmp_path):
    iso, counts = clfractal.components(volume, connectivity=connectivity)
    np.testing.assert_array_equal(iso, ref.default_isovalues(volume))
    assert counts.dtype == np.int64
    expected = [ref.components(volume, s, connectivity) for s in iso]
    np.testing.assert_array_equal(counts, expected)
    assert counts.max() > 1  # the noise makes pieces: the check is not vacuous
    path = write_raw(tmp_path, "v", volume)
    cli("components", path, "--connectivity", connectivity, "--csv", tmp_path / "c.csv")
    np.testing.assert_array_equal(counts, read_csv(tmp_path / "c.csv")["components"])
    some_iso, some = clfractal.components(volume, connectivity=connectivity, isovalues=iso[1::5])
    np.testing.assert_array_equal(some_iso, iso[1::5])
    np.testing.assert_array_equal(some, counts[1::5])
    # At most 32 isovalues are labelled one by one, without the sweep: the same counts.
    few_iso, few = clfractal.components(volume, connectivity=connectivity, isovalues=iso[2:60:7])
    np.testing.assert_array_equal(few_iso, iso[2:60:7])
    np.testing.assert_array_equal(few, counts[2:60:7])
    with pytest.raises(ValueError, match="connectivity|freudenthal"):
        clfractal.components(volume, connectivity="face")


# ------------------------------------------------------------------ fd4

def fd4_reference(v, q):
    """I4 and D4 from the definition: the bins every cube's span meets, at levels 0 and 1."""
    vmin = float(v.min())

    def i4(w, width):
        lo, hi = ref.cube_spans(w.astype(np.float64))
        return int(np.sum(np.floor((hi - vmin) / width) - np.floor((lo - vmin) / width) + 1))

    i0, i1 = i4(v, q), i4(ref.level(v, 1), 2 * q)
    return i0, i1, (np.log2(i0 / i1) if i0 and i1 else float("nan"))


@pytest.mark.parametrize("dtype", [np.uint8, np.int16, np.float32, np.float64])
def test_fd4_matches_definition_and_cli(dtype, cli, tmp_path):
    v = noisy_sphere((13, 10, 17), dtype, seed=7)
    for q in (0.0, 2.5):
        r = clfractal.fd4(v, q=q)
        want_q = q or (1.0 if np.issubdtype(v.dtype, np.integer) else (float(v.max()) - float(v.min())) / 256)
        assert r.q == want_q and r.vmin == float(v.min())
        i0, i1, d4 = fd4_reference(v, r.q)
        assert (r.i4_l0, r.i4_l1) == (i0, i1)
        assert r.d4 == pytest.approx(d4, rel=1e-12)
        assert 2.5 < r.d4 < 4.0
    out = tmp_path / "fd4.json"
    cli("fd4", write_raw(tmp_path, "v", v), "--json", out)
    j = json.loads(out.read_text())
    r = clfractal.fd4(v)
    assert (j["i4_l0"], j["i4_l1"], j["q"]) == (r.i4_l0, r.i4_l1, r.q)
    with pytest.raises(ValueError, match="q"):
        clfractal.fd4(v, q=-1.0)


# ------------------------------------------------------------------ noise_level

@pytest.mark.parametrize("dtype", [np.uint8, np.int16, np.uint16, np.float32, np.float64])
def test_noise_level_matches_definition_and_cli(dtype, cli, tmp_path):
    rng = np.random.default_rng(4)
    z, y, x = np.meshgrid(np.arange(30), np.arange(27), np.arange(41), indexing="ij")
    clean = 120 + 60 * np.sin(0.2 * x) * np.cos(0.15 * y) + 2 * z
    noisy = clean + rng.normal(0, 3, clean.shape)
    if np.issubdtype(dtype, np.integer):
        info = np.iinfo(dtype)
        noisy = np.clip(np.round(noisy), info.min, min(info.max, 200))  # the top clipped at 200
    v = noisy.astype(dtype)
    for block in (4, 8):
        r = clfractal.noise_level(v, block=block)
        sigma, share, usable, flat = ref.noise_level(v, block)
        assert (r.blocks_usable, r.blocks_flat) == (usable, flat)
        assert r.sigma_white == pytest.approx(sigma, rel=1e-5) and r.flat_share == pytest.approx(share, rel=1e-12)
        assert r.sigma == pytest.approx(3.0, rel=0.08)  # white noise: sigma is its white part
        assert len(r.correlation) == 3 and len(r.spread) == 3
        assert r.map.dtype == np.float32 and r.map.shape == (1, 1, 2)
        assert r.to_dict()["sigma"] == r.sigma
    assert clfractal.noise_level(clfractal.DeviceVolume(v)).sigma == clfractal.noise_level(v).sigma
    out = tmp_path / "fd.json"
    cli("fd", write_raw(tmp_path, "v", v), "--noise-level", "--isovalues", "150", "--json", out)
    j = json.loads(out.read_text())["noise"]
    mine = clfractal.noise_level(v).to_dict()
    assert j["sigma"] == pytest.approx(mine["sigma"], rel=1e-12)
    def close(a, b):  # plain JSON values equal, numbers to 1e-9
        if isinstance(a, dict):
            return a.keys() == b.keys() and all(close(a[k], b[k]) for k in a)
        if isinstance(a, list):
            return isinstance(b, list) and len(a) == len(b) and all(close(x, y) for x, y in zip(a, b))
        if isinstance(a, float) and b is not None:
            return b == pytest.approx(a, rel=1e-9)
        return a == b
    for key in ("sigma_white", "correlation", "sigma_strides", "texture", "spread", "variation", "notes", "map"):
        assert close(json.loads(json.dumps(mine[key])), j[key]), (key, mine[key], j[key])
    with pytest.raises(ValueError, match="block"):
        clfractal.noise_level(v, block=1)


# ------------------------------------------------------------------ local_fd

def test_local_fd_reference_is_the_brute_force_count():
    v = noisy_sphere((9, 7, 10), np.uint8, seed=5)
    for revision in (1, 2):
        np.testing.assert_array_equal(ref.local_fd(v, 100, 4, revision), ref.local_fd_brute_force(v, 100, 4, revision))


@pytest.mark.parametrize("window", [2, 4, 8])
def test_local_fd_matches_revision_2_windows(volume, window):
    s = float(np.median(volume)) + 0.5
    ld = clfractal.local_fd(volume, s, window=window)
    assert ld.dtype == np.float32 and ld.shape == volume.shape
    # The kernels take log2 in float (kernels/local.cl): within 1e-6, while two distinct count
    # ratios with I_W' <= 64 give LDs more than 4e-5 apart, so every count is checked exactly.
    assert_same_nan(ld, ref.local_fd(volume, s, window, revision=2), rtol=1e-6)


def test_local_fd_matches_cli(volume, cli, tmp_path):
    s = float(np.median(volume))
    ld = clfractal.local_fd(volume, s, window=4)
    assert ld.dtype == np.float32 and ld.shape == volume.shape
    assert np.isfinite(ld).any() and np.isnan(ld).any()
    cli("local", write_raw(tmp_path, "v", volume), "--iso", repr(s), "--window", 4, "-o", tmp_path / "ld.nrrd")
    np.testing.assert_array_equal(ld, read_nrrd(tmp_path / "ld.nrrd"))
    np.testing.assert_array_equal(ld, clfractal.read_volume(tmp_path / "ld.nrrd")[0])  # NaN kept
    with pytest.raises(ValueError, match="window"):
        clfractal.local_fd(volume, s, window=3)
    with pytest.raises(ValueError, match="finite|isovalue"):
        clfractal.local_fd(volume, float("nan"))


# ------------------------------------------------------------------ filters

def test_median_equals_scipy(volume, cli, tmp_path):
    out = clfractal.median(volume)
    assert out.dtype == volume.dtype and out.shape == volume.shape
    np.testing.assert_array_equal(out, ndimage.median_filter(volume, size=3, mode="nearest"))
    cli("filter", write_raw(tmp_path, "v", volume), "--median", "-o", tmp_path / "m.nrrd")
    np.testing.assert_array_equal(out, read_nrrd(tmp_path / "m.nrrd"))


@pytest.mark.parametrize("sigma", [0.7, 1.5])
def test_gaussian_is_the_exact_gaussian(volume, sigma):
    out = clfractal.gaussian(volume, sigma)
    assert out.dtype == volume.dtype
    exact = ndimage.gaussian_filter(volume.astype(np.float64), sigma, mode="nearest",
                                    truncate=np.ceil(3 * sigma) / sigma)
    if volume.dtype.kind == "f":
        np.testing.assert_allclose(out, exact, rtol=1e-5, atol=1e-4)
    else:
        info = np.iinfo(volume.dtype)
        assert np.abs(out.astype(np.float64) - np.clip(exact, info.min, info.max)).max() <= 1.0
    with pytest.raises(ValueError, match="(?i)sigma"):
        clfractal.gaussian(volume, -1)


def test_bilateral_matches_its_definition(volume):
    sigma_r = float(np.std(volume))
    out = clfractal.bilateral(volume, 1.0, sigma_r)
    assert out.dtype == volume.dtype
    exact = ref.bilateral(volume, 1.0, sigma_r)
    if volume.dtype.kind == "f":
        np.testing.assert_allclose(out, exact, rtol=1e-4, atol=1e-3)
    else:
        assert np.abs(out.astype(np.float64) - exact).max() <= 1.0


def test_targeted_filter(volume):
    s, h = float(np.median(volume)), 2.3
    r = clfractal.targeted_filter(volume, s, h, window=4)
    out, changed = r.volume, r.changed_share
    ld = clfractal.local_fd(volume, s, window=4)
    expected = np.where(ld > h, ndimage.median_filter(volume, size=3, mode="nearest"), volume)
    np.testing.assert_array_equal(out, expected)
    assert changed == pytest.approx(np.mean(out != volume))
    assert 0 < changed < 1
    assert r.changed == np.count_nonzero(out != volume)
    assert r.selected == np.count_nonzero(ld > h) and r.selected_share == pytest.approx(np.mean(ld > h))
    g = clfractal.targeted_filter(volume, s, h, method="gaussian", sigma=1.0, window=4).volume
    full = clfractal.gaussian(volume, 1.0)
    np.testing.assert_array_equal(g, np.where(ld > h, full, volume))
    with pytest.raises(ValueError, match="method"):
        clfractal.targeted_filter(volume, s, h, method="mean")


@pytest.mark.parametrize("variant", ["plain", "gaussian"])
def test_smooth_leaves_no_high_fractal_edge(volume, variant, cli, tmp_path):
    s, h = float(np.median(volume)) + 0.5, 2.2
    r = clfractal.smooth(volume, s, h, window=4, variant=variant)
    out = r.volume
    assert out.dtype == volume.dtype
    assert (out <= volume).all()  # values only decrease
    assert r.vertices_changed == np.count_nonzero(out != volume) > 0
    ld = clfractal.local_fd(volume, s, window=4)  # computed once, on the input
    high = ld > h
    s_cmp = np.float32(s) if volume.dtype == np.float32 else s
    for axis in range(3):
        n = out.shape[axis]
        fu, fw = np.take(out, range(n - 1), axis=axis), np.take(out, range(1, n), axis=axis)
        hit = (np.minimum(fu, fw) < s_cmp) & (s_cmp <= np.maximum(fu, fw))
        hu, hw = np.take(high, range(n - 1), axis=axis), np.take(high, range(1, n), axis=axis)
        assert not (hit & (hu | hw)).any()
    cli("smooth", write_raw(tmp_path, "v", volume), "--iso", repr(s), "--threshold", h, "--window", 4,
        "--variant", variant, "-o", tmp_path / "s.nrrd")
    np.testing.assert_array_equal(out, read_nrrd(tmp_path / "s.nrrd"))


# ------------------------------------------------------------------ mesh

def read_ply(path):
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    nv = int(next(l for l in header if l.startswith("element vertex")).split()[-1])
    nf = int(next(l for l in header if l.startswith("element face")).split()[-1])
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if "property uchar red" in header:
        fields += [("r", "u1"), ("g", "u1"), ("b", "u1")]
    if "property float ld" in header:
        fields += [("ld", "<f4")]
    vertices = np.frombuffer(data, dtype=fields, count=nv, offset=end)
    faces = np.frombuffer(data, dtype=[("n", "u1"), ("i", "<i4", 3)], count=nf, offset=end + vertices.nbytes)
    return vertices, faces


@pytest.mark.parametrize("method", ["mc", "mt"])
def test_mesh(volume, method, cli, tmp_path):
    s = float(np.median(volume)) + 0.5
    verts, faces, ld = clfractal.mesh(volume, s, method=method, color_by_ld=True, window=4)
    assert verts.dtype == np.float32 and verts.shape[1] == 3
    assert faces.dtype == np.int32 and faces.shape[1] == 3 and faces.min() >= 0 and faces.max() < len(verts)
    assert ld.dtype == np.float32 and ld.shape == (len(verts),)
    if method == "mc":  # one vertex per intersected grid edge, at its interpolation point
        points = ref.edge_points(volume, s)
        assert len(verts) == len(points)
        order = np.lexsort(verts.T[::-1])
        np.testing.assert_allclose(verts[order], points[np.lexsort(points.T[::-1])], atol=1e-4)
    # C++ results: the same mesh in (x, y, z) order with the opposite winding.
    cli("mesh", write_raw(tmp_path, "v", volume), "--iso", repr(s), "--method", method, "--color-by-ld",
        "--window", 4, "-o", tmp_path / "m.ply")
    pv, pf = read_ply(tmp_path / "m.ply")
    np.testing.assert_array_equal(verts, np.stack([pv["z"], pv["y"], pv["x"]], axis=1))
    np.testing.assert_array_equal(faces, pf["i"][:, [0, 2, 1]])
    np.testing.assert_array_equal(ld, pv["ld"])
    # write_ply writes what the CLI writes.
    clfractal.write_ply(tmp_path / "py.ply", verts, faces, ld)
    qv, qf = read_ply(tmp_path / "py.ply")
    assert qv.dtype == pv.dtype and qv.tobytes() == pv.tobytes()  # bytes: NaN LD compares equal
    np.testing.assert_array_equal(qf, pf)
    plain = clfractal.mesh(volume, s, method=method, spacing=(2.0, 1.0, 0.5))
    assert len(plain) == 3 and plain.ld is None
    np.testing.assert_allclose(plain[0], verts * np.float32([2.0, 1.0, 0.5]), rtol=1e-6)


def test_mesh_normals_point_to_lower_values():
    # Distance from the centre: low inside, so normals point inwards.
    v = noisy_sphere((21, 20, 19), np.float32, amplitude=0.0)
    verts, faces, ld = clfractal.mesh(-v, -100.0)
    assert ld is None
    a, b, c = (verts[faces[:, i]] for i in range(3))
    normals = np.cross(b - a, c - a)
    centre = np.array([(n - 1) / 2 for n in v.shape])
    inward = np.einsum("ij,ij->i", normals, centre - (a + b + c) / 3)
    assert (inward > 0).mean() > 0.99


# ------------------------------------------------------------------ noise, I/O, devices

def test_noise_dimension_is_theorem_1():
    r = np.array([0.0, 0.1, 0.49, 0.5, 0.75, 1.0, 2.0, 10.0])
    np.testing.assert_allclose(clfractal.noise_dimension(r), ref.theorem1(r), rtol=1e-12)
    assert clfractal.noise_dimension(0.0) == pytest.approx(2.0)
    assert clfractal.noise_dimension(3.0, gamma=2.0) == pytest.approx(float(ref.theorem1(1.5)))
    g = clfractal.noise_dimension([0.0, 1.0, 4.0], kind="gaussian")
    assert g[0] == pytest.approx(2.0, abs=1e-6) and 2 < g[1] < g[2] < 3
    with pytest.raises(ValueError):
        clfractal.noise_dimension(-1.0)
    with pytest.raises(ValueError, match="uniform|gaussian"):
        clfractal.noise_dimension(1.0, kind="pink")


def test_read_volume(tmp_path):
    v = noisy_sphere((6, 5, 4), np.uint16)
    a, spacing = clfractal.read_volume(write_raw(tmp_path, "v", v))
    np.testing.assert_array_equal(a, v)
    assert a.dtype == np.uint16 and spacing == (1.0, 1.0, 1.0)
    # NRRD with spacings per axis (x y z) and big-endian values.
    header = ("NRRD0004\ntype: int16\ndimension: 3\nsizes: 4 5 6\nspacings: 0.5 1 2\n"
              "endian: big\nencoding: raw\n\n")
    w = (v.astype(np.int16) - 300)
    (tmp_path / "w.nrrd").write_bytes(header.encode() + w.astype(">i2").tobytes())
    a, spacing = clfractal.read_volume(str(tmp_path / "w.nrrd"))
    np.testing.assert_array_equal(a, w)
    assert spacing == (2.0, 1.0, 0.5)
    s, _ = clfractal.read_volume("synthetic:sphere:16")
    assert s.shape == (16, 16, 16)
    # What read_volume returns goes to the measures as it is: its volume.
    f = clfractal.read_volume(str(tmp_path / "w.nrrd"))
    a, b = (clfractal.analyse(x, noise_level=False).json for x in (f, f.volume))
    for j in (a, b):
        for key in [k for k in j if k.startswith("seconds")]:
            del j[key]
    assert a == b
    with pytest.raises(ValueError, match="missing_4x4x4_uint8.raw: no such file"):
        clfractal.read_volume(tmp_path / "missing_4x4x4_uint8.raw")
    (tmp_path / "short_4x4x4_uint8.raw").write_bytes(b"\0" * 10)
    with pytest.raises(ValueError, match="short_4x4x4_uint8.raw"):
        clfractal.read_volume(tmp_path / "short_4x4x4_uint8.raw")


def test_devices_and_device_choice():
    listed = clfractal.devices()
    assert listed and sum(d["default"] for d in listed) == 1
    default = next(d for d in listed if d["default"])
    assert clfractal.device_description() == f"{default['platform']} / {default['name']}"
    v = noisy_sphere((8, 8, 8), np.uint8)
    chosen = clfractal.fd_curve(v, device=default["name"][:6].lower())
    np.testing.assert_array_equal(chosen.counts, clfractal.fd_curve(v).counts)
    with pytest.raises(RuntimeError, match="no OpenCL device matches"):
        clfractal.fd_curve(v, device="no-such-device")


# ------------------------------------------------------------------ DeviceVolume

def test_device_volume_is_uploaded_once_and_gives_the_array_results(volume):
    dv = clfractal.DeviceVolume(volume)
    assert dv.dtype == volume.dtype and dv.shape == volume.shape
    iso = float(np.median(volume))
    before = clfractal.uploads()
    curve = clfractal.fd_curve(dv, levels=3)
    ld = clfractal.local_fd(dv, iso, window=4)
    med = clfractal.median(dv)
    gauss = clfractal.gaussian(dv, 1.0)
    smoothed = clfractal.smooth(dv, iso, 2.3, window=4)
    smoothed, info = smoothed.volume, smoothed.to_dict()
    verts, faces, mesh_ld = clfractal.mesh(dv, iso, color_by_ld=True, window=4, spacing=(2.0, 1.0, 0.5))
    iso_c, counts = clfractal.components(dv)
    assert clfractal.uploads() == before  # every call read the device copy
    # The same results as the calls given the array (each uploads it).
    want = clfractal.fd_curve(volume, levels=3)
    np.testing.assert_array_equal(curve.counts, want.counts)
    np.testing.assert_array_equal(curve.isovalues, want.isovalues)
    np.testing.assert_array_equal(ld, clfractal.local_fd(volume, iso, window=4))
    np.testing.assert_array_equal(med, clfractal.median(volume))
    np.testing.assert_array_equal(gauss, clfractal.gaussian(volume, 1.0))
    want = clfractal.smooth(volume, iso, 2.3, window=4)
    want_s, want_info = want.volume, want.to_dict()
    np.testing.assert_array_equal(smoothed, want_s)
    assert {k: v for k, v in info.items() if k != "volume"} == {k: v for k, v in want_info.items() if k != "volume"}
    w_verts, w_faces, w_ld = clfractal.mesh(volume, iso, color_by_ld=True, window=4, spacing=(2.0, 1.0, 0.5))
    np.testing.assert_array_equal(verts, w_verts)
    np.testing.assert_array_equal(faces, w_faces)
    np.testing.assert_array_equal(mesh_ld, w_ld)
    w_iso, w_counts = clfractal.components(volume)
    np.testing.assert_array_equal(iso_c, w_iso)
    np.testing.assert_array_equal(counts, w_counts)
    assert clfractal.uploads() > before  # the array calls uploaded
    # fd4 and targeted_filter take it too (uploading its array).
    assert clfractal.fd4(dv) == clfractal.fd4(volume)
    np.testing.assert_array_equal(clfractal.targeted_filter(dv, iso, 2.3, window=4).volume,
                                  clfractal.targeted_filter(volume, iso, 2.3, window=4).volume)


def test_device_volume_counts_one_upload_and_copies_the_array():
    v = noisy_sphere((9, 10, 11), np.uint8, seed=5)
    before = clfractal.uploads()
    dv = clfractal.DeviceVolume(v)
    assert clfractal.uploads() == before + 1
    want = clfractal.median(v)
    v[:] = 0  # the DeviceVolume holds its own copy
    np.testing.assert_array_equal(clfractal.median(dv), want)
    with pytest.raises(ValueError):
        clfractal.DeviceVolume(np.zeros((2, 2)))
    with pytest.raises(ValueError):
        clfractal.local_fd(dv, 100, window=3)


# ------------------------------------------------------------------ CLI parity: local4, masked filters

def test_local4_and_the_ld4_targeted_filter_match_the_cli(volume, cli, tmp_path):
    raw = write_raw(tmp_path, "v", volume)
    ld4 = clfractal.local4(volume, window=4)
    assert ld4.dtype == np.float32 and ld4.shape == volume.shape
    cli("local4", raw, "--window", 4, "-o", tmp_path / "ld4.nrrd")
    np.testing.assert_array_equal(ld4, read_nrrd(tmp_path / "ld4.nrrd"))
    h = float(np.nanmedian(ld4))
    r = clfractal.targeted_filter(volume, None, h, mask="ld4", window=4)
    expected = np.where(ld4 > h, ndimage.median_filter(volume, size=3, mode="nearest"), volume)
    np.testing.assert_array_equal(r.volume, expected)
    assert r.selected == np.count_nonzero(ld4 > h) > 0
    cli("filter", raw, "--median", "--fractal4", "--threshold", repr(h), "--window", 4, "-o", tmp_path / "f4.nrrd")
    np.testing.assert_array_equal(r.volume, read_nrrd(tmp_path / "f4.nrrd"))
    with pytest.raises(ValueError, match="mask"):
        clfractal.targeted_filter(volume, 1.0, h, mask="ld5")
    with pytest.raises(ValueError, match="iso"):
        clfractal.targeted_filter(volume, None, h)


def test_bilateral_targeted_and_ld_guided_filters_match_the_cli(volume, cli, tmp_path):
    raw = write_raw(tmp_path, "v", volume)
    s, h = float(np.median(volume)), 2.3
    ss, sr = 1.5, float(volume.max() - volume.min()) / 10
    ld = clfractal.local_fd(volume, s, window=4)
    r = clfractal.targeted_filter(volume, s, h, method="bilateral", sigma_s=ss, sigma_r=sr, window=4)
    np.testing.assert_array_equal(r.volume, np.where(ld > h, clfractal.bilateral(volume, ss, sr), volume))
    cli("filter", raw, "--bilateral", f"{ss},{sr!r}", "--fractal", "--iso", repr(s), "--threshold", h,
        "--window", 4, "-o", tmp_path / "b.nrrd")
    np.testing.assert_array_equal(r.volume, read_nrrd(tmp_path / "b.nrrd"))
    g = clfractal.ld_guided_filter(volume, s, sigma_s=ss, sigma_r=sr, window=4)
    assert g.selected == np.count_nonzero(ld > 2)
    np.testing.assert_array_equal(g.volume[~(ld > 2)], volume[~(ld > 2)])  # LD <= 2 or NaN: kept
    cli("filter", raw, "--bilateral", f"{ss},{sr!r}", "--ld-guided", "--iso", repr(s), "--window", 4,
        "-o", tmp_path / "g.nrrd")
    np.testing.assert_array_equal(g.volume, read_nrrd(tmp_path / "g.nrrd"))
    with pytest.raises(ValueError, match="(?i)sigma"):
        clfractal.ld_guided_filter(volume, s, sigma_s=-1.0)


# ------------------------------------------------------------------ files: writers, raw options, info

@pytest.mark.parametrize("suffix", [".nii", ".nii.gz", ".nrrd"])
def test_write_volume_round_trips_with_its_spacing(tmp_path, suffix):
    v = noisy_sphere((7, 9, 11), np.int16, seed=5) - 300
    path = tmp_path / f"v{suffix}"
    clfractal.write_volume(path, v, spacing=(2.5, 0.75, 1.25))
    back, spacing = clfractal.read_volume(path)
    np.testing.assert_array_equal(back, v)
    assert back.dtype == v.dtype and spacing == (2.5, 0.75, 1.25)
    ld = clfractal.local_fd(v, float(np.median(v)), window=4)  # NaN where undefined: written as it is
    clfractal.write_volume(tmp_path / f"ld{suffix}", ld)
    stored = np.frombuffer((tmp_path / f"ld{suffix}").read_bytes()[-ld.nbytes:], dtype="<f4") if suffix != ".nii.gz" \
        else None
    if stored is not None:  # the file's last bytes are the values, x fastest
        np.testing.assert_array_equal(stored, ld.ravel())
    with pytest.raises(ValueError, match="v.tif"):
        clfractal.write_volume(tmp_path / "v.tif", v)
    with pytest.raises(ValueError, match="spacing"):
        clfractal.write_volume(path, v, spacing=(1, 0, 1))


def rotation_zyx(angle):
    """Unit LPS axes of a grid turned by `angle` about S, rows in (z, y, x) order."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[0.0, 0.0, 1.0], [-s, c, 0.0], [c, s, 0.0]])


@pytest.mark.parametrize("suffix", [".nii", ".nii.gz", ".nrrd"])
def test_write_volume_carries_the_orientation(tmp_path, suffix):
    v = noisy_sphere((5, 6, 7), np.uint8, seed=2)
    spacing, origin, axes = (2.5, 0.75, 1.25), (-12.5, 30.0, 4.25), rotation_zyx(0.3)
    path = tmp_path / f"o{suffix}"
    clfractal.write_volume(path, v, spacing=spacing, orientation=(origin, axes * 3.0))  # axes are normalised
    back, got_spacing = clfractal.read_volume(path)
    np.testing.assert_array_equal(back, v)
    np.testing.assert_allclose(got_spacing, spacing, rtol=1e-6)
    o = clfractal.info(path).orientation
    np.testing.assert_allclose(o.origin, origin, rtol=1e-6)
    np.testing.assert_allclose(o.axes, axes, atol=1e-6)
    if suffix == ".nii":  # the sform rows as stored (RAS: L and P negated), read with NumPy
        srow = np.frombuffer(path.read_bytes()[280:328], dtype="<f4").reshape(3, 4)
        ras = np.array([-1.0, -1.0, 1.0])[:, None]
        np.testing.assert_allclose(srow[:, :3], ras * (axes[::-1] * np.array(spacing[::-1])[:, None]).T, atol=1e-6)
        np.testing.assert_allclose(srow[:, 3], ras[:, 0] * origin, rtol=1e-6)
    clfractal.write_volume(tmp_path / f"plain{suffix}", v)  # spacing only
    assert clfractal.info(tmp_path / f"plain{suffix}").orientation is None
    with pytest.raises(ValueError, match="orientation"):
        clfractal.write_volume(path, v, orientation=(origin, np.zeros((3, 3))))


def nifti1(array, datatype, bitpix):
    """A single-file NIfTI-1 of a (z, y, x) array written with NumPy only (pixdim 1, no
    scaling, no orientation), independent of the library's writer."""
    header = np.zeros(348, np.uint8)
    def put(offset, values, dtype):
        b = np.asarray(values, dtype=dtype).tobytes()
        header[offset:offset + len(b)] = np.frombuffer(b, np.uint8)
    put(0, 348, "<i4")
    put(40, [3, *array.shape[::-1], 1, 1, 1, 1], "<i2")
    put(70, [datatype, bitpix], "<i2")
    put(76, [1, 1, 1, 1, 1, 1, 1, 1], "<f4")
    put(108, 352.0, "<f4")
    header[344:348] = np.frombuffer(b"n+1\0", np.uint8)
    return header.tobytes() + bytes(4) + np.ascontiguousarray(array).tobytes()


@pytest.mark.parametrize("dtype,code,bits", [("<f4", 16, 32), ("<f8", 64, 64)])
def test_nifti_keeps_nan_and_inf(tmp_path, dtype, code, bits):
    v = np.arange(4 * 5 * 6, dtype=dtype).reshape(4, 5, 6) / 7
    v[1, 2, 3], v[3, 0, 5], v[0, 4, 0] = np.nan, np.inf, -np.inf
    path = tmp_path / "nan.nii"
    path.write_bytes(nifti1(v, code, bits))
    back, _ = clfractal.read_volume(path)
    assert back.dtype == np.dtype(dtype).newbyteorder("=")
    np.testing.assert_array_equal(back, v)  # NaN where v has NaN, the infinities kept
    i = clfractal.info(path)
    assert (i.nan, i.inf) == (1, 2)
    # Counting refuses it as it refuses the same values in a NRRD: one line naming the counts.
    cli_path = os.environ.get("CLFRACTAL_CLI")
    if not cli_path:
        pytest.skip("CLFRACTAL_CLI is not set (run through ctest)")
    clfractal.write_volume(tmp_path / "nan.nrrd", v)
    runs = [subprocess.run([cli_path, "-q", "fd", str(tmp_path / name)], capture_output=True, text=True)
            for name in ("nan.nii", "nan.nrrd")]
    assert [r.returncode for r in runs] == [2, 2]
    assert "1 NaN" in runs[0].stderr and len(runs[0].stderr.strip().splitlines()) == 1, runs[0].stderr
    assert runs[0].stderr.replace("nan.nii", "F") == runs[1].stderr.replace("nan.nrrd", "F")


def test_read_volume_raw_options_and_info(tmp_path, cli):
    rng = np.random.default_rng(2)
    v = rng.integers(-3000, 3000, (5, 6, 7), dtype=np.int16)
    path = tmp_path / "scan.bin"
    v.astype(">i2").tofile(path)
    got, spacing = clfractal.read_volume(path, dims=(5, 6, 7), dtype=np.int16, endian="big", spacing=(3, 2, 1))
    np.testing.assert_array_equal(got, v)
    assert spacing == (3.0, 2.0, 1.0)
    as_float = clfractal.read_volume(path, dims=(5, 6, 7), dtype="int16", endian="big", as_type=np.float32).volume
    assert as_float.dtype == np.float32
    np.testing.assert_array_equal(as_float, v.astype(np.float32))
    i = clfractal.info(path, dims=(5, 6, 7), dtype=np.int16, endian="big")
    assert (i.shape, i.dtype, i.min, i.max, i.nan) == ((5, 6, 7), "int16", float(v.min()), float(v.max()), 0)
    text = cli("info", path, "--dims", "7,6,5", "--type", "int16", "--endian", "big")
    for line in i.header:
        assert line in text
    with pytest.raises(ValueError, match="scan.bin"):
        clfractal.read_volume(path, dims=(5, 6, 8), dtype=np.int16)
    with pytest.raises(ValueError, match="endian"):
        clfractal.read_volume(path, dims=(5, 6, 7), dtype=np.int16, endian="middle")


# ------------------------------------------------------------------ slice streams

@pytest.mark.parametrize("kind,levels", [("box", 2), ("edge", 3)])
def test_slice_stream_equals_the_whole_volume(volume, kind, levels):
    iso = np.unique(volume)[1:][::3]
    stream = clfractal.SliceStream(volume.shape[1:], volume.dtype, iso, levels=levels, kind=kind)
    stream.push(volume[:3])  # a stack, then slice by slice
    partial = stream.curve()
    np.testing.assert_array_equal(partial.counts, ref.span_counts(volume[:3], partial.isovalues, kind, levels))
    for z in range(3, volume.shape[0]):
        stream.push(volume[z])
    assert stream.slices == volume.shape[0]
    c, whole = stream.curve(), clfractal.fd_curve(volume, kind=kind, levels=levels, isovalues=iso)
    np.testing.assert_array_equal(c.isovalues, whole.isovalues)
    np.testing.assert_array_equal(c.counts, whole.counts)
    np.testing.assert_array_equal(c.counts, ref.span_counts(volume, c.isovalues, kind, levels))
    assert_same_nan(c.fd, whole.fd)
    with pytest.raises(ValueError, match="shape"):
        stream.push(volume[0, :, :-1])
    with pytest.raises(ValueError, match="fit"):
        stream.push(np.full(volume.shape[1:], 1e300))


@pytest.mark.parametrize("connectivity", ["cube", "freudenthal"])
def test_components_stream_equals_scipy_labelling(volume, connectivity):
    iso = np.unique(volume)[1:][::4][:8]
    stream = clfractal.ComponentsStream(volume.shape[1:], volume.dtype, iso, connectivity=connectivity)
    stream.push(volume[:3])  # a stack, then slice by slice
    part = stream.counts()
    assert part.counts.tolist() == [ref.components(volume[:3], s, connectivity) for s in part.isovalues]
    for z in range(3, volume.shape[0]):
        stream.push(volume[z])
    assert stream.slices == volume.shape[0]
    c = stream.counts()
    np.testing.assert_array_equal(c.isovalues, clfractal.components(volume, connectivity, isovalues=iso).isovalues)
    assert c.counts.tolist() == [ref.components(volume, s, connectivity) for s in c.isovalues]
    assert c.counts.tolist() == clfractal.components(volume, connectivity, isovalues=iso).counts.tolist()
    with pytest.raises(ValueError, match="shape"):
        stream.push(volume[0, :, :-1])
    with pytest.raises(ValueError, match="fit"):
        stream.push(np.full(volume.shape[1:], 1e300))
    with pytest.raises(ValueError, match="connectivity|cube"):
        clfractal.ComponentsStream(volume.shape[1:], volume.dtype, iso, connectivity="six")


@pytest.mark.parametrize("noise", [4.0, 40.0])
def test_analyse_matches_the_cli_and_the_reference(noise, cli, tmp_path):
    # A clean ball (noise 4) and one with no clean isovalue (noise 40, the denoising ladder).
    v = noisy_sphere((40, 40, 40), np.uint8, seed=3, amplitude=noise)
    a = clfractal.analyse(v, noise_level=False, components="recommended", fd4=False)  # what fd computes
    path = write_raw(tmp_path, "ball", v)
    cli("fd", path, "--json", tmp_path / "fd.json")
    j = json.loads((tmp_path / "fd.json").read_text())
    assert a.json["recommended"] == j["recommended"] and a.json["noisiest"] == j["noisiest"]
    assert [t["command"].split(" -o ")[0].split(" ", 3)[3] for t in a.denoise] == \
        [t["command"].split(" -o ")[0].split(" ", 3)[3] for t in j["denoise"]["attempts"]]
    assert a.clean == j["clean"] and a.recommended and a.best is a.recommended[0]
    # D and the verdicts from the plain NumPy counts.
    c = clfractal.fd_curve(v)
    d = ref.dimension(c.counts)
    for e in a.recommended:
        k = int(np.searchsorted(c.isovalues, e.isovalue))
        assert e.count == c.counts[0][k] and e.count_sub == c.counts[1][k]
        assert e.fd == pytest.approx(d[k], abs=1e-12)
        want = "clean" if d[k] <= 2.2 else "noisy" if d[k] >= 2.5 else "rough"
        assert e.verdict == want and e.components >= 1
    if noise == 40.0:
        assert not a.clean and a.best.basis == "cleanest quarter" and a.denoise
        assert a.denoise[-1]["clean"] == (a.denoise[-1]["recommended"][0]["verdict"] == "clean")
    else:
        assert a.clean and a.best.verdict == "clean" and a.denoise == []
    with pytest.raises(ValueError, match="components"):
        clfractal.analyse(v, components="some")
