#!/usr/bin/python3
"""Markdown table from the CSV lines of fclib-bench (adhesim) and siconos_bench.py.

Per file and solver: converged in every round or not, the largest error over the rounds, the
iterations of the last round and the median over rounds of the per-round median times.
Two summaries, ratio = adhesim's fastest converged solver / Siconos's fastest converged solver:
- on the condensed problem (W, q; a global file's condensation not timed, on both sides): the
  solvers whose name does not contain "global";
- global files in their global form, timed from M and H on (the solvers named "global"), with
  beside it the ratio to Siconos's fastest on the condensed problem, whose condensation is not
  timed: the reading least favourable to adhesim.
Usage: table.py ADHESIM_CSV SICONOS_CSV
"""
import csv
import statistics
import sys

COLS = ["file", "kind", "contacts", "solver", "converged", "error", "iterations", "time_ms",
        "runs", "condense_ms"]


def load(path):
    rows = {}
    with open(path) as fh:
        for rec in csv.DictReader(fh, fieldnames=COLS):
            key = (rec["file"], rec["solver"])
            rows.setdefault(key, []).append(rec)
    out = {}
    for key, recs in rows.items():
        out[key] = {
            "kind": recs[0]["kind"],
            "contacts": recs[0]["contacts"],
            "converged": all(r["converged"] == "true" for r in recs),
            "error": max(float(r["error"]) for r in recs),
            "iterations": recs[-1]["iterations"],
            "time": statistics.median(float(r["time_ms"]) for r in recs),
            "rounds": len(recs),
        }
    return out


def fmt_time(t):
    return f"{t:.3g}" if t < 1000 else f"{t:,.0f}"


def main(a_path, s_path):
    adh, sic = load(a_path), load(s_path)
    files = sorted({f for f, _ in adh} | {f for f, _ in sic})
    print("| file | contacts | solver | converged | error | iterations | time [ms] |")
    print("|---|---:|---|---|---:|---:|---:|")
    summary = []
    for f in files:
        best = {}
        for side, table in (("adhesim", adh), ("siconos", sic)):
            for (ff, solver), r in sorted(table.items()):
                if ff != f:
                    continue
                err = "–" if r["error"] != r["error"] else f"{r['error']:.1e}"
                print(f"| {f} | {r['contacts']} | {solver} | {'yes' if r['converged'] else 'no'} "
                      f"| {err} | {r['iterations']} | {fmt_time(r['time'])} |")
                form = "global" if "global" in solver else "condensed"
                key = (side, form)
                if r["converged"] and (key not in best or r["time"] < best[key][1]):
                    best[key] = (solver, r["time"])
        kind = next(r["kind"] for t in (adh, sic) for (ff, _), r in t.items() if ff == f)
        summary.append((f, kind, best))

    def txt(b):
        return f"{b[0]} {fmt_time(b[1])} ms" if b else "none converged"

    def ratio(a, s):
        return f"{a[1] / s[1]:.2f}" if a and s else "–"

    print()
    print("On the condensed problem (a global file's condensation not timed, on both sides):")
    print()
    print("| file | adhesim fastest | Siconos fastest | ratio adhesim / Siconos |")
    print("|---|---|---|---:|")
    for f, _, best in summary:
        a, s = best.get(("adhesim", "condensed")), best.get(("siconos", "condensed"))
        print(f"| {f} | {txt(a)} | {txt(s)} | {ratio(a, s)} |")
    print()
    print("Global files in their global form, timed from M and H on, on both sides:")
    print()
    print("| file | adhesim fastest | Siconos fastest | ratio adhesim / Siconos "
          "| ratio to Siconos's fastest on the condensed problem |")
    print("|---|---|---|---:|---:|")
    for f, kind, best in summary:
        if kind != "global":
            continue
        a, s = best.get(("adhesim", "global")), best.get(("siconos", "global"))
        sc = best.get(("siconos", "condensed"))
        print(f"| {f} | {txt(a)} | {txt(s)} | {ratio(a, s)} | {ratio(a, sc)} |")


if __name__ == "__main__":
    main(*sys.argv[1:3])
