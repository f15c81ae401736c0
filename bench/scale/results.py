#!/usr/bin/env python3
"""Reads the outputs of one run of the scale benchmark into a JSON record, and compares the
contact forces of adhesim and CalculiX.

Subcommands (used by run.sh; they can be run by hand):

  results.py adhesim DIR TIME_V_FILE  -- n N --solver LABEL   prints a record of an adhesim run
  results.py ccx JOB TIME_V_FILE -- n N                       prints a record of a ccx run
  results.py compare HISTORY.csv JOB.dat [--pair ground] [--tol 0.02]
                                    compares the forces at every common time (exit 1 if off)

A record holds the wall time and peak memory (from `/usr/bin/time -v`), the steps (increments),
Newton iterations, per-step phase times (adhesim) and the total contact force on the pad at
every committed time.
"""

import argparse
import csv
import json
import re
import statistics
import sys

# history.csv phase columns that are not contact work; every other `time_*` column is
# counted as contact (detection, Delassus operator, contact solve, ...).
NON_CONTACT_PHASES = ("time_assembly", "time_factorisation")


def read_time_v(path):
    """Wall time [s] and peak resident memory [kB] from the report of `/usr/bin/time -v`."""
    wall, rss, _ = read_time_v_full(path)
    return wall, rss


def read_time_v_full(path):
    """Wall time [s], peak resident memory [kB] and CPU time (user + system) [s] from the
    report of `/usr/bin/time -v`."""
    wall, rss, cpu = None, None, 0.0
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line.startswith("Elapsed (wall clock) time"):
                clock = line.split("):", 1)[1].strip() if "):" in line else line.split()[-1]
                parts = [float(p) for p in clock.split(":")]
                wall = 0.0
                for p in parts:
                    wall = wall * 60.0 + p
            elif line.startswith("Maximum resident set size"):
                rss = int(line.split(":")[1])
            elif line.startswith(("User time", "System time")):
                cpu += float(line.split(":")[1])
    return wall, rss, cpu


def read_history(path, pair="ground"):
    """Rows of adhesim's history.csv as dicts of floats (the t = 0 row left out)."""
    with open(path, newline="") as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    return [r for r in rows if r["step"] > 0]


def history_forces(rows, pair="ground"):
    return [[r["t"], r[f"{pair}.fx"], r[f"{pair}.fy"], r[f"{pair}.fz"]] for r in rows]


def ccx_forces(dat_path, node_set="RIGID"):
    """[t, fx, fy, fz] of the `total force` blocks of `node_set` in a ccx .dat file. The
    reaction at the fixed rigid block equals the contact force on the pad."""
    out = []
    head = re.compile(r"total force \(fx,fy,fz\) for set (\S+) and time\s+(\S+)")
    with open(dat_path) as f:
        lines = f.readlines()
    for i, line in enumerate(lines):
        m = head.search(line)
        if m and m.group(1).upper() == node_set:
            for nxt in lines[i + 1:i + 4]:
                if nxt.strip():
                    fx, fy, fz = (float(x) for x in nxt.split()[:3])
                    out.append([float(m.group(2)), fx, fy, fz])
                    break
    return out


def compare_forces(adh, ccx, tol):
    """Relative difference of the normal (y) force at the times both runs committed."""
    rows = []
    for t, *fa in adh:
        match = [fc for tc, *fc in ccx if abs(tc - t) < 1e-7]
        if match:
            fc = match[0]
            rel = (fa[1] - fc[1]) / abs(fc[1]) if fc[1] != 0.0 else float("inf")
            rows.append({"t": t, "adhesim": fa, "ccx": fc, "rel": rel, "ok": abs(rel) <= tol})
    return rows


def load_average():
    try:
        with open("/proc/loadavg") as f:
            return [float(x) for x in f.read().split()[:3]]
    except (OSError, ValueError):
        return None


def adhesim_record(a):
    rows = read_history(f"{a.dir}/history.csv", a.pair)
    wall, rss, cpu = read_time_v_full(a.time_v)
    phases = [c for c in rows[0] if c.startswith("time_")] if rows else []
    contact_cols = [c for c in phases if c not in NON_CONTACT_PHASES]
    per_step = {
        "assembly": [r.get("time_assembly", 0.0) for r in rows],
        "factorisation": [r.get("time_factorisation", 0.0) for r in rows],
        "contact": [sum(r[c] for c in contact_cols) for r in rows],
    }
    try:
        with open(f"{a.dir}/run.json") as f:
            run = json.load(f)
    except (OSError, ValueError):
        run = {}
    return {
        "tool": "adhesim",
        "n": a.n,
        "solver": a.solver,
        "commit": a.commit,
        "threads": a.threads,
        "exit": a.exit,
        "wall": wall,
        "cpu": cpu,
        "rss_kb": rss,
        "steps": len(rows),
        "cutbacks": int(sum(r["cutbacks"] for r in rows)),
        "newton": int(sum(r["newton_iterations"] for r in rows)),
        "contact_columns": contact_cols,
        "step_median": {k: statistics.median(v) if v else None for k, v in per_step.items()},
        "step_total": {k: sum(v) for k, v in per_step.items()},
        "status": run.get("status"),
        "load": load_average(),
        "forces": history_forces(rows, a.pair),
    }


def ccx_record(a):
    wall, rss, cpu = read_time_v_full(a.time_v)
    iterations = attempts = cutbacks = 0
    try:
        with open(f"{a.job}.log") as f:
            for line in f:
                if re.match(r"^ iteration \d+", line):
                    iterations += 1
                elif re.match(r"^ increment \d+ attempt \d+", line):
                    attempts += 1
                elif "the increment is reattempted" in line:
                    cutbacks += 1
    except OSError:
        pass
    forces = ccx_forces(f"{a.job}.dat")
    return {
        "tool": "ccx",
        "n": a.n,
        "threads": a.threads,
        "exit": a.exit,
        "wall": wall,
        "cpu": cpu,
        "rss_kb": rss,
        "steps": len(forces),
        "cutbacks": cutbacks,
        "newton": iterations,
        "load": load_average(),
        "forces": forces,
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    for name in ("adhesim", "ccx"):
        s = sub.add_parser(name)
        s.add_argument("dir" if name == "adhesim" else "job",
                       help="output directory" if name == "adhesim" else "ccx job (path without .inp)")
        s.add_argument("time_v", help="file written by /usr/bin/time -v -o")
        s.add_argument("--n", type=int, required=True)
        s.add_argument("--exit", type=int, default=0)
        s.add_argument("--threads", type=int, default=None)
        if name == "adhesim":
            s.add_argument("--solver", default="default")
            s.add_argument("--commit", default="")
            s.add_argument("--pair", default="ground")
    c = sub.add_parser("compare")
    c.add_argument("history")
    c.add_argument("dat")
    c.add_argument("--pair", default="ground")
    c.add_argument("--tol", type=float, default=0.02)
    a = p.parse_args(argv)
    if a.cmd == "adhesim":
        print(json.dumps(adhesim_record(a)))
    elif a.cmd == "ccx":
        print(json.dumps(ccx_record(a)))
    else:
        rows = compare_forces(history_forces(read_history(a.history), a.pair),
                              ccx_forces(a.dat), a.tol)
        if not rows:
            print("no common times", file=sys.stderr)
            return 1
        print(f"{'t':>6} {'adhesim fy [N]':>15} {'ccx fy [N]':>15} {'rel. diff':>10}")
        for r in rows:
            print(f"{r['t']:6.3f} {r['adhesim'][1]:15.6g} {r['ccx'][1]:15.6g} {100 * r['rel']:9.3f} %")
        return 0 if all(r["ok"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
