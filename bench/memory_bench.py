#!/usr/bin/env python3
"""Peak resident memory of each clfractal command on a CT-like uint16 phantom.

The phantom: air (20..60, uniform noise), a body ellipsoid (1000 +- 150 structure, +-40
noise) and a bone shell (1800..3500): a wide 16-bit value range, as a CT scan has. Each
command runs alone under /usr/bin/time -v; its peak RSS is compared with the bounds of a
volume of B bytes: in-core commands 4 B + 256 MiB, fd 1.25 B + 256 MiB, streamed commands
512 MiB, `components --slab` (z-parts of about a quarter of the volume, P bytes each) what its
plan budgets, 4 P + 256 MiB + 104 bytes a slice vertex a part. Exit 1 when a command fails or
passes its bound.

Each command first runs once on a 16^3 phantom of the same type, so the measured run finds
its kernels in the program cache: PoCL's in-process compiler takes up to ~180 MiB more on a
command's first run on a machine (a one-time cost that does not grow with the volume, which
is what the bounds are about); the cold figure of a command is its first run's.

With --form-only the bounds are printed but not judged: it exits 1 only when a command fails
or its peak cannot be read. That is the smoke test in ctest, where a cold program cache or a
loaded machine moves a small volume's absolute peak (a 40^3 report read 257 MiB against its
256 MiB on a fresh machine's first run, within it on the second); the bounds themselves are
judged by the plain runs on the performance page.

    memory_bench.py CLFRACTAL [--size N] [--keep DIR] [--markdown] [--form-only]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

MIB = 1 << 20


def phantom(n, path):
    """Writes the n^3 uint16 phantom as a raw-encoded NRRD, one slice at a time."""
    rng = np.random.default_rng(88172645)
    c = (n - 1) / 2.0
    y, x = np.mgrid[0:n, 0:n].astype(np.float64)
    with open(path, "wb") as f:
        f.write(("NRRD0004\ntype: uint16\ndimension: 3\nsizes: %d %d %d\nendian: little\nencoding: raw\n\n"
                 % (n, n, n)).encode())
        for z in range(n):
            r = np.sqrt(((x - c) / (0.45 * n)) ** 2 + ((y - c) / (0.38 * n)) ** 2 + ((z - c) / (0.48 * n)) ** 2)
            body = 1000 + 150 * np.sin(x * 0.05) * np.cos(y * 0.07) + 80 * (rng.random((n, n)) - 0.5)
            rb = np.sqrt(((x - c) / (0.15 * n)) ** 2 + ((y - c - 0.1 * n) / (0.12 * n)) ** 2)
            bone = 1800 + 1700 * (1 - np.abs(rb - 0.9) / 0.1) + 100 * (rng.random((n, n)) - 0.5)
            v = np.where(r > 1, 20 + 40 * rng.random((n, n)), np.where((rb > 0.8) & (rb < 1.0), bone, body))
            f.write(np.clip(np.rint(v), 0, 65535).astype("<u2").tobytes())


def commands(vol, out, n):
    """(name, arguments, bound kind) for the n^3 volume `vol`."""
    return [
        ("fd", ["fd", vol], "fd"),
        ("fd --stream", ["fd", "--stream", vol], "stream"),
        ("components", ["components", vol], "in-core"),
        ("components --stream", ["components", "--stream", vol, "--isovalues", "499:502:1"], "stream"),
        ("components --slab", ["components", vol, "--slab", str(slab_slices(n))], "slab"),
        ("smooth", ["smooth", vol, "--iso", "500", "--threshold", "2.3", "-o", out + "/smooth.nrrd"], "in-core"),
        ("local", ["local", vol, "--iso", "500", "-o", out + "/local.nrrd"], "in-core"),
        ("local --stream", ["local", "--stream", vol, "--iso", "500", "-o", out + "/local_s.nrrd"], "stream"),
        ("median", ["filter", "--median", vol, "-o", out + "/median.nrrd"], "in-core"),
        ("mesh", ["mesh", vol, "--iso", "500", "-o", out + "/mesh.ply"], "in-core"),
        ("report", ["report", vol, "-o", out + "/report.html"], "in-core"),
    ]


def slab_slices(n):
    """The slices of each z-part `components --slab` is given: about a quarter of the volume."""
    return max(2, n // 4 + 1)


def bound(kind, volume_bytes, n):
    if kind == "stream":
        return 512 * MIB
    if kind == "slab":  # what components plans for its z-parts: 4x a part + 256 MiB + their links
        p = slab_slices(n)
        parts = 1 if p >= n else -(-(n - 1) // (p - 1))
        return 4 * p * n * n * 2 + 256 * MIB + parts * 104 * n * n
    return (1.25 if kind == "fd" else 4.0) * volume_bytes + 256 * MIB


def time_v(cmd):
    """(exit status, wall s, CPU s of user + system, peak RSS bytes) of one run of `cmd` under
    /usr/bin/time -v."""
    p = subprocess.run(["/usr/bin/time", "-v"] + cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = cpu = 0.0
    rss = 0
    for line in p.stderr.splitlines():
        key, _, value = line.strip().rpartition(": ")
        if key == "Maximum resident set size (kbytes)":
            rss = int(value) * 1024
        elif key.startswith("Elapsed (wall clock)"):
            wall = sum(float(x) * 60 ** i for i, x in enumerate(reversed(value.split(":"))))
        elif key in ("User time (seconds)", "System time (seconds)"):
            cpu += float(value)
    if p.returncode != 0:
        sys.stderr.write(p.stderr[-2000:])
    return p.returncode, wall, cpu, rss


def peak_rss(cli, args):
    """(exit status, peak RSS in bytes, wall seconds) of one run."""
    rc, wall, _, rss = time_v([cli, "-q"] + args)
    return rc, rss, wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cli")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--only", action="append", help="run only these commands (by name)")
    ap.add_argument("--keep", help="write the phantom and outputs here instead of a temporary directory")
    ap.add_argument("--markdown", action="store_true", help="print the table as markdown")
    ap.add_argument("--form-only", action="store_true",
                    help="print the bounds without judging them: fail only when a command fails or reads no peak")
    a = ap.parse_args()
    work = a.keep or tempfile.mkdtemp(prefix="clfractal_memory_")
    os.makedirs(work, exist_ok=True)
    vol = os.path.join(work, "ct_%d.nrrd" % a.size)
    if not os.path.exists(vol):
        phantom(a.size, vol)
    volume_bytes = 2 * a.size ** 3
    warm = os.path.join(work, "warm")
    os.makedirs(warm, exist_ok=True)
    # 32^3: the smallest whose noise level takes blocks of 8, so every program is cached.
    small = os.path.join(warm, "ct_32.nrrd")
    phantom(32, small)
    rows, failed = [], False
    for (name, args, kind), (_, warm_args, _) in zip(commands(vol, work, a.size), commands(small, warm, 32)):
        if a.only and name not in a.only:
            continue
        peak_rss(a.cli, warm_args)  # compiles and caches the command's kernels
        rc, rss, wall = peak_rss(a.cli, args)
        limit = bound(kind, volume_bytes, a.size)
        ran = rc == 0 and rss > 0
        ok = ran and rss <= limit
        failed |= not ran if a.form_only else not ok
        status = "yes" if ok else ("NO (exit %d)" % rc if rc else "no peak read" if rss <= 0 else "NO")
        if a.form_only and ran and not ok:
            status = "over (not judged)"
        rows.append((name, rss / MIB, rss / volume_bytes, limit / MIB, wall, status))
    head = "%d^3 uint16 CT-like phantom (%.0f MiB), kernels cached" % (a.size, volume_bytes / MIB)
    if a.markdown:
        print("| command | peak RSS (MiB) | / volume | bound (MiB) | wall (s) | within |\n|---|---:|---:|---:|---:|---|")
        for r in rows:
            print("| %s | %.0f | %.2f | %.0f | %.1f | %s |" % r)
        print("\n" + head)
    else:
        print(head)
        for r in rows:
            print("%-15s %8.0f MiB %6.2fx  bound %6.0f MiB  %7.1f s  %s" % r)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
