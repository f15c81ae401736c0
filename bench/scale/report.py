#!/usr/bin/env python3
"""Writes bench/scale.md from the JSON lines that run.sh appends (one line per run).

Usage: report.py DATA.jsonl [--results bench/scale.md] [--layers 4] [--tol 0.02]

Per size: medians over the runs of wall time and peak memory of each program, their ratio
adhesim/CalculiX, adhesim's median time per step in assembly, factorisation and contact,
Newton iterations, CalculiX's increments and iterations, and the contact force of the two at
every increment both committed (from the most recent run of each).
"""

import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results import compare_forces  # noqa: E402


def fmt_time(s):
    if s is None:
        return "–"
    if s >= 100:
        return f"{s:.0f} s"
    if s >= 1:
        return f"{s:.2f} s"
    return f"{1000 * s:.1f} ms"


def fmt_mem(kb):
    if kb is None:
        return "–"
    return f"{kb / 1024 ** 2:.2f} GB" if kb >= 1024 ** 2 / 10 else f"{kb / 1024:.0f} MB"


def median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def ok(rec):
    return rec.get("exit") == 0 and rec.get("steps", 0) > 0


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("data")
    p.add_argument("--results", default="bench/scale.md")
    p.add_argument("--layers", type=int, default=4, help="element layers of the pad")
    p.add_argument("--tol", type=float, default=0.02)
    a = p.parse_args(argv)
    with open(a.data) as f:
        records = [json.loads(line) for line in f if line.strip()]
    ccx = {}
    adh = {}
    for r in records:
        if r["tool"] == "ccx":
            ccx.setdefault(r["n"], []).append(r)
        else:
            adh.setdefault(r["solver"], {}).setdefault(r["n"], []).append(r)
    sizes = sorted(set(ccx) | {n for by_n in adh.values() for n in by_n})
    nodes = {n: (n + 1) ** 2 for n in sizes}
    dofs = {n: 3 * (n + 1) ** 2 * (a.layers + 1) for n in sizes}
    threads = sorted({r.get("threads") for r in records if r.get("threads") is not None})
    loads = [r["load"][0] for r in records if r.get("load")]

    o = []
    w = o.append
    w("# Scale benchmark: adhesim and CalculiX on a pad pressed on a rigid plane\n")
    w("Written by `bench/scale/run.sh` (see `bench/scale/README.md`) from "
      f"`{os.path.relpath(a.data)}`. The problem: `scenarios/scale-pad.toml`, a Blatz-Ko pad "
      "(G = 1 MPa, 10 × 2 × 10 mm, n × 4 × n hex8) pushed 0.1 mm onto a rigid plane with "
      "friction μ = 0.3 in 5 quasi-static increments; CalculiX 2.20 (`ccx`) solves the same "
      "mesh (`bench/scale/ccx_pad.py`: *HYPERFOAM, N=2 = Blatz-Ko, surface-to-surface penalty "
      "contact with Coulomb friction, rigid plane = a fixed element). "
      f"Threads per program: {', '.join(str(t) for t in threads) or '?'}. "
      + (f"Load average (1 min) at the end of the runs: {min(loads):.1f} to {max(loads):.1f} "
         "on 2 cores, so the wall times carry the noise of a shared machine; the runs "
         "alternate between the two programs so that both see the same load.\n" if loads else "\n"))

    for solver, by_n in adh.items():
        w(f"\n## adhesim: {solver}\n")
        commits = sorted({r.get("commit", "") for rs in by_n.values() for r in rs})
        w(f"adhesim commit(s): {', '.join(commits)}.\n")
        w("\n### Wall time, CPU time and peak memory (medians over the runs)\n")
        w("CPU = user + system time of the process (`/usr/bin/time -v`): on a loaded machine "
          "it is the steadier measure; with one thread it is close to the wall time of an "
          "idle machine.\n")
        w("| contact nodes | n | DOFs | adhesim runs | adhesim wall | adhesim CPU | "
          "adhesim memory | CalculiX runs | CalculiX wall | CalculiX CPU | CalculiX memory | "
          "wall adhesim / CalculiX | CPU adhesim / CalculiX | memory adhesim / CalculiX |")
        w("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for n in sizes:
            ra = [r for r in by_n.get(n, []) if ok(r)]
            rc = [r for r in ccx.get(n, []) if ok(r)]
            if not ra and not rc:
                continue
            wa, ma = median([r["wall"] for r in ra]), median([r["rss_kb"] for r in ra])
            wc, mc = median([r["wall"] for r in rc]), median([r["rss_kb"] for r in rc])
            ca, cc = median([r.get("cpu") for r in ra]), median([r.get("cpu") for r in rc])

            def ratio(x, y):
                return f"{x / y:.2f}" if x and y else "–"

            w(f"| {nodes[n]} | {n} | {dofs[n]} | {len(ra)} | {fmt_time(wa)} | {fmt_time(ca)} | "
              f"{fmt_mem(ma)} | {len(rc)} | {fmt_time(wc)} | {fmt_time(cc)} | {fmt_mem(mc)} | "
              f"{ratio(wa, wc)} | {ratio(ca, cc)} | {ratio(ma, mc)} |")
        failed = [r for rs in by_n.values() for r in rs if not ok(r)]
        if failed:
            w("\nRuns left out (non-zero exit or no committed step): "
              + ", ".join(f"n = {r['n']} (exit {r.get('exit')})" for r in failed) + ".")
        w("\n### adhesim per step (medians over the steps of the most recent run)\n")
        cols = sorted({c for rs in by_n.values() for r in rs for c in r.get("contact_columns", [])})
        w(f"Contact = {' + '.join(f'`{c}`' for c in cols) or 'the contact phases'} of "
          "history.csv; share = contact / (assembly + factorisation + contact), from the "
          "totals over the steps.\n")
        w("| contact nodes | steps | cut-backs | Newton it. (total) | assembly | factorisation "
          "| contact | contact share |")
        w("|---:|---:|---:|---:|---:|---:|---:|---:|")
        for n in sizes:
            ra = [r for r in by_n.get(n, []) if ok(r)]
            if not ra:
                continue
            r = ra[-1]
            m, t = r["step_median"], r["step_total"]
            tot = sum(t.values())
            share = f"{100 * t['contact'] / tot:.0f} %" if tot > 0 else "–"
            w(f"| {nodes[n]} | {r['steps']} | {r['cutbacks']} | {r['newton']} | "
              f"{fmt_time(m['assembly'])} | {fmt_time(m['factorisation'])} | "
              f"{fmt_time(m['contact'])} | {share} |")
        w("\n### Contact force on the pad (most recent run of each)\n")
        w(f"Normal force f_y at every increment both committed; agreement required: "
          f"{100 * a.tol:g} %.\n")
        w("| contact nodes | f_y adhesim at t = 1 | f_y CalculiX at t = 1 | "
          "largest relative difference over the increments | increments compared | within |")
        w("|---:|---:|---:|---:|---:|---|")
        for n in sizes:
            ra = [r for r in by_n.get(n, []) if ok(r)]
            rc = [r for r in ccx.get(n, []) if ok(r)]
            if not ra or not rc:
                continue
            rows = compare_forces(ra[-1]["forces"], rc[-1]["forces"], a.tol)
            if not rows:
                continue
            last = rows[-1]
            worst = max(rows, key=lambda x: abs(x["rel"]))
            w(f"| {nodes[n]} | {last['adhesim'][1]:.5g} N | {last['ccx'][1]:.5g} N | "
              f"{100 * worst['rel']:+.2f} % | {len(rows)} | "
              f"{'yes' if all(x['ok'] for x in rows) else 'NO'} |")

    w("\n## CalculiX runs\n")
    w("| contact nodes | runs | wall (median) | CPU (median) | memory (median) | increments | "
      "cut-backs | iterations | f_y at t = 1 |")
    w("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in sizes:
        rc = [r for r in ccx.get(n, []) if ok(r)]
        if not rc:
            continue
        r = rc[-1]
        fy = [f"{f[2]:.5g} N" for f in r["forces"] if abs(f[0] - 1.0) < 1e-7] or ["–"]
        w(f"| {nodes[n]} | {len(rc)} | {fmt_time(median([x['wall'] for x in rc]))} | "
          f"{fmt_time(median([x.get('cpu') for x in rc]))} | "
          f"{fmt_mem(median([x['rss_kb'] for x in rc]))} | {r['steps']} | {r['cutbacks']} | "
          f"{r['newton']} | {fy[0]} |")
    bad = [r for rs in ccx.values() for r in rs if not ok(r)]
    if bad:
        w("\nCalculiX runs left out: " + ", ".join(
            f"n = {r['n']} (exit {r.get('exit')}, {fmt_time(r.get('wall'))})" for r in bad) + ".")

    notes = os.path.join(os.path.dirname(os.path.abspath(a.data)), "notes.md")
    if os.path.exists(notes):
        w("\n## Notes\n")
        w(open(notes).read().rstrip() + "\n")
    uni = os.path.join(os.path.dirname(os.path.abspath(a.data)), "uniaxial.md")
    if os.path.exists(uni):
        w("\n## Blatz-Ko in CalculiX: one-element uniaxial check (`bench/scale/uniaxial.py`)\n")
        w(open(uni).read().rstrip() + "\n")
    text = "\n".join(o) + "\n"
    while "\n\n\n" in text:
        text = text.replace("\n\n\n", "\n\n")
    with open(a.results, "w") as f:
        f.write(text)


if __name__ == "__main__":
    sys.exit(main())
