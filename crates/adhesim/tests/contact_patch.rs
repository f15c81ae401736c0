//! The contact patch test on non-matching meshes: a linear elastic block (1 × 0.5 × 1 m,
//! E = 1 MPa, ν = 0.3) on a block of the same size and material, frictionless, with
//! symmetry conditions on the faces x = 0 and z = 0 of both and the top pushed down by 1 mm.
//! The exact answer is a uniaxial stress: a uniform contact pressure E δ / H = 1000 Pa over
//! the whole interface (H = 1 m, both blocks) and a total force of 1000 N.
//!
//! Mortar contact passes it to round-off whatever the meshes and the contact solver:
//! pressure uniform to 1e-6 relative and force to 1e-8. The Newton and contact tolerances are
//! 1e-12, far below these, except for the augmented-Lagrangian solve (`newton`), whose
//! multiplier ρ of a thousand times the stiffness at a point leaves a round-off floor near
//! 1e-9: it runs at 1e-8 (its force then comes out within 1e-10). Node-to-surface contact,
//! shown beside it, passes only on matching meshes.

use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;

/// The exact contact pressure [Pa].
const PRESSURE: f64 = 1000.0;

fn scenario(slave: usize, master: usize, discretisation: &str, solver: &str) -> String {
    let tol = if solver == "newton" { 1e-8 } else { 1e-12 };
    format!(
        r#"
[time]
t_end = 1.0
dt = 1.0
mode = "quasi-static"
newton_tol = {tol:e}
contact_solver = "{solver}"
contact_tol = {tol:e}
[[body]]
name = "lower"
mesh = {{ generator = "block", size = [1.0, 0.5, 1.0], divisions = [{master}, 2, {master}] }}
material = {{ model = "linear-elastic", young = 1e6, poisson = 0.3 }}
density = 1000.0
[[body]]
name = "upper"
mesh = {{ generator = "block", size = [1.0, 0.5, 1.0], divisions = [{slave}, 2, {slave}] }}
material = {{ model = "linear-elastic", young = 1e6, poisson = 0.3 }}
density = 1000.0
offset = [0.0, 0.5, 0.0]
[[boundary]]
body = "lower"
set = "bottom"
fix = ["y"]
[[boundary]]
body = "upper"
set = "top"
fix = []
displacement = {{ y = [[0.0, 0.0], [1.0, -1e-3]] }}
[[boundary]]
body = "lower"
set = "left"
fix = ["x"]
[[boundary]]
body = "upper"
set = "left"
fix = ["x"]
[[boundary]]
body = "lower"
set = "back"
fix = ["z"]
[[boundary]]
body = "upper"
set = "back"
fix = ["z"]
[[contact]]
name = "interface"
slave = {{ body = "upper", set = "bottom" }}
master = {{ body = "lower", set = "top" }}
friction = 0.0
detection_distance = 0.01
discretisation = "{discretisation}"
"#
    )
}

/// Largest relative deviation of the slave nodes' pressure from the exact one, and the total
/// contact force [N].
fn patch(slave: usize, master: usize, discretisation: &str, solver: &str) -> (f64, f64) {
    let text = scenario(slave, master, discretisation, solver);
    let problem = adhesim_io::scenario::parse(&text, Path::new("patch.toml"))
        .unwrap()
        .problem;
    let pair = problem.contacts[0].clone();
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let sites = &s.contact[0];
    let force: f64 = sites.iter().map(|c| c.force[1]).sum();
    let worst = sites
        .iter()
        .zip(&pair.slave_area)
        .map(|(c, a)| ((c.force[1] / a) - PRESSURE).abs() / PRESSURE)
        .fold(0.0, f64::max);
    (worst, force)
}

#[test]
fn mortar_passes_the_contact_patch_test_on_non_matching_meshes() {
    for (slave, master) in [(7, 10), (10, 7), (4, 13), (10, 10)] {
        for solver in ["gauss-seidel", "semismooth", "newton"] {
            let (worst, force) = patch(slave, master, "mortar", solver);
            eprintln!(
                "mortar {slave}×{slave} on {master}×{master}, {solver}: pressure error \
                 {worst:.1e}, force {force:.10} N"
            );
            assert!(
                worst < 1e-6,
                "{slave} on {master}, {solver}: pressure off by {worst:e}"
            );
            let force_error = (force - PRESSURE).abs() / PRESSURE;
            assert!(
                force_error < 1e-8,
                "{slave} on {master}, {solver}: force {force}"
            );
        }
    }
}

#[test]
fn node_to_surface_fails_it_where_the_meshes_do_not_match() {
    for (slave, master) in [(7, 10), (10, 7)] {
        let (worst, force) = patch(slave, master, "node-to-surface", "gauss-seidel");
        eprintln!(
            "node-to-surface {slave}×{slave} on {master}×{master}: {worst:.1e}, {force:.6} N"
        );
        assert!(worst > 0.01, "{slave} on {master}: {worst}");
    }
    let (worst, force) = patch(10, 10, "node-to-surface", "gauss-seidel");
    eprintln!("node-to-surface 10×10 on 10×10: {worst:.1e}, {force:.6} N");
    assert!(worst < 1e-6 && (force - PRESSURE).abs() < 1e-8 * PRESSURE);
    let (worst, force) = patch(4, 13, "node-to-surface", "gauss-seidel");
    eprintln!("node-to-surface 4×4 on 13×13: {worst:.1e}, {force:.6} N");
    // The master nodes sink into the coarse slave faces: a fifth of the force is lost.
    assert!(worst > 0.1 && force < 0.9 * PRESSURE, "{worst}, {force}");
}
