//! The shipped scenario scenarios/soft/pdms-pull-off.toml (coarse variant, larger steps): a
//! viscoelastic, nearly incompressible cap pressed into an adhesive flat, held, pulled off.
//!
//! Check against an independent answer: for an incompressible linear viscoelastic solid held
//! at a fixed indentation the force relaxes like the shear modulus (Lee & Radok 1960), so
//! after the hold (4 τ) it equals the force of the same run with the long-term elastic
//! material μ∞ = μ₀ (1 − g), within the few % of relaxation left and of nonlinearity.

use adhesim_io::run::{run, Outcome, Silent};
use adhesim_io::scenario::{load_with, LoadOptions, Override};
use std::path::Path;

/// Runs the coarse variant with `overrides`; returns (t, flat.fy, flat.bonded) per step.
fn run_case(tag: &str, overrides: &[&str]) -> Vec<(f64, f64, f64)> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/soft/pdms-pull-off.toml");
    let opts = LoadOptions {
        variant: Some("coarse".into()),
        overrides: overrides
            .iter()
            .map(|s| Override::parse(s).unwrap())
            .collect(),
    };
    let problem = load_with(&path, &opts).unwrap_or_else(|e| panic!("{e}"));
    let out = std::env::temp_dir().join(format!("adhesim-test-pull-off-{tag}"));
    let summary = run(problem, Some(&path), &out, &mut Silent).unwrap();
    assert_eq!(summary.outcome, Outcome::Finished, "{overrides:?}");
    let (cols, rows) = adhesim_io::output::csv::read_history(out.join("history.csv")).unwrap();
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    let (t, fy, b) = (col("t"), col("flat.fy"), col("flat.bonded"));
    rows.iter().map(|r| (r[t], r[fy], r[b])).collect()
}

fn at(h: &[(f64, f64, f64)], t: f64) -> f64 {
    h.iter()
        .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
        .unwrap()
        .1
}

#[test]
fn held_force_relaxes_to_the_long_term_elastic_answer_and_the_cap_lets_go() {
    let common = ["v_pull=1e-2", "time.dt=2e-3"];
    let visco = run_case("visco", &common);
    let long_term = run_case(
        "long-term",
        &[
            common[0],
            common[1],
            "body.cap.material={ model = \"uncoupled-neo-hookean\", c10 = 0.12e6, kappa = 1.5e9 }",
        ],
    );
    // End of the hold: t = 0.3 s (the flat starts moving back then).
    let (f_visco, f_long) = (at(&visco, 0.298), at(&long_term, 0.298));
    let peak = visco.iter().map(|r| r.1).fold(0.0, f64::max);
    eprintln!(
        "compressive force: peak {peak:.4} N, end of hold {f_visco:.4} N, long-term elastic {f_long:.4} N"
    );
    assert!(
        (f_visco / f_long - 1.0).abs() < 0.03,
        "relaxed force {f_visco} vs long-term elastic {f_long}"
    );
    assert!(
        peak > 1.3 * f_visco,
        "no relaxation: peak {peak}, held {f_visco}"
    );
    // Pull-off: a tensile force, then no bond left at the end.
    let pull_off = -visco.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
    eprintln!("pull-off force {pull_off:.4} N");
    assert!(pull_off > 0.0);
    assert_eq!(visco.last().unwrap().2, 0.0, "bonds left at the end");
}
