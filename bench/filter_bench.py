#!/usr/bin/env python3
"""Filter throughput in one run: clfractal's median and Gaussian (timed by
clfractal_filter_bench) against scipy.ndimage (median_filter size=3 mode='nearest',
gaussian_filter truncate=3 mode='nearest') and pyclesperanto (median_box radius 1,
gaussian_blur) on the same OpenCL device, plus the fractal-targeted median against the full
one; every output is compared.

    filter_bench.py [--bench PATH] [--size N] [--sigma S] [--repeats R] [--volume PATH]...
                    [--device NAME] [--json F] [--smoke]

Checks (exit 1 on failure): our median equals scipy's exactly on every case (with --volume:
the real volumes too); our Gaussian is within 1 grey level of the exact (float64) Gaussian for
integer data and 1e-4 relative for float data. Without scipy (--smoke, or scipy absent) the
medians are checked against a numpy reference instead and nothing is timed against peers.
Figures are printed, never asserted: ratios > 1 mean clfractal is faster.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import warnings

import numpy as np

warnings.filterwarnings("ignore", category=DeprecationWarning)

DTYPES = {"uint8": np.uint8, "uint16": np.uint16, "int16": np.int16, "float32": np.float32}


def load(desc):
    nx, ny, nz = desc["dims"]
    return np.fromfile(desc["path"], dtype=DTYPES[desc["type"]]).reshape(nz, ny, nx)


def best_of(repeats, f):
    best, out = 1e300, None
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


def numpy_median(a):
    """The 3x3x3 median with edge clamping, by partitioning the 27 shifted copies."""
    p = np.pad(a, 1, mode="edge")
    nz, ny, nx = a.shape
    stack = np.stack([p[dz:dz + nz, dy:dy + ny, dx:dx + nx]
                      for dz in range(3) for dy in range(3) for dx in range(3)])
    return np.partition(stack, 13, axis=0)[13]


def exact_gaussian(a, sigma):
    """float64 Gaussian, radius ceil(3 sigma), edge clamping (scipy when present, else numpy)."""
    r = int(np.ceil(3 * sigma))
    i = np.arange(-r, r + 1)
    w = np.exp(-i * i / (2 * sigma * sigma))
    w /= w.sum()
    out = a.astype(np.float64)
    for axis in range(3):
        p = np.pad(out, [(r, r) if ax == axis else (0, 0) for ax in range(3)], mode="edge")
        n = out.shape[axis]
        out = sum(w[k] * np.take(p, np.arange(k, k + n), axis=axis) for k in range(2 * r + 1))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bench", default=os.path.join(here, "..", "build", "clfractal_filter_bench"))
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--sigma", type=float, default=1.0)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--volume", action="append", default=[], help="real volume: median checked against scipy")
    p.add_argument("--device", default="cpu", help="pyclesperanto device name or type (default: cpu)")
    p.add_argument("--json", help="write every figure as JSON")
    p.add_argument("--smoke", action="store_true", help="no peers: check our outputs with numpy only")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        return run(a, tmp)


def run(a, out):
    cmd = [a.bench, "--size", str(a.size), "--sigma", str(a.sigma), "--repeats", str(a.repeats), "--out", out]
    for v in a.volume:
        cmd += ["--volume", v]
    bench = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
    if bench.returncode != 0 or not bench.stdout.strip():
        sys.exit(f"filter_bench: {a.bench} failed (exit {bench.returncode})")
    report = json.loads(bench.stdout)

    scipy = cle = None
    if not a.smoke:
        try:
            import scipy.ndimage as scipy  # noqa: F811
        except ImportError:
            print("scipy absent: no peer timings, numpy checks only")
        try:
            import pyclesperanto as cle  # noqa: F811
            cle.select_device(a.device)
        except Exception as e:  # absent, or no such device
            print(f"pyclesperanto unavailable ({e}): skipped")
            cle = None
    ok = True
    r = a.repeats
    for row in report["cases"]:
        f = load(row["input"])
        ours = np.fromfile(row["median"], dtype=f.dtype).reshape(f.shape)
        if scipy:
            t, ref = best_of(r, lambda: scipy.median_filter(f, size=3, mode="nearest"))
            row["scipy_median_seconds"] = t
            row["median_vs_scipy"] = t / row["median_seconds"]
            row["median_equals_scipy"] = bool(np.array_equal(ours, ref))
            ok &= row["median_equals_scipy"]
        elif f.size <= 64 ** 3 or a.smoke:
            row["median_equals_numpy"] = bool(np.array_equal(ours, numpy_median(f)))
            ok &= row["median_equals_numpy"]
        if cle:
            g = cle.push(f)
            cle.median_box(g, radius_x=1, radius_y=1, radius_z=1)  # warm-up: compilation
            def cle_median():
                res = cle.median_box(g, radius_x=1, radius_y=1, radius_z=1)
                return cle.pull(res)
            t, _ = best_of(r, cle_median)
            row["cle_median_seconds"] = t
            row["median_vs_cle"] = t / row["median_seconds"]
        if "gaussian" not in row:
            continue
        ours_g = np.fromfile(row["gaussian"], dtype=f.dtype).reshape(f.shape)
        exact = exact_gaussian(f, report["sigma"])
        if f.dtype.kind == "f":
            err = float(np.max(np.abs(ours_g - exact) / (1 + np.abs(exact))))
            row["gaussian_max_relative_error"] = err
            ok &= err <= 1e-4
        else:
            lo, hi = np.iinfo(f.dtype).min, np.iinfo(f.dtype).max
            err = float(np.max(np.abs(ours_g.astype(np.float64) - np.clip(exact, lo, hi))))
            row["gaussian_max_error_levels"] = err
            ok &= err <= 1.0
        if scipy:
            t, ref = best_of(r, lambda: scipy.gaussian_filter(f, report["sigma"], truncate=3.0, mode="nearest"))
            row["scipy_gaussian_seconds"] = t
            row["gaussian_vs_scipy"] = t / row["gaussian_seconds"]
            row["gaussian_max_difference_scipy"] = float(np.max(np.abs(ours_g.astype(np.float64) - ref)))
        if cle:
            g = cle.push(f)
            s = report["sigma"]
            cle.gaussian_blur(g, sigma_x=s, sigma_y=s, sigma_z=s)
            def cle_gauss():
                return cle.pull(cle.gaussian_blur(g, sigma_x=s, sigma_y=s, sigma_z=s))
            t, _ = best_of(r, cle_gauss)
            row["cle_gaussian_seconds"] = t
            row["gaussian_vs_cle"] = t / row["gaussian_seconds"]

    print(f"device          {report['device']}")
    if cle:
        print(f"pyclesperanto   {cle.__version__} on {cle.get_device().name}")
    print(f"kernel compile  {report['compile_seconds']:.2f} s (apart from the figures); best of {r}")
    print(f"Gaussian sigma {report['sigma']} (radius {report['gaussian_radius']}); "
          f"targeted: iso {report['iso']}, LD > {report['threshold']}, window {report['window']}")
    print("ratios = peer time / our time (> 1: clfractal faster)")
    for row in report["cases"]:
        print(f"\n{row['case']}:")
        line = f"  median      ours {row['median_seconds']:.4f} s"
        if "scipy_median_seconds" in row:
            line += f" | scipy {row['scipy_median_seconds']:.4f} s ({row['median_vs_scipy']:.1f}x)"
        if "cle_median_seconds" in row:
            line += f" | pyclesperanto {row['cle_median_seconds']:.4f} s ({row['median_vs_cle']:.2f}x)"
        for k in ("median_equals_scipy", "median_equals_numpy"):
            if k in row:
                line += f" | {'equal' if row[k] else 'DIFFERENT'} ({k.split('_')[-1]})"
        print(line)
        if "gaussian_seconds" in row:
            line = f"  gaussian    ours {row['gaussian_seconds']:.4f} s"
            if "scipy_gaussian_seconds" in row:
                line += f" | scipy {row['scipy_gaussian_seconds']:.4f} s ({row['gaussian_vs_scipy']:.1f}x)"
            if "cle_gaussian_seconds" in row:
                line += f" | pyclesperanto {row['cle_gaussian_seconds']:.4f} s ({row['gaussian_vs_cle']:.2f}x)"
            err = row.get("gaussian_max_error_levels", row.get("gaussian_max_relative_error"))
            line += f" | max error vs exact {err:.3g}"
            if "gaussian_max_difference_scipy" in row:
                line += f", vs scipy {row['gaussian_max_difference_scipy']:.3g}"
            print(line)
            print(f"  targeted    median where LD > h: {100 * row['targeted_selected_share']:.2f}% selected, "
                  f"{100 * row['targeted_changed_share']:.2f}% changed; LD {row['targeted_ld_seconds']:.4f} s + "
                  f"filter {row['targeted_filter_seconds']:.4f} s = {row['targeted_median_seconds']:.4f} s "
                  f"({row['targeted_over_full']:.2f} of the full median); masked median alone "
                  f"{row['masked_median_seconds']:.4f} s ({row['masked_over_full']:.2f} of the full median)")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(report, fh, indent=1)
    print("\nall outputs agree" if ok else "\nOUTPUTS DIFFER")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
