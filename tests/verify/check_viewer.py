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
VIEWER_MODEL_VERTICES = 400_000  # terramesh::build::VIEWER_MODEL_VERTICES


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
    budget = viewer_budget(out)
    if surface["vertices"] != len(pts):
        require(len(pts) > budget and surface["vertices"] <= budget,
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


def model_units(out):
    """The geological model's unit names (model.json), or None for a build without one."""
    p = out.root / "model.json"
    return [u["name"] for u in json.loads(p.read_text())["units"]] if p.is_file() else None


def viewer_budget(out):
    """Most DSM vertices the viewer shows: VIEWER_VERTICES, less with a geological model (each
    unit's shell copies the planar vertices twice: VIEWER_MODEL_VERTICES in all)."""
    units = model_units(out)
    if not units:
        return VIEWER_VERTICES
    return min(VIEWER_VERTICES, VIEWER_MODEL_VERTICES // (2 * (len(units) + 1) - 1))


def check_viewer_model(out):
    """A build with [geology]: one viewer layer per unit with volume (unit-<name>.ts), named
    after it, each vertex a point of model.vtu (to float32 rounding of the offsets) unless the
    view is decimated (then inside model.vtu's bounds); the boreholes' collars as points and
    their traces as triangles coloured per vertex, in at least two of the units' colours."""
    units = model_units(out)
    if not units:
        return
    from check_model import Model
    from check_model_glb import nearest_index
    scene = scene_of(out)
    origin = np.asarray(scene["origin"], dtype=float)
    layers = {l["name"]: l for l in scene["layers"]}
    bodies = [u for u in units if (out.root / f"unit-{u}.ts").is_file()]
    shown = [n[len("unit "):] for n in layers if n.startswith("unit ")]
    require(shown == bodies, f"report.html viewer: unit layers {shown}, the model's bodies are {bodies}")
    pts = Model(out.root).vtu()[0]
    decimated = "decimated" in (scene.get("note") or "")
    tol = F32_EPS * np.abs(pts - origin).max() + 1e-6
    for u in bodies:
        l = layers[f"unit {u}"]
        p = _array(l, l["positions"], "<f4", "positions").astype(float).reshape(-1, 3) + origin
        if decimated:
            require(np.all(p >= pts.min(0) - tol) and np.all(p <= pts.max(0) + tol),
                    f"report.html viewer: unit {u} outside model.vtu's bounds")
        else:
            nearest_index(pts, p, tol, f"report.html viewer: unit {u} vs model.vtu")
    holes = [l for n, l in layers.items() if n.startswith("boreholes")]
    if (out.root / "model.json").is_file() and json.loads((out.root / "model.json").read_text()).get("boreholes"):
        require(holes and holes[0]["kind"] == "points" and holes[0]["vertices"] > 0,
                "report.html viewer: a model with boreholes but no borehole points")
        traces = [l for n, l in layers.items() if n.startswith("borehole traces")]
        require(traces and traces[0]["kind"] == "triangles" and traces[0].get("vertex_colours"),
                "report.html viewer: a model with boreholes but no borehole traces with vertex colours")
        t = traces[0]
        c = np.frombuffer(base64.b64decode(t["vertex_colours"]), dtype=np.uint8)
        require(c.size == 3 * t["vertices"],
                f"report.html viewer: borehole traces: {c.size} colour bytes for {t['vertices']} vertices")
        used = {tuple(int(v) for v in x) for x in c.reshape(-1, 3)}
        unit_colours = {tuple(l["colour"]) for n, l in layers.items() if n.startswith("unit ")}
        shown = used & unit_colours
        require(len(shown) >= min(2, len(unit_colours)),
                f"report.html viewer: the borehole traces show {len(shown)} of the units' colours")


CHECKS = [("report.html: 3D viewer data", check_viewer),
          ("report.html: 3D viewer geological units", check_viewer_model)]
