#!/usr/bin/env python3
"""The rule "unseen range" of the default fit (issue 33 goal 3) simulated outside terramesh, at
fixed fractions of the diameter: where the committed default's model is an exponential or
spherical without nugget whose range sits at the data's diameter (`wls_loo_range_bound`), an
exponential without nugget at F times the diameter instead (the rule without the leave-one-out
guard of the Rust version tried in e7394c1 and reverted). Not adopted: docs/geostatistics.md,
"Unseen range", has the figures and why.

Run from the repository root after `cargo build --release -p terramesh-cli`, in `.venv-hidden`:
    .venv-hidden/bin/python bench/fit_default_unseen.py [TERRAIN ...] [--seeds S1,...]
        [--fractions F1,...] [--known-best]

For each draw of `bench/fit_default.py` (the same data, truth and PyKrige cache; PyKrige's five
automatic fits are run where the cache lacks them): the default fit's hidden-truth RMSE
(`terramesh variogram --drift linear`, then `interpolate --method uk --drift linear`) and, where
the rule applies, that of the exponential at each fraction (universal kriging with a linear drift
over all the data, computed here in numpy: the same system as terramesh's). Prints one row per
draw (each minus the best PyKrige fit), then the terrain means. `--known-best`: for seeds 15-22,
PyKrige's best per draw from `fit_default_near.KNOWN`. The rule applies to the default of the
binary it runs (`CARGO_TARGET_DIR`, as `hidden_truth.py`): to reproduce the study, a binary of
3ddd1c0 (before the rule), whose default leaves the range at the bound.
"""
import json
import os
import sys

import numpy as np
from scipy.spatial.distance import cdist, pdist

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_default as fd  # noqa: E402
import fit_default_near as fn  # noqa: E402
import hidden_truth as ht  # noqa: E402


def uk_exponential(d, t, a):
    """Universal kriging (linear drift, all data) with an exponential of range `a`, no nugget."""
    x = d[:, :2]
    c, s = x.mean(0), np.ptp(x, 0).max()
    n = len(d)
    a_ = np.zeros((n + 3, n + 3))
    a_[:n, :n] = -(1 - np.exp(-3 * cdist(x, x) / a))
    f = np.column_stack([np.ones(n), (x - c) / s])
    a_[:n, n:], a_[n:, :n] = f, f.T
    w = np.linalg.solve(a_, np.concatenate([d[:, 2], np.zeros(3)]))
    out = np.empty(len(t))
    for i in range(0, len(t), 4000):
        tt = t[i:i + 4000, :2]
        g0 = 1 - np.exp(-3 * cdist(tt, x) / a)
        out[i:i + 4000] = -g0 @ w[:n] + np.column_stack([np.ones(len(tt)), (tt - c) / s]) @ w[n:]
    return out


def default_against_best(name, seed, known, label):
    """One draw: its data and truth, the best PyKrige RMSE (the docs' figure with `known`,
    else the five fits, cached), the default fit's model, its RMSE minus that best, the
    data's diameter, and whether the model is a lone exponential or spherical without nugget
    at the range bound (the diameter). `label` names the scratch files."""
    d, t, tag, dp, tp = fn.draw(name, seed)
    cache = os.path.join(fd.OUT, f"{tag}-pykrige-20000.json")
    if known and seed in fn.KNOWN and name in fn.KNOWN_NAMES:
        best = fn.KNOWN[seed][fn.KNOWN_NAMES.index(name)]
    else:
        if not os.path.exists(cache):
            json.dump({m: float(np.sqrt(np.mean((ht.pykrige_uk(d, t, m)[0] - t[:, 2]) ** 2)))
                       for m in ("spherical", "exponential", "gaussian", "power", "linear")},
                      open(cache, "w"))
        best = min(json.load(open(cache)).values())
    vj = os.path.join(fd.OUT, f"{tag}-{label}-default.json")
    ht.run(["variogram", "--data", dp, "--drift", "linear", "-o", vj])
    model = json.load(open(vj))["model"]
    e = ht.terramesh_uk(dp, tp, os.path.join(fd.OUT, f"{tag}-{label}-out.csv"), ["--variogram", vj])
    r0 = float(np.sqrt(np.mean((e - t[:, 2]) ** 2))) - best
    diam = float(pdist(d[:, :2]).max())
    st = model["structures"]
    at_bound = (model["nugget"] == 0 and len(st) == 1
                and st[0]["type"] in ("exponential", "spherical") and st[0]["range"] >= 0.999 * diam)
    return d, t, best, model, r0, diam, at_bound


def main():
    argv = sys.argv[1:]
    seeds = [int(s) for s in fd.take_opt(argv, "--seeds", "15").split(",")]
    fr = [float(f) for f in fd.take_opt(argv, "--fractions", "0.2,0.25,0.3").split(",")]
    known = "--known-best" in argv
    names = [a for a in argv if not a.startswith("--")] or list(fd.TERRAINS)
    os.makedirs(fd.OUT, exist_ok=True)
    rows = []
    print("| terrain | seed | best PyKrige | default minus best | "
          + " | ".join(f"F = {f} minus best" for f in fr) + " | default model |")
    print("|" + "---|" * (5 + len(fr)))
    for seed in seeds:
        for name in names:
            d, t, best, model, r0, diam, at_bound = default_against_best(name, seed, known, "unseen")
            rmse = lambda e: float(np.sqrt(np.mean((e - t[:, 2]) ** 2)))
            rr = [rmse(uk_exponential(d, t, f * diam)) - best if at_bound else r0 for f in fr]
            rows.append((name, r0, rr))
            print(f"| {name} | {seed} | {best:.3f} | {r0:+.4f} | " + " | ".join(f"{v:+.4f}" for v in rr)
                  + f" | {ht.describe(model)} |")
            sys.stdout.flush()
    print("\n| terrain | draws | default minus best | " + " | ".join(f"F = {f} minus best" for f in fr) + " |")
    print("|" + "---|" * (3 + len(fr)))
    for n in names + ["all"]:
        g = [r for r in rows if n in ("all", r[0])]
        print(f"| {n} | {len(g)} | {np.mean([r[1] for r in g]):+.4f} | "
              + " | ".join(f"{np.mean([r[2][i] for r in g]):+.4f}" for i in range(len(fr))) + " |")


if __name__ == "__main__":
    main()
