"""The napari plugin (clfractal/_napari.py, clfractal/napari.yaml) in a real viewer under Xvfb:
the widget opened through its npe2 manifest shows the library's curve, recommendations and
noise level, and the layers it adds hold exactly the library's mesh, LD values and filter
output. Skipped where napari (with pytest-qt and npe2) is not installed; python/tests/run_napari.sh
runs it (ctest label napari)."""
import pathlib
import subprocess
import sys

import numpy as np
import pytest

napari = pytest.importorskip("napari")
npe2 = pytest.importorskip("npe2")
pytest.importorskip("pytestqt")

import clfractal  # noqa: E402
from clfractal import _napari  # noqa: E402
from conftest import noisy_sphere  # noqa: E402

MANIFEST = pathlib.Path(clfractal.__file__).with_name("napari.yaml")


@pytest.fixture(scope="module")
def volume():
    """A 48^3 ball (radius 16, gradient 10 grey values per voxel) with uniform noise of
    amplitude 10: noisy enough that LD exceeds 2.5 on parts of the surface at s = 100 and the
    targeted filter changes voxels there."""
    return noisy_sphere((48, 48, 48), np.uint8, seed=7, amplitude=10.0)


@pytest.fixture
def widget(make_napari_viewer, volume):
    """The dock widget as napari makes it from the manifest, on an Image layer of `volume`."""
    pm = npe2.PluginManager.instance()
    if "clfractal" not in pm:  # the build tree has no installed entry point: register the file
        pm.register(npe2.PluginManifest.from_file(MANIFEST))
    viewer = make_napari_viewer(show=True)  # shown: the canvas renders (test_screenshot)
    viewer.add_image(volume, name="sphere", scale=(2.0, 1.0, 0.5))
    _, w = viewer.window.add_plugin_dock_widget("clfractal", "Fractal dimension")
    assert isinstance(w, _napari.FractalWidget)
    w.threaded = False
    return viewer, w


def test_manifest_validates():
    r = subprocess.run([str(pathlib.Path(sys.executable).with_name("npe2")), "validate", "--imports", str(MANIFEST)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "valid!" in r.stdout and "invalid" not in r.stdout.lower(), r.stdout


def test_curve_recommendations_and_noise_are_the_librarys(widget, volume):
    viewer, w = widget
    assert w.layer_box.currentText() == "sphere"
    w.curve_button.click()
    a = clfractal.analyse(volume, noise_level=False, denoise=False)
    curve = clfractal.fd_curve(volume)
    np.testing.assert_array_equal(w.isovalues, curve.isovalues)
    np.testing.assert_array_equal(w.fd, curve.fd)
    assert w.recommended_isovalues() == [e.isovalue for e in a.recommended]
    for e in a.recommended:
        assert f"s = {e.isovalue:g} (D = {e.fd:.3f}, {e.verdict})" in w.recommended_label.text()
    marked = [line.get_xdata()[0] for line in w.figure.axes[0].lines if line.get_color() == "tab:green"]
    assert marked == [e.isovalue for e in a.recommended]
    assert w.isovalue == a.best.isovalue  # the slider starts at the best recommendation
    sigma = clfractal.noise_level(volume).sigma
    assert w.noise.sigma == sigma
    assert f"sigma = {sigma:.4g} grey values" in w.noise_label.text()


def test_ld_surface_is_the_librarys_mesh(widget, volume):
    viewer, w = widget
    w.curve_button.click()
    w.set_isovalue(100)
    iso = w.isovalue
    assert iso == 100
    w.surface_button.click()
    surface = viewer.layers[-1]
    assert isinstance(surface, napari.layers.Surface)
    m = clfractal.mesh(volume, iso, color_by_ld=True, window=8)
    np.testing.assert_array_equal(surface.vertices, m.vertices)
    np.testing.assert_array_equal(surface.faces, m.faces)
    np.testing.assert_array_equal(surface.vertex_values, m.ld)  # NaN where LD is undefined
    np.testing.assert_array_equal(surface.scale, viewer.layers["sphere"].scale)
    # The report's colour map (docs/definitions.md §14): blue to 2.2, red from 2.5, grey for NaN.
    assert tuple(surface.contrast_limits) == (2.2, 2.5)
    cmap = surface.colormap
    np.testing.assert_allclose(cmap.map(np.array([0.0, 0.5, 1.0])),
                               [[0, 0, 1, 1], [0.5, 0, 0.5, 1], [1, 0, 0, 1]], atol=1e-6)
    np.testing.assert_allclose(cmap.nan_color, [128 / 255, 128 / 255, 128 / 255, 1.0])


def test_denoise_where_noisy_is_the_librarys_filter(widget, volume):
    viewer, w = widget
    w.curve_button.click()
    w.set_isovalue(100)
    iso = w.isovalue
    w.denoise_button.click()
    out = viewer.layers[-1]
    assert isinstance(out, napari.layers.Image) and out.name == f"sphere denoised s={iso:g}"
    r = clfractal.targeted_filter(volume, iso, threshold=2.5, method="median", window=8)
    assert r.changed > 0
    assert out.data.dtype == volume.dtype
    np.testing.assert_array_equal(out.data, r.volume)
    assert f"{100 * r.changed_share:.2f}% of the voxels changed" in w.status.text()


def test_threaded_curve(widget, volume, qtbot):
    """The default path: the work in a napari worker thread, the widget filled when it returns."""
    viewer, w = widget
    w.threaded = True
    w.curve_button.click()
    qtbot.waitUntil(lambda: w.analysis is not None and w.curve_button.isEnabled(), timeout=60000)
    assert w.isovalue == clfractal.analyse(volume, noise_level=False, denoise=False).best.isovalue


def test_screenshot(widget, qtbot):
    """The viewer renders the LD surface under Xvfb (Mesa): the canvas holds red (LD >= 2.5)
    and blue (LD <= 2.2) pixels. With CLFRACTAL_NAPARI_SCREENSHOT set, the window with the
    widget is saved there (the picture of docs/guide/napari.md)."""
    import os
    viewer, w = widget
    viewer.window.resize(1500, 900)
    w.curve_button.click()
    w.set_isovalue(100)
    w.surface_button.click()
    viewer.layers["sphere"].visible = False
    viewer.dims.ndisplay = 3
    viewer.reset_view()
    qtbot.wait(100)
    rgb = viewer.screenshot(canvas_only=True)[..., :3].astype(int)
    red = (rgb[..., 0] > 2 * rgb[..., 2] + 40).sum()
    blue = (rgb[..., 2] > 2 * rgb[..., 0] + 40).sum()
    assert red > 1000 and blue > 1000, (red, blue)
    target = os.environ.get("CLFRACTAL_NAPARI_SCREENSHOT")
    if target:
        viewer.screenshot(target, canvas_only=False)
