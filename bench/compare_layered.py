#!/usr/bin/env python3
"""Side-by-side timing of `terramesh model` against OpenGeoSys' `createLayeredMeshFromRasters`
(issue 13, "Speed").

The case: a 10 km x 10 km region meshed by terramesh into about 200,000 triangles; the terrain
and two unit tops as ESRI ASCII grids of 1001 x 1001 posts (10 m), smooth analytic surfaces
that cross so that onlap and pinch-out happen, and a flat base: three units, about 640,000
prisms. OpenGeoSys gets the same planar mesh (terramesh's `model-top.vtu`) and the same grids
plus a flat 1001 x 1001 base grid (it needs every layer as a raster: four rasters).

Timed, each in its own process under /usr/bin/time (wall clock and peak resident size):
* `terramesh model` of the project into a new folder ("cold"): the whole command, the DSM
  included (samples from the terrain grid, variogram, mesh, interpolation of the terrain at
  every vertex), then the grids read, the model built and checked, and every file written
  (model.vtu, the boundary meshes, model.msh, model.f3grid, the bodies .ts/.stl,
  interfaces/*.tif, model.json); the log's "geology" line gives the geology stage alone;
* `terramesh model` again into the same folder ("DSM reused"): the DSM kept there
  (dsm-cache.bin) is read instead of built, so the command starts, like OpenGeoSys, from a
  planar mesh with its terrain elevations: the horizon grids read, the model built and
  checked, every file written, and the previous folder replaced;
* `createLayeredMeshFromRasters` (reads its four ASCII grids, builds the mesh, writes one
  binary .vtu).
Each run REPEATS times, interleaved; the least wall clock and the least CPU time of each are
compared (peak memory: the largest). Prints the machine's load average with every figure: the
development machine is shared, and under load the wall clock mostly measures the wait for a
core, so the CPU time (user + system of all threads, from /usr/bin/time) is printed too.

Usage (from the repository root; `.venv-verify` holds the ogs wheel, `.ci/verify-setup.sh`):
    cargo build --release -p terramesh-cli
    .venv-verify/bin/python bench/compare_layered.py [REPEATS] [--keep DIR] [--layers N]
`--layers N` splits every unit into N sub-layers in terramesh (N = 8: about 5,000,000 cells);
OpenGeoSys has no sub-layers, so its run is skipped then.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
TERRAMESH = os.path.join(TARGET, "release", "terramesh")
X0, Y0, SIZE, N = 500_000.0, 5_000_000.0, 10_000.0, 1001
STEP = SIZE / (N - 1)
BASE = -120.0
# WGS 84 / UTM 32N (EPSG:32632) as ESRI WKT: the project's CRS, so no point is moved.
PRJ = ('PROJCS["WGS_1984_UTM_Zone_32N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",'
       '6378137.0,298.257223563]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]],'
       'PROJECTION["Transverse_Mercator"],PARAMETER["False_Easting",500000.0],'
       'PARAMETER["False_Northing",0.0],PARAMETER["Central_Meridian",9.0],'
       'PARAMETER["Scale_Factor",0.9996],PARAMETER["Latitude_Of_Origin",0.0],UNIT["Meter",1.0]]')


def surfaces():
    """Terrain and two unit tops on the 1001 x 1001 posts (rows top first), metres."""
    xs = np.linspace(0.0, SIZE, N)
    gx, gy = np.meshgrid(xs, xs[::-1])
    u, v = gx / SIZE, gy / SIZE
    terrain = 100.0 + 20.0 * np.sin(3.0 * u) * np.cos(2.0 * v) + 5.0 * u
    top1 = 60.0 + 30.0 * np.cos(4.0 * u + 1.0) * np.sin(3.0 * v)  # crosses the terrain and top2
    top2 = 30.0 + 25.0 * np.sin(5.0 * v + 0.5) - 10.0 * u
    return {"terrain": terrain, "top1": top1, "top2": top2, "base": np.full_like(terrain, BASE)}


def write_asc(path, rows):
    with open(path, "w") as f:
        f.write(f"ncols {N}\nnrows {N}\nxllcorner {X0 - STEP / 2!r}\nyllcorner {Y0 - STEP / 2!r}\n"
                f"cellsize {STEP!r}\nNODATA_value -9999\n")
        np.savetxt(f, rows, fmt="%.6f")
    with open(path[:-4] + ".prj", "w") as f:
        f.write(PRJ)


def project(layers):
    m = 200.0  # the region lies 200 m inside the grids' posts
    c = [(Y0 + m, X0 + m), (Y0 + m, X0 + SIZE - m), (Y0 + SIZE - m, X0 + SIZE - m), (Y0 + SIZE - m, X0 + m)]
    corners = "; ".join(f"{y} {x}" for y, x in c)
    lay = f"layers = {{ a = {layers}, b = {layers}, c = {layers} }}\n" if layers > 1 else ""
    return f"""title = "compare_layered: terramesh model against createLayeredMeshFromRasters"
[region]
corners = "{corners}"
crs = "EPSG:32632"
[source]
path = "terrain.asc"
[sampling]
rows = 100
cols = 100
margin = 0.0
method = "bilinear"
[mesh]
min_angle = 25.0
max_area = 440.0
smooth = 0
[interpolation]
methods = ["idw"]
neighbors = 8
[export]
formats = []
pictures = false
report = false
[geology]
units = ["a", "b", "c"]
surfaces = {{ b = "top1.asc", c = "top2.asc" }}
base = {BASE}
min_thickness = 0.5
{lay}interpolate = "tops"
"""


def timed(cmd, cwd):
    """(wall s, CPU s (user + system, all threads), peak MB, output) of one run under
    /usr/bin/time."""
    t = time.perf_counter()
    r = subprocess.run(["/usr/bin/time", "-f", "PEAK_KB %M CPU %U %S"] + cmd, cwd=cwd, capture_output=True,
                       text=True)
    wall = time.perf_counter() - t
    out = r.stdout + r.stderr
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{out[-3000:]}")
    peak, user, system = re.findall(r"PEAK_KB (\d+) CPU ([\d.]+) ([\d.]+)", out)[-1]
    return wall, float(user) + float(system), int(peak) / 1024, out


def load():
    return "load %.1f" % os.getloadavg()[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("repeats", nargs="?", type=int, default=3)
    ap.add_argument("--keep")
    ap.add_argument("--layers", type=int, default=1)
    a = ap.parse_args()
    work = a.keep or tempfile.mkdtemp(prefix="compare-layered-")
    os.makedirs(work, exist_ok=True)
    t = time.perf_counter()
    for name, rows in surfaces().items():
        write_asc(os.path.join(work, f"{name}.asc"), rows)
    with open(os.path.join(work, "terramesh.toml"), "w") as f:
        f.write(project(a.layers))
    with open(os.path.join(work, "layers.txt"), "w") as f:
        f.write("terrain.asc\ntop1.asc\ntop2.asc\nbase.asc\n")
    print(f"case written in {time.perf_counter() - t:.1f} s into {work}")

    ogs = None
    if a.layers == 1:
        ogs = shutil.which("createLayeredMeshFromRasters", path=os.path.dirname(sys.executable))
        if ogs is None:
            sys.exit("createLayeredMeshFromRasters not found beside this Python: use .venv-verify/bin/python")
    geo_re = r"\[\d+/\d+\] geology: (.*?) \(([\d.]+) s\)"
    runs = {"cold": [], "reused": [], "ogs": []}  # (wall, CPU, peak MB, geology stage s)
    out_dir = os.path.join(work, "out")
    # Interleaved, so that the three see about the same load.
    for k in range(a.repeats):
        shutil.rmtree(out_dir, ignore_errors=True)
        wall, cpu, peak, log = timed([TERRAMESH, "model", "terramesh.toml", "-o", out_dir], work)
        geo = re.search(geo_re, log)
        mesh = re.search(r"\[3/\d+\] mesh: (.*?) \(", log)
        print(f"terramesh model (cold): {wall:.2f} s wall, {cpu:.2f} s CPU, geology stage {geo.group(2)} s wall, "
              f"peak {peak:.0f} MB ({load()}); {mesh.group(1)}; {geo.group(1)}", flush=True)
        runs["cold"].append((wall, cpu, peak, float(geo.group(2))))
        wall, cpu, peak, log = timed([TERRAMESH, "model", "terramesh.toml", "-o", out_dir], work)
        geo = re.search(geo_re, log)
        if "dsm: reused" not in log:
            sys.exit(f"the second run did not reuse the DSM:\n{log[-2000:]}")
        print(f"terramesh model (DSM reused): {wall:.2f} s wall, {cpu:.2f} s CPU, geology stage {geo.group(2)} s "
              f"wall, peak {peak:.0f} MB ({load()})", flush=True)
        runs["reused"].append((wall, cpu, peak, float(geo.group(2))))
        if ogs is not None:
            if k == 0:
                shutil.copy(os.path.join(out_dir, "model-top.vtu"), os.path.join(work, "plane.vtu"))
            wall, cpu, peak, _ = timed([ogs, "-i", "plane.vtu", "-o", "ogs.vtu", "-r", "layers.txt", "-t", "0.5"],
                                       work)
            print(f"createLayeredMeshFromRasters: {wall:.2f} s wall, {cpu:.2f} s CPU, peak {peak:.0f} MB ({load()})",
                  flush=True)
            runs["ogs"].append((wall, cpu, peak, wall))
    sizes = sum(os.path.getsize(os.path.join(dp, f)) for dp, _, fs in os.walk(out_dir) for f in fs)
    print(f"terramesh wrote {sizes / 2**20:.0f} MiB")
    # The least wall clock and the least CPU time of the repeats (each the least disturbed).
    best = {k: (min(r[0] for r in v), min(r[1] for r in v), max(r[2] for r in v), min(r[3] for r in v))
            for k, v in runs.items() if v}
    for k, name in [("cold", "terramesh model, cold"), ("reused", "terramesh model, DSM reused"),
                    ("ogs", "createLayeredMeshFromRasters")]:
        if k in best:
            w, c, p, g = best[k]
            stage = f", geology stage {g:.2f} s wall" if k != "ogs" else ""
            print(f"best {name}: {w:.2f} s wall, {c:.2f} s CPU{stage}, peak {p:.0f} MB")
    if "ogs" in best:
        o = best["ogs"]
        for k in ["cold", "reused"]:
            print(f"ratio terramesh ({k}) / OpenGeoSys: {best[k][0] / o[0]:.2f} wall, {best[k][1] / o[1]:.2f} CPU "
                  f"(goal <= 0.25)")
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
