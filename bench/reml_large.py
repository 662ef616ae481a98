#!/usr/bin/env python3
"""The automatic REML fit above MAX_REML_BLOCKS: its cost and the accuracy of what it fits.

Run from the repository root after `cargo build --release -p terramesh-cli`, in the venv of
hidden_truth.py (`bench/hidden_truth-requirements.txt`):
    .venv-hidden/bin/python bench/reml_large.py [--n N] [--compare OTHER_BINARY]

Draws N distinct valid posts (default 100,000, seed 3) of ../shared/data/srtm/N48E007.hgt
spread over the whole tile, in local metres (equirectangular about 48.5 N, 7.5 E), and 20,000
other posts as the truth. Times `terramesh variogram --data D --fit reml --drift linear` with
`/usr/bin/time` for target/release/terramesh and, with --compare, for another binary (e.g. one
built before the block cap), then krigs the truth posts with each fitted variogram through
target/release/terramesh (`interpolate --method uk --drift linear --neighbors 64
--no-variance`) and prints one markdown row per binary: wall and CPU seconds, peak memory,
blocks and data in the likelihood, the model, the RMSE at the truth posts, and the load.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
BIN = os.path.join(TARGET, "release", "terramesh")
TILE = os.path.join(ROOT, "..", "shared", "data", "srtm", "N48E007.hgt")
OUT = os.path.join(tempfile.gettempdir(), "terramesh-reml-large")
R = 6371008.8


def posts(n, n_truth, seed):
    z = np.fromfile(TILE, ">i2").reshape(1201, 1201).astype(float)
    valid = np.flatnonzero(z.ravel() > -1000)
    pick = np.random.default_rng(seed).choice(valid, n + n_truth, replace=False)
    r, c = pick // 1201, pick % 1201
    lat, lon = 49 - r / 1200.0, 7 + c / 1200.0
    x = R * np.cos(np.radians(48.5)) * np.radians(lon - 7.5)
    y = R * np.radians(lat - 48.5)
    p = np.column_stack([x, y, z[r, c]])
    return p[:n], p[n:]


def timed(binary, args):
    tf = os.path.join(OUT, "time.txt")
    p = subprocess.run(["/usr/bin/time", "-f", "%e %U %M", "-o", tf, binary] + args,
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{binary} {' '.join(args)}: {p.stderr.strip()[-2000:]}")
    wall, user, kb = open(tf).read().split()[-3:]
    return float(wall), float(user), int(kb)


def describe(m):
    parts = [f"nugget {m['nugget']:.4g}"]
    for s in m["structures"]:
        t = s["type"] + (f" ν {s['shape']:g}" if s["type"] == "matern" else "")
        parts.append(f"{t} ({s['psill']:.4g}, {s['range']:.4g} m)")
    return " + ".join(parts)


def main():
    argv = sys.argv[1:]
    n, other = 100_000, None
    if "--n" in argv:
        n = int(argv[argv.index("--n") + 1])
    if "--compare" in argv:
        other = argv[argv.index("--compare") + 1]
    os.makedirs(OUT, exist_ok=True)
    d, t = posts(n, 20_000, 3)
    dp, tp = os.path.join(OUT, "data.csv"), os.path.join(OUT, "targets.csv")
    np.savetxt(dp, d, delimiter=",", header="x,y,z", comments="", fmt="%.10g")
    np.savetxt(tp, t[:, :2], delimiter=",", header="x,y", comments="", fmt="%.10g")
    print("| binary | `variogram --fit reml` wall / CPU, peak | blocks, data in the likelihood "
          "| model | RMSE at 20,000 held-out posts | load before-after |")
    print("|---|---|---|---|---|---|")
    for k, b in enumerate([BIN] + ([other] if other else [])):
        vj = os.path.join(OUT, f"variogram-{k}.json")
        l0 = os.getloadavg()[0]
        wall, user, kb = timed(b, ["variogram", "--data", dp, "--fit", "reml", "--drift",
                                   "linear", "-o", vj])
        l1 = os.getloadavg()[0]
        v = json.load(open(vj))
        pp = os.path.join(OUT, f"pred-{k}.csv")
        subprocess.run([BIN, "interpolate", "--data", dp, "--targets", tp, "--method", "uk",
                        "--drift", "linear", "--neighbors", "64", "--no-variance",
                        "--variogram", vj, "-o", pp], check=True, capture_output=True)
        est = np.loadtxt(pp, delimiter=",", skiprows=1)[:, 2]
        rmse = float(np.sqrt(np.mean((est - t[:, 2]) ** 2)))
        sel = v.get("selection", {})
        print(f"| {b} | {wall:.1f} s / {user:.1f} s, {kb / 1024:.0f} MB | "
              f"{sel.get('blocks')}, {sel.get('points'):,} | {describe(v['model'])} | "
              f"{rmse:.3f} m | {l0:.1f}-{l1:.1f} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
