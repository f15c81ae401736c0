#!/bin/sh
# Runs scenarios/interface/fatigue-pull-off.toml with and without interface fatigue and draws
# the pull-off force against cycle number with the fatigue law's closed form
# (docs/images/interface-fatigue.png), printing the table for docs/examples.md.
# Usage: bench/fatigue.sh
set -eu
cd "$(dirname "$0")/.."
out=${OUT:-out/fatigue-pull-off}
cargo build --release --quiet -p adhesim-cli
cargo build --release --quiet -p adhesim --example fatigue_figure
./target/release/adhesim run scenarios/interface/fatigue-pull-off.toml --overwrite -q \
    --out "$out/fatigue"
./target/release/adhesim run scenarios/interface/fatigue-pull-off.toml --overwrite -q \
    --set fatigue_energy=1e300 --out "$out/none"
./target/release/examples/fatigue_figure docs/images/interface-fatigue.png \
    "$out/fatigue=D_f = 40 J/m²" "$out/none=no fatigue"
