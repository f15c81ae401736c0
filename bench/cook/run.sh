#!/usr/bin/env bash
# Cook's membrane, plane strain, nearly incompressible (E = 250, nu = 0.4999, F = 100), solved
# by CalculiX (ccx 2.20) with 20-node hexahedra on n x n meshes one element thick: prints the
# vertical displacement of the corner (48, 60) (and of the mid-point (48, 52) of the loaded
# edge) per mesh and element type, and their Richardson extrapolations. The reference value of
# crates/adhesim/tests/fbar_locking.rs comes from here; see docs/elements.md.
#
#   bench/cook/run.sh                          # n = 4 ... 128, C3D20R and C3D20 (~35 s, 1 GB)
#   bench/cook/run.sh --sizes "64 128 256" --elements C3D20R    # (256: ~70 s, 4 GB)
#   bench/cook/run.sh --fineale                # the check against FinEALE's value, below
#
# --fineale solves the variant of P. Krysl's FinEALE example Cook_3D_strain (lambda = 7500,
# G = 0.375, total force 1, plane strain), whose script keeps 16.4326 as the converged
# deflection of the mid-point (48, 52) (a Richardson extrapolation of its quadratic triangles):
# an independent check of the geometry, load and constraints of these decks.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
sizes="4 8 16 32 64 128"
elements="C3D20R C3D20"
out="${TMPDIR:-/tmp}/adhesim-cook"
deck_args=()
poisson=0.4999
case_name=cook
title="Cook's membrane, plane strain, E = 250, nu = 0.4999, F = 100"

usage() {
    cat <<USAGE
usage: bench/cook/run.sh [--sizes "N N ..."] [--elements "C3D20R C3D20"] [--out DIR] [--fineale]
  --sizes      elements per side of the n x n meshes [$sizes]
  --elements   ccx element types (20-node hexahedra) [$elements]
  --out        work directory for the decks and ccx output [$out]
  --fineale    lambda = 7500, G = 0.375, F = 1 instead (FinEALE's Cook_3D_strain; sizes
               32 64 128 and C3D20R unless given after this option)
USAGE
}

while [ $# -gt 0 ]; do
    case "$1" in
        --sizes) sizes="$2"; shift 2 ;;
        --elements) elements="$2"; shift 2 ;;
        --out) out="$2"; shift 2 ;;
        --fineale)
            # E = G (3 lambda + 2 G) / (lambda + G), nu = lambda / (2 (lambda + G))
            poisson=0.4999750012499375
            deck_args=(--young 1.124981250937453 --poisson "$poisson" --force 1)
            sizes="32 64 128"; elements="C3D20R"; case_name=fineale
            title="FinEALE's Cook_3D_strain: lambda = 7500, G = 0.375, F = 1"
            title="$title (its converged mid-point deflection: 16.4326)"
            shift ;;
        -h|--help) usage; exit 0 ;;
        *) echo "run.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
    esac
done

if ! command -v ccx >/dev/null; then
    echo "run.sh: ccx not found (Debian: apt-get install calculix-ccx)" >&2
    exit 1
fi
version="$(ccx -v 2>&1 | sed -n 's/.*Version *//p' | head -1 || true)"
title="$title; ccx ${version:-(version not reported)}"
mkdir -p "$out"
runs="$out/runs_$case_name.txt"
: > "$runs"
# One thread: the numbers do not depend on it, and the machine is shared.
export OMP_NUM_THREADS=1 CCX_NPROC_EQUATION_SOLVER=1

for element in $elements; do
    for n in $sizes; do
        job="${case_name}_${element}_$n"
        python3 "$here/cook_ccx.py" deck --n "$n" --element "$element" "${deck_args[@]}" \
            "$out/$job.inp"
        start=$(date +%s.%N)
        if ! (cd "$out" && ccx -i "$job" > "$job.log" 2>&1); then
            echo "run.sh: ccx failed on $job, see $out/$job.log" >&2
            exit 1
        fi
        if grep -q "ERROR" "$out/$job.log"; then
            echo "run.sh: ccx reported an error on $job, see $out/$job.log" >&2
            exit 1
        fi
        end=$(date +%s.%N)
        values=$(python3 "$here/cook_ccx.py" tip "$out/$job.dat")
        read -r tip tip_spread mid mid_spread <<< "$values"
        seconds=$(python3 -c "print(f'{$end - $start:.2f}')")
        echo "$element $n: corner $tip, (48, 52) $mid (spread over z: $tip_spread," \
            "$mid_spread), ${seconds} s" >&2
        echo "$element $n $tip $mid $seconds" >> "$runs"
    done
done

echo
python3 "$here/cook_ccx.py" report --poisson "$poisson" --title "$title" "$runs"
