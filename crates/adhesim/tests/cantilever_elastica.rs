//! Large deflection of a cantilever under a dead tip load, quasi-static, converging under
//! mesh refinement to the elastica solution (Bisshopp & Drucker 1945; tabulated by
//! Mattiasson 1981): for P L²/(E I) = 2 the tip moves v/L = 0.49346 down and u/L = 0.16064
//! towards the clamp.
//!
//! The continuum model is a Saint Venant-Kirchhoff beam with ν = 0 (no Poisson coupling,
//! so the Euler-Bernoulli section stiffness is exact) and L/h = 25; shear deformation adds
//! ≈ 0.3 % to the deflection and the strains stay below 4 %.

use adhesim::material::SaintVenantKirchhoff;
use adhesim::mesh::generate;
use adhesim::problem::{NodalLoad, Table};
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

const ELASTICA_V: f64 = 0.49346;
const ELASTICA_U: f64 = 0.16064;

/// Tip displacement (u/L, v/L) for a mesh of nx × ny × 1 hexes.
fn tip(nx: usize, ny: usize) -> (f64, f64) {
    let (l, h): (f64, f64) = (1.0, 0.04);
    let e = 1.0e6;
    let inertia = h * h.powi(3) / 12.0;
    let p_tip = 2.0 * e * inertia / (l * l);
    let mesh = generate::block([l, h, h], [nx, ny, 1]);
    let mut p = one_body(
        mesh.clone(),
        Arc::new(SaintVenantKirchhoff::from_young_poisson(e, 0.0)),
        1000.0,
        quasi_static(1.0, 0.05),
    );
    p.time.newton_tol = 1e-10;
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true; 3]));
    let right = mesh.node_sets["right"].clone();
    p.loads.push(NodalLoad {
        nodes: right.clone(),
        total_force: [
            Table::constant(0.0),
            Table {
                t: vec![0.0, 1.0],
                v: vec![0.0, -p_tip],
            },
            Table::constant(0.0),
        ],
    });
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    while !s.finished() {
        s.step().expect("the load ramp converges");
    }
    let mean =
        |k: usize| right.iter().map(|&n| s.state.u[3 * n + k]).sum::<f64>() / right.len() as f64;
    (-mean(0) / l, -mean(1) / l)
}

#[test]
fn tip_deflection_converges_to_the_elastica() {
    // Each mesh halves the element size of the previous one.
    let meshes = [(25, 1), (50, 2), (100, 4), (200, 8)];
    let tips: Vec<(f64, f64)> = meshes.iter().map(|&(nx, ny)| tip(nx, ny)).collect();
    let error = |(u, v): (f64, f64)| {
        ((v - ELASTICA_V) / ELASTICA_V)
            .abs()
            .max(((u - ELASTICA_U) / ELASTICA_U).abs())
    };
    let errors: Vec<f64> = tips.iter().map(|&t| error(t)).collect();
    for ((nx, ny), (t, e)) in meshes.iter().zip(tips.iter().zip(&errors)) {
        eprintln!(
            "mesh {nx}x{ny}: u/L = {:.5}, v/L = {:.5}, relative error {e:.2e}",
            t.0, t.1
        );
    }
    // Full-integration hex8 elements lock in bending: the error is the locking error,
    // O(h²). Observed order from the three finest meshes must be close to 2.
    let order = ((tips[2].1 - tips[1].1) / (tips[3].1 - tips[2].1)).log2();
    eprintln!("observed order of convergence of v: {order:.2}");
    assert!(
        (1.6..2.4).contains(&order),
        "observed order {order}, errors {errors:?}"
    );
    // Richardson extrapolation with the theoretical order 2 lands on the elastica within
    // 0.5 % (what is left: shear deformation ≈ 0.3 % and the material nonlinearity of SVK).
    let r = 4.0;
    let extrapolate = |c: f64, f: f64| f + (f - c) / (r - 1.0);
    let v = extrapolate(tips[2].1, tips[3].1);
    let u = extrapolate(tips[2].0, tips[3].0);
    eprintln!("extrapolated: u/L = {u:.5}, v/L = {v:.5}");
    assert!(
        error((u, v)) < 5e-3,
        "extrapolated tip (u, v)/L = ({u}, {v})"
    );
    for w in errors.windows(2) {
        assert!(
            w[1] < w[0],
            "error did not fall with refinement: {errors:?}"
        );
    }
}
