//! The shipped scenario scenarios/contact/pad-on-pad-pull-off.toml: two pads with
//! non-matching meshes bonded by the RCC interface on mortar sites, pulled apart.
//!
//! Independent answers: with β = 1 after the hold and a bond viscosity small against the
//! pull's rate, the interface follows its rate-independent limit. Its force per unit area
//! is C_n u up to the opening u_c = √(w / C_n) where the bonds start to break, and w²/(C_n u³)
//! beyond, so the peak force is A √(C_n w) and the work of separation ∫ F du = w A
//! (docs/model.md §6). The pads deform uniformly (uniaxial stress with symmetry on x = 0),
//! so these hold for the whole interface. Tolerances 1 %: the peak is sampled at the steps
//! (0.017 µm of pull each, 0.8 % of u_c), and the force left at the end of the pull carries
//! 0.2 % of the work.

use adhesim_io::run::{run, Outcome, Silent};
use adhesim_io::scenario::{load_with, LoadOptions, Override};
use std::path::Path;

/// The scenario's interface: C_n [N/m³], w [J/m²], and its area A [m²] (4 × 1 mm).
const CN: f64 = 1e10;
const W: f64 = 0.05;
const AREA: f64 = 4e-6;

/// (applied displacement of the lower pad's bottom [m], force on it [N]) per step.
fn pull(tag: &str, overrides: &[&str]) -> Vec<(f64, f64)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/contact/pad-on-pad-pull-off.toml");
    let opts = LoadOptions {
        variant: None,
        overrides: overrides
            .iter()
            .map(|s| Override::parse(s).unwrap())
            .collect(),
    };
    let problem = load_with(&path, &opts).unwrap_or_else(|e| panic!("{e}"));
    let out = std::env::temp_dir().join(format!("adhesim-test-pad-on-pad-{tag}"));
    let _ = std::fs::remove_dir_all(&out);
    let summary = run(problem, Some(&path), &out, &mut Silent).unwrap();
    assert_eq!(summary.outcome, Outcome::Finished);
    let (cols, rows) = adhesim_io::output::csv::read_history(out.join("history.csv")).unwrap();
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    let (u, f) = (col("lower.bottom.uy"), col("lower.bottom.Fy"));
    rows.iter().map(|r| (r[u], r[f])).collect()
}

/// Peak tensile force [N] and the work of the tensile force over the pull [J].
fn peak_and_work(h: &[(f64, f64)]) -> (f64, f64) {
    // Pulling down: the support holds the lower pad up, a negative force.
    let tension = |f: f64| (-f).max(0.0);
    let peak = h.iter().map(|r| tension(r.1)).fold(0.0, f64::max);
    let work = h
        .windows(2)
        .filter(|p| p[1].0 < p[0].0)
        .map(|p| 0.5 * (tension(p[0].1) + tension(p[1].1)) * (p[0].0 - p[1].0))
        .sum();
    (peak, work)
}

#[test]
fn mortar_pads_pull_off_at_the_closed_form_peak_with_the_work_of_adhesion() {
    let (peak, work) = peak_and_work(&pull("mortar", &[]));
    let (peak_exact, work_exact) = (AREA * (CN * W).sqrt(), W * AREA);
    eprintln!(
        "peak {peak:.6e} N (closed form {peak_exact:.6e}), work {work:.6e} J (w A = {work_exact:.6e})"
    );
    assert!(
        (peak / peak_exact - 1.0).abs() < 0.01,
        "peak {peak} vs {peak_exact}"
    );
    assert!(
        (work / work_exact - 1.0).abs() < 0.01,
        "work {work} vs {work_exact}"
    );
}
