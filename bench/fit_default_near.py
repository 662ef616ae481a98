#!/usr/bin/env python3
"""A rule tried for the default fit (issue 33 goal 3), simulated outside terramesh: the range of
a chosen exponential or spherical option without nugget whose range sits at the diameter bound
(`wls_loo_range_bound`) refitted near the origin. Not adopted (docs/geostatistics.md, "Near-origin
range", has the figures and why).

Run from the repository root after `cargo build --release -p terramesh-cli`, in `.venv-hidden`:
    .venv-hidden/bin/python bench/fit_default_near.py [TERRAIN ...] [--seeds S1,...]
        [--spacings M] [--classes K] [--scan F1,...] [--known-best]

For each draw of `bench/fit_default.py` (the same data, truth and PyKrige cache; PyKrige's five
automatic fits are run where the cache lacks them, about 1.5 min per draw): the default fit
(`terramesh variogram --drift linear`) and its hidden-truth RMSE (UK, linear drift); where its
model is an exponential or spherical without nugget with a range at the data's diameter, the
same kind without nugget fitted by weighted least squares (weights N_k / gamma_k^2, the sill and
range both free, range between a tenth of the spacing and the diameter) to the experimental
variogram of the residuals from an OLS plane, over K (default 8) equal classes within M
(default 5) mean spacings (sqrt of the bounding box's area per datum), and that model's
hidden-truth RMSE. `--scan F1,...`: also the exponential without nugget at each range F times
the diameter, its leave-one-out RMSE (`terramesh cv`) and hidden-truth RMSE. Prints one row per
draw, then the mean per terrain of each fit minus the best PyKrige fit. `--known-best`: for seeds
15-22, PyKrige's best per draw from docs/geostatistics.md's tables of the same draws (`KNOWN`)
instead of the cache or a run.
"""
import json
import os
import subprocess
import sys

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.distance import pdist

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_default as fd  # noqa: E402
import hidden_truth as ht  # noqa: E402


# The best PyKrige automatic fit per draw, seeds 15-22 (vosges, fort-worth, colorado,
# grand-canyon, black-forest), from docs/geostatistics.md ("The default fit against PyKrige's",
# "Range bound and no nugget").
KNOWN = {15: [30.707, 4.695, 15.074, 69.265, 19.582], 16: [31.130, 4.652, 14.816, 72.679, 19.299],
         17: [30.355, 4.640, 15.803, 71.620, 17.657], 18: [30.681, 4.700, 15.442, 74.680, 18.226],
         19: [30.949, 4.658, 14.655, 72.441, 18.202], 20: [30.552, 4.747, 15.513, 72.726, 17.690],
         21: [31.365, 4.713, 15.207, 72.838, 19.421], 22: [31.231, 4.695, 14.627, 74.601, 18.097]}
KNOWN_NAMES = ["vosges", "fort-worth", "colorado", "grand-canyon", "black-forest"]


def gamma(kind, c, a, h):
    if kind == "exponential":
        return c * (1 - np.exp(-3 * h / a))
    return c * np.where(h < a, 1.5 * h / a - 0.5 * (h / a) ** 3, 1.0)


def near_origin(d, kind, diam, m, k):
    x, y = d[:, 0] - d[:, 0].mean(), d[:, 1] - d[:, 1].mean()
    a = np.column_stack([np.ones(len(d)), x, y])
    res = d[:, 2] - a @ np.linalg.lstsq(a, d[:, 2], rcond=None)[0]
    h, g = pdist(d[:, :2]), 0.5 * pdist(res[:, None]) ** 2
    s = np.sqrt(np.ptp(d[:, 0]) * np.ptp(d[:, 1]) / len(d))
    c = np.digitize(h, np.linspace(0, m * s, k + 1)) - 1
    ok = (c >= 0) & (c < k)
    n = np.bincount(c[ok], minlength=k)
    hm = np.bincount(c[ok], h[ok], k) / np.maximum(n, 1)
    gm = np.bincount(c[ok], g[ok], k) / np.maximum(n, 1)
    u = n > 0
    f = lambda p: np.sqrt(n[u]) * (gamma(kind, np.exp(p[0]), np.exp(p[1]), hm[u]) - gm[u]) / gm[u]
    r = least_squares(f, [np.log(2 * gm[u][-1]), np.log(m * s)],
                      bounds=([-50, np.log(s / 10)], [50, np.log(diam)]))
    return float(np.exp(r.x[0])), float(np.exp(r.x[1]))


def draw(name, seed):
    """One draw of a terrain: the data and targets split as fit_default.py splits them,
    written as CSV under fit_default.OUT; returns (data, targets, tag, data path, targets path)."""
    rng = np.random.default_rng(seed)
    d, t = ht.split(*fd.TERRAINS[name](), rng, 20000)
    tag = f"{name}-grid-1200-{seed}"
    dp, tp = os.path.join(fd.OUT, f"{tag}-data.csv"), os.path.join(fd.OUT, f"{tag}-targets.csv")
    np.savetxt(dp, d, delimiter=",", header="x,y,z", comments="", fmt="%.10g")
    np.savetxt(tp, t[:, :2], delimiter=",", header="x,y", comments="", fmt="%.10g")
    return d, t, tag, dp, tp


def main():
    argv = sys.argv[1:]

    def opt(name, default):
        return fd.take_opt(argv, name, default)

    seeds = [int(s) for s in opt("--seeds", "15").split(",")]
    m, k = float(opt("--spacings", "5")), int(opt("--classes", "8"))
    scan = [float(f) for f in opt("--scan", "").split(",") if f]
    known = "--known-best" in argv
    names = [a for a in argv if not a.startswith("--")] or list(fd.TERRAINS)
    os.makedirs(fd.OUT, exist_ok=True)
    rows = []
    print("| terrain | seed | best PyKrige | default minus best | near-origin minus best | default model | near-origin range / diameter |")
    print("|---|---|---|---|---|---|---|")
    for seed in seeds:
        for name in names:
            d, t, tag, dp, tp = draw(name, seed)
            out = os.path.join(fd.OUT, f"{tag}-near-out.csv")
            rmse = lambda v: float(np.sqrt(np.mean(
                (ht.terramesh_uk(dp, tp, out, ["--variogram", v]) - t[:, 2]) ** 2)))
            cache = os.path.join(fd.OUT, f"{tag}-pykrige-20000.json")
            if known and seed in KNOWN and name in KNOWN_NAMES:
                pyk = {"best": KNOWN[seed][KNOWN_NAMES.index(name)]}
            elif os.path.exists(cache):
                pyk = json.load(open(cache))
            else:
                pyk = {mo: float(np.sqrt(np.mean((ht.pykrige_uk(d, t, mo)[0] - t[:, 2]) ** 2)))
                       for mo in ("spherical", "exponential", "gaussian", "power", "linear")}
                json.dump(pyk, open(cache, "w"))
            best = min(pyk.values())
            vj = os.path.join(fd.OUT, f"{tag}-near-default.json")
            ht.run(["variogram", "--data", dp, "--drift", "linear", "-o", vj])
            model = json.load(open(vj))["model"]
            r0 = rmse(vj)
            diam = float(pdist(d[:, :2]).max())
            st = model["structures"]
            r1, note = r0, "unchanged"
            if (model["nugget"] == 0 and len(st) == 1 and st[0]["type"] in ("exponential", "spherical")
                    and st[0]["range"] >= 0.999 * diam):
                c, a = near_origin(d, st[0]["type"], diam, m, k)
                vn = os.path.join(fd.OUT, f"{tag}-near.json")
                json.dump({"model": {"nugget": 0.0, "structures": [
                    {"type": st[0]["type"], "psill": c, "range": a}]}}, open(vn, "w"))
                r1, note = rmse(vn), f"{a / diam:.3f}"
            rows.append((name, r0 - best, r1 - best))
            print(f"| {name} | {seed} | {best:.3f} | {r0 - best:+.4f} | {r1 - best:+.4f} | {ht.describe(model)} | {note} |")
            for f in scan:
                v = os.path.join(fd.OUT, f"{tag}-scan.json")
                json.dump({"model": {"nugget": 0.0, "structures": [
                    {"type": "exponential", "psill": 1000.0, "range": f * diam}]}}, open(v, "w"))
                p = subprocess.run([ht.BIN, "cv", "--data", dp, "--method", "uk", "--drift", "linear",
                                    "--variogram", v], capture_output=True, text=True, check=True)
                loo = float([ln for ln in p.stdout.splitlines() if ln.startswith("rmse,")][0].split(",")[1])
                print(f"<!-- {name} {seed} exponential range {f} diameter: leave-one-out {loo:.4f}, truth minus best {rmse(v) - best:+.4f} -->")
            sys.stdout.flush()
    print("\n| terrain | draws | default minus best (mean) | near-origin minus best (mean) |")
    print("|---|---|---|---|")
    for n in names + ["all"]:
        g = [r for r in rows if n in ("all", r[0])]
        print(f"| {n} | {len(g)} | {np.mean([r[1] for r in g]):+.4f} | {np.mean([r[2] for r in g]):+.4f} |")


if __name__ == "__main__":
    main()
