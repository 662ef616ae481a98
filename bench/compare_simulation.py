#!/usr/bin/env python3
"""Conditional simulation, terramesh against GSTools' CondSRF on the same case; prints ratios.

Run from the repository root after `cargo build --release -p terramesh-cli`:
    python3 -m venv .venv-bench && .venv-bench/bin/pip install gstools==1.7.0 numpy==2.4.6 scipy==1.17.1
    .venv-bench/bin/python bench/compare_simulation.py [--data 5000] [--targets 20000] [--realisations 100] [--gstools-chunk 1000] [--skip-gstools]

Case (issue 15's dense geometry): 5,000 SRTM posts of ../shared/data/srtm/N48E007.hgt in a
31 x 32 km window (a local equirectangular projection to metres, seeded random subset),
20,000 targets uniform in the window, universal kriging with a linear drift, exponential
model psill 12000, practical range 6000 m (GSTools len_scale 2000), nugget 50; 100
realisations, 1000 spectral modes each (GSTools' default mode_no, terramesh's default).

GSTools: `CondSRF(Universal(model, cond_pos, cond_val, "linear"))` with its defaults
(pseudo-inverse kriging matrix, nugget as measurement error), `set_pos` on the targets, then
100 calls with seeds 0..99, the kriging done in chunks of `--gstools-chunk` targets
(GSTools' own `chunk_size` argument, passed through `CondSRF.__call__` to the kriging: the
same kriging, in pieces; without it GSTools builds the whole target x data matrix at once and
asked for about 80 GB on this case). Its time includes building the kriging matrix. GSTools
1.7's CondSRF computes the kriging mean and variance once (the first call) and then each
realisation as mean + (kriging std / model std) x an unconditional field at the targets;
terramesh conditions every realisation by kriging its residuals at the data (docs/
geostatistics.md, "Conditional simulation"), so its realisations also have the conditional
covariance between targets. terramesh: the whole `terramesh simulate` run (reading the CSVs,
simulating, writing the 20,000 x 105 CSV).
Both wall-clock and CPU seconds (user + system, all threads) are printed with the load
average before each side: on a shared machine the CPU time is the fairer measure.
"""
import argparse
import os
import resource
import subprocess
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
BIN = os.path.join(TARGET, "release", "terramesh")
TMP = os.path.join(tempfile.gettempdir(), "terramesh-bench-sim")
os.makedirs(TMP, exist_ok=True)


def case(n, m, rng):
    h = np.fromfile(os.path.join(ROOT, "..", "shared", "data", "srtm", "N48E007.hgt"),
                    dtype=">i2").reshape(1201, 1201)
    # A 31 x 32 km window: about 0.42 deg of longitude and 0.29 deg of latitude at 48.5 N.
    r0, c0 = 300, 300
    rows, cols = int(0.29 * 1200), int(0.42 * 1200)
    r, c = np.meshgrid(np.arange(r0, r0 + rows), np.arange(c0, c0 + cols), indexing="ij")
    r, c = r.ravel(), c.ravel()
    keep = h[r, c] > -32768
    r, c = r[keep], c[keep]
    pick = rng.choice(len(r), n, replace=False)
    lat, lon = 49 - r[pick] / 1200, 7 + c[pick] / 1200
    lat0 = np.deg2rad(49 - (r0 + rows / 2) / 1200)
    x = 6371008.8 * np.cos(lat0) * np.deg2rad(lon - 7)
    y = 6371008.8 * np.deg2rad(lat - 48)
    z = h[r[pick], c[pick]].astype(float)
    tx = rng.uniform(x.min(), x.max(), m)
    ty = rng.uniform(y.min(), y.max(), m)
    return x, y, z, tx, ty


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", type=int, default=5000)
    ap.add_argument("--targets", type=int, default=20000)
    ap.add_argument("--realisations", type=int, default=100)
    ap.add_argument("--gstools-chunk", type=int, default=1000,
                    help="targets per kriging chunk on the GSTools side")
    ap.add_argument("--skip-gstools", action="store_true")
    a = ap.parse_args()
    rng = np.random.default_rng(15)
    x, y, z, tx, ty = case(a.data, a.targets, rng)
    dpath, tpath = os.path.join(TMP, "data.csv"), os.path.join(TMP, "targets.csv")
    np.savetxt(dpath, np.c_[x, y, z], delimiter=",", header="x,y,z", comments="", fmt="%.17g")
    np.savetxt(tpath, np.c_[tx, ty], delimiter=",", header="x,y", comments="", fmt="%.17g")
    print(f"case: {a.data} data, {a.targets} targets, {a.realisations} realisations, "
          f"extent {np.ptp(x) / 1e3:.1f} x {np.ptp(y) / 1e3:.1f} km")

    out = os.path.join(TMP, "sim.csv")
    cmd = [BIN, "simulate", "--data", dpath, "--targets", tpath, "--realisations",
           str(a.realisations), "--seed", "1", "--method", "uk", "--drift", "linear",
           "--model", "exponential", "--psill", "12000", "--range", "6000", "--nugget", "50",
           "-o", out]
    print(f"load average before terramesh: {os.getloadavg()[0]:.2f}")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    tm_wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    tm_cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    sim = np.loadtxt(out, delimiter=",", skiprows=1)
    tm_std = sim[:, -4].mean()
    print(f"terramesh: wall {tm_wall:.2f} s, cpu {tm_cpu:.2f} s, mean std {tm_std:.2f} m, "
          f"peak RSS {after.ru_maxrss / 1024:.0f} MB")

    if a.skip_gstools:
        return
    import gstools as gs
    print(f"load average before GSTools: {os.getloadavg()[0]:.2f}")
    model = gs.Exponential(dim=2, var=12000.0, len_scale=2000.0, nugget=50.0)
    c0, t0 = time.process_time(), time.perf_counter()
    krige = gs.krige.Universal(model, (x, y), z, "linear")
    srf = gs.CondSRF(krige)
    srf.set_pos((tx, ty), "unstructured")
    fields = np.empty((a.realisations, a.targets))
    for i in range(a.realisations):
        fields[i] = srf(seed=i, chunk_size=a.gstools_chunk)
    gs_wall, gs_cpu = time.perf_counter() - t0, time.process_time() - c0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"GSTools {gs.__version__} CondSRF (kriging chunks of {a.gstools_chunk} targets): "
          f"wall {gs_wall:.2f} s, cpu {gs_cpu:.2f} s, "
          f"mean std {fields.std(axis=0, ddof=1).mean():.2f} m, peak RSS {rss:.0f} MB")
    print(f"ratio terramesh / GSTools: wall {tm_wall / gs_wall:.3f}x, cpu {tm_cpu / gs_cpu:.3f}x")

if __name__ == "__main__":
    main()
