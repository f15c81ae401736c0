//! Cook's membrane at finite strain, incompressible neo-Hookean (μ = 1, E = 3; plane strain,
//! a dead shear traction 0.05 on the face x = 48, total 0.8 per unit thickness): the corner
//! deflection against the published two-dimensional reference 4.7011 of B. Müller's thesis
//! (docs/elements.md). Incompressibility is approached with κ = 5·10⁴ μ (ν = 0.49999); the
//! load is applied in ten equal increments.

use adhesim::element::QUAD8;
use adhesim::fbar::Formulation;
use adhesim::material::UncoupledNeoHookean;
use adhesim::mesh::generate;
use adhesim::problem::{NodalLoad, Table};
use std::sync::Arc;

mod common;
use common::*;

/// The published reference: vertical displacement of the corner (48, 60).
const MULLER_REFERENCE: f64 = 4.7011;

/// The corner's vertical displacement on n × n cells of `cells` (Hex8 or Hex20) with the
/// element kinematics `element`.
fn cook_neo_hookean(n: usize, cells: Cells, element: Formulation) -> f64 {
    let mut mesh = generate::block([1.0, 1.0, 1.0], [n, n, 1]);
    for x in &mut mesh.nodes {
        let (xi, eta) = (x[0], x[1]);
        *x = [48.0 * xi, 44.0 * xi + eta * (44.0 - 28.0 * xi), x[2]];
    }
    let mesh = match cells {
        Cells::Hex20 => mesh.with_mid_side_nodes(),
        _ => mesh,
    };
    let material = UncoupledNeoHookean {
        c10: 0.5,
        kappa: 5.0e4,
    };
    let mut p = one_body(
        mesh.clone(),
        Arc::new(material),
        1.0,
        quasi_static(1.0, 0.1),
    );
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-10;
    p.dirichlet
        .push(fixed((0..mesh.num_nodes()).collect(), [false, false, true]));
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true, true, false]));
    // Each face of x = 48 is (16 / n) × 1 and carries 0.05 · 16 / n; consistent nodal forces.
    let face_load = 0.05 * 16.0 / n as f64;
    for face in &mesh.face_sets["right"] {
        let quadratic = face.face_type().name == QUAD8.name;
        for k in 0..face.nodes().len() {
            let share = match (quadratic, k < 4) {
                (false, _) => 0.25,
                (true, true) => -1.0 / 12.0,
                (true, false) => 1.0 / 3.0,
            };
            p.loads.push(NodalLoad {
                nodes: vec![face.nodes()[k]],
                total_force: [
                    Table::constant(0.0),
                    ramp(share * face_load),
                    Table::constant(0.0),
                ],
            });
        }
    }
    let corner: Vec<usize> = mesh.node_sets["right"]
        .iter()
        .copied()
        .filter(|&i| (mesh.nodes[i][1] - 60.0).abs() < 1e-9)
        .collect();
    let s = solve(p);
    corner.iter().map(|&i| s.state.u[3 * i + 1]).sum::<f64>() / corner.len() as f64
}

/// The refinement study: `cargo test --release -p adhesim --test cook_neo_hookean --
/// --ignored --nocapture`.
#[test]
#[ignore]
fn cooks_membrane_neo_hookean_refinement() {
    for n in [4, 8, 16, 32] {
        let hex20 = cook_neo_hookean(n, Cells::Hex20, Formulation::FBar);
        let hex8 = cook_neo_hookean(2 * n, Cells::Hex8, Formulation::FBar);
        eprintln!(
            "Cook neo-Hookean: hex20 Q2/P1 {n}×{n} {hex20:.4} ({:+.3} %), F-bar hex8 {}×{} {hex8:.4} ({:+.3} %)",
            100.0 * (hex20 / MULLER_REFERENCE - 1.0),
            2 * n,
            2 * n,
            100.0 * (hex8 / MULLER_REFERENCE - 1.0)
        );
    }
}

/// On 8 × 8 hex20 (Q2/P1) and 16 × 16 F-bar hex8: both below the reference and within 2.5 %
/// of it (measured −1.84 % and −1.91 %; the clamped corner's singularity keeps every element
/// near h^1.1, docs/elements.md); the refinement study extrapolates to it within 0.1 %.
#[test]
fn cooks_membrane_neo_hookean_near_the_published_value() {
    for (n, cells) in [(8, Cells::Hex20), (16, Cells::Hex8)] {
        let v = cook_neo_hookean(n, cells, Formulation::FBar);
        let err = v / MULLER_REFERENCE - 1.0;
        eprintln!(
            "{cells:?} {n}×{n}: {v:.4} ({:+.2} % of {MULLER_REFERENCE})",
            100.0 * err
        );
        assert!(err < 0.0 && err > -0.025, "{cells:?} {n}: {v}");
    }
}
