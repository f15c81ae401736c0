#!/usr/bin/env bash
# Scale benchmark: the Blatz-Ko pad of scenarios/scale-pad.toml pressed on a rigid plane,
# solved by adhesim and by CalculiX on the same hex8 mesh, size by size, the two runs
# alternating. Records wall time and peak memory of every run (/usr/bin/time -v), adhesim's
# per-step phase times and Newton iterations (history.csv), the contact force of both at every
# increment; appends one JSON line per run to the data file and writes the report.
# See bench/scale/README.md.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
scenario="$root/scenarios/scale-pad.toml"

sizes="9,31,99,172"
reps=3
large_reps=1
large_from=99
adhesim_max_n=""
ccx_max_n=""
solver=""
label=""
threads=1
timeout_s=0
out="${TMPDIR:-/tmp}/adhesim-scale"
data="$here/results.jsonl"
results="$root/bench/scale.md"
report_only=0
build=1

usage() {
    cat <<USAGE
usage: bench/scale/run.sh [options]
  --sizes N,N,...         elements per side n (contact nodes (n+1)^2) [$sizes]
  --reps R                runs of each program per size [$reps]
  --large-reps R          runs per size from --large-from on [$large_reps]
  --large-from N          [$large_from]
  --adhesim-max-n N       skip adhesim above this n (e.g. a solver that cannot run there)
  --ccx-max-n N           skip CalculiX above this n
  --contact-solver NAME   adhesim contact solver (newton, gauss-seidel): passed as
                          --set contact.ground.contact_solver=NAME (or time.contact_solver)
                          when the scenario format has that key
  --label TEXT            name of the adhesim configuration in the report [the solver name]
  --threads T             threads of both programs (RAYON_NUM_THREADS, OMP_NUM_THREADS) [$threads]
  --timeout S             stop a run after S seconds (0: never) [$timeout_s]
  --out DIR               run directories [$out]
  --data FILE             JSON lines of the runs, appended [$data]
  --results FILE          report [$results]
  --report-only           write the report from the data file and stop
  --no-build              do not run cargo build
USAGE
}

while [ $# -gt 0 ]; do
    case "$1" in
        --sizes) sizes="$2"; shift 2 ;;
        --reps) reps="$2"; shift 2 ;;
        --large-reps) large_reps="$2"; shift 2 ;;
        --large-from) large_from="$2"; shift 2 ;;
        --adhesim-max-n) adhesim_max_n="$2"; shift 2 ;;
        --ccx-max-n) ccx_max_n="$2"; shift 2 ;;
        --contact-solver) solver="$2"; shift 2 ;;
        --label) label="$2"; shift 2 ;;
        --threads) threads="$2"; shift 2 ;;
        --timeout) timeout_s="$2"; shift 2 ;;
        --out) out="$2"; shift 2 ;;
        --data) data="$2"; shift 2 ;;
        --results) results="$2"; shift 2 ;;
        --report-only) report_only=1; shift ;;
        --no-build) build=0; shift ;;
        -h|--help) usage; exit 0 ;;
        *) echo "run.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
    esac
done

report() {
    python3 "$here/report.py" "$data" --results "$results"
    echo "report: $results"
}

if [ "$report_only" = 1 ]; then
    report
    exit 0
fi

for tool in /usr/bin/time ccx python3; do
    if ! command -v "$tool" >/dev/null; then
        echo "run.sh: $tool not found (apt-get install -y time calculix-ccx python3)" >&2
        exit 2
    fi
done

if [ "$build" = 1 ]; then
    (cd "$root" && cargo build --release -p adhesim-cli)
fi
adhesim="$root/target/release/adhesim"
commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"

# The contact solver: a scenario key, if this version of adhesim has one.
solver_args=()
if [ -n "$solver" ]; then
    for key in contact.ground.contact_solver time.contact_solver; do
        if msg="$("$adhesim" check "$scenario" --set "$key=\"$solver\"" 2>&1)"; then
            solver_args=(--set "$key=\"$solver\"")
            break
        elif ! grep -q 'unknown field `contact_solver`' <<< "$msg"; then
            # The key exists but the value (or something else) is refused: say why.
            echo "run.sh: adhesim refuses $key=\"$solver\":" >&2
            echo "$msg" >&2
            exit 2
        fi
    done
    if [ ${#solver_args[@]} -eq 0 ]; then
        echo "run.sh: this adhesim has no contact_solver key; running its only solver" >&2
        label="${label:-default solver (no contact_solver key)}"
    fi
fi
label="${label:-${solver:-default}}"

mkdir -p "$out"
# CalculiX's hyperfoam against the Blatz-Ko closed form (a second, and cheap)
python3 "$here/uniaxial.py" --workdir "$out/uniaxial" > "$here/uniaxial.md" \
    || { echo "run.sh: the CalculiX material check failed, see $here/uniaxial.md" >&2; exit 1; }
limit=()
[ "$timeout_s" != 0 ] && limit=(timeout "$timeout_s")

run_adhesim() { # n rep
    local n=$1 rep=$2 dir="$out/n$1/adhesim_r$2" rc=0
    rm -rf "$dir"
    echo "adhesim n=$n run $rep ($label)"
    env RAYON_NUM_THREADS="$threads" "${limit[@]}" /usr/bin/time -v -o "$dir.time" \
        "$adhesim" run "$scenario" --set "n=$n" "${solver_args[@]}" --quiet --out "$dir" || rc=$?
    python3 "$here/results.py" adhesim "$dir" "$dir.time" --n "$n" --exit "$rc" \
        --threads "$threads" --solver "$label" --commit "$commit" >> "$data" \
        || echo "run.sh: no result from $dir (exit $rc)" >&2
}

run_ccx() { # n rep
    local n=$1 rep=$2 dir="$out/n$1/ccx_r$2" rc=0
    rm -rf "$dir"; mkdir -p "$dir"
    echo "ccx n=$n run $rep"
    python3 "$here/ccx_pad.py" --n "$n" "$dir/pad.inp"
    (cd "$dir" && env OMP_NUM_THREADS="$threads" CCX_NPROC_EQUATION_SOLVER="$threads" \
        CCX_NPROC_RESULTS="$threads" CCX_NPROC_STIFFNESS="$threads" \
        "${limit[@]}" /usr/bin/time -v -o "$dir.time" ccx pad > pad.log 2>&1) || rc=$?
    python3 "$here/results.py" ccx "$dir/pad" "$dir.time" --n "$n" --exit "$rc" \
        --threads "$threads" >> "$data" || echo "run.sh: no result from $dir (exit $rc)" >&2
    rm -f "$dir/pad.frd"   # results are in the .dat; the frd of a large mesh is big
}

IFS=, read -r -a size_list <<< "$sizes"
for n in "${size_list[@]}"; do
    mkdir -p "$out/n$n"
    r=$reps
    [ "$n" -ge "$large_from" ] && r=$large_reps
    for ((rep = 1; rep <= r; rep++)); do
        if [ -z "$adhesim_max_n" ] || [ "$n" -le "$adhesim_max_n" ]; then
            run_adhesim "$n" "$rep"
        fi
        if [ -z "$ccx_max_n" ] || [ "$n" -le "$ccx_max_n" ]; then
            run_ccx "$n" "$rep"
        fi
    done
done
report
