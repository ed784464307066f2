#!/usr/bin/env python3
"""The noise level against known correlated noise: clfractal's noise.sigma, noise.sigma_white
and noise.correlation (`fd --noise-level --json`) on volumes whose noise is known, and on real
CTs against the standard deviation of their uniform regions.

    noise_correlated_bench.py --clfractal build/clfractal [--data DIR] [--seed N]
                              [--markdown F] [--json F] [--smoke]

Bases. Real anatomy of DIR smoothed with a Gaussian of 1.5 (seg3d_mr, an MRI head, cropped to
96 x 128 x 96; mni_avg152t1; niivue_ct_pitch, a head CT, cropped to 96 x 128 x 56), and a
sharp phantom (96^3: three nested spheres and a box, piecewise constant) and a shaded one (96^3:
the memory benchmark's ellipsoid shaded by a sinusoid, a bright ring, a dark background,
without its noise; structure that the wider taps reach). Each is scaled into
its value type with room for the noise (no clipping): uint8 (x 0.7 + 40); seg3d_mr and the
phantom also int16 (grey values and noise x 8) and float32.

Noise families, sigma 6 and 10 grey values (x 8 for int16): white; isotropically correlated,
white noise smoothed by a Gaussian of width w = 0.5, 0.8, 1.0, 1.5 voxels (generated 8 voxels
wider on every side and cropped, so no border effect), rescaled to sigma; z only (w = 1 along
z); in-plane only (w = 1 along x and y); spatially varying (white, sigma x 1 .. 2 along x,
scaled so that its RMS is sigma); Rician (the magnitude of (base + sigma n1, sigma n2), n1, n2
independent Gaussian, on the MRI bases only, without the offset so that their background is
dark: the noise an MRI magnitude image has).

Truth. sigma: the standard deviation of (noisy - clean) over every voxel, after rounding to the
type (the rounding is part of it); Rician: the sigma of the complex Gaussian (in the bright
tissue the magnitude's noise has that standard deviation; in the dark background, Rayleigh
noise, less). Correlation: w along the smoothed axes, 0 along the others. Errors: sigma
relative; correlation relative where w > 0, and the largest estimate where w = 0.

Real CTs (DIR/formats): the Philips head phantom (dicom_ct_phantom, 512 x 512 x 28 int16 HU,
0.45 mm pixels, 5 mm slices) and the lung CT (3DCT_lung_baseline_small, 57 x 78 x 64). Rule for
uniform regions of interest: the in-slice 8 x 8 squares (non-overlapping) whose mean lies in
-150 .. 150 HU and whose 8 neighbouring squares in the slice have means within 20 HU of it
(one soft-tissue-like material, no edge or gradient within 8 voxels: what a reader places an
ROI on); the reference is the median of their standard deviations (quartiles printed). In the
slice, because CT slices are often much thicker than their pixels (the phantom's 8^3 blocks
span 40 mm along z, where the phantom itself varies); the same rule on 8^3 blocks is printed
beside it.

Map. For the spatially varying family, the noise map's 10th, 50th and 90th percentiles against
those of the true per-cell noise (the standard deviation of noisy - clean in each cell the map
fills).

Peers: scikit-image estimate_sigma and dipy's estimate_sigma when they import (not needed).

--smoke: white and isotropic (w = 1) noise on the 48^3 phantom smoothed by 1.5 in float32 and
the z-only family on it in uint8, through the CLI; exit 1 if white is off by over 3%, correlated by over 15%, or a
correlation width by over 25%; and the real-CT rule on a made-up CT (tissue, a step to bone, an
air margin, in-slice correlated noise): exit 1 if the ROIs include a square by the step or the
air, if their SD median is off the noise, or if sigma is over 25% from it.
"""
import argparse
import glob
import json
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from noise_sigma_bench import fd_noise, gaussian, peers, read_raw, to_type  # noqa: E402

SIGMAS = (6, 10)
PAD = 8


# ------------------------------------------------------------------ bases and noise

def scaled(clean, dtype):
    """The clean base in dtype's grey values: uint8 x 0.7 + 40, int16 x 5.6 + 320 (8 x uint8's),
    float32 as uint8's; and the factor of the noise (8 for int16)."""
    u8 = 0.7 * clean / max(1e-9, clean.max()) * 255 + 40
    if dtype == np.int16:
        return 8 * u8, 8.0
    return u8, 1.0


def phantom(n):
    z, y, x = np.meshgrid(*[np.arange(n, dtype=np.float64)] * 3, indexing="ij")
    c = (n - 1) / 2
    r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    v = np.where(r < 0.42 * n, 60.0, 0.0) + np.where(r < 0.28 * n, 50.0, 0.0) + np.where(r < 0.12 * n, 60.0, 0.0)
    box = (abs(x - 0.2 * n) < 0.1 * n) & (abs(y - 0.75 * n) < 0.12 * n) & (abs(z - c) < 0.3 * n)
    return v + np.where(box, 90.0, 0.0)


def shaded(n):
    """The structure of bench/memory_bench.py's phantom without its noise: an ellipsoid body
    shaded by 150 sin(0.05 x) cos(0.07 y) (in voxels of a 384^3 volume, scaled to n), a bright
    ring inside it and a dark background, n^3."""
    z, y, x = np.meshgrid(*[np.arange(n, dtype=np.float64) * (384.0 / n)] * 3, indexing="ij")
    c, m = 383 / 2.0, 384.0
    r = np.sqrt(((x - c) / (0.45 * m)) ** 2 + ((y - c) / (0.38 * m)) ** 2 + ((z - c) / (0.48 * m)) ** 2)
    body = 1000 + 150 * np.sin(x * 0.05) * np.cos(y * 0.07)
    rb = np.sqrt(((x - c) / (0.15 * m)) ** 2 + ((y - c - 0.1 * m) / (0.12 * m)) ** 2)
    bone = 1800 + 1700 * np.clip(1 - np.abs(rb - 0.9) / 0.1, 0, 1)
    return np.where(r > 1, 40.0, np.where((rb > 0.8) & (rb < 1.0), bone, body))


def bases(data):
    out = []
    if data:
        def crop(name, shape):
            path = glob.glob(os.path.join(data, name + "_*.raw"))
            if not path:
                print(f"note: {name} not in {data}; skipped")
                return None
            a = read_raw(path[0])[1].astype(np.float64)
            sz, sy, sx = [max(0, (n - m) // 2) for n, m in zip(a.shape, shape)]
            return gaussian(a[sz:sz + shape[0], sy:sy + shape[1], sx:sx + shape[2]], 1.5)
        for name, shape, mri, types in (("seg3d_mr", (96, 128, 96), True, (np.uint8, np.int16, np.float32)),
                                        ("mni_avg152t1", (91, 109, 91), True, (np.uint8,)),
                                        ("niivue_ct_pitch", (56, 128, 96), False, (np.uint8,))):
            a = crop(name, shape)
            if a is not None:
                out.append((name, a, mri, types))
    out.append(("phantom", phantom(96), False, (np.uint8, np.int16, np.float32)))
    out.append(("shaded", shaded(96), False, (np.uint8, np.int16, np.float32)))
    return out


def families(mri):
    f = [("white", (0, 0, 0))] + [(f"iso {w}", (w, w, w)) for w in (0.5, 0.8, 1.0, 1.5)]
    f += [("z only", (0, 0, 1.0)), ("in-plane", (1.0, 1.0, 0)), ("varying x2", (0, 0, 0))]
    return f + ([("rician", (0, 0, 0))] if mri else [])


def unit_noise(shape, widths, rng):
    """Gaussian noise of standard deviation 1, smoothed by a Gaussian of widths (x, y, z) along
    each axis (generated PAD voxels wider on every side, then cropped)."""
    n = rng.standard_normal(tuple(s + 2 * PAD for s in shape))
    for axis, w in zip((2, 1, 0), widths):
        if w > 0:
            n = gaussian(n, w, (axis,))
    n = n[PAD:-PAD, PAD:-PAD, PAD:-PAD]
    return n / n.std()


def noisy_case(clean, family, widths, sigma, dtype, rng):
    """(noisy volume, true sigma)."""
    if family == "rician":  # on the base without its offset: the MRI's dark background stays dark
        dark = clean - clean.min()
        n1, n2 = rng.standard_normal(clean.shape), rng.standard_normal(clean.shape)
        pre = np.sqrt((dark + sigma * n1) ** 2 + (sigma * n2) ** 2)
        truth = sigma
    else:
        n = unit_noise(clean.shape, widths, rng) * sigma
        if family == "varying x2":
            ramp = np.linspace(1, 2, clean.shape[2])[None, None, :]
            n = n * ramp / np.sqrt(np.mean(ramp ** 2))
        pre = clean + n
        truth = None
    noisy = to_type(pre, dtype)
    if truth is None:
        truth = float(np.std(noisy.astype(np.float64) - clean))
    return noisy, truth


# ------------------------------------------------------------------ estimators

class Ours:
    """The noise object of clfractal fd --noise-level --json (noise_sigma_bench.fd_noise)."""

    def __init__(self, cli, work):
        self.cli, self.work = cli, work

    def __call__(self, a):
        return fd_noise(self.cli, self.work, a)[0]


def num(x):
    return float("nan") if x is None else float(x)


# ------------------------------------------------------------------ the runs

def run_synthetic(data, ours, others, rng):
    rows = []
    for name, base, mri, types in bases(data):
        for dtype in types:
            clean, factor = scaled(base, dtype)
            for family, widths in families(mri):
                for sd in SIGMAS:
                    noisy, truth = noisy_case(clean, family, widths, sd * factor, dtype, rng)
                    noise = ours(noisy)
                    map_error = map_percentile_errors(noise, noisy, clean) if family.startswith("varying") else None
                    row = {"base": name, "type": np.dtype(dtype).name, "family": family, "sd": sd * factor,
                           "truth": truth, "sigma": num(noise["sigma"]), "sigma_white": num(noise["sigma_white"]),
                           "widths": list(widths), "correlation": [num(c) for c in noise["correlation"]],
                           "variation": num(noise.get("variation")), "map_error": map_error}
                    for peer, f in others.items():
                        row[peer] = f(noisy.astype(np.float64))
                    rows.append(row)
                    print(row_line(row), flush=True)
    return rows


def map_percentile_errors(noise, noisy, clean):
    """Relative errors (%) of the noise map's 10th, 50th and 90th percentiles against those of
    the truth: the standard deviation of (noisy - clean) in each cell of the map that has a
    value (cells of map.cell^3 vertices, x fastest)."""
    m = noise["map"]
    cell, (mx, my, mz) = m["cell"], m["dims"]
    diff = noisy.astype(np.float64) - clean
    ours, truth = [], []
    for z in range(mz):
        for y in range(my):
            for x in range(mx):
                v = m["sigma"][x + mx * (y + my * z)]
                if v is None:
                    continue
                ours.append(v)
                truth.append(diff[z * cell:(z + 1) * cell, y * cell:(y + 1) * cell, x * cell:(x + 1) * cell].std())
    if not ours:
        return None
    q = (10, 50, 90)
    return [float(100 * (a / b - 1)) for a, b in zip(np.percentile(ours, q), np.percentile(truth, q))]


def sigma_error(r, key="sigma"):
    return 100 * (r[key] / r["truth"] - 1)


def width_errors(r):
    """Relative errors (%) of the correlation widths where the truth is > 0; the largest
    estimate where it is 0 (or None)."""
    rel = [100 * (c / w - 1) for c, w in zip(r["correlation"], r["widths"]) if w > 0]
    zero = [c for c, w in zip(r["correlation"], r["widths"]) if w == 0]
    return rel, (max(zero) if zero else None)


def row_line(r):
    rel, zero = width_errors(r)
    widths = " ".join(f"{c:.2f}" for c in r["correlation"])
    return (f"{r['base']:<16} {r['type']:<7} {r['family']:<11} {r['sd']:>4g}  truth {r['truth']:7.3f}  sigma "
            f"{r['sigma']:7.3f} ({sigma_error(r):+6.1f}%)  white {r['sigma_white']:7.3f}  widths {widths}"
            + (f" ({', '.join(f'{e:+.0f}%' for e in rel)})" if rel else ""))


def median_worst(values):
    a = np.abs(np.asarray(values, dtype=np.float64))
    return (float(np.median(a)), float(a.max())) if len(a) else (float("nan"), float("nan"))


def family_group(family):
    return "white" if family == "white" else "rician" if family == "rician" else \
        "varying x2" if family.startswith("varying") else "correlated"


def summary(rows):
    """Per family group and per family: median / worst |sigma error|, the white estimate's,
    the width errors."""
    out = []
    keys = [("all correlated", lambda r: family_group(r["family"]) == "correlated")]
    keys += [(g, lambda r, g=g: family_group(r["family"]) == g) for g in ("white", "varying x2", "rician")]
    fams = []
    for r in rows:
        if family_group(r["family"]) == "correlated" and r["family"] not in fams:
            fams.append(r["family"])
    keys += [(f, lambda r, f=f: r["family"] == f) for f in fams]
    keys += [("correlated, anatomy",
              lambda r: family_group(r["family"]) == "correlated" and r["base"] not in ("phantom", "shaded")),
             ("correlated, phantom", lambda r: family_group(r["family"]) == "correlated" and r["base"] == "phantom"),
             ("correlated, shaded", lambda r: family_group(r["family"]) == "correlated" and r["base"] == "shaded"),
             ("white, shaded", lambda r: r["family"] == "white" and r["base"] == "shaded")]
    for label, pick in keys:
        sel = [r for r in rows if pick(r)]
        if not sel:
            continue
        rel = [e for r in sel for e in width_errors(r)[0]]
        zeros = [z for r in sel for z in [width_errors(r)[1]] if z is not None]
        out.append({"group": label, "cases": len(sel), "sigma": median_worst([sigma_error(r) for r in sel]),
                    "sigma_white": median_worst([sigma_error(r, "sigma_white") for r in sel]),
                    "widths": median_worst(rel), "zero_width_max": max(zeros) if zeros else float("nan")})
    return out


# ------------------------------------------------------------------ real CTs

def uniform_rois(a, lo=-150, hi=150, tolerance=20, k=8, kz=1):
    """The standard deviations of the k x k x kz blocks (non-overlapping) whose mean lies in
    [lo, hi] HU and whose 8 neighbouring blocks in the slice plane have means within tolerance
    HU of it: one material, with no edge or gradient within k voxels."""
    nz, ny, nx = a.shape[0] // kz, a.shape[1] // k, a.shape[2] // k
    b = a[:nz * kz, :ny * k, :nx * k].astype(np.float64).reshape(nz, kz, ny, k, nx, k)
    means, sds = b.mean(axis=(1, 3, 5)), b.std(axis=(1, 3, 5), ddof=1)
    out = []
    for z in range(nz):
        for y in range(1, ny - 1):
            for x in range(1, nx - 1):
                m = means[z, y - 1:y + 2, x - 1:x + 2]
                if lo <= means[z, y, x] <= hi and np.all(np.abs(m - means[z, y, x]) <= tolerance):
                    out.append(sds[z, y, x])
    return np.asarray(out)


def run_ct(data, ours):
    rows = []
    for name in ("dicom_ct_phantom_512x512x28_int16.raw", "3DCT_lung_baseline_small_57x78x64_int16.raw"):
        path = os.path.join(data, "formats", name)
        if not os.path.exists(path):
            print(f"note: {path} is absent; skipped")
            continue
        label, a = read_raw(path)
        sds = uniform_rois(a)
        cubes = uniform_rois(a, kz=8)
        noise = ours(a)
        row = {"volume": label, "rois": int(len(sds)), "roi_median": float(np.median(sds)) if len(sds) else None,
               "rois_3d": int(len(cubes)), "roi_3d_median": float(np.median(cubes)) if len(cubes) else None,
               "roi_q1": float(np.percentile(sds, 25)) if len(sds) else None,
               "roi_q3": float(np.percentile(sds, 75)) if len(sds) else None,
               "sigma": num(noise["sigma"]), "sigma_white": num(noise["sigma_white"]),
               "correlation": [num(c) for c in noise["correlation"]], "spread": noise["spread"],
               "notes": noise.get("notes", [])}
        rows.append(row)
        print(f"{label}: {row['rois_3d']} uniform 8^3 ROIs, SD median {row['roi_3d_median']}")
        print(f"{label}: {row['rois']} uniform 8 x 8 x 1 ROIs, SD median {row['roi_median']}, quartiles "
              f"{row['roi_q1']} .. {row['roi_q3']}; sigma {row['sigma']:.3f}, white {row['sigma_white']:.3f}, "
              f"widths {row['correlation']}", flush=True)
    return rows


# ------------------------------------------------------------------ output

def fmt(x, digits=1):
    return "n/a" if x is None or (isinstance(x, float) and np.isnan(x)) else f"{x:.{digits}f}"


def markdown(rows, summ, ct):
    lines = [f"{len(rows)} cases. Median / worst |error| in %: `sigma` and `sigma_white` against the noise's true standard deviation, "
             "the correlation widths against the smoothing's where it is > 0; the largest width read along "
             "unsmoothed axes:", "",
             "| cases | n | sigma | sigma_white | widths | width where 0 |", "|---|---|---|---|---|---|"]
    for s in summ:
        lines.append(f"| {s['group']} | {s['cases']} | {fmt(s['sigma'][0])} / {fmt(s['sigma'][1])} | "
                     f"{fmt(s['sigma_white'][0])} / {fmt(s['sigma_white'][1])} | {fmt(s['widths'][0])} / "
                     f"{fmt(s['widths'][1])} | {fmt(s['zero_width_max'], 2)} |")
    if ct:
        lines += ["", "Real CTs against the median standard deviation of their uniform regions: in-slice 8 x 8 "
                  "squares whose mean lies in -150..150 HU and whose 8 neighbouring squares in the slice have "
                  "means within 20 HU of it (one material, no edge or gradient within 8 voxels). The same rule on "
                  "8³ blocks (neighbours in the plane) beside it: the phantom's 8³ blocks span 40 mm along z.", "",
                  "| volume | ROIs | ROI SD median (quartiles) | sigma | error | within 25% | sigma_white | "
                  "widths x, y, z | 8³ ROIs, SD median |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for r in ct:
            err = 100 * (r["sigma"] / r["roi_median"] - 1) if r["roi_median"] else float("nan")
            lines.append(f"| {r['volume']} | {r['rois']} | {fmt(r['roi_median'], 2)} ({fmt(r['roi_q1'], 2)} .. "
                         f"{fmt(r['roi_q3'], 2)}) | {fmt(r['sigma'], 2)} | {err:+.1f}% | "
                         f"{'yes' if abs(err) <= 25 else 'no'} | {fmt(r['sigma_white'], 2)} | "
                         + ", ".join(fmt(c, 2) for c in r["correlation"])
                         + f" | {r['rois_3d']}, {fmt(r['roi_3d_median'], 2)} |")
    varying = [r for r in rows if r.get("map_error")]
    if varying:
        lines += ["", "Noise varying x2 across x: the map's 10th, 50th and 90th percentiles against the truth's "
                  "(the standard deviation of the added noise in each 32³ cell that the map fills), |error| in %:", "",
                  "| base | type | sd | p10 | p50 | p90 |", "|---|---|---|---|---|---|"]
        for r in varying:
            lines.append(f"| {r['base']} | {r['type']} | {r['sd']:g} | "
                         + " | ".join(f"{e:+.1f}" for e in r["map_error"]) + " |")
        errs = [abs(e) for r in varying for e in r["map_error"]]
        lines += ["", f"Median / worst |error| over the {len(errs)} percentiles: {np.median(errs):.1f} / "
                  f"{max(errs):.1f}%."]
    lines += ["", "Worst cases (sigma):", "", "| base | type | family | sd | truth | sigma | error | widths |",
              "|---|---|---|---|---|---|---|---|"]
    for r in sorted(rows, key=lambda r: -abs(sigma_error(r)))[:8]:
        lines.append(f"| {r['base']} | {r['type']} | {r['family']} | {r['sd']:g} | {r['truth']:.3f} | "
                     f"{r['sigma']:.3f} | {sigma_error(r):+.1f}% | " + ", ".join(f"{c:.2f}" for c in r["correlation"])
                     + " |")
    return "\n".join(lines) + "\n"


def smoke(ours):
    rng = np.random.default_rng(5)
    clean = gaussian(phantom(48), 1.5)
    fails = 0
    for dtype, family, widths in ((np.float32, "white", (0, 0, 0)), (np.float32, "iso 1.0", (1.0, 1.0, 1.0)),
                                  (np.uint8, "z only", (0, 0, 1.0))):
        base, _ = scaled(clean, dtype)
        noisy, truth = noisy_case(base, family, widths, 8.0, dtype, rng)
        noise = ours(noisy)
        r = {"base": "phantom", "type": np.dtype(dtype).name, "family": family, "sd": 8.0, "truth": truth,
             "sigma": num(noise["sigma"]), "sigma_white": num(noise["sigma_white"]), "widths": list(widths),
             "correlation": [num(c) for c in noise["correlation"]]}
        print(row_line(r))
        rel, zero = width_errors(r)
        bad = abs(sigma_error(r)) > (3 if family == "white" else 15) or any(abs(e) > 25 for e in rel) or \
            (zero is not None and zero > 0.4)
        if bad:
            print(f"FAIL: {family}")
            fails += 1
    return fails + smoke_rois(ours)


def smoke_rois(ours):
    """The real-CT rule on a made-up CT of 128 x 128 x 4 int16 HU: soft tissue of 40 HU left of
    a step to 400 HU (bone) at x = 68, with a -1000 HU air margin 8 voxels deep, and noise of
    12 HU smoothed in the slice by 1 voxel: the in-slice ROIs are the squares of one material
    whose neighbours are too (none touching the step or the air), their SDs read the noise (the
    squares remove little of it), and sigma is within 25% of their median. 1 on a miss."""
    rng = np.random.default_rng(11)
    clean = np.full((4, 128, 128), 40.0)
    clean[:, :, 68:] = 400
    clean[:, :8, :], clean[:, -8:, :], clean[:, :, :8], clean[:, :, -8:] = -1000, -1000, -1000, -1000
    noise = unit_noise(clean.shape, (1.0, 1.0, 0), rng)
    a = to_type(clean + 12 * noise, np.int16)
    sds = uniform_rois(a)
    # Squares in tissue with tissue all round: columns 2..6 (column 8 holds the step at x = 68,
    # 0 is air, 1 and 7 touch them), rows 2..13, 4 slices: 240; a few drop out where the noise
    # moves a neighbour's mean by over 20 HU. A rule that let edges in would pass 240.
    most = 5 * 12 * 4
    sigma = num(ours(a)["sigma"])
    err = 100 * (sigma / np.median(sds) - 1) if len(sds) else float("nan")
    print(f"ROI rule: {len(sds)} ROIs (at most {most}), SD median {np.median(sds):.2f} (noise 12), sigma {sigma:.2f} "
          f"({err:+.1f}%)")
    bad = not 0.9 * most <= len(sds) <= most or not 9.5 <= np.median(sds) <= 12.5 or not abs(err) <= 25
    if bad:
        print("FAIL: ROI rule")
    return int(bad)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--clfractal", required=True)
    p.add_argument("--data", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared",
                                                  "data"))
    p.add_argument("--seed", type=int, default=1, help="of the noise")
    for output in ("--markdown", "--json"):
        p.add_argument(output, help="write the tables (markdown) or every case (json) here")
    p.add_argument("--smoke", action="store_true", help="three small cases; exit 1 on a miss")
    args = p.parse_args()
    start = time.time()
    with tempfile.TemporaryDirectory() as work:
        if args.smoke:
            sys.exit(1 if smoke(Ours(args.clfractal, work)) else 0)
        ours = Ours(args.clfractal, work)
        data = args.data if os.path.isdir(args.data) else None
        if not data:
            print(f"note: {args.data} is absent: the phantom only, no CTs")
        others = peers()
        print("peers:", ", ".join(others) or "none importable (scikit-image, dipy)")
        rows = run_synthetic(data, ours, others, np.random.default_rng(args.seed))
        ct = run_ct(data, ours) if data else []
        summ = summary(rows)
        for s in summ:
            print(f"{s['group']:<22} n {s['cases']:3d}  sigma {fmt(s['sigma'][0])} / {fmt(s['sigma'][1])} %  "
                  f"white {fmt(s['sigma_white'][0])} / {fmt(s['sigma_white'][1])} %  widths {fmt(s['widths'][0])} / "
                  f"{fmt(s['widths'][1])} %  width where 0 <= {fmt(s['zero_width_max'], 2)}")
        print(f"{time.time() - start:.0f} s")
        if args.markdown:
            open(args.markdown, "w").write(markdown(rows, summ, ct))
        if args.json:
            json.dump({"rows": rows, "summary": summ, "ct": ct}, open(args.json, "w"), indent=1)


if __name__ == "__main__":
    main()
