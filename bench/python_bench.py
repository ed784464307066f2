#!/usr/bin/env python3
"""The Python package's overhead and its peers, on one N^3 volume (default 256^3 uint8, the
embedded noisy sphere).

- fd_curve (box, levels 0 and 1, every integer isovalue): the wall time of the Python call
  (array in, curve object out) against the compute time the CLI reports for the same volume
  (`clfractal fd --json`: seconds_compute, the device time of the counting).
- median: the Python call against the CLI's filter time (`clfractal filter --median`, minus
  kernel compilation), against scipy.ndimage.median_filter(size=3, mode="nearest") (which it
  must equal), and against pyclesperanto's median_box (radius 1) on the same OpenCL device
  when pyclesperanto is installed.

Every time is the best of --repeats runs after a warm-up. Run it with the build's venv:
  build/python-venv/bin/python bench/python_bench.py --cli build/clfractal
(PYTHONPATH=build/python for the package built in the tree, or pip-install it).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

import clfractal


def best_of(repeats, fn):
    fn()  # warm-up: kernels compiled, caches filled
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def run_cli(cli, *args):
    r = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"python_bench: {cli} {' '.join(map(str, args))} failed: {r.stderr.strip()}")
    return r.stdout


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cli", required=True, help="path of the clfractal command-line tool")
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--json", help="write the figures here")
    a = p.parse_args()

    v, _ = clfractal.read_volume(f"synthetic:noisy-sphere:{a.size}")
    n = v.shape[2]
    print(f"device          {clfractal.device_description()}")
    print(f"volume          synthetic:noisy-sphere:{a.size}  {v.shape} {v.dtype}")
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, f"noisy-sphere_{n}x{n}x{n}_{clfractal.VALUE_TYPES[v.dtype]}.raw")
        v.tofile(path)

        # ---- fd_curve
        t_py, curve = best_of(a.repeats, lambda: clfractal.fd_curve(v))
        cli_fd = []
        for _ in range(a.repeats):
            run_cli(a.cli, "-q", "fd", path, "--json", os.path.join(tmp, "fd.json"))
            with open(os.path.join(tmp, "fd.json")) as f:
                j = json.load(f)
            cli_fd.append(j["seconds_compute"])
        t_cli = min(cli_fd)
        if abs(j["mean_fd"] - curve.summary["mean"]) > 1e-9:
            sys.exit("python_bench: fd_curve and the CLI disagree")
        rows["fd_python_seconds"] = t_py
        rows["fd_library_seconds"] = curve.summary["seconds_compute"]
        rows["fd_cli_seconds"] = t_cli
        rows["fd_overhead"] = t_py / t_cli - 1
        print(f"fd_curve        python {t_py:.4f} s | CLI compute {t_cli:.4f} s | overhead "
              f"{100 * rows['fd_overhead']:+.1f}%  (library's own device time in the call "
              f"{curve.summary['seconds_compute']:.4f} s)")

        # ---- median
        t_med, ours = best_of(a.repeats, lambda: clfractal.median(v))
        cli_med = []
        for _ in range(a.repeats):
            out = run_cli(a.cli, "filter", path, "--median", "-o", os.path.join(tmp, "m.nrrd"))
            t, compiled = re.search(r"time\s+([\d.e-]+) s, kernels compiled in ([\d.e-]+) s", out).groups()
            cli_med.append(float(t) - float(compiled))
        t_cli_med = min(cli_med)
        rows["median_python_seconds"] = t_med
        rows["median_cli_seconds"] = t_cli_med
        rows["median_overhead"] = t_med / t_cli_med - 1
        line = (f"median          python {t_med:.4f} s | CLI {t_cli_med:.4f} s | overhead "
                f"{100 * rows['median_overhead']:+.1f}%")
        from scipy import ndimage
        t_scipy, theirs = best_of(a.repeats, lambda: ndimage.median_filter(v, size=3, mode="nearest"))
        if not np.array_equal(ours, theirs):
            sys.exit("python_bench: median differs from scipy.ndimage.median_filter")
        rows["median_scipy_seconds"] = t_scipy
        rows["median_vs_scipy"] = t_scipy / t_med
        line += f" | scipy {t_scipy:.4f} s ({t_scipy / t_med:.2f}x)"
        try:
            import pyclesperanto as cle
            cle.select_device(clfractal.device_description().split(" / ")[-1])

            def cle_median():
                return cle.pull(cle.median_box(cle.push(v), radius_x=1, radius_y=1, radius_z=1))
            t_cle, theirs = best_of(a.repeats, cle_median)
            rows["median_cle_seconds"] = t_cle
            rows["median_vs_cle"] = t_cle / t_med
            rows["cle_equal"] = bool(np.array_equal(ours, theirs))
            line += (f" | pyclesperanto {t_cle:.4f} s ({t_cle / t_med:.2f}x, on {cle.get_device().name}, "
                     f"{'equal' if rows['cle_equal'] else 'differs at the borders'})")
        except ImportError as e:
            line += f" | pyclesperanto not installed ({e})"
        print(line)
    print("ratios are peer time / ours (> 1: ours is faster); overhead: python / CLI - 1")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
