#!/usr/bin/env python3
"""The recommendations against ground truth: phantoms of nested materials whose boundaries are
known, through `clfractal fd --json`, beside the two simpler rules a user might apply to the
same curve.

    recommend_bench.py --clfractal build/clfractal [--size N] [--markdown F] [--json F] [--smoke]

Phantoms (N^3, default 96): two to four nested materials (spheres, cubes with sharp corners,
or a cube inside a sphere) with values v_0 < v_1 < ... (uint8 0..255, uint16 with a wide range,
float32), blurred with a Gaussian of standard deviation 1 or 2 voxels (edges clamped), then
uniform noise of standard deviation 0, 2% or 6% of the smallest contrast (rounded and clipped
to the type), and a thin tube one to two voxels wide through the outer material.

Truth. Boundary i lies between materials i and i+1; its surface is every isovalue inside the
transition, and the one a user wants is its middle m_i = (v_i + v_(i+1)) / 2. A recommendation
*hits* boundary i when it lies in the central 80% of [v_i, v_(i+1)] (away from both plateaus,
where the isosurface is the plateau's noise). Per case: recall (boundaries hit by some
recommendation), precision (recommendations that hit a boundary), and the error
|s - m_i| / (v_(i+1) - v_i) of the recommendation nearest to each boundary.

Peers, on the same curve (the JSON's `curve` and `clean_bands`):
- middle: the middle isovalue of each clean band (the earlier rule of the tool);
- lowest-D: the well-populated isovalue with the lowest D (a one-line notebook rule).

--smoke: four small cases (N = 48) through the CLI; exit 1 if the tool's recall is below 1 on
the noise-free and low-noise ones.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from noise_sigma_bench import gaussian  # noqa: E402  the separable Gaussian, edges clamped

TYPES = {"uint8": (np.uint8, [20, 100, 180, 240]), "uint16": (np.uint16, [1000, 9000, 21000, 40000]),
         "float32": (np.float32, [-1.0, 0.5, 2.0, 3.5])}


def phantom(n, shape, materials, blur, noise_share, dtype, values, seed):
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64)
    c = (n - 1) / 2 + np.array([0.31, -0.17, 0.23])
    r = np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2)
    cheb = np.maximum(np.maximum(abs(x - c[0]), abs(y - c[1])), abs(z - c[2]))
    v = np.full(x.shape, float(values[0]))
    radii = np.linspace(0.44, 0.16, materials - 1) * n
    for i, rad in enumerate(radii):
        dist = r if shape == "spheres" or (shape == "mixed" and i == 0) else cheb
        v[dist <= rad] = values[i + 1]
    # A thin tube (1-2 voxels wide) of the second material through the outer one.
    tube = (np.hypot(y - c[1] - 0.3 * n, z - c[2]) <= 1.0) & (r > radii[0])
    v[tube] = values[1]
    v = gaussian(v, blur)
    contrast = min(np.diff(values[:materials]))
    rng = np.random.default_rng(seed)
    if noise_share > 0:
        v = v + rng.uniform(-1, 1, v.shape) * noise_share * contrast * np.sqrt(3)
    if np.issubdtype(dtype, np.integer):
        info = np.iinfo(dtype)
        v = np.clip(np.round(v), info.min, info.max)
    return v.astype(dtype)


def score(recs, values):
    bounds = [(values[i], values[i + 1]) for i in range(len(values) - 1)]
    hit = [False] * len(bounds)
    good = 0
    for s in recs:
        ok = False
        for i, (a, b) in enumerate(bounds):
            if a + 0.1 * (b - a) < s < b - 0.1 * (b - a):
                hit[i] = ok = True
        good += ok
    err = []
    for a, b in bounds:
        m = (a + b) / 2
        err.append(min(abs(s - m) for s in recs) / (b - a) if recs else float("nan"))
    return sum(hit) / len(bounds), (good / len(recs) if recs else 0.0), float(np.mean(err))


def peers(j):
    curve = j["curve"]
    iso = [r["isovalue"] for r in curve]
    middle = [b["isovalue"] for b in j["clean_bands"]]
    counts = [r["counts"][0] for r in curve]
    floor = max(1, 0.01 * max(counts))
    pop = [(r["fd"], r["isovalue"]) for r in curve if r["fd"] is not None and r["counts"][0] >= floor]
    lowest = [min(pop)[1]] if pop else []
    return {"middle": middle, "lowest-D": lowest}, iso


def run_case(cli, case, tmp):
    dtype, vals = TYPES[case["type"]]
    values = vals[:case["materials"]]
    v = phantom(case["n"], case["shape"], case["materials"], case["blur"], case["noise"], dtype, values, case["seed"])
    n = case["n"]
    path = os.path.join(tmp, "phantom_%dx%dx%d_%s.raw" % (n, n, n, case["type"]))
    v.tofile(path)
    out = os.path.join(tmp, "fd.json")
    subprocess.run([cli, "-q", "fd", path, "--json", out], check=True, stdout=subprocess.DEVNULL)
    j = json.load(open(out))
    recs = [e["isovalue"] for e in j["recommended"]]
    rows = {"clfractal": score(recs, values)}
    for name, r in peers(j)[0].items():
        rows[name] = score(r, values)
    verdicts = [e["verdict"] for e in j["recommended"]]
    return rows, recs, verdicts, j["clean"]


def cases(n, smoke):
    out = []
    seed = 1
    grid = [("spheres", 3, "uint8"), ("cubes", 3, "uint8"), ("mixed", 4, "uint8"), ("spheres", 4, "uint16"),
            ("cubes", 2, "uint16"), ("spheres", 3, "float32")]
    for shape, materials, t in grid:
        for blur in (1.0, 2.0):
            for noise in (0.0, 0.02, 0.06):
                out.append(dict(shape=shape, materials=materials, type=t, blur=blur, noise=noise, n=n, seed=seed))
                seed += 1
    if smoke:
        keep = {("spheres", "uint8", 2.0, 0.0), ("spheres", "uint8", 2.0, 0.02), ("cubes", "uint8", 1.0, 0.02),
                ("spheres", "float32", 1.0, 0.02)}
        out = [c for c in out if (c["shape"], c["type"], c["blur"], c["noise"]) in keep]
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--clfractal", required=True)
    p.add_argument("--size", type=int, default=96)
    p.add_argument("--markdown")
    p.add_argument("--json")
    p.add_argument("--smoke", action="store_true")
    a = p.parse_args()
    n = 48 if a.smoke else a.size
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for c in cases(n, a.smoke):
            rows, recs, verdicts, clean = run_case(a.clfractal, c, tmp)
            results.append(dict(case=c, rows=rows, recommended=recs, verdicts=verdicts, clean=clean))
            print("%-8s %d %-7s blur %.1f noise %4.0f%%: " % (c["shape"], c["materials"], c["type"], c["blur"],
                                                              100 * c["noise"]) +
                  "  ".join("%s recall %.2f precision %.2f err %.3f" % (k, *v) for k, v in rows.items()), flush=True)
    names = list(results[0]["rows"])
    lines = ["| rule | cases | mean recall | cases with every boundary found | mean precision | mean error / contrast |",
             "|---|---|---|---|---|---|"]
    summary = {}
    for name in names:
        rec = [r["rows"][name][0] for r in results]
        pre = [r["rows"][name][1] for r in results]
        err = [r["rows"][name][2] for r in results if not np.isnan(r["rows"][name][2])]
        summary[name] = dict(recall=float(np.mean(rec)), full=int(sum(x == 1 for x in rec)),
                             precision=float(np.mean(pre)), error=float(np.mean(err)) if err else None)
        lines.append("| %s | %d | %.3f | %d | %.3f | %.3f |" % (name, len(results), summary[name]["recall"],
                                                                summary[name]["full"], summary[name]["precision"],
                                                                summary[name]["error"] or float("nan")))
    print("\n".join(lines))
    if a.markdown:
        open(a.markdown, "w").write("\n".join(lines) + "\n")
    if a.json:
        json.dump(dict(results=results, summary=summary), open(a.json, "w"), indent=1)
    if a.smoke:
        bad = [r for r in results if r["case"]["noise"] < 0.05 and r["rows"]["clfractal"][0] < 1]
        if bad:
            print("FAIL: a boundary missed on", [r["case"] for r in bad])
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
