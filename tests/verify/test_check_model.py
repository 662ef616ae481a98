"""Negative tests of check_model.py: every check passes on the committed model
(tests/verify/fixtures/model/, written by terramesh's writers; the Rust test
`committed_verifier_fixture_is_current` keeps it current) and fails on a copy with one file
broken.

    .venv-verify/bin/python -m pytest tests/verify/test_check_model.py
"""

import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_model as cm  # noqa: E402

FIXTURE = HERE / "fixtures" / "model"


@pytest.fixture
def out(tmp_path):
    d = tmp_path / "model"
    shutil.copytree(FIXTURE, d)
    return d


def failures(d, check, capsys):
    """Runs only the check named `check`; returns its FAIL lines."""
    assert check in [n for n, _ in cm.CHECKS], check
    cm.run(d, only=[check])
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] in ("1 passed, 0 failed", "0 passed, 1 failed"), lines
    return [ln for ln in lines if ln.startswith("FAIL")]


def rewrite_vtu(path, change):
    """Reads a .vtu with meshio, lets `change(mesh)` alter it, writes it back (binary)."""
    import meshio
    m = meshio.read(path)
    field = dict(m.field_data)
    m.point_data = {k: np.array(v) for k, v in m.point_data.items()}
    m.cell_data = {k: [np.array(a) for a in v] for k, v in m.cell_data.items()}
    change(m)
    meshio.write(path, m, binary=True)
    if field:  # meshio's VTU writer leaves field data out: put it back
        xml = "".join(f'<DataArray type="UInt8" Name="{k}" NumberOfTuples="{len(v)}" format="ascii">'
                      f'{" ".join(str(int(x)) for x in v)}</DataArray>' for k, v in field.items())
        edit(path, "<UnstructuredGrid>", f"<UnstructuredGrid><FieldData>{xml}</FieldData>")


def invert_first(kind):
    """A change that reverses the orientation of the first cell of `kind` (meshio's order)."""
    def change(m):
        for c in m.cells:
            if c.type == kind:
                c.data[0] = c.data[0][{"wedge": [0, 2, 1, 3, 5, 4], "tetra": [0, 2, 1, 3],
                                       "pyramid": [0, 3, 2, 1, 4]}[kind]]
                return
        raise AssertionError(f"no {kind} in the fixture")
    return change


def edit(path, old, new, count=1):
    s = path.read_text()
    assert old in s, old
    path.write_text(s.replace(old, new, count))


def test_fixture_passes_every_check(capsys):
    cm.run(FIXTURE)
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f"{len(cm.CHECKS)} passed, 0 failed", lines


def test_fixture_has_every_cell_kind():
    cells, _ = cm.Model(FIXTURE).cells()
    assert {t for t, _ in cells} == {"wedge", "pyramid", "tetra"}


def test_inverted_wedge_fails_volume_check(out, capsys):
    rewrite_vtu(out / "model.vtu", invert_first("wedge"))
    f = failures(out, "model.vtu: cells, faces, closed boundary", capsys)
    assert f and "volume" in f[0], f


def test_duplicated_cell_fails_face_check(out, capsys):
    def dup(m):
        m.cells[0].data = np.vstack([m.cells[0].data, m.cells[0].data[:1]])
        m.cell_data["MaterialIDs"][0] = np.append(m.cell_data["MaterialIDs"][0], m.cell_data["MaterialIDs"][0][0])
    rewrite_vtu(out / "model.vtu", dup)
    f = failures(out, "model.vtu: cells, faces, closed boundary", capsys)
    assert f and "more than two cells" in f[0], f


def test_inverted_tetra_fails_vtk_validator(out, capsys):
    rewrite_vtu(out / "model.vtu", invert_first("tetra"))
    f = failures(out, "model.vtu: VTK reader, vtkCellValidator", capsys)
    assert f and "non-positive" in f[0], f


def test_inverted_pyramid_fails_vtk_validator(out, capsys):
    rewrite_vtu(out / "model.vtu", invert_first("pyramid"))
    f = failures(out, "model.vtu: VTK reader, vtkCellValidator", capsys)
    assert f and "non-positive" in f[0], f


def test_inverted_wedge_fails_ogs_checkmesh(out, capsys):
    rewrite_vtu(out / "model.vtu", invert_first("wedge"))
    f = failures(out, "model.vtu: OpenGeoSys checkMesh", capsys)
    assert f and "wrong node order" in f[0], f


def test_wrong_bulk_face_id_fails(out, capsys):
    def bump(m):
        m.cell_data["bulk_face_ids"][0][0] += 1
    rewrite_vtu(out / "model-top.vtu", bump)
    f = failures(out, "boundary meshes vs ExtractBoundary", capsys)
    assert f and "ExtractBoundary says" in f[0], f


def test_signed_bulk_node_ids_fail(out, capsys):
    def signed(m):
        m.point_data["bulk_node_ids"] = m.point_data["bulk_node_ids"].astype(np.int64)
    rewrite_vtu(out / "model-bottom.vtu", signed)
    f = failures(out, "boundary meshes vs ExtractBoundary", capsys)
    assert f and "bulk_node_ids (uint64)" in f[0], f


def test_missing_side_mesh_fails(out, capsys):
    (out / "model-side-east.vtu").unlink()
    f = failures(out, "boundary meshes vs ExtractBoundary", capsys)
    assert f and "in no boundary mesh" in f[0], f


def test_msh_unit_name_fails(out, capsys):
    edit(out / "model.msh", '3 2 "sand"', '3 2 "sandy"')
    f = failures(out, "model.msh (meshio)", capsys)
    assert f and "'sand'" in f[0], f


def first_prism_line(path):
    lines = path.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if re.fullmatch(r"3 \d+ 6 \d+", ln))
    return lines, k + 1


def test_msh_reversed_prism_fails_gmsh_jacobian(out, capsys):
    p = out / "model.msh"
    lines, k = first_prism_line(p)
    t = lines[k].split()
    lines[k] = " ".join([t[0], t[1], t[3], t[2], t[4], t[6], t[5]])
    p.write_text("\n".join(lines) + "\n")
    f = failures(out, "model.msh (gmsh)", capsys)
    assert f and "Jacobian" in f[0], f
    f = failures(out, "model.msh (meshio)", capsys)
    assert f and "volume" in f[0], f


def test_f3grid_left_handed_zone_fails(out, capsys):
    p = out / "model.f3grid"
    s = p.read_text()
    m = re.search(r"^Z W6 1 (\d+) (\d+) (\d+) (\d+) (\d+) (\d+)$", s, re.M)
    g = m.groups()
    p.write_text(s.replace(m.group(0), f"Z W6 1 {g[0]} {g[3]} {g[2]} {g[1]} {g[5]} {g[4]}"))
    f = failures(out, "model.f3grid (meshio)", capsys)
    assert f and "right-handed" in f[0], f


def test_f3grid_missing_zone_group_fails(out, capsys):
    edit(out / "model.f3grid", 'ZGROUP "clay"', 'ZGROUP "clays"')
    f = failures(out, "model.f3grid (meshio)", capsys)
    assert f and "zone group 'clay'" in f[0], f


def test_open_body_fails(out, capsys):
    p = out / "unit-sand.ts"
    lines = p.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("TRGL"))
    p.write_text("\n".join(lines[:k] + lines[k + 1:]) + "\n")
    f = failures(out, "bodies: ts, stl", capsys)
    assert f and "not closed" in f[0], f


def test_stl_with_wrong_origin_fails(out, capsys):
    p = out / "unit-clay.stl"
    b = bytearray(p.read_bytes())
    head = b[:80].decode("ascii")
    m = re.search(r"origin (\S+)", head)
    new = head.replace(m.group(0), "origin " + str(int(float(m.group(1))) + 1), 1)[:80]
    b[:80] = new.ljust(80).encode("ascii")
    p.write_bytes(bytes(b))
    f = failures(out, "bodies: ts, stl", capsys)
    assert f and "unit-clay.stl" in f[0], f


def test_shifted_bulk_node_ids_fail_ogs_diffusion(out, capsys):
    def shift(m):
        m.point_data["bulk_node_ids"] = m.point_data["bulk_node_ids"] - np.uint64(1)
    rewrite_vtu(out / "model-bottom.vtu", shift)
    f = failures(out, "ogs: steady diffusion u = z", capsys)
    assert f and "|u - z|" in f[0], f


def test_inverted_wedge_fails_ogs_heat(out, capsys):
    rewrite_vtu(out / "model.vtu", invert_first("wedge"))
    f = failures(out, "ogs: heat conduction per MaterialIDs", capsys)
    assert f, f


DATUM = "vertical datum: model.vtu, model.json, dsm.vtu, grids"


def write_grid(path, crs):
    """A 2 x 2 float64 GeoTIFF in `crs` (rasterio, so GDAL writes its GeoKeys)."""
    import rasterio
    from rasterio.transform import from_origin
    path.parent.mkdir(exist_ok=True)
    with rasterio.open(path, "w", driver="GTiff", width=2, height=2, count=1, dtype="float64",
                       crs=crs, transform=from_origin(500000, 5400000, 10, 10)) as dst:
        dst.write(np.ones((1, 2, 2)))


def test_fixture_names_its_datum():
    m = cm.Model(FIXTURE)
    m.vtu()
    import check_datum
    assert check_datum.vertical_of(m.field_data, "fixture") == ("navd88", 5703)


def test_model_json_with_another_datum_fails(out, capsys):
    (out / "model.json").write_text('{"vertical_datum": "egm96", "vertical_crs": "EPSG:5773"}')
    f = failures(out, DATUM, capsys)
    assert f and "model.json" in f[0], f
    (out / "model.json").write_text('{"vertical_datum": "navd88", "vertical_crs": "EPSG:5703"}')
    assert not failures(out, DATUM, capsys)


def test_grid_without_or_with_another_vertical_crs_fails(out, capsys):
    write_grid(out / "interfaces" / "a.tif", "EPSG:32632+5703")
    assert not failures(out, DATUM, capsys)
    for crs in ["EPSG:32632", "EPSG:32632+5773"]:
        write_grid(out / "interfaces" / "a.tif", crs)
        f = failures(out, DATUM, capsys)
        assert f and "a.tif" in f[0] and "vertical CRS" in f[0], (crs, f)
    write_grid(out / "interfaces" / "a.tif", "EPSG:32633+5703")
    f = failures(out, DATUM, capsys)
    assert f and "horizontal CRS" in f[0], f


def test_vertical_crs_that_is_not_vertical_fails(out, capsys):
    vtu = out / "model.vtu"
    # the field data is base64 in the appended block: rewrite_vtu puts it back as text
    rewrite_vtu(vtu, lambda m: None)
    text = " ".join(str(b) for b in b"EPSG:5703")
    edit(vtu, f'Name="vertical_crs" NumberOfTuples="9" format="ascii">{text}<',
         f'Name="vertical_crs" NumberOfTuples="9" format="ascii">{" ".join(str(b) for b in b"EPSG:4326")}<')
    f = failures(out, DATUM, capsys)
    assert f and "not a vertical CRS" in f[0], f


# A sound pyramid from the Kimberlina model (terramesh model with interpolation.neighbors=8):
# a vertical base of two node columns, 1.5 km across and 26-32 m high.
FLAT_PYRAMID = np.array([
    [297180.733, 3927228.51, -1943.02819],
    [297180.733, 3927228.51, -1916.83423],
    [295686.848, 3927843.29, -2000.49349],
    [295686.848, 3927843.29, -2032.88765],
    [295971.000, 3926399.00, -2024.08650],
])


def vtk_state(pts):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    g = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    for r in pts - pts.mean(axis=0):
        p.InsertNextPoint(*r)
    g.SetPoints(p)
    g.InsertNextCell(cm.VTK_PYRAMID, 5, [0, 1, 2, 3, 4])
    v = vtk.vtkCellValidator()
    v.SetInputData(g)
    v.SetTolerance(1e-9)
    v.Update()
    return int(vtk_to_numpy(v.GetOutput().GetCellData().GetArray("ValidityState"))[0])


def test_vtk_convexity_of_a_flat_pyramid_depends_on_its_scale():
    """Why check_model replaces VTK's convexity bit for pyramids: the same cell, scaled."""
    states = {s: vtk_state(FLAT_PYRAMID / s) for s in (1, 10, 1000)}
    assert len(set(states.values())) > 1, states
    assert cm.convex_pyramids(FLAT_PYRAMID, [("pyramid", (0, 1, 2, 3, 4))]) == []


def test_nonconvex_pyramid_fails_our_convexity_check():
    # A warped base: one node off the plane of the other three.
    bent = FLAT_PYRAMID.copy()
    bent[2] += [0.0, 5.0, 0.0]  # one node moved 5 m off the base's (vertical) plane
    assert cm.convex_pyramids(bent, [("pyramid", (0, 1, 2, 3, 4))]) == [0]
    # A dart-shaped base (a reflex corner at its fourth node), planar, apex above.
    dart = np.array([[0.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 2.0, 0.0], [0.5, 1.0, 0.0],
                     [0.8, 1.0, 1.0]])
    assert cm.convex_pyramids(dart, [("pyramid", (0, 1, 2, 3, 4))]) == [0]
    # Counter-clockwise seen from the apex (VTK's order): convex; the other way round, not.
    square = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0],
                       [1.0, 1.0, 1.0]])
    assert cm.convex_pyramids(square, [("pyramid", (0, 1, 2, 3, 4))]) == []
    assert cm.convex_pyramids(square, [("pyramid", (0, 3, 2, 1, 4))]) == [0]
