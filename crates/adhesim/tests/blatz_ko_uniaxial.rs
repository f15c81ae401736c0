//! Blatz-Ko uniaxial tension from a full finite-element run of a block (not just the
//! material routine): lateral stretch λ^(−1/4) and nominal stress P₁₁ = G(λ^(−1/2) − λ^(−3)).

use adhesim::material::BlatzKo;
use adhesim::mesh::generate;
use adhesim::problem::{Dirichlet, Table};
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

#[test]
fn block_in_uniaxial_tension_matches_the_closed_form() {
    let g = 1.0e6;
    let (lx, ly, lz) = (0.02, 0.01, 0.01);
    let mesh = generate::block([lx, ly, lz], [4, 2, 2]);
    let stretches = [1.1, 1.25, 1.5, 2.0];
    let t_end = stretches.len() as f64;
    let mut p = one_body(
        mesh.clone(),
        Arc::new(BlatzKo { g }),
        1000.0,
        quasi_static(t_end, 1.0),
    );
    // Symmetry planes x = 0, y = 0, z = 0 hold the block; the right face is pulled.
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true, false, false]));
    p.dirichlet.push(fixed(
        mesh.node_sets["bottom"].clone(),
        [false, true, false],
    ));
    p.dirichlet
        .push(fixed(mesh.node_sets["back"].clone(), [false, false, true]));
    let mut table = Table {
        t: vec![0.0],
        v: vec![0.0],
    };
    for (i, l) in stretches.iter().enumerate() {
        table.t.push(i as f64 + 1.0);
        table.v.push((l - 1.0) * lx);
    }
    p.dirichlet.push(Dirichlet {
        nodes: mesh.node_sets["right"].clone(),
        components: [true, false, false],
        translation: [table, Table::constant(0.0), Table::constant(0.0)],
        rotation: None,
    });
    let top = &mesh.node_sets["top"];
    let right = &mesh.node_sets["right"];
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    for (i, &lambda) in stretches.iter().enumerate() {
        // Step until the time at which this stretch is reached (Δt may be cut back).
        while s.state.t < i as f64 + 1.0 - 1e-9 {
            let r = s.step().unwrap();
            assert!(r.newton_iterations < 15);
        }
        // Lateral stretch from every top node.
        let expected_lateral = lambda.powf(-0.25);
        for &n in top {
            let y = mesh.nodes[n][1] + s.state.u[3 * n + 1];
            assert!(
                (y / ly - expected_lateral).abs() < 1e-9,
                "λ = {lambda}: lateral stretch {}",
                y / ly
            );
        }
        // Nominal stress from the reaction: the x internal forces on the pulled face.
        let f = s.disc.assemble(&s.state.u, false).force;
        let force: f64 = right.iter().map(|&n| f[3 * n]).sum();
        let p11 = force / (ly * lz);
        let exact = g * (lambda.powf(-0.5) - lambda.powi(-3));
        assert!(
            (p11 - exact).abs() < 1e-8 * g,
            "λ = {lambda}: P11 = {p11}, closed form {exact}"
        );
    }
}
