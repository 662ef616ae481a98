"""model.glb, the geological model for the web: the Khronos glTF-Validator reports 0 errors and
0 warnings, and pygltflib reads one named mesh per sealed unit body whose triangles, after adding
the root node's translation (the recorded origin), are those of the unit's GOCAD TSurf
(`unit-<name>.ts`, doubles, checked against model.vtu by check_model.check_bodies) to 1 mm;
`extras` name the CRS (model.vtu's), origin, units and vertical datum."""

import numpy as np

from check_gltf import GLB_MM, load_glb, require_clean, validate, y_up_to_z_up
from vcommon import canonical_triangles, close, require


def glb_present(model):
    return (model.root / "model.glb").is_file()


def check_model_glb_validator(model):
    """model.glb: glTF-Validator, 0 errors and 0 warnings."""
    require_clean(validate(model.path("model.glb")), "model.glb")


def nearest_index(ref, pts, tol, what):
    """For each row of pts, the index of the row of ref within tol (metres); fails otherwise."""
    cell = max(tol, 1e-6) * 10
    grid = {}
    for i, p in enumerate(ref):
        grid.setdefault(tuple(np.floor(p / cell).astype(np.int64)), []).append(i)
    out = np.empty(len(pts), dtype=np.int64)
    for k, p in enumerate(pts):
        c = np.floor(p / cell).astype(np.int64)
        best, bd = -1, np.inf
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for i in grid.get((c[0] + dx, c[1] + dy, c[2] + dz), []):
                        d = np.abs(ref[i] - p).max()
                        if d < bd:
                            best, bd = i, d
        require(best >= 0 and bd <= tol, f"{what}: vertex {p.tolist()} is no vertex of the reference within {tol} m")
        out[k] = best
    return out


def check_model_glb(model):
    """model.glb (pygltflib): one mesh per unit-<name>.ts in the order of the units, each the
    body's triangles to 1 mm after adding the origin; extras: crs (= model.vtu's), origin (= the
    root translation), units, vertical_datum."""
    from check_model import read_tsurf
    _, _, _, names, crs = model.vtu()
    bodies = [n for n in names if (model.root / f"unit-{n}.ts").is_file()]
    g, meshes = load_glb(model.path("model.glb"))
    got = [m[0] for m in meshes]
    require(got == bodies, f"model.glb: meshes {got}, the model's bodies (unit-*.ts) are {bodies}")
    root = g.nodes[g.scenes[g.scene or 0].nodes[0]]
    extras = root.extras or {}
    for key in ["crs", "origin", "units", "vertical_datum"]:
        require(key in extras, f"model.glb: root node extras lack '{key}' (has {sorted(extras)})")
    require(extras["crs"] == crs, f"model.glb: extras crs {extras['crs']!r}, model.vtu's is {crs!r}")
    t0 = np.array(root.translation or [0, 0, 0], dtype=float)
    close(y_up_to_z_up(t0[None, :])[0], np.array(extras["origin"], dtype=float), 1e-12,
          "model.glb: the root translation vs extras origin")
    for name, pos, tris in meshes:
        v, t = read_tsurf(model.path(f"unit-{name}.ts"))
        pts = y_up_to_z_up(pos)
        require(len(tris) == len(t), f"model.glb: mesh {name} has {len(tris)} triangles, unit-{name}.ts {len(t)}")
        ids = nearest_index(v, pts, GLB_MM, f"model.glb: mesh {name} vs unit-{name}.ts (1 mm)")
        mapped = ids[np.asarray(tris, dtype=np.int64)]
        require(np.array_equal(canonical_triangles(mapped), canonical_triangles(t)),
                f"model.glb: mesh {name}'s triangles (or their orientation) differ from unit-{name}.ts")


CHECKS = [
    ("model.glb: glTF-Validator", check_model_glb_validator),
    ("model.glb: bodies (pygltflib)", check_model_glb),
]
