#!/usr/bin/env python3
"""A rule tried for the default fit (issue 33 goal 3), simulated outside terramesh: the range of
a chosen exponential or spherical without nugget at the diameter bound (`wls_loo_range_bound`)
chosen by cross-validation at two spacings, extrapolated to the targets' distance. Not adopted
unless docs/geostatistics.md ("Thinned cross-validation") says so; it has the figures.

Run from the repository root after `cargo build --release -p terramesh-cli`, in `.venv-hidden`:
    .venv-hidden/bin/python bench/fit_default_thin.py [TERRAIN ...] [--seeds S1,...]
        [--fractions F1,...] [--known-best]

For each draw of `bench/fit_default.py` (the same data, truth and PyKrige cache), where the
committed default's model is an exponential or spherical without nugget whose range is at the
data's diameter, the candidates are that model and the exponential without nugget at each
fraction F of the diameter (default 0.2,0.3,0.45,0.6,0.75). For each candidate (universal
kriging with a linear drift over the given data, numpy, the same system as terramesh's):
  e1 = the leave-one-out mean squared error on all the data (closed form), at r1 = the mean
       distance from each datum to its nearest other datum;
  e2 = the mean squared error of predicting the other data from a thinned subset (one datum per
       cell of a square grid of twice the mean spacing sqrt(area / n), the one nearest the cell's
       centre), at r2 = the mean distance from those data to their nearest datum of the subset;
  the error at the targets' distance rT (mean distance from the hidden-truth posts to their
  nearest datum) extrapolated on log-log axes: log e = log e1 + log(e2 / e1) log(rT / r1) /
  log(r2 / r1).
The rule keeps the candidate whose extrapolated error is least ("thin"); "loo" (least e1) and
"sub" (least e2) are printed for comparison. Each figure: the chosen model's hidden-truth RMSE
minus the best of PyKrige's five automatic fits on that draw. `--known-best`: PyKrige's best per
draw for seeds 15-22 from `fit_default_near.KNOWN`.
"""
import json
import os
import sys

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist, pdist

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_default as fd  # noqa: E402
import fit_default_near as fn  # noqa: E402
import fit_default_unseen as fu  # noqa: E402
import hidden_truth as ht  # noqa: E402


def gamma(kind, a, h):
    """Unit-sill semivariance of an exponential or spherical of range a, no nugget."""
    if kind == "exponential":
        return 1 - np.exp(-3 * h / a)
    return np.where(h < a, 1.5 * h / a - 0.5 * (h / a) ** 3, 1.0)


def system(x, kind, a, c, s):
    n = len(x)
    m = np.zeros((n + 3, n + 3))
    m[:n, :n] = -gamma(kind, a, cdist(x, x))
    f = np.column_stack([np.ones(n), (x - c) / s])
    m[:n, n:], m[n:, :n] = f, f.T
    return m


def loo_mse(d, kind, a):
    x, z = d[:, :2], d[:, 2]
    c, s = x.mean(0), np.ptp(x, 0).max()
    n = len(d)
    inv = np.linalg.inv(system(x, kind, a, c, s))
    w = inv[:, :n] @ z
    e = w[:n] / np.diag(inv)[:n]
    return float(np.mean(e ** 2))


def predict(d, q, kind, a):
    x, z = d[:, :2], d[:, 2]
    c, s = x.mean(0), np.ptp(x, 0).max()
    n = len(d)
    w = np.linalg.solve(system(x, kind, a, c, s), np.concatenate([z, np.zeros(3)]))
    g0 = gamma(kind, a, cdist(q, x))
    return -g0 @ w[:n] + np.column_stack([np.ones(len(q)), (q - c) / s]) @ w[n:]


def thinned(d):
    """Indices of one datum per cell of twice the mean spacing (nearest the cell's centre)."""
    x = d[:, :2]
    lo = x.min(0)
    sp = 2 * np.sqrt(np.prod(np.ptp(x, 0)) / len(d))
    cell = np.floor((x - lo) / sp).astype(int)
    dist = np.hypot(*((x - lo) - (cell + 0.5) * sp).T)
    keep = {}
    for i in np.argsort(dist):
        keep.setdefault((cell[i, 0], cell[i, 1]), i)
    return np.array(sorted(keep.values()))


def main():
    argv = sys.argv[1:]
    seeds = [int(s) for s in fd.take_opt(argv, "--seeds", "15").split(",")]
    fr = [float(f) for f in fd.take_opt(argv, "--fractions", "0.2,0.3,0.45,0.6,0.75").split(",")]
    known = "--known-best" in argv
    names = [a for a in argv if not a.startswith("--")] or list(fd.TERRAINS)
    rows = []
    print("| terrain | seed | best PyKrige | default minus best | thin minus best | loo minus best | sub minus best | thin's range / diameter |")
    print("|---|---|---|---|---|---|---|---|")
    for seed in seeds:
        for name in names:
            d, t, best, model, r0, diam, at_bound = fu.default_against_best(name, seed, known, "thin")
            rmse = lambda e: float(np.sqrt(np.mean((e - t[:, 2]) ** 2)))
            if not at_bound:
                rows.append((name, r0, r0, r0, r0))
                print(f"| {name} | {seed} | {best:.3f} | {r0:+.4f} | {r0:+.4f} | {r0:+.4f} | {r0:+.4f} | not at the bound |")
                continue
            x = d[:, :2]
            r1 = float(np.mean(cKDTree(x).query(x, 2)[0][:, 1]))
            sub = thinned(d)
            rest = np.setdiff1d(np.arange(len(d)), sub)
            r2 = float(np.mean(cKDTree(x[sub]).query(x[rest])[0]))
            rt = float(np.mean(cKDTree(x).query(t[:, :2])[0]))
            st = model["structures"]
            cands = [(st[0]["type"], st[0]["range"], None)] + [("exponential", f * diam, f) for f in fr]
            crit = []
            for kind, a, f in cands:
                e1 = loo_mse(d, kind, a)
                e2 = float(np.mean((predict(d[sub], x[rest], kind, a) - d[rest, 2]) ** 2))
                ex = np.exp(np.log(e1) + np.log(e2 / e1) * np.log(rt / r1) / np.log(r2 / r1))
                crit.append((ex, e1, e2))
            truth = [r0] + [rmse(fu.uk_exponential(d, t, f * diam)) - best for f in fr]
            pick = [int(np.argmin([c[k] for c in crit])) for k in range(3)]
            label = lambda i: "bound" if i == 0 else f"{fr[i - 1]}"
            rows.append((name, r0, truth[pick[0]], truth[pick[1]], truth[pick[2]]))
            print(f"| {name} | {seed} | {best:.3f} | {r0:+.4f} | {truth[pick[0]]:+.4f} | {truth[pick[1]]:+.4f} | "
                  f"{truth[pick[2]]:+.4f} | {label(pick[0])} |")
            print(f"<!-- {name} {seed} r1 {r1:.0f} r2 {r2:.0f} rT {rt:.0f} m; per candidate (range/diameter: "
                  "extrapolated MSE, e1, e2, truth minus best): "
                  + "; ".join(f"{label(i)}: {c[0]:.2f}, {c[1]:.2f}, {c[2]:.2f}, {truth[i]:+.4f}"
                              for i, c in enumerate(crit)) + " -->")
            sys.stdout.flush()
    print("\n| terrain | draws | default minus best | thin minus best | loo minus best | sub minus best |")
    print("|---|---|---|---|---|---|")
    for n in names + ["all"]:
        g = [r for r in rows if n in ("all", r[0])]
        print(f"| {n} | {len(g)} | " + " | ".join(f"{np.mean([r[k] for r in g]):+.4f}" for k in range(1, 5)) + " |")


if __name__ == "__main__":
    main()
