#!/usr/bin/env python3
"""The noise level against known noise: clfractal's estimate (`fd --noise-level --json`, key
noise.sigma) beside skimage.restoration.estimate_sigma and dipy's estimate_sigma on the same
arrays.

    noise_sigma_bench.py --clfractal build/clfractal [--data DIR] [--volumes A,B,...]
                         [--smooth S] [--seed N] [--markdown F] [--json F] [--smoke]

Cases. Smooth synthetic fields (float32, 128^3: the distance to the centre, Marschner-Lobb
x 255, a ramp 2x + y + z/2; and the ramp 20..235 in uint8) and real volumes of DIR (the
NAME_XxYxZ_TYPE.raw files) smoothed with a Gaussian of standard deviation S (default 1.5,
numpy, radius ceil(3 S), edges clamped) so that little of their own noise is left, rounded to
their type; two of them also kept in float32. To each: uniform and Gaussian noise of standard
deviation 2, 4, 8 (16-bit data also 32 and 128), rounded and clipped to the type.

Truth. sigma_added = std(round(clean + n) - clean), the noise added (after rounding, before
clipping): what the estimator is meant to find. sigma_all = std(noisy - clean) over every
voxel after clipping: where a zero background is clipped it is much smaller, because clipped
voxels keep a truncated, one-sided remainder of the noise. Both are printed, with the share of
clipped voxels; errors are relative to sigma_added, the summary gives both. "clean" is each
estimator on the clean volume alone: its own residual (the rounding of the smoothed values),
which adds in quadrature and is part of every estimate.

Real volumes without added noise: each estimator beside the standard deviation in 8^3
windows that read no extreme value (percentiles 5, 25, 50 over the windows): a noise estimate
that counts anatomy as noise lands far above the flat windows.

--smoke: three small synthetic cases (40^3) through the CLI, no peers, exit 1 if an error exceeds 5%.
The peers need scikit-image (with PyWavelets) and dipy; without them their columns are empty.
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

warnings.filterwarnings("ignore")

DTYPES = {"uint8": np.uint8, "uint16": np.uint16, "int16": np.int16, "float32": np.float32}
DEFAULT_VOLUMES = "seg3d_mr,niivue_ct_pitch,mni_avg152t1,engine,bonsai,lobster,walnut,stent"
FLOAT_VOLUMES = ("seg3d_mr", "engine")
CT_VOLUMES = ("niivue_ct_pitch", "stent", "engine", "walnut", "bonsai")


# ------------------------------------------------------------------ volumes

def read_raw(path):
    m = re.match(r"(.+)_(\d+)x(\d+)x(\d+)_(\w+)\.raw$", os.path.basename(path))
    name, nx, ny, nz, t = m.groups()
    return name, np.fromfile(path, DTYPES[t]).reshape(int(nz), int(ny), int(nx))


def gaussian(a, s, axes=(0, 1, 2)):
    """Separable Gaussian of standard deviation s in float64 along `axes`, radius ceil(3 s),
    edges clamped."""
    r = int(np.ceil(3 * s))
    w = np.exp(-np.arange(-r, r + 1) ** 2 / (2 * s * s))
    w /= w.sum()
    out = a.astype(np.float64)
    for axis in axes:
        p = np.pad(out, [(r, r) if i == axis else (0, 0) for i in range(3)], mode="edge")
        n = out.shape[axis]
        out = sum(wi * np.take(p, range(i, i + n), axis=axis) for i, wi in enumerate(w))
    return out


def to_type(x, dtype):
    if np.issubdtype(dtype, np.integer):
        info = np.iinfo(dtype)
        return np.clip(np.round(x), info.min, info.max).astype(dtype)
    return x.astype(dtype)


def synthetic(n):
    z, y, x = np.meshgrid(*[np.arange(n, dtype=np.float64)] * 3, indexing="ij")
    c = (n - 1) / 2
    u, v, w = (x / (n - 1)) * 2 - 1, (y / (n - 1)) * 2 - 1, (z / (n - 1)) * 2 - 1
    ml = (1 - np.sin(np.pi * w / 2) + 0.25 * (1 + np.cos(2 * np.pi * 6 * np.cos(np.pi * np.hypot(u, v) / 2)))) / 2.5
    ramp = 2 * x + y + z / 2
    return [("distance", np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2).astype(np.float32)),
            ("marschner-lobb", (255 * ml).astype(np.float32)),
            ("ramp", ramp.astype(np.float32)),
            ("ramp", to_type(20 + 215 * x / (n - 1), np.uint8))]


def noise_levels(dtype):
    return (2, 4, 8, 32, 128) if np.dtype(dtype).itemsize == 2 else (2, 4, 8)


def add_noise(clean, kind, sd, rng):
    """(noisy, sigma_added, sigma_all, clipped share) for noise of `kind` and std sd."""
    n = rng.normal(0, sd, clean.shape) if kind == "gaussian" else rng.uniform(-sd * 3 ** 0.5, sd * 3 ** 0.5, clean.shape)
    c = clean.astype(np.float64)
    pre = np.round(c + n) if np.issubdtype(clean.dtype, np.integer) else (c + n).astype(clean.dtype).astype(np.float64)
    noisy = to_type(pre, clean.dtype)
    f = noisy.astype(np.float64)
    return noisy, float(np.std(pre - c)), float(np.std(f - c)), float(np.mean(f != pre))


# ------------------------------------------------------------------ estimators

def fd_noise(cli, work, a):
    """(the "noise" object of clfractal fd --noise-level --json on `a` written as a raw file,
    one isovalue: the curve is not needed; the command's wall time)."""
    nz, ny, nx = a.shape
    t = {np.dtype(k): v for v, k in DTYPES.items()}[a.dtype]
    path = os.path.join(work, f"case_{nx}x{ny}x{nz}_{t}.raw")
    a.tofile(path)
    out = os.path.join(work, "fd.json")
    iso = str(float(np.median(a))) if t == "float32" else str(int(np.median(a)))
    start = time.perf_counter()
    r = subprocess.run([cli, "-q", "fd", path, "--noise-level", "--isovalues", iso, "--json", out],
                       capture_output=True, text=True)
    wall = time.perf_counter() - start
    if r.returncode:
        sys.exit(f"clfractal failed: {r.stderr}")
    return json.load(open(out))["noise"], wall


class Ours:
    """clfractal fd --noise-level --json on a raw file (fd_noise)."""

    def __init__(self, cli, work):
        self.cli, self.work = cli, work

    def __call__(self, a):
        noise, wall = fd_noise(self.cli, self.work, a)
        sigma = noise["sigma"]
        return (float("nan") if sigma is None else sigma), noise["flat_share"], noise["seconds"], wall


def package_timer():
    """f(array) -> (seconds of clfractal.noise_level on the array, on a DeviceVolume of it), each
    the best of 3 after a warm-up, when the Python package imports; else None."""
    try:
        import clfractal
    except ImportError:
        return None

    def best(f):
        f()
        return min(timed(lambda _: f(), None)[1] for _ in range(3))

    def run(a):
        resident = clfractal.DeviceVolume(a)
        return best(lambda: clfractal.noise_level(a)), best(lambda: clfractal.noise_level(resident))
    return run


def peers():
    """The peer estimators that import, as name -> f(float64 array) -> sigma."""
    out = {}
    try:
        from skimage.restoration import estimate_sigma
        import pywt  # noqa: F401  (estimate_sigma needs it)
        out["skimage"] = lambda a: float(estimate_sigma(a))
    except ImportError:
        pass
    try:
        from dipy.denoise.noise_estimate import estimate_sigma as dipy_sigma
        out["dipy"] = lambda a: float(np.asarray(dipy_sigma(a)).ravel()[0])
    except ImportError:
        pass
    return out


def timed(f, a):
    start = time.perf_counter()
    value = f(a)
    return value, time.perf_counter() - start


# ------------------------------------------------------------------ the runs

def run_case(label, clean, ours, others, rng, rows, clean_sigma, package):
    for kind in ("uniform", "gaussian"):
        for sd in noise_levels(clean.dtype):
            noisy, added, everything, clipped = add_noise(clean, kind, sd, rng)
            sigma, share, _, wall = ours(noisy)
            row = {"case": label, "type": str(noisy.dtype), "voxels": int(noisy.size), "noise": kind, "sd": sd,
                   "sigma_added": added, "sigma_all": everything, "clipped": clipped, "clean": clean_sigma,
                   "ours": sigma, "flat_share": share, "wall_ours": wall}
            if package and kind == "uniform" and sd == 2:  # timed once per volume
                row["seconds_ours"], row["seconds_resident"] = package(noisy)
            f = noisy.astype(np.float64)
            for name, peer in others.items():
                row[name], row["seconds_" + name] = timed(peer, f)
            rows.append(row)
            print_row(row, others)


def err(estimate, truth):
    return 100 * (estimate / truth - 1)


def print_row(r, others):
    cells = [f"{r['case']:<16} {r['type']:<7} {r['noise']:<8} {r['sd']:>4}", f"{r['sigma_added']:8.3f}",
             f"{r['sigma_all']:8.3f}", f"{100 * r['clipped']:5.1f}%", f"{r['ours']:8.3f} {err(r['ours'], r['sigma_added']):+6.2f}%",
             f"{100 * r['flat_share']:5.1f}%"]
    cells += [f"{r[n]:8.3f} {err(r[n], r['sigma_added']):+7.2f}%" for n in others]
    print(" | ".join(cells), flush=True)


def header(others):
    print(" | ".join(["case             type    noise      sd", "  added", "    all", " clip", "    ours    err",
                      "share"] + [f"{n:>8}    err" for n in others]))


def real_cases(data, names, smooth):
    for name in names:
        paths = glob.glob(os.path.join(data, name + "_*.raw"))
        if not paths:
            print(f"{name}: not in {data}, skipped", file=sys.stderr)
            continue
        _, a = read_raw(paths[0])
        s = gaussian(a, smooth)
        yield f"{name}", to_type(s, a.dtype)
        if name in FLOAT_VOLUMES:
            yield f"{name}", s.astype(np.float32)


def flat_window_std(a, k=8):
    """Percentiles 5, 25, 50 of the standard deviation in k^3 windows (step k/2) that read no
    extreme value of the volume."""
    f = a.astype(np.float64)
    lo, hi = f.min(), f.max()
    out = []
    h = k // 2
    for z in range(0, f.shape[0] - k + 1, h):
        for y in range(0, f.shape[1] - k + 1, h):
            for x in range(0, f.shape[2] - k + 1, h):
                w = f[z:z + k, y:y + k, x:x + k]
                if w.min() > lo and w.max() < hi:
                    out.append(w.std())
    return np.percentile(out, [5, 25, 50]) if out else [float("nan")] * 3


def run_real(data, ours, others):
    rows = []
    print("\nreal volumes, no added noise: estimates beside the std in flat 8^3 windows (p5 p25 p50)")
    for name in CT_VOLUMES:
        paths = glob.glob(os.path.join(data, name + "_*.raw"))
        if not paths:
            continue
        _, a = read_raw(paths[0])
        sigma, share, _, _ = ours(a)
        row = {"case": name, "type": str(a.dtype), "ours": sigma, "flat_share": share}
        for n, peer in others.items():
            row[n] = peer(a.astype(np.float64))
        row["window_std"] = [float(x) for x in flat_window_std(a)]
        rows.append(row)
        peers_text = "  ".join(f"{n} {row[n]:.3f}" for n in others)
        print(f"{name:<16} {row['type']:<7} ours {sigma:.3f} ({100 * share:.1f}% of voxels)  {peers_text}  "
              f"window std {row['window_std'][0]:.2f} {row['window_std'][1]:.2f} {row['window_std'][2]:.2f}")
    return rows


# ------------------------------------------------------------------ summaries

def stats(values):
    v = np.abs(np.asarray(values, dtype=np.float64))
    v = v[~np.isnan(v)]
    return (float(np.median(v)), float(v.max())) if len(v) else (float("nan"), float("nan"))


def summary(rows, names):
    """Per estimator, median and worst |error| in % against both truths, over all cases and by group."""
    groups = {"all": rows, "synthetic": [r for r in rows if r["group"] == "synthetic"],
              "real, typed": [r for r in rows if r["group"] == "real typed"],
              "real, float32": [r for r in rows if r["group"] == "real float"]}
    out = {}
    for name in names:
        out[name] = {g: stats([err(r[name], r["sigma_added"]) for r in rs]) for g, rs in groups.items() if rs}
        out[name]["all, against sigma_all"] = stats([err(r[name], r["sigma_all"]) for r in rows])
    return out


def group_rows(rows, names):
    """One line per (case, type): clean residual, median / worst |error| per estimator, shares."""
    keys = []
    for r in rows:
        if (r["case"], r["type"]) not in keys:
            keys.append((r["case"], r["type"]))
    out = []
    for case, t in keys:
        rs = [r for r in rows if r["case"] == case and r["type"] == t]
        line = {"case": case, "type": t, "clean": rs[0]["clean"], "clipped": max(r["clipped"] for r in rs),
                "flat_share": (min(r["flat_share"] for r in rs), max(r["flat_share"] for r in rs)),
                "sd": sorted({r["sd"] for r in rs})}
        for n in names:
            line[n] = stats([err(r[n], r["sigma_added"]) for r in rs])
        out.append(line)
    return out


def timings(rows, names):
    """Per volume size, median seconds: the package call (array in), on a resident DeviceVolume,
    the whole `clfractal fd` process, and each peer."""
    out = []
    for n in sorted({r["voxels"] for r in rows}):
        rs = [r for r in rows if r["voxels"] == n]
        med = lambda key: float(np.median([r[key] for r in rs if key in r])) if any(key in r for r in rs) else float("nan")
        line = {"voxels": n, "ours": med("seconds_ours"), "resident": med("seconds_resident"), "ours_cli": med("wall_ours")}
        for name in names[1:]:
            line[name] = med("seconds_" + name)
        out.append(line)
    return out


def markdown(rows, real, names, smooth):
    fmt = lambda s: f"{s[0]:.2f} / {s[1]:.2f}"
    head = "| estimator | " + " | ".join(names) + " |\n|---|" + "---|" * len(names) + "\n"
    sm = summary(rows, names)
    text = "Median / worst |error| in %, against the added noise (after rounding, before clipping):\n\n" + head
    for g in sm[names[0]]:
        text += f"| {g} | " + " | ".join(fmt(sm[n][g]) for n in names) + " |\n"
    text += (f"\nPer volume (smoothed with a Gaussian of {smooth}, uniform and Gaussian noise of every std): "
             "the estimator's residual on the clean volume, median / worst |error| in %, the largest clipped "
             "share and the flat share of our estimate:\n\n| volume | type | std added | clean (ours) | "
             + " | ".join(names) + " | clipped | flat share |\n|---|---|---|---|" + "---|" * len(names) + "---|---|\n")
    for g in group_rows(rows, names):
        text += (f"| {g['case']} | {g['type']} | {', '.join(map(str, g['sd']))} | {g['clean']:.3f} | "
                 + " | ".join(fmt(g[n]) for n in names)
                 + f" | {100 * g['clipped']:.0f}% | {100 * g['flat_share'][0]:.0f}-{100 * g['flat_share'][1]:.0f}% |\n")
    text += "\nReal volumes without added noise, beside the std in 8³ windows that read no extreme value:\n\n"
    text += "| volume | type | " + " | ".join(names) + " | window std p5 / p25 / p50 |\n|---|---|" + "---|" * len(names) + "---|\n"
    for r in real:
        text += (f"| {r['case']} | {r['type']} | " + " | ".join(f"{r[n]:.3f}" for n in names)
                 + f" | {r['window_std'][0]:.2f} / {r['window_std'][1]:.2f} / {r['window_std'][2]:.2f} |\n")
    text += ("\nSeconds per volume size (median): `clfractal.noise_level` on the array and on a resident "
             "`DeviceVolume` (best of 3, warm), the whole `clfractal fd --noise-level` process (read, one "
             "isovalue, the Theorem 1 pass), the peers:\n\n")
    text += ("| voxels | ours (array) | ours (resident) | ours (CLI process) | " + " | ".join(names[1:]) + " |\n|---|---|---|---|"
             + "---|" * (len(names) - 1) + "\n")
    for t in timings(rows, names):
        text += (f"| {t['voxels']:,} | {t['ours']:.4f} | {t['resident']:.4f} | {t['ours_cli']:.2f} | "
                 + " | ".join(f"{t[n]:.3f}" for n in names[1:]) + " |\n")
    return text


def print_summary(rows, names):
    print("\nmedian / worst |error| in % (against sigma_added unless said otherwise)")
    for name, groups in summary(rows, names).items():
        print(f"  {name:<8} " + "  ".join(f"{g}: {m:.2f} / {w:.2f}" for g, (m, w) in groups.items()))


# ------------------------------------------------------------------ main

def clean_residuals(clean, ours, others):
    values = {"ours": ours(clean)[0]}
    for n, peer in others.items():
        values[n] = peer(clean.astype(np.float64))
    return values


def run_all(args, ours, others):
    rng = np.random.default_rng(args.seed)
    rows = []
    cases = [("synthetic", label, a) for label, a in synthetic(args.size)]
    volumes = [v for v in args.volumes.split(",") if v]
    cases += [("real float" if a.dtype == np.float32 else "real typed", label, a)
              for label, a in real_cases(args.data, volumes, args.smooth)]
    header(others)
    package = package_timer()
    for group, label, clean in cases:
        residual = clean_residuals(clean, ours, others)
        start = len(rows)
        run_case(label, clean, ours, others, rng, rows, residual["ours"], package)
        for r in rows[start:]:
            r["group"] = group
            r["clean_all"] = residual
    return rows


def smoke(ours):
    rng = np.random.default_rng(3)
    worst = 0.0
    for label, clean in [c for c in synthetic(40) if c[0] in ("distance", "ramp")]:
        noisy, added, _, _ = add_noise(clean, "gaussian" if clean.dtype == np.float32 else "uniform", 4, rng)
        sigma = ours(noisy)[0]
        print(f"{label} {clean.dtype}: added {added:.3f}, estimated {sigma:.3f} ({err(sigma, added):+.2f}%)")
        worst = max(worst, abs(err(sigma, added)))
    return 0 if worst <= 5 else 1


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--clfractal", default="build/clfractal")
    p.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))
    p.add_argument("--volumes", default=DEFAULT_VOLUMES)
    p.add_argument("--smooth", type=float, default=1.5)
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--markdown")
    p.add_argument("--json")
    p.add_argument("--smoke", action="store_true")
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as work:
        ours = Ours(args.clfractal, work)
        if args.smoke:
            return smoke(ours)
        others = peers()
        rows = run_all(args, ours, others)
        real = run_real(args.data, ours, others)
    names = ["ours"] + list(others)
    print_summary(rows, names)
    if args.markdown:
        open(args.markdown, "w").write(markdown(rows, real, names, args.smooth))
    if args.json:
        json.dump({"cases": rows, "real": real, "summary": summary(rows, names)}, open(args.json, "w"), indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
