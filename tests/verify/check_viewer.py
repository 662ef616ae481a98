"""The data of report.html's 3D viewer (the JSON in <script id="tmv-data">), decoded here with
base64 and numpy and compared with dsm-vertices.csv and dsm.vtu: the DSM surface's float32
positions plus the origin are the vertices (float32 rounding of the offsets), its Uint32
triangles are dsm.vtu's, its fields are the CSV's kriging_std and elevation_uk - elevation_idw.
A decimated surface (more than VIEWER_VERTICES vertices in the build) must say so in the note
and lie inside the DSM's bounds."""

import base64
import json
import re

import numpy as np

from vcommon import F32_EPS, CheckFailed, require

VIEWER_VERTICES = 200_000  # terramesh::build::VIEWER_VERTICES


def _array(layer, text, dtype, what):
    """Decodes base64 `text` of `layer` as little-endian `dtype` values."""
    try:
        raw = base64.b64decode(text, validate=True)
    except (ValueError, TypeError) as e:
        raise CheckFailed(f"report.html viewer: layer {layer.get('name')!r} {what}: {e}")
    require(len(raw) % 4 == 0, f"report.html viewer: layer {layer.get('name')!r} {what}: {len(raw)} bytes")
    return np.frombuffer(raw, dtype=dtype)


def scene_of(out):
    text = out.path("report.html").read_text(encoding="utf-8")
    m = re.search(r'<script type="application/json" id="tmv-data">(.*?)</script>', text, re.S)
    require(m, "report.html: no 3D viewer data (<script type=\"application/json\" id=\"tmv-data\">)")
    try:
        return json.loads(m.group(1))
    except json.JSONDecodeError as e:
        raise CheckFailed(f"report.html viewer: the scene JSON does not parse: {e}")


def check_viewer(out):
    """The viewer's DSM surface equals the build's vertices, triangles and fields."""
    scene = scene_of(out)
    cols, pts, tris = out.ref()
    origin = np.asarray(scene.get("origin", []), dtype=float)
    require(origin.shape == (3,), f"report.html viewer: origin {scene.get('origin')!r}")
    for key, f in scene.get("fields", {}).items():
        require(f["lo"] <= f["hi"], f"report.html viewer: field {key} range {f['lo']} > {f['hi']}")
        require(len(f["colours"]) >= 2 and all(len(c) == 3 and all(0 <= v <= 255 for v in c) for c in f["colours"]),
                f"report.html viewer: field {key} colours {f['colours']!r}")
    layers = scene.get("layers", [])
    surface = next((l for l in layers if l.get("kind") == "triangles"), None)
    require(surface is not None, "report.html viewer: no triangle layer (the DSM surface)")
    require(surface["name"] == "DSM surface", f"report.html viewer: first surface is {surface['name']!r}")
    for l in layers:
        p = _array(l, l["positions"], "<f4", "positions")
        require(p.size == 3 * l["vertices"], f"report.html viewer: layer {l['name']!r}: {p.size} coordinates for {l['vertices']} vertices")
        require(np.all(np.isfinite(p)), f"report.html viewer: layer {l['name']!r}: non-finite position")
        if l["kind"] == "triangles":
            t = _array(l, l["indices"], "<u4", "indices")
            require(t.size == 3 * l["triangles"], f"report.html viewer: layer {l['name']!r}: {t.size} indices for {l['triangles']} triangles")
            require(t.size == 0 or t.max() < l["vertices"], f"report.html viewer: layer {l['name']!r}: index {t.max()} of {l['vertices']} vertices")
        for key in l["fields"]:
            require(key in scene["fields"], f"report.html viewer: layer {l['name']!r} field {key} not in the scene's fields")
            v = _array(l, l["fields"][key], "<f4", key)
            require(v.size == l["vertices"], f"report.html viewer: layer {l['name']!r} field {key}: {v.size} values for {l['vertices']} vertices")
    pos = _array(surface, surface["positions"], "<f4", "positions").astype(float).reshape(-1, 3) + origin
    idx = _array(surface, surface["indices"], "<u4", "indices").astype(np.int64).reshape(-1, 3)
    if surface["vertices"] != len(pts):
        require(len(pts) > VIEWER_VERTICES and surface["vertices"] <= VIEWER_VERTICES,
                f"report.html viewer: {surface['vertices']} surface vertices for a DSM of {len(pts)}")
        require("decimated" in (scene.get("note") or ""), "report.html viewer: a decimated surface without a note saying so")
        lo, hi = pts.min(0), pts.max(0)
        slack = 1e-3 + F32_EPS * np.abs(pts - origin).max()
        require(np.all(pos >= lo - slack) and np.all(pos <= hi + slack), "report.html viewer: decimated surface outside the DSM's bounds")
        return
    # float32 offsets from the origin: half an ulp of the largest offset, per coordinate.
    tol = F32_EPS * np.abs(pts - origin).max(0) + 1e-9
    err = np.abs(pos - pts)
    k = int(np.argmax((err / tol).max(1)))
    require(np.all(err <= tol), f"report.html viewer: surface vertex {k} at {pos[k].tolist()} != {pts[k].tolist()} (tolerance {tol.tolist()})")
    require(idx.shape == tris.shape and np.array_equal(idx, tris), "report.html viewer: surface triangles differ from dsm.vtu's")
    expect = {"kriging_std": cols["kriging_std"], "uk_minus_idw": cols["elevation_uk"] - cols["elevation_idw"]}
    for key, want in expect.items():
        require(key in surface["fields"], f"report.html viewer: the surface has no field {key}")
        got = _array(surface, surface["fields"][key], "<f4", key).astype(float)
        ftol = F32_EPS * np.maximum(np.abs(want), 1e-30) + 1e-12
        bad = np.abs(got - want) > ftol
        require(not bad.any(), f"report.html viewer: field {key} at vertex {int(np.argmax(bad))}: {got[bad][:1]} != {want[bad][:1]}")


CHECKS = [("report.html: 3D viewer data", check_viewer)]
