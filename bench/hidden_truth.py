#!/usr/bin/env python3
"""Hidden-truth check of the automatic variogram: sample a real DEM, keep the rest as truth.

Run from the repository root after `cargo build --release -p terramesh-cli`, in a venv of its
own (`bench/hidden_truth-requirements.txt`):
    python3 -m venv .venv-hidden && .venv-hidden/bin/pip install -r bench/hidden_truth-requirements.txt
    .venv-hidden/bin/python bench/hidden_truth.py [TERRAIN ...] [--truth N] [--skip-pykrige]
        [--seeds S1,S2,...] [--quick] [--loo]

`--seeds` draws the data and truth again with each seed (default 15, the seed of the tables in
docs/geostatistics.md) and ends with a summary per terrain: for each draw, terramesh UK auto
(`--fit reml` and `--fit wls`) against the best of PyKrige's auto fits, and their means over the
draws. `--quick` runs only the methods of that summary (no exact REML, no per-model REML, no IDW,
no griddata). `--loo` adds terramesh UK auto with `--fit loo` (its column is nan without it).

For each terrain (a DEM of ../shared/data, see TERRAINS below) the posts are put in local
metres (equirectangular about the DEM's centre: the same coordinates for every method), and
1,200 data are drawn on a jittered grid (one random post in each of about 1,200 equal cells,
seeded). The truth is the other valid posts inside the data's convex hull (a seeded random
N of them, default 20,000, so that every method predicts the same points). Methods:

- terramesh `interpolate --method uk --drift linear --variogram auto` with `--fit reml` (its
  block composite likelihood, the default `--reml-block`), `--fit reml --reml-block 0` (exact
  REML on all data), `--fit wls` (the former automatic fit) and, with `--loo`, `--fit loo`;
- terramesh UK with each model fitted alone by REML (`variogram --model M --fit reml`);
- terramesh IDW, 16 neighbours, power 2;
- PyKrige `UniversalKriging(..., drift_terms=["regional_linear"])` with its own automatic fit
  of each model (its defaults: 6 lags, no weights); its constructor's fit statistics (unused by
  `execute`, O(n^4)) are skipped, as in compare_kriging.py;
- scipy `griddata(..., method="cubic")` (Clough-Tocher).

Prints one markdown table of RMSE (metres) against the truth per terrain.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import rasterio
from scipy.interpolate import griddata
from scipy.spatial import Delaunay

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
BIN = os.path.join(TARGET, "release", "terramesh")
DATA = os.path.join(ROOT, "..", "shared", "data")
OUT = os.path.join(tempfile.gettempdir(), "terramesh-hidden-truth")
R = 6371008.8
N_DATA = 1200


def srtm_vosges():
    """SRTM3 N48E007, a 30 x 31 km crop of the northern Vosges and their edge (Saverne)."""
    h = np.fromfile(os.path.join(DATA, "srtm", "N48E007.hgt"), dtype=">i2").reshape(1201, 1201)
    r0, c0, nr, nc = 170, 160, 334, 490
    z = h[r0:r0 + nr, c0:c0 + nc].astype(float)
    lat = 49 - (r0 + np.arange(nr)) / 1200
    lon = 7 + (c0 + np.arange(nc)) / 1200
    return lon, lat, np.where(z == -32768, np.nan, z)


def fort_worth():
    """The Fort Worth 3-arc-second GeoTIFF, whole (about 34 x 33 km, gentle relief)."""
    with rasterio.open(os.path.join(DATA, "grids", "fort-worth-3arcsec.tif")) as ds:
        z = ds.read(1).astype(float)
        z[z == ds.nodata] = np.nan
        t = ds.transform
        lon = t.c + t.a * (np.arange(ds.width) + 0.5)
        lat = t.f + t.e * (np.arange(ds.height) + 0.5)
    return lon, lat, z


def colorado():
    """SRTMGL3 Colorado Front Range, whole (about 12 x 16 km, mountains)."""
    with rasterio.open(os.path.join(DATA, "grids", "colorado-front-range-srtmgl3.asc")) as ds:
        z = ds.read(1).astype(float)
        t = ds.transform
        lon = t.c + t.a * (np.arange(ds.width) + 0.5)
        lat = t.f + t.e * (np.arange(ds.height) + 0.5)
    return lon, lat, z  # NODATA 0: no such cell in this file


def grand_canyon():
    """Terrarium tile z=11 x=385 y=803, whole (about 16 x 16 km, canyon walls)."""
    with rasterio.open(os.path.join(DATA, "tiles", "terrarium_11_385_803.png")) as ds:
        rgb = ds.read().astype(float)
    z = rgb[0] * 256 + rgb[1] + rgb[2] / 256 - 32768
    n = 2 ** 11
    px = (385 + (np.arange(256) + 0.5) / 256) / n
    py = (803 + (np.arange(256) + 0.5) / 256) / n
    lon = px * 360 - 180
    lat = np.degrees(np.arctan(np.sinh(np.pi * (1 - 2 * py))))
    return lon, lat, z


TERRAINS = {"vosges": srtm_vosges, "fort-worth": fort_worth, "colorado": colorado,
            "grand-canyon": grand_canyon}


def local_metres(lon, lat):
    lon0, lat0 = np.mean(lon), np.mean(lat)
    x = R * np.cos(np.radians(lat0)) * np.radians(lon - lon0)
    y = R * np.radians(lat - lat0)
    return x, y


def split(lon, lat, z, rng, n_truth):
    x1, y1 = local_metres(lon, lat)
    X, Y = np.meshgrid(x1, y1)
    ny, nx = z.shape
    # about N_DATA cells of equal shape over the posts' index grid
    aspect = (nx * abs(x1[1] - x1[0])) / (ny * abs(y1[1] - y1[0]))
    cx = max(1, round(np.sqrt(N_DATA * aspect)))
    cy = max(1, round(N_DATA / cx))
    picked = np.zeros(z.shape, bool)
    for a in range(cy):
        for b in range(cx):
            r0, r1 = a * ny // cy, (a + 1) * ny // cy
            c0, c1 = b * nx // cx, (b + 1) * nx // cx
            for _ in range(20):  # a valid post in the cell
                r, c = rng.integers(r0, r1), rng.integers(c0, c1)
                if np.isfinite(z[r, c]):
                    picked[r, c] = True
                    break
    d = np.column_stack([X[picked], Y[picked], z[picked]])
    rest = ~picked & np.isfinite(z)
    t = np.column_stack([X[rest], Y[rest], z[rest]])
    t = t[Delaunay(d[:, :2]).find_simplex(t[:, :2]) >= 0]
    if len(t) > n_truth:
        t = t[np.sort(rng.choice(len(t), n_truth, replace=False))]
    return d, t


def run(args):
    p = subprocess.run([BIN] + args, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"terramesh {' '.join(args)}: {p.stderr.strip()}")
    return p


def predict_csv(path):
    return np.loadtxt(path, delimiter=",", skiprows=1)[:, 2]


def terramesh_uk(dpath, tpath, out, extra):
    run(["interpolate", "--data", dpath, "--targets", tpath, "--method", "uk", "--drift",
         "linear", "--no-variance", "-o", out] + extra)
    return predict_csv(out)


def pykrige_uk(d, t, model):
    import pykrige.uk
    pykrige.uk._find_statistics = lambda X, *a, **k: (np.zeros(len(X)), np.ones(len(X)),
                                                      np.zeros(len(X)))
    uk = pykrige.UniversalKriging(d[:, 0], d[:, 1], d[:, 2], variogram_model=model,
                                  drift_terms=["regional_linear"])
    est = np.empty(len(t))
    for s in range(0, len(t), 2000):  # bounds the vectorized backend's memory
        e, _ = uk.execute("points", t[s:s + 2000, 0], t[s:s + 2000, 1], backend="vectorized")
        est[s:s + 2000] = e
    return est, uk.variogram_model_parameters


def main():
    argv = sys.argv[1:]
    n_truth = 20000
    if "--truth" in argv:
        i = argv.index("--truth")
        n_truth = int(argv[i + 1])
        del argv[i:i + 2]
    seeds = [15]
    if "--seeds" in argv:
        i = argv.index("--seeds")
        seeds = [int(v) for v in argv[i + 1].split(",")]
        del argv[i:i + 2]
    skip_pyk = "--skip-pykrige" in argv
    quick = "--quick" in argv
    with_loo = "--loo" in argv
    names = [a for a in argv if not a.startswith("--")] or list(TERRAINS)
    os.makedirs(OUT, exist_ok=True)
    summary = {}
    for name, seed in ((n, s) for n in names for s in seeds):
        rng = np.random.default_rng(seed)
        d, t = split(*TERRAINS[name](), rng, n_truth)
        dpath, tpath = os.path.join(OUT, f"{name}-data.csv"), os.path.join(OUT, f"{name}-targets.csv")
        np.savetxt(dpath, d, delimiter=",", header="x,y,z", comments="", fmt="%.10g")
        np.savetxt(tpath, t[:, :2], delimiter=",", header="x,y", comments="", fmt="%.10g")
        ext = (d[:, 0].max() - d[:, 0].min()) / 1000, (d[:, 1].max() - d[:, 1].min()) / 1000
        rmse = lambda e: float(np.sqrt(np.mean((e - t[:, 2]) ** 2)))
        rows = []
        o = os.path.join(OUT, f"{name}-out.csv")
        autos = (("reml", ["--fit", "reml"]),
                 ("reml, exact", ["--fit", "reml", "--reml-block", "0"]),
                 ("wls", ["--fit", "wls"]),
                 ("loo", ["--fit", "loo"]))
        for label, flags in (a for a in autos
                             if not (quick and a[0] == "reml, exact") and (a[0] != "loo" or with_loo)):
            vj = os.path.join(OUT, f"{name}-auto-{label.replace(', ', '-')}.json")
            run(["variogram", "--data", dpath, "--drift", "linear", "-o", vj] + flags)
            m = json.load(open(vj))["model"]
            # the file's model: `interpolate --variogram auto` makes the same fit (deterministic)
            r = terramesh_uk(dpath, tpath, o, ["--variogram", vj])
            rows.append((f"terramesh UK auto ({label})", rmse(r), describe(m)))
        for model in () if quick else ("spherical", "exponential", "gaussian", "matern", "power",
                                       "linear"):
            vj = os.path.join(OUT, f"{name}-{model}.json")
            try:
                run(["variogram", "--data", dpath, "--model", model, "--fit", "reml", "--drift",
                     "linear", "-o", vj])
                r = terramesh_uk(dpath, tpath, o, ["--variogram", vj])
                rows.append((f"terramesh UK {model} (REML)", rmse(r),
                             describe(json.load(open(vj))["model"])))
            except RuntimeError as e:
                rows.append((f"terramesh UK {model} (REML)", float("nan"), str(e)[-80:]))
        if not quick:
            run(["interpolate", "--data", dpath, "--targets", tpath, "--method", "idw",
                 "--neighbors", "16", "--power", "2", "-o", o])
            rows.append(("terramesh IDW 16 neighbours", rmse(predict_csv(o)), ""))
        if not skip_pyk:
            for model in ("spherical", "exponential", "gaussian", "power", "linear"):
                e, par = pykrige_uk(d, t, model)
                rows.append((f"PyKrige UK {model} (its auto fit)", rmse(e),
                             ", ".join(f"{v:.4g}" for v in par)))
        if not quick:
            c = griddata(d[:, :2], d[:, 2], t[:, :2], method="cubic")
            ok = np.isfinite(c)
            rows.append(("scipy griddata cubic", rmse(np.where(ok, c, t[:, 2])),
                         f"{(~ok).sum()} targets outside"))
        summary.setdefault(name, []).append((seed, dict((r[0], r[1]) for r in rows)))
        print(f"\n### {name} (seed {seed}): {len(d)} data, {len(t)} truth posts, {ext[0]:.1f} x {ext[1]:.1f} km, "
              f"z {t[:, 2].min():.0f}-{t[:, 2].max():.0f} m\n")
        print("| method | RMSE m | model |\n|---|---|---|")
        for label, v, m in rows:
            print(f"| {label} | {v:.2f} | {m} |")
        sys.stdout.flush()
    if len(seeds) > 1 and not skip_pyk:
        print_summary(summary)


def print_summary(summary):
    """Per terrain and draw: terramesh UK auto (REML, WLS) against the best PyKrige auto fit."""
    print("\n### Summary over the draws (RMSE m)\n")
    print("| terrain | seed | terramesh UK auto (loo) | terramesh UK auto (reml) | terramesh UK auto (wls) "
          "| best PyKrige auto fit | loo minus best PyKrige | reml minus best PyKrige |\n"
          "|---|---|---|---|---|---|---|---|")
    for name, draws in summary.items():
        acc = []
        for seed, r in draws:
            pyk = {k: v for k, v in r.items() if k.startswith("PyKrige")}
            best = min(pyk, key=pyk.get)
            lo, a, w, b = (r.get("terramesh UK auto (loo)", float("nan")), r["terramesh UK auto (reml)"],
                           r["terramesh UK auto (wls)"], pyk[best])
            acc.append((lo, a, w, b))
            model = best.split()[2]
            print(f"| {name} | {seed} | {lo:.3f} | {a:.3f} | {w:.3f} | {b:.3f} ({model}) | {lo - b:+.3f} "
                  f"| {a - b:+.3f} |")
        lo, a, w, b = (float(np.mean(v)) for v in zip(*acc))
        wins = sum(x[0] <= x[3] for x in acc)
        rwins = sum(x[1] <= x[3] for x in acc)
        print(f"| {name} | mean of {len(acc)} | {lo:.3f} | {a:.3f} | {w:.3f} | {b:.3f} | {lo - b:+.3f} "
              f"(loo at least as good in {wins} of {len(acc)}) | {a - b:+.3f} "
              f"(reml at least as good in {rwins} of {len(acc)}) |")


def describe(m):
    s = f"nugget {m['nugget']:.4g}"
    for t in m["structures"]:
        s += f" + {t['type']} {t['psill']:.4g}, {t['range']:.4g} m"
        if t.get("shape"):
            s += f", shape {t['shape']:.3g}"
    return s


if __name__ == "__main__":
    main()
