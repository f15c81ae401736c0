#!/bin/sh
# Runs the coarse variants of the paper's four examples, two Newton-contact runs, the PDMS
# pull-off and the cantilever with the `adhesim` binary BIN into OUT, so that two builds can
# be compared with bench/compare_histories.py (a refactoring must leave them unchanged).
# Usage: bench/same_history.sh BIN OUT
set -u
cd "$(dirname "$0")/.."
bin=$1
out=$2
mkdir -p "$out"
for s in indentation plate-on-cylinder rolling-wheel twist-3d; do
    "$bin" run scenarios/paper/$s.toml --variant coarse --out "$out/$s" -q --overwrite
done
"$bin" run scenarios/paper/indentation.toml --variant coarse --set time.contact_solver=newton \
    --out "$out/indentation-newton" -q --overwrite
# Stops early (the Newton contact solve's stick-slip limit): compared up to there.
"$bin" run scenarios/paper/plate-on-cylinder.toml --variant coarse --set time.contact_solver=newton \
    --set mu=0.4 --set v_descent=1.0 --out "$out/plate-on-cylinder-newton" -q --overwrite
"$bin" run scenarios/soft/pdms-pull-off.toml --out "$out/pdms" -q --overwrite
"$bin" run scenarios/cantilever.toml --out "$out/cantilever" -q --overwrite
exit 0
