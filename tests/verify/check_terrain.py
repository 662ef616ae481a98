"""Terrain checks of the output verifier: `terrain/layer.json` and every `terrain/{z}/{x}/{y}.terrain`
decoded with the PyPI `quantized-mesh-tile` reader, tile bounds from its `GlobalGeodetic`, compared
with the DSM (dsm-vertices.csv, dsm.vtu) taken to lon/lat by PROJ and to the WGS-84 ellipsoid with
the PyPI `egm96` package's 5' EGM96 grid, independently of terramesh (see docs/verification.md)."""

import json
import math
import re
import warnings
from pathlib import Path

import numpy as np

from vcommon import CheckFailed, require

QMAX = 32767.0
WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563
# The egm96 package: bilinear on the 5' grid, at most 0.06 m from the full model (its own figure);
# terramesh uses the degree-360 expansion on a 1' grid (a few mm). Absolute heights get this slack.
GEOID_TOL = 0.07
# The difference between the two geoid evaluations is smooth: over the DSM it is a plane to
# within this (a kink where a grid line crosses the area stays well below it).
GEOID_PLANE_TOL = 0.005
# Barycentric margin: vertices this close to the DSM's boundary (in barycentric units) are in
# neither class (terramesh locates them in degrees, this in UTM metres).
BOUNDARY_BAND = 1e-6
EDGE_DEG = 1e-12  # shared edge positions: the same u/v on bounds computed the same way
EDGE_H = 1e-9  # shared edge heights: the same multiple of the level's power-of-two step


class Terrain:
    """layer.json and the decoded tiles of an output directory, read once."""

    def __init__(self, out):
        self.root = out.root / "terrain"
        p = self.root / "layer.json"
        require(p.is_file(), "missing file terrain/layer.json")
        try:
            self.layer = json.loads(p.read_text())
        except ValueError as e:
            raise CheckFailed(f"terrain/layer.json: {e}")
        self.files = {}
        for f in sorted(self.root.rglob("*.terrain")):
            m = re.fullmatch(r"(\d+)/(\d+)/(\d+)\.terrain", f.relative_to(self.root).as_posix())
            require(m is not None, f"terrain/{f.relative_to(self.root)}: not a {{z}}/{{x}}/{{y}}.terrain path")
            self.files[tuple(int(g) for g in m.groups())] = f
        self._tiles = None

    def tiles(self):
        """{(z, x, y): decoded tile dict}, every tile decoded with quantized-mesh-tile."""
        if self._tiles is None:
            from quantized_mesh_tile.global_geodetic import GlobalGeodetic
            from quantized_mesh_tile.terrain import TerrainTile
            geo = GlobalGeodetic(True)
            self._tiles = {}
            for (z, x, y), f in self.files.items():
                w, s, e, n = geo.TileBounds(x, y, z)
                t = TerrainTile(west=w, south=s, east=e, north=n)
                name = f"terrain/{z}/{x}/{y}.terrain"
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("error")  # trailing bytes are an error
                        t.fromFile(str(f), hasLighting=True)
                except (Exception, SystemExit) as ex:
                    raise CheckFailed(f"{name}: quantized-mesh-tile cannot read it ({type(ex).__name__}: {ex})")
                u, v, h = (np.array(a, dtype=float) for a in (t.u, t.v, t.h))
                require(len(u) > 0, f"{name}: no vertices")
                hd = t.header
                lo, hi = float(hd["minimumHeight"]), float(hd["maximumHeight"])
                tri = np.array(t.indices, dtype=np.int64).reshape(-1, 3)
                self._tiles[(z, x, y)] = {
                    "name": name, "bounds": (w, s, e, n), "u": u, "v": v, "q": h,
                    "lon": w + (e - w) * u / QMAX, "lat": s + (n - s) * v / QMAX,
                    "h": lo + (hi - lo) * h / QMAX, "quantum": (hi - lo) / QMAX, "range": (lo, hi),
                    "tri": tri, "edges": [list(t.westI), list(t.southI), list(t.eastI), list(t.northI)],
                    "normals": np.array(t.vLight, dtype=float).reshape(-1, 3), "header": hd,
                }
        return self._tiles


def terrain(out):
    if getattr(out, "_terrain", None) is None:
        out._terrain = Terrain(out)
    return out._terrain


def ecef(lat, lon, h):
    e2 = WGS84_F * (2 - WGS84_F)
    la, lo = np.radians(lat), np.radians(lon)
    n = WGS84_A / np.sqrt(1 - e2 * np.sin(la) ** 2)
    return np.column_stack([(n + h) * np.cos(la) * np.cos(lo), (n + h) * np.cos(la) * np.sin(lo),
                            (n * (1 - e2) + h) * np.sin(la)])


# ---------------------------------------------------------------- layer.json


def check_layer(out):
    """layer.json: Cesium's keys; `available` lists exactly the tile files; level 0 complete, every
    parent present; the deepest level's spacing reaches the DSM's mean edge length."""
    t = terrain(out)
    lj = t.layer
    for k, want in [("format", "quantized-mesh-1.0"), ("scheme", "tms"), ("projection", "EPSG:4326")]:
        require(lj.get(k) == want, f"terrain/layer.json: {k} {lj.get(k)!r}, expected {want!r}")
    require(lj.get("tiles") == ["{z}/{x}/{y}.terrain"], f"terrain/layer.json: tiles {lj.get('tiles')!r}")
    require("octvertexnormals" in (lj.get("extensions") or []),
            f"terrain/layer.json: extensions {lj.get('extensions')!r} lack 'octvertexnormals'")
    datum = (lj.get("terramesh") or {}).get("vertical_datum")
    require(datum == "wgs84", f"terrain/layer.json: terramesh.vertical_datum {datum!r}, expected 'wgs84'")
    avail = lj.get("available")
    require(isinstance(avail, list) and avail, "terrain/layer.json: no 'available' list")
    listed = set()
    for z, ranges in enumerate(avail):
        for r in ranges:
            for y in range(r["startY"], r["endY"] + 1):
                for x in range(r["startX"], r["endX"] + 1):
                    listed.add((z, x, y))
    files = set(t.files)
    require(listed == files, f"terrain/layer.json: available lists {sorted(listed - files)[:5]} without a file, "
            f"files {sorted(files - listed)[:5]} are not listed")
    require({(0, 0, 0), (0, 1, 0)} <= files, "terrain: level 0 needs both tiles 0/0/0 and 0/1/0")
    orphans = [k for k in files if k[0] > 0 and (k[0] - 1, k[1] // 2, k[2] // 2) not in files]
    require(not orphans, f"terrain: tiles without their parent: {sorted(orphans)[:5]}")
    zmax = max(k[0] for k in files)
    require(lj.get("maxzoom") == zmax, f"terrain/layer.json: maxzoom {lj.get('maxzoom')} but tiles go to {zmax}")
    _, pts, tris = out.ref()
    p = pts[tris][:, :, :2]
    mean_edge = float(np.mean([np.hypot(*(p[:, (k + 1) % 3] - p[:, k]).T) for k in range(3)]))
    cells = max(len(np.unique(tt["v"])) for k, tt in terrain(out).tiles().items() if k[0] == zmax) - 1
    spacing = lambda z: math.radians(180.0 / 2 ** z) * WGS84_A / cells
    require(spacing(zmax) <= mean_edge * 1.001 and (zmax == 0 or spacing(zmax - 1) > mean_edge * 0.999),
            f"terrain: deepest level {zmax} has spacing {spacing(zmax):.3f} m (level above "
            f"{spacing(max(zmax - 1, 0)):.3f} m); the DSM's mean edge is {mean_edge:.3f} m")


# ---------------------------------------------------------------- tiles


def check_tiles(out):
    """Every tile: valid indices, counter-clockwise triangles covering the tile, heights within the
    header's range, unit normals pointing up, bounding sphere holding every vertex, and the horizon
    occlusion point of the spec (see `occlusion`)."""
    for t in terrain(out).tiles().values():
        name, n = t["name"], len(t["u"])
        tri = t["tri"]
        require(len(tri) > 0 and tri.min() >= 0 and tri.max() < n, f"{name}: triangle indices outside 0..{n - 1}")
        a = np.column_stack([t["u"], t["v"]])[tri]
        area = 0.5 * ((a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1]) - (a[:, 2, 0] - a[:, 0, 0]) * (a[:, 1, 1] - a[:, 0, 1]))
        require(np.all(area > 0), f"{name}: {int(np.sum(area <= 0))} triangles not counter-clockwise in u/v")
        require(abs(area.sum() - QMAX * QMAX) < 1e-6 * QMAX * QMAX,
                f"{name}: triangles cover {area.sum() / QMAX ** 2:.6f} of the tile, not all of it")
        require(np.all(t["q"] <= QMAX) and np.all(t["u"] <= QMAX) and np.all(t["v"] <= QMAX), f"{name}: values above 32767")
        nr = t["normals"]
        require(len(nr) == n, f"{name}: {len(nr)} normals for {n} vertices")
        require(np.allclose(np.linalg.norm(nr, axis=1), 1.0, atol=1e-6), f"{name}: normals not unit length")
        pos = ecef(t["lat"], t["lon"], t["h"])
        up = ecef(t["lat"], t["lon"], np.ones(n)) - ecef(t["lat"], t["lon"], np.zeros(n))
        require(np.all(np.einsum("ij,ij->i", nr, up) > 0), f"{name}: normals pointing below the horizon")
        hd = t["header"]
        c = np.array([hd["boundingSphereCenterX"], hd["boundingSphereCenterY"], hd["boundingSphereCenterZ"]])
        r = float(hd["boundingSphereRadius"])
        d = np.linalg.norm(pos - c, axis=1)
        require(np.all(d <= r * (1 + 1e-9) + 1e-6), f"{name}: vertex {int(np.argmax(d))} lies {d.max() - r:.3g} m "
                "outside the bounding sphere")
        got = np.array([hd["horizonOcclusionPointX"], hd["horizonOcclusionPointY"], hd["horizonOcclusionPointZ"]])
        occlusion(name, pos, c, got, min(t["range"][0], 0.0))


def occlusion(name, pos, centre, p, min_height):
    """The horizon occlusion point (Cozzi 2013, as the spec cites): in the frame where the
    ellipsoid (shrunk by a negative minimum height) is the unit sphere, on the ray towards the
    bounding sphere's centre, at the distance where its horizon cone just holds every vertex's:
    acos(1/|P|) >= angle(q, P) + acos(1/|q|) for every vertex q, with equality for one. A tile too
    wide for any such point must put it so far out (|P| >= 1e5) that it never culls."""
    b = WGS84_A * (1 - WGS84_F)
    radii = np.array([WGS84_A, WGS84_A, b]) + min_height
    q = pos / radii
    d = centre / radii
    d /= np.linalg.norm(d)
    pn = np.linalg.norm(p)
    require(pn > 0 and np.linalg.norm(np.cross(p / pn, d)) < 1e-9,
            f"{name}: horizon occlusion point {p.tolist()} is not towards the bounding sphere's centre")
    qn = np.linalg.norm(q, axis=1)
    alpha = np.arccos(np.clip((q @ d) / qn, -1, 1))
    beta = np.arccos(1 / np.maximum(qn, 1.0))
    need = float(np.max(alpha + beta))
    if need >= math.pi / 2 - 1e-9:
        require(pn >= 1e5, f"{name}: no horizon point can hold this tile, yet |P| = {pn:.6g} culls it")
        return
    have = math.acos(1 / max(pn, 1.0))
    require(have >= need - 1e-9, f"{name}: horizon occlusion point too close: its horizon {have:.9f} rad "
            f"does not hold a vertex's {need:.9f} rad (Cesium would cull a visible tile)")
    require(have <= need + 1e-6, f"{name}: horizon occlusion point farther than needed ({have:.9f} vs {need:.9f} rad)")


def check_edges(out):
    """Edge index lists complete and in Cesium's order: west south->north, south east->west, east
    north->south, north west->east."""
    for t in terrain(out).tiles().values():
        u, v = t["u"], t["v"]
        want = [(u == 0, v, 1), (v == 0, u, -1), (u == QMAX, v, -1), (v == QMAX, u, 1)]
        for side, got, (on, key, sign) in zip(["west", "south", "east", "north"], t["edges"], want):
            idx = np.flatnonzero(on)
            require(sorted(got) == sorted(idx.tolist()),
                    f"{t['name']}: {side} edge lists {len(got)} vertices, {len(idx)} lie on that edge")
            k = sign * key[np.array(got, dtype=np.int64)]
            require(np.all(np.diff(k) > 0), f"{t['name']}: {side} edge indices out of order")


def check_shared_edges(out):
    """Neighbours of a level share their edge vertices: same positions, same heights."""
    tiles = terrain(out).tiles()
    pairs = 0
    for (z, x, y), a in tiles.items():
        for dx, dy, ea, eb, axis in [(1, 0, 2, 0, "lat"), (0, 1, 3, 1, "lon")]:
            b = tiles.get((z, x + dx, y + dy))
            if b is None:
                continue
            pairs += 1
            ia, ib = np.array(a["edges"][ea], dtype=np.int64), np.array(b["edges"][eb], dtype=np.int64)
            what = f"{a['name']} and {b['name']}"
            require(len(ia) == len(ib), f"{what}: {len(ia)} and {len(ib)} vertices on their shared edge")
            ia, ib = ia[np.argsort(a[axis][ia])], ib[np.argsort(b[axis][ib])]
            for c in ["lon", "lat"]:
                require(np.all(np.abs(a[c][ia] - b[c][ib]) <= EDGE_DEG), f"{what}: shared edge {c} differ")
            dh = np.abs(a["h"][ia] - b["h"][ib])
            require(np.all(dh <= EDGE_H), f"{what}: shared edge heights differ by up to {dh.max():.3g} m")
    require(pairs > 0 or len(tiles) <= 2, "terrain: no neighbouring tiles to compare")


# ---------------------------------------------------------------- heights against the DSM


def locate(px, py, tx, ty):
    """For points (px, py) and triangles (tx, ty: (m, 3)): the best barycentric minimum over the
    triangles (>= 0 inside), the triangle index and the barycentric weights there."""
    n = len(px)
    best = np.full(n, -np.inf)
    which = np.full(n, -1)
    w = np.zeros((n, 3))
    order = np.argsort(px)
    sx = px[order]
    for i in range(len(tx)):
        x0, x1 = tx[i].min(), tx[i].max()
        pad = 1e-6 * (x1 - x0 + ty[i].max() - ty[i].min())
        lo, hi = np.searchsorted(sx, x0 - pad), np.searchsorted(sx, x1 + pad, side="right")
        if lo == hi:
            continue
        k = order[lo:hi]
        k = k[(py[k] >= ty[i].min() - pad) & (py[k] <= ty[i].max() + pad)]
        if len(k) == 0:
            continue
        (ax, bx, cx), (ay, by, cy) = tx[i], ty[i]
        d = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
        l1 = ((bx - px[k]) * (cy - py[k]) - (cx - px[k]) * (by - py[k])) / d
        l2 = ((cx - px[k]) * (ay - py[k]) - (ax - px[k]) * (cy - py[k])) / d
        l3 = 1 - l1 - l2
        m = np.minimum(np.minimum(l1, l2), l3)
        better = m > best[k]
        kb = k[better]
        best[kb], which[kb] = m[better], i
        w[kb] = np.column_stack([l1, l2, l3])[better]
    return best, which, w


def check_heights(out):
    """Each tile vertex inside the DSM: height = DSM (barycentric on dsm.vtu's triangle, elevation_uk)
    + EGM96 undulation, within the tile's height quantum + the triangle's slope x the tile's position
    quantum (1/32767 of the tile) + the geoid tolerance; the offsets from the egm96 package's geoid a
    plane to 5 mm. Outside: the fill height, the DSM's lowest ellipsoidal height."""
    import egm96
    from pyproj import Transformer
    _, pts, tris = out.ref()
    epsg = out.epsg()
    require(epsg is not None, "terrain: no EPSG in dsm.tif to place the DSM")
    inv = Transformer.from_crs(epsg, 4326, always_xy=True)
    fwd = Transformer.from_crs(4326, epsg, always_xy=True)
    vlon, vlat = inv.transform(pts[:, 0], pts[:, 1])
    fill = float(np.min(pts[:, 2] + egm96.undulation(vlat, vlon)))
    tx, ty, tz = pts[tris, 0], pts[tris, 1], pts[tris, 2]
    # The gradient of each DSM triangle's plane.
    e1 = np.stack([tx[:, 1] - tx[:, 0], ty[:, 1] - ty[:, 0], tz[:, 1] - tz[:, 0]], 1)
    e2 = np.stack([tx[:, 2] - tx[:, 0], ty[:, 2] - ty[:, 0], tz[:, 2] - tz[:, 0]], 1)
    nrm = np.cross(e1, e2)
    slope = np.hypot(nrm[:, 0], nrm[:, 1]) / np.abs(nrm[:, 2])
    box = (vlon.min(), vlat.min(), vlon.max(), vlat.max())
    inside_all = []
    for t in terrain(out).tiles().values():
        lon, lat, h, q = t["lon"], t["lat"], t["h"], t["quantum"]
        w, s, e, n = t["bounds"]
        posq = max(math.radians(e - w) * WGS84_A * math.cos(math.radians(max(abs(s), abs(n)) if s * n > 0 else 0.0)),
                   math.radians(n - s) * WGS84_A) / QMAX
        near = (lon >= box[0] - 1e-6) & (lon <= box[2] + 1e-6) & (lat >= box[1] - 1e-6) & (lat <= box[3] + 1e-6)
        best = np.full(len(lon), -np.inf)
        which = np.full(len(lon), -1)
        wts = np.zeros((len(lon), 3))
        if near.any():
            x, y = fwd.transform(lon[near], lat[near])
            best[near], which[near], wts[near] = locate(np.asarray(x), np.asarray(y), tx, ty)
        inside, outside = best >= 0, best < -BOUNDARY_BAND
        # Outside: the fill.
        err = np.abs(h[outside] - fill)
        require(np.all(err <= 0.5 * q + GEOID_TOL + 1e-9), f"{t['name']}: a vertex outside the DSM at "
                f"{h[outside][np.argmax(err)] if err.size else 0:.4f} m, the fill height is {fill:.4f} m")
        if inside.any():
            k = which[inside]
            ortho = np.einsum("ij,ij->i", wts[inside], tz[k])
            N = egm96.undulation(lat[inside], lon[inside])
            tol = 0.5 * q + slope[k] * posq + 1e-9
            err = np.abs(h[inside] - (ortho + N))
            j = int(np.argmax(err - tol - GEOID_TOL))
            require(np.all(err <= tol + GEOID_TOL), f"{t['name']}: vertex at lon {lon[inside][j]:.9f} lat "
                    f"{lat[inside][j]:.9f} has height {h[inside][j]:.4f} m, the DSM + EGM96 gives "
                    f"{ortho[j] + N[j]:.4f} m (tolerance {tol[j] + GEOID_TOL:.4f} m)")
            inside_all.append(np.column_stack([lon[inside], lat[inside], h[inside] - ortho - N, tol]))
    require(inside_all, "terrain: no tile vertex lies inside the DSM")
    a = np.vstack(inside_all)
    A = np.column_stack([np.ones(len(a)), a[:, 0] - a[:, 0].mean(), a[:, 1] - a[:, 1].mean()])
    coef, *_ = np.linalg.lstsq(A, a[:, 2], rcond=None)
    res = np.abs(a[:, 2] - A @ coef)
    j = int(np.argmax(res - a[:, 3]))
    require(np.all(res <= a[:, 3] + GEOID_PLANE_TOL),
            f"terrain: height minus (DSM + EGM96) is not a smooth geoid difference: {res[j]:.4f} m off its plane "
            f"at lon {a[j, 0]:.9f} lat {a[j, 1]:.9f} (tolerance {a[j, 3] + GEOID_PLANE_TOL:.4f} m)")


CHECKS = [
    ("terrain layer.json (Cesium keys, available, levels)", check_layer),
    ("terrain tiles (quantized-mesh-tile)", check_tiles),
    ("terrain edge indices", check_edges),
    ("terrain shared edges", check_shared_edges),
    ("terrain heights vs DSM + EGM96", check_heights),
]
