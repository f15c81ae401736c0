#!/usr/bin/python3
"""Solves fclib problems with Siconos's frictional contact solvers (Debian's python3-siconos)
and prints one CSV line per file and solver, in the columns of adhesim's fclib-bench.

For the local solvers (fc3d_driver), global problems are condensed to W = H^T M^-1 H,
q = H^T M^-1 f + w (not timed). W is given to Siconos in its 3x3 sparse-block storage.
Global problems are also solved in their global form by Siconos's global solvers
(gfc3d_driver, names "siconos-global-..."), M and H given as sparse matrices, timed from M and
H on (the "_WR" solvers condense inside the timed call); each runs in a child process with a
time limit, since some of them crash (a crash or a timeout is reported as not converged, with
the time limit as its time). Every solver starts from r = 0. The error printed is computed
here from r alone, the same way as adhesim's: ||F_nat(r)|| / max(||q||, ||r||, ||u||) with
F_nat(r) = r - P_K(r - (u + mu ||u_T|| N)), u = W r + q, contact by contact.

Usage: siconos_bench.py [--tol T] [--runs N] [--max-iter N] [--global-timeout S] FILE...
"""
import subprocess
import sys
import time
import warnings

import h5py
import numpy as np
import scipy.sparse as sp

warnings.simplefilter("ignore")
import siconos.numerics as sn  # noqa: E402

LONG_RUN = 5.0  # s: no further repetition once one run took this long


def sparse(g):
    m, n, nz = int(g["m"][0]), int(g["n"][0]), int(g["nz"][0])
    p, i, x = g["p"][()], g["i"][()], g["x"][()]
    if nz == -1:
        return sp.csc_matrix((x[: p[n]], i[: p[n]], p[: n + 1]), shape=(m, n))
    if nz == -2:
        return sp.csr_matrix((x[: p[m]], i[: p[m]], p[: m + 1]), shape=(m, n)).tocsc()
    return sp.coo_matrix((x[:nz], (i[:nz], p[:nz])), shape=(m, n)).tocsc()


def load(path):
    f = h5py.File(path, "r")
    if "fclib_local" in f:
        g = f["fclib_local"]
        return "local", sparse(g["W"]), g["vectors/q"][()], g["vectors/mu"][()], None
    g = f["fclib_global"]
    t0 = time.perf_counter()
    M = sparse(g["M"]).toarray()
    H = sparse(g["H"]).toarray()
    mu = g["vectors/mu"][()]
    Minv_H = np.linalg.solve(M, H)
    W = H.T @ Minv_H
    W = 0.5 * (W + W.T)
    q = H.T @ np.linalg.solve(M, g["vectors/f"][()]) + g["vectors/w"][()]
    condense_ms = 1e3 * (time.perf_counter() - t0)
    return "global", sp.csc_matrix(W), q, mu, condense_ms


def project_cone(v, mu):
    """Projection of (N, T1, T2) onto {r_N >= 0, ||r_T|| <= mu r_N}."""
    n, t = v[0], np.hypot(v[1], v[2])
    if mu * t <= -n:
        return np.zeros(3)
    if t <= mu * n:
        return v.copy()
    rn = (n + mu * t) / (1.0 + mu * mu)
    return np.array([rn, mu * rn * v[1] / t, mu * rn * v[2] / t])


def error(W, q, mu, r):
    u = W @ r + q
    s = 0.0
    for c in range(len(mu)):
        rc, uc = r[3 * c : 3 * c + 3], u[3 * c : 3 * c + 3]
        uhat = uc.copy()
        uhat[0] += mu[c] * np.hypot(uc[1], uc[2])
        fc = rc - project_cone(rc - uhat, mu[c])
        s += fc @ fc
    scale = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    return np.sqrt(s) / scale if scale > 0 else np.sqrt(s)


def options(name, tol, max_iter):
    ids = {
        "siconos-nsgs": sn.SICONOS_FRICTION_3D_NSGS,
        "siconos-nsgs-ac": sn.SICONOS_FRICTION_3D_NSGS,
        "siconos-nsn-ac": sn.SICONOS_FRICTION_3D_NSN_AC,
        "siconos-prox": sn.SICONOS_FRICTION_3D_PROX,
        "siconos-vi-eg": sn.SICONOS_FRICTION_3D_VI_EG,
    }
    so = sn.SolverOptions(ids[name])
    so.dparam[sn.SICONOS_DPARAM_TOL] = tol
    so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
    if name == "siconos-nsgs-ac":
        # NSGS with the local Alart-Curnier nonsmooth Newton solver.
        sn.solver_options_update_internal(so, 0, sn.SICONOS_FRICTION_3D_ONECONTACT_NSN)
    return so


SOLVERS = ["siconos-nsgs", "siconos-nsgs-ac", "siconos-nsn-ac", "siconos-prox", "siconos-vi-eg"]

# Siconos's global solvers that converge on at least one of the global files at 1e-8. Left
# out: NSGS, VI_EG and VI_FPP (no convergence on any file within 20,000 iterations), IPM (its
# 4.4 build reports success with a condensed error of 1e-2), ACLMFP (1.9 s on 4 contacts, over
# 2 minutes on 256), NSGSV_WR (exits with an error on every file).
GLOBAL_SOLVERS = {
    "siconos-global-nsgs-wr": "NSGS_WR",
    "siconos-global-nsn-ac": "NSN_AC",
    "siconos-global-nsn-ac-wr": "NSN_AC_WR",
    "siconos-global-prox-wr": "PROX_WR",
    "siconos-global-admm": "ADMM",
    "siconos-global-admm-wr": "ADMM_WR",
}


def int64_csc(a):
    """A scipy matrix in compressed columns with 64-bit indices, as siconos.numerics takes it."""
    a = sp.csc_matrix(a)
    a.indices = a.indices.astype(np.int64)
    a.indptr = a.indptr.astype(np.int64)
    return a


def read_global(path):
    """M, H, f, w and mu of a global file."""
    g = h5py.File(path, "r")["fclib_global"]
    return (int64_csc(sparse(g["M"])), int64_csc(sparse(g["H"])), g["vectors/f"][()],
            g["vectors/w"][()], g["vectors/mu"][()])


def global_problem(M, H, f, w, mu):
    """Siconos's GlobalFrictionContactProblem (M v = q + H r, u = H^T v + b: fclib's f, w)."""
    p = sn.GlobalFrictionContactProblem()
    p.dimension = 3
    p.numberOfContacts = len(mu)
    p.M, p.H, p.q, p.b, p.mu = M, H, f, w, mu
    return p


def timed_runs(runs, prepare, solve):
    """Up to `runs` runs (once more only while a run takes less than LONG_RUN), each
    solve(prepare()) with only solve timed; the last result and each run's time [s]."""
    times = []
    for _ in range(runs):
        args = prepare()
        t0 = time.perf_counter()
        solve(*args)
        times.append(time.perf_counter() - t0)
        if times[-1] > LONG_RUN:
            break
    return args, times


def csv_line(path, kind, contacts, solver, converged, err, iters, time_ms, runs, condense_ms=""):
    """One line of the CSV this script prints."""
    name = path.rsplit("/", 1)[-1]
    return (f"{name},{kind},{contacts},{solver},{str(bool(converged)).lower()},{err:.3e},"
            f"{iters},{time_ms:.4f},{runs},{condense_ms}")


def run_global_child(path, solver, tol, runs, max_iter):
    """One global solver on one file, in this (child) process: prints its CSV line."""
    kind, Wc, q, mu, _ = load(path)
    data = read_global(path)
    n, m = data[0].shape[0], 3 * len(mu)

    def prepare():
        # A fresh problem for every run: the "_WR" solvers crash (SIGFPE) when a problem is
        # solved a second time.
        so = sn.SolverOptions(getattr(sn, "SICONOS_GLOBAL_FRICTION_3D_" + GLOBAL_SOLVERS[solver]))
        so.dparam[sn.SICONOS_DPARAM_TOL] = tol
        so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
        return global_problem(*data), np.zeros(m), np.zeros(m), np.zeros(n), so

    (_, r, _, _, so), times = timed_runs(runs, prepare, sn.gfc3d_driver)
    err = error(Wc, q, mu, r)
    iters = so.iparam[sn.SICONOS_IPARAM_ITER_DONE]
    print(csv_line(path, kind, len(mu), solver, err <= tol, err, iters,
                   1e3 * float(np.median(times)), len(times)), flush=True)


def run_global(path, contacts, solver, tol, runs, max_iter, timeout):
    """A global solver in a child process; a crash or a timeout is a line 'not converged'."""
    args = [sys.executable, __file__, "--tol", str(tol), "--runs", str(runs), "--max-iter",
            str(max_iter), "--global-child", solver, path]
    try:
        out = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
        line = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else ""
        if out.returncode == 0 and line.count(",") == 9:
            print(line, flush=True)
            return
        why = f"exit status {out.returncode}"
    except subprocess.TimeoutExpired:
        why = f"over {timeout} s"
    print(f"{path}: {solver}: {why}", file=sys.stderr)
    print(csv_line(path, "global", contacts, solver, False, float("nan"), 0, 1e3 * timeout, 0),
          flush=True)


def main(argv):
    tol, runs, max_iter, files = 1e-8, 5, 100_000, []
    child, timeout = None, 60.0
    it = iter(argv)
    for a in it:
        if a == "--global-child":
            child = next(it)
        elif a == "--global-timeout":
            timeout = float(next(it))
        elif a == "--tol":
            tol = float(next(it))
        elif a == "--runs":
            runs = int(next(it))
        elif a == "--max-iter":
            max_iter = int(next(it))
        else:
            files.append(a)
    if child is not None:
        run_global_child(files[0], child, tol, runs, max_iter)
        return
    print("file,kind,contacts,solver,converged,error,iterations,time_ms,runs,condense_ms")
    for path in files:
        kind, Wc, q, mu, condense_ms = load(path)
        m = Wc.shape[0]
        Wc = int64_csc(Wc)
        info, sbm = sn.SBM_from_csparse(3, Wc)
        if info != 0:
            sys.exit(f"{path}: W cannot be stored in 3x3 blocks")
        Wsbm = sn.NM_new_SBM(m, m, sbm)
        problem = sn.FrictionContactProblem(3, Wsbm, q, mu)
        cm = "" if condense_ms is None else f"{condense_ms:.3f}"
        for solver in SOLVERS:
            def prepare():
                return problem, np.zeros(m), np.zeros(m), options(solver, tol, max_iter)

            (_, r, _, so), times = timed_runs(runs, prepare, sn.fc3d_driver)
            err = error(Wc, q, mu, r)
            iters = so.iparam[sn.SICONOS_IPARAM_ITER_DONE]
            print(csv_line(path, kind, len(mu), solver, err <= tol, err, iters,
                           1e3 * float(np.median(times)), len(times), cm), flush=True)
        if kind == "global":
            for solver in GLOBAL_SOLVERS:
                run_global(path, len(mu), solver, tol, runs, max_iter, timeout)


if __name__ == "__main__":
    main(sys.argv[1:])
