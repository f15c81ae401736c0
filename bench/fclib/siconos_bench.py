#!/usr/bin/python3
"""Solves fclib problems with Siconos's frictional contact solvers (Debian's python3-siconos)
and prints one CSV line per file and solver, in the columns of adhesim's fclib-bench.

Global problems are condensed to W = H^T M^-1 H, q = H^T M^-1 f + w (not timed). W is given to
Siconos in its 3x3 sparse-block storage. Every solver starts from r = 0. The error printed is
computed here, the same way as adhesim's: ||F_nat(r)|| / max(||q||, ||r||, ||u||) with
F_nat(r) = r - P_K(r - (u + mu ||u_T|| N)), u = W r + q, contact by contact.

Usage: siconos_bench.py [--tol T] [--runs N] [--max-iter N] FILE...
"""
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


def main(argv):
    tol, runs, max_iter, files = 1e-8, 5, 100_000, []
    it = iter(argv)
    for a in it:
        if a == "--tol":
            tol = float(next(it))
        elif a == "--runs":
            runs = int(next(it))
        elif a == "--max-iter":
            max_iter = int(next(it))
        else:
            files.append(a)
    print("file,kind,contacts,solver,converged,error,iterations,time_ms,runs,condense_ms")
    for path in files:
        kind, Wc, q, mu, condense_ms = load(path)
        m = Wc.shape[0]
        Wc.indices = Wc.indices.astype(np.int64)
        Wc.indptr = Wc.indptr.astype(np.int64)
        info, sbm = sn.SBM_from_csparse(3, Wc)
        if info != 0:
            sys.exit(f"{path}: W cannot be stored in 3x3 blocks")
        Wsbm = sn.NM_new_SBM(m, m, sbm)
        problem = sn.FrictionContactProblem(3, Wsbm, q, mu)
        name = path.rsplit("/", 1)[-1]
        for solver in SOLVERS:
            times = []
            for _ in range(runs):
                so = options(solver, tol, max_iter)
                r, u = np.zeros(m), np.zeros(m)
                t0 = time.perf_counter()
                sn.fc3d_driver(problem, r, u, so)
                dt = time.perf_counter() - t0
                times.append(dt)
                if dt > LONG_RUN:
                    break
            err = error(Wc, q, mu, r)
            iters = so.iparam[sn.SICONOS_IPARAM_ITER_DONE]
            cm = "" if condense_ms is None else f"{condense_ms:.3f}"
            print(
                f"{name},{kind},{len(mu)},{solver},{str(bool(err <= tol)).lower()},{err:.3e},"
                f"{iters},{1e3 * float(np.median(times)):.4f},{len(times)},{cm}",
                flush=True,
            )


if __name__ == "__main__":
    main(sys.argv[1:])
