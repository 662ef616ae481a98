"""Checks a geological model's engineering objects (issue 32: tunnels, excavations, structures)
with readers that share no code with terramesh: meshio, Gmsh's own API and OpenGeoSys'
removeMeshElements, ExtractBoundary, checkMesh and ogs.

    python tests/verify/check_structures.py MODEL_DIR [--only NAME]

MODEL_DIR holds what terramesh_io::model::write_object_model writes: model.vtu with int32
`excavation_stage` and `object` beside `MaterialIDs` and field data `object_names` (and
`unit_names` naming the structures' and linings' materials after the units); per object
object-<name>.vtu (its boundary faces with OpenGeoSys' bulk_node_ids, bulk_element_ids,
bulk_face_ids) and object-<name>.ts; model.msh with a physical volume per object group
(tunnel-<name>, excavation-<name>, structure-<name>, lining-<name>) and a physical surface
<group>-boundary; model.f3grid with the groups' zone groups (slot 3; a lining's is its
material's, slot 1), stage-<n> (slot 4) and the boundaries' face groups (slots 2, 3, ...).
Prints `PASS name` or `FAIL name: why` per check, then `N passed, M failed`; exits 1 if any
failed. See docs/geology.md, "Engineering structures".
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from check_model import (HERE, TOL_OGS, VTK_FACES, Model, cell_volumes, check_vtu_ogs, faces_of, ogs_tool,
                         read_tsurf)
from vcommon import CheckFailed, close, meshio_read, model_dir_main, require, run_checks

KINDS = ("tunnel", "excavation", "structure")


def names(fd, key):
    require(key in fd, f"model.vtu: no field data {key!r} ({sorted(fd)})")
    s = bytes(np.asarray(fd[key], dtype=np.uint8)).decode().split("\0")
    require(s[-1] == "", f"model.vtu: {key} does not end with a zero byte")
    return s[:-1]


def cat(m, key):
    return np.concatenate([np.asarray(a).ravel() for a in m.cell_data[key]])


class Objects:
    """model.vtu read once by meshio; the object groups named by model.msh's physical volumes."""

    def __init__(self, root):
        self.model = Model(root)
        m = meshio_read(self.model.path("model.vtu"))
        for key in ("MaterialIDs", "excavation_stage", "object"):
            require(key in m.cell_data, f"model.vtu: no cell data {key!r} ({sorted(m.cell_data)})")
            require(all(a.dtype == np.int32 for a in m.cell_data[key]), f"model.vtu: {key} is not int32")
        self.points = m.points
        self.cells = [(c.type, tuple(x)) for c in m.cells for x in c.data.tolist()]
        self.mats = cat(m, "MaterialIDs")
        self.stage = cat(m, "excavation_stage")
        self.object = cat(m, "object")
        self.units = names(m.field_data, "unit_names")
        self.objects = names(m.field_data, "object_names")
        require(self.objects, "model.vtu: object_names is empty")
        self.volumes = cell_volumes(self.points, self.cells, VTK_FACES)

    def lining(self, k):
        """The cells of object k (0-based) that are its lining (the material lining-<name>)."""
        name = f"lining-{self.objects[k]}"
        if name not in self.units:
            return np.zeros(len(self.cells), dtype=bool)
        return (self.object == k + 1) & (self.mats == self.units.index(name))

    def groups(self, kinds):
        """[(group name, cell mask)]: per object its cells without the lining, then the lining;
        `kinds` maps an object name to its kind (from model.msh)."""
        out = []
        for k, n in enumerate(self.objects):
            lin = self.lining(k)
            out.append((f"{kinds[n]}-{n}", (self.object == k + 1) & ~lin))
            if lin.any():
                out.append((f"lining-{n}", lin))
        return out


def msh_kinds(o):
    """The kind of every object, from the physical volume names of model.msh (read as text)."""
    text = o.model.path("model.msh").read_text()
    a = text.index("$PhysicalNames\n")
    lines = text[a:text.index("$EndPhysicalNames")].splitlines()[2:]
    vols = {ln.split(" ", 2)[2].strip('"') for ln in lines if ln.startswith("3 ")}
    kinds = {}
    for n in o.objects:
        found = [k for k in KINDS if f"{k}-{n}" in vols]
        require(len(found) == 1, f"model.msh: object {n!r} has {len(found)} physical volumes of "
                f"{', '.join(k + '-' + n for k in KINDS)}")
        kinds[n] = found[0]
    return kinds


def check_vtu_objects(o):
    """model.vtu: object in 0..len(object_names), every object with cells; excavation_stage >= 0,
    0 where there is no object and on every lining; one stage per object; MaterialIDs within
    unit_names; a lining's and a structure's cells of materials after the units, the others'
    (tunnels, excavations) the units' own."""
    n = len(o.objects)
    require(o.object.min() >= 0 and o.object.max() <= n, f"model.vtu: object beyond 0..{n}")
    require(o.mats.min() >= 0 and o.mats.max() < len(o.units), "model.vtu: MaterialIDs beyond unit_names")
    require((o.stage >= 0).all(), "model.vtu: a negative excavation_stage")
    require((o.stage[o.object == 0] == 0).all(), "model.vtu: cells of no object are excavated")
    kinds = msh_kinds(o)
    for k, name in enumerate(o.objects):
        cells = o.object == k + 1
        require(cells.any(), f"model.vtu: object {name!r} has no cells")
        lin = o.lining(k)
        require((o.stage[lin] == 0).all(), f"model.vtu: lining-{name} is excavated")
        s = np.unique(o.stage[cells & ~lin])
        require(len(s) == 1, f"model.vtu: object {name!r} has stages {s}")
        mats = np.unique(o.mats[cells & ~lin])
        if kinds[name] == "structure":
            require(len(mats) == 1 and o.object[o.mats == mats[0]].min() > 0 and s[0] == 0,
                    f"model.vtu: structure {name!r}: materials {mats}, stage {s}: want one material of "
                    "its own, never excavated")
        else:
            require(s[0] > 0, f"model.vtu: {kinds[name]} {name!r} is never excavated")
            require((o.mats[cells & ~lin] < len(o.units)).all(), f"model.vtu: {name!r}")
            require(not any(o.units[x].startswith("lining-") for x in mats),
                    f"model.vtu: {name!r} has lining materials outside its lining")


def object_mesh(o, name):
    """object-<name>.vtu by meshio: arrays checked; (faces as bulk node tuples, bulk element
    ids, bulk face ids, MaterialIDs)."""
    p = o.model.path(f"object-{name}.vtu")
    b = meshio_read(p)
    require("bulk_node_ids" in b.point_data and b.point_data["bulk_node_ids"].dtype == np.uint64,
            f"{p.name}: point data bulk_node_ids (uint64) missing or of another type")
    for key, dt in [("bulk_element_ids", np.uint64), ("bulk_face_ids", np.uint64), ("MaterialIDs", np.int32)]:
        require(key in b.cell_data and all(a.dtype == dt for a in b.cell_data[key]),
                f"{p.name}: cell data {key} ({dt.__name__}) missing or of another type")
    bn = b.point_data["bulk_node_ids"].astype(np.int64)
    require(bn.max() < len(o.points), f"{p.name}: bulk_node_ids beyond model.vtu's points")
    close(b.points, o.points[bn], 0.0, f"{p.name}: points vs model.vtu's at bulk_node_ids")
    faces = [tuple(bn[c]) for blk in b.cells for c in blk.data.tolist()]
    c = lambda k: np.concatenate([np.asarray(a).ravel() for a in b.cell_data[k]]).astype(np.int64)
    return faces, c("bulk_element_ids"), c("bulk_face_ids"), c("MaterialIDs")


def closed_volume(points, faces, what):
    """The volume enclosed by outward faces (the divergence theorem), after checking that every
    edge is used once in each direction."""
    edges = {}
    vol = 0.0
    for f in faces:
        for a, b in zip(f, f[1:] + f[:1]):
            ka, kb = tuple(points[a]), tuple(points[b])
            key = (min(ka, kb), max(ka, kb))
            edges[key] = edges.get(key, 0) + (1 if ka < kb else -1)
        p = points[list(f)]
        for t in range(1, len(f) - 1):
            vol += np.dot(p[0], np.cross(p[t], p[t + 1])) / 6.0
    open_edges = [k for k, v in edges.items() if v != 0]
    require(not open_edges, f"{what}: not closed ({len(open_edges)} edges unpaired), e.g. {open_edges[:1]}")
    return vol


def check_object_meshes(o):
    """object-<name>.vtu: every face a face of its bulk element, counter-clockwise seen from
    outside it, that element in the object (not its lining), with its MaterialIDs; the faces
    closed, enclosing the object's cells' volume (1e-9)."""
    table = faces_of(o.cells, VTK_FACES)
    outward = {}
    for key, lst in table.items():
        for i, nodes in lst:
            outward[(i, tuple(sorted(nodes)))] = nodes
    for k, name in enumerate(o.objects):
        faces, ele, _, mat = object_mesh(o, name)
        require(len(faces) > 0, f"object-{name}.vtu: no faces")
        cells = (o.object == k + 1) & ~o.lining(k)
        require(cells[ele].all(), f"object-{name}.vtu: a bulk element outside the object")
        require(np.array_equal(mat, o.mats[ele]), f"object-{name}.vtu: MaterialIDs differ from its cells'")
        for face, e in zip(faces, ele):
            got = outward.get((int(e), tuple(sorted(face))))
            require(got is not None, f"object-{name}.vtu: face {face} is not a face of cell {e}")
            j = got.index(face[0])
            require(tuple(got[j:] + got[:j]) == tuple(face),
                    f"object-{name}.vtu: face {face} is not counter-clockwise seen from outside cell {e}")
        vol = closed_volume(o.points, [list(f) for f in faces], f"object-{name}.vtu")
        close(vol, o.volumes[cells].sum(), 1e-9, f"object-{name}.vtu: enclosed volume vs its cells'")


def remove_elements(src, dst, args):
    r = subprocess.run([ogs_tool("removeMeshElements"), "-i", str(src), "-o", str(dst)] + args,
                       capture_output=True, text=True, timeout=600)
    require(r.returncode == 0, f"removeMeshElements {' '.join(args)} failed: {(r.stdout + r.stderr)[-600:]}")


def extract_boundary_of(src, dst):
    """ExtractBoundary on src: (points, faces, bulk element ids, bulk face ids)."""
    r = subprocess.run([ogs_tool("ExtractBoundary"), "-i", str(src), "-o", str(dst)],
                       capture_output=True, text=True, timeout=600)
    require(r.returncode == 0, f"ExtractBoundary failed: {(r.stdout + r.stderr)[-600:]}")
    b = meshio_read(dst)
    faces = [tuple(c) for blk in b.cells for c in blk.data.tolist()]
    c = lambda k: np.concatenate([np.asarray(a).ravel() for a in b.cell_data[k]]).astype(np.int64)
    return b.points, faces, c("bulk_element_ids"), c("bulk_face_ids")


def check_object_ogs(o):
    """object-<name>.vtu is what OpenGeoSys extracts: removeMeshElements keeps the object's cells
    (object == k, its lining's material removed), ExtractBoundary extracts their boundary: the
    same faces (by their points, same orientation) with the same bulk elements (mapped back to
    model.vtu) and bulk face ids."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for k, name in enumerate(o.objects):
            only = tmp / f"only-{name}.vtu"
            remove_elements(o.model.path("model.vtu"), only,
                            ["-n", "object", "--min-value", str(k + 1), "--max-value", str(k + 1), "--outside"])
            lin = o.lining(k)
            cells = (o.object == k + 1) & ~lin
            if lin.any():
                src = only
                only = tmp / f"only-{name}-bore.vtu"
                lid = o.units.index(f"lining-{name}")
                remove_elements(src, only, ["-n", "MaterialIDs", "--property-value", str(lid)])
            pts, faces, ele, fid = extract_boundary_of(only, tmp / f"boundary-{name}.vtu")
            orig = np.nonzero(cells)[0]
            require(len(meshio_read(only).cells[0].data) == len(orig),
                    f"removeMeshElements kept {len(meshio_read(only).cells[0].data)} cells of {name!r}, "
                    f"model.vtu has {len(orig)}")
            canon = lambda p: min(tuple(map(tuple, np.roll(p, s, axis=0))) for s in range(len(p)))
            ref = {canon(pts[list(f)]): (int(orig[e]), int(i)) for f, e, i in zip(faces, ele, fid)}
            mf, me, mi, _ = object_mesh(o, name)
            got = {canon(o.points[list(f)]): (int(e), int(i)) for f, e, i in zip(mf, me, mi)}
            require(len(got) == len(mf), f"object-{name}.vtu: a face twice")
            require(set(got) == set(ref), f"object-{name}.vtu: {len(set(got) - set(ref))} faces that "
                    f"ExtractBoundary does not extract, {len(set(ref) - set(got))} it extracts are missing")
            bad = [f for f in got if got[f] != ref[f]]
            require(not bad, f"object-{name}.vtu: {len(bad)} faces with other bulk element/face ids than "
                    f"ExtractBoundary's, e.g. {got[bad[0]] if bad else ''} vs {ref[bad[0]] if bad else ''}")


def check_object_tsurf(o):
    """object-<name>.ts: the triangles of object-<name>.vtu (same points, same orientation)."""
    for name in o.objects:
        faces, _, _, _ = object_mesh(o, name)
        v, t = read_tsurf(o.model.path(f"object-{name}.ts"))
        canon = lambda tri: min(tuple(map(tuple, np.roll(tri, s, axis=0))) for s in range(3))
        want = []
        for f in faces:
            for j in range(1, len(f) - 1):
                want.append(canon(o.points[[f[0], f[j], f[j + 1]]]))
        got = sorted(canon(v[list(x)]) for x in t)
        require(got == sorted(want), f"object-{name}.ts: {len(got)} triangles differ from object-{name}.vtu's")


def check_f3grid_objects(o):
    """model.f3grid (meshio): a zone group per object group with exactly its cells (slot 3; a
    lining's group is its material's, slot 1), stage-<n> (slot 4) with the cells of stage n, and
    a face group <group>-boundary per object whose faces are object-<name>.vtu's."""
    m = meshio_read(o.model.path("model.f3grid"))
    kinds = msh_kinds(o)
    nface = sum(len(b.data) for b in m.cells if b.type not in VTK_FACES)
    flat = [tuple(sorted(c)) for b in m.cells for c in b.data.tolist()]
    zone = {}
    for key, ids in m.cell_sets.items():
        if key.startswith("zone:"):
            _, name, slot = key.split(":")
            zone[name] = (slot, np.sort(np.concatenate(ids)) - nface)
    for name, mask in o.groups(kinds):
        slot = "1" if name.startswith("lining-") else "3"
        require(name in zone, f"model.f3grid: no zone group {name!r} ({sorted(zone)})")
        require(zone[name][0] == slot, f"model.f3grid: zone group {name!r} in slot {zone[name][0]}, not {slot}")
        require(np.array_equal(zone[name][1], np.nonzero(mask)[0]), f"model.f3grid: zone group {name!r} is not its cells")
    for s in np.unique(o.stage[o.stage > 0]):
        name = f"stage-{s}"
        require(name in zone and zone[name][0] == "4", f"model.f3grid: no zone group {name!r} in slot 4")
        require(np.array_equal(zone[name][1], np.nonzero(o.stage == s)[0]), f"model.f3grid: {name} is not its cells")
    faces = {key.split(":")[1]: np.concatenate(ids) for key, ids in m.cell_sets.items() if key.startswith("face:")}
    for name in o.objects:
        g = f"{kinds[name]}-{name}-boundary"
        require(g in faces, f"model.f3grid: no face group {g!r} ({sorted(faces)})")
        mf, _, _, _ = object_mesh(o, name)
        want = sorted(tuple(sorted(x)) for x in mf)
        require(sorted(flat[i] for i in faces[g]) == want, f"model.f3grid: face group {g} is not object-{name}.vtu's faces")


def check_msh_objects(o):
    """model.msh opened by Gmsh: a physical volume per object group whose elements are exactly
    the group's cells and whose volume (Gmsh's Jacobians) is theirs (1e-9); a physical surface
    <group>-boundary per group, the object's of the area of object-<name>.ts."""
    import gmsh
    kinds = msh_kinds(o)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        try:
            gmsh.open(str(o.model.path("model.msh")))
        except Exception as e:
            raise CheckFailed(f"model.msh: Gmsh cannot open it: {e}")
        errors = [x for x in gmsh.logger.get() if x.startswith("Error")]
        require(not errors, f"model.msh: Gmsh: {' | '.join(errors)[:600]}")
        groups = {(d, gmsh.model.getPhysicalName(d, t)): t for d, t in gmsh.model.getPhysicalGroups()}

        def elements(dim, tag):
            out = []
            for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                _, tags, _ = gmsh.model.mesh.getElements(dim, ent)
                for t in tags:
                    out.extend(int(x) for x in t)
            return np.sort(np.array(out, dtype=np.int64))

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

        for name, mask in o.groups(kinds):
            require((3, name) in groups, f"model.msh: Gmsh finds no physical volume {name!r} ({sorted(groups)})")
            tag = groups[(3, name)]
            require(np.array_equal(elements(3, tag) - 1, np.nonzero(mask)[0]),
                    f"model.msh: physical volume {name!r} is not its cells")
            close(integral(3, tag), o.volumes[mask].sum(), 1e-9, f"model.msh: Gmsh's volume of {name}")
            b = (2, f"{name}-boundary")
            require(b in groups, f"model.msh: Gmsh finds no physical surface {b[1]!r}")
        for name in o.objects:
            v, t = read_tsurf(o.model.path(f"object-{name}.ts"))
            area = sum(0.5 * np.linalg.norm(np.cross(v[b] - v[a], v[c] - v[a])) for a, b, c in t)
            close(integral(2, groups[(2, f"{kinds[name]}-{name}-boundary")]), area, 1e-9,
                  f"model.msh: Gmsh's area of {kinds[name]}-{name}-boundary vs object-{name}.ts")
    finally:
        gmsh.logger.stop()
        gmsh.finalize()


def check_ogs_excavated(o):
    """OpenGeoSys on the model with every excavated cell removed (removeMeshElements keeps
    excavation_stage == 0), its whole boundary extracted (ExtractBoundary: the outer faces, the
    tunnels' walls, the pits' faces and floors), u = z there, one medium of diffusion 1 per
    MaterialIDs: the steady diffusion reproduces u = z at every node to 1e-9 of the z range."""
    excavated = int((o.stage > 0).sum())
    require(excavated > 0, "model.vtu: no excavated cell")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        kept = tmp / "excavated.vtu"
        remove_elements(o.model.path("model.vtu"), kept,
                        ["-n", "excavation_stage", "--min-value", "0", "--max-value", "0", "--outside"])
        km = meshio_read(kept)
        n = sum(len(b.data) for b in km.cells)
        require(n == len(o.cells) - excavated, f"removeMeshElements kept {n} cells, want "
                f"{len(o.cells)} - {excavated} excavated")
        extract_boundary_of(kept, tmp / "excavated-boundary.vtu")
        media = "".join(
            f"<medium id=\"{k}\"><properties>"
            "<property><name>diffusion</name><type>Constant</type><value>1</value></property>"
            "<property><name>reference_temperature</name><type>Constant</type><value>293.15</value></property>"
            "</properties></medium>" for k in range(len(o.units)))
        prj = (HERE / "ogs" / "excavated.prj").read_text().replace("<!--MEDIA-->", media)
        (tmp / "excavated.prj").write_text(prj)
        r = subprocess.run([ogs_tool("ogs"), "-o", str(tmp / "out"), str(tmp / "excavated.prj")], cwd=tmp,
                           capture_output=True, text=True, timeout=600)
        log = (r.stdout + r.stderr).strip()
        require(r.returncode == 0, f"ogs excavated.prj failed: {log[-800:]}")
        outs = sorted((tmp / "out").glob("*.vtu"), key=lambda p: p.stat().st_mtime)
        require(outs, f"ogs excavated.prj wrote no .vtu: {log[-400:]}")
        out = meshio_read(outs[-1])
    require("pressure" in out.point_data, f"ogs output lacks 'pressure' ({sorted(out.point_data)})")
    u = np.asarray(out.point_data["pressure"]).ravel()
    zr = np.ptp(o.points[:, 2])
    err = np.abs(u - out.points[:, 2]).max()
    require(err <= TOL_OGS * zr, f"ogs diffusion without the excavated cells: max |u - z| = {err:.3g}, "
            f"more than {TOL_OGS} x z range {zr:.3g}")


CHECKS = [
    ("model.vtu: object, excavation_stage, materials", check_vtu_objects),
    ("object-<name>.vtu: the objects' boundaries", check_object_meshes),
    ("object-<name>.vtu vs removeMeshElements + ExtractBoundary", check_object_ogs),
    ("object-<name>.ts", check_object_tsurf),
    ("model.f3grid: object zone groups, stages, boundary face groups (meshio)", check_f3grid_objects),
    ("model.msh: object volumes and boundaries (gmsh)", check_msh_objects),
    ("model.vtu: OpenGeoSys checkMesh", lambda o: check_vtu_ogs(o.model)),
    ("ogs: steady diffusion u = z without the excavated cells", check_ogs_excavated),
]


def run(model_dir, only=None):
    """Runs the checks, prints a line each, returns (passed, failed)."""
    try:
        o = Objects(model_dir)
    except CheckFailed as e:
        print(f"FAIL model.vtu: {e}\n0 passed, 1 failed")
        return 0, 1
    return run_checks(CHECKS, o, only)


def main(argv=None):
    return model_dir_main(__doc__, run, argv)


if __name__ == "__main__":
    sys.exit(main())
