//! Solves fclib problems with adhesim's contact solvers and prints, per file and solver, the
//! error measure (Siconos's relative natural-map error), the iterations and the median time.
//!
//! Usage: fclib-bench [--tol T] [--runs N] [--max-iter N] [--solvers a,b,...] FILE...
//!
//! Solvers: `nsgs-dense` (the stepper's Gauss-Seidel on a dense W,
//! `contact::solver::gauss_seidel::sweep`), `nsgs-blocks` (Gauss-Seidel on W in 3×3 sparse
//! blocks), `newton` (semismooth Newton), `newton-prox` (proximal-point iterations of
//! semismooth Newton), and for global problems only, timed from M and H on: `global-newton`
//! (semismooth Newton on (v, r) with M and H, never forming W) and `global-condensed` (the
//! condensation W = Hᵀ M⁻¹ H block by block of M, then `newton`). Newton solvers stop after
//! at most 2000 iterations whatever `--max-iter` says.
//! For the other solvers global problems are condensed to W = Hᵀ M⁻¹ H first; the
//! condensation is timed apart (column `condense_ms`) and not included in their times. Every
//! solver starts from r = 0.
//! Output: one CSV line per file and solver.

use std::process::ExitCode;
use std::time::Instant;

use adhesim::contact::detect::ContactPoint;
use adhesim::contact::history::PointHistory;
use adhesim::contact::law::InterfaceLaw;
use adhesim::contact::solver::gauss_seidel::delassus::Delassus;
use adhesim::contact::solver::gauss_seidel::reduced::gauss_seidel_blocks;
use adhesim::contact::solver::gauss_seidel::sweep::gauss_seidel;
use adhesim::contact::solver::reduced::{error_of, ReducedSolution};
use adhesim::contact::solver::semismooth::reduced::{proximal_newton, semismooth_newton};
use adhesim_fclib::{read, solve_global, Problem, ReducedProblem};

const SOLVERS: [&str; 6] = [
    "nsgs-dense",
    "nsgs-blocks",
    "newton",
    "newton-prox",
    "global-newton",
    "global-condensed",
];
/// Default largest number of iterations (Gauss-Seidel sweeps; Newton steps plus fallback
/// sweeps).
const MAX_ITER: usize = 100_000;
/// Largest number of iterations of the Newton solvers (each costs a sparse factorisation).
const MAX_NEWTON: usize = 2_000;
/// No further repetition once one run took this long [s].
const LONG_RUN: f64 = 5.0;

struct Options {
    tol: f64,
    runs: usize,
    max_iter: usize,
    solvers: Vec<String>,
    files: Vec<String>,
}

fn parse_args() -> Result<Options, String> {
    let mut o = Options {
        tol: 1e-8,
        runs: 5,
        max_iter: MAX_ITER,
        solvers: SOLVERS.iter().map(|s| s.to_string()).collect(),
        files: Vec::new(),
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--tol" => {
                let v = value("--tol")?;
                o.tol = v
                    .parse()
                    .ok()
                    .filter(|t: &f64| *t > 0.0)
                    .ok_or(format!("--tol {v}: a positive number expected"))?;
            }
            "--runs" => {
                let v = value("--runs")?;
                o.runs = v
                    .parse()
                    .ok()
                    .filter(|n: &usize| *n > 0)
                    .ok_or(format!("--runs {v}: a positive integer expected"))?;
            }
            "--max-iter" => {
                let v = value("--max-iter")?;
                o.max_iter = v
                    .parse()
                    .ok()
                    .filter(|n: &usize| *n > 0)
                    .ok_or(format!("--max-iter {v}: a positive integer expected"))?;
            }
            "--solvers" => {
                let v = value("--solvers")?;
                o.solvers = v.split(',').map(str::to_string).collect();
                if let Some(bad) = o.solvers.iter().find(|s| !SOLVERS.contains(&s.as_str())) {
                    return Err(format!(
                        "--solvers: unknown solver {bad}; valid: {}",
                        SOLVERS.join(", ")
                    ));
                }
            }
            "-h" | "--help" => {
                return Err(
                    "usage: fclib-bench [--tol T] [--runs N] [--max-iter N] [--solvers nsgs-dense,nsgs-blocks,newton,newton-prox,global-newton,global-condensed] FILE..."
                        .into(),
                )
            }
            f if f.starts_with("--") => return Err(format!("unknown option {f}")),
            f => o.files.push(f.to_string()),
        }
    }
    if o.files.is_empty() {
        return Err("no fclib file given".into());
    }
    Ok(o)
}

/// Gauss-Seidel of the stepper (`contact::solver::gauss_seidel::sweep::gauss_seidel`) on a dense
/// W, one sweep per call so that Siconos's error can be checked after each sweep (the warm
/// start carries r).
fn nsgs_dense(p: &ReducedProblem, del: &Delassus, tol: f64, max_iter: usize) -> ReducedSolution {
    let n = p.w.points();
    let points: Vec<ContactPoint> = (0..n)
        .map(|k| ContactPoint {
            pair: k,
            local: k,
            slave: k,
            area: 1.0,
            frame: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            master: Vec::new(),
            master_point_end: [0.0; 3],
            d0: [0.0; 3],
            twins: Vec::new(),
            slave_weights: Vec::new(),
        })
        .collect();
    let laws: Vec<InterfaceLaw> = p.mu.iter().map(|&mu| InterfaceLaw::coulomb(mu)).collect();
    let history0 = vec![PointHistory::default(); n];
    let mut r = vec![[0.0; 3]; n];
    let mut x = vec![[0.0; 3]; n];
    let (mut residual, mut error) = error_of(&p.w, &p.q, &p.mu, &r, &mut x);
    let mut sweeps = 0;
    while error > tol && sweeps < max_iter {
        let sol = gauss_seidel(&points, &laws, &history0, 1.0, del, &p.q, &r, &r, 0.0, 1);
        r = sol.points.iter().map(|s| s.r_dry.into()).collect();
        sweeps += 1;
        (residual, error) = error_of(&p.w, &p.q, &p.mu, &r, &mut x);
    }
    ReducedSolution {
        r,
        x,
        iterations: sweeps,
        residual,
        error,
        converged: error <= tol,
    }
}

fn solve(name: &str, p: &ReducedProblem, del: &Delassus, o: &Options) -> ReducedSolution {
    let r0 = vec![[0.0; 3]; p.w.points()];
    match name {
        "nsgs-dense" => nsgs_dense(p, del, o.tol, o.max_iter),
        "nsgs-blocks" => gauss_seidel_blocks(&p.w, &p.q, &p.mu, &r0, o.tol, o.max_iter),
        "newton" => semismooth_newton(&p.w, &p.q, &p.mu, &r0, o.tol, o.max_iter.min(MAX_NEWTON)).0,
        "newton-prox" => {
            proximal_newton(&p.w, &p.q, &p.mu, &r0, o.tol, o.max_iter.min(MAX_NEWTON)).0
        }
        _ => unreachable!("solver names are checked when parsing; global solvers are run apart"),
    }
}

/// Runs `f` up to `runs` times (once more only while a run takes less than [`LONG_RUN`]);
/// the last result and the wall time of each run [s].
fn timed<T>(runs: usize, mut f: impl FnMut() -> T) -> (T, Vec<f64>) {
    let mut times = Vec::new();
    loop {
        let t = Instant::now();
        let result = f();
        let dt = t.elapsed().as_secs_f64();
        times.push(dt);
        if times.len() >= runs.max(1) || dt > LONG_RUN {
            return (result, times);
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() -> ExitCode {
    let o = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("fclib-bench: {e}");
            return ExitCode::from(2);
        }
    };
    println!("file,kind,contacts,solver,converged,error,iterations,time_ms,runs,condense_ms");
    let mut failed = false;
    for path in &o.files {
        let file = match read(path) {
            Ok(f) => f,
            Err(e) => {
                eprintln!("fclib-bench: {e}");
                failed = true;
                continue;
            }
        };
        let kind = match file.problem {
            Problem::Local(_) => "local",
            Problem::Global(_) => "global",
        };
        let t0 = Instant::now();
        let problem = match ReducedProblem::of_file(&file) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("fclib-bench: {path}: {e}");
                failed = true;
                continue;
            }
        };
        let condense_ms = match file.problem {
            Problem::Global(_) => format!("{:.3}", 1e3 * t0.elapsed().as_secs_f64()),
            Problem::Local(_) => String::new(),
        };
        let name = std::path::Path::new(path)
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.clone());
        let del = Delassus {
            w: problem.dense_w(),
            m: 3 * problem.w.points(),
        };
        for solver in &o.solvers {
            // The global solvers are timed from M and H on: any condensation is in their time,
            // not in the `condense_ms` column.
            let max_newton = o.max_iter.min(MAX_NEWTON);
            let (sol, times, condensed) = if solver.starts_with("global-") {
                let Some(global) = file.global() else {
                    continue;
                };
                let (sol, times) = timed(o.runs, || {
                    if solver == "global-newton" {
                        solve_global(global, o.tol, max_newton)
                    } else {
                        ReducedProblem::condense(global).map(|p| {
                            let r0 = vec![[0.0; 3]; p.w.points()];
                            semismooth_newton(&p.w, &p.q, &p.mu, &r0, o.tol, max_newton).0
                        })
                    }
                });
                (sol, times, "")
            } else {
                let (sol, times) = timed(o.runs, || solve(solver, &problem, &del, &o));
                (Ok(sol), times, condense_ms.as_str())
            };
            match sol {
                Ok(sol) => println!(
                    "{name},{kind},{},{solver},{},{:.3e},{},{:.4},{},{condensed}",
                    file.contacts(),
                    sol.converged,
                    sol.error,
                    sol.iterations,
                    1e3 * median(times.clone()),
                    times.len()
                ),
                Err(e) => {
                    eprintln!("fclib-bench: {path}: {solver}: {e}");
                    failed = true;
                }
            }
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
