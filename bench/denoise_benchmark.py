#!/usr/bin/env python3
"""Which denoiser should a user pick? Every filter of clfractal against ground truth.

Clean volumes (float32, so that neither noise nor filters are clipped or quantised):
  vessels  an analytic phantom: a ball with tubes 1 and 2 voxels wide along the axes and a
           diagonal, the thin features of the thesis' aneurysm (Fig. 4.2); isovalue 50 of 0/100;
  nested   an analytic phantom of nested materials with sharp corners: a ball (100) holding a
           cube (200) holding a ball (300); isovalue 150, the cube's interface;
  real     volumes of ../shared/data smoothed by a Gaussian of sigma 1 (scipy), isovalue by
           Otsu's rule on the clean volume.
Known noise from a fixed seed: uniform [-mu, mu] with mu = 0.3 c and 0.6 c, Gaussian with
sigma = 0.15 c and 0.3 c, c the contrast (100 for the phantoms, half the 1..99 percentile
range for the real volumes); and in tables of their own (", correlated noise") correlated
Gaussian noise of sigma 0.15 c and 0.3 c, white noise smoothed by a Gaussian of 1 voxel and
rescaled, as a reconstruction kernel or an earlier filter leaves it.

Every method runs through the command-line tool (`clfractal filter`, `clfractal smooth`) on
the noisy volume; each result is scored against the clean volume at the isovalue s:
  mismatch  % of vertices on the wrong side of s ({f >= s} differs from the clean one);
  comp      isosurface components C26({f >= s}) + C6({f < s}) - 1 (the cube convention), and
            the comp error |comp - comp_clean|;
  D         the box span dimension log2(I(G) / I(G')) at s, and the D error |D - D_clean|;
  dist      the distances between the intersected-cube sets of the result and of the clean
            volume (each cube of one to the nearest of the other, both ways): mean and 95th
            percentile, in voxels;
  thin      % of the clean volume's thin voxels kept on the positive side: the voxels of
            {clean >= s} that an opening by the 6-neighbour cross removes (tubes up to 2
            voxels wide, cube edges and corners);
  RMSE      root mean square difference to the clean volume;
  changed   % of vertices the method changed in the noisy input;
  seconds   compute time the tool reports (no file I/O, no kernel compilation; the smoothing
            reports device and queue time).
The bilateral range scale is 2 x the known noise standard deviation (an oracle choice that
favours it). Prints one table per family (means over volumes and noise levels) and the winner
of each criterion; --markdown writes the tables, --plot a figure. --smoke runs one small
phantom, one noise level, every method, and checks the small-components results' guarantee.
Exits 1 when a method fails or a check does not hold.
"""
import argparse
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import ndimage

CUBE26 = np.ones((3, 3, 3), dtype=bool)
CROSS6 = ndimage.generate_binary_structure(3, 1)


# ---- clean volumes -------------------------------------------------------------------------

def vessels_phantom(n):
    """A ball with thin tubes (1 and 2 voxels wide) along x, y, z and one diagonal: 0 / 100."""
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64)
    c = (n - 1) / 2
    inside = (x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2 <= (n / 6) ** 2
    q = n // 4
    inside |= (np.abs(y - q) < 0.5) & (np.abs(z - c) < 0.5)                                   # 1 wide along x
    inside |= (np.abs(x - q) < 0.5) & (np.abs(y - 3 * q) < 0.5)                               # 1 wide along z
    inside |= (np.abs(x - 3 * q - 0.5) < 1) & (np.abs(z - q - 0.5) < 1)                       # 2 wide along y
    inside |= (np.abs(y - 3 * q - 0.5) < 1) & (np.abs(z - 3 * q - 0.5) < 1) & (x > c)         # 2 wide, ends in the ball
    d = np.stack([x - y, y - z, x - z])                                                       # distance to the diagonal
    inside |= np.sqrt((d ** 2).sum(0) / 3) < 0.75
    return np.where(inside, 100.0, 0.0).astype(np.float32), 50.0, 100.0


def nested_phantom(n):
    """A ball (100) holding a cube (200) holding a ball (300): the isovalue 150 is the cube's
    interface with the material around it, sharp edges and corners."""
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64)
    c = (n - 1) / 2
    f = np.zeros((n, n, n))
    f[(x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2 < (0.45 * n) ** 2] = 100
    f[(np.abs(x - c) < 0.25 * n) & (np.abs(y - c) < 0.22 * n) & (np.abs(z - c) < 0.2 * n)] = 200
    f[(x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2 < (0.1 * n) ** 2] = 300
    return f.astype(np.float32), 150.0, 100.0


def otsu(f):
    hist, edges = np.histogram(f, bins=256)
    centres = (edges[:-1] + edges[1:]) / 2
    w = np.cumsum(hist)
    m = np.cumsum(hist * centres)
    total, mean = w[-1], m[-1] / w[-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        between = (mean * w - m) ** 2 / (w * (total - w))
    return float(centres[np.nanargmax(between[:-1])])


def real_volume(data, name, crop):
    """A volume of the shared data, cropped to at most `crop`^3 around its centre, smoothed."""
    path = next(pathlib.Path(data).glob(f"{name}_*x*x*_*.raw"))
    m = re.search(r"_(\d+)x(\d+)x(\d+)_(\w+)\.raw$", path.name)
    nx, ny, nz = map(int, m.groups()[:3])
    a = np.fromfile(path, dtype=np.dtype(m.group(4))).reshape(nz, ny, nx).astype(np.float32)
    sl = tuple(slice(max(0, (s - crop) // 2), max(0, (s - crop) // 2) + min(s, crop)) for s in a.shape)
    clean = ndimage.gaussian_filter(a[sl], 1.0, mode="nearest").astype(np.float32)
    lo, hi = np.percentile(clean, [1, 99])
    return clean, otsu(clean), float(hi - lo) / 2


def noises(c, smoke):
    cases = [("gaussian", 0.3 * c)] if smoke else [("uniform", 0.3 * c), ("uniform", 0.6 * c),
                                                   ("gaussian", 0.15 * c), ("gaussian", 0.3 * c),
                                                   ("correlated", 0.15 * c), ("correlated", 0.3 * c)]
    return cases


def add_noise(clean, kind, level, seed):
    """(noisy volume, the noise's standard deviation). correlated: Gaussian noise smoothed by a
    Gaussian of 1 voxel (periodic borders, so that every voxel's noise is alike), rescaled to
    standard deviation `level`: the noise of a reconstruction kernel or an earlier filter."""
    rng = np.random.default_rng(seed)
    if kind == "uniform":
        noise, sigma = rng.uniform(-level, level, clean.shape), level / math.sqrt(3)
    elif kind == "correlated":
        noise = ndimage.gaussian_filter(rng.normal(0, 1, clean.shape), 1.0, mode="wrap")
        noise, sigma = noise * (level / noise.std()), level
    else:
        noise, sigma = rng.normal(0, level, clean.shape), level
    return (clean + noise).astype(np.float32), sigma


# ---- methods -------------------------------------------------------------------------------

def methods(s, sigma):
    """name -> list of steps; a step is (command, arguments)."""
    b = f"1,{2 * sigma:.6g}"
    sc = lambda k: ("filter", ["--small-components", str(k), "--iso", f"{s:.9g}"])
    fm = lambda h: ("filter", ["--median", "--fractal", "--iso", f"{s:.9g}", "--threshold", str(h)])
    return {
        "none": [],
        "median": [("filter", ["--median"])],
        "gaussian 1": [("filter", ["--gaussian", "1"])],
        "bilateral 1,2sd": [("filter", ["--bilateral", b])],
        "targeted median h2.2": [fm(2.2)],
        "targeted median h2.5": [fm(2.5)],
        "targeted gaussian h2.2": [("filter", ["--gaussian", "1", "--fractal", "--iso", f"{s:.9g}", "--threshold", "2.2"])],
        "targeted gaussian h2.5": [("filter", ["--gaussian", "1", "--fractal", "--iso", f"{s:.9g}", "--threshold", "2.5"])],
        "LD4 median h3.3": [("filter", ["--median", "--fractal4", "--threshold", "3.3"])],
        "LD-guided bilateral": [("filter", ["--bilateral", b, "--ld-guided", "--iso", f"{s:.9g}"])],
        "small comp. K5": [sc(5)],
        "small comp. K20": [sc(20)],
        "small comp. K100": [sc(100)],
        "smoothing h2.2": [("smooth", ["--iso", f"{s:.9g}", "--threshold", "2.2"])],
        "median + K20": [("filter", ["--median"]), sc(20)],
        "targeted median h2.5 + K20": [fm(2.5), sc(20)],
    }


def raw_path(directory, name, a):
    nz, ny, nx = a.shape
    return pathlib.Path(directory) / f"{name}_{nx}x{ny}x{nz}_float32.raw"


def read_nrrd(path):
    """The raw-encoded NRRD files the tool writes: header lines up to a blank line, then data."""
    blob = pathlib.Path(path).read_bytes()
    end = blob.index(b"\n\n")
    fields = dict(line.split(": ", 1) for line in blob[:end].decode().splitlines()[1:] if ": " in line)
    if fields.get("encoding") != "raw" or fields.get("type") != "float":
        raise RuntimeError(f"{path}: expected a raw float NRRD, got {fields}")
    nx, ny, nz = map(int, fields["sizes"].split())
    return np.frombuffer(blob[end + 2:], dtype="<f4").reshape(nz, ny, nx).copy()


def run_step(cli, command, args, src, out, json_path):
    cmd = [cli, "-q", command, str(src), *args, "-o", str(out)]
    if command == "filter":
        cmd += ["--json", str(json_path)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()}")
    if command == "filter":
        return json.loads(pathlib.Path(json_path).read_text())["seconds_compute"]
    m = re.search(r"time\s+([0-9.eE+-]+) s device.*?, ([0-9.eE+-]+) s queue", r.stdout)
    return float(m.group(1)) + float(m.group(2))


def run_method(cli, work, noisy, steps):
    """The method's result and its compute seconds (the sum over its steps)."""
    if not steps:
        return noisy, 0.0
    src = raw_path(work, "noisy", noisy)
    noisy.tofile(src)
    seconds = 0.0
    for i, (command, args) in enumerate(steps):
        out = pathlib.Path(work) / f"step{i}.nrrd"
        seconds += run_step(cli, command, args, src, out, pathlib.Path(work) / "step.json")
        a = read_nrrd(out)
        src = raw_path(work, f"step{i}", a)
        a.tofile(src)
    return a, seconds


# ---- scores --------------------------------------------------------------------------------

def components(f, s):
    p, n = f >= s, f < s
    if not p.any() or not n.any():
        return 0
    return ndimage.label(p, structure=CUBE26)[1] + ndimage.label(n, structure=CROSS6)[1] - 1


def intersected(f, s):
    """Cubes whose span [a, b] has a < s <= b."""
    lo = hi = None
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                c = f[dz:f.shape[0] - 1 + dz, dy:f.shape[1] - 1 + dy, dx:f.shape[2] - 1 + dx]
                lo = c if lo is None else np.minimum(lo, c)
                hi = c if hi is None else np.maximum(hi, c)
    return (lo < s) & (s <= hi)


def box_dimension(f, s):
    i0, i1 = intersected(f, s).sum(), intersected(f[::2, ::2, ::2], s).sum()
    return math.log2(i0 / i1) if i0 and i1 else float("nan")


def surface_distances(f, clean, s):
    a, b = intersected(f, s), intersected(clean, s)
    if not a.any() or not b.any():
        return float("inf"), float("inf")
    d = np.concatenate([ndimage.distance_transform_edt(~b)[a], ndimage.distance_transform_edt(~a)[b]])
    return float(d.mean()), float(np.percentile(d, 95))


def scores(f, noisy, clean, s, thin):
    mean, p95 = surface_distances(f, clean, s)
    return {
        "mismatch": 100 * float(((f >= s) != (clean >= s)).mean()),
        "comp": components(f, s),
        "D": box_dimension(f, s),
        "dist": mean,
        "p95": p95,
        "thin": 100 * float((f[thin] >= s).mean()) if thin.any() else float("nan"),
        "rmse": float(np.sqrt(((f.astype(np.float64) - clean) ** 2).mean())),
        "changed": 100 * float((f != noisy).mean()),
    }


def small_components_guarantee(f, s, k):
    """The small-components filter's guarantee: no component of either set with <= k vertices."""
    sizes = [np.bincount(ndimage.label(f >= s, structure=CUBE26)[0].ravel())[1:],
             np.bincount(ndimage.label(f < s, structure=CROSS6)[0].ravel())[1:]]
    return all((x > k).all() for x in sizes)


# ---- the run -------------------------------------------------------------------------------

def cases(args):
    if args.smoke:
        yield "vessels", "vessels", *vessels_phantom(args.size)
        return
    yield "vessels", "vessels", *vessels_phantom(args.size)
    yield "nested", "nested", *nested_phantom(args.size)
    data = pathlib.Path(args.data)
    if (data / "MANIFEST.tsv").exists():
        for name in args.real:
            yield "real", name, *real_volume(data, name, args.size)
    else:
        print(f"{data}: no MANIFEST.tsv, the real family is skipped", file=sys.stderr)


CRITERIA = [  # key, heading, best ("min", "max", "minabs": closest to the clean value), format
    ("mismatch", "mismatch %", "min", "{:.3f}"),
    ("dcomp", "comp error", "min", "{:.1f}"),
    ("comp", "comp", None, "{:.1f}"),
    ("dD", "D error", "min", "{:.3f}"),
    ("D", "D", None, "{:.3f}"),
    ("dist", "dist mean", "min", "{:.3f}"),
    ("p95", "dist p95", "min", "{:.2f}"),
    ("thin", "thin kept %", "max", "{:.1f}"),
    ("rmse", "RMSE", "min", "{:.2f}"),
    ("changed", "changed %", None, "{:.2f}"),
    ("seconds", "seconds", "min", "{:.4f}"),
]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--clfractal", required=True, help="the command-line tool")
    p.add_argument("--data", default=str(pathlib.Path(__file__).resolve().parents[2] / "shared" / "data"))
    p.add_argument("--real", nargs="*", default=["nucleon", "engine"], help="real volumes (MANIFEST names)")
    p.add_argument("--size", type=int, default=64, help="phantom edge and real crop (vertices)")
    p.add_argument("--smoke", action="store_true", help="one 24^3 phantom, one noise level, every method")
    p.add_argument("--markdown", help="write the tables and winners as markdown to this file")
    p.add_argument("--plot", help="write a figure (PNG) of mismatch and component error per method")
    args = p.parse_args()
    if args.smoke and args.size == 64:
        args.size = 24
    t_start = time.time()
    rows = {}  # family -> method -> list of score dicts
    clean_stats = {}
    failures = []
    with tempfile.TemporaryDirectory() as work:
        for family, name, clean, s, contrast in cases(args):
            thin = (clean >= s) & ~ndimage.binary_opening(clean >= s, structure=CROSS6)
            c_comp, c_d = components(clean, s), box_dimension(clean, s)
            for table in (family, family + ", correlated noise"):
                clean_stats.setdefault(table, []).append((name, s, c_comp, c_d, int(thin.sum())))
            for j, (kind, level) in enumerate(noises(contrast, args.smoke)):
                noisy, sigma = add_noise(clean, kind, level, seed=1000 + j)
                table = family + (", correlated noise" if kind == "correlated" else "")
                for method, steps in methods(s, sigma).items():
                    try:
                        f, seconds = run_method(args.clfractal, work, noisy, steps)
                    except RuntimeError as e:
                        failures.append(f"{name} {kind} {level:g} {method}: {e}")
                        continue
                    sc = scores(f, noisy, clean, s, thin)
                    sc.update(seconds=seconds, dcomp=abs(sc["comp"] - c_comp), dD=abs(sc["D"] - c_d))
                    rows.setdefault(table, {}).setdefault(method, []).append(sc)
                    if args.smoke and method.startswith("small comp."):
                        k = int(method.split("K")[1])
                        if not small_components_guarantee(f, s, k):
                            failures.append(f"{name} {method}: a component of <= {k} vertices is left")
                    if args.smoke and not all(math.isfinite(sc[key]) for key in ("mismatch", "rmse", "dist")):
                        failures.append(f"{name} {method}: a score is not finite: {sc}")
    report = []
    for family, by_method in rows.items():
        report.append(f"### {family}\n")
        for name, s, c_comp, c_d, nthin in clean_stats[family]:
            report.append(f"- clean `{name}`: isovalue {s:.6g}, {c_comp} components, D {c_d:.3f}, "
                          f"{nthin} thin voxels")
        report.append("")
        report.append("| method | " + " | ".join(h for _, h, _, _ in CRITERIA) + " |")
        report.append("|---" * (len(CRITERIA) + 1) + "|")
        means = {m: {k: float(np.mean([r[k] for r in rs])) for k, _, _, _ in CRITERIA} for m, rs in by_method.items()}
        for m, mean in means.items():
            report.append(f"| {m} | " + " | ".join(fmt.format(mean[k]) for k, _, _, fmt in CRITERIA) + " |")
        report.append("")
        for key, heading, best, fmt in CRITERIA:
            if best is None:
                continue
            pool = {m: v[key] for m, v in means.items() if not (key == "seconds" and m == "none")}
            pool = {m: v for m, v in pool.items() if math.isfinite(v)}
            if not pool:
                continue
            target = max(pool.values()) if best == "max" else min(pool.values())
            winners = [m for m, v in pool.items() if v == target]
            report.append(f"- best {heading}: **{', '.join(winners)}** ({fmt.format(target)})")
        report.append("")
    text = "\n".join(report)
    print(text)
    print(f"device: {device_line(args.clfractal)}; {time.time() - t_start:.1f} s in all")
    if args.markdown:
        pathlib.Path(args.markdown).write_text(
            "<!-- written by bench/denoise_benchmark.py; do not edit -->\n\n" + text + "\n")
    if args.plot:
        plot(rows, args.plot)
    for f in failures:
        print("FAILED:", f, file=sys.stderr)
    return 1 if failures else 0


def device_line(cli):
    r = subprocess.run([cli, "devices"], capture_output=True, text=True)
    chosen = [line for line in r.stdout.splitlines() if "*" in line]
    return (chosen[0] if chosen else r.stdout.strip().splitlines()[0] if r.stdout.strip() else "?").strip()


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    families = list(rows)
    fig, axes = plt.subplots(len(families), 2, figsize=(12, 3.2 * len(families)), squeeze=False)
    for i, family in enumerate(families):
        ms = list(rows[family])
        for j, (key, label) in enumerate([("mismatch", "vertices on the wrong side of s (%)"),
                                          ("dcomp", "|components - clean|")]):
            ax = axes[i][j]
            ax.barh(ms, [np.mean([r[key] for r in rows[family][m]]) for m in ms])
            ax.set_title(f"{family}: {label}", fontsize=9)
            ax.tick_params(labelsize=7)
            ax.invert_yaxis()
            if key == "dcomp":
                ax.set_xscale("symlog")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    sys.exit(main())
