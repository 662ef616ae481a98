#!/usr/bin/env python3
"""One row of docs/scaling.md's "Per tile at three tile sizes" from a run of
bench/tiles_fort_worth.sh: per-tile vertices, seconds (the tiles' own built.seconds.total),
peak RSS and CPU (user + system, /usr/bin/time -v), per-vertex wall and CPU, the plan's and
the merge's wall, CPU and peak, and the samples the tiles read.
    bench/tiles_table.py bench-out/r10km
"""
import json
import sys
from pathlib import Path


def timefile(p):
    d = {}
    for line in Path(p).read_text().splitlines():
        k, _, v = line.strip().rpartition(": ")
        d[k] = v
    wall = d["Elapsed (wall clock) time (h:mm:ss or m:ss)"].split(":")
    secs = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
    cpu = float(d["User time (seconds)"]) + float(d["System time (seconds)"])
    return secs, cpu, int(d["Maximum resident set size (kbytes)"]) / 1000.0


out = Path(sys.argv[1])
m = json.loads((out / "plan/tiles.json").read_text())
rows = []
for t in m["tiles"]:
    b = t["built"]
    total = dict((k, v) for k, v in b["seconds"])["total"]
    _, cpu, peak = timefile(out / f"tile-{t['id']}.time")
    rows.append((b["vertices"], total, peak, cpu, b["samples_read"]))
v = [r[0] for r in rows]
s = [r[1] for r in rows]
pk = [r[2] for r in rows]
cpu = [r[3] for r in rows]
pw, pc, pp = timefile(out / "plan.time")
mw, mc, mp = timefile(out / "merge.time")
print(f"tiles {len(rows)} ({m['shape'][0]} x {m['shape'][1]}), vertices {min(v):,}-{max(v):,} "
      f"(sum {sum(v):,}), seconds {min(s):.1f}-{max(s):.1f}, peak {min(pk):.1f}-{max(pk):.1f} MB, "
      f"wall/vertex {1e6 * sum(s) / sum(v):.0f} us, cpu/vertex {1e6 * sum(cpu) / sum(v):.0f} us, "
      f"plan {pw:.1f} s, {pc:.1f} s CPU, {pp:.1f} MB, merge {mw:.1f} s, {mc:.1f} s CPU, {mp:.1f} MB, "
      f"samples read {sum(r[4] for r in rows):,}, largest tile {max(rows)[0]:,} vertices at "
      f"{max(rows)[2]:.1f} MB")
