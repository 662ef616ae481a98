"""terramesh's geological model against OpenGeoSys' own layered mesher (issue 13).

    .venv-verify/bin/python tests/verify/compare_ogs_layered.py --terramesh target/release/terramesh
        [--min-thickness 0] [--tol 1e-6] [--keep DIR]

Builds one case twice, with `terramesh model` and with OpenGeoSys' `createLayeredMeshFromRasters`
(the `ogs` wheel), from the same inputs:

* the horizon grids of Shellmound (`fixtures/data/geology/shellmound/{mccu,mcaq,mdwy}_surf.tif`,
  USGS MERAS, feet, EPSG:5070 and EPSG:4269). OpenGeoSys reads only grids in the mesh's own
  coordinates (no CRS), so this script first resamples each into an ESRI ASCII grid in
  NAD83 / UTM 15N metres (pyproj moves the 400 m posts into the grid's CRS, bilinear between
  the source's pixel centres, nodata where one of the four is nodata); **both** programs then
  read these same `.asc` files (with a `.prj` that terramesh reads and OpenGeoSys ignores).
* a planar terrain about 40 m high (a DEM `.asc` for OpenGeoSys; samples of the same plane for
  terramesh, whose universal kriging with a linear drift reproduces a plane exactly, as
  OpenGeoSys' bilinear interpolation does) and a flat base at -500 m. The committed DEM
  crop does not reach the area where the Middle Claiborne confining unit (mccu) pinches out,
  which is the case this comparison needs, so the terrain is synthetic; it lies above every
  grid, so nothing is eroded.
* the same planar mesh: terramesh's `model-top.vtu` (its planar triangles at the terrain) is the
  2D input mesh of `createLayeredMeshFromRasters`.

The region (12 km x 8 km, west of the example's) crosses the edge of mccu.

What OpenGeoSys does (MeshToolsLib/MeshGenerators/MeshLayerMapper.cpp and
GeoLib/Raster.cpp of OpenGeoSys 6.5): `Raster::interpolateValueAtPoint` is bilinear between
pixel centres, the origin being `xllcorner` (pixel-is-area, like terramesh); a pixel that is
nodata (or off the grid) gets weight 0 and the others are renormalised, so the value is nodata
only when all four are. The layers are built **from the bottom up**: a raster's value at a node
is `min(value, DEM)`, and a node whose value is nodata, or less than `min_thickness` above the
node below, is that node (the layer has zero thickness there). terramesh goes **from the top
down** (a unit thinner than `min_thickness` collapses onto its top, see docs/geology.md), and
a point where one of its four pixels is nodata is nodata. So the two agree exactly on every
planar triangle none of whose vertices has a partly-nodata 2 x 2 block ("both sample the grids
the same way"), with `min_thickness = 0` (where the two orders give the same stack when no grid
crosses the one above it, which the script checks). The rest is printed and explained in
docs/geology.md.

OpenGeoSys numbers MaterialIDs from the bottom layer, terramesh from the top unit: the script
maps them. Exits 1 when a compared unit volume differs by more than `--tol` (relative).
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from check_model import VTK_FACES, ogs_tool, polyhedron_volume
from vcommon import meshio_read

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
GRIDS = ROOT / "fixtures" / "data" / "geology" / "shellmound"
UNITS = ["cover", "mccu", "mcaq", "mdwy"]
BASE = -900.0


def terrain(x, y):
    """The synthetic terrain (m): a gentle plane."""
    return 40.0 + 0.001 * (x - X0) + 0.0005 * (y - Y0)


# Region (NAD83 / UTM 15N) and the resampled grids' posts.
X0, X1, Y0, Y1 = 728_000.0, 740_000.0, 3_722_000.0, 3_730_000.0
STEP, PAD = 400.0, 2_000.0
NODATA = -9999.0
FT = 0.3048


def resample(name):
    """The Shellmound grid `name` in UTM 15N metres: (xll corner, yll corner, rows top first)."""
    import pyproj
    import rasterio

    with rasterio.open(GRIDS / f"{name}_surf.tif") as r:
        a = r.read(1).astype(np.float64)
        void = ~np.isfinite(a) | (a == r.nodata) | (a < -1e30)
        inv = ~r.transform
        crs = r.crs.to_wkt()
    t = pyproj.Transformer.from_crs("EPSG:26915", crs, always_xy=True)
    xs = np.arange(X0 - PAD, X1 + PAD + STEP / 2, STEP)  # post centres
    ys = np.arange(Y0 - PAD, Y1 + PAD + STEP / 2, STEP)
    gx, gy = np.meshgrid(xs, ys[::-1])  # top row first (the north), as ESRI grids are written
    sx, sy = t.transform(gx.ravel(), gy.ravel())
    col, row = inv * (np.asarray(sx), np.asarray(sy))
    c, rr = np.asarray(col) - 0.5, np.asarray(row) - 0.5  # from pixel centres
    c0, r0 = np.floor(c).astype(int), np.floor(rr).astype(int)
    fc, fr = c - c0, rr - r0
    out = np.zeros(c.size)
    bad = (c0 < 0) | (r0 < 0) | (c0 + 1 >= a.shape[1]) | (r0 + 1 >= a.shape[0])
    c0, r0 = np.clip(c0, 0, a.shape[1] - 2), np.clip(r0, 0, a.shape[0] - 2)
    for dr, dc, w in [(0, 0, (1 - fr) * (1 - fc)), (0, 1, (1 - fr) * fc), (1, 0, fr * (1 - fc)), (1, 1, fr * fc)]:
        out += w * a[r0 + dr, c0 + dc]
        bad |= void[r0 + dr, c0 + dc]
    if (bad & (out == out)).all():
        raise SystemExit(f"{name}: no post of the region has data")
    out = np.where(bad, NODATA, out * FT).reshape(gx.shape)
    return xs[0] - STEP / 2, ys[0] - STEP / 2, out


def write_asc(path, xll, yll, rows):
    """An ESRI ASCII grid, and its .prj (NAD83 / UTM 15N, ESRI WKT) for terramesh."""
    import pyproj

    Path(path).with_suffix(".prj").write_text(pyproj.CRS("EPSG:26915").to_wkt("WKT1_ESRI"))
    with open(path, "w") as f:
        f.write(f"ncols {rows.shape[1]}\nnrows {rows.shape[0]}\nxllcorner {float(xll)!r}\nyllcorner {float(yll)!r}\n")
        f.write(f"cellsize {STEP!r}\nNODATA_value {NODATA!r}\n")
        for r in rows:
            f.write(" ".join(repr(float(v)) for v in r) + "\n")


def dem_posts(xll, yll, shape):
    """The (x, y) of an ESRI grid's pixel centres, top row first."""
    xs = xll + STEP * (np.arange(shape[1]) + 0.5)
    ys = yll + STEP * (np.arange(shape[0]) + 0.5)
    return np.meshgrid(xs, ys[::-1])


def project_toml(grids, min_thickness):
    surfaces = ", ".join(f'{u} = "{grids[u].name}"' for u in UNITS[1:])
    return f"""title = "terramesh against createLayeredMeshFromRasters (Shellmound grids)"
[region]
corners = "{Y0} {X0}; {Y0} {X1}; {Y1} {X1}; {Y1} {X0}"
crs = "EPSG:26915"
[source]
path = "terrain.csv"
[sampling]
rows = 12
cols = 12
[mesh]
min_angle = 30.0
max_area = 400000.0
[interpolation]
methods = ["uk"]
drift = "linear"
[export]
formats = []
pictures = false
report = false
[geology]
units = {UNITS!r}
surfaces = {{ {surfaces} }}
base = {BASE}
min_thickness = {min_thickness}
interpolate = "tops"
""".replace("'", '"')


def run(cmd, cwd):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))} failed:\n{(r.stdout + r.stderr)[-2000:]}")
    return r.stdout + r.stderr


def per_triangle(mesh, material_of):
    """{(unit, triangle key): volume} for a VTU's cells; the key is the cell's plan triangle
    (its three distinct (x, y), rounded to a millimetre)."""
    out = {}
    pts = mesh.points
    for block, mats in zip(mesh.cells, mesh.cell_data["MaterialIDs"]):
        table = VTK_FACES[block.type]
        for cell, m in zip(block.data, np.asarray(mats).ravel()):
            if block.type == "wedge":  # meshio reorders VTK wedges into Gmsh's order
                cell = cell[[0, 2, 1, 3, 5, 4]]
            v = abs(polyhedron_volume(pts, [[cell[i] for i in f] for f in table]))
            key = frozenset((round(pts[n, 0], 3), round(pts[n, 1], 3)) for n in cell)
            assert len(key) == 3, key
            k = (material_of(int(m)), key)
            out[k] = out.get(k, 0.0) + v
    return out


def partly_void(grid, x, y):
    """Whether the 2 x 2 block of pixel centres around (x, y) mixes data and nodata."""
    xll, yll, rows = grid
    a = rows[::-1]  # row 0 the south
    c, r = (x - xll) / STEP - 0.5, (y - yll) / STEP - 0.5
    c0, r0 = int(np.floor(c)), int(np.floor(r))
    block = a[r0:r0 + 2, c0:c0 + 2] == NODATA
    return bool(block.any() and not block.all())


def compare(terramesh, min_thickness, tol, keep=None):
    work = Path(keep) if keep else Path(tempfile.mkdtemp(prefix="ogs-layered-"))
    work.mkdir(parents=True, exist_ok=True)
    grids, files = {}, {}
    for u in UNITS[1:]:
        grids[u] = resample(u)
        files[u] = work / f"{u}.asc"
        write_asc(files[u], *grids[u])
    xll, yll, anyg = grids[UNITS[1]]
    write_asc(work / "dem.asc", xll, yll, terrain(*dem_posts(xll, yll, anyg.shape)))
    write_asc(work / "base.asc", xll, yll, np.full(anyg.shape, BASE))
    with open(work / "terrain.csv", "w") as f:
        f.write("x,y,z\n")
        for x in np.linspace(X0 - PAD / 2, X1 + PAD / 2, 15):
            for y in np.linspace(Y0 - PAD / 2, Y1 + PAD / 2, 11):
                f.write(f"{float(x)!r},{float(y)!r},{float(terrain(x, y))!r}\n")
    (work / "terramesh.toml").write_text(project_toml(files, min_thickness))
    run([terramesh, "model", "terramesh.toml", "-o", "tm"], work)
    (work / "layers.txt").write_text("".join(f"{p}\n" for p in
                                             ["dem.asc"] + [files[u].name for u in UNITS[1:]] + ["base.asc"]))
    run([ogs_tool("createLayeredMeshFromRasters"), "-i", "tm/model-top.vtu", "-o", "ogs.vtu",
         "-r", "layers.txt", "-t", str(min_thickness)], work)

    ours = per_triangle(meshio_read(work / "tm" / "model.vtu"), lambda m: m)
    theirs = per_triangle(meshio_read(work / "ogs.vtu"), lambda m: len(UNITS) - 1 - m)
    top = meshio_read(work / "tm" / "model-top.vtu")
    tris = [frozenset((round(p[0], 3), round(p[1], 3)) for p in top.points[t])
            for b in top.cells for t in b.data]
    mixed = set()
    for t in tris:
        if any(partly_void(grids[u], x, y) for u in UNITS[1:] for x, y in t):
            mixed.add(t)
    print(f"{len(tris)} planar triangles, {len(mixed)} with a vertex on a partly-nodata 2 x 2 "
          f"block of some grid (OpenGeoSys averages the pixels with data, terramesh calls it nodata)")
    failed = 0
    for u, name in enumerate(UNITS):
        same = [t for t in tris if t not in mixed]
        a = sum(ours.get((u, t), 0.0) for t in same)
        b = sum(theirs.get((u, t), 0.0) for t in same)
        whole_a = sum(v for (k, _), v in ours.items() if k == u)
        whole_b = sum(v for (k, _), v in theirs.items() if k == u)
        rel = abs(a - b) / max(abs(b), 1e-300) if (a or b) else 0.0
        ok = rel <= tol
        failed += not ok
        print(f"{'PASS' if ok else 'FAIL'} {name}: same sampling {a:.6e} m3 (terramesh) vs {b:.6e} "
              f"(OpenGeoSys), relative {rel:.2e}; all triangles {whole_a:.6e} vs {whole_b:.6e} "
              f"({(whole_a - whole_b) / max(abs(whole_b), 1e-300):+.2e})")
    total_a, total_b = sum(ours.values()), sum(theirs.values())
    print(f"total {total_a:.9e} vs {total_b:.9e} m3; OpenGeoSys {len(theirs)} (unit, triangle) pairs "
          f"with volume, terramesh {len(ours)}")
    if not keep:
        shutil.rmtree(work, ignore_errors=True)
    return failed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--terramesh", required=True, help="the terramesh binary")
    ap.add_argument("--min-thickness", type=float, default=0.0)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--keep", help="work in this folder and keep it")
    a = ap.parse_args(argv)
    failed = compare(str(Path(a.terramesh).resolve()), a.min_thickness, a.tol, a.keep)
    print("ok" if not failed else f"{failed} unit(s) differ")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
