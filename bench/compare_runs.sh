#!/usr/bin/env bash
# Runs one scenario with two builds of adhesim in alternation and prints, per run, the wall
# time and the history's phase times (assembly, factorisation, Delassus, contact solve),
# Newton iterations, W builds and cut-backs, then the median wall time of each build and
# their ratio.
# Usage: bench/compare_runs.sh BIN_A BIN_B SCENARIO ROUNDS [adhesim run options...]
set -euo pipefail
a=$1; b=$2; scenario=$3; rounds=$4; shift 4
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for i in $(seq "$rounds"); do
  for side in A B; do
    bin=$a; [[ $side == B ]] && bin=$b
    t0=$(date +%s.%N)
    "$bin" run "$scenario" --out "$out/$side" --overwrite -q "$@" >/dev/null
    t1=$(date +%s.%N)
    python3 - "$out/$side/history.csv" "$side" "$i" "$(awk "BEGIN{print $t1 - $t0}")" <<'PY'
import csv, sys
path, side, rnd, wall = sys.argv[1:]
rows = list(csv.DictReader(open(path)))
s = lambda k: sum(float(r[k]) for r in rows)
print(f"{side} round {rnd}: wall {float(wall):7.1f} s | t = {rows[-1]['t']} in {len(rows) - 1} steps, "
      f"Newton {int(s('newton_iterations'))}, W builds {int(s('delassus_builds'))}, "
      f"cut-backs {int(s('cutbacks'))} | assembly {s('time_assembly'):.1f} s, "
      f"factorisation {s('time_factorisation'):.1f} s, Delassus {s('time_delassus'):.1f} s, "
      f"contact solve {s('time_contact_solve'):.1f} s")
PY
    echo "$side $(awk "BEGIN{print $t1 - $t0}")" >> "$out/walls"
  done
done
python3 - "$out/walls" <<'PY'
import statistics, sys
w = {}
for line in open(sys.argv[1]):
    side, t = line.split()
    w.setdefault(side, []).append(float(t))
ma, mb = statistics.median(w["A"]), statistics.median(w["B"])
print(f"median wall: A {ma:.1f} s, B {mb:.1f} s, B/A = {mb / ma:.2f}")
PY
