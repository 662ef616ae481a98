#!/usr/bin/env python3
"""Writes the synthetic faulted site of examples/faulted/ (issue 31): a planar terrain, eight
planar strata (three thin weak interbeds), three planar faults (F1 normal, F2 reverse, F3 normal
ending at F1) offsetting them by constant throws, and 25 vertical boreholes logged from the
known truth (past the reverse fault F2 a hole logs the units it repeats). Standard library only; deterministic (seeded).

    python3 examples/faulted/make_site.py      # rewrites the files beside it

The truth is the closed form of `terramesh_faults::Site::true_unit` (crates/terramesh-faults/
src/synth.rs), written down here independently: `site.json` holds its parameters, read by
crates/terramesh-cli/tests/model_faulted.rs to rebuild the truth and compare every cell.
"""

import json
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
SIZE = 400.0
PLANE = [150.0, 0.02, -0.01]  # terrain z = a + b x + c y
BASE = 0.0
UNITS = ["colluvium", "sandstone_a", "weak_1", "sandstone_b", "weak_2", "limestone",
         "weak_3", "marl"]
TOPS = [140.0, 115.0, 113.0, 90.0, 88.5, 62.0, 60.5]  # interfaces where no fault moved them
DIP = [0.01, 0.005]  # the strata's gradient
# name, trace (two points, beyond the region), dip, dip direction, throw of the positive
# side (hanging wall) downwards (negative: up, a reverse fault), ends_at (fault index, side)
FAULTS = [
    ("F1", [[150.0, -50.0], [190.0, 450.0]], 60.0, 90.0, 12.0, None, "normal"),
    ("F2", [[-50.0, 250.0], [450.0, 230.0]], 70.0, 180.0, -8.0, None, "reverse"),
    ("F3", [[-50.0, 100.0], [250.0, 160.0]], 75.0, 0.0, 6.0, (0, -1), "normal"),
]


def terrain(x, y):
    return PLANE[0] + PLANE[1] * x + PLANE[2] * y


def true_side(f, q):
    _, (a, b), dip, ddir, _, _, _ = FAULTS[f]
    d = math.radians(ddir)
    u = [math.sin(d), math.cos(d)]
    cot = 0.0 if dip == 90.0 else 1.0 / math.tan(math.radians(dip))
    e = [b[0] - a[0], b[1] - a[1], terrain(*b) - terrain(*a)]
    w = [cot * u[0], cot * u[1], -1.0]
    n = [e[1] * w[2] - e[2] * w[1], e[2] * w[0] - e[0] * w[2], e[0] * w[1] - e[1] * w[0]]
    if n[0] * u[0] + n[1] * u[1] < 0.0:
        n = [-c for c in n]
    ln = math.sqrt(sum(c * c for c in n))
    za = terrain(*a)
    return (n[0] * (q[0] - a[0]) + n[1] * (q[1] - a[1]) + n[2] * (q[2] - za)) / ln


def counts(f, q):
    e = FAULTS[f][5]
    if e is None:
        return True
    g, s = e
    return (true_side(g, q) > 0.0) == (s > 0)


def true_unit(q):
    z = q[2]
    for f in range(len(FAULTS)):
        if counts(f, q) and true_side(f, q) > 0.0:
            z += FAULTS[f][4]
    return sum(1 for t in TOPS if t + DIP[0] * q[0] + DIP[1] * q[1] > z)


def crossing(f, x, y, z0, z1):
    """The elevation where the vertical line at (x, y) crosses fault f between z0 and z1."""
    s0 = true_side(f, [x, y, z0])
    for _ in range(60):
        zm = 0.5 * (z0 + z1)
        if (true_side(f, [x, y, zm]) > 0) == (s0 > 0):
            z0 = zm
        else:
            z1 = zm
    return 0.5 * (z0 + z1)


def main():
    rng = random.Random(31)
    # The terrain as points (the DSM is kriged from them), 20 m apart, 40 m beyond the region.
    with open(os.path.join(HERE, "heights.csv"), "w") as fh:
        fh.write("x,y,z\n")
        for j in range(-2, 23):
            for i in range(-2, 23):
                x, y = 20.0 * i, 20.0 * j
                fh.write(f"{x},{y},{terrain(x, y):.6f}\n")
    for name, (a, b), *_ in FAULTS:
        with open(os.path.join(HERE, f"{name.lower()}.csv"), "w") as fh:
            fh.write("x,y\n")
            for p in (a, b):
                fh.write(f"{p[0]},{p[1]}\n")
    collars, intervals, picks = [], [], []
    step = 0.01
    for j in range(5):
        for i in range(5):
            x = 40.0 + 80.0 * i + rng.uniform(-15.0, 15.0)
            y = 40.0 + 80.0 * j + rng.uniform(-15.0, 15.0)
            name = f"B{5 * j + i + 1:02d}"
            zc = terrain(x, y)
            collars.append(f"{name},{x:.3f},{y:.3f},{zc:.6f}")
            # The log from the truth every 1 cm, down to 25 m above the base; past a reverse
            # fault a unit the hole has passed comes again, and is logged again.
            runs = []
            md = 0.0
            bottom = BASE + 25.0
            while zc - md > bottom:
                u = true_unit([x, y, zc - md - step / 2])
                if runs and runs[-1][2] == u:
                    runs[-1][1] = md + step
                else:
                    runs.append([md, md + step, u])
                md += step
            depth = runs[-1][1]
            for r in runs:
                intervals.append(f"{name},{r[0]:.2f},{r[1]:.2f},{UNITS[r[2]]}")
            for f, fault in enumerate(FAULTS):
                top = true_side(f, [x, y, zc])
                low = true_side(f, [x, y, zc - depth])
                if (top > 0) != (low > 0):
                    z = crossing(f, x, y, zc, zc - depth)
                    if counts(f, [x, y, z]):
                        picks.append(f"{name},{zc - z:.3f},{fault[0]}")
    with open(os.path.join(HERE, "collars.csv"), "w") as fh:
        fh.write("hole,x,y,z\n" + "\n".join(collars) + "\n")
    with open(os.path.join(HERE, "intervals.csv"), "w") as fh:
        fh.write("hole,from,to,unit\n" + "\n".join(intervals) + "\n")
    with open(os.path.join(HERE, "fault_picks.csv"), "w") as fh:
        fh.write("hole,depth,fault\n" + "\n".join(picks) + "\n")
    site = {
        "plane": PLANE,
        "base": BASE,
        "tops": TOPS,
        "dip": DIP,
        "units": UNITS,
        "faults": [
            {"name": n, "trace": t, "dip": d, "dip_direction": dd, "throw": th,
             "ends_at": e, "kind": k}
            for n, t, d, dd, th, e, k in FAULTS
        ],
    }
    with open(os.path.join(HERE, "site.json"), "w") as fh:
        json.dump(site, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
