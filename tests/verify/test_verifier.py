"""Negative tests of verify_outputs.py: each check passes on a valid generated directory and
fails on a copy in which one file is broken.

    .venv-verify/bin/python -m pytest tests/verify
"""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_programs  # noqa: E402
import make_fixture as fx  # noqa: E402
import vcommon  # noqa: E402
import verify_outputs as vo  # noqa: E402


@pytest.fixture(scope="session")
def valid(tmp_path_factory):
    d = tmp_path_factory.mktemp("valid")
    fx.write_all(d)
    return d


@pytest.fixture
def out(valid, tmp_path):
    d = tmp_path / "out"
    shutil.copytree(valid, d)
    return d


def failures(d, check, capsys, compare=None):
    """Runs only the check named `check`; returns its FAIL lines."""
    names = [n for n, _ in vo.CHECKS] + ["determinism (--compare)"]
    assert check in names, check
    vo.run(d, compare=compare, only=[check])
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] in ("1 passed, 0 failed", "0 passed, 1 failed"), lines
    return [ln for ln in lines if ln.startswith("FAIL")]


def surface():
    xy, uk, std, idw, tris = fx.surface()
    return np.column_stack([xy, uk]), tris


def edit(path, old, new, count=1):
    s = path.read_text()
    assert old in s, old
    path.write_text(s.replace(old, new, count))


def test_valid_directory_passes_every_check(valid, capsys):
    assert vo.main([str(valid), "--compare", str(valid)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f"{len(vo.CHECKS) + 1} passed, 0 failed"


def test_cli_exits_nonzero_and_counts(out):
    (out / "dsm.obj").write_text("v 0 0 0\n")
    r = subprocess.run([sys.executable, str(HERE / "verify_outputs.py"), str(out), "--only", "obj"],
                       capture_output=True, text=True)
    assert r.returncode == 1
    assert r.stdout.splitlines()[-1] == "0 passed, 1 failed"


def test_csv_header(out, capsys):
    edit(out / "dsm-vertices.csv", "kriging_std", "std")
    assert "header" in failures(out, "vertices csv + vtu triangles", capsys)[0]


def test_vtu_missing_cell_data(out, capsys):
    edit(out / "dsm.vtu", 'Name="min_angle_deg"', 'Name="min_angle"')
    assert "min_angle_deg" in failures(out, "vtu: geometry, point and cell data", capsys)[0]


def test_vtu_point_data_differs(out, capsys):
    pts, tris = surface()
    xy, uk, std, idw, _ = fx.surface()
    fields = {"elevation_uk": uk, "kriging_std": std * 1.01, "elevation_idw": idw, "uk_minus_idw": uk - idw}
    fx.write_vtu(out / "dsm.vtu", pts, tris, fields, {"min_angle_deg": fx.min_angles(xy, tris)})
    assert "kriging_std" in failures(out, "vtu: geometry, point and cell data", capsys)[0]


def test_vtu_clockwise_triangle(out, capsys):
    pts, tris = surface()
    xy, uk, std, idw, _ = fx.surface()
    tris[3] = tris[3][::-1]
    fields = {"elevation_uk": uk, "kriging_std": std, "elevation_idw": idw, "uk_minus_idw": uk - idw}
    fx.write_vtu(out / "dsm.vtu", pts, tris, fields, {"min_angle_deg": fx.min_angles(xy, tris)})
    assert "#3" in failures(out, "vtu: counter-clockwise triangles", capsys)[0]


def test_obj_missing_face(out, capsys):
    lines = (out / "dsm.obj").read_text().splitlines()
    (out / "dsm.obj").write_text("\n".join(lines[:-1]) + "\n")
    assert "triangles" in failures(out, "obj", capsys)[0]


def test_ply_ascii_rejected(out, capsys):
    pts, tris = surface()
    body = "".join(f"{p[0]!r} {p[1]!r} {p[2]!r}\n" for p in pts.tolist())
    body += "".join(f"3 {a} {b} {c}\n" for a, b, c in tris)
    (out / "dsm.ply").write_text(f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\nproperty double x\n"
                                 f"property double y\nproperty double z\nelement face {len(tris)}\n"
                                 f"property list uchar int vertex_indices\nend_header\n{body}")
    assert "binary" in failures(out, "ply", capsys)[0]


def test_ply_wrong_z(out, capsys):
    pts, tris = surface()
    pts[5, 2] += 0.01
    fx.write_ply(out / "dsm.ply", pts, tris, {})
    assert "elevation_uk" in failures(out, "ply", capsys)[0]


def test_msh_moved_node(out, capsys):
    pts, tris = surface()
    pts[2, 0] += 1e-3
    fx.write_msh(out / "dsm.msh", pts, tris)
    assert "x,y" in failures(out, "msh", capsys)[0]


def test_stl_truncated(out, capsys):
    data = (out / "dsm.stl").read_bytes()
    (out / "dsm.stl").write_bytes(data[:-20])
    assert "bytes" in failures(out, "stl", capsys)[0]


def test_stl_origin_mismatch(out, capsys):
    (out / "dsm-origin.json").write_text(json.dumps({"x": fx.ORIGIN[0] + 1, "y": fx.ORIGIN[1], "z": 0.0}))
    assert "origin" in failures(out, "stl", capsys)[0]


def test_stl_geometry(out, capsys):
    pts, tris = surface()
    pts[7, 2] += 0.05
    fx.write_stl(out / "dsm.stl", pts, tris, fx.ORIGIN)
    assert "float32" in failures(out, "stl", capsys)[0]


def test_tsurf_without_end(out, capsys):
    edit(out / "dsm.ts", "END\n", "")
    assert "GocadTSurfaceReader failed" in failures(out, "tsurf (GocadTSurfaceReader)", capsys)[0]


def test_tsurf_wrong_vertex(out, capsys):
    edit(out / "dsm.ts", "VRTX 2 ", "VRTX 2 1")  # prefixes x with a digit
    assert "x,y" in failures(out, "tsurf (GocadTSurfaceReader)", capsys)[0]


def test_dxf_missing_face(out, capsys):
    s = (out / "dsm.dxf").read_text()
    first = s.index("0\n3DFACE")
    second = s.index("0\n3DFACE", first + 1)
    (out / "dsm.dxf").write_text(s[:first] + s[second:])
    assert "3DFACEs" in failures(out, "dxf (ezdxf)", capsys)[0]


def test_kml_schema_invalid_element(out, capsys):
    edit(out / "dsm.kml", "<altitudeMode>", "<altitude>0</altitude><altitudeMode>")
    assert "xmllint" in failures(out, "kml schema (xmllint)", capsys)[0]


def test_kml_altitude_mode(out, capsys):
    edit(out / "dsm.kml", "<altitudeMode>absolute", "<altitudeMode>clampToGround", count=2)
    assert "absolute" in failures(out, "kml geometry", capsys)[0]
    assert not failures(out, "kml schema (xmllint)", capsys)  # schema-valid, caught by the geometry check


def test_kml_swapped_lon_lat(out, capsys):
    xy, uk, _, _, tris = fx.surface()
    fx.write_kml(out / "dsm.kml", xy, uk + 0.01, tris)
    assert "altitude" in failures(out, "kml geometry", capsys)[0]


def test_solid_stl_not_watertight(out, capsys):
    pts, tris = surface()
    sp, st = fx.solid(pts, tris, fx.BASE)
    fx.write_stl(out / "dsm-solid.stl", sp, st[:-1], fx.ORIGIN)
    assert "watertight" in failures(out, "solid stl: watertight, volume", capsys)[0]


def test_solid_msh_inward(out, capsys):
    pts, tris = surface()
    sp, st = fx.solid(pts, tris, fx.BASE)
    fx.write_msh(out / "dsm-solid.msh", sp, st[:, ::-1])
    assert "not positive" in failures(out, "solid msh: watertight, volume", capsys)[0]


def test_solid_volume_in_json(out, capsys):
    info = json.loads((out / "dsm-solid.json").read_text())
    info["volume"] *= 1.001
    (out / "dsm-solid.json").write_text(json.dumps(info))
    assert "integral" in failures(out, "solid volume vs surface integral", capsys)[0]
    assert "dsm-solid.json" in failures(out, "solid msh: watertight, volume", capsys)[0]


def test_grid_crs_not_utm(out, capsys):
    import rasterio
    with rasterio.open(out / "dsm.tif", "r+") as ds:
        ds.crs = "EPSG:3857"
    assert "UTM" in failures(out, "grids tif + asc (rasterio)", capsys)[0]


def test_grid_values_differ(out, capsys):
    lines = (out / "dsm.asc").read_text().splitlines()
    vals = lines[7].split()
    vals[2] = repr(float(vals[2]) + 0.5)
    lines[7] = " ".join(vals)
    (out / "dsm.asc").write_text("\n".join(lines) + "\n")
    assert "values" in failures(out, "grids tif + asc (rasterio)", capsys)[0]


def test_report_external_url(out, capsys):
    edit(out / "report.html", "<h1>", '<img src="https://example.org/x.png"><h1>')
    assert "external URL" in failures(out, "report.html: self-contained", capsys)[0]


def test_report_image_bad_png(out, capsys):
    png = bytearray(fx.write_png(None))
    png[20] ^= 0xFF  # inside IHDR: the CRC no longer matches
    import base64
    edit(out / "report.html", "<h1>", f'<img src="data:image/png;base64,{base64.b64encode(png).decode()}"><h1>')
    assert "CRC" in failures(out, "report.html: self-contained", capsys)[0]


def test_report_console_error(out, capsys):
    edit(out / "report.html", "</body>", "<script>console.error('boom')</script></body>")
    assert "boom" in failures(out, "report.html: renders (chromium)", capsys)[0]


def test_report_script_file(out, capsys):
    edit(out / "report.html", "</body>", '<script src="viewer.js"></script></body>')
    assert "scripts must be inline" in failures(out, "report.html: self-contained", capsys)[0]


def test_viewer_missing(out, capsys):
    edit(out / "report.html", 'id="tmv-data"', 'id="other"')
    assert "no 3D viewer data" in failures(out, "report.html: 3D viewer data", capsys)[0]


def test_viewer_origin_off(out, capsys):
    import re
    s = (out / "report.html").read_text()
    s = re.sub(r'"origin": \[([-0-9.e]+)', lambda m: f'"origin": [{float(m.group(1)) + 0.5!r}', s, count=1)
    (out / "report.html").write_text(s)
    assert "surface vertex" in failures(out, "report.html: 3D viewer data", capsys)[0]


def test_viewer_triangles_differ(out, capsys):
    import base64
    import json
    import re
    s = (out / "report.html").read_text()
    m = re.search(r'id="tmv-data">(.*?)</script>', s)
    scene = json.loads(m.group(1))
    idx = np.frombuffer(base64.b64decode(scene["layers"][0]["indices"]), "<u4").copy()
    idx[[0, 1]] = idx[[1, 0]]  # one triangle turned over
    scene["layers"][0]["indices"] = base64.b64encode(idx.tobytes()).decode()
    (out / "report.html").write_text(s.replace(m.group(1), json.dumps(scene)))
    assert "triangles differ" in failures(out, "report.html: 3D viewer data", capsys)[0]


def test_viewer_field_wrong(out, capsys):
    import base64
    import json
    import re
    s = (out / "report.html").read_text()
    m = re.search(r'id="tmv-data">(.*?)</script>', s)
    scene = json.loads(m.group(1))
    # The elevations where UK minus IDW belongs.
    scene["layers"][0]["fields"]["uk_minus_idw"] = scene["layers"][0]["fields"]["elevation"]
    (out / "report.html").write_text(s.replace(m.group(1), json.dumps(scene)))
    assert "field uk_minus_idw" in failures(out, "report.html: 3D viewer data", capsys)[0]


def test_report_blank(out, capsys):
    (out / "report.html").write_text("<!DOCTYPE html><html><body></body></html>\n")
    assert "blank" in failures(out, "report.html: renders (chromium)", capsys)[0]


def test_pictures_broken_svg(out, capsys):
    (out / "pictures" / "dsm.svg").write_text("<svg xmlns='http://www.w3.org/2000/svg'>")
    assert "well-formed" in failures(out, "pictures", capsys)[0]


def test_tables_ragged(out, capsys):
    (out / "samples.csv").write_text("x,y,elevation\n1,2\n")
    assert "widths" in failures(out, "tables", capsys)[0]


def test_compare_detects_difference(out, valid, capsys):
    edit(out / "report.html", "triangles", "triangles (timing 1.2 s)")
    assert not failures(valid, "determinism (--compare)", capsys, compare=out)
    edit(out / "dsm.obj", "f 1 ", "f 1  ")
    assert "dsm.obj" in failures(valid, "determinism (--compare)", capsys, compare=out)[0]


# ---------------------------------------------------------------- COLLADA (check_collada.py)


def test_dae_schema_invalid_element(out, capsys):
    edit(out / "dsm.dae", "<unit ", "<units ")
    assert "COLLADA 1.4.1 schema" in failures(out, "dae schema (COLLADA 1.4.1)", capsys)[0]


def test_dae_wrong_version(out, capsys):
    edit(out / "dsm.dae", 'version="1.4.1"', 'version="1.5.0"')
    assert "1.5.0" in failures(out, "dae schema (COLLADA 1.4.1)", capsys)[0]


def test_dae_truncated(out, capsys):
    data = (out / "dsm.dae").read_text()
    (out / "dsm.dae").write_text(data[: len(data) // 2])
    assert "dsm.dae" in failures(out, "dae schema (COLLADA 1.4.1)", capsys)[0]
    assert "dsm.dae" in failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]


def test_dae_missing_triangle(out, capsys):
    xy, uk, _, _, tris = fx.surface()
    fx.write_dae(out, xy, uk, tris[:-1])
    assert "triangles" in failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]


def test_dae_clockwise_triangle(out, capsys):
    xy, uk, _, _, tris = fx.surface()
    tris[4] = tris[4][::-1]
    fx.write_dae(out, xy, uk, tris)
    fail = failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]
    assert "triangles differ" in fail or "counter-clockwise" in fail


def test_dae_altitude_off_by_a_millimetre(out, capsys):
    xy, uk, _, _, tris = fx.surface()
    z = uk.copy()
    z[6] += 1e-3
    fx.write_dae(out, xy, z, tris)
    # The model KML's altitude is the lowest z: unchanged, so only vertex 6 moves.
    assert "altitude" in failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]


def test_dae_float32_positions(out, capsys):
    xy, uk, _, _, tris = fx.surface()
    fx.write_dae(out, xy, uk, tris, fmt=lambda v: repr(float(np.float32(v))))
    fail = failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]
    assert "lon/lat" in fail or "altitude" in fail


def test_dae_location_moved(out, capsys):
    s = (out / "dsm-model.kml").read_text()
    lon = s.split("<longitude>")[1].split("<")[0]
    edit(out / "dsm-model.kml", f"<longitude>{lon}<", f"<longitude>{float(lon) + 1e-9!r}<")
    assert "lon/lat" in failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]


def test_dae_y_up_accepted(out, capsys):
    # The same surface written Y_UP (x, up, -north) is still in place.
    xy, uk, _, _, tris = fx.surface()
    enu = fx.write_dae(out, xy, uk, tris)
    yup = np.column_stack([enu[:, 0], enu[:, 2], -enu[:, 1]])
    s = (out / "dsm.dae").read_text()
    old = " ".join(repr(float(v)) for v in enu.ravel())
    assert old in s
    s = s.replace(old, " ".join(repr(float(v)) for v in yup.ravel())).replace("Z_UP", "Y_UP")
    (out / "dsm.dae").write_text(s)
    assert not failures(out, "dae geometry (pycollada, PROJ)", capsys)
    (out / "dsm.dae").write_text(s.replace("Y_UP", "Z_UP"))
    fail = failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]
    assert "counter-clockwise" in fail or "lon/lat" in fail


def test_model_kml_not_absolute(out, capsys):
    edit(out / "dsm-model.kml", "<altitudeMode>absolute", "<altitudeMode>relativeToGround")
    assert "absolute" in failures(out, "dae model kml schema (xmllint)", capsys)[0]
    assert "absolute" in failures(out, "dae geometry (pycollada, PROJ)", capsys)[0]


def test_model_kml_schema_invalid(out, capsys):
    edit(out / "dsm-model.kml", "<Location>", "<Position>")
    edit(out / "dsm-model.kml", "</Location>", "</Position>")
    assert "xmllint" in failures(out, "dae model kml schema (xmllint)", capsys)[0]


def test_model_kml_wrong_link(out, capsys):
    edit(out / "dsm-model.kml", "<href>dsm.dae", "<href>model.dae")
    assert "model.dae" in failures(out, "dae model kml schema (xmllint)", capsys)[0]


# ---------------------------------------------------------------- Gmsh and VTK (check_programs.py)


def test_gmsh_truncated_msh(out, capsys):
    s = (out / "dsm.msh").read_text()
    (out / "dsm.msh").write_text(s[: s.index("$Elements") + 40])
    assert "dsm.msh" in failures(out, "gmsh: dsm.msh", capsys)[0]


def test_gmsh_moved_node(out, capsys):
    pts, tris = surface()
    pts[3, 0] += 1e-3
    fx.write_msh(out / "dsm.msh", pts, tris)
    assert "Gmsh node coordinates" in failures(out, "gmsh: dsm.msh", capsys)[0]


def test_gmsh_solid_open(out, capsys):
    pts, tris = surface()
    sp, st = fx.solid(pts, tris, fx.BASE)
    fx.write_msh(out / "dsm-solid.msh", sp, st[1:])
    info = json.loads((out / "dsm-solid.json").read_text())
    info["triangles"] -= 1
    (out / "dsm-solid.json").write_text(json.dumps(info))
    assert "closed surface" in failures(out, "gmsh: dsm-solid.msh closed", capsys)[0]


def test_gmsh_solid_count_vs_json(out, capsys):
    info = json.loads((out / "dsm-solid.json").read_text())
    info["vertices"] += 1
    (out / "dsm-solid.json").write_text(json.dumps(info))
    assert "dsm-solid.json says" in failures(out, "gmsh: dsm-solid.msh closed", capsys)[0]


def test_vtk_float32_points(out, capsys):
    edit(out / "dsm.vtu", '<DataArray type="Float64" Name="Points"', '<DataArray type="Float32" Name="Points"')
    assert "Float64" in failures(out, "vtk: dsm.vtu (ParaView's reader)", capsys)[0]


def test_vtk_missing_point_data(out, capsys):
    edit(out / "dsm.vtu", 'Name="uk_minus_idw"', 'Name="difference"')
    assert "uk_minus_idw" in failures(out, "vtk: dsm.vtu (ParaView's reader)", capsys)[0]


def test_vtk_broken_xml(out, capsys):
    edit(out / "dsm.vtu", "</Piece>", "</Peace>")
    # meshio (the reference) fails on it too; VTK's own reader must report it as well.
    assert "dsm.vtu" in failures(out, "vtk: dsm.vtu (ParaView's reader)", capsys)[0]
    with pytest.raises(vcommon.CheckFailed, match="dsm.vtu: VTK"):
        check_programs.vtk_read(vcommon.Outputs(out), "dsm.vtu")


# ---------------------------------------------------------------- glTF and 3D Tiles


def rewrite_glb(path, change):
    """Applies `change` to the JSON chunk of a GLB (a dict) and writes it back."""
    import struct
    b = path.read_bytes()
    jl = struct.unpack_from("<I", b, 12)[0]
    doc = json.loads(b[20:20 + jl])
    change(doc)
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    rest = b[20 + jl:]
    body = struct.pack("<I4s", len(js), b"JSON") + js + rest
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


def test_glb_validator_reports_a_wrong_accessor_max(out, capsys):
    def wrong_max(doc):
        doc["accessors"][0]["max"][0] += 1.0
    rewrite_glb(out / "dsm.glb", wrong_max)
    f = failures(out, "glb: glTF-Validator", capsys)
    assert "dsm.glb" in f[0] and "ACCESSOR_MAX_MISMATCH" in f[0], f


def test_glb_validator_checks_the_tile_contents(out, capsys):
    def wrong_min(doc):
        doc["accessors"][0]["min"][1] -= 1.0
    rewrite_glb(out / "3dtiles" / "tiles" / "leaf1.glb", wrong_min)
    f = failures(out, "glb: glTF-Validator", capsys)
    assert "leaf1.glb" in f[0], f


def test_dsm_glb_origin_off_by_a_centimetre(out, capsys):
    def shift(doc):
        doc["nodes"][0]["translation"][0] += 0.01
    rewrite_glb(out / "dsm.glb", shift)
    assert "> 1 mm" in failures(out, "glb: dsm.glb vertices (pygltflib)", capsys)[0]


def test_dsm_glb_in_ellipsoidal_heights(out, capsys):
    def datum(doc):
        doc["nodes"][0]["extras"]["vertical_datum"] = "wgs84"
    rewrite_glb(out / "dsm.glb", datum)
    assert "vertical datum" in failures(out, "glb: dsm.glb vertices (pygltflib)", capsys)[0]


def edit_tileset(out, change):
    p = out / "3dtiles" / "tileset.json"
    ts = json.loads(p.read_text())
    change(ts)
    p.write_text(json.dumps(ts))


# Each break of the tree fails our own reader and py3dtiles' alike.
TREE_CHECKS = ["3dtiles: tree, boxes, errors", "3dtiles: py3dtiles reader"]


@pytest.mark.parametrize("check", TREE_CHECKS)
def test_tileset_leaf_with_an_error(out, capsys, check):
    edit_tileset(out, lambda ts: ts["root"]["children"][0].update(geometricError=0.5))
    assert "leaf" in failures(out, check, capsys)[0]


@pytest.mark.parametrize("check", TREE_CHECKS)
def test_tileset_child_error_above_its_parent(out, capsys, check):
    edit_tileset(out, lambda ts: ts["root"].update(geometricError=1.0, children=[
        {**ts["root"], "geometricError": 2.0, "children": ts["root"]["children"]}]))
    assert "exceeds its parent" in failures(out, check, capsys)[0]


@pytest.mark.parametrize("check", TREE_CHECKS)
def test_tileset_box_too_small_for_its_content(out, capsys, check):
    def shrink(ts):
        ts["root"]["children"][1]["boundingVolume"]["box"][3] *= 0.9
    edit_tileset(out, shrink)
    assert "sticks out of its box" in failures(out, check, capsys)[0]


@pytest.mark.parametrize("check", TREE_CHECKS)
def test_tileset_content_outside_an_ancestor_box(out, capsys, check):
    def shrink(ts):
        ts["root"]["boundingVolume"]["box"][11] = 0.01  # flat root box; the leaves rise above it
        ts["root"].pop("content")
    edit_tileset(out, shrink)
    assert "an ancestor" in failures(out, check, capsys)[0]


def test_tileset_without_the_ellipsoidal_shift(out, capsys):
    def drop(ts):
        tr = ts["root"]["transform"]
        for k in range(3):  # move the frame down its up axis by the undulation
            tr[12 + k] -= 48.6 * tr[8 + k]
    edit_tileset(out, drop)
    assert "records" in failures(out, "3dtiles: ellipsoidal heights (PROJ)", capsys)[0]


def test_tileset_leaf_vertices_off_the_dsm(out, capsys):
    def move(ts):
        ts["root"]["transform"][12] += 0.5
    edit_tileset(out, move)
    assert "no DSM vertex" in failures(out, "3dtiles: ellipsoidal heights (PROJ)", capsys)[0]
# ---------------------------------------------------------------- terrain tiles


def tile_paths(d):
    return sorted((d / "terrain").rglob("*.terrain"), key=lambda p: [int(x) for x in p.relative_to(d / "terrain").with_suffix("").parts])


def rewrite_tile(path, fn):
    """Decodes a tile with quantized-mesh-tile, applies `fn` to it and writes it back."""
    from quantized_mesh_tile.global_geodetic import GlobalGeodetic
    from quantized_mesh_tile.terrain import TerrainTile
    z, x, y = (int(p) for p in path.with_suffix("").parts[-3:])
    w, s, e, n = GlobalGeodetic(True).TileBounds(x, y, z)
    t = TerrainTile(west=w, south=s, east=e, north=n)
    t.fromFile(str(path), hasLighting=True)
    fn(t)
    path.write_bytes(t.toBytesIO().getvalue())


def deepest(d):
    paths = tile_paths(d)
    z = int(paths[-1].parts[-3])
    return z, [p for p in paths if int(p.parts[-3]) == z]


def centre_tile_and_vertex(d):
    """The deepest tile holding the fixture DSM's centre, and its vertex nearest to it."""
    import egm96  # noqa: F401  (the check needs it too)
    from pyproj import Transformer
    xy = fx.surface()[0]
    lon, lat = Transformer.from_crs(fx.EPSG, 4326, always_xy=True).transform(*xy.mean(axis=0))
    z, paths = deepest(d)
    size = 180 / 2 ** z
    p = d / "terrain" / str(z) / str(int((lon + 180) // size)) / f"{int((lat + 90) // size)}.terrain"
    assert p in paths
    w, s = -180 + int((lon + 180) // size) * size, -90 + int((lat + 90) // size) * size
    return p, (lon - w) / size * 32767, (lat - s) / size * 32767


def test_python_egm96_matches_nga_test_points():
    # NGA's EGM96 test points (INTPT.DAT / OUTINTPT.DAT, NIMA 1996), as in terramesh-core's
    # coords/geoid.rs: the egm96 package installed on this Python must reproduce them.
    import egm96
    pts = [(38.6281550, 269.7791550, -31.628), (-14.6212170, 305.0211140, -2.969),
           (46.8743190, 102.4487290, -43.575), (-23.6174460, 133.8747120, 15.871),
           (38.6254730, 359.9995000, 50.066), (-0.4667440, 0.0023000, 17.329)]
    for lat, lon, n in pts:
        assert abs(egm96.undulation(lat, lon) - n) < vo.check_terrain.GEOID_TOL


def test_terrain_layer_format(out, capsys):
    edit(out / "terrain" / "layer.json", '"quantized-mesh-1.0"', '"heightmap-1.0"')
    assert "format" in failures(out, "terrain layer.json (Cesium keys, available, levels)", capsys)[0]


def test_terrain_missing_tile(out, capsys):
    _, paths = deepest(out)
    paths[0].unlink()
    assert "without a file" in failures(out, "terrain layer.json (Cesium keys, available, levels)", capsys)[0]


def test_terrain_unlisted_tile(out, capsys):
    _, paths = deepest(out)
    extra = paths[0].parent.parent / "1" / "0.terrain"
    extra.parent.mkdir(parents=True, exist_ok=True)
    shutil.copy(paths[0], extra)
    assert "not listed" in failures(out, "terrain layer.json (Cesium keys, available, levels)", capsys)[0]


def test_terrain_pyramid_too_shallow(out, capsys):
    z, paths = deepest(out)
    shutil.rmtree(out / "terrain" / str(z))
    lj = json.loads((out / "terrain" / "layer.json").read_text())
    lj["available"].pop()
    lj["maxzoom"] = z - 1
    (out / "terrain" / "layer.json").write_text(json.dumps(lj))
    assert "mean edge" in failures(out, "terrain layer.json (Cesium keys, available, levels)", capsys)[0]


def test_terrain_truncated_tile(out, capsys):
    p = tile_paths(out)[5]
    p.write_bytes(p.read_bytes()[:200])
    assert "cannot read" in failures(out, "terrain tiles (quantized-mesh-tile)", capsys)[0]


def test_terrain_normals_pointing_down(out, capsys):
    rewrite_tile(tile_paths(out)[-1], lambda t: setattr(t, "vLight", [[-c for c in n] for n in t.vLight]))
    assert "below the horizon" in failures(out, "terrain tiles (quantized-mesh-tile)", capsys)[0]


def test_terrain_occlusion_point_too_close(out, capsys):
    def shrink(t):
        for k in ["horizonOcclusionPointX", "horizonOcclusionPointY", "horizonOcclusionPointZ"]:
            t.header[k] *= 0.99999
    rewrite_tile(tile_paths(out)[-1], shrink)
    assert "too close" in failures(out, "terrain tiles (quantized-mesh-tile)", capsys)[0]


def test_terrain_edge_list_incomplete(out, capsys):
    rewrite_tile(tile_paths(out)[-1], lambda t: setattr(t, "westI", t.westI[:-1]))
    assert "west edge lists" in failures(out, "terrain edge indices", capsys)[0]


def test_terrain_edge_list_order(out, capsys):
    rewrite_tile(tile_paths(out)[-1], lambda t: setattr(t, "southI", t.southI[::-1]))
    assert "south edge indices out of order" in failures(out, "terrain edge indices", capsys)[0]


def test_terrain_shared_edge_heights(out, capsys):
    _, paths = deepest(out)
    def bump(t):  # one quantum up on the tile's eastern edge: within the height tolerance
        k = t.eastI[len(t.eastI) // 2]
        t.h[k] = t.h[k] + 1 if t.h[k] < 32767 else t.h[k] - 1
    rewrite_tile(paths[0], bump)
    assert "heights differ" in failures(out, "terrain shared edges", capsys)[0]


def test_terrain_height_off_the_dsm(out, capsys):
    p, u0, v0 = centre_tile_and_vertex(out)
    def lift(t):
        k = int(np.argmin((np.array(t.u) - u0) ** 2 + (np.array(t.v) - v0) ** 2))
        step = (t.header["maximumHeight"] - t.header["minimumHeight"]) / 32767
        t.h[k] += int(round(0.2 / step))  # 20 cm
    rewrite_tile(p, lift)
    assert "the DSM + EGM96 gives" in failures(out, "terrain heights vs DSM + EGM96", capsys)[0]


def test_terrain_height_off_by_centimetres(out, capsys):
    p, u0, v0 = centre_tile_and_vertex(out)
    def lift(t):  # 2 cm: within the geoid tolerance, caught as a bump in the geoid difference
        k = int(np.argmin((np.array(t.u) - u0) ** 2 + (np.array(t.v) - v0) ** 2))
        step = (t.header["maximumHeight"] - t.header["minimumHeight"]) / 32767
        t.h[k] += int(round(0.02 / step))
    rewrite_tile(p, lift)
    assert "not a smooth geoid difference" in failures(out, "terrain heights vs DSM + EGM96", capsys)[0]


def test_terrain_heights_without_the_geoid(out, capsys):
    import egm96
    n = egm96.undulation(48.7, 7.33)
    for p in tile_paths(out):
        def lower(t):
            t.header["minimumHeight"] -= n
            t.header["maximumHeight"] -= n
        rewrite_tile(p, lower)
    assert failures(out, "terrain heights vs DSM + EGM96", capsys)
