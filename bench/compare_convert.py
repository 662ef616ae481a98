#!/usr/bin/env python3
"""Side-by-side speed of terramesh's UTM conversion and pyproj, on this machine, same run.

1. Library throughput on one core: pyproj's vectorised Transformer.transform on 1,000,000
   points versus terramesh-core's batch kernel (examples/utm_throughput.rs, one thread).
2. End to end: a 1,000,000-row CSV converted by `terramesh convert --to utm` versus
   bench/pyproj_convert.py (pandas + pyproj), each run 3 times, best time kept.

Run from the repository root after `cargo build --release --workspace --examples`:
    .venv-bench/bin/python bench/compare_convert.py
(needs pyproj, numpy and pandas: bench/requirements.txt, see bench/README.md). Prints the ratios.
"""
import os
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
EXAMPLE = os.path.join(TARGET, "release", "examples", "utm_throughput")
N = 1_000_000


def best(f, reps=3):
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


# 1. Library throughput, one core. Same point distribution as the Rust example.
i = np.arange(N)
lat = 40.0 + 20.0 * (i / N)
lon = 6.0 + 6.0 * ((i * 7919) % N) / N
t = pyproj.Transformer.from_crs(4326, 32632, always_xy=True)
py_rate = N / best(lambda: t.transform(lon, lat))
rates = []
for _ in range(3):
    out = subprocess.run([EXAMPLE, str(N)], capture_output=True, text=True, check=True).stdout
    rates.append(float(out.split(":")[1].split("M")[0]) * 1e6)
tm_rate = max(rates)
print(f"library, one core: pyproj {py_rate / 1e6:.2f} M points/s, "
      f"terramesh {tm_rate / 1e6:.2f} M points/s, ratio {tm_rate / py_rate:.2f}x")

# 2. End to end on a 1,000,000-row CSV.
with tempfile.TemporaryDirectory() as d:
    src = os.path.join(d, "in.csv")
    rng = np.random.default_rng(1)
    la = rng.uniform(47.0, 50.0, N)
    lo = rng.uniform(6.5, 11.5, N)
    z = rng.uniform(100.0, 1400.0, N)
    with open(src, "w") as fh:
        fh.write("id,lat,lon,z\n")
        for k in range(N):
            fh.write(f"{k},{la[k]:.10f},{lo[k]:.10f},{z[k]:.2f}\n")
    out_py = os.path.join(d, "py.csv")
    out_tm = os.path.join(d, "tm.csv")
    py = best(lambda: subprocess.run([sys.executable, os.path.join(ROOT, "bench", "pyproj_convert.py"),
                                      src, out_py, "32632"], check=True))
    tm = best(lambda: subprocess.run([BIN, "convert", "--to", "utm", "--zone", "32N", src,
                                      "-o", out_tm], check=True))
    # The two outputs agree.
    a = np.loadtxt(out_py, delimiter=",", skiprows=1, usecols=(4, 5), max_rows=1000)
    b = np.loadtxt(out_tm, delimiter=",", skiprows=1, usecols=(4, 5), max_rows=1000)
    assert np.abs(a - b).max() < 1e-5, np.abs(a - b).max()
    print(f"CSV end to end, {N:,} rows: pandas+pyproj {py:.2f} s, terramesh {tm:.2f} s, "
          f"ratio {py / tm:.1f}x faster")
