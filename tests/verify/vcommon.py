"""Shared parts of the output verifier: failures, tolerances, geometry helpers, the output
directory with its reference data (see verify_outputs.py and docs/verification.md)."""

import csv
import json
import subprocess
from pathlib import Path

import numpy as np

REL_DOUBLE = 1e-9  # files that store doubles (shortest round trip or %.17g)
REL_FLOAT32 = 1e-6  # binary STL: float32 coordinates relative to the origin
F32_EPS = 2.0**-23  # float32 relative rounding bound (two half-ulps)
KML_DEG = 1e-7  # KML: 10 decimals, and terramesh's projection vs PROJ (~1 cm)
KML_ALT = 5e-4 + 1e-9  # KML altitudes have 3 decimals
# COLLADA: shortest round-trip doubles in metres around the model origin. Back to lat/lon/alt
# they agree with PROJ to ~4e-14 degrees and ~5e-9 m on the example, so these leave a margin of
# 20 and still catch float32 coordinates (~4e-6 m at 100 m from the origin).
DAE_DEG = 1e-11  # about 1 micrometre
DAE_ALT = 1e-7
GRID_OVERSHOOT = 0.1  # grid values may exceed the vertex range by this fraction of it
CSV_COLUMNS = ["x", "y", "elevation_uk", "kriging_std", "elevation_idw"]
POINT_FIELDS = ["elevation_uk", "kriging_std", "elevation_idw", "uk_minus_idw"]
CELL_FIELDS = ["min_angle_deg"]
# The report and build.json hold the stages' times and peak memory.
NOT_DETERMINISTIC = {"report.html", "build.json"}


class CheckFailed(Exception):
    """A check's failure, with the reason shown to the user."""


def run_checks(checks, subject, only=None):
    """Runs each `(name, fn)` of `checks` on `subject` (those whose name starts with one of
    `only`, if given), its own output hidden; prints `PASS name` or `FAIL name: why` per check
    and the totals; returns (passed, failed)."""
    import contextlib
    import io

    passed = failed = 0
    for name, fn in checks:
        if only and not any(name.startswith(s) for s in only):
            continue
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                fn(subject)
        except CheckFailed as e:
            print(f"FAIL {name}: {e}", flush=True)
            failed += 1
        except (Exception, SystemExit) as e:
            print(f"FAIL {name}: {type(e).__name__}: {e}", flush=True)
            failed += 1
        else:
            print(f"PASS {name}", flush=True)
            passed += 1
    print(f"{passed} passed, {failed} failed")
    return passed, failed


def model_dir_main(doc, run, argv=None):
    """The command line of a model checker: MODEL_DIR and --only; `run(model_dir, only)`
    returns (passed, failed). Exit status 2 for a missing folder, 1 if a check failed."""
    import argparse
    import sys

    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("model_dir")
    ap.add_argument("--only", action="append", help="run only the checks whose name starts with this")
    a = ap.parse_args(argv)
    if not Path(a.model_dir).is_dir():
        print(f"error: {a.model_dir} is not a directory", file=sys.stderr)
        return 2
    _, failed = run(a.model_dir, a.only)
    return 1 if failed else 0


def require(cond, msg):
    if not cond:
        raise CheckFailed(msg)


def close(a, b, rel, what, atol=0.0):
    """Fails unless arrays `a` and `b` agree to `rel` relative to b's magnitude (plus atol)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    require(a.shape == b.shape, f"{what}: shape {a.shape} != {b.shape}")
    if a.size == 0:
        return
    tol = rel * np.maximum(np.abs(b), 1.0) + atol
    err = np.abs(a - b)
    k = int(np.argmax(err - tol))
    require(np.all(err <= tol), f"{what}: differs at index {np.unravel_index(k, a.shape)}: "
            f"{a.ravel()[k]!r} vs {b.ravel()[k]!r} (tolerance {tol.ravel()[k]:.3g})")


# ---------------------------------------------------------------- shared geometry helpers


def planar_areas(pts, tris):
    p = pts[tris]
    return 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                  - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))


def canonical_triangles(tris):
    """Triangles rotated to start at their smallest index (orientation kept), rows sorted."""
    t = np.asarray(tris, dtype=np.int64)
    k = np.argmin(t, axis=1)
    rot = np.stack([t[np.arange(len(t)), (k + j) % 3] for j in range(3)], axis=1)
    return rot[np.lexsort(rot.T[::-1])]


def signed_volume(pts, tris):
    p = pts[tris]
    return float(np.sum(np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2]))) / 6.0)


def watertight(tris, what):
    """Every undirected edge in exactly two triangles, traversed in opposite directions."""
    directed = {}
    for t in np.asarray(tris).tolist():
        for k in range(3):
            e = (t[k], t[(k + 1) % 3])
            directed[e] = directed.get(e, 0) + 1
    bad = [e for e, n in directed.items() if n != 1 or directed.get((e[1], e[0]), 0) != 1]
    require(not bad, f"{what}: not watertight, {len(bad)} bad directed edges, e.g. {bad[:3]} "
            "(open boundary, non-manifold or inconsistently oriented)")


def single_triangle_block(mesh, what):
    blocks = [c.data for c in mesh.cells if c.type == "triangle"]
    others = sorted({c.type for c in mesh.cells} - {"triangle"})
    require(len(blocks) >= 1, f"{what}: no triangles")
    require(not others, f"{what}: unexpected cell types {others}")
    return np.vstack(blocks)


def meshio_read(path, **kw):
    """meshio.read, whose failure on a broken file (it calls sys.exit) names the file."""
    import meshio
    try:
        return meshio.read(path, **kw)
    except (Exception, SystemExit) as e:
        raise CheckFailed(f"{Path(path).name}: meshio cannot read it ({type(e).__name__}: {e})")


# ---------------------------------------------------------------- the outputs being checked


class Outputs:
    """The output directory with lazily read reference data."""

    def __init__(self, root):
        self.root = Path(root)
        self._ref = None

    def path(self, name):
        p = self.root / name
        require(p.is_file(), f"missing file {name}")
        require(p.stat().st_size > 0, f"empty file {name}")
        return p

    def ref(self):
        """(csv columns as dict of arrays, points (n,3) with z = elevation_uk, triangles)."""
        if self._ref is None:
            with open(self.path("dsm-vertices.csv"), newline="") as f:
                rows = list(csv.reader(f))
            require(rows and rows[0] == CSV_COLUMNS, f"dsm-vertices.csv: header {rows[:1]} != {CSV_COLUMNS}")
            require(len(rows) > 3, "dsm-vertices.csv: fewer than 3 vertices")
            vals = np.array([[float(v) for v in r] for r in rows[1:]])
            require(np.all(np.isfinite(vals)), "dsm-vertices.csv: non-finite values")
            cols = dict(zip(CSV_COLUMNS, vals.T))
            tris = single_triangle_block(meshio_read(self.path("dsm.vtu")), "dsm.vtu")
            require(tris.min() >= 0 and tris.max() < len(vals), "dsm.vtu: triangle index out of range")
            pts = np.column_stack([cols["x"], cols["y"], cols["elevation_uk"]])
            self._ref = (cols, pts, tris)
        return self._ref

    def origin(self):
        o = json.loads(self.path("dsm-origin.json").read_text())
        require(set(o) >= {"x", "y", "z"}, f"dsm-origin.json: keys {sorted(o)} lack x, y, z")
        return np.array([float(o["x"]), float(o["y"]), float(o["z"])])

    def epsg(self):
        import rasterio
        with rasterio.open(self.path("dsm.tif")) as ds:
            return ds.crs.to_epsg() if ds.crs else None


# ---------------------------------------------------------------- XML schemas


def kml_schema_dir():
    """pykml's copy of ogckml22.xsd, whose atom and xAL imports point at local files."""
    import importlib.util
    spec = importlib.util.find_spec("pykml")
    require(spec is not None, "pykml not installed: it bundles the KML 2.2 schema")
    d = Path(list(spec.submodule_search_locations)[0]) / "schemas"
    for f in ["ogckml22.xsd", "atom-author-link.xsd", "xAL.xsd"]:
        require((d / f).is_file(), f"pykml schema {f} missing in {d}")
    return d


def xmllint_schema(out, name, xsd):
    """Fails unless `name` in the output directory is valid against the XML schema `xsd`."""
    r = subprocess.run(["xmllint", "--noout", "--nonet", "--schema", str(xsd), str(out.path(name))],
                       capture_output=True, text=True)
    require(r.returncode == 0, f"{name}: xmllint: {r.stderr.strip()[-600:]}")
