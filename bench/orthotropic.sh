#!/bin/sh
# Runs scenarios/interface/orthotropic-drag.toml at eleven drag directions and draws the
# direction of the friction force against the drag direction with the elliptic cone's closed
# form (docs/images/orthotropic-drag.png), printing the table for docs/examples.md.
# Usage: bench/orthotropic.sh
set -eu
cd "$(dirname "$0")/.."
out=${OUT:-out/orthotropic-drag}
cargo build --release --quiet -p adhesim-cli
cargo build --release --quiet -p adhesim --example orthotropic_figure
args=""
for a in 0 15 30 45 60 70 75 80 84 87 90; do
    ./target/release/adhesim run scenarios/interface/orthotropic-drag.toml --overwrite -q \
        --set drag_angle=$a --out "$out/a$a"
    args="$args $out/a$a=$a"
done
./target/release/examples/orthotropic_figure docs/images/orthotropic-drag.png $args
