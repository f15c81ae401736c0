#!/usr/bin/python3
"""Markdown table from the CSV lines of fclib-bench (adhesim) and siconos_bench.py.

Per file and solver: converged in every round or not, the largest error over the rounds, the
iterations of the last round and the median over rounds of the per-round median times.
Ratio: adhesim's fastest converged solver / Siconos's fastest converged solver.
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
                print(f"| {f} | {r['contacts']} | {solver} | {'yes' if r['converged'] else 'no'} "
                      f"| {r['error']:.1e} | {r['iterations']} | {fmt_time(r['time'])} |")
                if r["converged"] and (side not in best or r["time"] < best[side][1]):
                    best[side] = (solver, r["time"])
        summary.append((f, best))
    print()
    print("| file | adhesim fastest | Siconos fastest | ratio adhesim / Siconos |")
    print("|---|---|---|---:|")
    for f, best in summary:
        a = best.get("adhesim")
        s = best.get("siconos")
        a_txt = f"{a[0]} {fmt_time(a[1])} ms" if a else "none converged"
        s_txt = f"{s[0]} {fmt_time(s[1])} ms" if s else "none converged"
        ratio = f"{a[1] / s[1]:.2f}" if a and s else "–"
        print(f"| {f} | {a_txt} | {s_txt} | {ratio} |")


if __name__ == "__main__":
    main(*sys.argv[1:3])
