"""glTF and 3D Tiles checks of the output verifier: every GLB through the Khronos glTF-Validator
(npm `gltf-validator`, pinned in tests/verify/gltf), dsm.glb read back with pygltflib against
dsm-vertices.csv, and 3dtiles/tileset.json read with our own reader (py3dtiles 12.1.1 needs
numba, which needs numpy < 2.4, against the numpy 2.4.6 pinned for the other readers) for
containment, error monotonicity and the ellipsoidal heights, which PROJ (pyproj) takes from
ECEF back to latitude, longitude and height (see docs/verification.md)."""

import json
import subprocess
from pathlib import Path

import numpy as np

from vcommon import CheckFailed, canonical_triangles, close, require

GLTF_DIR = Path(__file__).resolve().parent / "gltf"
# dsm.glb's vertices plus its origin must give the DSM's to this (metres), the issue's 1 mm.
GLB_MM = 1e-3
# A tile's content may stick out of its box by this much (metres): float32 rounding.
BOX_TOL = 1e-3
# EGM96 undulations lie between -106 m and +86 m; over a study area they vary smoothly.
GEOID_RANGE = (-107.0, 87.0)
GEOID_SPREAD = 5.0


def validate(path):
    """The glTF-Validator's report of `path` (a dict); fails unless it ran."""
    script = GLTF_DIR / "validate.js"
    require((GLTF_DIR / "node_modules" / "gltf-validator").is_dir(),
            f"gltf-validator not installed in {GLTF_DIR} (run .ci/verify-setup.sh)")
    r = subprocess.run(["node", str(script), str(path)], capture_output=True, text=True, timeout=300)
    require(r.returncode == 0, f"{path.name}: glTF-Validator failed: {r.stderr.strip()[-400:]}")
    return json.loads(r.stdout)


def require_clean(report, name):
    issues = report.get("issues", {})
    errors, warnings = issues.get("numErrors", -1), issues.get("numWarnings", -1)
    if errors or warnings:
        msgs = [f"{m.get('code')} {m.get('pointer', '')}: {m.get('message')}"
                for m in issues.get("messages", []) if m.get("severity", 9) <= 1][:3]
        raise CheckFailed(f"{name}: glTF-Validator reports {errors} errors, {warnings} warnings: {' | '.join(msgs)}")


def load_glb(path):
    """(pygltflib document, [(mesh name, positions (n,3) float64 in the glTF world, triangles)]),
    world = node translations added along the scene's hierarchy (no rotation or scale)."""
    import pygltflib
    try:
        g = pygltflib.GLTF2().load(str(path))
    except Exception as e:  # noqa: BLE001 - any parse failure fails the check
        raise CheckFailed(f"{path.name}: pygltflib cannot read it: {type(e).__name__}: {e}")
    require(g is not None and g.asset.version == "2.0", f"{path.name}: not glTF 2.0")
    blob = g.binary_blob()
    require(blob is not None, f"{path.name}: no binary chunk")

    def array(k, comps):
        a = g.accessors[k]
        v = g.bufferViews[a.bufferView]
        dt = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}[a.componentType]
        start = (v.byteOffset or 0) + (a.byteOffset or 0)
        n = a.count * comps
        require(start + n * np.dtype(dt).itemsize <= len(blob), f"{path.name}: accessor {k} past the buffer")
        return np.frombuffer(blob, dtype=dt, count=n, offset=start).reshape(-1, comps) if comps > 1 else \
            np.frombuffer(blob, dtype=dt, count=n, offset=start)

    out = []

    def walk(i, offset):
        node = g.nodes[i]
        require(node.rotation in (None, [0, 0, 0, 1]) and node.scale in (None, [1, 1, 1]) and not node.matrix,
                f"{path.name}: node {node.name!r} is rotated or scaled")
        t = offset + np.array(node.translation or [0.0, 0.0, 0.0], dtype=float)
        if node.mesh is not None:
            mesh = g.meshes[node.mesh]
            for p in mesh.primitives:
                pos = array(p.attributes.POSITION, 3).astype(float) + t
                tris = array(p.indices, 1).astype(np.int64).reshape(-1, 3)
                out.append((mesh.name, pos, tris))
        for c in node.children or []:
            walk(c, t)

    for i in g.scenes[g.scene or 0].nodes:
        walk(i, np.zeros(3))
    return g, out


def y_up_to_z_up(p):
    """glTF (X, Y, Z), Y up, to the source frame (x, y, z) = (X, -Z, Y)."""
    return np.column_stack([p[:, 0], -p[:, 2], p[:, 1]])


def every_glb(out):
    files = [out.path("dsm.glb")]
    d = out.root / "3dtiles"
    if d.is_dir():
        files += sorted(d.rglob("*.glb"))
    return files


def check_glb_validator(out):
    """Every GLB (dsm.glb and the 3D Tiles contents): glTF-Validator, 0 errors and 0 warnings."""
    for f in every_glb(out):
        require_clean(validate(f), str(f.relative_to(out.root)))


def check_dsm_glb(out):
    """dsm.glb (pygltflib): vertices + origin equal dsm-vertices.csv to 1 mm, same triangles,
    extras naming the CRS, origin, units and the vertical datum of dsm-origin.json (egm96 for a
    geographic project, source for one in its own CRS)."""
    cols, ref_pts, tris = out.ref()
    g, meshes = load_glb(out.path("dsm.glb"))
    require(len(meshes) == 1, f"dsm.glb: {len(meshes)} meshes, expected 1")
    name, pos, t = meshes[0]
    require(name, "dsm.glb: the mesh has no name")
    pts = y_up_to_z_up(pos)
    require(len(pts) == len(ref_pts), f"dsm.glb: {len(pts)} vertices, dsm-vertices.csv has {len(ref_pts)}")
    err = np.abs(pts - ref_pts).max()
    require(err <= GLB_MM, f"dsm.glb: vertices + origin differ from dsm-vertices.csv by up to {err:.4f} m (> 1 mm)")
    require(np.array_equal(canonical_triangles(t), canonical_triangles(tris)), "dsm.glb: triangles differ from dsm.vtu's")
    extras = g.nodes[g.scenes[g.scene or 0].nodes[0]].extras or {}
    for key in ["crs", "origin", "units", "vertical_datum"]:
        require(key in extras, f"dsm.glb: root node extras lack '{key}' (has {sorted(extras)})")
    # (A dsm-origin.json without the key predates it: glb was then written for UTM projects
    # only, in EGM96 heights.)
    datum = json.loads(out.path("dsm-origin.json").read_text()).get("vertical_datum", "egm96")
    require(extras["vertical_datum"] == datum,
            f"dsm.glb: vertical datum {extras['vertical_datum']!r}, dsm-origin.json's is {datum!r}")
    epsg = out.epsg()
    require(extras["crs"] == f"EPSG:{epsg}", f"dsm.glb: extras crs {extras['crs']!r}, dsm.tif is EPSG:{epsg}")
    t0 = np.array(g.nodes[g.scenes[g.scene or 0].nodes[0]].translation or [0, 0, 0])
    close(y_up_to_z_up(t0[None, :])[0], np.array(extras["origin"], dtype=float), 1e-12,
          "dsm.glb: the root translation vs extras origin")


def box_coords(box, p):
    """Coordinates of points p in a 3D Tiles box: within [-1, 1] each when inside."""
    b = np.array(box, dtype=float)
    c, axes = b[:3], b[3:].reshape(3, 3)
    out = []
    for a in axes:
        n2 = a @ a
        require(n2 > 0, f"box {box}: a zero half-axis")
        out.append((p - c) @ a / n2 * 1.0)
    scale = np.array([np.sqrt(a @ a) for a in axes])
    return np.column_stack(out), scale


def tiles(tile, ancestors=()):
    yield tile, ancestors
    for c in tile.get("children", []):
        yield from tiles(c, ancestors + (tile,))


def check_tileset(out):
    """3dtiles/tileset.json: 3D Tiles 1.1, a root transform, every content inside its tile's box
    and every ancestor's, geometric errors never growing towards the leaves and 0 at them, the
    leaves holding every DSM triangle."""
    ts, root = read_tileset(out)
    n_leaf_tris, n_contents = 0, 0
    for tile, anc in tiles(root):
        e = tile.get("geometricError")
        require(isinstance(e, (int, float)) and e >= 0, f"tileset.json: tile geometricError {e!r}")
        for a in anc[-1:]:
            require(e <= a["geometricError"], f"tileset.json: a tile's geometricError {e} exceeds its parent's {a['geometricError']}")
        if not tile.get("children"):
            require(e == 0, f"tileset.json: leaf {tile.get('content', {}).get('uri')} has geometricError {e}, expected 0")
        require("box" in tile.get("boundingVolume", {}), "tileset.json: a tile without a box bounding volume")
        if "content" not in tile:
            continue
        n_contents += 1
        uri = tile["content"]["uri"]
        _, meshes = load_glb(out.root / "3dtiles" / uri)
        for _, pos, t in meshes:
            p = y_up_to_z_up(pos)
            for owner in (tile, *anc):
                u, scale = box_coords(owner["boundingVolume"]["box"], p)
                over = (np.abs(u) - 1.0) * scale
                require(over.max() <= BOX_TOL,
                        f"tileset.json: content {uri} sticks out of {'its' if owner is tile else 'an ancestor'} box by {over.max():.4f} m")
            if not tile.get("children"):
                n_leaf_tris += len(t)
    require(ts["geometricError"] >= root["geometricError"], "tileset.json: tileset geometricError below the root's")
    _, _, tris = out.ref()
    require(n_leaf_tris == len(tris), f"3dtiles: the leaves hold {n_leaf_tris} triangles, the DSM {len(tris)}")
    require(n_contents >= 2, f"3dtiles: only {n_contents} content tiles: no level of detail")


def read_tileset(out):
    ts = json.loads(out.path("3dtiles/tileset.json").read_text())
    require(ts.get("asset", {}).get("version") == "1.1", f"tileset.json: asset version {ts.get('asset')}")
    root = ts.get("root")
    require(isinstance(root, dict), "tileset.json: no root")
    tr = root.get("transform")
    require(isinstance(tr, list) and len(tr) == 16, "tileset.json: the root lacks a 4x4 transform")
    return ts, root


def check_tileset_heights(out):
    """3D Tiles leaves to ECEF by the root transform, then to WGS-84 latitude, longitude and
    ellipsoidal height by PROJ (EPSG:4978 -> 4979) and to UTM: each leaf vertex is a DSM vertex
    (1 cm), raised by a geoid undulation (ellipsoidal - DSM elevation) inside EGM96's range,
    smooth over the area and equal to the tileset's recorded undulation at its origin (0.5 m)."""
    from pyproj import Transformer
    ts, root = read_tileset(out)
    m = np.array(root["transform"], dtype=float).reshape(4, 4).T  # column-major
    cols, ref_pts, _ = out.ref()
    to_geo = Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)
    to_utm = Transformer.from_crs("EPSG:4326", f"EPSG:{out.epsg()}", always_xy=True)
    key = {}
    for x, y, z in ref_pts:
        key.setdefault((round(x * 100), round(y * 100)), []).append((x, y, z))

    def dsm_z(x, y):
        """Elevation of the DSM vertex within 1 cm of (x, y), or None."""
        kx, ky = round(x * 100), round(y * 100)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for px, py, pz in key.get((kx + dx, ky + dy), []):
                    if np.hypot(px - x, py - y) <= 0.01:
                        return pz
        return None

    shifts = []
    for tile, _ in tiles(root):
        if tile.get("children") or "content" not in tile:
            continue
        _, meshes = load_glb(out.root / "3dtiles" / tile["content"]["uri"])
        for _, pos, _ in meshes:
            p = y_up_to_z_up(pos)
            e = (m @ np.column_stack([p, np.ones(len(p))]).T).T[:, :3]
            lon, lat, h = to_geo.transform(e[:, 0], e[:, 1], e[:, 2])
            x, y = to_utm.transform(lon, lat)
            for xi, yi, hi in zip(x, y, h):
                z = dsm_z(xi, yi)
                require(z is not None, f"3dtiles: leaf vertex at UTM {xi:.3f} {yi:.3f} is no DSM vertex (1 cm)")
                shifts.append(hi - z)
    s = np.array(shifts)
    require(len(s) > 0, "3dtiles: no leaf vertices")
    require(GEOID_RANGE[0] <= s.min() and s.max() <= GEOID_RANGE[1],
            f"3dtiles: ellipsoidal - DSM elevation spans {s.min():.3f}..{s.max():.3f} m, outside EGM96's range")
    require(s.max() - s.min() <= GEOID_SPREAD, f"3dtiles: the height shift varies by {s.max() - s.min():.3f} m over the area")
    rec = ts.get("extras", {}).get("undulation_at_origin")
    require(isinstance(rec, (int, float)), "tileset.json: extras lack undulation_at_origin")
    require(abs(np.median(s) - rec) <= 0.5, f"3dtiles: median height shift {np.median(s):.3f} m, the tileset records {rec} m")
    require(ts["extras"].get("vertical_datum") == "wgs84", "tileset.json: extras vertical_datum is not wgs84")


CHECKS = [
    ("glb: glTF-Validator", check_glb_validator),
    ("glb: dsm.glb vertices (pygltflib)", check_dsm_glb),
    ("3dtiles: tree, boxes, errors", check_tileset),
    ("3dtiles: ellipsoidal heights (PROJ)", check_tileset_heights),
]
