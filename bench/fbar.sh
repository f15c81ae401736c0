#!/bin/sh
# F-bar hex8 benchmark: element and assembly cost against the standard hex8 (median of
# repeated runs, one thread), and Newton iterations of the nearly incompressible Hertz
# indentation (nu = 0.4999, one quasi-static step, h = a/4 as in the tests: F-bar hexahedra
# and averaged-nodal-pressure tetrahedra).
# Usage: bench/fbar.sh [n] [reps]   (defaults 30 and 7)
set -eu
cd "$(dirname "$0")/.."
n=${1:-30}
reps=${2:-7}
cargo run --release --quiet --example bench_fbar -- "$n" "$reps"
echo
cargo test --release --quiet -p adhesim --test hertz_sphere nearly_incompressible -- --nocapture 2>&1 \
    | grep "Newton iterations"
