"""Checks the outputs of `terramesh build` with readers that share no code with terramesh.

    python tests/verify/verify_outputs.py OUT_DIR [--compare OUT_DIR2]

Prints one line per check (`PASS name` or `FAIL name: why`), then `N passed, M failed`, and
exits 1 if any check failed. The reference is `dsm-vertices.csv` (the library's values) with the
triangles of `dsm.vtu`; every other file is compared to it. See docs/verification.md.
"""

import argparse
import base64
import csv
import contextlib
import html.parser
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import warnings
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path

import numpy as np

from vcommon import (F32_EPS, GRID_OVERSHOOT, KML_ALT, KML_DEG, NOT_DETERMINISTIC, POINT_FIELDS, CELL_FIELDS,
                     REL_DOUBLE, REL_FLOAT32, CheckFailed, Outputs, canonical_triangles, close, kml_schema_dir,
                     planar_areas, require, signed_volume, single_triangle_block, watertight, xmllint_schema)
import check_collada
import check_model
import check_model_glb
import check_gltf
import check_py3dtiles
import check_viewer
import check_programs
import check_terrain


# ---------------------------------------------------------------- surface mesh checks


def compare_surface(name, pts, tris, ref_pts, ref_tris, rel):
    """Same vertex and triangle counts, same connectivity, same z, same planar area."""
    require(len(pts) == len(ref_pts), f"{name}: {len(pts)} vertices, dsm-vertices.csv has {len(ref_pts)}")
    require(len(tris) == len(ref_tris), f"{name}: {len(tris)} triangles, dsm.vtu has {len(ref_tris)}")
    close(pts[:, :2], ref_pts[:, :2], rel, f"{name}: vertex x,y")
    close(pts[:, 2], ref_pts[:, 2], rel, f"{name}: vertex z vs elevation_uk")
    require(np.array_equal(canonical_triangles(tris), canonical_triangles(ref_tris)),
            f"{name}: triangles differ from dsm.vtu's")
    close(planar_areas(pts, tris).sum(), planar_areas(ref_pts, ref_tris).sum(), rel, f"{name}: planar area")


def check_vtu(out):
    """dsm.vtu (meshio): geometry, point data equal to the CSV, min_angle_deg recomputed."""
    import meshio
    cols, ref_pts, tris = out.ref()
    m = meshio.read(out.path("dsm.vtu"))
    compare_surface("dsm.vtu", m.points, tris, ref_pts, tris, REL_DOUBLE)
    for name in POINT_FIELDS:
        require(name in m.point_data, f"dsm.vtu: point data '{name}' missing (has {sorted(m.point_data)})")
    for name in ["elevation_uk", "kriging_std", "elevation_idw"]:
        close(m.point_data[name], cols[name], REL_DOUBLE, f"dsm.vtu: {name} vs CSV")
    close(m.point_data["uk_minus_idw"], cols["elevation_uk"] - cols["elevation_idw"], REL_DOUBLE,
          "dsm.vtu: uk_minus_idw vs CSV elevation_uk - elevation_idw", atol=1e-9)
    for name in CELL_FIELDS:
        require(name in m.cell_data, f"dsm.vtu: cell data '{name}' missing (has {sorted(m.cell_data)})")
    ang = np.concatenate([np.ravel(a) for a in m.cell_data["min_angle_deg"]])
    close(ang, min_angles_deg(ref_pts[:, :2], tris), 1e-9, "dsm.vtu: min_angle_deg vs recomputed", atol=1e-6)


def min_angles_deg(xy, tris):
    p = xy[tris]
    out = np.full(len(tris), np.inf)
    for k in range(3):
        u, v = p[:, (k + 1) % 3] - p[:, k], p[:, (k + 2) % 3] - p[:, k]
        ang = np.degrees(np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]), np.einsum("ij,ij->i", u, v)))
        out = np.minimum(out, ang)
    return out


def check_orientation(out):
    """Every triangle of dsm.vtu counter-clockwise seen from above (positive planar area)."""
    _, pts, tris = out.ref()
    a = planar_areas(pts, tris)
    require(np.all(a > 0), f"dsm.vtu: {int(np.sum(a <= 0))} triangles not counter-clockwise, e.g. #{int(np.argmin(a))}")


def check_meshio_surface(out, name):
    import meshio
    _, ref_pts, ref_tris = out.ref()
    m = meshio.read(out.path(name))
    compare_surface(name, m.points, single_triangle_block(m, name), ref_pts, ref_tris, REL_DOUBLE)
    return m


def check_obj(out):
    """dsm.obj (meshio)."""
    check_meshio_surface(out, "dsm.obj")


def check_msh(out):
    """dsm.msh (meshio, Gmsh 4.1)."""
    require(out.path("dsm.msh").read_text().split("\n")[1].split()[0] == "4.1", "dsm.msh: not MSH 4.1")
    check_meshio_surface(out, "dsm.msh")


def check_ply(out):
    """dsm.ply (meshio): binary, double x/y/z, and per-vertex fields equal to the CSV."""
    head = out.path("dsm.ply").read_bytes().split(b"end_header", 1)[0].decode("ascii", "replace")
    require(re.search(r"^format binary_little_endian 1.0$", head, re.M), "dsm.ply: not binary_little_endian PLY")
    for c in "xyz":
        require(re.search(rf"^property double {c}$", head, re.M), f"dsm.ply: {c} is not a double property")
    cols, _, _ = out.ref()
    m = check_meshio_surface(out, "dsm.ply")
    for name in ["elevation_uk", "kriging_std", "elevation_idw"]:
        if name in m.point_data:
            close(m.point_data[name], cols[name], REL_DOUBLE, f"dsm.ply: {name} vs CSV")


def read_stl_checked(out, name):
    """meshio's points (merged) and triangles, plus the origin from dsm-origin.json."""
    import meshio
    p = out.path(name)
    data = p.read_bytes()
    require(len(data) >= 84, f"{name}: shorter than a binary STL header")
    n = int.from_bytes(data[80:84], "little")
    require(len(data) == 84 + 50 * n, f"{name}: {len(data)} bytes, a binary STL of {n} triangles has {84 + 50 * n}")
    origin = out.origin()
    header = data[:80].decode("ascii", "replace")
    mo = re.search(r"origin (\S+) (\S+) (\S+)", header)
    require(mo is not None, f"{name}: header does not name the origin: {header.strip()!r}")
    close([float(v) for v in mo.groups()], origin, 1e-12, f"{name}: header origin vs dsm-origin.json")
    m = meshio.read(p, file_format="stl")
    return m.points.astype(np.float64), single_triangle_block(m, name), origin


def check_stl(out):
    """dsm.stl (meshio): triangles, float32 geometry + origin, planar area."""
    _, ref_pts, ref_tris = out.ref()
    pts, tris, origin = read_stl_checked(out, "dsm.stl")
    require(len(tris) == len(ref_tris), f"dsm.stl: {len(tris)} triangles, dsm.vtu has {len(ref_tris)}")
    local = ref_pts[ref_tris] - origin
    got = pts[tris]
    err = np.abs(got - local)
    tol = F32_EPS * np.maximum(np.abs(local), 1e-30)
    require(np.all(err <= tol), f"dsm.stl: triangle #{int(np.argmax((err - tol).max(axis=(1, 2))))} differs "
            "from dsm.vtu's beyond float32 rounding (after subtracting the origin)")
    area = planar_areas(pts + origin, tris).sum()
    close(area, planar_areas(ref_pts, ref_tris).sum(), REL_FLOAT32, "dsm.stl: planar area")


def check_tsurf(out):
    """dsm.ts with OpenGeoSys's GocadTSurfaceReader (C++, from the `ogs` wheel)."""
    import meshio
    _, ref_pts, ref_tris = out.ref()
    exe = shutil.which("GocadTSurfaceReader", path=os.pathsep.join([str(Path(sys.executable).parent),
                                                                     os.environ.get("PATH", "")]))
    require(exe is not None, "GocadTSurfaceReader not found: pip install ogs (see tests/verify/requirements.txt)")
    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run([exe, "-s", "-l", "warn", "-i", str(out.path("dsm.ts")), "-o", tmp],
                           capture_output=True, text=True, timeout=300)
        msg = (r.stdout + r.stderr).strip().replace("\n", " | ")
        require(r.returncode == 0, f"dsm.ts: GocadTSurfaceReader failed: {msg}")
        vtus = sorted(Path(tmp).glob("*.vtu"))
        require(len(vtus) == 1, f"dsm.ts: expected one surface, GocadTSurfaceReader wrote {len(vtus)}")
        m = meshio.read(vtus[0])
    compare_surface("dsm.ts", m.points, single_triangle_block(m, "dsm.ts"), ref_pts, ref_tris, REL_DOUBLE)


def check_dxf(out):
    """dsm.dxf (ezdxf): one 3DFACE per triangle, corners equal to the mesh's."""
    import ezdxf
    _, ref_pts, ref_tris = out.ref()
    try:
        doc = ezdxf.readfile(out.path("dsm.dxf"))
    except (IOError, ezdxf.DXFError) as e:
        raise CheckFailed(f"dsm.dxf: ezdxf cannot read it: {e}")
    faces = doc.modelspace().query("3DFACE")
    require(len(faces) == len(ref_tris), f"dsm.dxf: {len(faces)} 3DFACEs, dsm.vtu has {len(ref_tris)} triangles")
    got = np.array([[list(f.dxf.get(f"vtx{k}")) for k in range(4)] for f in faces])
    close(got[:, 3], got[:, 2], 0.0, "dsm.dxf: 4th corner repeats the 3rd")
    close(got[:, :3], ref_pts[ref_tris], REL_DOUBLE, "dsm.dxf: 3DFACE corners vs mesh")


# ---------------------------------------------------------------- KML


def check_kml_schema(out):
    """dsm.kml valid against the OGC KML 2.2 schema (xmllint, pykml's offline XSDs)."""
    xmllint_schema(out, "dsm.kml", kml_schema_dir() / "ogckml22.xsd")


def check_kml_geometry(out):
    """dsm.kml: one absolute-altitude closed triangle per mesh triangle, lon/lat = PROJ's."""
    from pyproj import Transformer
    ns = {"k": "http://www.opengis.net/kml/2.2"}
    _, ref_pts, ref_tris = out.ref()
    root = ET.parse(out.path("dsm.kml")).getroot()
    require(root.tag == "{http://www.opengis.net/kml/2.2}kml", f"dsm.kml: root element {root.tag}")
    polys = root.findall(".//k:Polygon", ns)
    require(len(polys) == len(ref_tris), f"dsm.kml: {len(polys)} polygons, dsm.vtu has {len(ref_tris)} triangles")
    modes = [p.findtext("k:altitudeMode", None, ns) for p in polys]
    bad = [i for i, m in enumerate(modes) if (m or "").strip() != "absolute"]
    require(not bad, f"dsm.kml: polygon #{bad[0] if bad else 0} altitudeMode {modes[bad[0]] if bad else ''!r}, "
            "expected 'absolute'")
    rings = []
    for i, p in enumerate(polys):
        text = p.findtext("k:outerBoundaryIs/k:LinearRing/k:coordinates", "", ns)
        c = np.array([[float(v) for v in t.split(",")] for t in text.split()])
        require(c.shape == (4, 3), f"dsm.kml: polygon #{i} has coordinates of shape {c.shape}, expected 4 x 3")
        require(np.array_equal(c[0], c[3]), f"dsm.kml: polygon #{i} ring not closed")
        rings.append(c[:3])
    got = np.array(rings)
    epsg = out.epsg()
    require(epsg is not None, "dsm.kml: no EPSG in dsm.tif to project the vertices")
    lon, lat = Transformer.from_crs(epsg, 4326, always_xy=True).transform(ref_pts[:, 0], ref_pts[:, 1])
    want = np.column_stack([lon, lat])[ref_tris]
    close(got[..., :2], want, 0.0, "dsm.kml: lon/lat vs PROJ", atol=KML_DEG)
    close(got[..., 2], ref_pts[ref_tris][..., 2], 0.0, "dsm.kml: altitude vs elevation_uk", atol=KML_ALT)


# ---------------------------------------------------------------- sealed solid


def solid_info(out):
    info = json.loads(out.path("dsm-solid.json").read_text())
    require(set(info) >= {"base_elevation", "volume"}, f"dsm-solid.json: keys {sorted(info)}")
    return float(info["base_elevation"]), float(info["volume"])


def check_solid_stl(out):
    """dsm-solid.stl (meshio, merged vertices): watertight, outward, volume = dsm-solid.json's."""
    base, volume = solid_info(out)
    pts, tris, origin = read_stl_checked(out, "dsm-solid.stl")
    watertight(tris, "dsm-solid.stl")
    v = signed_volume(pts, tris)
    require(v > 0, f"dsm-solid.stl: signed volume {v} not positive (triangles face inward)")
    close(v, volume, REL_FLOAT32, "dsm-solid.stl: volume vs dsm-solid.json")
    close(pts[:, 2].min() + origin[2], base, REL_FLOAT32, "dsm-solid.stl: lowest z vs base_elevation")


def check_solid_msh(out):
    """dsm-solid.msh (meshio): watertight, outward, volume = dsm-solid.json's, base and top."""
    import meshio
    base, volume = solid_info(out)
    _, ref_pts, _ = out.ref()
    m = meshio.read(out.path("dsm-solid.msh"))
    tris = single_triangle_block(m, "dsm-solid.msh")
    watertight(tris, "dsm-solid.msh")
    v = signed_volume(m.points - m.points.mean(axis=0), tris)
    require(v > 0, f"dsm-solid.msh: signed volume {v} not positive (triangles face inward)")
    close(v, volume, REL_DOUBLE, "dsm-solid.msh: volume vs dsm-solid.json")
    close(m.points[:, 2].min(), base, REL_DOUBLE, "dsm-solid.msh: lowest z vs base_elevation")
    close(m.points[:, 2].max(), ref_pts[:, 2].max(), REL_DOUBLE, "dsm-solid.msh: highest z vs elevation_uk max")


def check_solid_volume(out):
    """dsm-solid.json volume = integral of (elevation_uk - base) over the surface; base below it."""
    base, volume = solid_info(out)
    _, pts, tris = out.ref()
    require(base < pts[:, 2].min(), f"dsm-solid.json: base_elevation {base} not below the surface "
            f"(lowest elevation_uk {pts[:, 2].min()})")
    integral = float(np.sum(planar_areas(pts, tris) * (pts[tris, 2].mean(axis=1) - base)))
    close(volume, integral, REL_DOUBLE, "dsm-solid.json: volume vs integral of (z - base) over dsm")


# ---------------------------------------------------------------- grids


def check_grids(out):
    """dsm.tif and dsm.asc (rasterio): shape, UTM EPSG, transform, equal values, range."""
    import rasterio
    cols, pts, _ = out.ref()
    # GDAL reads ESRI ASCII grids as float32 unless told otherwise.
    with rasterio.Env(AAIGRID_DATATYPE="Float64"), rasterio.open(out.path("dsm.tif")) as t, \
            rasterio.open(out.path("dsm.asc")) as a:
        epsg = t.crs.to_epsg() if t.crs else None
        require(epsg is not None and (32601 <= epsg <= 32660 or 32701 <= epsg <= 32760),
                f"dsm.tif: CRS EPSG {epsg} is not WGS 84 / UTM (326xx/327xx)")
        require(t.dtypes[0] == "float64", f"dsm.tif: data type {t.dtypes[0]}, expected float64")
        require(t.shape == a.shape, f"dsm.tif shape {t.shape} != dsm.asc shape {a.shape}")
        close(list(t.transform)[:6], list(a.transform)[:6], REL_DOUBLE, "dsm.tif vs dsm.asc: geotransform")
        tm, am = t.read(1, masked=True), a.read(1, masked=True)
        b = t.bounds
    require(np.array_equal(np.ma.getmaskarray(tm), np.ma.getmaskarray(am)), "dsm.tif and dsm.asc: nodata cells differ")
    valid = ~np.ma.getmaskarray(tm)
    require(valid.any(), "dsm.tif: every cell is nodata")
    close(tm.data[valid], am.data[valid], REL_DOUBLE, "dsm.tif vs dsm.asc: values")
    lo, hi = cols["elevation_uk"].min(), cols["elevation_uk"].max()
    slack = GRID_OVERSHOOT * (hi - lo)
    v = tm.data[valid]
    require(np.all(np.isfinite(v)), "dsm.tif: non-finite values outside nodata")
    require(v.min() >= lo - slack and v.max() <= hi + slack,
            f"dsm.tif: values {v.min()}..{v.max()} outside elevation_uk {lo}..{hi} (+-{GRID_OVERSHOOT:.0%})")
    dx = (b.right - b.left) / tm.shape[1]
    require(b.left <= pts[:, 0].min() + dx and b.right >= pts[:, 0].max() - dx
            and b.bottom <= pts[:, 1].min() + dx and b.top >= pts[:, 1].max() - dx,
            f"dsm.tif: bounds {tuple(b)} do not cover the mesh")


# ---------------------------------------------------------------- report and pictures


def png_ok(data):
    """Walks the PNG chunks, checking signature, CRCs, IHDR first, IEND last."""
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "no PNG signature"
    pos, tags = 8, []
    while pos < len(data):
        if pos + 12 > len(data):
            return "truncated chunk"
        n = int.from_bytes(data[pos:pos + 4], "big")
        tag, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if len(body) != n or pos + 12 + n > len(data):
            return f"truncated {tag!r} chunk"
        if zlib.crc32(tag + body) != int.from_bytes(data[pos + 8 + n:pos + 12 + n], "big"):
            return f"bad CRC in {tag!r}"
        tags.append(tag)
        pos += 12 + n
    if not tags or tags[0] != b"IHDR" or tags[-1] != b"IEND" or b"IDAT" not in tags:
        return f"chunks {tags[:3]}...{tags[-1:]} lack IHDR/IDAT/IEND"
    return None


class _Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.refs, self.imgs, self.scripts, self.script_src = [], [], 0, []

    def handle_starttag(self, tag, attrs):
        for k, v in attrs:
            if k in ("src", "href", "srcset", "poster", "data", "action") and v:
                self.refs.append((tag, k, v))
        if tag == "img":
            self.imgs.append(dict(attrs).get("src") or "")
        if tag == "script":
            self.scripts += 1
            if dict(attrs).get("src") is not None:
                self.script_src.append(dict(attrs)["src"])


def check_report_html(out):
    """report.html: scripts only inline (the 3D viewer), no external URLs, every <img> a data: URI of a
    valid PNG."""
    text = out.path("report.html").read_text(encoding="utf-8")
    p = _Links()
    p.feed(text)
    require(not p.script_src, f"report.html: <script src={p.script_src[:1]}>: scripts must be inline" if p.script_src else "")
    ext = [r for r in p.refs if re.match(r"\s*(https?:)?//", r[2], re.I)]
    require(not ext, f"report.html: external URL in <{ext[0][0]} {ext[0][1]}>: {ext[0][2][:80]}" if ext else "")
    css = re.findall(r"url\(\s*['\"]?\s*(?:https?:)?//", text, re.I) + re.findall(r"@import", text, re.I)
    require(not css, "report.html: external resource in CSS (url(http...) or @import)")
    require(p.imgs, "report.html: no <img>")
    for i, src in enumerate(p.imgs):
        require(src.startswith("data:image/png;base64,"), f"report.html: <img> #{i} is not a PNG data URI: {src[:60]}")
        try:
            data = base64.b64decode(src.split(",", 1)[1], validate=True)
        except ValueError as e:
            raise CheckFailed(f"report.html: <img> #{i} base64: {e}")
        err = png_ok(data)
        require(err is None, f"report.html: <img> #{i} is not a valid PNG: {err}")


def chromium_exe():
    for name in ["chromium", "chromium-browser", "google-chrome"]:
        exe = shutil.which(name)
        if exe:
            return exe
    raise CheckFailed("chromium not found: run .ci/verify-setup.sh")


def check_report_render(out):
    """report.html in headless Chromium: non-blank screenshot, no console messages."""
    import rasterio
    page = out.path("report.html").resolve()
    with tempfile.TemporaryDirectory() as tmp:
        shot = Path(tmp) / "shot.png"
        cmd = [chromium_exe(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               # Software WebGL for the 3D viewer (Chromium 137+ asks for this opt-in).
               "--enable-unsafe-swiftshader",
               f"--user-data-dir={tmp}/profile", "--enable-logging=stderr", "--v=0",
               f"--screenshot={shot}", "--window-size=1280,4000", page.as_uri()]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        # Software GL reports each read-back of a WebGL canvas (the screenshot) as a driver
        # performance notice; that one is the browser's, not the page's.
        console = [ln for ln in r.stderr.splitlines()
                   if ":CONSOLE" in ln and "GL Driver Message (OpenGL, Performance" not in ln]
        require(not console, f"report.html: console messages: {' | '.join(console)[:600]}")
        require(shot.is_file(), f"report.html: no screenshot (exit {r.returncode}): {r.stderr.strip()[-400:]}")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
            with rasterio.open(shot) as ds:
                img = ds.read()
    require(img.shape[1] > 100 and img.shape[2] > 100, f"report.html: screenshot only {img.shape}")
    require(len(np.unique(img.reshape(img.shape[0], -1), axis=1).T) > 2, "report.html: screenshot is blank")


def check_pictures(out):
    """pictures/: at least one PNG and one SVG; PNGs valid, SVGs well-formed with an <svg> root."""
    d = out.root / "pictures"
    require(d.is_dir(), "missing directory pictures/")
    pngs, svgs = sorted(d.glob("*.png")), sorted(d.glob("*.svg"))
    require(pngs and svgs, f"pictures/: {len(pngs)} PNG and {len(svgs)} SVG files")
    for f in pngs:
        err = png_ok(f.read_bytes())
        require(err is None, f"pictures/{f.name}: {err}")
    for f in svgs:
        try:
            root = ET.parse(f).getroot()
        except ET.ParseError as e:
            raise CheckFailed(f"pictures/{f.name}: not well-formed XML: {e}")
        require(root.tag == "{http://www.w3.org/2000/svg}svg", f"pictures/{f.name}: root {root.tag}")


def check_tables(out):
    """samples.csv, mesh-quality.csv, cross-validation.csv: a header and numeric rows; variogram.json parses."""
    for name in ["samples.csv", "mesh-quality.csv", "cross-validation.csv"]:
        with open(out.path(name), newline="") as f:
            rows = list(csv.reader(f))
        require(len(rows) >= 2, f"{name}: no data rows")
        widths = {len(r) for r in rows}
        require(len(widths) == 1, f"{name}: rows of different widths {sorted(widths)}")
    try:
        json.loads(out.path("variogram.json").read_text())
    except ValueError as e:
        raise CheckFailed(f"variogram.json: {e}")


# ---------------------------------------------------------------- determinism


def check_identical(out, other):
    """Every file byte-identical in a second build, except report.html and build.json (timings)."""
    a = {p.relative_to(out.root) for p in out.root.rglob("*") if p.is_file()}
    b = {p.relative_to(other) for p in Path(other).rglob("*") if p.is_file()}
    require(a == b, f"file lists differ: only in first {sorted(map(str, a - b))}, only in second {sorted(map(str, b - a))}")
    diff = [str(p) for p in sorted(a) if str(p) not in NOT_DETERMINISTIC
            and (out.root / p).read_bytes() != (Path(other) / p).read_bytes()]
    require(not diff, f"files differ between the two builds: {diff}")


CHECKS = [
    ("vertices csv + vtu triangles", lambda o: o.ref()),
    ("vtu: geometry, point and cell data", check_vtu),
    ("vtu: counter-clockwise triangles", check_orientation),
    ("obj", check_obj),
    ("ply", check_ply),
    ("msh", check_msh),
    ("stl", check_stl),
    ("tsurf (GocadTSurfaceReader)", check_tsurf),
    ("dxf (ezdxf)", check_dxf),
    ("kml schema (xmllint)", check_kml_schema),
    ("kml geometry", check_kml_geometry),
    *check_collada.CHECKS,
    *check_gltf.CHECKS,
    *check_py3dtiles.CHECKS,
    *check_terrain.CHECKS,
    ("solid stl: watertight, volume", check_solid_stl),
    ("solid msh: watertight, volume", check_solid_msh),
    *check_programs.CHECKS,
    ("solid volume vs surface integral", check_solid_volume),
    ("grids tif + asc (rasterio)", check_grids),
    ("report.html: self-contained", check_report_html),
    ("report.html: renders (chromium)", check_report_render),
    *check_viewer.CHECKS,
    ("pictures", check_pictures),
    ("tables", check_tables),
]


def run(out_dir, compare=None, only=None):
    """Runs the checks, prints a line each, returns (passed, failed)."""
    out = Outputs(out_dir)
    checks = list(CHECKS)
    if (out.root / "model.vtu").exists():  # a build with [geology]: the model's checks too
        checks += [(f"geology model: {n}", lambda o, fn=fn: fn(check_model.Model(o.root)))
                   for n, fn in check_model.CHECKS]
        if check_model_glb.glb_present(check_model.Model(out.root)):
            checks += [(f"geology model: {n}", lambda o, fn=fn: fn(check_model.Model(o.root)))
                       for n, fn in check_model_glb.CHECKS]
    if compare:
        checks.append(("determinism (--compare)", lambda o: check_identical(o, compare)))
    passed = failed = 0
    for name, fn in checks:
        if only and not any(name.startswith(s) for s in only):
            continue
        try:
            with contextlib.redirect_stdout(io.StringIO()):  # meshio prints blank lines
                fn(out)
        except CheckFailed as e:
            print(f"FAIL {name}: {e}", flush=True)
            failed += 1
        except (Exception, SystemExit) as e:  # a reader choking on a broken file fails the check
            print(f"FAIL {name}: {type(e).__name__}: {e}", flush=True)
            failed += 1
        else:
            print(f"PASS {name}", flush=True)
            passed += 1
    print(f"{passed} passed, {failed} failed")
    return passed, failed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir", help="output directory of `terramesh build`")
    ap.add_argument("--compare", metavar="OUT2", help="a second build's directory: files must be byte-identical")
    ap.add_argument("--only", action="append", help="run only the checks whose name starts with this (repeatable)")
    args = ap.parse_args(argv)
    if not Path(args.out_dir).is_dir():
        print(f"error: {args.out_dir} is not a directory", file=sys.stderr)
        return 2
    _, failed = run(args.out_dir, args.compare, args.only)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
