#!/usr/bin/env bash
# Each stage's time and peak memory of the one-piece build of examples/fort-worth-1m (every
# export, pictures and report) at several thread counts (RAYON_NUM_THREADS), and the ratio
# (exports + pictures + report) / (mesh + interpolation), compared within each run (issue 33,
# goal 1: at most 0.5). Figures from each build's build.json; the process's user CPU time,
# wall time and peak RSS from /usr/bin/time -v.
#   bench/stages_fort_worth.sh [THREADS...]      # default: 1 2, and 4 8 16 up to nproc
# BIN=path picks another terramesh (e.g. an older build, to compare); OUT=dir (bench-out/stages).
# The machine's load (`uptime`) is printed before each build: on a shared machine, wall times
# are inflated by the other processes, so compare the ratio of one run, not times across runs.
# Needs ../shared/data/grids/fort-worth-3arcsec.tif and target/release/terramesh (or BIN=path).
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
printf '%-7s %7s %7s %7s %7s %7s %7s %7s %8s %8s %6s\n' threads mesh interp exports \
  pictures report total user_s peak_MB load1 ratio
for t in "${threads[@]}"; do
  load=$(cut -d' ' -f1 /proc/loadavg)
  rm -rf "$out/t$t"
  RAYON_NUM_THREADS=$t /usr/bin/time -v -o "$out/t$t.time" "$bin" build "$ex" -o "$out/t$t" \
    --quiet >"$out/t$t.log" 2>&1
  python3 - "$out/t$t/build.json" "$out/t$t.time" "$t" "$load" <<'EOF'
import json, re, sys
b = json.load(open(sys.argv[1]))
s = {x["stage"]: x["seconds"] for x in b["stages"]}
tv = open(sys.argv[2]).read()
user = float(re.search(r"User time \(seconds\): ([\d.]+)", tv).group(1))
peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", tv).group(1)) / 1e3
g = lambda k: s.get(k, 0.0)
ratio = (g("exports") + g("pictures") + g("report")) / (g("mesh") + g("interpolation"))
print("%-7s %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %8.1f %8s %6.2f" % (
    sys.argv[3], g("mesh"), g("interpolation"), g("exports"), g("pictures"), g("report"),
    b["seconds"], user, peak, sys.argv[4], ratio))
EOF
done
