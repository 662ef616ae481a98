"""The pipeline from Python: sampling and a full build of examples/haut-barr (with its
committed SRTM crop, so it works without ../shared), read back by meshio; Ctrl-C."""

import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import terramesh

CORNERS = "N48°43'20.64\" E7°20'12.48\"; N48°43'20.64\" E7°20'25.44\"; N48°43'33.6\" E7°20'25.44\"; N48°43'33.6\" E7°20'12.48\""


def example(root, tmp_path):
    """The example project, its source pointed at the bundled crop (as without ../shared)."""
    src = root / "examples" / "haut-barr"
    for f in ("terramesh.toml", "srtm-crop.asc", "corners.csv"):
        shutil.copy(src / f, tmp_path / f)
    return tmp_path / "terramesh.toml"


def test_sample_the_crop_matches_the_cli_table(root, tmp_path):
    crop = root / "examples" / "haut-barr" / "srtm-crop.asc"
    s = terramesh.sample(crop, CORNERS, rows=20, cols=10, margin=0.1, output=tmp_path / "s.csv")
    assert s.zone == "32N" and len(s.z) == 200 and np.all(np.isfinite(s.z))
    rows = np.genfromtxt(tmp_path / "s.csv", delimiter=",", names=True)
    np.testing.assert_allclose(rows["z"], s.z, atol=5e-4)
    e, n, _ = terramesh.utm.forward(s.lat, s.lon, zone="32N")
    np.testing.assert_allclose(e, s.x, atol=1e-6)
    np.testing.assert_allclose(n, s.y, atol=1e-6)


def test_full_build_of_the_example(root, tmp_path):
    project = example(root, tmp_path)
    out = tmp_path / "out"
    r = terramesh.build(project, out, set={"export.pictures": False}, progress=False)
    assert r.vertices > 2000 and r.triangles > 4000
    assert all(f.is_file() for f in r.files)
    assert (out / "report.html").is_file() and (out / "dsm.vtu") in r.files
    assert r.variogram is not None and r.variogram.structures
    assert {row["method"] for row in r.cross_validation} >= {"UK", "OK", "IDW"}
    # The build's UK heights are what terramesh.krige gives on its samples with its variogram.
    s = np.genfromtxt(out / "samples.csv", delimiter=",", names=True)
    v = r.vertices_table()
    est = terramesh.krige(s["easting"], s["northing"], s["z"], v["x"], v["y"], method="uk", drift="linear",
                          variogram=r.variogram, neighbors=64, return_variance=False)
    np.testing.assert_allclose(est, v["elevation_uk"], atol=1e-6)
    meshio = pytest.importorskip("meshio")
    m = r.to_meshio()
    assert len(m.points) == r.vertices
    assert m.cells_dict["triangle"].shape == (r.triangles, 3)
    np.testing.assert_allclose(m.point_data["elevation_uk"], v["elevation_uk"], atol=1e-9)


def test_build_from_a_dict_and_errors_name_the_key(root, tmp_path):
    crop = root / "examples" / "haut-barr" / "srtm-crop.asc"
    project = {
        "region": {"corners": CORNERS},
        "source": {"path": str(crop)},
        "sampling": {"rows": 30, "cols": 15},
        "mesh": {"max_area": 800.0},
        "export": {"formats": ["vtu"], "pictures": False, "report": False},
    }
    r = terramesh.build(project, tmp_path / "o", progress=False)
    assert (tmp_path / "o" / "dsm.vtu").is_file() and r.triangles > 100
    with pytest.raises(terramesh.InputError, match="mesh.min_angle"):
        terramesh.build(project, tmp_path / "o2", set={"mesh.min_angle": 40}, progress=False)
    with pytest.raises(terramesh.InputError, match="nope"):
        terramesh.build({**project, "nope": {"x": 1}}, tmp_path / "o3", progress=False)


def test_ctrl_c_stops_a_build_and_leaves_no_output(root, tmp_path):
    project = example(root, tmp_path)
    out = tmp_path / "out"
    code = textwrap.dedent(
        f"""
        import sys, terramesh
        try:
            terramesh.build({str(project)!r}, {str(out)!r}, set={{"interpolation.neighbors": 0}}, progress=False)
        except KeyboardInterrupt:
            print("interrupted"); sys.exit(3)
        print("finished")
        """
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    time.sleep(2.0)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    stdout, _ = p.communicate(timeout=120)
    assert "interrupted" in stdout and p.returncode == 3, stdout
    assert not out.exists()
    leftovers = [f for f in os.listdir(tmp_path) if f.startswith(".out") or "tmp" in f]
    assert leftovers == [], leftovers


def test_sample_over_rings_equals_sample_over_the_corner_list(root):
    crop = root / "examples" / "haut-barr" / "srtm-crop.asc"
    lat = [terramesh.utm.parse_dms(c.split()[0]) for c in CORNERS.split(";")]
    lon = [terramesh.utm.parse_dms(c.split()[1]) for c in CORNERS.split(";")]
    a = terramesh.sample(crop, CORNERS, rows=12, cols=6, clip=True)
    b = terramesh.sample(crop, [list(zip(lon, lat))], rows=12, cols=6, clip=True)
    np.testing.assert_array_equal(a.z, b.z)
    np.testing.assert_array_equal(a.x, b.x)
    with pytest.raises(terramesh.InputError, match="margin"):
        terramesh.sample(crop, CORNERS, margin="ten")
