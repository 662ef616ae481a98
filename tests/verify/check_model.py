"""Checks the geological model's files (issue 13) with readers that share no code with terramesh.

    python tests/verify/check_model.py MODEL_DIR [--only NAME]

MODEL_DIR holds model.vtu, the boundary meshes model-top.vtu, model-bottom.vtu and
model-side-*.vtu, model.msh, model.f3grid and unit-<name>.ts / .stl; in a build folder also
model.json, interfaces/<unit>.tif and possibly dsm.vtu and dsm.tif, whose vertical datum is
checked against model.vtu's. Prints `PASS name` or
`FAIL name: why` per check, then `N passed, M failed`; exits 1 if any failed. The reference is
model.vtu as meshio reads it; every other file is compared with it. See docs/geology.md.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from check_datum import check_vertical_datum
from vcommon import REL_DOUBLE, CheckFailed, close, meshio_read, model_dir_main, require, run_checks

HERE = Path(__file__).resolve().parent
TOL_OGS = 1e-9  # OpenGeoSys solutions: of the z range, and inflow + outflow of the inflow
F32 = 2.0**-23

# Outward faces of each cell type in each format's own node order, from the formats' docs:
# VTK (vtkTetra.cxx, vtkPyramid.cxx, vtkWedge.cxx faces; a wedge's first triangle faces away
# from its second), Gmsh (reference manual "Node ordering": the 6-node prism's 0 1 2 lies under
# 3 4 5, counter-clockwise seen from above).
VTK_FACES = {
    "tetra": [(0, 1, 3), (1, 2, 3), (2, 0, 3), (0, 2, 1)],
    "pyramid": [(0, 3, 2, 1), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
    "wedge": [(0, 1, 2), (3, 5, 4), (0, 3, 4, 1), (1, 4, 5, 2), (2, 5, 3, 0)],
}
GMSH_FACES = {
    "tetra": VTK_FACES["tetra"],
    "pyramid": VTK_FACES["pyramid"],
    "wedge": [(0, 2, 1), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)],
}
GMSH_TYPES = {4: "tetra", 7: "pyramid", 6: "wedge"}
VTK_TETRA, VTK_WEDGE, VTK_PYRAMID = 10, 13, 14


class Model:
    """The model directory, with model.vtu read once."""

    def __init__(self, root):
        self.root = Path(root)
        self._vtu = None
        self._raw = None

    def path(self, name):
        p = self.root / name
        require(p.is_file(), f"missing file {name}")
        require(p.stat().st_size > 0, f"empty file {name}")
        return p

    def vtu(self):
        """(points, [(type, cells)], MaterialIDs per block, unit names, crs)."""
        if self._vtu is None:
            m = meshio_read(self.path("model.vtu"))
            require(m.points.dtype == np.float64, f"model.vtu: points are {m.points.dtype}, not Float64")
            blocks = [(c.type, np.asarray(c.data, dtype=np.int64)) for c in m.cells]
            others = sorted({t for t, _ in blocks} - set(VTK_FACES))
            require(not others, f"model.vtu: unexpected cell types {others}")
            require("MaterialIDs" in m.cell_data, f"model.vtu: no MaterialIDs (cell data {sorted(m.cell_data)})")
            mats = m.cell_data["MaterialIDs"]
            require(all(a.dtype == np.int32 for a in mats), "model.vtu: MaterialIDs are not int32")
            fd = m.field_data
            require("unit_names" in fd and "crs" in fd, f"model.vtu: field data {sorted(fd)} lack unit_names, crs")
            names = bytes(np.asarray(fd["unit_names"], dtype=np.uint8)).decode().split("\0")
            require(names[-1] == "", "model.vtu: unit_names does not end with a zero byte")
            crs = bytes(np.asarray(fd["crs"], dtype=np.uint8)).decode()
            self.field_data = {k: bytes(np.asarray(v, dtype=np.uint8)).decode() for k, v in fd.items()
                               if k != "unit_names"}
            self._vtu = (m.points, blocks, [np.asarray(a).ravel() for a in mats], names[:-1], crs)
        return self._vtu

    def cells(self):
        """All cells in file order, as stored (VTK's node order, read by VTK's own reader, which
        reorders nothing; meshio turns wedges into Gmsh's order): list of (type, node tuple),
        and the materials."""
        if self._raw is None:
            import vtk
            from vtk.util.numpy_support import vtk_to_numpy
            r = vtk.vtkXMLUnstructuredGridReader()
            r.SetFileName(str(self.path("model.vtu")))
            r.Update()
            g = r.GetOutput()
            conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).astype(np.int64)
            offs = vtk_to_numpy(g.GetCells().GetOffsetsArray()).astype(np.int64)
            types = vtk_to_numpy(g.GetCellTypes())
            names = {VTK_TETRA: "tetra", VTK_PYRAMID: "pyramid", VTK_WEDGE: "wedge"}
            bad = sorted(set(types.tolist()) - set(names))
            require(not bad, f"model.vtu: VTK cell types {bad} besides tetra, pyramid, wedge")
            self._raw = [(names[t], tuple(conn[offs[i]:offs[i + 1]].tolist())) for i, t in enumerate(types.tolist())]
        _, _, mats, _, _ = self.vtu()
        return self._raw, np.concatenate(mats)

    def meshio_cells(self):
        """model.vtu's cells as meshio reads them (wedges in Gmsh's order)."""
        _, blocks, _, _, _ = self.vtu()
        return [(t, tuple(c)) for t, b in blocks for c in b.tolist()]


# ---------------------------------------------------------------- geometry


def polyhedron_volume(pts, faces):
    """Divergence theorem over outward faces (polygons fanned from their first node)."""
    o = pts[faces[0][0]]  # relative to one of its nodes: UTM magnitudes would cancel badly
    v = 0.0
    for f in faces:
        p0 = pts[f[0]] - o
        for k in range(1, len(f) - 1):
            v += np.dot(p0, np.cross(pts[f[k]] - o, pts[f[k + 1]] - o))
    return v / 6.0


def cell_volumes(pts, cells, table):
    return np.array([polyhedron_volume(pts, [[c[i] for i in f] for f in table[t]]) for t, c in cells])


def directed_edges(polys):
    d = {}
    for f in polys:
        for k in range(len(f)):
            e = (f[k], f[(k + 1) % len(f)])
            d[e] = d.get(e, 0) + 1
    return d


def balanced(polys, what):
    """Closed and consistently oriented: every directed edge as often as its reverse."""
    d = directed_edges(polys)
    bad = [e for e, n in d.items() if d.get((e[1], e[0]), 0) != n]
    require(d and not bad, f"{what}: not closed, {len(bad)} unbalanced directed edges, e.g. {bad[:3]}")


def faces_of(cells, table):
    """{sorted nodes: [(cell, outward node tuple)]}."""
    out = {}
    for i, (t, c) in enumerate(cells):
        for f in table[t]:
            nodes = tuple(c[k] for k in f)
            out.setdefault(tuple(sorted(nodes)), []).append((i, nodes))
    return out


def boundary_names(model):
    return sorted(p.name for p in model.root.glob("model-*.vtu"))


# ---------------------------------------------------------------- model.vtu


def check_vtu_cells(model):
    """model.vtu: every cell's volume positive (VTK's face orders), interior faces shared by
    exactly two cells, the boundary a closed surface, MaterialIDs within the unit names."""
    pts, _, _, names, crs = model.vtu()
    cells, mats = model.cells()
    require(len(names) >= 1 and all(names), f"model.vtu: unit_names {names}")
    require(crs.strip() != "", "model.vtu: empty crs")
    require(mats.min() >= 0 and mats.max() < len(names), f"model.vtu: MaterialIDs {mats.min()}..{mats.max()} "
            f"outside 0..{len(names) - 1}")
    vol = cell_volumes(pts, cells, VTK_FACES)
    k = int(np.argmin(vol))
    require(vol[k] > 0, f"model.vtu: cell {k} ({cells[k][0]}) has volume {vol[k]:.3g} in VTK's node order")
    faces = faces_of(cells, VTK_FACES)
    over = [k for k, v in faces.items() if len(v) > 2]
    require(not over, f"model.vtu: {len(over)} faces shared by more than two cells, e.g. {over[:2]}")
    for k, v in faces.items():
        if len(v) == 2:
            a, b = v[0][1], v[1][1]
            require(directed_edges([a]).keys().isdisjoint(directed_edges([b]).keys()),
                    f"model.vtu: face {k} has the same orientation in cells {v[0][0]} and {v[1][0]}")
    boundary = [v[0][1] for v in faces.values() if len(v) == 1]
    balanced(boundary, "model.vtu: boundary faces")
    # Total volume by the divergence theorem over the boundary equals the cells' sum.
    close(polyhedron_volume(pts, boundary), vol.sum(), REL_DOUBLE,
          "model.vtu: volume enclosed by the boundary vs the cells' sum")


def convex_pyramids(pts, cells, rel=1e-9):
    """The indices of the pyramids (VTK order: base 0-3, apex 4) that are not convex: a base
    more than `rel` of the cell's size from planar, or a node outside the plane of a face (its
    outward normal by VTK_FACES) by more than that."""
    bad = []
    for i, (t, c) in enumerate(cells):
        if t != "pyramid":
            continue
        q = pts[list(c)]
        q = q - q.mean(axis=0)  # UTM magnitudes would cancel in the cross products
        tol = rel * np.ptp(q, axis=0).max()
        for f in VTK_FACES["pyramid"]:
            f = list(f)
            ring = q[f]
            # Newell's normal: exact for a planar polygon, the mean plane of a warped one.
            n = sum(np.cross(ring[k], ring[(k + 1) % len(f)]) for k in range(len(f)))
            n = n / np.linalg.norm(n)
            d = (q - ring.mean(axis=0)) @ n
            if np.abs(d[f]).max() > tol or d.max() > tol:
                bad.append(i)
                break
    return bad


def check_vtu_vtk(model):
    """model.vtu read by VTK (ParaView's reader): points and MaterialIDs equal meshio's; VTK's
    vtkCellSizeFilter gives every tetrahedron and pyramid a positive volume equal to ours (1e-9)
    and vtkCellValidator finds them valid. Wedges: VTK's documentation, meshio and OpenGeoSys
    want a wedge's first triangle facing away from the second (what model.vtu holds), which
    VTK 9's own vtkCellSizeFilter and vtkCellValidator call inverted: for wedges only the size
    (VTK's volume up to its sign) is compared; OpenGeoSys' checkMesh rules on the order (next
    check)."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    pts, _, _, _, _ = model.vtu()
    cells, mats = model.cells()
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(model.path("model.vtu")))
    r.Update()
    g = r.GetOutput()
    require(g.GetNumberOfPoints() == len(pts) and g.GetNumberOfCells() == len(cells),
            f"model.vtu: VTK reads {g.GetNumberOfPoints()} points, {g.GetNumberOfCells()} cells")
    close(vtk_to_numpy(g.GetPoints().GetData()), pts, 0.0, "model.vtu: VTK's points vs meshio's")
    ids = vtk_to_numpy(g.GetCellData().GetArray("MaterialIDs"))
    require(np.array_equal(ids, mats), "model.vtu: VTK's MaterialIDs differ from meshio's")
    # Around the origin: VTK's tolerances are absolute, and UTM magnitudes cancel badly.
    local = vtk.vtkUnstructuredGrid()
    local.DeepCopy(g)
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(pts - pts.mean(axis=0), deep=True))
    local.SetPoints(p)
    f = vtk.vtkCellSizeFilter()
    f.SetInputData(local)
    f.Update()
    size = vtk_to_numpy(f.GetOutput().GetCellData().GetArray("Volume"))
    ours = cell_volumes(pts, cells, VTK_FACES)
    wedge = np.array([t == "wedge" for t, _ in cells])
    neg = np.nonzero((size <= 0) & ~wedge)[0]
    require(len(neg) == 0, f"model.vtu: vtkCellSizeFilter gives {len(neg)} tetrahedra or pyramids a non-positive "
            f"volume, e.g. cell {neg[:1]} {size[neg[:1]]}")
    close(np.where(wedge, np.abs(size), size), ours, 1e-9, "model.vtu: vtkCellSizeFilter's volumes vs ours",
          atol=1e-9 * np.abs(ours).max())
    v = vtk.vtkCellValidator()
    v.SetInputData(local)
    v.SetTolerance(1e-9)
    v.Update()
    state = vtk_to_numpy(v.GetOutput().GetCellData().GetArray("ValidityState"))
    # On a pyramid whose base is planar only to rounding (a vertical quad of two node
    # columns) or that is a sliver (a 5 cm edge on a cell 1.5 km across), VTK's convexity (16)
    # and edge-intersection (2) bits are rounding noise: the same sound cell is flagged or not
    # as it is scaled by 10, 300 or 1000 or the tolerance changes (tests/verify/
    # test_check_model.py). For pyramids those two bits are replaced by convex_pyramids (a
    # tolerance relative to the cell's size; a convex cell has no intersecting edges); every
    # other bit, and every bit of a tetrahedron, stands.
    pyramid = np.array([t == "pyramid" for t, _ in cells])
    state = np.where(pyramid, state & ~(16 | 2), state)
    nonconvex = convex_pyramids(pts, cells)
    require(not nonconvex, f"model.vtu: {len(nonconvex)} pyramids are not convex "
            f"(a point outside a face's plane by more than 1e-9 of the cell's size, or a base that is "
            f"not planar), e.g. cell {nonconvex[:1]}")
    bad = np.nonzero((state != 0) & ~wedge)[0]
    require(len(bad) == 0, f"model.vtu: vtkCellValidator flags {len(bad)} tetrahedra or pyramids, e.g. cell "
            f"{bad[:1]} state {state[bad[:1]]} (16: nonconvex, 32: faces oriented incorrectly)")


def check_vtu_ogs(model):
    """model.vtu by OpenGeoSys' checkMesh: no element with a wrong node order, non-convex or of
    zero volume, no hole, no unused node."""
    r = subprocess.run([ogs_tool("checkMesh"), "-v", str(model.path("model.vtu"))],
                       capture_output=True, text=True, timeout=600)
    log = r.stdout + r.stderr
    require(r.returncode == 0, f"checkMesh failed: {log[-600:]}")
    for what in ["wrong node order", "non-convex geometry", "zero volume", "non coplanar nodes"]:
        m = re.search(r"(\d+) elements? found with " + what, log)
        require(m is None, f"model.vtu: checkMesh: {m.group(0) if m else ''}")
    require("No holes found" in log, f"model.vtu: checkMesh finds holes: {log[-400:]}")
    m = re.search(r"(\d+) unused mesh nodes", log)
    require(m is None or int(m.group(1)) == 0, f"model.vtu: checkMesh: {m.group(0) if m else ''}")


# ---------------------------------------------------------------- boundary meshes


def extract_boundary(model, tmp):
    """OpenGeoSys' ExtractBoundary on model.vtu: {sorted bulk nodes: (bulk element, face id)}."""
    exe = ogs_tool("ExtractBoundary")
    out = Path(tmp) / "boundary.vtu"
    r = subprocess.run([exe, "-i", str(model.path("model.vtu")), "-o", str(out)],
                       capture_output=True, text=True, timeout=600)
    require(r.returncode == 0, f"ExtractBoundary failed: {(r.stdout + r.stderr)[-600:]}")
    b = meshio_read(out)
    bn = np.asarray(b.point_data["bulk_node_ids"], dtype=np.int64)
    ele = np.concatenate(b.cell_data["bulk_element_ids"])
    fid = np.concatenate(b.cell_data["bulk_face_ids"])
    faces = [tuple(bn[c]) for blk in b.cells for c in blk.data.tolist()]
    return {tuple(sorted(f)): (int(e), int(k)) for f, e, k in zip(faces, ele, fid)}


def check_boundary_meshes(model):
    """model-top/-bottom/-side-*.vtu: OpenGeoSys' array names and types, points equal to the bulk
    nodes, each face's bulk_element_ids and bulk_face_ids equal to what OpenGeoSys'
    ExtractBoundary writes for it, outward normals (top up, bottom down, sides horizontal), and
    together exactly the boundary of model.vtu."""
    pts, _, _, _, _ = model.vtu()
    names = boundary_names(model)
    require({"model-top.vtu", "model-bottom.vtu"} <= set(names), f"boundary meshes {names} lack top or bottom")
    require(any(n.startswith("model-side-") for n in names), f"no side boundary mesh among {names}")
    with tempfile.TemporaryDirectory() as tmp:
        ref = extract_boundary(model, tmp)
    seen = set()
    for name in names:
        b = meshio_read(model.path(name))
        for key, dt in [("bulk_node_ids", np.uint64)]:
            require(key in b.point_data and b.point_data[key].dtype == dt,
                    f"{name}: point data {key} ({dt.__name__}) missing or of another type")
        for key, dt in [("bulk_element_ids", np.uint64), ("bulk_face_ids", np.uint64), ("MaterialIDs", np.int32)]:
            require(key in b.cell_data and all(a.dtype == dt for a in b.cell_data[key]),
                    f"{name}: cell data {key} ({dt.__name__}) missing or of another type")
        bn = b.point_data["bulk_node_ids"].astype(np.int64)
        require(bn.max() < len(pts), f"{name}: bulk_node_ids beyond model.vtu's points")
        close(b.points, pts[bn], 0.0, f"{name}: points vs model.vtu's at bulk_node_ids")
        ele = np.concatenate(b.cell_data["bulk_element_ids"]).astype(np.int64)
        fid = np.concatenate(b.cell_data["bulk_face_ids"]).astype(np.int64)
        faces = [tuple(bn[c]) for blk in b.cells for c in blk.data.tolist()]
        for f, e, k in zip(faces, ele, fid):
            s = tuple(sorted(f))
            require(s in ref, f"{name}: face {f} is not on the boundary of model.vtu (ExtractBoundary)")
            require(ref[s] == (e, k), f"{name}: face {f} has bulk element/face {(e, k)}, ExtractBoundary "
                    f"says {ref[s]}")
            require(s not in seen, f"{name}: face {f} in two boundary meshes")
            seen.add(s)
            p = pts[list(f)]
            n = sum(np.cross(p[i] - p[0], p[i + 1] - p[0]) for i in range(1, len(f) - 1))
            n = n / np.linalg.norm(n)
            if name == "model-top.vtu":
                require(n[2] > 0, f"{name}: face {f} does not face up")
            elif name == "model-bottom.vtu":
                require(n[2] < 0, f"{name}: face {f} does not face down")
            elif name == "model-side-structures.vtu":
                # A structure's exposed surface above the terrain (a dam's faces and crest):
                # any orientation; being on the boundary, once, is checked above.
                pass
            else:
                want = {"north": (0, 1), "south": (0, -1), "east": (1, 0), "west": (-1, 0)}.get(name[11:-4])
                require(abs(n[2]) < 1e-9, f"{name}: face {f} is not vertical")
                if want:
                    require(np.dot(n[:2], want) > 0.999, f"{name}: face {f} does not face {name[11:-4]}")
    missing = set(ref) - seen
    require(not missing, f"{len(missing)} boundary faces of model.vtu are in no boundary mesh, e.g. {list(missing)[:2]}")


# ---------------------------------------------------------------- Gmsh


def check_msh_meshio(model):
    """model.msh (meshio): points and cells equal model.vtu's (meshio reads both into its order:
    Gmsh's prism is VTK's wedge with each triangle reversed), volumes positive in Gmsh's order, gmsh:physical = MaterialIDs + 1
    with the units' names, and a named surface group per boundary mesh."""
    pts, _, _, names, _ = model.vtu()
    cells, mats = model.cells()
    m = meshio_read(model.path("model.msh"))
    close(m.points, pts, 0.0, "model.msh: points vs model.vtu")
    phys = m.cell_data.get("gmsh:physical")
    require(phys is not None, "model.msh: no physical groups")
    vol_cells, vol_phys = [], []
    for blk, p in zip(m.cells, phys):
        if blk.type in GMSH_FACES:
            vol_cells += [(blk.type, tuple(c)) for c in blk.data.tolist()]
            vol_phys.append(np.asarray(p))
    require(len(vol_cells) == len(cells), f"model.msh: {len(vol_cells)} volume elements, model.vtu has {len(cells)}")
    vol = cell_volumes(m.points, vol_cells, GMSH_FACES)
    require(vol.min() > 0, f"model.msh: element {int(np.argmin(vol))} has volume {vol.min():.3g} in Gmsh's order")
    gm = {tuple(sorted(c)): (t, c, ph) for (t, c), ph in zip(vol_cells, np.concatenate(vol_phys))}
    for (t, c), mat in zip(model.meshio_cells(), mats):
        got = gm.get(tuple(sorted(c)))
        require(got is not None, f"model.msh: no element with the nodes of model.vtu's {t} {c}")
        require(got[:2] == (t, c), f"model.msh: {got[0]} {got[1]} is not model.vtu's {t} {c} (both in meshio's order)")
        require(got[2] == mat + 1, f"model.msh: element {c} in physical volume {got[2]}, MaterialID {mat}")
    fd = {k: tuple(int(x) for x in v) for k, v in m.field_data.items()}
    for u, n in enumerate(names):
        if (mats == u).any():
            require(fd.get(n) == (u + 1, 3), f"model.msh: physical volume of unit {n!r}: {fd.get(n)}, want {(u + 1, 3)}")
    for b in boundary_names(model):
        tag = {"model-top.vtu": "top", "model-bottom.vtu": "bottom"}.get(b, b[11:-4])
        require(tag in fd and fd[tag][1] == 2, f"model.msh: no physical surface {tag!r} (has {sorted(fd)})")


def check_msh_gmsh(model):
    """model.msh opened by Gmsh: every volume element's Jacobian positive at Gauss points, each
    physical volume named after its unit with the volume of that unit's cells (1e-9), surface
    groups with the areas of the boundary meshes."""
    import gmsh
    pts, _, _, names, _ = model.vtu()
    cells, mats = model.cells()
    vol = cell_volumes(pts, cells, VTK_FACES)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        try:
            gmsh.open(str(model.path("model.msh")))
        except Exception as e:
            raise CheckFailed(f"model.msh: Gmsh cannot open it: {e}")
        errors = [x for x in gmsh.logger.get() if x.startswith("Error")]
        require(not errors, f"model.msh: Gmsh: {' | '.join(errors)[:600]}")
        groups = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            groups[(dim, gmsh.model.getPhysicalName(dim, tag))] = (tag, gmsh.model.getEntitiesForPhysicalGroup(dim, tag))
        for u, n in enumerate(names):
            if not (mats == u).any():
                continue
            require((3, n) in groups, f"model.msh: Gmsh finds no physical volume {n!r} ({sorted(groups)})")
            total = 0.0
            for ent in groups[(3, n)][1]:
                types, _, _ = gmsh.model.mesh.getElements(3, ent)
                for t in types:
                    lc, w = gmsh.model.mesh.getIntegrationPoints(int(t), "Gauss2")
                    _, det, _ = gmsh.model.mesh.getJacobians(int(t), lc, ent)
                    det = np.asarray(det).reshape(-1, len(w))
                    require(det.min() > 0, f"model.msh: Gmsh finds a non-positive Jacobian in unit {n!r} "
                            f"({GMSH_TYPES.get(int(t), t)})")
                    total += float((det * np.asarray(w)).sum())
            close(total, vol[mats == u].sum(), 1e-9, f"model.msh: Gmsh's volume of {n!r} vs model.vtu's cells")
        for b in boundary_names(model):
            tag = {"model-top.vtu": "top", "model-bottom.vtu": "bottom"}.get(b, b[11:-4])
            require((2, tag) in groups, f"model.msh: Gmsh finds no physical surface {tag!r}")
    finally:
        gmsh.logger.stop()
        gmsh.finalize()


# ---------------------------------------------------------------- FLAC3D


def check_f3grid(model):
    """model.f3grid: meshio reads it, with model.vtu's points and the node sets of its cells;
    in the file every zone's first four gridpoints are right-handed (FLAC3D's rule), a W6's
    vertical edges are 0-2, 1-4, 3-5 and a P5's base is 0 1 4 2 (FLAC3D's zone shapes); a zone
    group per unit holds exactly its cells, a face group per boundary mesh."""
    pts, _, _, names, _ = model.vtu()
    cells, mats = model.cells()
    m = meshio_read(model.path("model.f3grid"))
    close(m.points, pts, 0.0, "model.f3grid: points vs model.vtu")
    zc = [(b.type, tuple(sorted(c))) for b in m.cells if b.type in VTK_FACES for c in b.data.tolist()]
    require(len(zc) == len(cells), f"model.f3grid: {len(zc)} zones, model.vtu has {len(cells)} cells")
    require(zc == [(t, tuple(sorted(c))) for t, c in cells], "model.f3grid: zones differ from model.vtu's cells")
    gp = {}
    for line in model.path("model.f3grid").read_text().splitlines():
        s = line.split()
        if s and s[0] == "G":
            gp[int(s[1])] = np.array([float(v) for v in s[2:5]])
        elif s and s[0] == "Z":
            p = [gp[int(v)] for v in s[3:]]
            det = np.dot(p[1] - p[0], np.cross(p[2] - p[0], p[3] - p[0]))
            require(det > 0, f"model.f3grid: zone {s[2]} ({s[1]}) is not right-handed")
            vertical = {"W6": [(0, 2), (1, 4), (3, 5)], "P5": [], "T4": []}[s[1]]
            for a, b in vertical:
                require(np.allclose(p[a][:2], p[b][:2], rtol=0, atol=1e-9) and p[b][2] >= p[a][2],
                        f"model.f3grid: zone {s[2]} (W6): gridpoint {b} is not above {a}")
            if s[1] == "P5":
                q = [p[0], p[1], p[4], p[2]]
                n = np.cross(q[1] - q[0], q[3] - q[0])
                require(abs(np.dot(n, q[2] - q[0])) <= 1e-9 * np.linalg.norm(n) * np.linalg.norm(q[2] - q[0]),
                        f"model.f3grid: zone {s[2]} (P5): 0 1 4 2 is not a planar base")
    zone_sets = {k.split(":")[1]: np.concatenate(v) for k, v in m.cell_sets.items() if k.startswith("zone:")}
    face_sets = {k.split(":")[1] for k in m.cell_sets if k.startswith("face:")}
    nface = sum(len(b.data) for b in m.cells if b.type not in VTK_FACES)
    for u, n in enumerate(names):
        if (mats == u).any():
            require(n in zone_sets, f"model.f3grid: no zone group {n!r} ({sorted(zone_sets)})")
            require(np.array_equal(np.sort(zone_sets[n] - nface), np.nonzero(mats == u)[0]),
                    f"model.f3grid: zone group {n!r} is not the cells of MaterialID {u}")
    for b in boundary_names(model):
        tag = {"model-top.vtu": "top", "model-bottom.vtu": "bottom"}.get(b, b[11:-4])
        require(tag in face_sets, f"model.f3grid: no face group {tag!r} ({sorted(face_sets)})")


# ---------------------------------------------------------------- bodies


def read_tsurf(path):
    v, t = {}, []
    for line in path.read_text().splitlines():
        s = line.split()
        if s and s[0] in ("VRTX", "PVRTX"):
            v[int(s[1])] = [float(x) for x in s[2:5]]
        elif s and s[0] == "TRGL":
            t.append(tuple(int(x) for x in s[1:4]))
    require(v and t, f"{path.name}: no vertices or triangles")
    keys = sorted(v)
    idx = {k: i for i, k in enumerate(keys)}
    require(all(k in idx for tr in t for k in tr), f"{path.name}: a triangle refers to a missing vertex")
    return np.array([v[k] for k in keys]), [tuple(idx[k] for k in tr) for tr in t]


def check_bodies(model):
    """unit-<name>.ts: closed and consistently oriented (an edge where the unit pinches out may
    carry four triangles, balanced), enclosed volume = the unit's cells' volume to 1e-9
    relative, vertices among model.vtu's points; unit-<name>.stl (meshio, float32 + the origin
    in its header) the same triangles to float32 rounding and the same volume to 1e-6."""
    import meshio
    pts, _, _, names, _ = model.vtu()
    cells, mats = model.cells()
    vol = cell_volumes(pts, cells, VTK_FACES)
    lookup = {tuple(p): i for i, p in enumerate(pts.tolist())}
    for u, n in enumerate(names):
        want = vol[mats == u].sum()
        if want == 0:
            continue
        v, t = read_tsurf(model.path(f"unit-{n}.ts"))
        ids = [lookup.get(tuple(p)) for p in v.tolist()]
        require(None not in ids, f"unit-{n}.ts: a vertex is not a point of model.vtu")
        gt = [tuple(ids[k] for k in tr) for tr in t]
        balanced(gt, f"unit-{n}.ts")
        close(polyhedron_volume(pts, gt), want, 1e-9, f"unit-{n}.ts: enclosed volume vs the unit's cells")
        p = model.path(f"unit-{n}.stl")
        head = p.read_bytes()[:80].decode("ascii", "replace")
        mo = re.search(r"origin (\S+) (\S+) (\S+)", head)
        require(mo is not None, f"unit-{n}.stl: header names no origin: {head.strip()!r}")
        origin = np.array([float(x) for x in mo.groups()])
        s = meshio.read(p, file_format="stl")
        tri = np.vstack([b.data for b in s.cells if b.type == "triangle"])
        require(len(tri) == len(t), f"unit-{n}.stl: {len(tri)} triangles, unit-{n}.ts has {len(t)}")
        local = v[np.array(t)] - origin
        got = s.points.astype(np.float64)[tri]
        require(np.all(np.abs(got - local) <= 2 * F32 * np.maximum(np.abs(local), 1e-30)),
                f"unit-{n}.stl: triangles differ from unit-{n}.ts beyond float32 rounding")
        sv = polyhedron_volume(s.points.astype(np.float64) + origin, tri.tolist())
        close(sv, want, 1e-6, f"unit-{n}.stl: enclosed volume vs the unit's cells")


# ---------------------------------------------------------------- OpenGeoSys


def ogs_tool(name):
    exe = shutil.which(name, path=os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")]))
    require(exe is not None, f"{name} not found: pip install ogs (see tests/verify/requirements.txt)")
    return exe


def run_ogs(model, prj, tmp, extra=None):
    """Runs `ogs` on the project `prj` of tests/verify/ogs/ with the model's meshes copied beside
    it; returns the last output .vtu read by meshio."""
    tmp = Path(tmp)
    for f in ["model.vtu"] + boundary_names(model):
        shutil.copy(model.path(f), tmp / f)
    text = (HERE / "ogs" / prj).read_text()
    for k, v in (extra or {}).items():
        text = text.replace(k, v)
    (tmp / prj).write_text(text)
    r = subprocess.run([ogs_tool("ogs"), "-o", str(tmp / "out"), str(tmp / prj)], cwd=tmp,
                       capture_output=True, text=True, timeout=600)
    log = (r.stdout + r.stderr).strip()
    require(r.returncode == 0, f"ogs {prj} failed: {log[-800:]}")
    outs = sorted((tmp / "out").glob("*.vtu"), key=lambda p: p.stat().st_mtime)
    require(outs, f"ogs {prj} wrote no .vtu: {log[-400:]}")
    return meshio_read(outs[-1])


def check_ogs_diffusion(model):
    """OpenGeoSys steady-state diffusion on model.vtu, homogeneous conductivity, u = z on
    model-top and model-bottom (and on a structure's exposed surface above the terrain,
    model-side-structures, where there is one: it is not vertical, so no flow through it would
    not be u = z), no flow through the vertical sides: the exact solution u = z holds at every
    node to 1e-9 of the z range."""
    pts, _, _, names, _ = model.vtu()
    media = "".join(
        f"<medium id=\"{k}\"><properties>"
        "<property><name>diffusion</name><type>Constant</type><value>1</value></property>"
        "<property><name>reference_temperature</name><type>Constant</type><value>293.15</value></property>"
        "</properties></medium>" for k in range(len(names)))
    extra = {"<!--MEDIA-->": media}
    if "model-side-structures.vtu" in boundary_names(model):
        extra["<mesh>model-bottom.vtu</mesh>"] = (
            "<mesh>model-bottom.vtu</mesh><mesh>model-side-structures.vtu</mesh>")
        extra["</boundary_conditions>"] = (
            "<boundary_condition><mesh>model-side-structures</mesh><type>Dirichlet</type>"
            "<parameter>z</parameter></boundary_condition></boundary_conditions>")
    with tempfile.TemporaryDirectory() as tmp:
        out = run_ogs(model, "diffusion.prj", tmp, extra)
    require("pressure" in out.point_data, f"ogs output lacks 'pressure' ({sorted(out.point_data)})")
    u = np.asarray(out.point_data["pressure"]).ravel()
    zr = np.ptp(pts[:, 2])
    err = np.abs(u - out.points[:, 2]).max()
    require(err <= TOL_OGS * zr, f"ogs diffusion: max |u - z| = {err:.3g}, more than {TOL_OGS} x z range {zr:.3g}")


def check_ogs_heat(model):
    """OpenGeoSys heat conduction with a different conductivity per MaterialIDs, T = 1 on
    model-top and 0 on model-bottom, sides insulated: it solves, the temperature stays within
    [0, 1], and the nodal heat flow into the top equals the flow out of the bottom to 1e-9."""
    _, _, _, names, _ = model.vtu()
    lam = [1.0, 0.2, 3.0, 0.5, 2.0, 0.7, 1.5, 4.0]
    media = "".join(
        f"<medium id=\"{k}\"><properties>"
        f"<property><name>thermal_conductivity</name><type>Constant</type><value>{lam[k % len(lam)]}</value></property>"
        "<property><name>specific_heat_capacity</name><type>Constant</type><value>0</value></property>"
        "<property><name>density</name><type>Constant</type><value>1</value></property>"
        "</properties></medium>" for k in range(len(names)))
    with tempfile.TemporaryDirectory() as tmp:
        out = run_ogs(model, "heat.prj", tmp, {"<!--MEDIA-->": media})
        top = meshio_read(Path(tmp) / "model-top.vtu").point_data["bulk_node_ids"].astype(np.int64)
        bot = meshio_read(Path(tmp) / "model-bottom.vtu").point_data["bulk_node_ids"].astype(np.int64)
    require("temperature" in out.point_data, f"ogs output lacks 'temperature' ({sorted(out.point_data)})")
    flow = [k for k in out.point_data if k.lower().replace("_", "") == "heatflowrate"]
    require(flow, f"ogs output lacks the nodal heat flow rate ({sorted(out.point_data)})")
    T = np.asarray(out.point_data["temperature"]).ravel()
    require(T.min() >= -1e-9 and T.max() <= 1 + 1e-9, f"ogs heat: temperature outside [0, 1]: {T.min()}..{T.max()}")
    q = np.asarray(out.point_data[flow[0]]).ravel()
    qin, qout = q[top].sum(), q[bot].sum()
    require(abs(qin) > 0, "ogs heat: no heat flows")
    require(abs(qin + qout) <= TOL_OGS * abs(qin), f"ogs heat: inflow {qin:.12g} + outflow {qout:.12g} "
            f"= {qin + qout:.3g}, more than {TOL_OGS} of the inflow")


CHECKS = [
    ("model.vtu: cells, faces, closed boundary", check_vtu_cells),
    ("vertical datum: model.vtu, model.json, dsm.vtu, grids", check_vertical_datum),
    ("model.vtu: VTK reader, vtkCellValidator", check_vtu_vtk),
    ("model.vtu: OpenGeoSys checkMesh", check_vtu_ogs),
    ("boundary meshes vs ExtractBoundary", check_boundary_meshes),
    ("model.msh (meshio)", check_msh_meshio),
    ("model.msh (gmsh)", check_msh_gmsh),
    ("model.f3grid (meshio)", check_f3grid),
    ("bodies: ts, stl", check_bodies),
    ("ogs: steady diffusion u = z", check_ogs_diffusion),
    ("ogs: heat conduction per MaterialIDs", check_ogs_heat),
]


def run(model_dir, only=None):
    """Runs the checks, prints a line each, returns (passed, failed)."""
    model = Model(model_dir)
    import check_model_glb  # model.glb's checks, when the build wrote one
    glb = check_model_glb.CHECKS if check_model_glb.glb_present(model) else []
    return run_checks(CHECKS + glb, model, only)


def main(argv=None):
    return model_dir_main(__doc__, run, argv)


if __name__ == "__main__":
    sys.exit(main())
