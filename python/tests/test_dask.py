"""terramesh.dask: a tiled build of the Haut-Barr example (the committed SRTM crop when the
shared data are absent) on a dask.distributed LocalCluster of 2 workers, against the
one-piece build with the same variogram file."""

import json
import os
import pathlib
import signal
import struct
import subprocess
import threading
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "haut-barr" / "terramesh.toml"

distributed = pytest.importorskip("distributed")
from terramesh.dask import build_tiles, main  # noqa: E402


@pytest.fixture(scope="module")
def binary():
    b = os.environ.get("TERRAMESH_BIN") or str(ROOT / "target" / "release" / "terramesh")
    if not os.path.exists(b):
        if os.environ.get("CI"):
            pytest.fail(f"{b} missing: cargo build --release -p terramesh-cli first")
        pytest.skip(f"skipped: {b} missing (cargo build --release -p terramesh-cli)")
    return b


def run(*args):
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p.stdout


def asc(path):
    vals = []
    for line in pathlib.Path(path).read_text().splitlines():
        if line[:1].isalpha():
            continue
        vals += [float(x) for x in line.split()]
    return vals


def vtu(path):
    """Points and triangles of the merged dsm.vtu (raw appended binary, UInt64 headers)."""
    raw = pathlib.Path(path).read_bytes()
    mark = b'<AppendedData encoding="raw">'
    start = raw.index(b"_", raw.index(mark) + len(mark)) + 1
    xml = raw[:start].decode()

    def block(tag, fmt, size):
        head = xml[xml.rindex("<DataArray", 0, xml.index(tag)) : xml.index(">", xml.index(tag))]
        off = start + int(head.split('offset="')[1].split('"')[0])
        (n,) = struct.unpack_from("<Q", raw, off)
        return list(struct.unpack_from(f"<{n // size}{fmt}", raw, off + 8))

    p = block('NumberOfComponents="3"', "d", 8)
    c = block('Name="connectivity"', "q", 8)
    points = [tuple(p[i : i + 3]) for i in range(0, len(p), 3)]
    tris = [tuple(c[i : i + 3]) for i in range(0, len(c), 3)]
    return points, tris


def seg_dist(a, b, p):
    dx, dy = b[0] - a[0], b[1] - a[1]
    t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)
    t = min(1.0, max(0.0, t))
    return ((a[0] + t * dx - p[0]) ** 2 + (a[1] + t * dy - p[1]) ** 2) ** 0.5


def set_env(name, value):
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value


def test_tiles_on_a_local_cluster_match_the_one_piece_build(tmp_path, binary):
    plan = tmp_path / "plan"
    run(binary, "tiles", "plan", EXAMPLE, "--tile-size", "70m", "-o", plan, "--quiet")
    manifest = json.loads((plan / "tiles.json").read_text())
    assert manifest["shape"][0] >= 4 and manifest["shape"][1] >= 4
    ids = [t["id"] for t in manifest["tiles"]]
    out = tmp_path / "merged"
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    client = distributed.Client(cluster)
    try:
        # A tile that fails on purpose is reported (and recorded), and the merge does not run.
        bad = "x1y1"
        client.run(set_env, "TERRAMESH_TILES_FAIL", bad)
        r = build_tiles(plan, client, tiles=[bad], merge_to=out, retries=1, binary=binary)
        assert not r.ok and "on purpose" in r.failed[bad] and r.merged is None
        state = {t["id"]: t for t in json.loads((plan / "tiles.json").read_text())["tiles"]}
        assert state[bad]["state"] == "failed" and "on purpose" in state[bad]["error"]
        client.run(set_env, "TERRAMESH_TILES_FAIL", None)
        # Rebuilt alone.
        r = build_tiles(plan, client, tiles=[bad], binary=binary)
        assert r.ok and list(r.built) == [bad]

        # The rest, with one worker killed in the middle of the run.
        killed = []

        def kill_one():
            deadline = time.time() + 60
            while time.time() < deadline and not killed:
                done = sum(
                    t["state"] == "done"
                    for t in json.loads((plan / "tiles.json").read_text())["tiles"]
                )
                busy = [w for w, ks in client.processing().items() if ks]
                if done >= 4 and busy:
                    pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                    os.kill(pid, signal.SIGKILL)
                    killed.append(busy[0])
                time.sleep(0.05)

        killer = threading.Thread(target=kill_one)
        killer.start()
        r = build_tiles(plan, client, merge_to=out, binary=binary)
        killer.join()
        assert killed, "no worker was killed"
        assert r.ok, r.failed
        assert set(r.built) == set(ids) and r.merged
    finally:
        client.close()
        cluster.close()

    # The one-piece build with the plan's variogram file: the same grid to 1e-9 m.
    one = tmp_path / "one"
    run(
        binary, "build", EXAMPLE, "-o", one, "--quiet",
        "--set", f"interpolation.variogram={plan / 'variogram.json'}",
        "--set", 'export.formats=["vtu"]',
        "--set", "export.pictures=false",
        "--set", "export.report=false",
    )
    a, b = asc(out / "dsm.asc"), asc(one / "dsm.asc")
    assert len(a) == len(b) and sum(v != -9999.0 for v in a) > 1000
    assert max(abs(x - y) for x, y in zip(a, b)) <= 1e-9

    # The merged mesh: no edge in more than two triangles, boundary edges only on the region's
    # outline, the region's area to 1e-9, every vertex (seam vertices included) once.
    points, tris = vtu(out / "dsm.vtu")
    edges = {}
    area = 0.0
    for t in tris:
        a_, b_, c_ = (points[i] for i in t)
        area += 0.5 * ((b_[0] - a_[0]) * (c_[1] - a_[1]) - (b_[1] - a_[1]) * (c_[0] - a_[0]))
        for k in range(3):
            u, v = t[k], t[(k + 1) % 3]
            e = (min(u, v), max(u, v))
            edges[e] = edges.get(e, 0) + 1
    assert max(edges.values()) <= 2
    region = json.loads((plan / "tiles.json").read_text())["region"]
    n = len(region)
    whole = abs(sum(
        0.5 * (region[i][0] * region[(i + 1) % n][1] - region[(i + 1) % n][0] * region[i][1])
        for i in range(n)
    ))
    assert abs(area - whole) <= 1e-9 * whole

    def on_outline(p):
        return any(seg_dist(region[i], region[(i + 1) % n], p) <= 1e-6 for i in range(n))

    for (u, v), c in edges.items():
        if c == 1:
            assert on_outline(points[u]) and on_outline(points[v])
    xy = [(p[0], p[1]) for p in points]
    assert len(set(xy)) == len(xy)
    seam = {
        tuple(v)
        for t in json.loads((plan / "tiles.json").read_text())["tiles"]
        for s in t["seams"]
        for v in s["vertices"]
    }
    assert len(seam) > 100 and seam <= set(xy)


def test_the_command_line_reports_a_missing_plan(tmp_path, capsys):
    with pytest.raises(FileNotFoundError, match="terramesh tiles plan"):
        main([str(tmp_path), "--scheduler", "local", "--binary", "/bin/true"])
