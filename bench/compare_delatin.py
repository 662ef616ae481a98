#!/usr/bin/env python3
"""Terrain-adaptive refinement (terramesh) against a uniform mesh of the same error and
against Delatin's greedy insertion (pydelatin), on analytic surfaces over a 200 m square.

Delatin meshes the 201 x 201 heightmap at 1 m spacing and measures its error at those grid
points; terramesh measures at triangle centres and edge midpoints (err_nodes) and, for
comparison, at the same grid points (err_grid). 3D angles are of the lifted triangles.
Build first: cargo build --release -p terramesh-mesh --example adaptive_compare
Usage: .venv-bench/bin/python bench/compare_delatin.py
"""
import os
import subprocess

import numpy as np
from pydelatin import Delatin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# cargo's output folder: $CARGO_TARGET_DIR when set, as cargo itself does
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
RUST = os.path.join(TARGET, "release", "examples", "adaptive_compare")

FUNCS = {
    "cliff": lambda x, y: 20.0 * np.tanh((x - 100.0) / 5.0),
    "cone": lambda x, y: 60.0 - 0.5 * np.hypot(x - 100.0, y - 100.0),
}


def min_angles(v, tri):
    """Smallest angle of the lifted (3D) and of the planar triangles, degrees."""
    p = v[tri]
    out3, out2 = [], []
    for k in range(3):
        u = p[:, (k + 1) % 3] - p[:, k]
        w = p[:, (k + 2) % 3] - p[:, k]
        out3.append(np.degrees(np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), (u * w).sum(1))))
        cz = np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])
        out2.append(np.degrees(np.arctan2(cz, (u[:, :2] * w[:, :2]).sum(1))))
    return np.min(out3), np.min(out2)


def main():
    g = np.arange(201.0)
    X, Y = np.meshgrid(g, g)
    print(f"{'surface':7} {'max err':>7} {'tool':22} {'triangles':>9} {'err@grid':>8} "
          f"{'min 3D':>7} {'min 2D':>7}  notes")
    for name, f in FUNCS.items():
        H = f(X, Y).astype(np.float32)
        for tol in (0.5, 0.1):
            d = Delatin(H, max_error=tol)
            v = np.column_stack([d.vertices[:, 0], d.vertices[:, 1], f(d.vertices[:, 0], d.vertices[:, 1])])
            a3, a2 = min_angles(v, d.triangles)
            out = subprocess.run([RUST, name, str(tol)], check=True, capture_output=True, text=True).stdout
            r = {k: float(x) for k, x in (t.split("=") for t in out.split())}
            print(f"{name:7} {tol:7.2f} {'Delatin (pydelatin)':22} {len(d.triangles):9d} {d.error:8.4f} "
                  f"{a3:7.2f} {a2:7.2f}")
            print(f"{name:7} {tol:7.2f} {'terramesh adaptive':22} {int(r['adaptive_triangles']):9d} "
                  f"{r['err_grid']:8.4f} {r['min3d']:7.2f} {r['min2d']:7.2f}  err at centres/midpoints "
                  f"{r['err_nodes']:.4f}; 3D min angle {r['min3d_before']:.2f} before improvement "
                  f"({int(r['flips'])} flips, {int(r['moves'])} moves); {r['seconds']:.2f} s")
            print(f"{name:7} {tol:7.2f} {'uniform 30 deg mesh':22} {int(r['uniform_triangles']):9d} "
                  f"{'':8} {r['uniform_min3d']:7.2f} {'>=30':>7}  coarsest area limit within the error")
            out20 = subprocess.run([RUST, name, str(tol), "20"], check=True, capture_output=True, text=True).stdout
            r20 = {k: float(x) for k, x in (t.split("=") for t in out20.split())}
            print(f"{name:7} {tol:7.2f} {'terramesh adaptive 20':22} {int(r20['adaptive_triangles']):9d} "
                  f"{r20['err_grid']:8.4f} {r20['min3d']:7.2f} {r20['min2d']:7.2f}  same, 2D minimum angle 20 deg")
            print(f"{name:7} {tol:7.2f} ratios: adaptive/uniform "
                  f"{r['adaptive_triangles'] / r['uniform_triangles']:.3f}, adaptive/Delatin "
                  f"{r['adaptive_triangles'] / len(d.triangles):.2f}")


if __name__ == "__main__":
    main()
