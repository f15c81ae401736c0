#!/bin/sh
# Runs scenarios/soft/pdms-pull-off.toml at three pull speeds and draws the pull-off force
# against speed (docs/images/soft-pull-off.png), printing the table for docs/examples.md.
# Usage: bench/pull_off.sh [variant]   (e.g. `coarse`; default: the full scenario)
set -eu
cd "$(dirname "$0")/.."
variant=${1:-}
out=${OUT:-out/pdms-pull-off-speeds}
cargo build --release --quiet -p adhesim-cli
cargo build --release --quiet -p adhesim --example pull_off_figure
args=""
for v in 1e-4 1e-3 1e-2; do
    if [ -n "$variant" ]; then
        /usr/bin/time -f "v_pull = $v: %e s" ./target/release/adhesim run \
            scenarios/soft/pdms-pull-off.toml --variant "$variant" --set v_pull=$v --out "$out/v$v" >/dev/null
    else
        /usr/bin/time -f "v_pull = $v: %e s" ./target/release/adhesim run \
            scenarios/soft/pdms-pull-off.toml --set v_pull=$v --out "$out/v$v" >/dev/null
    fi
    args="$args $out/v$v=$v"
done
./target/release/examples/pull_off_figure docs/images/soft-pull-off.png $args
