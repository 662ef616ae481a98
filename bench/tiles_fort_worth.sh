#!/usr/bin/env bash
# Tiled build of examples/fort-worth-1m on 2 parallel workers against the one-piece build with
# the same outputs (dsm.vtu, dsm.tif, dsm.asc; no pictures, no report) and the same variogram
# file. Wall time and the peak RSS of each process from /usr/bin/time -v.
#   bench/tiles_fort_worth.sh [TILE_SIZE] [OUT_DIR]
# ONE_PIECE=0 skips the one-piece build (per-tile figures only, e.g. at other tile sizes).
# The machine's load (`uptime`) is printed before and after: ratios measured under load.
# Needs ../shared/data/grids/fort-worth-3arcsec.tif and target/release/terramesh (or BIN=path).
set -euo pipefail
cd "$(dirname "$0")/.."
size=${1:-10km}
out=${2:-bench-out/tiles}
bin=${BIN:-target/release/terramesh}
ex=examples/fort-worth-1m/terramesh.toml
rm -rf "$out" && mkdir -p "$out"
peak() { awk -F': ' '/Maximum resident/ {print $2}' "$1"; }
wall() { awk -F': ' '/Elapsed \(wall/ {print $2}' "$1"; }
echo "load before: $(uptime)"
t0=$(date +%s.%N)
/usr/bin/time -v -o "$out/plan.time" $bin tiles plan $ex --tile-size "$size" -o "$out/plan" --quiet
ids=$(python3 -c "import json,sys; print(' '.join(t['id'] for t in json.load(open(sys.argv[1]))['tiles']))" "$out/plan/tiles.json")
# Two workers: each takes the next tile until none is left.
printf '%s\n' $ids | xargs -P 2 -I{} /usr/bin/time -v -o "$out/tile-{}.time" $bin tiles build "$out/plan" --tile {} >/dev/null
/usr/bin/time -v -o "$out/merge.time" $bin tiles merge "$out/plan" -o "$out/merged" >/dev/null
t1=$(date +%s.%N)
echo "load after the tiled build: $(uptime)"
if [ "${ONE_PIECE:-1}" = 0 ]; then
  echo "tile size $size: $(echo $ids | wc -w) tiles, tiled total $(echo "$t1 - $t0" | bc) s"
  for f in "$out"/plan.time "$out"/tile-*.time "$out"/merge.time; do
    echo "$(basename "$f" .time): $(wall "$f"), peak $(peak "$f") kB"
  done
  exit 0
fi
/usr/bin/time -v -o "$out/one.time" $bin build $ex -o "$out/one" --quiet \
  --set "interpolation.variogram=$PWD/$out/plan/variogram.json" \
  --set 'export.formats=["vtu"]' --set export.pictures=false --set export.report=false
t2=$(date +%s.%N)
echo "load after the one-piece build: $(uptime)"
tiled=$(echo "$t1 - $t0" | bc); one=$(echo "$t2 - $t1" | bc)
maxtile=$(for f in "$out"/tile-*.time; do peak "$f"; done | sort -n | tail -1)
echo "tile size $size: $(echo $ids | wc -w) tiles"
echo "plan: $(wall "$out/plan.time"), peak $(peak "$out/plan.time") kB"
for f in "$out"/tile-*.time; do echo "$(basename "$f" .time): $(wall "$f"), peak $(peak "$f") kB"; done
echo "merge: $(wall "$out/merge.time"), peak $(peak "$out/merge.time") kB"
echo "one-piece: $(wall "$out/one.time"), peak $(peak "$out/one.time") kB"
largest=$(for f in "$out"/plan.time "$out"/tile-*.time "$out"/merge.time; do peak "$f"; done | sort -n | tail -1)
echo "tiled total ${tiled} s vs one-piece ${one} s: time ratio $(echo "scale=3; $tiled / $one" | bc)"
echo "largest tiled process ${largest} kB (largest tile ${maxtile} kB) vs one-piece $(peak "$out/one.time") kB: memory ratio $(echo "scale=3; $largest / $(peak "$out/one.time")" | bc)"
cmp "$out/merged/dsm.tif" "$out/one/dsm.tif" && echo "dsm.tif byte-identical to the one-piece build"
