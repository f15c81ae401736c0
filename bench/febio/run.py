#!/usr/bin/env python3
"""Runs adhesim and FEBio 4 on the same problems in alternation and writes bench/febio.md.

  run.py --febio PATH/febio4 [--sizes 9,31,99] [--mus 0,0.3] [--reps 3] [--threads 2]
  run.py --report-only

For each size and friction coefficient, `--reps` pairs of runs: adhesim then FEBio on even
repetitions, FEBio then adhesim on odd ones, each under `/usr/bin/time -v` with the same
number of threads (RAYON_NUM_THREADS for adhesim; OMP_NUM_THREADS and MKL_NUM_THREADS for
FEBio). One JSON line per run goes to results.jsonl beside this script (wall and CPU time,
peak memory, Newton iterations, factorisations, the force on the pad's top at each step);
the report gives medians and the adhesim/FEBio ratios taken pair by pair.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE.parent / "scale"))
from results import read_history, read_time_v_full  # noqa: E402

RESULTS = HERE / "results.jsonl"
REPORT = HERE.parent / "febio.md"


def timed(cmd, cwd, env_extra, time_file, log_file):
    """Runs cmd under /usr/bin/time -v; returns its exit code."""
    env = dict(os.environ, **env_extra)
    with open(log_file, "w") as log:
        return subprocess.run(["/usr/bin/time", "-v", "-o", str(time_file)] + cmd, cwd=cwd,
                              env=env, stdout=log, stderr=subprocess.STDOUT).returncode


def git_commit():
    r = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                       text=True)
    return r.stdout.strip()


# The history.csv column of the force on the pushed top face, per problem.
TOP_FORCE = {"pad": "pad.top.Fy", "blocks": "pad.top.Fy", "hertz": "cap.top.Fy"}

# Base elements per side for the pad's n in problem 2 (faces about 1.3 times the pad's).
BASE_DIVISIONS = {9: 8, 31: 29, 99: 91}


# Problem 3's mesh (one size) and its load, as bench/febio/hertz.toml has them.
HERTZ_MESH = ROOT / "crates/adhesim/tests/data/hertz-hemisphere-tet4.msh"
HERTZ_LOAD = ["--depth", "2e-6", "--increments", "2"]


def sizes(problem, n):
    """The size parameters of `problem` at the pad's `n`: [(name, value)]."""
    if problem == "hertz":
        return []
    return [("n", n)] + ([("m", BASE_DIVISIONS[n])] if problem == "blocks" else [])


def hertz_quarter_force(young=2.6e6, poisson=0.3, radius=5e-3, depth=2e-6):
    """Hertz's force [N] on the quarter sphere of problem 3: 4/3 E* sqrt(R) d^(3/2) / 4."""
    e_star = young / (1.0 - poisson ** 2)
    return e_star * radius ** 0.5 * depth ** 1.5 / 3.0


def adhesim_run(a, problem, n, mu, work):
    out = work / f"adhesim-{problem}-n{n}-mu{mu}"
    sets = [f"{k}={v}" for k, v in sizes(problem, n)] + [f"mu={mu}"] + a.adhesim_set
    cmd = [str(a.adhesim), "run", str(HERE / f"{problem}.toml"), "--out", str(out), "-q",
           "--overwrite"]
    for item in sets:
        cmd += ["--set", item]
    code = timed(cmd, ROOT, {"RAYON_NUM_THREADS": str(a.threads)}, work / "adhesim.time",
                 work / "adhesim.log")
    wall, rss, cpu = read_time_v_full(work / "adhesim.time")
    rows = read_history(out / "history.csv") if code == 0 else []
    phases = {k: sum(r.get(f"time_{k}", 0.0) for r in rows)
              for k in ("assembly", "factorisation", "contact_solve", "detection")}
    return {"tool": "adhesim", "commit": git_commit(), "exit": code, "wall": wall, "cpu": cpu,
            "rss_kb": rss, "steps": len(rows),
            "newton": int(sum(r["newton_iterations"] for r in rows)),
            "factorisations": int(sum(r["factorisations"] for r in rows)),
            "phases": phases, "forces": [[r["t"], r[TOP_FORCE[problem]]] for r in rows]}


def febio_log_totals(path):
    """Iterations, reformations, steps and the linear solver's time from FEBio's .log."""
    keys = {"Number of time steps completed": "steps",
            "Total number of equilibrium iterations": "newton",
            "Total number of stiffness reformations": "factorisations",
            "time in linear solver": "linear_solver_s"}
    out, normal = {}, False
    for line in Path(path).read_text(errors="replace").splitlines():
        for key, name in keys.items():
            if key in line and ":" in line:
                value = line.rsplit(":", 1)[1].strip()
                if name == "linear_solver_s":
                    value = value.split("(")[-1].split()[0]
                    out[name] = float(value)
                else:
                    out[name] = int(value)
        normal = normal or "N O R M A L   T E R M I N A T I O N" in line
    out["normal_termination"] = normal
    return out


def febio_forces(path):
    """[t, sum of Ry] per time of a node_data logfile."""
    forces, t, total = [], None, 0.0
    for line in Path(path).read_text().splitlines():
        if line.startswith("*Time"):
            if t is not None:
                forces.append([t, total])
            t, total = float(line.split("=")[1]), 0.0
        elif line and line[0].isdigit():
            total += float(line.split(",")[1])
    if t is not None:
        forces.append([t, total])
    return forces


def febio_run(a, problem, n, mu, work):
    deck = work / f"febio-{problem}-n{n}-mu{mu}" / "pad.feb"
    deck.parent.mkdir(parents=True, exist_ok=True)
    size_args = [arg for k, v in sizes(problem, n) for arg in (f"--{k}", str(v))]
    if problem == "hertz":
        size_args += ["--msh", str(HERTZ_MESH)] + HERTZ_LOAD
    subprocess.run([sys.executable, str(HERE / "feb.py"), problem] + size_args
                   + ["--mu", str(mu), str(deck)], check=True)
    for stale in ("pad.log", "top_reaction.txt", "pad.xplt"):
        (deck.parent / stale).unlink(missing_ok=True)
    threads = {"OMP_NUM_THREADS": str(a.threads), "MKL_NUM_THREADS": str(a.threads)}
    code = timed([str(a.febio), "-i", "pad.feb", "-silent"], deck.parent, threads,
                 work / "febio.time", work / "febio.stdout")
    wall, rss, cpu = read_time_v_full(work / "febio.time")
    record = {"tool": "febio", "exit": code, "wall": wall, "cpu": cpu, "rss_kb": rss}
    if (deck.parent / "pad.log").exists():
        record.update(febio_log_totals(deck.parent / "pad.log"))
    if (deck.parent / "top_reaction.txt").exists():
        record["forces"] = febio_forces(deck.parent / "top_reaction.txt")
    return record


def run_all(a):
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    for problem in a.problems:
        for n in (a.sizes if problem != "hertz" else [0]):
            for mu in a.mus:
                for rep in range(a.reps):
                    run_pair(a, problem, n, mu, rep, work)


def run_pair(a, problem, n, mu, rep, work):
    """One adhesim run and one FEBio run, in an order that alternates with `rep`."""
    order = (adhesim_run, febio_run) if rep % 2 == 0 else (febio_run, adhesim_run)
    pair = f"{time.time():.0f}-{problem}-{n}-{mu}-{rep}"
    for run in order:
        record = run(a, problem, n, mu, work)
        record.update({"problem": problem, "n": n, "mu": mu, "threads": a.threads,
                       "pair": pair, "load": os.getloadavg()[0],
                       "adhesim_set": a.adhesim_set})
        with open(a.results, "a") as f:
            f.write(json.dumps(record) + "\n")
        print(f"{problem} n={n} mu={mu} rep={rep} {record['tool']}: exit {record['exit']}, "
              f"wall {record['wall']:.2f} s, cpu {record['cpu']:.2f} s, "
              f"{record['rss_kb'] / 1e6:.2f} GB, force "
              f"{record.get('forces', [[0, float('nan')]])[-1][1]:.6g} N", flush=True)


def load_records(path):
    path = Path(path)
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def pair_ratios(records, key):
    by_pair = {}
    for r in records:
        by_pair.setdefault(r["pair"], {})[r["tool"]] = r
    return [p["adhesim"][key] / p["febio"][key] for p in by_pair.values()
            if "adhesim" in p and "febio" in p and p["febio"][key]]


def contact_nodes(problem, n):
    """The pad's contact nodes, (n + 1)², or the mesh's name for problem 3."""
    return "tet4 mesh" if problem == "hertz" else f"{(n + 1) ** 2:,}"


def force_difference(adh, feb):
    """Largest ||F_adhesim| − |F_FEBio|| / |F_FEBio| over the times both report (each code
    gives the reaction at the pad's top with its own sign convention)."""
    feb_at = {round(t, 9): abs(f) for t, f in feb}
    diffs = [abs(abs(f) - feb_at[round(t, 9)]) / feb_at[round(t, 9)]
             for t, f in adh if feb_at.get(round(t, 9))]
    return max(diffs) if diffs else float("nan")


def report(a):
    records = [r for r in load_records(a.results) if r["exit"] == 0]
    commit_of_pair = {r["pair"]: r.get("commit", "") for r in records if r["tool"] == "adhesim"}
    groups = {}
    for r in records:
        key = (r.get("problem", "pad"), r["n"], r["mu"], " ".join(r.get("adhesim_set", [])),
               commit_of_pair.get(r["pair"], ""))
        groups.setdefault(key, []).append(r)
    lines = ["# adhesim and FEBio 4 side by side", "",
             f"Written by `bench/febio/run.py` from `bench/febio/results.jsonl` "
             f"(see bench/febio/README.md). Medians over the successful runs; the ratios are "
             f"taken pair by pair (alternating runs) and their median given.", "",
             "| problem | adhesim settings | adhesim commit | contact nodes | μ | pairs | adhesim wall | FEBio wall | wall adhesim/FEBio | "
             "CPU adhesim/FEBio | adhesim memory | FEBio memory | adhesim Newton it. / "
             "factorisations | FEBio iterations / reformations | force at the end adhesim, "
             "FEBio | largest force difference over the steps |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---|---:|"]
    for (problem, n, mu, settings, commit), rs in sorted(groups.items()):
        adh = [r for r in rs if r["tool"] == "adhesim"]
        feb = [r for r in rs if r["tool"] == "febio"]
        if not adh or not feb or "forces" not in feb[-1]:
            continue
        med = lambda xs, k: statistics.median(x[k] for x in xs)  # noqa: E731
        walls, cpus = pair_ratios(rs, "wall"), pair_ratios(rs, "cpu")
        la, lf = adh[-1], feb[-1]
        lines.append(
            f"| {problem} | {settings or 'defaults'} | {commit} | {contact_nodes(problem, n)} | "
            f"{mu:g} | {len(walls)} | {med(adh, 'wall'):.2f} s | "
            f"{med(feb, 'wall'):.2f} s | {statistics.median(walls):.2f} | "
            f"{statistics.median(cpus):.2f} | {med(adh, 'rss_kb') / 1e6:.2f} GB | "
            f"{med(feb, 'rss_kb') / 1e6:.2f} GB | {la['newton']} / {la['factorisations']} | "
            f"{lf.get('newton')} / {lf.get('factorisations')} | {la['forces'][-1][1]:.5g} N, "
            f"{lf['forces'][-1][1]:.5g} N | "
            f"{100 * force_difference(la['forces'], lf['forces']):.2f} % |")
    hertz = [r for r in records if r.get("problem") == "hertz" and "forces" in r]
    if hertz:
        closed = hertz_quarter_force()
        lines += ["", f"Problem 3 against Hertz's force on the quarter sphere, {closed:.5g} N "
                  f"(4/3 E* √R d^(3/2) / 4): " + ", ".join(
                      f"{tool} {abs(rs[-1]['forces'][-1][1]) / closed:.4f}"
                      for tool in ("adhesim", "febio")
                      for rs in [[r for r in hertz if r["tool"] == tool]] if rs) + " of it."]
    Path(a.report).write_text("\n".join(lines) + "\n")
    print(Path(a.report).read_text())


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--febio", default=os.environ.get("FEBIO"))
    p.add_argument("--adhesim", default=str(ROOT / "target" / "release" / "adhesim"))
    p.add_argument("--problems", default="pad,blocks,hertz")
    p.add_argument("--sizes", default="9,31,99")
    p.add_argument("--mus", default="0,0.3")
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--adhesim-set", action="append", default=[],
                   help="an extra --set for adhesim, e.g. time.newton=preconditioned")
    p.add_argument("--work", default=str(ROOT / "out" / "febio-bench"))
    p.add_argument("--report-only", action="store_true")
    p.add_argument("--results", default=str(RESULTS), help="the JSON lines to append to")
    p.add_argument("--report", default=str(REPORT), help="the report to write")
    a = p.parse_args(argv)
    if not a.report_only:
        if not a.febio:
            p.error("--febio PATH (or FEBIO=PATH): the febio4 binary, see bench/febio/README.md")
        a.sizes = [int(s) for s in a.sizes.split(",")]
        a.problems = a.problems.split(",")
        a.mus = [float(m) for m in a.mus.split(",")]
        run_all(a)
    report(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
