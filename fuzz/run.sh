#!/usr/bin/env bash
# Fuzzes every cargo-fuzz target (or those named) for SECONDS each, on a nightly toolchain:
#   fuzz/run.sh 20                 # every target, 20 s each (what .ci/run does)
#   fuzz/run.sh 600 wkt geotiff    # two targets, 10 minutes each
# Each run starts from the committed seeds (fuzz/corpus/<target>/, the fixture crops listed in
# crates/terramesh-fuzz/src/lib.rs and the regression inputs) copied into a scratch corpus, so
# the repository is not modified. A crash, a timeout (an input taking over 30 s) or an
# allocation over 4 GiB fails the script and leaves the input in fuzz/artifacts/<target>/:
# fix the bug, then commit the input to fuzz/regressions/<target>/ so that
# `cargo test -p terramesh-fuzz` replays it for ever.
set -euo pipefail
cd "$(dirname "$0")"
secs="${1:?usage: fuzz/run.sh SECONDS [TARGET...]}"
shift
targets=("$@")
if ((${#targets[@]} == 0)); then
  mapfile -t targets < <(sed -n 's/^name = "\(.*\)"$/\1/p' Cargo.toml | grep -v '^terramesh-fuzz-targets$')
fi
seeds_of() { # the fixture crops seeding a target, from FIXTURE_SEEDS in the harness crate
  sed -n "s|^ *(\"$1\", \"\(.*\)\"),\$|\1|p" ../crates/terramesh-fuzz/src/lib.rs
}
# The memory ceiling of terramesh's own size guard (terramesh_core::limits) is lowered to 1 GiB,
# below libFuzzer's 4 GiB malloc limit: an input the guard refuses is an error, as it should
# be, and only an allocation the guard does not see trips the limit.
export TERRAMESH_MAX_MEMORY="${TERRAMESH_MAX_MEMORY:-1GiB}"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
cargo +nightly fuzz build -O
failed=()
for t in "${targets[@]}"; do
  mkdir -p "$scratch/$t" "artifacts/$t"
  cp -r corpus/"$t"/. "$scratch/$t"/ 2>/dev/null || true
  cp -r regressions/"$t"/. "$scratch/$t"/ 2>/dev/null || true
  for f in $(seeds_of "$t"); do cp "../$f" "$scratch/$t/"; done
  rm -f "$scratch/$t/.gitkeep"
  start=$(date +%s)
  # The CPU seconds the target got (the wall-clock seconds overstate it on a loaded machine).
  timer=()
  [ -x /usr/bin/time ] && timer=(/usr/bin/time -f "%U %S" -o "$scratch/$t.cpu")
  if "${timer[@]}" cargo +nightly fuzz run -O "$t" "$scratch/$t" -- -max_total_time="$secs" -timeout=30 \
      -rss_limit_mb=4096 -malloc_limit_mb=4096 -artifact_prefix="artifacts/$t/" \
      -print_final_stats=1 >"$scratch/$t.log" 2>&1; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$scratch/$t.log" | tail -1)
    cpu=$(awk '{printf "%.0f", $1 + $2}' "$scratch/$t.cpu" 2>/dev/null || echo "?")
    echo "fuzz: $t: ${runs:-?} inputs in $(( $(date +%s) - start )) s (${cpu} s of CPU), no crash"
  else
    echo "fuzz: $t: FAILED after $(( $(date +%s) - start )) s; the input is in fuzz/artifacts/$t/:" >&2
    grep -E "ERROR|panicked|SUMMARY|Test unit written" "$scratch/$t.log" | head -8 >&2
    failed+=("$t")
  fi
done
if ((${#failed[@]})); then
  echo "fuzz: ${#failed[@]} target(s) failed: ${failed[*]}" >&2
  exit 1
fi
