"""terramesh.mesh: invariants checked independently (numpy), files read back by meshio."""

import json

import numpy as np
import pytest

import terramesh


def signed_areas(m):
    p, t = m.points, m.triangles
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1]))


def min_angles(m):
    p, t = m.points[:, :2], m.triangles
    out = np.full(len(t), 180.0)
    for k in range(3):
        u = p[t[:, (k + 1) % 3]] - p[t[:, k]]
        v = p[t[:, (k + 2) % 3]] - p[t[:, k]]
        ang = np.degrees(np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]), (u * v).sum(1)))
        out = np.minimum(out, ang)
    return out


def test_square_with_a_hole_is_covered_with_quality_triangles():
    shell = np.array([[0, 0], [200, 0], [200, 100], [0, 100]], float)
    hole = [(80, 30), (120, 30), (120, 70), (80, 70)]
    m = terramesh.mesh([shell, hole], min_angle=30, max_area=40.0)
    areas = signed_areas(m)
    assert np.all(areas > 0)  # counter-clockwise, none degenerate
    assert areas.sum() == pytest.approx(200 * 100 - 40 * 40, rel=1e-12)
    assert areas.max() <= 40.0 + 1e-9
    np.testing.assert_allclose(m.min_angle, min_angles(m), atol=1e-9)
    assert m.min_angle.min() >= 30.0 - 1e-9
    centroids = m.points[m.triangles].mean(axis=1)
    inside_hole = (centroids[:, 0] > 80) & (centroids[:, 0] < 120) & (centroids[:, 1] > 30) & (centroids[:, 1] < 70)
    assert not inside_hole.any()


def test_geo_interface_and_geographic_regions():
    class Shape:
        __geo_interface__ = {
            "type": "Polygon",
            "coordinates": [[(7.3368, 48.7224), (7.3404, 48.7224), (7.3404, 48.726), (7.3368, 48.726), (7.3368, 48.7224)]],
        }

    m = terramesh.mesh(Shape(), crs="geographic", max_area=500.0)
    assert m.zone == "32N"
    lon, lat = np.array(Shape.__geo_interface__["coordinates"][0][:4]).T
    e, n, _ = terramesh.utm.forward(lat, lon, zone="32N")
    for ce, cn in zip(e, n):  # every projected corner is a mesh vertex
        assert np.min(np.hypot(m.points[:, 0] - ce, m.points[:, 1] - cn)) < 1e-6


def test_region_file_path(tmp_path):
    p = tmp_path / "r.geojson"
    p.write_text(json.dumps({"type": "Polygon", "coordinates": [[[0, 0], [50, 0], [50, 50], [0, 50], [0, 0]]]}))
    m = terramesh.mesh(str(p), crs="projected", max_area=20.0)
    assert signed_areas(m).sum() == pytest.approx(2500.0)


def test_meshio_reads_what_to_meshio_gives(tmp_path):
    meshio = pytest.importorskip("meshio")
    m = terramesh.mesh([[(0, 0), (30, 0), (30, 20), (0, 20)]], max_area=5.0)
    z = np.sin(m.points[:, 0] / 10)
    lifted = m.with_heights(z)
    mm = lifted.to_meshio()
    path = tmp_path / "m.vtu"
    mm.write(path)
    back = meshio.read(path)
    np.testing.assert_array_equal(back.points, lifted.points)
    np.testing.assert_array_equal(back.cells_dict["triangle"], m.triangles)
    np.testing.assert_array_equal(back.cell_data["min_angle_deg"][0], m.min_angle)


def test_bad_regions_raise_input_errors(tmp_path):
    with pytest.raises(terramesh.InputError, match="region"):
        terramesh.mesh([[(0, 0), (1, 1), (0, 1), (1, 0)]])  # self-intersecting
    with pytest.raises(terramesh.InputError):
        terramesh.mesh({"type": "LineString", "coordinates": [[0, 0], [1, 1]]})
    with pytest.raises(terramesh.Error):
        terramesh.mesh(str(tmp_path / "missing.geojson"))
    with pytest.raises(terramesh.InputError, match="min_angle|angle"):
        terramesh.mesh([[(0, 0), (1, 0), (0, 1)]], min_angle=50)
