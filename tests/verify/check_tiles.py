"""Checks the `dsm.vtu` of `terramesh tiles merge` with readers that share no code with terramesh.

    python tests/verify/check_tiles.py MERGED_DIR PLAN_DIR

MERGED_DIR is the merge's output (`dsm.vtu`, `merge.json`), PLAN_DIR the plan (`tiles.json`:
the region outline and every tile's planned seam vertices). meshio reads the mesh; the checks
are that the merged surface is conforming and covers exactly the region:

* no edge in more than two triangles, the triangles counter-clockwise and consistently oriented;
* every boundary edge (in one triangle) lies on one segment of the region's outline, and the
  boundary's length is the outline's perimeter;
* the planar area is the region's (shoelace formula) to 1e-9 relative;
* every planned seam vertex is a vertex of the mesh exactly once (no two vertices share x, y),
  and the counts agree with `merge.json`;
* VTK's own reader (ParaView's) reads the same points, triangles and point arrays as meshio.

Prints `PASS name` or `FAIL name: why` per check, then `N passed, M failed`; exits 1 on failure.
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from vcommon import CheckFailed, planar_areas, require  # noqa: E402

AREA_REL = 1e-9  # issue 17: the merged area equals the region's to 1e-9
ON_OUTLINE = 1e-6  # metres: planned outline vertices are interpolated on the segments


class Merged:
    """The merged mesh (read once by meshio), the plan's region and seam vertices, merge.json."""

    def __init__(self, merged, plan):
        self.merged, self.plan = Path(merged), Path(plan)
        self._mesh = None

    def mesh(self):
        if self._mesh is None:
            import meshio
            m = meshio.read(self.merged / "dsm.vtu")
            blocks = [c for c in m.cells if c.type == "triangle"]
            require(len(blocks) == len(m.cells) and blocks,
                    f"dsm.vtu: expected triangle cells only, got {[c.type for c in m.cells]}")
            tris = np.concatenate([b.data for b in blocks]).astype(np.int64)
            require(tris.min() >= 0 and tris.max() < len(m.points),
                    f"dsm.vtu: connectivity refers to vertex {tris.max()} of {len(m.points)}")
            self._mesh = (np.asarray(m.points, dtype=float), tris)
        return self._mesh

    def manifest(self):
        return json.loads((self.plan / "tiles.json").read_text())

    def region(self):
        r = np.asarray(self.manifest()["region"], dtype=float)
        require(r.ndim == 2 and r.shape[1] == 2 and len(r) >= 3, f"tiles.json: region {r.tolist()!r}")
        return r

    def seam_vertices(self):
        keys = set()
        for t in self.manifest()["tiles"]:
            for s in t["seams"]:
                keys.update((float(v[0]), float(v[1])) for v in s["vertices"])
        return keys

    def summary(self):
        return json.loads((self.merged / "merge.json").read_text())


def edge_counts(tris):
    """Undirected edge -> number of triangles, and directed edge -> number of triangles."""
    directed = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    und, und_n = np.unique(undirected, axis=0, return_counts=True)
    dire, dire_n = np.unique(directed, axis=0, return_counts=True)
    return und, und_n, dire, dire_n


def check_readable(d):
    """meshio reads dsm.vtu; its counts are merge.json's."""
    pts, tris = d.mesh()
    s = d.summary()
    require(len(pts) == s["vertices"], f"dsm.vtu: {len(pts)} vertices, merge.json says {s['vertices']}")
    require(len(tris) == s["triangles"], f"dsm.vtu: {len(tris)} triangles, merge.json says {s['triangles']}")


def check_edges(d):
    """No edge in more than two triangles; triangles counter-clockwise, consistently oriented."""
    pts, tris = d.mesh()
    und, und_n, dire, dire_n = edge_counts(tris)
    k = int(np.argmax(und_n))
    require(und_n.max() <= 2, f"dsm.vtu: {int(np.sum(und_n > 2))} edges in more than two triangles, "
            f"e.g. {und[k].tolist()} in {und_n[k]}")
    require(dire_n.max() == 1, f"dsm.vtu: {int(np.sum(dire_n > 1))} edges traversed twice in the same "
            f"direction (inconsistent orientation), e.g. {dire[int(np.argmax(dire_n))].tolist()}")
    a = planar_areas(pts, tris)
    require(np.all(a > 0), f"dsm.vtu: {int(np.sum(a <= 0))} triangles not counter-clockwise, e.g. #{int(np.argmin(a))}")


def seg_dist(a, b, p):
    """Distances of points p (n x 2) to segment a-b."""
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.hypot(*(a + t[:, None] * ab - p).T)


def check_boundary(d):
    """Every boundary edge on one segment of the region's outline; boundary length = perimeter."""
    pts, tris = d.mesh()
    region = d.region()
    und, und_n, _, _ = edge_counts(tris)
    bnd = und[und_n == 1]
    require(len(bnd) >= 3, f"dsm.vtu: {len(bnd)} boundary edges")
    u, v = pts[bnd[:, 0], :2], pts[bnd[:, 1], :2]
    on_one = np.zeros(len(bnd), dtype=bool)
    for i in range(len(region)):
        a, b = region[i], region[(i + 1) % len(region)]
        on_one |= (seg_dist(a, b, u) <= ON_OUTLINE) & (seg_dist(a, b, v) <= ON_OUTLINE)
    k = int(np.argmin(on_one))
    require(on_one.all(), f"dsm.vtu: {int(np.sum(~on_one))} boundary edges not on the region's outline "
            f"(a gap, a duplicated seam or a moved vertex), e.g. {u[k].tolist()} - {v[k].tolist()}")
    length = float(np.hypot(*(u - v).T).sum())
    perimeter = float(np.hypot(*(region - np.roll(region, -1, axis=0)).T).sum())
    require(abs(length - perimeter) <= AREA_REL * perimeter,
            f"dsm.vtu: boundary length {length!r} m, the region's perimeter is {perimeter!r} m")


def check_area(d):
    """Planar area of the triangles = the region's (shoelace), to 1e-9 relative."""
    pts, tris = d.mesh()
    r = d.region()
    r = r - r[0]  # shoelace about a corner: products of UTM coordinates would lose ~1e-4 m²
    whole = abs(0.5 * float(np.sum(r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1])))
    area = float(planar_areas(pts, tris).sum())
    require(abs(area - whole) <= AREA_REL * whole,
            f"dsm.vtu: planar area {area!r} m², the region's is {whole!r} m² (relative {abs(area - whole) / whole:.3g})")


def check_seam_vertices(d):
    """Each planned seam vertex in the mesh exactly once; no two vertices at the same x, y."""
    pts, _ = d.mesh()
    xy, n = np.unique(pts[:, :2], axis=0, return_counts=True)
    require(n.max() == 1, f"dsm.vtu: {int(np.sum(n > 1))} positions hold more than one vertex, "
            f"e.g. {xy[int(np.argmax(n))].tolist()} x{int(n.max())}")
    have = set(map(tuple, pts[:, :2].tolist()))
    seam = d.seam_vertices()
    missing = [p for p in seam if p not in have]
    require(seam, "tiles.json: no seam vertices (a plan of one tile?)")
    require(not missing, f"dsm.vtu: {len(missing)} of {len(seam)} planned seam vertices missing, "
            f"e.g. {missing[:1]}")
    s = d.summary()
    require(s["seam_vertices"] == len(seam),
            f"merge.json: seam_vertices {s['seam_vertices']}, tiles.json plans {len(seam)}")


def check_vtk(d):
    """VTK (ParaView's reader) reads dsm.vtu to the same points, triangles and point arrays."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(d.merged / "dsm.vtu"))
    r.Update()
    g = r.GetOutput()
    pts, tris = d.mesh()
    require(g.GetNumberOfPoints() == len(pts) and g.GetNumberOfCells() == len(tris),
            f"VTK reads {g.GetNumberOfPoints()} points and {g.GetNumberOfCells()} cells, "
            f"meshio {len(pts)} and {len(tris)}")
    vp = vtk_to_numpy(g.GetPoints().GetData())
    require(np.array_equal(vp, pts), "VTK's points differ from meshio's")
    conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 3)
    require(np.array_equal(conn, tris), "VTK's triangles differ from meshio's")
    import meshio
    m = meshio.read(d.merged / "dsm.vtu")
    pd = g.GetPointData()
    for name, values in m.point_data.items():
        a = pd.GetArray(name)
        require(a is not None, f"VTK does not read point array {name}")
        require(np.array_equal(vtk_to_numpy(a), values), f"point array {name}: VTK and meshio differ")


CHECKS = [
    ("readable", check_readable),
    ("vtk", check_vtk),
    ("edges", check_edges),
    ("boundary", check_boundary),
    ("area", check_area),
    ("seam vertices", check_seam_vertices),
]


def run(merged, plan, only=None):
    """Runs the checks, printing one line each; returns the names of the failed ones."""
    d = Merged(merged, plan)
    failed, passed = [], 0
    for name, check in CHECKS:
        if only and name not in only:
            continue
        try:
            check(d)
            print(f"PASS {name}")
            passed += 1
        except CheckFailed as e:
            print(f"FAIL {name}: {e}")
            failed.append(name)
        except (Exception, SystemExit) as e:  # meshio exits on an unreadable file: a failure, not a crash
            print(f"FAIL {name}: {type(e).__name__}: {e}")
            failed.append(name)
    print(f"{passed} passed, {len(failed)} failed")
    return failed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("merged", help="the output folder of `terramesh tiles merge`")
    ap.add_argument("plan", help="the plan folder (tiles.json)")
    ap.add_argument("--only", action="append", help="run only this check (repeatable)")
    a = ap.parse_args(argv)
    return 1 if run(a.merged, a.plan, a.only) else 0


if __name__ == "__main__":
    sys.exit(main())
