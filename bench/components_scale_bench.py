#!/usr/bin/env python3
"""The component curve and the report at the scale of CT and micro-CT: `clfractal components`
and `clfractal report` on bench/memory_bench.py's uint16 CT-like phantoms, on every core and
on one, with wall time, CPU time (user + system of all threads) and peak resident memory from
/usr/bin/time -v, against the memory bound of 4 volumes + 256 MiB.

One core (sides up to --one-core-up-to, 384 by default) is `taskset -c 0` (the OpenMP
sweeps and PoCL's threads all on CPU 0): the figure a single-threaded run of the same build
gives. Before the timed runs each command runs once on a
32^3 phantom (the smallest whose noise level takes blocks of 8, as the timed ones do), so that
the timed ones find their kernels in the program cache (PoCL compiling a program in the process
raised the 384^3 report's peak from 639 to 771 MiB in one run). The curves of the
runs on one core and on all of them (`--csv`) must be identical, and so must the reports'
component curves (each entry's `components` in their JSON's `curve`).

    components_scale_bench.py CLFRACTAL [--size N]... [--one-core-up-to N] [--work DIR] [--markdown]

Exit 1 when a run fails, passes its bound, or two curves differ.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from memory_bench import phantom, time_v  # noqa: E402

MIB = 1 << 20


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cli")
    ap.add_argument("--size", type=int, action="append", help="phantom side (repeatable; default 384 and 640)")
    ap.add_argument("--one-core-up-to", type=int, default=384,
                    help="run on one core too up to this side (default 384: the 640^3 report alone takes minutes)")
    ap.add_argument("--work", help="keep the phantoms and outputs here (default: a temporary folder)")
    ap.add_argument("--markdown", action="store_true", help="print a markdown table")
    a = ap.parse_args()
    sizes = a.size or [384, 640]
    cores = os.cpu_count() or 1
    work = a.work or tempfile.mkdtemp(prefix="components_scale_")
    os.makedirs(work, exist_ok=True)
    small = os.path.join(work, "p32.nrrd")
    phantom(32, small)
    for args in (["components", small, "--csv", os.path.join(work, "w.csv")],
                 ["report", small, "-o", os.path.join(work, "w.html")]):
        subprocess.run([a.cli, "-q"] + args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    rows, failed = [], 0
    for n in sizes:
        vol = os.path.join(work, f"p{n}.nrrd")
        if not os.path.exists(vol):
            phantom(n, vol)
        volume_bytes = 2 * n ** 3
        bound = 4 * volume_bytes + 256 * MIB
        curves = {}
        for command in ("components", "report"):
            for c in sorted({cores, 1} if n <= a.one_core_up_to else {cores}, reverse=True):
                tag = f"{command}{n}_{c}"
                if command == "components":
                    out = os.path.join(work, tag + ".csv")
                    args = ["components", vol, "--csv", out]
                else:
                    out = os.path.join(work, tag + ".json")
                    args = ["report", vol, "-o", os.path.join(work, tag + ".html"), "--json", out]
                pin = ["taskset", "-c", "0"] if c == 1 and cores > 1 else []
                rc, wall, cpu, rss = time_v(pin + [a.cli, "-q"] + args)
                within = rc == 0 and rss <= bound
                failed += not within
                if rc == 0:
                    if command == "components":
                        curves.setdefault(command, []).append(open(out).read())
                    else:
                        curve = json.load(open(out))["curve"]
                        curves.setdefault(command, []).append(json.dumps([(e["isovalue"], e["components"]) for e in curve]))
                rows.append((f"{n}^3 uint16 ({volume_bytes / MIB:.0f} MiB)", command, c, wall, cpu, rss, bound,
                             "yes" if within else ("FAILED" if rc else "NO")))
        for command, got in curves.items():
            if len(set(got)) > 1:
                print(f"{command} {n}^3: the curves on {cores} cores and on 1 differ", file=sys.stderr)
                failed += 1
    if a.markdown:
        print("| volume | command | cores | wall s | CPU s | peak MiB | bound MiB | within |")
        print("|---|---|---:|---:|---:|---:|---:|---|")
        for v, cmd, c, wall, cpu, rss, bound, ok in rows:
            print(f"| {v} | `{cmd}` | {c} | {wall:.1f} | {cpu:.1f} | {rss / MIB:.0f} | {bound / MIB:.0f} | {ok} |")
        print()
        print("Curves on one core and on all: " + ("identical" if not failed else "see the errors above") + ".")
    else:
        for v, cmd, c, wall, cpu, rss, bound, ok in rows:
            print(f"{v:<22} {cmd:<11} {c} core(s)  wall {wall:7.1f} s  CPU {cpu:7.1f} s  peak {rss / MIB:6.0f} MiB"
                  f"  bound {bound / MIB:.0f} MiB  {ok}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
