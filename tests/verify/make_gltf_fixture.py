"""The glTF outputs of the verifier's fixture directory, written here in Python (numpy, struct,
pyproj), independently of terramesh's writers: dsm.glb and a two-level 3dtiles/ tileset.

The fixture's ellipsoidal heights add a constant UNDULATION (a plausible EGM96 value for the
fixture's place): the verifier checks that the shift is applied consistently, not its value
(no EGM96 model installs offline for Python here; the Rust tests check terramesh's geoid
against NGA's published points)."""

import json
import struct
from pathlib import Path

import numpy as np

UNDULATION = 48.6


def glb_bytes(vertices, tris, origin, extras, name="dsm"):
    """A minimal valid GLB: one mesh (float32 positions relative to `origin`, Y-up), u16 or u32
    indices, the origin as the root node's translation, `extras` on the root node."""
    rel = np.asarray(vertices, float) - origin
    pos = np.column_stack([rel[:, 0], rel[:, 2], -rel[:, 1]]).astype(np.float32)
    idx = np.asarray(tris).astype(np.uint16 if len(pos) < 65535 else np.uint32).ravel()
    pbin = pos.tobytes()
    ibin = idx.tobytes()
    ibin += b"\0" * (-len(ibin) % 4)
    doc = {
        "asset": {"version": "2.0", "generator": "terramesh verifier fixture"},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"name": name, "translation": [origin[0], origin[2], -origin[1]], "children": [1], "extras": extras},
                  {"name": name + "-mesh", "mesh": 0}],
        "meshes": [{"name": name, "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
             "min": [float(v) for v in pos.min(0)], "max": [float(v) for v in pos.max(0)]},
            {"bufferView": 1, "componentType": 5123 if idx.dtype == np.uint16 else 5125, "count": len(idx), "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pbin), "target": 34962},
                        {"buffer": 0, "byteOffset": len(pbin), "byteLength": idx.nbytes, "target": 34963}],
        "buffers": [{"byteLength": len(pbin) + len(ibin)}],
    }
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(pbin) + len(ibin), b"BIN\0") + pbin + ibin
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def centre_low(p):
    return np.array([0.5 * (p[:, 0].min() + p[:, 0].max()), 0.5 * (p[:, 1].min() + p[:, 1].max()), p[:, 2].min()])


def box(p):
    lo, hi = p.min(0), p.max(0)
    c, h = 0.5 * (lo + hi), 0.5 * (hi - lo) + 0.005
    return [*c, h[0], 0, 0, 0, h[1], 0, 0, 0, h[2]]


def write_gltf(out, xy, z, tris, epsg):
    from make_fixture import ecef, to_enu
    from pyproj import Transformer
    out = Path(out)
    pts = np.column_stack([xy, z])
    o = centre_low(pts)
    extras = {"crs": f"EPSG:{epsg}", "origin": list(o), "units": "metre", "vertical_datum": "egm96"}
    (out / "dsm.glb").write_bytes(glb_bytes(pts, tris, o, extras))

    # 3D Tiles: a root of two triangles over the corners, two leaves cutting the DSM by centroid.
    to_geo = Transformer.from_crs(epsg, 4326, always_xy=True)
    lon, lat = to_geo.transform(xy[:, 0], xy[:, 1])
    lon0, lat0 = to_geo.transform(o[0], o[1])
    h0 = o[2] + UNDULATION
    enu = to_enu(lat, lon, z + UNDULATION, lat0, lon0, h0)
    corners = [int(np.argmin(xy[:, 0] + xy[:, 1])), int(np.argmax(xy[:, 0] - xy[:, 1])),
               int(np.argmax(xy[:, 0] + xy[:, 1])), int(np.argmin(xy[:, 0] - xy[:, 1]))]
    root_tris = np.array([[0, 1, 2], [0, 2, 3]])
    d = out / "3dtiles"
    (d / "tiles").mkdir(parents=True, exist_ok=True)
    (d / "tiles" / "root.glb").write_bytes(glb_bytes(enu[corners], root_tris, enu[corners].mean(0), {}))
    cx = xy[tris].mean(1)[:, 0]
    split = np.median(cx)
    leaves = []
    for k, sel in enumerate([cx < split, cx >= split]):
        t = tris[sel]
        used = np.unique(t)
        remap = {int(v): i for i, v in enumerate(used)}
        lt = np.vectorize(remap.get)(t)
        (d / "tiles" / f"leaf{k}.glb").write_bytes(glb_bytes(enu[used], lt, enu[used].mean(0), {}))
        leaves.append({"boundingVolume": {"box": box(enu[used])}, "geometricError": 0.0,
                       "content": {"uri": f"tiles/leaf{k}.glb"}})
    la, lo = np.radians(lat0), np.radians(lon0)
    t0 = ecef(np.array([lat0]), np.array([lon0]), np.array([h0]))[0]
    transform = [-np.sin(lo), np.cos(lo), 0, 0,
                 -np.sin(la) * np.cos(lo), -np.sin(la) * np.sin(lo), np.cos(la), 0,
                 np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la), 0, *t0, 1]
    root = {"transform": [float(v) for v in transform], "boundingVolume": {"box": box(enu)},
            "geometricError": 5.0, "refine": "REPLACE", "content": {"uri": "tiles/root.glb"}, "children": leaves}
    ts = {"asset": {"version": "1.1"}, "geometricError": 20.0, "root": root,
          "extras": {"vertical_datum": "wgs84", "undulation_at_origin": UNDULATION}}
    (d / "tileset.json").write_text(json.dumps(ts, indent=1) + "\n")
