"""Negative tests of check_viewer.check_viewer_model: a report.html whose viewer scene is written
here from the committed model fixture's bodies (tests/verify/fixtures/model/unit-*.ts) passes,
and fails with a unit missing, a unit moved off the model, no borehole points, no borehole
traces, or traces not in the units' colours.

    .venv-verify/bin/python -m pytest tests/verify/test_check_viewer_model.py
"""

import base64
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_model as cm  # noqa: E402
import check_viewer as cv  # noqa: E402
from vcommon import CheckFailed, Outputs  # noqa: E402

FIXTURE = HERE / "fixtures" / "model"


def b64(a, dtype):
    return base64.b64encode(np.asarray(a, dtype=dtype).tobytes()).decode()


def write(d, drop=None, shift=0.0, holes=True, traces=True, grey=False):
    """model.json (unit names, one contact) and report.html with one layer per body."""
    _, _, _, names, _ = cm.Model(d).vtu()
    bodies = [(n, *cm.read_tsurf(d / f"unit-{n}.ts")) for n in names if (d / f"unit-{n}.ts").is_file()]
    origin = np.vstack([v for _, v, _ in bodies]).min(0)
    layers = []
    for n, v, t in bodies:
        if n == drop:
            continue
        p = v - origin + np.array([0.0, 0.0, shift])
        layers.append({"name": f"unit {n}", "kind": "triangles", "vertices": len(p), "triangles": len(t),
                       "positions": b64(p, "<f4"), "indices": b64(t, "<u4"), "fields": {},
                       "colour": [40 * len(layers), 100, 200]})
    if holes:
        layers.append({"name": "boreholes (1 collars)", "kind": "points", "vertices": 1,
                       "positions": b64([[0.0, 0.0, 0.0]], "<f4"), "indices": "", "fields": {}})
    if traces:
        # One triangle per unit layer, in that layer's colour (or all grey).
        units = [l for l in layers if l["name"].startswith("unit ")]
        cols = [[110, 110, 110] if grey else l["colour"] for l in units for _ in range(3)]
        layers.append({"name": "borehole traces (1, coloured by logged unit)", "kind": "triangles",
                       "vertices": len(cols), "triangles": len(units),
                       "positions": b64(np.zeros((len(cols), 3)), "<f4"),
                       "indices": b64(np.arange(len(cols)), "<u4"), "fields": {},
                       "vertex_colours": base64.b64encode(np.asarray(cols, dtype=np.uint8).tobytes()).decode()})
    scene = {"origin": origin.tolist(), "note": None, "fields": {}, "layers": layers}
    (d / "model.json").write_text(json.dumps({"units": [{"name": n} for n in names],
                                              "boreholes": [{"hole": "B1"}]}))
    (d / "report.html").write_text(f'<html><script type="application/json" id="tmv-data">'
                                   f'{json.dumps(scene)}</script></html>')


@pytest.fixture
def out(tmp_path):
    d = tmp_path / "out"
    shutil.copytree(FIXTURE, d)
    return d


def test_units_written_from_the_bodies_pass(out):
    write(out)
    cv.check_viewer_model(Outputs(out))


def test_a_missing_unit_fails(out):
    write(out, drop="clay")
    with pytest.raises(CheckFailed, match="unit layers"):
        cv.check_viewer_model(Outputs(out))


def test_a_unit_off_the_model_fails(out):
    write(out, shift=0.5)
    with pytest.raises(CheckFailed, match="vs model.vtu"):
        cv.check_viewer_model(Outputs(out))


def test_no_borehole_points_fails(out):
    write(out, holes=False)
    with pytest.raises(CheckFailed, match="borehole points"):
        cv.check_viewer_model(Outputs(out))


def test_no_borehole_traces_fails(out):
    write(out, traces=False)
    with pytest.raises(CheckFailed, match="no borehole traces"):
        cv.check_viewer_model(Outputs(out))


def test_traces_without_the_units_colours_fail(out):
    write(out, grey=True)
    with pytest.raises(CheckFailed, match="units' colours"):
        cv.check_viewer_model(Outputs(out))
