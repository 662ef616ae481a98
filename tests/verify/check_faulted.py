"""Checks a faulted geological model's fault outputs (issue 31) with readers that share no code
with terramesh: meshio, Gmsh's own API and OpenGeoSys' ExtractBoundary and checkMesh.

    python tests/verify/check_faulted.py MODEL_DIR [--only NAME]

MODEL_DIR holds what terramesh_io::model::write_faulted_model writes: model.vtu with int32
`block` beside `MaterialIDs` and field data `fault_names`, `block_names`; per fault
fault-<name>.vtu (every face once from each side, with OpenGeoSys' bulk_node_ids,
bulk_element_ids, bulk_face_ids) and fault-<name>.ts; model.msh with a physical surface
fault-<name> per fault; model.f3grid with face groups fault-<name> and a zone group per block
(slot 2); a fault zone's cells, if any, the material `zone-<fault>` of unit_names. The rest of the model (cells, boundary meshes, bodies, ogs) is check_model.py's.
Prints `PASS name` or `FAIL name: why` per check, then `N passed, M failed`; exits 1 if any
failed. See docs/geology.md, "Faulted model files".
"""

import sys
import tempfile

import numpy as np

from check_model import (VTK_FACES, Model, cell_volumes, check_vtu_ogs, extract_boundary, faces_of,
                         read_tsurf)
from vcommon import CheckFailed, close, meshio_read, model_dir_main, require, run_checks


def names(fd, key):
    require(key in fd, f"model.vtu: no field data {key!r} ({sorted(fd)})")
    s = bytes(np.asarray(fd[key], dtype=np.uint8)).decode().split("\0")
    require(s[-1] == "", f"model.vtu: {key} does not end with a zero byte")
    return s[:-1]


class Faulted:
    """model.vtu read once by meshio: points, cells (meshio order), MaterialIDs, block, names."""

    def __init__(self, root):
        self.model = Model(root)
        m = meshio_read(self.model.path("model.vtu"))
        for key in ("MaterialIDs", "block"):
            require(key in m.cell_data, f"model.vtu: no cell data {key!r} ({sorted(m.cell_data)})")
            require(all(a.dtype == np.int32 for a in m.cell_data[key]), f"model.vtu: {key} is not int32")
        self.points = m.points
        self.cells = [(c.type, tuple(x)) for c in m.cells for x in c.data.tolist()]
        self.mats = np.concatenate([np.asarray(a).ravel() for a in m.cell_data["MaterialIDs"]])
        self.block = np.concatenate([np.asarray(a).ravel() for a in m.cell_data["block"]])
        self.units = names(m.field_data, "unit_names")
        self.faults = names(m.field_data, "fault_names")
        self.blocks = names(m.field_data, "block_names")


def check_vtu_block(f):
    """model.vtu: int32 block per cell, an index into block_names; every block has cells; fault
    names given."""
    require(len(f.block) == len(f.cells), "model.vtu: block is not one per cell")
    require(f.block.min() >= 0 and f.block.max() < len(f.blocks),
            f"model.vtu: block {f.block.min()}..{f.block.max()} beyond the {len(f.blocks)} block_names")
    empty = [b for i, b in enumerate(f.blocks) if not (f.block == i).any()]
    require(not empty, f"model.vtu: blocks without cells: {empty}")
    require(f.faults, "model.vtu: fault_names is empty")


def fault_mesh(f, name):
    """fault-<name>.vtu by meshio: its arrays' names and types checked; returns (faces as bulk
    node tuples, bulk element ids, bulk face ids, sides, blocks)."""
    p = f.model.path(f"fault-{name}.vtu")
    b = meshio_read(p)
    require("bulk_node_ids" in b.point_data and b.point_data["bulk_node_ids"].dtype == np.uint64,
            f"{p.name}: point data bulk_node_ids (uint64) missing or of another type")
    for key, dt in [("bulk_element_ids", np.uint64), ("bulk_face_ids", np.uint64), ("MaterialIDs", np.int32),
                    ("block", np.int32), ("side", np.int32)]:
        require(key in b.cell_data and all(a.dtype == dt for a in b.cell_data[key]),
                f"{p.name}: cell data {key} ({dt.__name__}) missing or of another type")
    bn = b.point_data["bulk_node_ids"].astype(np.int64)
    require(bn.max() < len(f.points), f"{p.name}: bulk_node_ids beyond model.vtu's points")
    close(b.points, f.points[bn], 0.0, f"{p.name}: points vs model.vtu's at bulk_node_ids")
    faces = [tuple(bn[c]) for blk in b.cells for c in blk.data.tolist()]
    cat = lambda k: np.concatenate([np.asarray(a).ravel() for a in b.cell_data[k]]).astype(np.int64)
    return faces, cat("bulk_element_ids"), cat("bulk_face_ids"), cat("side"), cat("block"), cat("MaterialIDs")


def check_fault_meshes(f):
    """fault-<name>.vtu: every face a face of its bulk element (nodes counter-clockwise seen from
    outside it, VTK's face order), with that element's block and material; sides 0 and 1 in
    equal numbers, the k-th face of side 1 the k-th of side 0 seen from the other side (same
    points, reverse order) in another cell of another block."""
    table = faces_of(f.cells, VTK_FACES)
    outward = {}
    for key, lst in table.items():
        for i, nodes in lst:
            outward[(i, tuple(sorted(nodes)))] = nodes
    for name in f.faults:
        faces, ele, fid, side, blk, mat = fault_mesh(f, name)
        require(len(faces) > 0, f"fault-{name}.vtu: no faces")
        for face, e in zip(faces, ele):
            got = outward.get((int(e), tuple(sorted(face))))
            require(got is not None, f"fault-{name}.vtu: face {face} is not a face of cell {e}")
            k = got.index(face[0])
            require(tuple(got[k:] + got[:k]) == tuple(face),
                    f"fault-{name}.vtu: face {face} is not counter-clockwise seen from outside cell {e}")
        require(np.array_equal(blk, f.block[ele]), f"fault-{name}.vtu: block differs from its cells'")
        require(np.array_equal(mat, f.mats[ele]), f"fault-{name}.vtu: MaterialIDs differ from its cells'")
        n = len(faces) // 2
        require(len(faces) == 2 * n and (side[:n] == 0).all() and (side[n:] == 1).all(),
                f"fault-{name}.vtu: not every face once per side (side 0 then side 1)")
        for a, b, ea, eb in zip(faces[:n], faces[n:], ele[:n], ele[n:]):
            pa, pb = f.points[list(a)], f.points[list(b)][::-1]
            ok = any(np.array_equal(pa, np.roll(pb, s, axis=0)) for s in range(len(a)))
            require(ok, f"fault-{name}.vtu: face {a} of cell {ea} and face {b} of cell {eb} are not one face")
            require(ea != eb and f.block[ea] != f.block[eb],
                    f"fault-{name}.vtu: cells {ea} and {eb} on its two sides are in one block")


def check_fault_ogs(f):
    """fault-<name>.vtu's bulk_element_ids and bulk_face_ids are OpenGeoSys': for a model with
    split nodes (the faults opened, so that their faces are on the boundary), each fault face of
    both sides is on the boundary that ExtractBoundary extracts, with its bulk element and face
    number; without split nodes, where no fault face is on the boundary, checkMesh is clean."""
    with tempfile.TemporaryDirectory() as tmp:
        ref = extract_boundary(f.model, tmp)
    split = False
    for name in f.faults:
        faces, ele, fid, _, _, _ = fault_mesh(f, name)
        on = [tuple(sorted(x)) in ref for x in faces]
        if not any(on):
            continue
        split = True
        n = len(faces) // 2
        opened = sum(on[:n])
        require(opened > 0, f"fault-{name}.vtu: no face opened")
        for face, e, k, o in zip(faces, ele, fid, on):
            if o:
                require(ref[tuple(sorted(face))] == (int(e), int(k)),
                        f"fault-{name}.vtu: face {face} has bulk element/face {(int(e), int(k))}, "
                        f"ExtractBoundary says {ref[tuple(sorted(face))]}")
    if not split:
        check_vtu_ogs(f.model)


def check_fault_tsurf(f):
    """fault-<name>.ts: the triangles of fault-<name>.vtu's side 0 (same points, same
    orientation)."""
    for name in f.faults:
        faces, _, _, _, _, _ = fault_mesh(f, name)
        n = len(faces) // 2
        v, t = read_tsurf(f.model.path(f"fault-{name}.ts"))
        canon = lambda tri: min(tuple(map(tuple, np.roll(tri, s, axis=0))) for s in range(3))
        got = sorted(canon(v[list(x)]) for x in t)
        want = sorted(canon(f.points[list(x)]) for x in faces[:n])
        require(len(got) == len(want) and got == want, f"fault-{name}.ts: {len(got)} triangles differ from "
                f"fault-{name}.vtu's {len(want)} faces of side 0")


def check_f3grid_groups(f):
    """model.f3grid (meshio): a face group fault-<name> per fault with its faces (the nodes of
    fault-<name>.vtu's side 0), a zone group per block in slot 2 with exactly its cells."""
    m = meshio_read(f.model.path("model.f3grid"))
    nface = sum(len(b.data) for b in m.cells if b.type not in VTK_FACES)
    blocks = [(b.type, b.data) for b in m.cells]
    flat = [tuple(sorted(c)) for t, d in blocks for c in d.tolist()]
    for name in f.faults:
        key = f"face:fault-{name}:1"
        require(key in m.cell_sets, f"model.f3grid: no face group fault-{name} ({sorted(m.cell_sets)})")
        ids = np.concatenate(m.cell_sets[key])
        faces, _, _, _, _, _ = fault_mesh(f, name)
        want = sorted(tuple(sorted(x)) for x in faces[:len(faces) // 2])
        require(sorted(flat[i] for i in ids) == want, f"model.f3grid: face group fault-{name} is not its faces")
    for b, name in enumerate(f.blocks):
        key = f"zone:{name}:2"
        require(key in m.cell_sets, f"model.f3grid: no zone group {name!r} in slot 2")
        ids = np.sort(np.concatenate(m.cell_sets[key])) - nface
        require(np.array_equal(ids, np.nonzero(f.block == b)[0]), f"model.f3grid: zone group {name!r} is not block {b}")


def check_msh_faults(f):
    """model.msh opened by Gmsh: a physical surface fault-<name> (dimension 2) per fault whose
    area is fault-<name>.ts's, a physical volume (dimension 3) per unit, and the volumes of the
    physical volumes (Gmsh's Jacobians) summing to model.vtu's to 1e-9."""
    import gmsh
    vol = cell_volumes(f.points, f.cells, VTK_FACES)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        try:
            gmsh.open(str(f.model.path("model.msh")))
        except Exception as e:
            raise CheckFailed(f"model.msh: Gmsh cannot open it: {e}")
        errors = [x for x in gmsh.logger.get() if x.startswith("Error")]
        require(not errors, f"model.msh: Gmsh: {' | '.join(errors)[:600]}")
        groups = {(d, gmsh.model.getPhysicalName(d, t)): t for d, t in gmsh.model.getPhysicalGroups()}

        def integral(dim, tag):
            total = 0.0
            for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                types, _, _ = gmsh.model.mesh.getElements(dim, ent)
                for t in types:
                    lc, w = gmsh.model.mesh.getIntegrationPoints(int(t), "Gauss2")
                    _, det, _ = gmsh.model.mesh.getJacobians(int(t), lc, ent)
                    det = np.asarray(det).reshape(-1, len(w))
                    require(det.min() > 0, f"model.msh: a non-positive Jacobian in group {dim}/{tag}")
                    total += float((det * np.asarray(w)).sum())
            return total

        total = 0.0
        for u, n in enumerate(f.units):
            if (f.mats == u).any():
                require((3, n) in groups, f"model.msh: Gmsh finds no physical volume {n!r} ({sorted(groups)})")
                total += integral(3, groups[(3, n)])
        close(total, vol.sum(), 1e-9, "model.msh: Gmsh's volume of all units vs model.vtu's cells")
        for name in f.faults:
            g = (2, f"fault-{name}")
            require(g in groups, f"model.msh: Gmsh finds no physical surface fault-{name} ({sorted(groups)})")
            require((3, f"fault-{name}") not in groups, f"model.msh: fault-{name} is a volume")
            v, t = read_tsurf(f.model.path(f"fault-{name}.ts"))
            area = sum(0.5 * np.linalg.norm(np.cross(v[b] - v[a], v[c] - v[a])) for a, b, c in t)
            close(integral(2, groups[g]), area, 1e-9, f"model.msh: Gmsh's area of fault-{name} vs fault-{name}.ts")
    finally:
        gmsh.logger.stop()
        gmsh.finalize()


def point_triangle(p, tri):
    """Distance of points p (n, 3) to triangles tri (m, 3, 3): (n, m) distances and whether the
    nearest point lies strictly inside the triangle (the point's projection on its plane)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    nn = np.einsum("ij,ij->i", n, n)
    w = p[:, None, :] - a[None]
    h = np.einsum("nmk,mk->nm", w, n) / np.sqrt(nn)
    q = p[:, None, :] - (h / np.sqrt(nn))[..., None] * n[None]
    # barycentric signs of the projection: the three sub-triangles' normals against n
    inside = np.ones(h.shape, dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("nmk,mk->nm", np.cross(v[None] - u[None], q - u[None]), n) > 0
    def seg(u, v):
        d = v - u
        t = np.clip(np.einsum("nmk,mk->nm", p[:, None, :] - u[None], d) / np.einsum("ij,ij->i", d, d), 0, 1)
        return np.linalg.norm(p[:, None, :] - (u[None] + t[..., None] * d[None]), axis=2)
    edge = np.minimum(np.minimum(seg(a, b), seg(b, c)), seg(c, a))
    return np.where(inside, np.abs(h), edge), inside


def fault_distances(points, tri, reach):
    """Per point: the distance to the nearest of the triangles tri (inf beyond `reach` of every
    triangle's bounding box) and whether that nearest point lies inside a triangle. Triangles
    are binned in a grid of cubes of their median size, each in every cube its box grown by
    `reach` meets; a point is tested against its cube's triangles only."""
    size = max(float(np.median(np.linalg.norm(tri[:, 1] - tri[:, 0], axis=1))), reach, 1e-6)
    lo, hi = tri.min(axis=1) - reach, tri.max(axis=1) + reach
    bins = {}
    for i, (l, h) in enumerate(zip(np.floor(lo / size).astype(np.int64), np.floor(hi / size).astype(np.int64))):
        for x in range(l[0], h[0] + 1):
            for y in range(l[1], h[1] + 1):
                for z in range(l[2], h[2] + 1):
                    bins.setdefault((x, y, z), []).append(i)
    key = np.floor(points / size).astype(np.int64)
    dist = np.full(len(points), np.inf)
    inside = np.zeros(len(points), dtype=bool)
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.ravel()
    order = np.argsort(inv, kind="stable")
    starts = np.searchsorted(inv[order], np.arange(len(uniq) + 1))
    for g, k in enumerate(map(tuple, uniq.tolist())):
        cand = bins.get(k)
        if not cand:
            continue
        idx = order[starts[g]:starts[g + 1]]
        d, ins = point_triangle(points[idx], tri[cand])
        j = np.argmin(d, axis=1)
        dist[idx] = d[np.arange(len(idx)), j]
        inside[idx] = ins[np.arange(len(idx)), j]
    return dist, inside


def tet_volumes(pts, cells):
    v = np.array([c for _, c in cells], dtype=np.int64)
    a, b, c, d = (pts[v[:, k]] for k in range(4))
    return np.abs(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)) / 6.0


def check_zones(f):
    """Fault zones (materials `zone-<fault>` in unit_names): each a slab along fault-<fault>.ts,
    read from the files alone. Its thickness w is twice the largest distance of its cells'
    nodes from the fault's triangles, of the nodes over the inside of a triangle (the nodes on
    its walls; beyond the fault's edges, on the terrain, the distance to the nearest edge is
    larger); its cells lie on both sides of
    the fault (two blocks or more); every cell whose centroid lies over the inside of a fault
    triangle less than w/2 − 1 cm from it is in a zone; the volume of the zone cells whose
    centroids lie within w/2 of the fault (w beyond its edges) is w times the fault's area within 5 %. A model
    without zones passes."""
    zones = [(m, n[len("zone-"):]) for m, n in enumerate(f.units) if n.startswith("zone-")]
    if not zones:
        return
    require(all(t == "tetra" for t, _ in f.cells), "zones: the model has cells other than tetrahedra")
    v = np.array([c for _, c in f.cells], dtype=np.int64)
    cen = f.points[v].mean(axis=1)
    vol = tet_volumes(f.points, f.cells)
    in_zone = np.isin(f.mats, [m for m, _ in zones])
    for mat, name in zones:
        require(name in f.faults, f"model.vtu: material zone-{name} names no fault of fault_names")
        tv, tt = read_tsurf(f.model.path(f"fault-{name}.ts"))
        tri = tv[np.array(tt)]
        area = float(0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum())
        mine = f.mats == mat
        require(mine.any(), f"zone-{name}: no cells")
        nodes = np.unique(v[mine])
        extent = float(np.ptp(f.points, axis=0).max())
        reach = 4.0
        while True:
            dn, over = fault_distances(f.points[nodes], tri, reach)
            if np.isfinite(dn).all() or reach > extent:
                break
            reach *= 2.0
        require(np.isfinite(dn).all(), f"zone-{name}: nodes far from fault-{name}.ts")
        require(over.any(), f"zone-{name}: no node lies over the inside of a triangle of fault-{name}.ts")
        w = 2.0 * float(dn[over].max())
        require(w > 0.02, f"zone-{name}: its nodes lie on fault-{name}.ts (thickness {w} m)")
        blocks = np.unique(f.block[mine])
        require(len(blocks) >= 2, f"zone-{name}: its cells lie in one block ({blocks}), not on both sides")
        dc, inside = fault_distances(cen, tri, 0.5 * w + 0.1)
        miss = inside & (dc < 0.5 * w - 0.01) & ~in_zone
        if miss.any():
            raise CheckFailed(f"zone-{name}: {int(miss.sum())} cells {float(dc[miss].min()):.3f} m or more from "
                              f"fault-{name}.ts (thickness {w:.3f} m) are in no zone, e.g. cell "
                              f"{int(np.nonzero(miss)[0][0])}")
        # beyond the fault's edges (its trace on the terrain, the sides) the distance to its
        # triangles grows faster than the distance to its plane: count zone cells out to w there
        covered = float(vol[in_zone & (dc < np.where(inside, 0.5 * w, w))].sum())
        close(covered, w * area, 0.05, f"zone-{name}: the zone cells' volume within {w / 2:.3f} m of "
              f"fault-{name}.ts vs thickness {w:.3f} m times its area {area:.1f} m²")


CHECKS = [
    ("model.vtu: block, fault_names, block_names", check_vtu_block),
    ("fault-<name>.vtu: faces of both sides", check_fault_meshes),
    ("fault-<name>.vtu vs ExtractBoundary / checkMesh", check_fault_ogs),
    ("fault-<name>.ts", check_fault_tsurf),
    ("model.f3grid: fault face groups, block zone groups (meshio)", check_f3grid_groups),
    ("model.msh: fault surfaces, unit volumes (gmsh)", check_msh_faults),
    ("zone-<fault> materials: slabs along fault-<fault>.ts", check_zones),
]


def run(model_dir, only=None):
    """Runs the checks, prints a line each, returns (passed, failed)."""
    try:
        f = Faulted(model_dir)
    except CheckFailed as e:
        print(f"FAIL model.vtu: {e}\n0 passed, 1 failed")
        return 0, 1
    return run_checks(CHECKS, f, only)


def main(argv=None):
    return model_dir_main(__doc__, run, argv)


if __name__ == "__main__":
    sys.exit(main())
