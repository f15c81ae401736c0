//! Rayleigh damping and the mass matrices.

use adhesim::material::BlatzKo;
use adhesim::mesh::generate;
use adhesim::problem::TimeSettings;
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

/// A free body translating at v₀ with mass-proportional damping A = αM: the trapezoidal
/// rule gives exactly v₁ = v₀ (1 − αΔt/2)/(1 + αΔt/2) per step (no strain, K plays no part).
/// On hex8 and on the quadratic elements, whose lumped mass is the scaled diagonal.
#[test]
fn mass_proportional_damping_matches_the_discrete_closed_form() {
    for (cells, lumped) in [Cells::Hex8, Cells::Hex20, Cells::Tet10]
        .into_iter()
        .flat_map(|c| [(c, false), (c, true)])
    {
        let (alpha, dt) = (20.0, 1e-3);
        let mesh = cells.block([0.01, 0.01, 0.01], [2, 2, 2]);
        let time = TimeSettings {
            t_end: 0.05,
            dt,
            newton_tol: 1e-12,
            lumped_mass: lumped,
            rayleigh: (alpha, 0.0),
            ..TimeSettings::default()
        };
        let mut p = one_body(mesh, Arc::new(BlatzKo { g: 1e6 }), 1000.0, time);
        p.bodies[0].initial_velocity = [0.3, -0.2, 0.1];
        let mut s = Stepper::new(Arc::new(p)).unwrap();
        let factor: f64 = (1.0 - alpha * dt / 2.0) / (1.0 + alpha * dt / 2.0);
        let mut steps = 0;
        while !s.finished() {
            s.step().unwrap();
            steps += 1;
        }
        let expected = 0.3 * factor.powi(steps);
        for i in 0..s.disc.num_nodes {
            let v = s.state.v[3 * i];
            assert!(
                (v - expected).abs() < 1e-12,
                "{cells:?}, lumped = {lumped}: v = {v}, expected {expected}"
            );
        }
    }
}

/// Consistent and lumped mass both hold the body's mass ρV in every direction, and the
/// consistent one gives the exact kinetic energy ½ m v² of a rigid translation.
#[test]
fn mass_matrices_carry_the_total_mass() {
    let mesh = generate::disk(0.01, 0.002, 4, 3);
    let p = one_body(
        mesh,
        Arc::new(BlatzKo { g: 1e6 }),
        1200.0,
        TimeSettings::default(),
    );
    let s = Stepper::new(Arc::new(p)).unwrap();
    let volume = s.disc.volume();
    let mass = 1200.0 * volume;
    for lumped in [false, true] {
        let m = s.disc.mass(&[1200.0], lumped);
        let v: Vec<f64> = (0..s.disc.num_dofs())
            .map(|d| if d % 3 == 1 { 2.0 } else { 0.0 })
            .collect();
        let mut mv = vec![0.0; v.len()];
        s.disc.pattern.symmetric_matvec(&m, &v, &mut mv);
        let ke: f64 = 0.5 * v.iter().zip(&mv).map(|(a, b)| a * b).sum::<f64>();
        assert!(
            (ke - 0.5 * mass * 4.0).abs() < 1e-12 * ke,
            "lumped = {lumped}: {ke} vs {}",
            0.5 * mass * 4.0
        );
    }
}
