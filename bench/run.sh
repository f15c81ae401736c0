#!/usr/bin/env bash
# Builds bench_core and the CHOLMOD driver, then runs the benchmark and writes
# bench/results.md. Extra arguments are passed to bench_core (see --help).
#
# Environment:
#   SIZES=20,30,40   cube meshes n³ (QUICK=1 sets 20,30)
#   REPS=5           timed repetitions per measurement (after one warm-up)
#   THREADS=1,2      thread counts
#   BLAS=openblas    BLAS used by CHOLMOD: openblas (libopenblas0-pthread) or system
#                    (whatever libblas.so.3 points to; Debian's default is the reference BLAS)
#   DENSE=3000       size of the dense-kernel diagnostic (0 skips it)
#   RESULTS=bench/results.md
set -euo pipefail

bench_dir=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$bench_dir")

if [[ "${QUICK:-0}" == 1 ]]; then
  sizes=${SIZES:-20,30}
else
  sizes=${SIZES:-20,30,40}
fi
reps=${REPS:-5}
threads=${THREADS:-1,2}
blas=${BLAS:-openblas}
results=${RESULTS:-$bench_dir/results.md}

cargo build --release --quiet --example bench_core --manifest-path "$root/Cargo.toml"
target_dir=$(cargo metadata --format-version 1 --no-deps --manifest-path "$root/Cargo.toml" |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
bench_core="$target_dir/release/examples/bench_core"

cholmod_args=()
if [[ -f /usr/include/suitesparse/cholmod.h ]]; then
  make --quiet -C "$bench_dir/cholmod"
  cholmod_args=(--cholmod "$bench_dir/cholmod/cholmod_bench")
  case "$blas" in
    openblas)
      openblas_dir=/usr/lib/x86_64-linux-gnu/openblas-pthread
      if [[ -e "$openblas_dir/libblas.so.3" ]]; then
        export LD_LIBRARY_PATH="$openblas_dir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
      else
        echo "run.sh: $openblas_dir not found (apt-get install libopenblas0-pthread);" \
          "CHOLMOD uses the system BLAS" >&2
      fi
      ;;
    system) ;;
    *)
      echo "run.sh: BLAS must be openblas or system" >&2
      exit 2
      ;;
  esac
else
  echo "run.sh: CHOLMOD headers not found (apt-get install libsuitesparse-dev libmetis-dev);" \
    "measuring faer only" >&2
fi

"$bench_core" --sizes "$sizes" --reps "$reps" --threads "$threads" \
  --dense "${DENSE:-3000}" "${cholmod_args[@]}" --results "$results" "$@"
