//! Orthotropic friction through the whole solver, on the shipped scenario
//! scenarios/interface/orthotropic-drag.toml: a pad pressed on a rigid flat with μ₁ = 0.6
//! along x and μ₂ = 0.2 along z, dragged in the direction θ.
//!
//! Independent answer: once every node slides in the drag direction d = (cos θ, sin θ), each
//! node's friction force is where the elliptic cone's normal is d (maximal dissipation), so
//! the resultant is F_t = −N (μ₁² cos θ, μ₂² sin θ)/√(μ₁² cos² θ + μ₂² sin² θ), with N the
//! total normal force, whatever the pressure distribution.

use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;

const MU1: f64 = 0.6;
const MU2: f64 = 0.2;

/// (N, F_x, F_z) of the pair at the end of the drag, and whether every node slides then.
fn drag(angle_deg: f64, edit: impl Fn(String) -> String) -> (f64, f64, f64, bool) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/interface/orthotropic-drag.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = edit(text.replace("drag_angle = 45.0", &format!("drag_angle = {angle_deg:?}")));
    let problem = adhesim::scenario::parse(&text, &path).unwrap_or_else(|e| panic!("{e}"));
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let nodes = &s.contact[0];
    let total = |k: usize| nodes.iter().map(|c| c.force[k]).sum::<f64>();
    let all_slide = nodes.iter().all(|c| c.state == 3);
    (total(1), total(0), total(2), all_slide)
}

#[test]
fn dragged_pad_follows_the_elliptic_cone() {
    for angle in [0.0f64, 30.0, 45.0, 90.0] {
        let (n, fx, fz, all_slide) = drag(angle, |t| t);
        assert!(all_slide, "{angle}°: not every node slides");
        let th = angle.to_radians();
        let m = (MU1 * th.cos()).hypot(MU2 * th.sin());
        let expect = [-MU1 * MU1 * th.cos() / m, -MU2 * MU2 * th.sin() / m];
        eprintln!(
            "θ = {angle}°: F_t/N = ({:.9}, {:.9}), closed form ({:.9}, {:.9})",
            fx / n,
            fz / n,
            expect[0],
            expect[1]
        );
        // Each committed step meets the contact law to 1e-8 of the force scale and the
        // equilibrium to 1e-8 (time.newton_tol): 1e-6 leaves room for both.
        assert!(
            (fx / n - expect[0]).abs() < 1e-6,
            "{angle}°: F_x/N {}",
            fx / n
        );
        assert!(
            (fz / n - expect[1]).abs() < 1e-6,
            "{angle}°: F_z/N {}",
            fz / n
        );
    }
}

#[test]
fn equal_coefficients_on_material_axes_reproduce_the_isotropic_law() {
    // μ₂ = μ₁: the same law, but the local frames follow the material axis instead of the
    // default tangents, so the results agree to round-off only.
    let ortho = drag(30.0, |t| t.replace("friction_2 = 0.2", "friction_2 = 0.6"));
    let iso = drag(30.0, |t| {
        let line = "orthotropy = { axis = [1.0, 0.0, 0.0], friction_2 = 0.2 }";
        assert!(t.contains(line));
        t.replace(line, "")
    });
    for (a, b, what) in [
        (ortho.0, iso.0, "N"),
        (ortho.1, iso.1, "F_x"),
        (ortho.2, iso.2, "F_z"),
    ] {
        assert!((a - b).abs() < 1e-9 * iso.0.abs(), "{what}: {a} vs {b}");
    }
    // And the isotropic friction force is along the slip: |F_t| = μ N.
    let ft = iso.1.hypot(iso.2);
    assert!((ft / iso.0 - MU1).abs() < 1e-6, "{}", ft / iso.0);
}
