"""Negative tests of check_model_glb.py: a model.glb written here in Python from the committed
model fixture's bodies (tests/verify/fixtures/model/unit-*.ts, independently of terramesh's
writer) passes both checks, and fails them with one thing broken.

    .venv-verify/bin/python -m pytest tests/verify/test_check_model_glb.py
"""

import json
import shutil
import struct
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import check_model as cm  # noqa: E402
import check_model_glb as cg  # noqa: E402

FIXTURE = HERE / "fixtures" / "model"


def model_glb(meshes, origin, extras, translation=None):
    """A GLB of several named meshes (float32 positions relative to `origin`, Y-up, u32
    indices), each on a child node of a root node holding the origin and `extras`."""
    bins, views, accessors, gmeshes, nodes = [], [], [], [], []
    offset = 0

    def add(data, target):
        nonlocal offset
        b = data.tobytes()
        b += b"\0" * (-len(b) % 4)
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": data.nbytes, "target": target})
        bins.append(b)
        offset += len(b)
        return len(views) - 1

    for name, v, t in meshes:
        rel = np.asarray(v, float) - origin
        pos = np.column_stack([rel[:, 0], rel[:, 2], -rel[:, 1]]).astype(np.float32)
        idx = np.asarray(t, dtype=np.uint32).ravel()
        accessors.append({"bufferView": add(pos, 34962), "componentType": 5126, "count": len(pos), "type": "VEC3",
                          "min": [float(x) for x in pos.min(0)], "max": [float(x) for x in pos.max(0)]})
        accessors.append({"bufferView": add(idx, 34963), "componentType": 5125, "count": len(idx),
                          "type": "SCALAR"})
        gmeshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                      "indices": len(accessors) - 1}]})
        nodes.append({"name": name, "mesh": len(gmeshes) - 1})
    t = origin if translation is None else translation
    root = {"name": "model", "translation": [t[0], t[2], -t[1]], "extras": extras,
            "children": list(range(1, len(nodes) + 1))}
    doc = {"asset": {"version": "2.0", "generator": "terramesh verifier test"}, "scene": 0,
           "scenes": [{"nodes": [0]}], "nodes": [root, *nodes], "meshes": gmeshes, "accessors": accessors,
           "bufferViews": views, "buffers": [{"byteLength": offset}]}
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    blob = b"".join(bins)
    body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(blob), b"BIN\0") + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def bodies(d):
    """(name, vertices, triangles) of every unit-<name>.ts in the order of model.vtu's units."""
    _, _, _, names, crs = cm.Model(d).vtu()
    out = []
    for n in names:
        p = d / f"unit-{n}.ts"
        if p.is_file():
            v, t = cm.read_tsurf(p)
            out.append((n, v, np.array(t)))
    return out, crs


def write(d, change=lambda meshes, extras: None, shift=(0.0, 0.0, 0.0)):
    meshes, crs = bodies(d)
    allv = np.vstack([v for _, v, _ in meshes])
    origin = np.array([0.5 * (allv[:, 0].min() + allv[:, 0].max()), 0.5 * (allv[:, 1].min() + allv[:, 1].max()),
                       allv[:, 2].min()])
    # A shifted origin is recorded consistently (extras and translation), so only the
    # vertices betray it.
    shifted = origin + np.array(shift)
    extras = {"crs": crs, "origin": list(shifted), "units": "metre", "vertical_datum": "egm96"}
    change(meshes, extras)
    (d / "model.glb").write_bytes(model_glb(meshes, origin, extras, translation=shifted))


@pytest.fixture
def out(tmp_path):
    d = tmp_path / "model"
    shutil.copytree(FIXTURE, d)
    return d


def failures(d, capsys, validator=False):
    """Runs the model.glb checks (the glTF-Validator, which takes seconds, only when asked);
    returns their FAIL lines."""
    m = cm.Model(d)
    fails = []
    for name, fn in cg.CHECKS:
        if "Validator" in name and not validator:
            continue
        try:
            fn(m)
        except cm.CheckFailed as e:
            fails.append(f"FAIL {name}: {e}")
    return fails


def test_a_model_glb_written_independently_passes(out, capsys):
    write(out)
    assert cg.glb_present(cm.Model(out))
    assert failures(out, capsys, validator=True) == []


def test_an_origin_off_by_a_centimetre_fails(out, capsys):
    write(out, shift=(0.0, 0.0, 0.01))
    (f,) = failures(out, capsys)
    assert "bodies" in f and "1 mm" in f, f


def test_a_missing_unit_mesh_fails(out, capsys):
    write(out, change=lambda meshes, extras: meshes.pop())
    (f,) = failures(out, capsys)
    assert "meshes" in f, f


def test_reversed_triangles_fail(out, capsys):
    def flip(meshes, extras):
        n, v, t = meshes[0]
        meshes[0] = (n, v, t[:, ::-1].copy())
    write(out, change=flip)
    (f,) = failures(out, capsys)
    assert "orientation" in f, f


def test_a_wrong_crs_fails(out, capsys):
    write(out, change=lambda meshes, extras: extras.update(crs="EPSG:4326"))
    (f,) = failures(out, capsys)
    assert "crs" in f, f


def test_the_validator_reports_a_wrong_accessor_max(out, capsys):
    write(out)
    p = out / "model.glb"
    b = p.read_bytes()
    jl = struct.unpack_from("<I", b, 12)[0]
    doc = json.loads(b[20:20 + jl])
    doc["accessors"][0]["max"][0] += 1.0
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js + b[20 + jl:]
    p.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
    f = failures(out, capsys, validator=True)
    assert any("glTF-Validator" in x and "ACCESSOR_MAX_MISMATCH" in x for x in f), f
