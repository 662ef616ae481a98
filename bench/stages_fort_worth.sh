#!/usr/bin/env bash
# Each stage's time and peak memory of the one-piece build of examples/fort-worth-1m (every
# export, pictures and report) at several thread counts (RAYON_NUM_THREADS), and the ratio
# (exports, pictures and report together) / (mesh + interpolation) within each run (issue 33,
# goal 1: at most 0.5).
#   bench/stages_fort_worth.sh [THREADS...]      # default: 1 2, and 4 8 16 up to nproc
# BIN=path picks another terramesh (e.g. main's, to compare); OUT=dir (bench-out/stages).
#
# Per stage: wall seconds from build.json, and the CPU seconds the process spent in it (its
# utime + stime from /proc/PID/stat, read as each stage's log line appears). The exports,
# pictures and report run at once and log their lines together at the end, so their CPU is
# one figure ("outputs": from the interpolation's line to the report's) and their wall time
# is build.json's `outputs_seconds` (the first one's start to the last one's end); each
# one's own seconds are printed beside it. A binary from before they ran at once (no
# `outputs_seconds`) ran them one after another: its outputs' wall time is the sum of the
# three (which left out the kept DSM, dsm-cache.bin, written untimed before the exports).
# On a shared machine wall times stretch with the other processes' load (the load average
# is printed); the CPU ratio is the steadier figure there, the wall ratio the one the goal
# names. Peak memory: /usr/bin/time -v's maximum RSS of the whole build.
# Needs ../shared/data/grids/fort-worth-3arcsec.tif, python3, /usr/bin/time and
# target/release/terramesh (or BIN=path).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BIN:-target/release/terramesh}
out=${OUT:-bench-out/stages}
ex=examples/fort-worth-1m/terramesh.toml
threads=("$@")
if [ ${#threads[@]} = 0 ]; then
  threads=(1 2)
  for t in 4 8 16; do [ "$t" -le "$(nproc)" ] && threads+=("$t"); done
fi
mkdir -p "$out"
echo "binary: $bin ($("$bin" --version)); $(nproc) cores"
python3 - "$bin" "$ex" "$out" "${threads[@]}" <<'EOF'
import json, os, re, shutil, subprocess, sys

bin_, ex, out, *threads = sys.argv[1:]
tick = os.sysconf("SC_CLK_TCK")
heavy = ["mesh", "interpolation"]
light = ["exports", "pictures", "report"]
cols = heavy + ["outputs"]
print("%-7s %5s  %s  %20s  %7s %7s %8s  %9s %8s" % (
    "threads", "load", " ".join("%13s" % c for c in cols), "exports/pict./report",
    "total", "user+sys", "peak MB", "wall ratio", "cpu ratio"))
print("%-7s %5s  %s  %20s" % ("", "", " ".join("%13s" % "wall / cpu s" for _ in cols),
                              "own wall s"))
for t in threads:
    load = open("/proc/loadavg").read().split()[0]
    dest = os.path.join(out, f"t{t}")
    shutil.rmtree(dest, ignore_errors=True)
    timef = os.path.join(out, f"t{t}.time")
    env = dict(os.environ, RAYON_NUM_THREADS=t)
    p = subprocess.Popen(["/usr/bin/time", "-v", "-o", timef, bin_, "build", ex, "-o", dest],
                         stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=env)
    # /usr/bin/time's child: the build itself.
    kids = []
    cpu, last = {}, 0.0
    for line in p.stderr:
        m = re.match(r"terramesh: \[\d+/\d+\] ([a-z ]+):", line)
        if not m:
            continue
        if not kids:
            kids = open(f"/proc/{p.pid}/task/{p.pid}/children").read().split()
        try:
            f = open(f"/proc/{kids[0]}/stat").read().rsplit(")", 1)[1].split()
            now = (int(f[11]) + int(f[12])) / tick
        except (OSError, IndexError):
            now = last
        cpu[m.group(1)] = now - last
        last = now
    if p.wait() != 0:
        sys.exit(f"the build with {t} threads failed: see {dest}")
    b = json.load(open(os.path.join(dest, "build.json")))
    wall = {x["stage"]: x["seconds"] for x in b["stages"]}
    wall["outputs"] = b.get("outputs_seconds", sum(wall.get(k, 0.0) for k in light))
    cpu["outputs"] = sum(cpu.get(k, 0.0) for k in light)
    tv = open(timef).read()
    user = sum(float(x) for x in re.findall(r"(?:User|System) time \(seconds\): ([\d.]+)", tv))
    peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", tv).group(1)) / 1e3
    g = lambda d, ks: sum(d.get(k, 0.0) for k in ks)
    print("%-7s %5s  %s  %20s  %7.2f %8.2f %8.1f  %9.2f %8.2f" % (
        t, load, " ".join("%6.2f / %5.2f" % (wall.get(c, 0), cpu.get(c, 0)) for c in cols),
        " / ".join("%.2f" % wall.get(k, 0.0) for k in light),
        b["seconds"], user, peak, wall["outputs"] / g(wall, heavy),
        cpu["outputs"] / g(cpu, heavy)))
EOF
