//! Energy: with θ = ξ = ½ (trapezoidal rule) a linear-elastic cantilever in free vibration
//! keeps kinetic + strain energy constant to round-off over many steps; θ = ξ = 1 dissipates.

use adhesim::material::LinearElastic;
use adhesim::mesh::generate;
use adhesim::problem::TimeSettings;
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

/// Runs `steps` steps of a cantilever released with a bending velocity field; returns the
/// total energy after every step.
fn energies(theta: f64, steps: usize) -> Vec<f64> {
    let (l, h) = (0.1, 0.01);
    let mesh = generate::block([l, h, h], [10, 2, 2]);
    let time = TimeSettings {
        t_end: 1.0,
        dt: 1e-3,
        theta,
        xi: theta,
        newton_tol: 1e-12,
        ..TimeSettings::default()
    };
    let mut p = one_body(
        mesh.clone(),
        Arc::new(LinearElastic::from_young_poisson(1e6, 0.3)),
        1000.0,
        time,
    );
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true; 3]));
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    // Initial velocity ∝ (x/L)², zero on the clamped face, 1 m/s at the tip.
    for (i, x) in mesh.nodes.iter().enumerate() {
        s.state.v[3 * i + 1] = (x[0] / l).powi(2);
    }
    let e0 = s.kinetic_energy(&s.state.v);
    let mut out = vec![e0];
    for _ in 0..steps {
        let r = s.step().unwrap();
        out.push(r.kinetic + r.internal);
    }
    out
}

#[test]
fn trapezoidal_rule_conserves_energy_of_a_linear_elastic_cantilever() {
    // First bending mode: f₁ = 1.875²/(2π) √(EI/(ρAL⁴)) ≈ 5.1 Hz, so 400 steps of 1 ms
    // cover two periods.
    let e = energies(0.5, 400);
    let e0 = e[0];
    let worst = e.iter().map(|v| (v - e0).abs() / e0).fold(0.0, f64::max);
    // Newton converges in one iteration for a linear problem (residual ~1e-16 relative);
    // the drift is round-off accumulated over 400 steps.
    assert!(worst < 1e-10, "relative energy drift {worst:e}");
}

#[test]
fn backward_euler_dissipates_energy() {
    let e = energies(1.0, 400);
    for w in e.windows(2) {
        assert!(
            w[1] <= w[0] * (1.0 + 1e-12),
            "energy grew: {} -> {}",
            w[0],
            w[1]
        );
    }
    // Backward Euler multiplies the energy of a mode of pulsation ω by 1/(1 + (ωΔt)²) per
    // step: for the first mode (ωΔt ≈ 0.032) that is a loss of ≈ 33 % over 400 steps, and
    // higher modes lose more.
    assert!(
        e[e.len() - 1] < 0.75 * e[0],
        "θ = 1 should lose energy: {} -> {}",
        e[0],
        e[e.len() - 1]
    );
}
