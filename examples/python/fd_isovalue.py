#!/usr/bin/env python3
"""Choose an isovalue from the fractal dimension curve and plot the curve (thesis Fig. 2.1).

The box span dimension D(s) is near 2 where the isosurface is a smooth surface and rises
towards 3 where it is noise. The isovalue comes from clfractal.analyse, the same
recommendation `clfractal fd` prints: the material boundary of the best clean band (or,
when nothing is clean, of the cleanest quarter), with its verdict.

    python fd_isovalue.py [VOLUME] [--out fd.png]

VOLUME is a file clfractal reads (NRRD, NAME_XxYxZ_TYPE.raw) or synthetic:NAME[:N]
(default synthetic:noisy-sphere:96). Needs matplotlib.
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import clfractal


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("volume", nargs="?", default="synthetic:noisy-sphere:96")
    p.add_argument("--out", default="fd.png")
    a = p.parse_args()

    volume, spacing = clfractal.read_volume(a.volume)
    curve = clfractal.fd_curve(volume)
    best = clfractal.analyse(volume, noise_level=False, denoise=False).best
    j = int(np.searchsorted(curve.isovalues, best.isovalue))
    s = curve.summary
    print(f"{a.volume}: {volume.shape} {volume.dtype} on {s['device']}")
    print(f"mean D {s['mean']:.3f} (std {s['std']:.3f}) over {s['defined']} isovalues")
    print(f"recommended isovalue {curve.isovalues[j]} ({best.verdict}): D = {curve.fd[j]:.3f}, "
          f"{curve.counts[0][j]} cubes, {best.components} components")

    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(curve.isovalues, curve.fd, color="#1f5fa8", lw=1.5, label="D(s)")
    ax.axvline(curve.isovalues[j], color="#c03030", ls="--", label=f"chosen s = {curve.isovalues[j]}")
    ax.set_xlabel("isovalue s")
    ax.set_ylabel("fractal box span dimension D(s)")
    ax.set_ylim(1.8, 3.05)
    ax.set_title(a.volume)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
