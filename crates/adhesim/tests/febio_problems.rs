//! The problems of the FEBio comparison (bench/febio/) at their smallest size, adhesim's side
//! only, against the forces FEBio 4.11 computed on the same meshes (bench/febio/results.jsonl,
//! the decks of bench/febio/feb.py) and, for the Hertz problem, the closed form: so that the
//! benchmark's problems cannot drift from what the table in bench/febio.md measured.
//!
//! The force is the reaction on the pushed top face at the end of the push [N].
//! Tolerances: FEBio stops its augmentations when the multipliers change by less than 1 % and
//! its quasi-Newton iterations at 1 % of the energy norm, so its force carries that error;
//! observed differences are 7e-7 (frictionless, rigid wall at 10¹² Pa/m), 4.6e-4 (pad with
//! friction on a fixed plate), 4.7e-3 (pad on a soft block, penalty scale 1) and 3.5e-5
//! (Hertz). The bounds are a few times those, and all well below what losing friction
//! changes (7 % on the pad, 2 % on the block).

use adhesim_io::run::{run, Outcome, Silent};
use adhesim_io::scenario::{load_with, LoadOptions, Override};
use std::path::{Path, PathBuf};

fn scenario(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../bench/febio/{name}.toml"))
}

/// Runs bench/febio/`name`.toml with `sets` and returns |column| at the last step, t = 1.
fn final_force(name: &str, sets: &[&str], column: &str) -> f64 {
    let options = LoadOptions {
        variant: None,
        overrides: sets.iter().map(|s| Override::parse(s).unwrap()).collect(),
    };
    let file = scenario(name);
    let problem = load_with(&file, &options).unwrap();
    let tag = format!("{name}-{}", sets.join("-")).replace(['=', '.'], "_");
    let out = std::env::temp_dir().join(format!("adhesim-test-febio-{tag}"));
    let summary = run(problem, Some(&file), &out, &mut Silent).unwrap();
    assert_eq!(summary.outcome, Outcome::Finished);
    let (cols, rows) = adhesim_io::output::csv::read_history(out.join("history.csv")).unwrap();
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    let last = rows.last().unwrap();
    assert!((last[col("t")] - 1.0).abs() < 1e-12);
    last[col(column)].abs()
}

fn assert_near(what: &str, f: f64, reference: f64, tol: f64) {
    let rel = (f - reference) / reference;
    eprintln!("{what}: {f:.7} N against {reference:.7} N ({rel:+.2e})");
    assert!(rel.abs() <= tol, "{what}: {f} N, reference {reference} N");
}

#[test]
fn pad_on_a_rigid_plane_matches_febio() {
    let f = final_force("pad", &["mu=0"], "pad.top.Fy");
    assert_near("pad, frictionless", f, 15.990558272793997, 1e-5);
    let f = final_force("pad", &["mu=0.3"], "pad.top.Fy");
    assert_near("pad, μ = 0.3", f, 17.091857693326794, 2e-3);
}

#[test]
fn pad_on_a_soft_block_matches_febio() {
    let f = final_force("blocks", &[], "pad.top.Fy");
    assert_near(
        "pad on a soft block, mortar, μ = 0.3",
        f,
        8.747072595308596,
        1e-2,
    );
}

/// Both codes give 1.073 of Hertz's force on this coarse tet4 mesh (three linear tetrahedra
/// across the contact radius, stiff): the closed form checks that the problem is Hertz's,
/// FEBio's force that it is the same discretisation.
#[test]
fn hertz_on_a_gmsh_tet4_mesh_matches_febio() {
    let f = final_force("hertz", &[], "cap.top.Fy");
    assert_near("hertz, quarter sphere", f, 0.00020444929228897996, 1e-4);
    let (e, nu, r, d) = (2.6e6_f64, 0.3_f64, 5e-3_f64, 2e-6_f64);
    let hertz_quarter = e / (1.0 - nu * nu) * r.sqrt() * d.powf(1.5) / 3.0;
    let ratio = f / hertz_quarter;
    assert!((1.0..1.1).contains(&ratio), "{ratio} of Hertz's force");
}
