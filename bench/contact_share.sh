#!/bin/sh
# Alternates two adhesim binaries on the scale pad (scenarios/scale-pad.toml) at one size and
# prints, per run, the contact share of the step (time_contact_solve over assembly +
# factorisation + contact, totals over the steps), the total of the three phases, the Newton
# iterations and the normal force at the end; then the median share and total of each binary.
# Usage: bench/contact_share.sh OLD_BIN NEW_BIN N ROUNDS   (N = 31: 1,024 contact nodes,
#        N = 99: 10,000)
set -u
cd "$(dirname "$0")/.."
old=$1
new=$2
n=$3
rounds=$4
out=${TMPDIR:-/tmp}/contact-share
mkdir -p "$out"
: > "$out/rows"
i=0
while [ "$i" -lt "$rounds" ]; do
    for which in old new; do
        eval bin=\$$which
        RAYON_NUM_THREADS=1 "$bin" run scenarios/scale-pad.toml --set n="$n" \
            --out "$out/$which" -q --overwrite
        python3 - "$out/$which/history.csv" "$which" >> "$out/rows" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))[1:]
total = lambda k: sum(float(r[k]) for r in rows)
a, f, c = total("time_assembly"), total("time_factorisation"), total("time_contact_solve")
newton = sum(int(float(r["newton_iterations"])) for r in rows)
print(sys.argv[2], f"{c / (a + f + c):.4f}", f"{a + f + c:.3f}", newton, rows[-1]["ground.fy"])
PY
        tail -1 "$out/rows"
    done
    i=$((i + 1))
done
python3 - "$out/rows" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
for which in ("old", "new"):
    mine = [r for r in rows if r[0] == which]
    share = statistics.median(float(r[1]) for r in mine)
    total = statistics.median(float(r[2]) for r in mine)
    print(f"{which}: median contact share {100 * share:.1f} %, median assembly + "
          f"factorisation + contact {total:.2f} s over {len(mine)} runs")
PY
