#!/usr/bin/env bash
# Peak memory of `terramesh tiles plan` on examples/fort-worth-1m sampled at ROWS x COLS,
# 10 km tiles (docs/scaling.md, "`tiles plan` per tile"), and the plan folder it wrote.
#   bench/plan_memory.sh 1436 1468                  # this build, into bench-out/planmem-1436
#   BIN=other/terramesh TAG=ref bench/plan_memory.sh 1436 1468   # into bench-out/planmem-ref-1436
#   diff -r bench-out/planmem-ref-1436 bench-out/planmem-1436      # the two plans
# Prints samples, wall, CPU (user + system) and peak RSS (/usr/bin/time -v).
set -euo pipefail
rows=$1 cols=$2
bin=${BIN:-target/release/terramesh}
tile=${TILE:-10km}
out=bench-out/planmem${TAG:+-$TAG}-$rows${TILE:+-$TILE}
rm -rf "$out"
mkdir -p bench-out
/usr/bin/time -v "$bin" tiles plan examples/fort-worth-1m/terramesh.toml --tile-size "$tile" \
  -o "$out" --quiet --set sampling.rows="$rows" --set sampling.cols="$cols" 2> "$out.time"
samples=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['data']['count'])" "$out/tiles.json")
awk -v s="$samples" -v o="$out" -F': ' '
  /Elapsed/ {w=$2} /User time/ {u=$2} /System time/ {y=$2} /Maximum resident/ {m=$2}
  END {printf "%s: %s samples, wall %s, CPU %.2f s, peak RSS %.1f MB\n", o, s, w, u+y, m/1000}' "$out.time"
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
