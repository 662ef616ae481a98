"""Writes a small, valid `terramesh build` output directory, for testing the verifier.

The files follow the output contract of `terramesh build` (see docs/verification.md) but are
produced here, in Python, independently of terramesh's Rust writers: the verifier's negative
tests break one file of a valid directory at a time.

    python tests/verify/make_fixture.py OUT_DIR
"""

import base64
import json
import struct
import sys
import zlib
from pathlib import Path

import numpy as np

import make_gltf_fixture
import fixture_terrain

EPSG = 32632
ORIGIN = (377000.0, 5397000.0, 0.0)
BASE = 300.0
CHECKER = "#f4f4f4"


def surface(seed=0, nx=6, ny=5):
    """Jittered grid mesh: UTM vertices, counter-clockwise triangles, fields."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.linspace(0, 200, nx), np.linspace(0, 150, ny))
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    inner = (xy[:, 0] > 0) & (xy[:, 0] < 200) & (xy[:, 1] > 0) & (xy[:, 1] < 150)
    xy[inner] += rng.uniform(-8, 8, (inner.sum(), 2))
    xy += [ORIGIN[0] + 0.123456789, ORIGIN[1] + 0.987654321]
    tris = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = j * nx + i
            tris += [[a, a + 1, a + nx + 1], [a, a + nx + 1, a + nx]]
    tris = np.array(tris)
    lx, ly = xy[:, 0] - ORIGIN[0], xy[:, 1] - ORIGIN[1]
    uk = 350.0 + 0.05 * lx + 0.02 * ly + 3.0 * np.sin(lx / 40.0) * np.cos(ly / 30.0)
    std = 0.5 + 0.01 * np.hypot(lx - 100, ly - 75)
    idw = uk + 0.3 * np.cos(lx / 17.0)
    return xy, uk, std, idw, tris


def min_angles(xy, tris):
    p = xy[tris]
    out = []
    for t in p:
        ang = []
        for k in range(3):
            u, v = t[(k + 1) % 3] - t[k], t[(k + 2) % 3] - t[k]
            c = np.dot(u, v) / (np.linalg.norm(u) * np.linalg.norm(v))
            ang.append(np.degrees(np.arccos(np.clip(c, -1, 1))))
        out.append(min(ang))
    return np.array(out)


def solid(pts3, tris, base):
    """Closed solid: the surface, a bottom at `base` and walls along the boundary."""
    n = len(pts3)
    bottom = pts3.copy()
    bottom[:, 2] = base
    allp = np.vstack([pts3, bottom])
    faces = [list(t) for t in tris] + [[t[0] + n, t[2] + n, t[1] + n] for t in tris]
    edges = {}
    for t in tris:
        for k in range(3):
            a, b = int(t[k]), int(t[(k + 1) % 3])
            edges[(a, b)] = True
    for a, b in edges:
        if (b, a) not in edges:
            faces += [[a + n, b + n, b], [a + n, b, a]]
    return allp, np.array(faces)


def write_stl(path, pts, tris, origin):
    header = f"terramesh binary STL, metres, origin {origin[0]:g} {origin[1]:g} {origin[2]:g}"
    buf = bytearray(header.encode().ljust(80, b" "))
    buf += struct.pack("<I", len(tris))
    for t in tris:
        p = pts[t] - np.array(origin)
        nrm = np.cross(p[1] - p[0], p[2] - p[0])
        nrm = nrm / (np.linalg.norm(nrm) or 1.0)
        buf += struct.pack("<12f", *nrm, *p.ravel()) + b"\0\0"
    path.write_bytes(bytes(buf))


def write_msh(path, pts, tris):
    lo, hi = pts.min(0), pts.max(0)
    n, m = len(pts), len(tris)
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Entities", "0 0 1 0",
             " ".join(map(repr, [1, *lo.tolist(), *hi.tolist(), 0, 0])), "$EndEntities",
             "$Nodes", f"1 {n} 1 {n}", f"2 1 0 {n}"]
    lines += [str(i + 1) for i in range(n)] + [" ".join(map(repr, p.tolist())) for p in pts]
    lines += ["$EndNodes", "$Elements", f"1 {m} 1 {m}", f"2 1 2 {m}"]
    lines += [f"{k + 1} {t[0] + 1} {t[1] + 1} {t[2] + 1}" for k, t in enumerate(tris)]
    path.write_text("\n".join(lines + ["$EndElements"]) + "\n")


def write_vtu(path, pts, tris, point_data, cell_data):
    def arr(name, vals, comps=1, typ="Float64"):
        body = "\n".join(" ".join(repr(v) if isinstance(v, float) else str(v) for v in np.atleast_1d(row).tolist())
                         for row in vals)
        extra = f' NumberOfComponents="{comps}"' if comps > 1 else ""
        return f'<DataArray type="{typ}" Name="{name}"{extra} format="ascii">\n{body}\n</DataArray>'
    pd = "\n".join(arr(k, v) for k, v in point_data.items())
    cd = "\n".join(arr(k, v) for k, v in cell_data.items())
    s = (f'<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
         f'header_type="UInt64">\n<UnstructuredGrid>\n<Piece NumberOfPoints="{len(pts)}" NumberOfCells="{len(tris)}">\n'
         f"<PointData>\n{pd}\n</PointData>\n<CellData>\n{cd}\n</CellData>\n<Points>\n"
         f"{arr('Points', pts, 3)}\n</Points>\n<Cells>\n{arr('connectivity', tris, typ='Int64')}\n"
         f"{arr('offsets', 3 * np.arange(1, len(tris) + 1), typ='Int64')}\n"
         f"{arr('types', np.full(len(tris), 5), typ='UInt8')}\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    path.write_text(s)


def write_ply(path, pts, tris, fields):
    head = ["ply", "format binary_little_endian 1.0", "comment terramesh", f"element vertex {len(pts)}",
            "property double x", "property double y", "property double z"]
    head += [f"property double {k}" for k in fields]
    head += [f"element face {len(tris)}", "property list uchar int vertex_indices", "end_header"]
    buf = bytearray(("\n".join(head) + "\n").encode())
    cols = np.column_stack([pts] + list(fields.values()))
    buf += cols.astype("<f8").tobytes()
    for t in tris:
        buf += struct.pack("<B3i", 3, *map(int, t))
    path.write_bytes(bytes(buf))


def write_png(path_or_none, w=8, h=6):
    """A tiny RGB PNG (a colour gradient), returned as bytes."""
    raw = b"".join(b"\0" + bytes(v for i in range(w) for v in (30 * i % 256, 40 * j % 256, 120)) for j in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    if path_or_none:
        Path(path_or_none).write_bytes(png)
    return png


def write_grids(out, xy, uk):
    import rasterio
    from rasterio.transform import from_origin
    cell = 25.0
    x0, y1 = float(xy[:, 0].min()), float(xy[:, 1].max())
    nx, ny = 8, 6
    lx = x0 + cell * (np.arange(nx) + 0.5) - ORIGIN[0]
    ly = y1 - cell * (np.arange(ny) + 0.5) - ORIGIN[1]
    gx, gy = np.meshgrid(lx, ly)
    g = 350.0 + 0.05 * gx + 0.02 * gy
    g[0, 0] = g[-1, -1] = -9999.0
    tr = from_origin(x0, y1, cell, cell)
    with rasterio.open(out / "dsm.tif", "w", driver="GTiff", width=nx, height=ny, count=1, dtype="float64",
                       crs=f"EPSG:{EPSG}", transform=tr, nodata=-9999.0) as ds:
        ds.write(g, 1)
    rows = [f"ncols {nx}", f"nrows {ny}", f"xllcorner {x0!r}", f"yllcorner {y1 - ny * cell!r}",
            f"cellsize {cell!r}", "NODATA_value -9999"]
    rows += [" ".join(repr(float(v)) for v in r) for r in g]
    (out / "dsm.asc").write_text("\n".join(rows) + "\n")


def write_kml(path, xy, z, tris):
    from pyproj import Transformer
    lon, lat = Transformer.from_crs(EPSG, 4326, always_xy=True).transform(xy[:, 0], xy[:, 1])
    polys = []
    for t in tris:
        c = " ".join(f"{lon[i]:.10f},{lat[i]:.10f},{z[i]:.3f}" for i in [*t, t[0]])
        polys.append("<Polygon><altitudeMode>absolute</altitudeMode><outerBoundaryIs><LinearRing>"
                     f"<coordinates>{c}</coordinates></LinearRing></outerBoundaryIs></Polygon>")
    path.write_text('<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">\n'
                    "<Document><name>terramesh DSM</name><Placemark><name>DSM</name><MultiGeometry>\n"
                    + "\n".join(polys) + "\n</MultiGeometry></Placemark></Document></kml>\n")


def ecef(lat, lon, h):
    """Geodetic degrees and ellipsoidal height to WGS-84 ECEF metres (numpy, not PROJ)."""
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    la, lo = np.radians(lat), np.radians(lon)
    n = a / np.sqrt(1 - e2 * np.sin(la) ** 2)
    return np.column_stack([(n + h) * np.cos(la) * np.cos(lo), (n + h) * np.cos(la) * np.sin(lo),
                            (n * (1 - e2) + h) * np.sin(la)])


def to_enu(lat, lon, h, lat0, lon0, h0):
    """East, north, up metres in the tangent plane at (lat0, lon0, h0)."""
    d = ecef(lat, lon, h) - ecef(np.array([lat0]), np.array([lon0]), np.array([h0]))
    la, lo = np.radians(lat0), np.radians(lon0)
    rot = np.array([[-np.sin(lo), np.cos(lo), 0.0],
                    [-np.sin(la) * np.cos(lo), -np.sin(la) * np.sin(lo), np.cos(la)],
                    [np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)]])
    return d @ rot.T


def write_dae(out, xy, z, tris, fmt=repr):
    """dsm.dae (COLLADA 1.4.1, Z_UP, east-north-up metres) and dsm-model.kml placing it; returns
    the ENU positions. `fmt` writes each coordinate (repr: shortest round trip)."""
    from pyproj import Transformer
    lon, lat = Transformer.from_crs(EPSG, 4326, always_xy=True).transform(xy[:, 0], xy[:, 1])
    lon0, lat0 = Transformer.from_crs(EPSG, 4326, always_xy=True).transform(
        0.5 * (xy[:, 0].min() + xy[:, 0].max()), 0.5 * (xy[:, 1].min() + xy[:, 1].max()))
    h0 = float(z.min())
    enu = to_enu(lat, lon, z, lat0, lon0, h0)
    pos = " ".join(fmt(float(v)) for v in enu.ravel())
    idx = " ".join(str(int(i)) for i in np.ravel(tris))
    (Path(out) / "dsm.dae").write_text(
        '<?xml version="1.0" encoding="utf-8"?>\n'
        '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">\n'
        "<asset><created>2024-01-01T00:00:00</created><modified>2024-01-01T00:00:00</modified>"
        '<unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>\n'
        '<library_geometries><geometry id="g"><mesh>\n'
        f'<source id="pos"><float_array id="pos-a" count="{enu.size}">{pos}</float_array>'
        f'<technique_common><accessor source="#pos-a" count="{len(enu)}" stride="3"><param name="X" type="float"/>'
        '<param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>\n'
        '<vertices id="v"><input semantic="POSITION" source="#pos"/></vertices>\n'
        f'<triangles count="{len(tris)}"><input semantic="VERTEX" source="#v" offset="0"/><p>{idx}</p></triangles>\n'
        "</mesh></geometry></library_geometries>\n"
        '<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node>'
        '</visual_scene></library_visual_scenes>\n<scene><instance_visual_scene url="#s"/></scene>\n</COLLADA>\n')
    (Path(out) / "dsm-model.kml").write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">\n'
        "<Placemark><name>DSM</name><Model><altitudeMode>absolute</altitudeMode>"
        f"<Location><longitude>{lon0!r}</longitude><latitude>{lat0!r}</latitude><altitude>{h0!r}</altitude>"
        "</Location><Link><href>dsm.dae</href></Link></Model></Placemark>\n</kml>\n")
    return enu


def viewer_data(pts, tris, std, diff):
    """The 3D viewer's scene as terramesh_report::viewer writes it: float32 offsets from an origin
    (bbox centre in x, y; lowest z), Uint32 triangles, float32 fields, all base64."""
    origin = [float((pts[:, 0].min() + pts[:, 0].max()) / 2), float((pts[:, 1].min() + pts[:, 1].max()) / 2),
              float(pts[:, 2].min())]
    b64 = lambda a, t: base64.b64encode(np.asarray(a, dtype=t).tobytes()).decode()
    field = lambda label, colours, v: {"label": label, "unit": "m", "lo": float(v.min()), "hi": float(v.max()),
                                       "colours": colours, "diverging": False}
    grey = [[0, 0, 0], [255, 255, 255]]
    layer = {"name": "DSM surface", "kind": "triangles", "vertices": len(pts), "triangles": len(tris),
             "positions": b64(pts - origin, "<f4"), "indices": b64(tris, "<u4"),
             "fields": {"elevation": b64(pts[:, 2], "<f4"), "kriging_std": b64(std, "<f4"),
                        "uk_minus_idw": b64(diff, "<f4")},
             "colour": [200, 200, 200], "visible": True, "pickable": True, "clipped": True}
    return json.dumps({"crs": "WGS 84 / UTM zone 32N", "note": None, "origin": origin,
                       "fields": {"elevation": field("elevation", grey, pts[:, 2]),
                                  "kriging_std": field("kriging std", grey, std),
                                  "uk_minus_idw": field("UK minus IDW", grey, diff)},
                       "layers": [layer]})


def write_all(out):
    out = Path(out)
    (out / "pictures").mkdir(parents=True, exist_ok=True)
    xy, uk, std, idw, tris = surface()
    pts = np.column_stack([xy, uk])
    rows = ["x,y,elevation_uk,kriging_std,elevation_idw"]
    rows += [",".join(repr(float(v)) for v in r) for r in np.column_stack([xy, uk, std, idw])]
    (out / "dsm-vertices.csv").write_text("\n".join(rows) + "\n")
    fields = {"elevation_uk": uk, "kriging_std": std, "elevation_idw": idw, "uk_minus_idw": uk - idw}
    write_vtu(out / "dsm.vtu", pts, tris, fields, {"min_angle_deg": min_angles(xy, tris)})
    (out / "dsm.obj").write_text("".join(f"v {p[0]!r} {p[1]!r} {p[2]!r}\n" for p in pts.tolist())
                                 + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tris))
    write_ply(out / "dsm.ply", pts, tris, fields)
    write_stl(out / "dsm.stl", pts, tris, ORIGIN)
    (out / "dsm-origin.json").write_text(json.dumps(dict(zip("xyz", ORIGIN))) + "\n")
    (out / "dsm.ts").write_text("GOCAD TSurf 1\nHEADER {\nname:dsm\n}\nTFACE\n"
                                + "".join(f"VRTX {i + 1} {p[0]!r} {p[1]!r} {p[2]!r}\n" for i, p in enumerate(pts.tolist()))
                                + "".join(f"TRGL {a + 1} {b + 1} {c + 1}\n" for a, b, c in tris) + "END\n")
    write_msh(out / "dsm.msh", pts, tris)
    pts_l = pts.tolist()
    dxf = ["0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n"]
    for t in tris:
        dxf.append("0\n3DFACE\n8\nDSM\n" + "".join(
            f"1{k}\n{pts_l[i][0]!r}\n2{k}\n{pts_l[i][1]!r}\n3{k}\n{pts_l[i][2]!r}\n"
            for k, i in enumerate([*t, t[2]])))
    (out / "dsm.dxf").write_text("".join(dxf) + "0\nENDSEC\n0\nEOF\n")
    write_kml(out / "dsm.kml", xy, uk, tris)
    write_dae(out, xy, uk, tris)
    make_gltf_fixture.write_gltf(out, xy, uk, tris, EPSG)
    sp, st = solid(pts, tris, BASE)
    write_stl(out / "dsm-solid.stl", sp, st, ORIGIN)
    write_msh(out / "dsm-solid.msh", sp, st)
    a = xy[tris]
    area = 0.5 * ((a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1]) - (a[:, 2, 0] - a[:, 0, 0]) * (a[:, 1, 1] - a[:, 0, 1]))
    volume = float(np.sum(area * (uk[tris].mean(1) - BASE)))
    (out / "dsm-solid.json").write_text(json.dumps({"base_elevation": BASE, "volume": volume,
                                                           "vertices": len(sp), "triangles": len(st)}) + "\n")
    write_grids(out, xy, uk)
    fixture_terrain.write_terrain(out, xy, uk, tris, EPSG)
    (out / "samples.csv").write_text("x,y,elevation\n377010.5,5397020.25,351.5\n377150.0,5397100.0,360.25\n")
    (out / "mesh-quality.csv").write_text("metric,value\nmin_angle_deg,%r\n" % float(min_angles(xy, tris).min()))
    (out / "cross-validation.csv").write_text("x,y,observed,predicted,std\n377010.5,5397020.25,351.5,351.4,0.5\n")
    (out / "variogram.json").write_text(json.dumps({"model": "spherical", "nugget": 0.1, "sill": 4.0, "range": 120.0}) + "\n")
    png = write_png(out / "pictures" / "dsm.png")
    (out / "pictures" / "dsm.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
                                              '<rect width="10" height="10" fill="teal"/></svg>\n')
    uri = "data:image/png;base64," + base64.b64encode(png).decode()
    viewer = viewer_data(pts, tris, std, uk - idw)
    (out / "report.html").write_text(
        f'<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>DSM report</title>'
        f"<style>body{{background:{CHECKER};font-family:sans-serif}}</style></head><body>"
        f'<h1>Discrete surface model</h1><p>{len(tris)} triangles.</p><img alt="dsm" width="400" src="{uri}">'
        f'<script type="application/json" id="tmv-data">{viewer}</script>'
        f"</body></html>\n")


if __name__ == "__main__":
    write_all(sys.argv[1])
