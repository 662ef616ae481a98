"""Negative tests of check_tiles.py: every check passes on a valid merged mesh of two tiles
(written here with meshio) and fails on a copy broken in one way.

    .venv-verify/bin/python -m pytest tests/verify/test_check_tiles.py
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_tiles as ct  # noqa: E402

X0, Y0, H = 377000.0, 5397000.0, 0.25  # UTM-like coordinates, exact in decimal and binary
NX, NY = 9, 5  # vertices along x (2 m, two 1 m tiles) and y (1 m)


def grid():
    """A 2 m x 1 m region meshed as a lattice, two counter-clockwise triangles per cell."""
    ii, jj = np.meshgrid(np.arange(NX), np.arange(NY), indexing="xy")
    pts = np.column_stack([X0 + H * ii.ravel(), Y0 + H * jj.ravel(), np.sin(ii.ravel()) + jj.ravel()])
    tris = []
    for j in range(NY - 1):
        for i in range(NX - 1):
            a, b, c, d = j * NX + i, j * NX + i + 1, (j + 1) * NX + i + 1, (j + 1) * NX + i
            tris += [[a, b, c], [a, c, d]]
    return pts, np.array(tris)


def write(d, pts, tris, region=None, seam=None, summary=None):
    import meshio
    (d / "merged").mkdir(parents=True, exist_ok=True)
    (d / "plan").mkdir(parents=True, exist_ok=True)
    meshio.write_points_cells(d / "merged" / "dsm.vtu", pts, [("triangle", tris)], binary=False)
    if region is None:
        region = [[X0, Y0], [X0 + 2, Y0], [X0 + 2, Y0 + 1], [X0, Y0 + 1]]
    if seam is None:
        seam = [[X0 + 1, Y0 + H * j] for j in range(NY)]
    tiles = [{"id": "x0y0", "seams": [{"neighbour": "x1y0", "vertices": seam}]},
             {"id": "x1y0", "seams": [{"neighbour": "x0y0", "vertices": seam}]}]
    (d / "plan" / "tiles.json").write_text(json.dumps({"region": region, "tiles": tiles}))
    s = {"vertices": len(pts), "triangles": len(tris), "seam_vertices": len(seam)}
    s.update(summary or {})
    (d / "merged" / "merge.json").write_text(json.dumps(s))


def failed(d, capsys):
    out = ct.run(d / "merged", d / "plan")
    capsys.readouterr()
    return out


def test_valid_merge_passes_every_check(tmp_path, capsys):
    write(tmp_path, *grid())
    assert failed(tmp_path, capsys) == []
    assert ct.main([str(tmp_path / "merged"), str(tmp_path / "plan")]) == 0


def test_truncated_vtu_is_unreadable(tmp_path, capsys):
    write(tmp_path, *grid())
    f = tmp_path / "merged" / "dsm.vtu"
    f.write_text(f.read_text()[:2000])
    assert "readable" in failed(tmp_path, capsys)
    assert ct.main([str(tmp_path / "merged"), str(tmp_path / "plan")]) == 1


def test_edge_in_three_triangles(tmp_path, capsys):
    pts, tris = grid()
    write(tmp_path, pts, np.vstack([tris, tris[10:11]]))
    bad = failed(tmp_path, capsys)
    assert "edges" in bad and "area" in bad


def test_clockwise_triangle(tmp_path, capsys):
    pts, tris = grid()
    tris[5] = tris[5][::-1]
    write(tmp_path, pts, tris)
    assert "edges" in failed(tmp_path, capsys)


def test_hole_puts_a_boundary_edge_inside(tmp_path, capsys):
    pts, tris = grid()
    write(tmp_path, pts, np.delete(tris, 20, axis=0))
    bad = failed(tmp_path, capsys)
    assert "boundary" in bad and "area" in bad and "edges" not in bad


def test_seam_vertices_written_twice(tmp_path, capsys):
    # The right tile keeps its own copies of the seam vertices: not conforming.
    pts, tris = grid()
    seam = np.flatnonzero(pts[:, 0] == X0 + 1)
    copies = {int(v): len(pts) + k for k, v in enumerate(seam)}
    right = pts[tris].mean(axis=1)[:, 0] > X0 + 1
    tris[right] = np.vectorize(lambda v: copies.get(int(v), int(v)))(tris[right])
    write(tmp_path, np.vstack([pts, pts[seam]]), tris)
    bad = failed(tmp_path, capsys)
    assert "seam vertices" in bad and "boundary" in bad and "area" not in bad


def test_planned_seam_vertex_missing(tmp_path, capsys):
    pts, tris = grid()
    seam = [[X0 + 1, Y0 + H * j] for j in range(NY)]
    seam[2] = [X0 + 1, Y0 + 0.6]  # planned, but the mesh has no vertex there
    write(tmp_path, pts, tris, seam=seam)
    assert failed(tmp_path, capsys) == ["seam vertices"]


def test_outline_vertex_moved(tmp_path, capsys):
    pts, tris = grid()
    pts[2, 1] -= 1e-3  # a vertex of the bottom edge, 1 mm outside the region
    write(tmp_path, pts, tris)
    bad = failed(tmp_path, capsys)
    assert "boundary" in bad and "area" in bad


@pytest.mark.parametrize("grow", [1e-6, 1e-3])
def test_area_differs_from_the_region(tmp_path, capsys, grow):
    # The mesh covers 2 m x 1 m; a region larger by `grow` m in y is not covered to 1e-9.
    pts, tris = grid()
    region = [[X0, Y0], [X0 + 2, Y0], [X0 + 2, Y0 + 1 + grow], [X0, Y0 + 1 + grow]]
    write(tmp_path, pts, tris, region=region)
    assert "area" in failed(tmp_path, capsys)


def test_counts_differ_from_merge_json(tmp_path, capsys):
    write(tmp_path, *grid(), summary={"vertices": 1})
    assert failed(tmp_path, capsys) == ["readable"]
