#!/usr/bin/env python3
"""Local fractal dimension throughput in one run: clfractal's device field and its OpenMP
implementation (both timed by clfractal_local_bench) against numpy (bench/local_numpy.py) on
the same volumes, with every field checked against the device's (same NaN pattern, values
within 1e-6).

    local_bench.py [--bench PATH] [--size N]... [--window K] [--repeats R] [--out DIR] [--json F]

Exits 1 if any field disagrees. Run it with a python3 that has numpy (Debian:
/usr/bin/python3 with python3-numpy).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import local_numpy  # noqa: E402


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bench", default=os.path.join(here, "..", "build", "clfractal_local_bench"),
                   help="the clfractal_local_bench executable (default: build/)")
    p.add_argument("--size", type=int, action="append", help="N of the N^3 cases (repeatable; default 256)")
    p.add_argument("--window", type=int, default=8)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--out", help="directory for the volumes and fields (default: a temporary one)")
    p.add_argument("--json", help="write the figures as JSON")
    a = p.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        return run(a, a.out or tmp)


def run(a, out):
    cmd = [a.bench, "--window", str(a.window), "--repeats", str(a.repeats), "--out", out]
    for n in a.size or [256]:
        cmd += ["--size", str(n)]
    bench = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
    if not bench.stdout.strip():
        sys.exit(f"local_bench: {a.bench} failed (exit {bench.returncode})")
    report = json.loads(bench.stdout)
    ok = bench.returncode == 0

    for row in report["cases"]:
        f = local_numpy.read_nrrd(row["volume"])
        seconds, ld = local_numpy.best_of(a.repeats, lambda: local_numpy.local_dimension(f, row["iso"], a.window))
        same_nan, err = local_numpy.compare(local_numpy.read_nrrd(row["field"]), ld)
        row.update({"numpy_seconds": seconds, "numpy_gvoxels_per_s": row["voxels"] / seconds / 1e9,
                    "speedup_vs_numpy": seconds / row["device_seconds"],
                    "numpy_max_difference": err, "numpy_agrees": same_nan and err <= 1e-6})
        ok &= row["numpy_agrees"] and row["openmp_agrees"]

    print(f"device          {report['device']}")
    print(f"copy bandwidth  {report['copy_gb_per_s']:.2f} GB/s (read + write)")
    print(f"OpenMP threads  {report['openmp_threads']}; numpy single-threaded")
    print(f"kernel compile  {report['compile_seconds']:.3f} s (apart from the figures below)")
    print(f"\nLD field, window {a.window}, best of {a.repeats}, Gvoxel/s (whole calls: host volume in, field out):")
    print(f"  {'case':26s} {'device s':>9s} {'device':>7s} {'GB/s':>6s} {'resident':>9s} {'OpenMP':>7s} "
          f"{'numpy':>7s} {'vs OpenMP':>10s} {'vs numpy':>9s}  fields")
    for r in report["cases"]:
        agree = "equal" if r["openmp_agrees"] and r["numpy_agrees"] else "DIFFER"
        print(f"  {r['case']:26s} {r['device_seconds']:9.4f} {r['device_gvoxels_per_s']:7.3f} "
              f"{r['device_gb_per_s']:6.2f} {r['resident_gvoxels_per_s']:9.3f} {r['openmp_gvoxels_per_s']:7.3f} "
              f"{r['numpy_gvoxels_per_s']:7.3f} {r['speedup_vs_openmp']:9.2f}x {r['speedup_vs_numpy']:8.2f}x  {agree}")
    print("(resident: the field of a volume already on the device, left there; GB/s: volume read once and"
          " field written once, against the copy bandwidth; vs X > 1: device faster)")
    if a.json:
        with open(a.json, "w") as out:
            json.dump(report, out, indent=1)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
