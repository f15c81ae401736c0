#!/usr/bin/env bash
# Peak memory of a run against its size: the shipped 3D twist scenario
# (scenarios/paper/twist-3d.toml) on blocks of n × m × n hexes, cut to its first steps (the
# contact face is in contact from the first step, so the Delassus operator of every contact
# node is built), each run under /usr/bin/time -v. Two families: the contact face fixed and
# the block made taller (DOF grow, contact nodes fixed), and the block made wider (both
# grow). Prints one line per run (DOF, contact points, peak RSS) and a least-squares fit
#   RSS ≈ a + b·DOF + c·N_c²
# (N_c contact points; the Delassus operator is a dense 3N_c × 3N_c matrix).
# The blocks: SIZES="n m ..." (default below: a fixed 12 × 12 contact face with 3 to 48
# layers, wider blocks of 3 layers, and cubes). A size already in OUT_DIR/memory.csv is not
# run again; delete that file to measure everything afresh.
# Usage: [SIZES="12 3 24 24"] bench/memory.sh [OUT_DIR]   (default out/bench-memory; the
# default sizes take some 20 minutes on 2 cores, most of it the 48 × 3 × 48 block)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/out/bench-memory}
bin=$root/target/release/adhesim
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
mkdir -p "$out"
table=$out/memory.csv
[ -s "$table" ] || echo "n,m,dof,contact_points,peak_rss_kib,wall_s" >"$table"
# n m: the block's divisions [n, m, n].
sizes=(${SIZES:-12 3 12 12 12 24 12 48 24 3 36 3 48 3 16 16 24 24 32 32})
for ((i = 0; i < ${#sizes[@]}; i += 2)); do
  n=${sizes[i]} m=${sizes[i + 1]}
  if grep -q "^$n,$m," "$table"; then continue; fi
  dir=$out/twist-n$n-m$m
  log=$out/twist-n$n-m$m.time
  /usr/bin/time -v "$bin" run "$root/scenarios/paper/twist-3d.toml" -q --overwrite \
    --set "body.block.mesh.divisions=[$n,$m,$n]" --set time.t_end=3e-4 \
    --set output.figures=false --set 'map=[]' --checkpoint-every 0 --out "$dir" 2>"$log"
  rss=$(awk -F: '/Maximum resident set size/ {gsub(/ /, "", $2); print $2}' "$log")
  wall=$(python3 -c "import json; print(json.load(open('$dir/run.json'))['wall_time'])")
  nodes=$(python3 -c "import json; print(json.load(open('$dir/run.json'))['nodes'])")
  nc=$(python3 - "$dir/history.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print(max(int(float(r["contact_points"])) for r in rows))
PY
)
  echo "$n,$m,$((3 * nodes)),$nc,$rss,$wall" | tee -a "$table"
done
python3 - "$table" <<'PY'
import csv, sys
import numpy as np
rows = list(csv.DictReader(open(sys.argv[1])))
dof = np.array([float(r["dof"]) for r in rows])
nc = np.array([float(r["contact_points"]) for r in rows])
rss = np.array([float(r["peak_rss_kib"]) * 1024 for r in rows])  # bytes
cube = np.array([r["n"] == r["m"] for r in rows])
# Fitted on the blocks of a few layers and the fixed contact face, where the sparse factor's
# fill per DOF hardly changes; the cubes (fill growing with size) are shown against it.
A = np.column_stack([np.ones_like(dof), dof, nc**2])
coef, *_ = np.linalg.lstsq(A[~cube], rss[~cube], rcond=None)
fit = A @ coef
print(f"fit (blocks n x m x n, n != m): RSS = {coef[0]/2**20:.1f} MiB + "
      f"{coef[1]/1024:.2f} KiB x DOF + {coef[2]:.0f} B x N_c^2")
print(f"{'n':>3} {'m':>3} {'DOF':>7} {'N_c':>5} {'RSS MiB':>8} {'fit MiB':>8} {'misfit':>7}")
for r, f, x in zip(rows, fit, rss):
    print(f"{r['n']:>3} {r['m']:>3} {r['dof']:>7} {r['contact_points']:>5} "
          f"{x/2**20:8.1f} {f/2**20:8.1f} {100*(f-x)/x:6.1f}%")
print("the dense Delassus operator W alone: 72 B x N_c^2 (3N_c x 3N_c doubles)")
PY
