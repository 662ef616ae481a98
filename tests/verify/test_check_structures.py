"""check_structures.py on the committed model with engineering objects
(tests/verify/fixtures/structures/, written by terramesh's writers from the fault kernel's
synthetic site without faults (one block), a lined tunnel through the western side, a pit
and a box-shaped structure; the Rust test `committed_structures_fixture_is_current` keeps it
current): every check passes, among them Gmsh opening the object groups, meshio reading the
FLAC3D zone groups (`stage-<n>` too) and face groups, OpenGeoSys' checkMesh, and the steady
diffusion with the excavated cells removed reproducing u = z; and a copy with one thing broken
fails the check that should catch it.

    .venv-verify/bin/python -m pytest tests/verify/test_check_structures.py
"""

import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_structures as cs  # noqa: E402
from test_check_model import edit, rewrite_vtu  # noqa: E402

FIXTURE = HERE / "fixtures" / "structures"


def rewrite_model(path, change):
    """rewrite_vtu for model.vtu, whose empty field data fault_names (no faults) meshio cannot
    read back once written as ascii: dropped first."""
    edit(path, '<DataArray type="UInt8" Name="fault_names" NumberOfTuples="0"', '<DataArray type="UInt8" Name="x"')
    s = path.read_text()
    s = re.sub(r'<DataArray type="UInt8" Name="x"[^\n]*\n', "", s, count=1)
    path.write_text(s)
    rewrite_vtu(path, change)


@pytest.fixture
def out(tmp_path):
    d = tmp_path / "structures"
    shutil.copytree(FIXTURE, d)
    return d


def failures(d, check, capsys):
    """Runs only the check named `check`; returns its FAIL lines."""
    assert check in [n for n, _ in cs.CHECKS], check
    cs.run(d, only=[check])
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] in ("1 passed, 0 failed", "0 passed, 1 failed"), lines
    return [ln for ln in lines if ln.startswith("FAIL")]


def test_fixture_passes_every_check(capsys):
    cs.run(FIXTURE)
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f"{len(cs.CHECKS)} passed, 0 failed", lines


def test_fixture_has_every_kind_of_object_and_two_stages():
    o = cs.Objects(FIXTURE)
    assert o.objects == ["adit", "pit", "dam"], o.objects
    assert cs.msh_kinds(o) == {"adit": "tunnel", "pit": "excavation", "dam": "structure"}
    assert sorted(set(o.stage.tolist())) == [0, 1, 2]
    assert o.units[-2:] == ["concrete", "lining-adit"] and o.lining(0).any()


def test_excavated_lining_fails(out, capsys):
    def dig(m):
        o = cs.Objects(FIXTURE)
        m.cell_data["excavation_stage"][0][np.nonzero(o.lining(0))[0][0]] = 2
    rewrite_model(out / "model.vtu", dig)
    f = failures(out, "model.vtu: object, excavation_stage, materials", capsys)
    assert f and "lining-adit is excavated" in f[0], f


def test_missing_boundary_face_fails(out, capsys):
    def drop(m):
        m.cells[0].data = m.cells[0].data[1:]
        for k in m.cell_data:
            m.cell_data[k][0] = m.cell_data[k][0][1:]
    rewrite_vtu(out / "object-pit.vtu", drop)
    f = failures(out, "object-<name>.vtu: the objects' boundaries", capsys)
    assert f and "not closed" in f[0], f


def test_wrong_bulk_face_id_fails_extract_boundary(out, capsys):
    def bump(m):
        k = m.cell_data["bulk_face_ids"][0]
        k[0] = (k[0] + 1) % 4
    rewrite_vtu(out / "object-dam.vtu", bump)
    f = failures(out, "object-<name>.vtu vs removeMeshElements + ExtractBoundary", capsys)
    assert f and "other bulk element/face ids" in f[0], f


def test_missing_tsurf_triangle_fails(out, capsys):
    p = out / "object-adit.ts"
    p.write_text(re.sub(r"\nTRGL [^\n]*", "", p.read_text(), count=1))
    f = failures(out, "object-<name>.ts", capsys)
    assert f and "differ from" in f[0], f


def test_stage_group_in_another_slot_fails(out, capsys):
    edit(out / "model.f3grid", 'ZGROUP "stage-1" SLOT 4', 'ZGROUP "stage-1" SLOT 3')
    f = failures(out, "model.f3grid: object zone groups, stages, boundary face groups (meshio)", capsys)
    assert f and "stage-1" in f[0], f


def test_renamed_boundary_face_group_fails(out, capsys):
    edit(out / "model.f3grid", 'FGROUP "tunnel-adit-boundary"', 'FGROUP "tunnel-adit-wall"')
    f = failures(out, "model.f3grid: object zone groups, stages, boundary face groups (meshio)", capsys)
    assert f and "no face group 'tunnel-adit-boundary'" in f[0], f


def test_entity_out_of_its_object_group_fails(out, capsys):
    # the first volume entity in two physical groups (its material's and an object group's)
    # loses the object group: the group misses those cells
    p = out / "model.msh"
    s = p.read_text()
    a, b = s.index("$Entities\n"), s.index("$EndEntities")
    m = re.search(r" 2 (\d+) (\d+) 0\n", s[a:b])
    assert m
    p.write_text(s[:a] + s[a:b].replace(m.group(0), f" 1 {m.group(1)} 0\n", 1) + s[b:])
    f = failures(out, "model.msh: object volumes and boundaries (gmsh)", capsys)
    assert f and ("is not its cells" in f[0] or "finds no physical volume" in f[0]), f


def test_nothing_excavated_fails_the_diffusion(out, capsys):
    def keep(m):
        m.cell_data["excavation_stage"][0][:] = 0
    rewrite_model(out / "model.vtu", keep)
    f = failures(out, "ogs: steady diffusion u = z without the excavated cells", capsys)
    assert f and "no excavated cell" in f[0], f
