#!/usr/bin/env python3
"""The isosurface coloured by the local fractal dimension (thesis §2.4): blue where the
surface is smooth (LD <= 2.2), red where it is noise (LD >= 2.5).

    python ld_mesh.py [VOLUME] [--iso S] [--out mesh.png] [--no-viewer]

Shows the mesh in napari when napari is installed (and --no-viewer is not given), else
renders it with matplotlib to a PNG. VOLUME as in fd_isovalue.py (default
synthetic:noisy-sphere:64; --iso defaults to the middle of the value range).
"""
import argparse
import warnings

import numpy as np

import clfractal


def ld_colours(ld):
    """RGBA per value: blue up to 2.2, red from 2.5, linear in between, grey where undefined."""
    t = np.clip((ld - 2.2) / 0.3, 0, 1)
    rgba = np.stack([t, np.zeros_like(t), 1 - t, np.ones_like(t)], axis=-1)
    rgba[np.isnan(ld)] = (0.5, 0.5, 0.5, 1)
    return rgba


def render_png(verts, faces, ld, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    triangles = verts[faces][:, :, ::-1]  # (x, y, z) for the axes
    with warnings.catch_warnings():  # triangles with LD undefined at every corner stay NaN (grey)
        warnings.simplefilter("ignore", RuntimeWarning)
        face_ld = np.nanmean(ld[faces], axis=1)
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(triangles, facecolors=ld_colours(face_ld), linewidths=0))
    lo, hi = verts.min(axis=0)[::-1], verts.max(axis=0)[::-1]
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.set_title(title)
    ax.set_axis_off()
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("volume", nargs="?", default="synthetic:noisy-sphere:64")
    p.add_argument("--iso", type=float)
    p.add_argument("--window", type=int, default=8)
    p.add_argument("--out", default="mesh.png")
    p.add_argument("--no-viewer", action="store_true", help="write the PNG even when napari is installed")
    a = p.parse_args()

    volume, spacing = clfractal.read_volume(a.volume)
    iso = a.iso if a.iso is not None else (float(volume.min()) + float(volume.max())) / 2
    verts, faces, ld = clfractal.mesh(volume, iso, color_by_ld=True, window=a.window, spacing=spacing)
    defined = ld[~np.isnan(ld)]
    print(f"{a.volume} at isovalue {iso}: {len(verts)} vertices, {len(faces)} triangles; "
          f"{np.mean(defined >= 2.5):.1%} red (LD >= 2.5), {np.mean(defined <= 2.2):.1%} blue (LD <= 2.2)")
    if not a.no_viewer:
        try:
            import napari
        except ImportError:
            napari = None
        if napari is not None:
            viewer = napari.Viewer()
            viewer.add_image(volume, scale=spacing, visible=False)
            viewer.add_surface((verts, faces, np.nan_to_num(ld, nan=2.0)), colormap="bwr",
                               contrast_limits=(2.2, 2.5), name="LD")
            napari.run()
            return
    render_png(verts, faces, ld, a.out, f"{a.volume}, isovalue {iso:g}, coloured by LD")


if __name__ == "__main__":
    main()
