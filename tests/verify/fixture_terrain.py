"""`terrain/` for the verifier's fixture directory (make_fixture.py): a quantized-mesh pyramid of the
fixture DSM made here, in Python, following the output contract of docs/verification.md (lattice
tiles sampled from the DSM's triangles plus EGM96, fill height outside, per-level power-of-two
height steps, Cesium's edge order) and encoded by quantized-mesh-tile's writer. Its lattice is
4 x 4 cells per tile instead of terramesh's 64, which keeps it small and the verifier honest about
not assuming 64."""

import json
import math
from collections import OrderedDict

import numpy as np

LATTICE = 4
QMAX = 32767
A = 6378137.0
F = 1.0 / 298.257223563


def lattice():
    """Vertex order (first use by the triangles), u, v, triangles of the fixture lattice."""
    n = LATTICE + 1
    raw = []
    for j in range(LATTICE):
        for i in range(LATTICE):
            a = j * n + i
            raw += [[a, a + 1, a + n + 1], [a, a + n + 1, a + n]]
    new, order = {}, []
    for t in raw:
        for k in t:
            if k not in new:
                new[k] = len(order)
                order.append(k)
    q = [int(round(i * QMAX / LATTICE)) for i in range(n)]
    u = np.array([q[k % n] for k in order])
    v = np.array([q[k // n] for k in order])
    return u, v, [[new[k] for k in t] for t in raw]


def ecef(lat, lon, h):
    e2 = F * (2 - F)
    la, lo = np.radians(lat), np.radians(lon)
    nn = A / np.sqrt(1 - e2 * np.sin(la) ** 2)
    return np.column_stack([(nn + h) * np.cos(la) * np.cos(lo), (nn + h) * np.cos(la) * np.sin(lo),
                            (nn * (1 - e2) + h) * np.sin(la)])


def sample(px, py, xy, z, tris):
    """Barycentric height on the triangle holding each point (brute force), NaN outside."""
    t = xy[tris]
    np.seterr(invalid="ignore")  # points far away project to inf; they are outside anyway
    (ax, bx, cx), (ay, by, cy) = t[:, :, 0].T, t[:, :, 1].T
    d = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
    px, py = px[:, None], py[:, None]
    l1 = ((bx - px) * (cy - py) - (cx - px) * (by - py)) / d
    l2 = ((cx - px) * (ay - py) - (ax - px) * (cy - py)) / d
    l3 = 1 - l1 - l2
    m = np.minimum(np.minimum(l1, l2), l3)
    k = np.argmax(m, axis=1)
    r = np.arange(len(k))
    h = l1[r, k] * z[tris[k, 0]] + l2[r, k] * z[tris[k, 1]] + l3[r, k] * z[tris[k, 2]]
    return np.where(m[r, k] >= -1e-12, h, np.nan)


def occlusion_point(pos, centre):
    b = A * (1 - F)
    radii = np.array([A, A, b])
    q = pos / radii
    d = centre / radii
    d /= np.linalg.norm(d)
    qn = np.linalg.norm(q, axis=1)
    ang = np.arccos(np.clip((q @ d) / qn, -1, 1)) + np.arccos(1 / np.maximum(qn, 1.0))
    need = ang.max()
    return d * (1e6 if need >= math.pi / 2 - 1e-9 else 1 / math.cos(need))


def write_terrain(out, xy, uk, tris, epsg):
    import egm96
    from pyproj import Transformer
    from quantized_mesh_tile.terrain import TerrainTile
    inv = Transformer.from_crs(epsg, 4326, always_xy=True)
    fwd = Transformer.from_crs(4326, epsg, always_xy=True)
    vlon, vlat = inv.transform(xy[:, 0], xy[:, 1])
    ell = uk + egm96.undulation(vlat, vlon)
    fill = float(ell.min())
    p = xy[tris]
    mean_edge = float(np.mean([np.hypot(*(p[:, (k + 1) % 3] - p[:, k]).T) for k in range(3)]))
    zmax = next(z for z in range(30) if math.radians(180 / 2 ** z) * A / LATTICE <= mean_edge)
    u, v, ltris = lattice()
    root = out / "terrain"
    available = []
    for z in range(zmax + 1):
        size = 180 / 2 ** z
        if z == 0:
            xs, ys = [0, 1], [0]
        else:
            xs = list(range(int((vlon.min() + 180) // size), int((vlon.max() + 180) // size) + 1))
            ys = list(range(int((vlat.min() + 90) // size), int((vlat.max() + 90) // size) + 1))
        available.append([{"startX": xs[0], "startY": ys[0], "endX": xs[-1], "endY": ys[-1]}])
        level = {}
        for y in ys:
            for x in xs:
                w, s = -180 + x * size, -90 + y * size
                lon, lat = w + size * u / QMAX, s + size * v / QMAX
                px, py = fwd.transform(lon, lat)
                h = sample(np.asarray(px), np.asarray(py), xy, uk, np.asarray(tris))
                h = np.where(np.isnan(h), fill, h + egm96.undulation(lat, lon))
                level[(x, y)] = (w, s, lon, lat, h)
        rng = max(hh.max() - hh.min() for *_, hh in level.values())
        big = max(np.abs(hh).max() for *_, hh in level.values())
        step = 2.0 ** math.ceil(math.log2(max(rng / (QMAX - 2), big / 2 ** 22, 2 ** -20)))
        for (x, y), (w, s, lon, lat, h) in level.items():
            k0 = math.floor(h.min() / step)
            q = (np.round(h / step) - k0).astype(int)
            lo, hi = k0 * step, (k0 + QMAX) * step
            hq = lo + (hi - lo) * q / QMAX
            pos = ecef(lat, lon, hq)
            box_c = 0.5 * (pos.min(axis=0) + pos.max(axis=0))
            occ = occlusion_point(pos, box_c)
            centre = ecef(np.array([s + size / 2]), np.array([w + size / 2]), np.array([(lo + hi) / 2]))[0]
            t = TerrainTile(west=w, south=s, east=w + size, north=s + size)
            t.header = OrderedDict(zip(
                TerrainTile.quantizedMeshHeader.keys(),
                [*centre, lo, hi, *box_c, float(np.linalg.norm(pos - box_c, axis=1).max()), *occ]))
            t.u, t.v, t.h = u.tolist(), v.tolist(), q.tolist()
            t.indices = [k for tr in ltris for k in tr]
            idx = np.arange(len(u))
            t.westI = idx[u == 0][np.argsort(v[u == 0])].tolist()
            t.southI = idx[v == 0][np.argsort(-u[v == 0])].tolist()
            t.eastI = idx[u == QMAX][np.argsort(-v[u == QMAX])].tolist()
            t.northI = idx[v == QMAX][np.argsort(u[v == QMAX])].tolist()
            up = ecef(lat, lon, np.ones(len(u))) - ecef(lat, lon, np.zeros(len(u)))
            t.vLight = (up / np.linalg.norm(up, axis=1)[:, None]).tolist()
            d = root / str(z) / str(x)
            d.mkdir(parents=True, exist_ok=True)
            (d / f"{y}.terrain").write_bytes(t.toBytesIO().getvalue())
    layer = {"tilejson": "2.1.0", "format": "quantized-mesh-1.0", "scheme": "tms", "projection": "EPSG:4326",
             "tiles": ["{z}/{x}/{y}.terrain"], "extensions": ["octvertexnormals"], "minzoom": 0, "maxzoom": zmax,
             "bounds": [-180, -90, 180, 90], "available": available,
             "terramesh": {"vertical_datum": "wgs84", "fill_height": fill, "lattice": LATTICE}}
    (root / "layer.json").write_text(json.dumps(layer, indent=2) + "\n")
