#!/usr/bin/env python3
"""Side-by-side timing of terramesh-mesh (spade CDT + refinement) against Triangle.

terramesh uses its default strips (4 for the 1.55 cases, run on the machine's cores; Triangle
is single-threaded); the "one strip" cases run it in one piece on one core. Each run is its own
process, so peak memory (VmHWM) is the run's own; the best of REPEATS
runs is reported. Timings cover meshing only (not process start, Python import or file
reading). Build first:  cargo build --release -p terramesh-mesh --example bench_mesh
Usage: .venv-bench/bin/python bench/compare_triangle.py [REPEATS [CASE-SUBSTRING]]
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# cargo's output folder: $CARGO_TARGET_DIR when set, as cargo itself does
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
RUST = os.path.join(TARGET, "release", "examples", "bench_mesh")

TRIANGLE_RUN = r"""
import sys, time, numpy as np, triangle
def rss():
    for l in open('/proc/self/status'):
        if l.startswith('VmHWM:'):
            return float(l.split()[1]) / 1024
mode = sys.argv[1]
if mode == 'quality':
    angle, area = sys.argv[2], sys.argv[3]
    sq = lambda x, y, s: [[x, y], [x + s, y], [x + s, y + s], [x, y + s]]
    v = np.array(sq(0, 0, 1000) + sq(200, 200, 100) + sq(600, 500, 100), float)
    seg = []
    for b in (0, 4, 8):
        seg += [[b + i, b + (i + 1) % 4] for i in range(4)]
    inp = dict(vertices=v, segments=np.array(seg), holes=np.array([[250.0, 250.0], [650.0, 550.0]]))
    t = time.perf_counter()
    out = triangle.triangulate(inp, 'pq%sa%sQ' % (angle, area))
    dt = time.perf_counter() - t
else:
    pts = np.fromfile(sys.argv[2], dtype='<f8').reshape(-1, 2)
    t = time.perf_counter()
    out = triangle.triangulate(dict(vertices=pts), 'Q')
    dt = time.perf_counter() - t
tri = out['triangles']; p = out['vertices'][tri]
a = []
for k in range(3):
    u = p[:, (k + 1) % 3] - p[:, k]; w = p[:, (k + 2) % 3] - p[:, k]
    a.append(np.degrees(np.arctan2(np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]), (u * w).sum(1))))
print('triangles=%d seconds=%.4f min_angle=%.3f peak_rss_mb=%.1f' % (len(tri), dt, np.min(a), rss()))
"""


def parse(line):
    return {k: float(v) for k, v in (f.split("=") for f in line.split())}


def run(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.strip()
    return parse(out.splitlines()[-1])


def interleaved(cmds, repeats):
    """Runs the commands in turn, REPEATS rounds, so that load from other work on the machine
    falls on both alike; returns each command's best run and all its times."""
    runs = [[] for _ in cmds]
    for _ in range(repeats):
        for k, cmd in enumerate(cmds):
            runs[k].append(run(cmd))
    return [(min(r, key=lambda x: x["seconds"]), [x["seconds"] for x in r]) for r in runs]


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    tmp = tempfile.mkdtemp()
    pts_file = os.path.join(tmp, "points.f64")
    rng = np.random.default_rng(0)
    (rng.random((1_000_000, 2)) * 1000.0).astype("<f8").tofile(pts_file)
    cases = [
        ("quality 30 deg, max area 1.55", ["quality", "30", "1.55"]),
        ("quality 33 deg, max area 1.55", ["quality", "33", "1.55"]),
        ("quality 30 deg, max area 15.5", ["quality", "30", "15.5"]),
        ("Delaunay, 1,000,000 random points", ["delaunay", pts_file]),
        # terramesh in one piece, on one core (the cases above use its default strips).
        ("quality 30 deg, area 1.55, one strip", ["quality", "30", "1.55", "1"]),
        ("quality 33 deg, area 1.55, one strip", ["quality", "33", "1.55", "1"]),
    ]
    print(f"best of {repeats} interleaved runs, each in its own process; "
          f"ratios = terramesh / Triangle (time: best and median)")
    print(f"{'case':36} {'tool':10} {'triangles':>10} {'min angle':>9} {'seconds':>8} {'peak MB':>8}  all runs (s)")
    only = sys.argv[2] if len(sys.argv) > 2 else ""
    for name, args in cases:
        if only not in name:
            continue
        (tri, tri_runs), (ours, our_runs) = interleaved(
            [[sys.executable, "-c", TRIANGLE_RUN] + args, [RUST] + args], repeats)
        for tool, r, runs in (("Triangle", tri, tri_runs), ("terramesh", ours, our_runs)):
            print(f"{name:36} {tool:10} {int(r['triangles']):>10} {r['min_angle']:>9.3f} "
                  f"{r['seconds']:>8.3f} {r['peak_rss_mb']:>8.1f}  {' '.join('%.3f' % s for s in runs)}")
        med = float(np.median(our_runs)) / float(np.median(tri_runs))
        print(f"{name:36} ratios: time {ours['seconds'] / tri['seconds']:.2f} (median {med:.2f}), "
              f"triangles {ours['triangles'] / tri['triangles']:.3f}, "
              f"memory {ours['peak_rss_mb'] / tri['peak_rss_mb']:.2f}")


if __name__ == "__main__":
    main()
