#!/usr/bin/env python3
"""Cost of the automatic REML fit at larger sizes: the table "Cost at larger sizes" of
docs/geostatistics.md.

Run from the repository root after `cargo build --release -p terramesh-cli`, in the venv of
hidden_truth.py (`bench/hidden_truth-requirements.txt`):
    .venv-hidden/bin/python bench/reml_cost.py [CELLS ...] [--seed S] [--targets N]

For each CELLS (default 5000 and 20000) the Vosges DEM of hidden_truth.py is drawn on a
jittered grid of about CELLS cells (its sampler, seed 15 by default), N targets (default 1,000)
are drawn from the other posts, and two commands are timed with `/usr/bin/time -v`:

    terramesh variogram --data D --fit reml --drift linear -o V
    terramesh interpolate --data D --targets T --method uk --drift linear --no-variance \
        --variogram auto --fit reml -o P

Prints a markdown row per size: data, wall and user seconds of each, the interpolation's
maximum resident set size, the 1-minute load average before and after, and the model chosen.
Timings are wall clock: run it on an idle machine (the load columns say whether it was).
"""
import json
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hidden_truth as ht  # noqa: E402


def timed(args):
    p = subprocess.run(["/usr/bin/time", "-v", ht.BIN] + args, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"terramesh {' '.join(args)}: {p.stderr.strip()[-2000:]}")
    grab = lambda key: re.search(re.escape(key) + r":\s*(\S+)", p.stderr).group(1)
    wall = grab("Elapsed (wall clock) time (h:mm:ss or m:ss)")
    secs = sum(float(v) * 60 ** i for i, v in enumerate(reversed(wall.split(":"))))
    return secs, float(grab("User time (seconds)")), int(grab("Maximum resident set size (kbytes)"))


def load():
    return os.getloadavg()[0]


def main():
    argv = sys.argv[1:]
    seed, n_targets = 15, 1000
    for flag in ("--seed", "--targets"):
        if flag in argv:
            i = argv.index(flag)
            v = int(argv[i + 1])
            del argv[i:i + 2]
            if flag == "--seed":
                seed = v
            else:
                n_targets = v
    sizes = [int(a) for a in argv] or [5000, 20000]
    os.makedirs(ht.OUT, exist_ok=True)
    print("| data | `variogram` wall / user | `interpolate --variogram auto` wall / user, "
          "max RSS | load before-after | model |")
    print("|---|---|---|---|---|")
    for cells in sizes:
        ht.N_DATA = cells
        d, t = ht.split(*ht.srtm_vosges(), np.random.default_rng(seed), n_targets)
        dp = os.path.join(ht.OUT, f"cost-{cells}-data.csv")
        tp = os.path.join(ht.OUT, f"cost-{cells}-targets.csv")
        vj = os.path.join(ht.OUT, f"cost-{cells}-variogram.json")
        pp = os.path.join(ht.OUT, f"cost-{cells}-out.csv")
        np.savetxt(dp, d, delimiter=",", header="x,y,z", comments="", fmt="%.10g")
        np.savetxt(tp, t[:, :2], delimiter=",", header="x,y", comments="", fmt="%.10g")
        l0 = load()
        vw, vu, _ = timed(["variogram", "--data", dp, "--fit", "reml", "--drift", "linear",
                           "-o", vj])
        iw, iu, rss = timed(["interpolate", "--data", dp, "--targets", tp, "--method", "uk",
                             "--drift", "linear", "--no-variance", "--variogram", "auto",
                             "--fit", "reml", "-o", pp])
        l1 = load()
        model = ht.describe(json.load(open(vj))["model"])
        print(f"| {len(d):,} | {vw:.1f} s / {vu:.1f} s | {iw:.1f} s / {iu:.1f} s, "
              f"{rss / 1024:.0f} MB | {l0:.1f}-{l1:.1f} | {model} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
