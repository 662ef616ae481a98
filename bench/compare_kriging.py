#!/usr/bin/env python3
"""Side-by-side timings of terramesh and PyKrige on the same machine; prints ratios.

Run from the repository root after `cargo build --release -p terramesh-cli`:
    .venv-bench/bin/python bench/compare_kriging.py [--skip-pykrige] [--big] [--check] [--only=TEXT]

`--check` compares terramesh's estimates and variances with PyKrige's (largest differences, on
stderr); `--only=TEXT` runs only the cases whose label contains TEXT (e.g. `--only=dense`).
Two geometries: the whole tile (5,000 posts over about 73 x 111 km, about 70 data within the
6 km range of a target) and a dense 31 x 32 km square (5,000 posts, about 490 within range).

Data: posts of the SRTM tile ../shared/data/srtm/N48E007.hgt projected to UTM 32N with pyproj
(seeded random subsets), targets uniform in the data's box. Written to $TMPDIR/terramesh-bench.
PyKrige: UniversalKriging(..., drift_terms=["regional_linear"]) with explicit variogram
parameters (no fitting) and its fit statistics (unused by execute, O(n^4)) stubbed out; its
time is that of `execute("points", ...,
backend="vectorized")` alone, measured in a child process whose peak RSS is also reported.
terramesh: the whole CLI run (reading CSV, solving, writing CSV), wall time and peak RSS from
`/usr/bin/time`-style rusage of the child.
"""
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
import pyproj

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# cargo's output folder: $CARGO_TARGET_DIR when set, as cargo itself does
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
BIN = os.path.join(TARGET, "release", "terramesh")
TMP = os.path.join(tempfile.gettempdir(), "terramesh-bench")
os.makedirs(TMP, exist_ok=True)
rng = np.random.default_rng(7)


def posts():
    h = np.fromfile(os.path.join(ROOT, "..", "shared", "data", "srtm", "N48E007.hgt"),
                    dtype=">i2").reshape(1201, 1201)
    r, c = np.nonzero(h > -32768)
    lat, lon = 49 - r / 1200, 7 + c / 1200
    x, y = pyproj.Transformer.from_crs(4326, 32632, always_xy=True).transform(lon, lat)
    return np.asarray(x), np.asarray(y), h[r, c].astype(float)


def write(name, cols, header):
    p = os.path.join(TMP, name)
    if not os.path.exists(p):
        np.savetxt(p, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.17g")
    return p


def run_child(cmd):
    t0 = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    return wall, p


def terramesh(args):
    # peak RSS of this child alone: run under /usr/bin/env python wrapper measuring rusage
    code = ("import resource,subprocess,sys,time;t=time.perf_counter();"
            "r=subprocess.run(sys.argv[1:]);w=time.perf_counter()-t;"
            "u=resource.getrusage(resource.RUSAGE_CHILDREN);"
            "print(w, u.ru_maxrss, u.ru_utime + u.ru_stime);sys.exit(r.returncode)")
    p = subprocess.run([sys.executable, "-c", code, BIN] + args, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"terramesh failed: {args}\n{p.stderr}")
    wall, kb, cpu = p.stdout.split()
    return float(wall), int(kb) / 1024, float(cpu)


PYK = r"""
import sys, time, resource, numpy as np, pykrige
d = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1); t = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1)
model = sys.argv[3]; psill, rng_, nug = 12000.0, 6000.0, 50.0
# terramesh's range is the practical range (GSLIB): for the Gaussian, 1 - exp(-3 h^2 / a^2).
# PyKrige's Gaussian is 1 - exp(-h^2 / (4 r / 7)^2), so the same model has r = a * 7 / (4 sqrt 3).
if model == "gaussian":
    rng_ = rng_ * 7.0 / (4.0 * np.sqrt(3.0))
# The constructor's fit statistics (an O(n^4) loop of growing solves, about an hour at 5,000
# points) are not used by execute(): skip them.
import pykrige.uk
pykrige.uk._find_statistics = lambda X, *a, **k: (np.zeros(len(X)), np.ones(len(X)), np.zeros(len(X)))
uk = pykrige.UniversalKriging(d[:, 0], d[:, 1], d[:, 2], variogram_model=model,
        variogram_parameters={"psill": psill, "range": rng_, "nugget": nug}, drift_terms=["regional_linear"])
u0 = resource.getrusage(resource.RUSAGE_SELF); t0 = time.perf_counter()
z, s = uk.execute("points", t[:, 0], t[:, 1], backend="vectorized")
u1 = resource.getrusage(resource.RUSAGE_SELF)
print(time.perf_counter() - t0, u1.ru_maxrss / 1024, u1.ru_utime + u1.ru_stime - u0.ru_utime - u0.ru_stime)
if len(sys.argv) > 4:
    np.save(sys.argv[4], np.column_stack((np.ma.getdata(z), np.ma.getdata(s))))
"""


def pykrige(data, targets, model, check=None):
    """PyKrige's execute time, peak MB and CPU time; with `check` (terramesh's output CSV),
    also prints the largest differences of the estimates and variances from PyKrige's."""
    saved = os.path.join(TMP, "pykrige.npy")
    cmd = [sys.executable, "-c", PYK, data, targets, model] + ([saved] if check else [])
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, (p.stderr.strip().splitlines()[-1] if p.stderr else "failed"), None
    t, mb, cpu = p.stdout.split()
    if check:
        ref = np.load(saved)
        with open(check) as f:
            names = f.readline().strip().split(",")
        got = np.loadtxt(check, delimiter=",", skiprows=1)
        est, var = got[:, names.index("z")], got[:, names.index("variance")]
        print(f"  check {model}: max |dz| {np.abs(est - ref[:, 0]).max():.2e}, "
              f"max |dvar| {np.abs(var - ref[:, 1]).max():.2e} (PyKrige's variance up to "
              f"{ref[:, 1].max():.0f})", file=sys.stderr, flush=True)
    return float(t), float(mb), float(cpu)


def main():
    skip = "--skip-pykrige" in sys.argv
    x, y, z = posts()
    i = rng.choice(len(x), 5000, replace=False)
    data = write("data5000.csv", (x[i], y[i], z[i]), "x,y,z")
    box = (x.min(), x.max(), y.min(), y.max())
    for m in (20000, 100000):
        write(f"targets{m}.csv", (rng.uniform(box[0], box[1], m), rng.uniform(box[2], box[3], m)), "x,y")
    t20, t100 = os.path.join(TMP, "targets20000.csv"), os.path.join(TMP, "targets100000.csv")
    # The dense geometry: 5,000 posts of a 31 x 32 km square (about 490 data within the 6 km
    # range of a target, against about 70 in the whole tile), 20,000 targets in that square.
    sq = (x0 := x.min() + 20000.0, x0 + 31000.0, y0 := y.min() + 40000.0, y0 + 32000.0)
    inside = np.nonzero((x >= sq[0]) & (x <= sq[1]) & (y >= sq[2]) & (y <= sq[3]))[0]
    k = rng.choice(inside, 5000, replace=False)
    dense = write("dense5000.csv", (x[k], y[k], z[k]), "x,y,z")
    td = write("dense_targets20000.csv", (rng.uniform(sq[0], sq[1], 20000),
                                          rng.uniform(sq[2], sq[3], 20000)), "x,y")
    common = ["--psill", "12000", "--range", "6000", "--nugget", "50"]
    last_pyk = {}
    print("| case | terramesh wall s | terramesh CPU s | terramesh peak MB | PyKrige execute wall s "
          "| PyKrige CPU s | PyKrige peak MB | ratio wall | ratio CPU |")
    print("|---|---|---|---|---|---|---|---|---|")
    only = [a.split("=", 1)[1] for a in sys.argv if a.startswith("--only=")]
    for label, model, dt, tg, extra in [
        ("UK linear, spherical, 5k data, 20k targets, variances", "spherical", data, t20, []),
        ("UK linear, exponential, 5k data, 20k targets, variances", "exponential", data, t20, []),
        ("UK linear, gaussian, 5k data, 20k targets, variances", "gaussian", data, t20, []),
        ("UK linear, spherical, 5k data, 20k targets, --no-variance", "spherical", data, t20, ["--no-variance"]),
        ("UK linear, spherical, 5k data, 100k targets, variances", "spherical", data, t100, []),
        ("dense square: UK linear, spherical, 5k data, 20k targets, variances", "spherical", dense, td, []),
        ("dense square: UK linear, exponential, 5k data, 20k targets, variances", "exponential", dense, td, []),
        ("dense square: UK linear, gaussian, 5k data, 20k targets, variances", "gaussian", dense, td, []),
    ]:
        if only and not any(o in label for o in only):
            continue
        out = os.path.join(TMP, "out.csv")
        tm, mb, tc = terramesh(["interpolate", "--data", dt, "--targets", tg, "--method", "uk",
                                "--model", model] + common + extra + ["-o", out])
        if skip or tg == t100:
            pt, pmb, pc = (None, "not run (needs > 24 GB at 100k targets)" if tg == t100 else "skipped", None)
        elif extra:
            pt, pmb, pc = last_pyk.get((dt, model), (None, "-", None))
        else:
            pt, pmb, pc = pykrige(dt, tg, model, out if "--check" in sys.argv else None)
            last_pyk[(dt, model)] = (pt, pmb, pc)
        rw = f"{tm / pt:.3f}" if pt else "-"
        rc = f"{tc / pc:.3f}" if pc else "-"
        f = lambda v: "-" if v is None else (v if isinstance(v, str) else f"{v:.2f}")
        print(f"| {label} | {tm:.2f} | {tc:.2f} | {mb:.0f} | {f(pt)} | {f(pc)} | "
              f"{pmb if isinstance(pmb, str) else round(pmb)} | {rw} | {rc} |", flush=True)
    if "--big" in sys.argv:
        j = rng.choice(len(x), 1000000, replace=False)
        big = write("data1m.csv", (x[j], y[j], z[j]), "x,y,z")
        bt = write("targets1m.csv", (rng.uniform(box[0], box[1], 1000000),
                                     rng.uniform(box[2], box[3], 1000000)), "x,y")
        out = os.path.join(TMP, "out.csv")
        tm, mb, tc = terramesh(["interpolate", "--data", big, "--targets", bt, "--method", "ok",
                                "--model", "spherical"] + common + ["--neighbors", "32", "-o", out])
        print(f"| OK, 32 neighbours, 1M data, 1M targets (CLI, with CSV I/O) | {tm:.2f} | {tc:.2f} | {mb:.0f} | - | - | - | - | - |")
        tm, mb, tc = terramesh(["interpolate", "--data", big, "--targets", bt, "--method", "idw",
                                "--power", "2", "--neighbors", "16", "-o", out])
        print(f"| IDW, 16 neighbours, 1M data, 1M targets (CLI, with CSV I/O) | {tm:.2f} | {tc:.2f} | {mb:.0f} | - | - | - | - | - |")


if __name__ == "__main__":
    main()
