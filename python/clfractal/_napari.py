"""The napari plugin (the npe2 manifest napari.yaml; ``pip install "clfractal[napari]"``).

A dock widget on a 3D Image layer: the fractal dimension curve D(s) with the library's
recommended isovalues marked (``analyse``), the noise level (``noise_level``), an isovalue
slider that starts at the best recommendation, a Surface layer of the isosurface at that
isovalue coloured by its local fractal dimension (``mesh(..., color_by_ld=True)``, the colour
map of docs/definitions.md §14) and "denoise where noisy": the fractal-targeted median where
LD > 2.5 at that isovalue (``targeted_filter``, the first step of the analysis' denoising
ladder) as a new Image layer. Only the package's public API is used.

The computations run in napari's worker threads so that the viewer stays responsive on large
volumes; ``threaded=False`` runs them in the calling thread (tests, scripts).
"""
from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure
from napari.layers import Image
from napari.qt.threading import create_worker
from napari.utils.colormaps import Colormap
from qtpy.QtCore import Qt
from qtpy.QtWidgets import QComboBox, QLabel, QPushButton, QSlider, QVBoxLayout, QWidget

import clfractal

#: docs/definitions.md §14: blue up to 2.2, red from 2.5, linear in between, grey where
#: undefined (NaN); used with contrast limits (CLEAN_FD, NOISY_FD).
CLEAN_FD, NOISY_FD = 2.2, 2.5
LD_COLORMAP = Colormap(colors=[[0.0, 0.0, 1.0, 1.0], [1.0, 0.0, 0.0, 1.0]], name="clfractal LD",
                       nan_color=[128 / 255, 128 / 255, 128 / 255, 1.0])
#: The LD window of the surface colours and the targeted filter (the library's default).
WINDOW = 8


class FractalWidget(QWidget):
    """The dock widget: pick an Image layer, "Compute curve", then add the LD-coloured surface
    or the denoised volume at the slider's isovalue.

    After "Compute curve": ``analysis`` (``clfractal.analyse``), ``noise``
    (``clfractal.noise_level``) and ``isovalues``/``fd`` (the curve drawn, the analysis'
    ``curve``); ``isovalue`` is the slider's value.
    """

    def __init__(self, napari_viewer, threaded: bool = True):
        super().__init__()
        self.viewer = napari_viewer
        self.threaded = threaded
        self.analysis = self.noise = None
        self.isovalues = self.fd = None
        self._volume = self._layer = None
        self._workers = []
        self.layer_box = QComboBox()
        self.curve_button = QPushButton("Compute curve")
        self.figure = Figure(figsize=(4, 3), tight_layout=True)
        self.canvas = FigureCanvasQTAgg(self.figure)
        self.recommended_label = QLabel("Recommended: (compute the curve)")
        self.noise_label = QLabel("Noise level: (compute the curve)")
        self.slider = QSlider(Qt.Horizontal)
        self.slider.setEnabled(False)
        self.isovalue_label = QLabel("Isovalue: -")
        self.surface_button = QPushButton("LD-coloured surface")
        self.denoise_button = QPushButton("Denoise where noisy")
        self.status = QLabel("")
        self.status.setWordWrap(True)
        self._lay_out()
        self.curve_button.clicked.connect(self.compute_curve)
        self.slider.valueChanged.connect(self._slider_moved)
        self.surface_button.clicked.connect(self.add_surface)
        self.denoise_button.clicked.connect(self.denoise)
        self.viewer.layers.events.inserted.connect(self._refresh_layers)
        self.viewer.layers.events.removed.connect(self._refresh_layers)
        self._refresh_layers()
        self._set_ready(False)

    def _lay_out(self) -> None:
        box = QVBoxLayout(self)
        for w in (QLabel("Image layer (3D)"), self.layer_box, self.curve_button, self.canvas,
                  self.recommended_label, self.noise_label, self.isovalue_label, self.slider,
                  self.surface_button, self.denoise_button, self.status):
            box.addWidget(w)
        box.addStretch(1)

    # ---------------------------------------------------------------- layers and threads

    def _refresh_layers(self, event=None) -> None:
        current = self.layer_box.currentText()
        names = [layer.name for layer in self.viewer.layers if isinstance(layer, Image) and layer.ndim == 3]
        self.layer_box.clear()
        self.layer_box.addItems(names)
        if current in names:
            self.layer_box.setCurrentText(current)

    def _image(self):
        """The chosen layer and its data as a NumPy array."""
        name = self.layer_box.currentText()
        if not name:
            raise ValueError("no 3D Image layer: open a volume first")
        layer = self.viewer.layers[name]
        return layer, np.asarray(layer.data)

    def _run(self, compute, done, what: str) -> None:
        """compute() in a worker thread (or here), then done(result) in the Qt thread; an
        error is shown in the status line."""
        self._set_busy(True, what)

        def finish(result):
            self._set_busy(False, "")
            done(result)

        def fail(error):
            self._set_busy(False, f"{what} failed: {error}")

        if not self.threaded:
            try:
                result = compute()
            except Exception as error:  # shown, as the threaded path shows it
                fail(error)
                raise
            finish(result)
            return
        worker = create_worker(compute)
        worker.returned.connect(finish)
        worker.errored.connect(fail)
        worker.finished.connect(lambda: self._workers.remove(worker))
        self._workers.append(worker)
        worker.start()

    def _set_busy(self, busy: bool, text: str) -> None:
        self.status.setText(text + ("..." if busy else ""))
        self.curve_button.setEnabled(not busy)
        self._set_ready(not busy and self.analysis is not None)

    def _set_ready(self, ready: bool) -> None:
        for w in (self.slider, self.surface_button, self.denoise_button):
            w.setEnabled(ready)

    # ---------------------------------------------------------------- the curve

    def compute_curve(self) -> None:
        """The analysis (recommendations, curve) and the noise level of the chosen layer."""
        layer, volume = self._image()

        def compute():
            return (clfractal.analyse(volume, noise_level=False, denoise=False),
                    clfractal.noise_level(volume))

        def done(result):
            self._layer, self._volume = layer, volume
            self.analysis, self.noise = result
            curve = self.analysis.json["curve"]
            self.isovalues = np.array([row["isovalue"] for row in curve], dtype=np.float64)
            self.fd = np.array([np.nan if row["fd"] is None else row["fd"] for row in curve], dtype=np.float64)
            self._show_analysis()
        self._run(compute, done, "Computing the curve")

    def _show_analysis(self) -> None:
        a, best = self.analysis, self.analysis.best
        self.recommended_label.setText("Recommended: " + ", ".join(
            f"s = {e.isovalue:g} (D = {e.fd:.3f}, {e.verdict})" for e in a.recommended))
        self.noise_label.setText(f"Noise level: sigma = {self.noise.sigma:.4g} grey values, white part "
                                 f"{self.noise.sigma_white:.4g} (flat blocks {100 * self.noise.flat_share:.1f}% "
                                 "of the volume)")
        self.slider.blockSignals(True)
        self.slider.setRange(0, len(self.isovalues) - 1)
        self.slider.setValue(int(np.argmin(np.abs(self.isovalues - best.isovalue))))
        self.slider.blockSignals(False)
        self._set_ready(True)
        self._slider_moved()

    def recommended_isovalues(self) -> list:
        """The isovalues marked on the plot (the analysis' recommendations, best first)."""
        return [e.isovalue for e in self.analysis.recommended]

    @property
    def isovalue(self) -> float:
        """The slider's isovalue (one of the curve's)."""
        return float(self.isovalues[self.slider.value()])

    def set_isovalue(self, value: float) -> None:
        """Moves the slider to the curve's isovalue nearest `value`."""
        self.slider.setValue(int(np.argmin(np.abs(self.isovalues - value))))

    def _slider_moved(self, _=None) -> None:
        self.isovalue_label.setText(f"Isovalue: {self.isovalue:g}")
        self._draw()

    def _draw(self) -> None:
        self.figure.clear()
        ax = self.figure.add_subplot()
        ax.plot(self.isovalues, self.fd, color="black", lw=1, label="D(s)")
        ax.axhspan(1.9, CLEAN_FD, color="tab:blue", alpha=0.08)
        ax.axhspan(NOISY_FD, 3.1, color="tab:red", alpha=0.08)
        for i, e in enumerate(self.analysis.recommended):
            ax.axvline(e.isovalue, color="tab:green", lw=2 if i == 0 else 1, ls="-" if i == 0 else "--",
                       label="recommended" if i == 0 else None)
        ax.axvline(self.isovalue, color="tab:orange", lw=1, label="slider")
        ax.set_xlabel("isovalue s")
        ax.set_ylabel("D(s)")
        ax.set_ylim(1.9, 3.1)
        ax.legend(loc="upper right", fontsize="small")
        self.canvas.draw_idle()

    # ---------------------------------------------------------------- surface and denoising

    def add_surface(self) -> None:
        """A Surface layer: the isosurface at the slider's isovalue, vertices coloured by LD."""
        layer, volume, iso = self._layer, self._volume, self.isovalue

        def done(m):
            self.viewer.add_surface((m.vertices, m.faces, m.ld), name=f"{layer.name} LD s={iso:g}",
                                    colormap=LD_COLORMAP, contrast_limits=(CLEAN_FD, NOISY_FD),
                                    scale=layer.scale, translate=layer.translate)
        self._run(lambda: clfractal.mesh(volume, iso, color_by_ld=True, window=WINDOW), done, "Meshing")

    def denoise(self) -> None:
        """A new Image layer: the fractal-targeted median where LD > 2.5 at the slider's
        isovalue (``targeted_filter``), the input elsewhere."""
        layer, volume, iso = self._layer, self._volume, self.isovalue

        def done(r):
            self.viewer.add_image(r.volume, name=f"{layer.name} denoised s={iso:g}", scale=layer.scale,
                                  translate=layer.translate, contrast_limits=layer.contrast_limits,
                                  colormap=layer.colormap)
            self.status.setText(f"Denoised where LD > {NOISY_FD} at s = {iso:g}: "
                                f"{100 * r.changed_share:.2f}% of the voxels changed")
        self._run(lambda: clfractal.targeted_filter(volume, iso, threshold=NOISY_FD, method="median", window=WINDOW),
                  done, "Denoising")
