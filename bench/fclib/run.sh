#!/usr/bin/env bash
# fclib problems solved by adhesim's contact solvers and by Siconos's, side by side.
#
# Usage: bench/fclib/run.sh [ROUNDS] [RUNS] [MAX_ITER]
#   ROUNDS   rounds over the files (default 3); in each round every file is solved by adhesim
#            then by Siconos, so that both see the same machine load
#   RUNS     repetitions per solver and file within a round, median taken (default 5)
#   MAX_ITER iteration cap of every solver on both sides (default 20000)
# Files: $FCLIB_DIR/*.hdf5 (default ../shared/fclib). Tolerance 1e-8 on Siconos's error.
# Needs Debian's python3-siconos, python3-h5py and python3-scipy, and libhdf5-dev to build.
# Prints the markdown table of bench/fclib.md; raw CSV lines go to target/fclib-bench/.
set -euo pipefail
cd "$(dirname "$0")/../.."
rounds=${1:-3}
runs=${2:-5}
max_iter=${3:-20000}
dir=${FCLIB_DIR:-../shared/fclib}
shopt -s nullglob
files=("$dir"/*.hdf5)
if [ ${#files[@]} -eq 0 ]; then
  echo "no .hdf5 file in $dir (set FCLIB_DIR)" >&2
  exit 1
fi
if ! /usr/bin/python3 -c "import siconos.numerics, h5py, scipy" 2>/dev/null; then
  echo "Siconos is missing: apt-get install -y python3-siconos python3-h5py python3-scipy" >&2
  exit 1
fi
cargo build --release -q -p adhesim-fclib
out=target/fclib-bench
mkdir -p "$out"
rm -f "$out/adhesim.csv" "$out/siconos.csv"
# Siconos's BLAS threads slow it down on a loaded machine; both sides run on one core.
export OPENBLAS_NUM_THREADS=1
for round in $(seq 1 "$rounds"); do
  for f in "${files[@]}"; do
    echo "round $round: $(basename "$f")" >&2
    target/release/fclib-bench --runs "$runs" --max-iter "$max_iter" "$f" | tail -n +2 >>"$out/adhesim.csv"
    /usr/bin/python3 bench/fclib/siconos_bench.py --runs "$runs" --max-iter "$max_iter" "$f" |
      tail -n +2 >>"$out/siconos.csv"
  done
done
/usr/bin/python3 bench/fclib/table.py "$out/adhesim.csv" "$out/siconos.csv"
