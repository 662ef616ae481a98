#!/usr/bin/env bash
# Peak memory of `terramesh tiles plan` on examples/fort-worth-1m sampled at ROWS x COLS,
# 10 km tiles (or TILE), (docs/scaling.md, "`tiles plan` per tile"), and the plan folder it
# wrote.
#   bench/plan_memory.sh 1436 1468                  # this build, into bench-out/planmem-1436
#   BIN=other/terramesh TAG=ref bench/plan_memory.sh 1436 1468   # into bench-out/planmem-ref-1436
#   diff -r bench-out/planmem-ref-1436 bench-out/planmem-1436      # the two plans
#   TILE=5km bench/plan_memory.sh 5744 5872         # 5 km tiles, into bench-out/planmem-5744-5km
#   SAMPLING_ONLY=1 bench/plan_memory.sh 10050 10270   # stop the plan once it has sampled
# Prints samples, wall, CPU (user + system), peak RSS (/usr/bin/time -v), the plan folder's
# size on disk at the end and at its peak (scratch files included; `du` every 5 s), and the
# peak RSS and CPU through the sampling: VmHWM and utime + stime of the process when the
# first bucket file appears (the samples are all in .plan-scratch/raw.f64 then; read every
# 0.5 s). With SAMPLING_ONLY=1 the plan is stopped there and only those are printed.
set -euo pipefail
rows=$1 cols=$2
bin=${BIN:-target/release/terramesh}
tile=${TILE:-10km}
out=bench-out/planmem${TAG:+-$TAG}-$rows${TILE:+-$TILE}
rm -rf "$out" "$out.sampled"
mkdir -p bench-out
peak=$out.du
echo 0 > "$peak"
start=$(date +%s.%N)
/usr/bin/time -v "$bin" tiles plan examples/fort-worth-1m/terramesh.toml --tile-size "$tile" \
  -o "$out" --quiet --set sampling.rows="$rows" --set sampling.cols="$cols" 2> "$out.time" &
timer=$!
( n=0
  while kill -0 $timer 2>/dev/null; do
    pid=$(pgrep -P $timer | head -1 || true)
    if [ -n "$pid" ] && [ ! -e "$out.sampled" ] && compgen -G "$out/.plan-scratch/b*.bin" > /dev/null; then
      hwm=$(awk '/VmHWM/ {print $2}' /proc/$pid/status)
      cpu=$(awk -v t="$(getconf CLK_TCK)" '{printf "%.2f", ($14 + $15) / t}' /proc/$pid/stat)
      echo "$hwm $cpu $(date +%s.%N)" > "$out.sampled"
      [ -n "${SAMPLING_ONLY:-}" ] && kill "$pid"
    fi
    n=$((n + 1))
    if [ $((n % 10)) -eq 0 ]; then
      d=$(du -sk "$out" 2>/dev/null | cut -f1) || d=0
      [ "${d:-0}" -gt "$(cat "$peak")" ] && echo "$d" > "$peak"
    fi
    sleep 0.5
  done ) &
watcher=$!
wait $timer || true
wait $watcher || true
if [ -e "$out.sampled" ]; then
  read -r hwm cpu at < "$out.sampled"
  echo "$out: through the sampling ($(awk -v a="$at" -v s="$start" 'BEGIN {printf "%.0f", a - s}') s): peak RSS $(awk -v h="$hwm" 'BEGIN {printf "%.1f", h / 1000}') MB, CPU $cpu s"
fi
if [ -n "${SAMPLING_ONLY:-}" ]; then
  echo "$out: stopped after the sampling ($(du -sk "$out" | cut -f1) KB on disk then)"
  echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
  rm -rf "$out"
  exit 0
fi
samples=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['data']['count'])" "$out/tiles.json")
tiles=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['tiles']))" "$out/tiles.json")
disk=$(du -sk "$out" | cut -f1)
awk -v s="$samples" -v t="$tiles" -v o="$out" -v d="$disk" -v p="$(cat "$peak")" -F': ' '
  /Elapsed/ {w=$2} /User time/ {u=$2} /System time/ {y=$2} /Maximum resident/ {m=$2}
  END {printf "%s: %s samples, %s tiles, wall %s, CPU %.2f s, peak RSS %.1f MB, plan %.2f GB on disk (%.0f bytes a sample), at least %.2f GB at its peak\n", o, s, t, w, u+y, m/1000, d/1e6*1.024, d*1024/s, p/1e6*1.024}' "$out.time"
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
