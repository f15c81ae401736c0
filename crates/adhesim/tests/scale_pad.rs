//! The scale benchmark's problem (scenarios/scale-pad.toml) at its smallest size, 100 contact
//! nodes, against CalculiX 2.20 on the same hex8 mesh (bench/scale/).
//!
//! The reference forces were computed by `ccx` with the deck of bench/scale/ccx_pad.py
//! (Blatz-Ko as *HYPERFOAM, N=2, surface-to-surface penalty contact with a fixed rigid
//! element as the plane):
//! - frictionless, `ccx_pad.py --n 9 --mu 0 pad.inp` (normal penalty 1e13 Pa/m):
//!   f_y = 15.55931 N at the end of the push;
//! - μ = 0.3, `ccx_pad.py --n 9 --stick-slope 1e12 pad.inp` (tangential penalty 1e12 Pa/m,
//!   ten times the one the benchmark uses): f_y = 16.11847 N.
//!
//! A penalty lets the pad sink into the plane by p/k (1e-8 m here, 1e-4 of the push) and
//! slip elastically by τ/k_t, so CalculiX's force approaches the exact one from below as the
//! penalties grow: with stick slopes 1e9, 1e10, 1e11, 1e12 Pa/m it gives 15.851, 16.065,
//! 16.113, 16.118 N. The tolerances (0.1 % frictionless, 0.2 % with friction) hold that
//! penalty error and the Newton tolerances of both codes (ccx: 5e-3 of the mean force),
//! well below the 3.6 % by which friction raises the force, so the test fails if friction
//! is lost or misapplied.

use adhesim_io::run::{run, Outcome, Silent};
use adhesim_io::scenario::{load_with, LoadOptions, Override};
use std::path::{Path, PathBuf};

fn scenario() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/scale-pad.toml")
}

/// Runs the scenario with `sets` and returns the pad's normal contact force at every step.
fn normal_force(sets: &[&str], tag: &str) -> Vec<(f64, f64)> {
    let options = LoadOptions {
        variant: None,
        overrides: sets.iter().map(|s| Override::parse(s).unwrap()).collect(),
    };
    let problem = load_with(&scenario(), &options).unwrap();
    let out = std::env::temp_dir().join(format!("adhesim-test-scale-pad-{tag}"));
    let summary = run(problem, Some(&scenario()), &out, &mut Silent).unwrap();
    assert_eq!(summary.outcome, Outcome::Finished);
    let (cols, rows) = adhesim_io::output::csv::read_history(out.join("history.csv")).unwrap();
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    let (t, fy) = (col("t"), col("ground.fy"));
    rows.iter().map(|r| (r[t], r[fy])).collect()
}

fn final_force(forces: &[(f64, f64)]) -> f64 {
    let &(t, f) = forces.last().unwrap();
    assert!(
        (t - 1.0).abs() < 1e-12,
        "the run should end at t = 1, not {t}"
    );
    f
}

#[test]
fn frictionless_pad_force_matches_calculix() {
    let f = final_force(&normal_force(&["mu=0"], "frictionless"));
    let reference = 15.55931;
    assert!(
        (f - reference).abs() < 1e-3 * reference,
        "f_y = {f} N, CalculiX {reference} N"
    );
}

#[test]
fn frictional_pad_force_matches_calculix() {
    let forces = normal_force(&[], "frictional");
    assert_eq!(forces.len(), 6, "5 increments and the initial row");
    // The force grows with the push, a little faster than linearly (the pad stiffens in
    // compression).
    for w in forces.windows(2) {
        assert!(w[1].1 > w[0].1);
    }
    let f = final_force(&forces);
    let reference = 16.11847;
    assert!(
        (f - reference).abs() < 2e-3 * reference,
        "f_y = {f} N, CalculiX {reference} N"
    );
}

#[test]
fn mesh_counts_take_whole_expressions_only() {
    // n = 9 gives 9 × 4 × 9 cells through `divisions = ["= n", "= layers", "= n"]`.
    let options = LoadOptions {
        variant: None,
        overrides: vec![],
    };
    let problem = load_with(&scenario(), &options).unwrap().problem;
    assert_eq!(problem.bodies[0].mesh.num_cells(), 9 * 4 * 9);
    // A count that is not whole is refused, naming the value.
    let options = LoadOptions {
        variant: None,
        overrides: vec![Override::parse("n=4.5").unwrap()],
    };
    let err = load_with(&scenario(), &options).unwrap_err().to_string();
    assert!(
        err.contains("whole number") && err.contains("4.5"),
        "unexpected message: {err}"
    );
}
