#!/usr/bin/env bash
# Runs the paper's four examples at full resolution and their coarse variants, and the
# 25-case study of example 4.3 (coarse) with 1 and 2 workers; prints wall times.
# Usage: bench/examples.sh [OUT_DIR]   (default out/bench-examples)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/out/bench-examples}
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
bin="$root/target/release/adhesim"
mkdir -p "$out"
stamp() { date +%s.%N; }
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
for ex in indentation rolling-wheel plate-on-cylinder twist-3d; do
  for variant in coarse full; do
    args=()
    [[ $variant == coarse ]] && args=(--variant coarse)
    t0=$(stamp)
    "$bin" run "$root/scenarios/paper/$ex.toml" "${args[@]}" --out "$out/$ex-$variant" -q
    t1=$(stamp)
    printf '%-18s %-6s %8.1f s\n' "$ex" "$variant" "$(awk "BEGIN{print $t1 - $t0}")"
  done
done
for jobs in 1 2; do
  t0=$(stamp)
  "$bin" sweep "$root/scenarios/paper/plate-on-cylinder.toml" --variant coarse \
    --set v_descent=1.0,0.8,0.6,0.4,0.2 --set mu=0,0.2,0.4,0.6,0.8 \
    --jobs "$jobs" --out "$out/study-4.3-jobs$jobs" -q
  t1=$(stamp)
  printf '4.3 study (25 coarse cases), %d worker(s): %8.1f s\n' "$jobs" "$(awk "BEGIN{print $t1 - $t0}")"
done
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
