#!/bin/sh
# The pressed block of press.toml on hex8 (F-bar) and hex20 (element = "fbar": the volume
# change linear in each element; and standard) meshes of three refinements: the plane's
# force at the end [N]. Needs Python's gmsh package.
# Usage: bench/hex20/run.sh [BIN]   (default target/release/adhesim)
set -eu
cd "$(dirname "$0")/../.."
bin=${1:-target/release/adhesim}
work=$(mktemp -d)
cp bench/hex20/press.toml "$work/"
for level in 0 1 2; do
    for order in 1 2; do
        python3 bench/hex20/box.py "$order" "$level" "$work/box.msh"
        for element in fbar standard; do
            [ "$order" = 1 ] && [ "$element" = standard ] && continue
            "$bin" run "$work/press.toml" --set "body.box.element=$element" \
                --out "$work/out" -q --overwrite
            force=$(python3 -c "import csv; print(list(csv.DictReader(open('$work/out/history.csv')))[-1]['flat.fn'])")
            echo "level $level, order $order, $element: force $force N"
        done
    done
done
rm -r "$work"
