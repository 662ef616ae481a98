#!/usr/bin/env python3
"""A dense survey built with default settings (issue 33, goal 2): the figures of docs/scaling.md.

Writes a project whose [source] is a CSV of 10,509 terrain points (lat, lon, z) over a
1 x 0.8 km region around Haut-Barr castle, and times `terramesh build` on it with every other
setting left at its default.

The points: seeded pseudo-random positions (uniform over the region's box), each height the
bilinear interpolation of the SRTM posts of the committed crop examples/haut-barr/srtm-crop.asc
(cut from ../shared/data/srtm/N48E007.hgt by examples/haut-barr/make_crop.py; metres above
EGM96), plus a seeded 5 cm Gaussian measurement error (a GNSS survey's). The crop is committed,
so the project is the same on every clone; Python's standard library only.

Usage (from the repository root, after `cargo build --release -p terramesh-cli`):

    python3 bench/dense_survey.py [--points N] [--repeats R] [--binary PATH] [--keep DIR]
        [--set KEY=VALUE ...]

It prints the build's log (per-stage time and peak memory) of every run, then the best wall
time. `--binary` times another terramesh (e.g. main's) on the same project; `--set` passes
settings to the build (`--set interpolation.neighbors=0` asks for global kriging).
"""

import argparse
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CROP = os.path.join(ROOT, "examples", "haut-barr", "srtm-crop.asc")

# The region: 1 km east-west by 0.8 km north-south, centred on the paper's study area.
CENTRE = (48.7242, 7.3386)  # lat, lon
WIDTH_M, HEIGHT_M = 1000.0, 800.0
SEED = 33
NOISE_M = 0.05


def read_asc(path):
    head = {}
    with open(path) as f:
        for _ in range(6):
            k, v = f.readline().split()
            head[k.lower()] = float(v)
        rows = [list(map(float, line.split())) for line in f if line.strip()]
    return head, rows


def bilinear(head, rows, lat, lon):
    """The crop's posts (pixel-is-point, row 0 northmost) interpolated at (lat, lon)."""
    c = head["cellsize"]
    nrows = int(head["nrows"])
    fx = (lon - head["xllcenter"]) / c
    fy = (head["yllcenter"] + (nrows - 1) * c - lat) / c  # rows from the north
    i, j = int(math.floor(fy)), int(math.floor(fx))
    ty, tx = fy - i, fx - j
    z = [[rows[i + a][j + b] for b in (0, 1)] for a in (0, 1)]
    if any(v == head["nodata_value"] for r in z for v in r):
        raise SystemExit(f"a void of {CROP} at {lat}, {lon}")
    top = z[0][0] * (1 - tx) + z[0][1] * tx
    bottom = z[1][0] * (1 - tx) + z[1][1] * tx
    return top * (1 - ty) + bottom * ty


def box():
    """The region's box in degrees (south, west, north, east)."""
    lat0, lon0 = CENTRE
    dlat = HEIGHT_M / 111_132.0
    dlon = WIDTH_M / (111_320.0 * math.cos(math.radians(lat0)))
    return lat0 - dlat / 2, lon0 - dlon / 2, lat0 + dlat / 2, lon0 + dlon / 2


def write_project(folder, n):
    head, rows = read_asc(CROP)
    s, w, nn, e = box()
    rng = random.Random(SEED)
    with open(os.path.join(folder, "survey.csv"), "w") as f:
        f.write("lat,lon,z\n")
        for _ in range(n):
            lat = rng.uniform(s, nn)
            lon = rng.uniform(w, e)
            z = bilinear(head, rows, lat, lon) + rng.gauss(0.0, NOISE_M)
            f.write(f"{lat:.8f},{lon:.8f},{z:.3f}\n")
    with open(os.path.join(folder, "terramesh.toml"), "w") as f:
        f.write(
            "# bench/dense_survey.py: 1 x 0.8 km around Haut-Barr, default settings\n"
            'title = "Dense survey (bench/dense_survey.py)"\n\n'
            "[region]\n"
            f'corners = "{s:.8f} {w:.8f}; {s:.8f} {e:.8f}; {nn:.8f} {e:.8f}; {nn:.8f} {w:.8f}"\n\n'
            "[source]\n"
            'path = "survey.csv"\n'
        )


def binary(arg):
    if arg:
        return arg
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    return os.path.join(target, "release", "terramesh")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=10_509)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--binary")
    ap.add_argument("--keep", help="write the project and the build here (kept)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    a = ap.parse_args()
    exe = binary(a.binary)
    if not os.path.exists(exe):
        raise SystemExit(f"{exe} not found: cargo build --release -p terramesh-cli first")
    folder = a.keep or tempfile.mkdtemp(prefix="terramesh-dense-")
    os.makedirs(folder, exist_ok=True)
    write_project(folder, a.points)
    print(f"project: {a.points} points over {WIDTH_M:.0f} x {HEIGHT_M:.0f} m "
          f"(seed {SEED}, {NOISE_M} m noise) in {folder}", flush=True)
    cmd = [exe, "build", os.path.join(folder, "terramesh.toml"), "-o", os.path.join(folder, "out")]
    for s in a.set:
        cmd += ["--set", s]
    print("command:", " ".join(cmd), flush=True)
    times = []
    for k in range(a.repeats):
        t = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t
        if r.returncode != 0:
            sys.stderr.write(r.stdout + r.stderr)
            raise SystemExit(f"build failed (exit {r.returncode})")
        times.append(wall)
        print(f"--- run {k + 1}: {wall:.2f} s wall")
        print((r.stdout + r.stderr).strip())
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    print(f"best of {a.repeats}: {min(times):.2f} s (load average {load:.2f}, {os.cpu_count()} CPUs)")
    if not a.keep:
        shutil.rmtree(folder)


if __name__ == "__main__":
    main()
