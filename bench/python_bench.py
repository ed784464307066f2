#!/usr/bin/env python3
"""The Python package's overhead and its peers, on one N^3 volume (default 256^3 uint8, the
embedded noisy sphere).

- fd_curve (box, levels 0 and 1, every integer isovalue): the wall time of the Python call
  (array in, curve object out) against the compute time the CLI reports for the same volume
  (`clfractal fd --json`: seconds_compute, the device time of the counting); also with the
  isovalues given. Without them the call finds its set itself: 8-bit data is counted at every
  value of its type and cropped to the value range (no pass of its own); other types take a
  pass over the values for the range.
- span curve of a --span-size^3 uint8 noisy sphere (default 512^3, the embedded generator):
  the warm Python fd_curve call (array in, curve out, its own isovalue set) against the
  tuned OpenMP loop (bench/baselines/span_openmp.cpp) and the device as a C++ library call,
  both timed by `clfractal bench` in the same run on the same volume; the Python counts must
  equal those of `clfractal fd --csv` on that volume.
- median: the Python call against the same C++ library call (`clfractal_filter_bench
  --volume`), against scipy.ndimage.median_filter(size=3, mode="nearest") (which it
  must equal), and against pyclesperanto's median_box (radius 1) on the same OpenCL device
  when pyclesperanto is installed.

Every time is the best of --repeats runs after a warm-up (the peers: of at most 2). Run it with the build's venv:
  build/python-venv/bin/python bench/python_bench.py --cli build/clfractal
(PYTHONPATH=build/python for the package built in the tree, or pip-install it).
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


def span_against_openmp(a, tmp):
    """The warm Python span curve of the N^3 noisy sphere against `clfractal bench`'s OpenMP
    loop and device call on the same volume (its 2 (N/2)^3 case), in one run."""
    n = a.span_size
    bench_json = os.path.join(tmp, "bench.json")
    run_cli(a.cli, "-q", "bench", "--size", n // 2, "--repeats", a.repeats, "--json", bench_json)
    with open(bench_json) as f:
        case = next(c for c in json.load(f)["span"] if c["volume"] == f"uint8 {n}^3")
    if not case["counts_equal"]:
        sys.exit("python_bench: clfractal bench's device and OpenMP counts differ")
    v, _ = clfractal.read_volume(f"synthetic:noisy-sphere:{n}")
    t_py, curve = best_of(a.repeats, lambda: clfractal.fd_curve(v))
    # Like the two timed by clfractal bench, given the isovalue set.
    every = np.arange(int(v.min()), int(v.max()) + 1)
    t_given, given = best_of(a.repeats, lambda: clfractal.fd_curve(v, isovalues=every))
    if not np.array_equal(given.counts, curve.counts):
        sys.exit("python_bench: fd_curve with its isovalues given differs")
    path = os.path.join(tmp, f"span_{n}x{n}x{n}_uint8.raw")
    v.tofile(path)
    csv = os.path.join(tmp, "span.csv")
    run_cli(a.cli, "-q", "fd", path, "--csv", csv, "--no-denoise")
    want = np.genfromtxt(csv, delimiter=",", names=True)
    if not np.array_equal(np.asarray(curve.counts[0], dtype=np.float64), want["count"]):
        sys.exit("python_bench: fd_curve's counts differ from clfractal fd's")
    os.remove(path)
    t_omp, t_dev = case["openmp_seconds"], case["device_seconds"]
    print(f"span {n}^3       OpenMP loop {t_omp:.4f} s | C++ device call {t_dev:.4f} s ({t_omp / t_dev:.2f}x) | "
          f"python fd_curve, isovalues given {t_given:.4f} s ({t_omp / t_given:.2f}x), its own set "
          f"{t_py:.4f} s ({t_omp / t_py:.2f}x)  (x: OpenMP / ours; counts equal)")
    return dict(span_size=n, span_python_seconds=t_py, span_python_given_seconds=t_given, span_cpp_seconds=t_dev,
                span_openmp_seconds=t_omp, span_python_vs_openmp=t_omp / t_py,
                span_python_given_vs_openmp=t_omp / t_given, span_cpp_vs_openmp=t_omp / t_dev)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cli", required=True, help="path of the clfractal command-line tool")
    p.add_argument("--filter-bench", help="path of clfractal_filter_bench (default: beside --cli)")
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--span-size", type=int, default=512,
                   help="N of the span-curve comparison with the OpenMP loop (even; 0: skip it)")
    p.add_argument("--json", help="write the figures here")
    a = p.parse_args()
    a.filter_bench = a.filter_bench or os.path.join(os.path.dirname(a.cli), "clfractal_filter_bench")

    v, _ = clfractal.read_volume(f"synthetic:noisy-sphere:{a.size}")
    n = v.shape[2]
    print(f"device          {clfractal.device_description()}")
    print(f"volume          synthetic:noisy-sphere:{a.size}  {v.shape} {v.dtype}")
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, f"noisy-sphere_{n}x{n}x{n}_{clfractal.VALUE_TYPES[v.dtype]}.raw")
        v.tofile(path)

        # ---- fd_curve: Python calls and CLI runs interleaved (best of each), so that a busy
        # machine slows both alike.
        clfractal.fd_curve(v)  # warm-up
        every = np.arange(int(v.min()), int(v.max()) + 1)  # the default set, given explicitly
        t_py, t_given, t_lib, t_lib_given, t_cli = [], [], [], [], []
        for _ in range(a.repeats):
            t0 = time.perf_counter()
            curve = clfractal.fd_curve(v)
            t_py.append(time.perf_counter() - t0)
            t_lib.append(curve.summary["seconds_compute"])
            t0 = time.perf_counter()
            given = clfractal.fd_curve(v, isovalues=every)
            t_given.append(time.perf_counter() - t0)
            t_lib_given.append(given.summary["seconds_compute"])
            run_cli(a.cli, "-q", "fd", path, "--json", os.path.join(tmp, "fd.json"))
            with open(os.path.join(tmp, "fd.json")) as f:
                j = json.load(f)
            t_cli.append(j["seconds_compute"])
            if abs(j["mean_fd"] - curve.summary["mean"]) > 1e-9 or not np.array_equal(given.counts, curve.counts):
                sys.exit("python_bench: fd_curve and the CLI disagree")
        rows.update(fd_python_seconds=min(t_py), fd_python_given_seconds=min(t_given),
                    fd_library_seconds=min(t_lib), fd_library_given_seconds=min(t_lib_given),
                    fd_cli_seconds=min(t_cli))
        # Host work of the call beyond the device counting, per call (then the best).
        rows["fd_host_seconds"] = min(p - d for p, d in zip(t_py, t_lib))
        rows["fd_host_given_seconds"] = min(p - d for p, d in zip(t_given, t_lib_given))
        rows["fd_overhead"] = min(t_py) / min(t_cli) - 1
        rows["fd_overhead_given"] = min(t_given) / min(t_cli) - 1
        print(f"fd_curve        python {min(t_py):.4f} s | CLI compute {min(t_cli):.4f} s | overhead "
              f"{100 * rows['fd_overhead']:+.1f}%  (device time inside the Python call {min(t_lib):.4f} s)")
        print(f"  isovalues given: python {min(t_given):.4f} s | overhead {100 * rows['fd_overhead_given']:+.1f}%"
              f"  (the set given; the CLI's seconds_compute leaves out its own value pass too)")
        print(f"  host work of the call beyond the device counting: {1e3 * rows['fd_host_seconds']:.1f} ms "
              f"(the isovalue set, copy, results), {1e3 * rows['fd_host_given_seconds']:.1f} ms with isovalues given")

        if a.span_size:
            rows.update(span_against_openmp(a, tmp))

        # ---- median: the C++ library call timed by clfractal_filter_bench (best of --repeats
        # after a warm-up; its --volume case times the median alone)
        t_med, ours = best_of(a.repeats, lambda: clfractal.median(v))
        out = run_cli(a.filter_bench, "--size", 8, "--repeats", a.repeats, "--volume", path)
        t_cpp = json.loads(out)["cases"][-1]["median_seconds"]
        rows.update(median_python_seconds=t_med, median_cpp_seconds=t_cpp, median_overhead=t_med / t_cpp - 1)
        line = (f"median          python {t_med:.4f} s | C++ {t_cpp:.4f} s | overhead "
                f"{100 * rows['median_overhead']:+.1f}%")
        from scipy import ndimage
        peer_repeats = min(a.repeats, 2)  # the peers take seconds per call
        t_scipy, theirs = best_of(peer_repeats, lambda: ndimage.median_filter(v, size=3, mode="nearest"))
        if not np.array_equal(ours, theirs):
            sys.exit("python_bench: median differs from scipy.ndimage.median_filter")
        rows["median_scipy_seconds"] = t_scipy
        rows["median_vs_scipy"] = t_scipy / t_med
        line += f" | scipy {t_scipy:.4f} s ({t_scipy / t_med:.2f}x)"
        try:
            import pyclesperanto as cle
            cle.select_device(clfractal.device_description().split(" / ")[-1])

            def cle_median():
                return cle.pull(cle.median_box(cle.push(v), None, 1, 1, 1))
            with warnings.catch_warnings():  # median_box is deprecated in favour of median()
                warnings.simplefilter("ignore", DeprecationWarning)
                t_cle, theirs = best_of(peer_repeats, cle_median)
            rows["median_cle_seconds"] = t_cle
            rows["median_vs_cle"] = t_cle / t_med
            rows["cle_equal"] = bool(np.array_equal(ours, theirs))
            line += (f" | pyclesperanto {t_cle:.4f} s ({t_cle / t_med:.2f}x, on {cle.get_device().name}, "
                     f"{'equal' if rows['cle_equal'] else 'differs at the borders'})")
        except ImportError as e:
            line += f" | pyclesperanto not installed ({e})"
        print(line)
    print("ratios are peer time / ours (> 1: ours is faster); overhead: python / C++ - 1")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
