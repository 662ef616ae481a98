"""Negative tests of check_faulted.py: every check passes on the committed faulted model
(tests/verify/fixtures/faulted/, written by terramesh's writers from the fault kernel's
synthetic site with two crossing faults and split nodes; the Rust test
`committed_faulted_fixture_is_current` keeps it current) and fails on a copy with one file
broken.

    .venv-verify/bin/python -m pytest tests/verify/test_check_faulted.py
"""

import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_faulted as cf  # noqa: E402
from test_check_model import edit, rewrite_vtu  # noqa: E402

FIXTURE = HERE / "fixtures" / "faulted"


@pytest.fixture
def out(tmp_path):
    d = tmp_path / "faulted"
    shutil.copytree(FIXTURE, d)
    return d


def failures(d, check, capsys):
    """Runs only the check named `check`; returns its FAIL lines."""
    assert check in [n for n, _ in cf.CHECKS], check
    cf.run(d, only=[check])
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] in ("1 passed, 0 failed", "0 passed, 1 failed"), lines
    return [ln for ln in lines if ln.startswith("FAIL")]


def test_fixture_passes_every_check(capsys):
    cf.run(FIXTURE)
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f"{len(cf.CHECKS)} passed, 0 failed", lines


def test_fixture_has_two_faults_and_four_blocks():
    f = cf.Faulted(FIXTURE)
    assert f.faults == ["F1", "F2"] and len(f.blocks) == 4, (f.faults, f.blocks)


def test_missing_block_array_fails(out, capsys):
    edit(out / "model.vtu", 'Name="block"', 'Name="blocks"')
    cf.run(out)
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == "0 passed, 1 failed" and "no cell data 'block'" in lines[0], lines


def test_block_beyond_the_names_fails(out, capsys):
    def bump(m):
        m.cell_data["block"][0][0] = 9
    rewrite_vtu(out / "model.vtu", bump)
    f = failures(out, "model.vtu: block, fault_names, block_names", capsys)
    assert f and "beyond the 4 block_names" in f[0], f


def test_one_sided_fault_mesh_fails(out, capsys):
    def one_side(m):
        m.cell_data["side"][0][:] = 0
    rewrite_vtu(out / "fault-F1.vtu", one_side)
    f = failures(out, "fault-<name>.vtu: faces of both sides", capsys)
    assert f and "once per side" in f[0], f


def test_face_of_another_cell_fails(out, capsys):
    def other(m):
        e = m.cell_data["bulk_element_ids"][0]
        e[0] = (e[0] + 1) % e.max()
    rewrite_vtu(out / "fault-F2.vtu", other)
    f = failures(out, "fault-<name>.vtu: faces of both sides", capsys)
    assert f and "is not a face of cell" in f[0], f


def test_wrong_bulk_face_id_fails_extract_boundary(out, capsys):
    def bump(m):
        k = m.cell_data["bulk_face_ids"][0]
        k[0] = (k[0] + 1) % 4
    rewrite_vtu(out / "fault-F1.vtu", bump)
    f = failures(out, "fault-<name>.vtu vs ExtractBoundary / checkMesh", capsys)
    assert f and "ExtractBoundary says" in f[0], f


def test_missing_tsurf_triangle_fails(out, capsys):
    p = out / "fault-F2.ts"
    p.write_text(re.sub(r"\nTRGL [^\n]*", "", p.read_text(), count=1))
    f = failures(out, "fault-<name>.ts", capsys)
    assert f and "differ from" in f[0], f


def test_renamed_face_group_fails(out, capsys):
    edit(out / "model.f3grid", 'FGROUP "fault-F1"', 'FGROUP "fault-X"')
    f = failures(out, "model.f3grid: fault face groups, block zone groups (meshio)", capsys)
    assert f and "no face group fault-F1" in f[0], f


def test_block_group_in_slot_1_fails(out, capsys):
    p = out / "model.f3grid"
    s = p.read_text()
    assert " SLOT 2\n" in s
    p.write_text(s.replace(" SLOT 2\n", " SLOT 1\n", 1))
    f = failures(out, "model.f3grid: fault face groups, block zone groups (meshio)", capsys)
    assert f and "in slot 2" in f[0], f


def test_fault_as_volume_group_fails(out, capsys):
    p = out / "model.msh"
    s = p.read_text()
    m = re.search(r'\n2 (\d+) "fault-F1"\n', s)
    assert m
    p.write_text(s.replace(m.group(0), f'\n2 {m.group(1)} "fault-Fx"\n'))
    f = failures(out, "model.msh: fault surfaces, unit volumes (gmsh)", capsys)
    assert f and "no physical surface fault-F1" in f[0], f


def test_checks_read_numbers_not_names():
    # the fixture's fault faces really are split: each side names its own nodes
    f = cf.Faulted(FIXTURE)
    faces, _, _, _, _, _ = cf.fault_mesh(f, "F1")
    n = len(faces) // 2
    assert any(not set(a) & set(b) for a, b in zip(faces[:n], faces[n:]))
    assert np.isfinite(f.points).all()


class _Slab:
    """A box 10 m x 10 m x 10 m from x = -5 to 5, its cubes (1 m) split into six tetrahedra
    each (Kuhn), a vertical fault on x = 0 (fault-F.ts: two triangles over the box's section),
    the cells with |x| < 1 the material zone-F (a 2 m zone), blocks by the side of x = 0: what
    check_zones reads of a Faulted, without files but the fault's TSurf."""

    def __init__(self, root):
        n = 10
        idx = lambda i, j, k: (i * (n + 1) + j) * (n + 1) + k
        self.points = np.array([[i - 5.0, j, k] for i in range(n + 1) for j in range(n + 1)
                                for k in range(n + 1)])
        perms = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
        cells = []
        for i in range(n):
            for j in range(n):
                for k in range(n):
                    for p in perms:
                        c, t = [i, j, k], [idx(i, j, k)]
                        for axis in p:
                            c[axis] += 1
                            t.append(idx(*c))
                        cells.append(("tetra", tuple(t)))
        self.cells = cells
        cen = self.points[np.array([c for _, c in cells])].mean(axis=1)
        self.units = ["rock", "zone-F"]
        self.faults = ["F"]
        self.mats = np.where(np.abs(cen[:, 0]) < 1.0, 1, 0).astype(np.int32)
        self.block = (cen[:, 0] > 0).astype(np.int32)
        ts = root / "fault-F.ts"
        ts.write_text("GOCAD TSurf 1\nVRTX 1 0 0 0\nVRTX 2 0 10 0\nVRTX 3 0 10 10\nVRTX 4 0 0 10\n"
                      "TRGL 1 2 3\nTRGL 1 3 4\nEND\n")
        self.model = type("M", (), {"path": lambda _, name: root / name})()


def test_zone_slab_passes(tmp_path):
    cf.check_zones(_Slab(tmp_path))


def test_zone_cell_labelled_as_its_unit_fails(tmp_path):
    s = _Slab(tmp_path)
    cen = s.points[np.array([c for _, c in s.cells])].mean(axis=1)
    inner = np.nonzero((np.abs(cen[:, 0]) < 0.5) & (cen[:, 1] > 3) & (cen[:, 2] > 3))[0]
    s.mats[inner[0]] = 0
    with pytest.raises(cf.CheckFailed, match="are in no zone"):
        cf.check_zones(s)


def test_zone_on_one_side_fails(tmp_path):
    s = _Slab(tmp_path)
    s.block[:] = 0
    with pytest.raises(cf.CheckFailed, match="in one block"):
        cf.check_zones(s)


def test_zone_thinner_than_its_walls_fails(tmp_path):
    # half of the zone's cells taken out where its far wall still stands: the volume is short
    s = _Slab(tmp_path)
    cen = s.points[np.array([c for _, c in s.cells])].mean(axis=1)
    s.mats[(cen[:, 0] > 0) & (cen[:, 0] < 1) & (cen[:, 1] < 5)] = 0
    with pytest.raises(cf.CheckFailed, match="in no zone|vs thickness"):
        cf.check_zones(s)
