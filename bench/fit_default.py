#!/usr/bin/env python3
"""The default automatic fit against the hidden truth and the best of PyKrige's automatic fits.

Run from the repository root after `cargo build --release -p terramesh-cli`, in the venv of
`bench/hidden_truth.py` (`.venv-hidden`):
    .venv-hidden/bin/python bench/fit_default.py [TERRAIN ...] [--seeds S1,...] [--fits F1,...]
        [--data N] [--sampling grid|random] [--truth N] [--time-only]

For each terrain and draw, the data and the truth are drawn as `hidden_truth.py` draws them
(`--sampling grid`, its jittered grid of about N data, default 1,200) or as N posts drawn
uniformly at random among the valid posts (`--sampling random`, a draw of our own: clusters
and gaps instead of an even spread). Each fit of `--fits` (default `default,wls,loo,reml`;
`default` runs `terramesh variogram` without `--fit`) is timed (`variogram --drift linear`,
wall seconds) and its model used by `interpolate --method uk --drift linear`; PyKrige's UK with
its own automatic fit of each of its five models is run once per draw and kept in a cache
beside the draws (`$TMPDIR/terramesh-fit-default`). Prints one row per draw, then the mean per
terrain and over all draws, with the best PyKrige fit and each fit's difference from it.
The means per terrain have two bars: the mean over draws of the best of PyKrige's five fits per
draw (an oracle that may pick a different model on each draw), and the best over PyKrige's five
models of the mean over draws of that model's RMSE (issue 33's wording: "the best of PyKrige's
automatic fits on the mean over draws"), with the model named.
TERRAIN is one of hidden_truth.py's four or `black-forest` (a 28 x 30 km crop of the same SRTM
tile east of the Rhine: the Black Forest's western edge and the plain).
`--time-only` skips PyKrige and the truth (timings and models only).
"""
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hidden_truth as ht  # noqa: E402

OUT = os.path.join(os.environ.get("TMPDIR", "/tmp"), "terramesh-fit-default")


def black_forest():
    """SRTM3 N48E007, rows 560-893, columns 700-1189: Black Forest edge and Rhine plain."""
    h = np.fromfile(os.path.join(ht.DATA, "srtm", "N48E007.hgt"), dtype=">i2").reshape(1201, 1201)
    r0, c0, nr, nc = 560, 700, 334, 490
    z = h[r0:r0 + nr, c0:c0 + nc].astype(float)
    lat = 49 - (r0 + np.arange(nr)) / 1200
    lon = 7 + (c0 + np.arange(nc)) / 1200
    return lon, lat, np.where(z == -32768, np.nan, z)


TERRAINS = dict(ht.TERRAINS, **{"black-forest": black_forest})


def random_split(lon, lat, z, rng, n_truth, n_data):
    x1, y1 = ht.local_metres(lon, lat)
    X, Y = np.meshgrid(x1, y1)
    ok = np.flatnonzero(np.isfinite(z).ravel())
    pick = np.zeros(z.size, bool)
    pick[rng.choice(ok, n_data, replace=False)] = True
    pick = pick.reshape(z.shape)
    d = np.column_stack([X[pick], Y[pick], z[pick]])
    rest = ~pick & np.isfinite(z)
    t = np.column_stack([X[rest], Y[rest], z[rest]])
    t = t[ht.Delaunay(d[:, :2]).find_simplex(t[:, :2]) >= 0]
    if len(t) > n_truth:
        t = t[np.sort(rng.choice(len(t), n_truth, replace=False))]
    return d, t


def take_opt(argv, name, default):
    """The value after `name` in `argv`, both removed from it; `default` when absent."""
    if name in argv:
        i = argv.index(name)
        v = argv[i + 1]
        del argv[i:i + 2]
        return v
    return default


def main():
    argv = sys.argv[1:]

    def opt(name, default):
        return take_opt(argv, name, default)

    seeds = [int(s) for s in opt("--seeds", "15").split(",")]
    fits = opt("--fits", "default,wls,loo,reml").split(",")
    n_data = int(opt("--data", "1200"))
    sampling = opt("--sampling", "grid")
    n_truth = int(opt("--truth", "20000"))
    time_only = "--time-only" in argv
    names = [a for a in argv if not a.startswith("--")] or list(ht.TERRAINS)
    os.makedirs(OUT, exist_ok=True)
    ht.N_DATA = n_data
    rows = []
    print(f"| terrain | seed | data | " + " | ".join(f"{f} RMSE m (fit s)" for f in fits)
          + " | best PyKrige auto fit | " + " | ".join(f"{f} minus best" for f in fits) + " |")
    print("|" + "---|" * (4 + 2 * len(fits)))
    for name, seed in ((n, s) for n in names for s in seeds):
        rng = np.random.default_rng(seed)
        if sampling == "grid":
            d, t = ht.split(*TERRAINS[name](), rng, n_truth)
        else:
            d, t = random_split(*TERRAINS[name](), rng, n_truth, n_data)
        tag = f"{name}-{sampling}-{n_data}-{seed}"
        dpath, tpath = os.path.join(OUT, f"{tag}-data.csv"), os.path.join(OUT, f"{tag}-targets.csv")
        np.savetxt(dpath, d, delimiter=",", header="x,y,z", comments="", fmt="%.10g")
        np.savetxt(tpath, t[:, :2], delimiter=",", header="x,y", comments="", fmt="%.10g")
        rmse = lambda e: float(np.sqrt(np.mean((e - t[:, 2]) ** 2)))
        res = {}
        for f in fits:
            vj = os.path.join(OUT, f"{tag}-{f}.json")
            flags = [] if f == "default" else ["--fit", f]
            t0 = time.perf_counter()
            ht.run(["variogram", "--data", dpath, "--drift", "linear", "-o", vj] + flags)
            dt = time.perf_counter() - t0
            model = ht.describe(json.load(open(vj))["model"])
            r = float("nan") if time_only else rmse(
                ht.terramesh_uk(dpath, tpath, os.path.join(OUT, f"{tag}-out.csv"), ["--variogram", vj]))
            res[f] = (r, dt, model)
        best, pyk = (float("nan"), ""), {}
        if not time_only:
            cache = os.path.join(OUT, f"{tag}-pykrige-{n_truth}.json")
            if os.path.exists(cache):
                pyk = json.load(open(cache))
            else:
                pyk = {m: rmse(ht.pykrige_uk(d, t, m)[0])
                       for m in ("spherical", "exponential", "gaussian", "power", "linear")}
                json.dump(pyk, open(cache, "w"))
            m = min(pyk, key=pyk.get)
            best = (pyk[m], m)
        rows.append((name, seed, res, best, pyk))
        print(f"| {name} | {seed} | {len(d)} | "
              + " | ".join(f"{res[f][0]:.3f} ({res[f][1]:.1f})" for f in fits)
              + f" | {best[0]:.3f} ({best[1]}) | "
              + " | ".join(f"{res[f][0] - best[0]:+.4f}" for f in fits) + " |")
        for f in fits:
            print(f"<!-- {name} {seed} {f}: {res[f][2]} -->")
        if pyk:
            print(f"<!-- {name} {seed} PyKrige: " + ", ".join(f"{mo} {v:.4f}" for mo, v in pyk.items()) + " -->")
        sys.stdout.flush()
    print("\n| terrain | draws | " + " | ".join(f"{f} mean RMSE (mean fit s)" for f in fits)
          + " | best PyKrige per draw, mean | " + " | ".join(f"{f} minus it (draws at least as good)" for f in fits)
          + " | best PyKrige model's mean (model) | " + " | ".join(f"{f} minus it" for f in fits) + " |")
    print("|" + "---|" * (4 + 3 * len(fits)))
    groups = {n: [r for r in rows if r[0] == n] for n in names}
    groups["all"] = rows
    for n, g in groups.items():
        b = np.mean([r[3][0] for r in g])
        if time_only:
            bm, bmod = float("nan"), ""
        else:
            means = {mo: np.mean([r[4][mo] for r in g]) for mo in g[0][4]}
            bmod = min(means, key=means.get)
            bm = means[bmod]
        cells, diffs, lits = [], [], []
        for f in fits:
            m = np.mean([r[2][f][0] for r in g])
            s = np.mean([r[2][f][1] for r in g])
            wins = sum(r[2][f][0] <= r[3][0] for r in g)
            cells.append(f"{m:.3f} ({s:.1f})")
            diffs.append(f"{m - b:+.4f} ({wins} of {len(g)})")
            lits.append(f"{m - bm:+.4f}")
        print(f"| {n} | {len(g)} | " + " | ".join(cells) + f" | {b:.3f} | " + " | ".join(diffs)
              + f" | {bm:.3f} ({bmod}) | " + " | ".join(lits) + " |")

if __name__ == "__main__":
    main()
