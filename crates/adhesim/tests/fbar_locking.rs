//! Nearly incompressible solids (ν = 0.4999) on hex8 meshes: the F-bar element against full
//! integration.
//!
//! - A cantilever with 4 elements through the thickness: F-bar within 5 % of the converged
//!   answer of the same model (Richardson extrapolation of its own refinements), while full
//!   integration locks.
//! - Cook's membrane, plane strain, small load (linear regime): the tip deflection converges,
//!   and the finest mesh is within 1 % of the converged value computed with CalculiX
//!   (bench/cook/run.sh).
//! - A block under large simple shear keeps its volume element by element (|J − 1| < 1e-3).
//! - A patch test: a homogeneous finite deformation is reproduced on a distorted mesh.

use adhesim::fbar::volume_ratio;
use adhesim::fbar::Formulation;
use adhesim::material::UncoupledNeoHookean;
use adhesim::mesh::{generate, Mesh};
use adhesim::problem::{NodalLoad, Problem, Table};
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

const NU: f64 = 0.4999;

/// Converged vertical displacement of the top right corner (48, 60) of Cook's membrane in
/// plane strain, E = 250, ν = 0.4999, F = 100 (the problem of `cook`), from
/// `bench/cook/run.sh`: CalculiX 2.20, C3D20R (quadratic hexahedra, reduced integration) on
/// 4² … 128² meshes of the same mapping, Richardson extrapolation of 32², 64², 128² with the
/// observed order 1.09: 7.7709 (64², 128², 256²: 7.7713; C3D20: 7.7714). The order matches the
/// corner singularity at the clamp (0, 44) (a point value converges as h^(2λ), 2λ = 1.087).
/// The literature on locking-free elements quotes about 7.7 for this load case
/// (docs/elements.md).
const COOK_REFERENCE: f64 = 7.771;

/// Fixes z on every node (plane strain for a slab one element thick).
fn plane_strain(p: &mut Problem, mesh: &Mesh) {
    p.dirichlet
        .push(fixed((0..mesh.num_nodes()).collect(), [false, false, true]));
}

fn mean_of(s: &Stepper, nodes: &[usize], k: usize) -> f64 {
    nodes.iter().map(|&n| s.state.u[3 * n + k]).sum::<f64>() / nodes.len() as f64
}

/// Plane-strain cantilever L × h (L/h = 10) clamped at x = 0, a small dead shear load on its
/// free end (tip deflection ~ 1e-3 L, linear regime); `ny` elements through the thickness,
/// 10·ny along. Returns the mean tip deflection in units of the Euler-Bernoulli value.
fn cantilever(ny: usize, element: Formulation) -> f64 {
    cantilever_beam(ny, false, element, NU, Section::PlaneStrain { nu_load: NU })
}

#[test]
fn cantilever_with_four_elements_through_the_thickness_does_not_lock() {
    // Tip deflections in units of the Euler-Bernoulli value.
    let fbar: Vec<f64> = [4, 8, 16]
        .iter()
        .map(|&n| cantilever(n, Formulation::FBar))
        .collect();
    let standard4 = cantilever(4, Formulation::Standard);
    // Richardson extrapolation with the observed order from the three meshes.
    let order = ((fbar[1] - fbar[0]) / (fbar[2] - fbar[1])).log2();
    let converged = fbar[2] + (fbar[2] - fbar[1]) / (2f64.powf(order) - 1.0);
    eprintln!(
        "cantilever ν = {NU}: F-bar ny = 4, 8, 16: {:.4} {:.4} {:.4} (order {order:.2}), \
         extrapolated {converged:.4}; full integration ny = 4: {standard4:.4}",
        fbar[0], fbar[1], fbar[2]
    );
    assert!(order > 0.8, "no convergence: {fbar:?}");
    // Shear deformation and the clamp move the converged value by a few % from
    // Euler-Bernoulli (L/h = 10); a wildly different value would mean something else is wrong.
    assert!((0.95..1.1).contains(&converged), "extrapolated {converged}");
    let err4 = (fbar[0] - converged).abs() / converged;
    assert!(
        err4 < 0.05,
        "F-bar at 4 elements: {err4:.3} off the converged answer"
    );
    // Full integration on the same mesh is several times too stiff.
    assert!(
        standard4 < 0.5 * converged,
        "full integration: {standard4} vs {converged}"
    );
}

/// Cook's membrane (a tapered panel with corners (0, 0), (48, 44), (48, 60), (0, 44), clamped
/// on x = 0, a total vertical shear force F on x = 48), plane strain, E = 250, ν = 0.4999,
/// n × n elements. Returns the vertical displacement of the top right corner per unit of
/// F/100 (the benchmark's F = 100; this load is 1e-4 of it, so the response is linear).
fn cook(n: usize, element: Formulation) -> f64 {
    let mut mesh = generate::block([1.0, 1.0, 1.0], [n, n, 1]);
    for x in &mut mesh.nodes {
        let (xi, eta) = (x[0], x[1]);
        *x = [48.0 * xi, 44.0 * xi + eta * (44.0 - 28.0 * xi), x[2]];
    }
    let material = UncoupledNeoHookean::from_young_poisson(250.0, NU);
    let mut p = one_body(
        mesh.clone(),
        Arc::new(material),
        1.0,
        quasi_static(1.0, 1.0),
    );
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-10;
    plane_strain(&mut p, &mesh);
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true, true, false]));
    // A uniform shear traction on the right edge: consistent nodal forces, end nodes of
    // the edge taking half a share. Two nodes (z = 0, 1) per edge point.
    let scale = 1e-4;
    let f_total = 100.0 * scale;
    let right = &mesh.node_sets["right"];
    for &node in right {
        let eta = (mesh.nodes[node][1] - 44.0) / 16.0;
        let end = eta.abs() < 1e-9 || (eta - 1.0).abs() < 1e-9;
        let share = f_total / (2.0 * n as f64) * if end { 0.5 } else { 1.0 };
        p.loads.push(NodalLoad {
            nodes: vec![node],
            total_force: [Table::constant(0.0), ramp(share), Table::constant(0.0)],
        });
    }
    let corner: Vec<usize> = right
        .iter()
        .copied()
        .filter(|&i| (mesh.nodes[i][1] - 60.0).abs() < 1e-9)
        .collect();
    assert_eq!(corner.len(), 2);
    let s = solve(p);
    mean_of(&s, &corner, 1) / scale
}

#[test]
fn cooks_membrane_converges() {
    let ns = [4, 8, 16, 32, 64];
    let fbar: Vec<f64> = ns.iter().map(|&n| cook(n, Formulation::FBar)).collect();
    let standard: Vec<f64> = ns[..3]
        .iter()
        .map(|&n| cook(n, Formulation::Standard))
        .collect();
    // Richardson extrapolation from the three finest meshes with the observed order (the
    // re-entrant corner at the clamp keeps it below 2).
    let (c, m, f) = (fbar[2], fbar[3], fbar[4]);
    let order = ((m - c) / (f - m)).log2();
    let converged = f + (f - m) / (2f64.powf(order) - 1.0);
    for (i, n) in ns.iter().enumerate() {
        eprintln!(
            "Cook n = {n:2}: F-bar {:.4}  full integration {}",
            fbar[i],
            standard.get(i).map_or("-".into(), |v| format!("{v:.4}"))
        );
    }
    let err_ref = (f - COOK_REFERENCE) / COOK_REFERENCE;
    eprintln!(
        "observed order {order:.2}, extrapolated {converged:.4}; 64×64 vs the CalculiX \
         reference {COOK_REFERENCE}: {:+.2} %",
        100.0 * err_ref
    );
    assert!(order > 1.0, "order {order}: {fbar:?}");
    // Monotone convergence from below (a stiff element under-predicts).
    for w in fbar.windows(2) {
        assert!(w[1] > w[0], "{fbar:?}");
    }
    let err = (f - converged).abs() / converged;
    assert!(err < 0.01, "F-bar 64×64: {f} vs {converged} ({err:.4})");
    // The finest mesh against the reference from a peer code (COOK_REFERENCE), within 1 %.
    // F-bar is 0.44 % low at 64×64, and no element is expected to be much closer there: the
    // clamped corner (0, 44) limits every element to h^1.09, so halving h only about halves the
    // error (C3D20R, quadratic, is still 0.35 % low at 64×64). The rest of the budget covers
    // what is not discretisation: the reference's own uncertainty (~0.01 %, the spread of its
    // extrapolations) and the geometric nonlinearity of our finite-strain run (load 1e-4 of
    // F = 100: ~1e-5 relative).
    assert!(
        err_ref.abs() < 0.01,
        "F-bar 64×64: {f} vs the reference {COOK_REFERENCE} ({:+.2} %)",
        100.0 * err_ref
    );
    // The element's own extrapolation lands on the reference too (0.07 % below it; with the
    // corner's order 1.09 instead of the observed 1.29 it would be 0.04 % above).
    assert!(
        ((converged - COOK_REFERENCE) / COOK_REFERENCE).abs() < 0.005,
        "extrapolated {converged} vs the reference {COOK_REFERENCE}"
    );
    // Full integration locks: at 16×16 it is still at a third of the answer.
    assert!(standard[2] < 0.5 * converged, "{standard:?}");
}

/// Largest |θ − 1| over the elements, θ = v/V their volume ratio.
fn volume_change(s: &Stepper, mesh: &Mesh) -> f64 {
    let mut worst: f64 = 0.0;
    for h in mesh.hexes() {
        let x = h.map(|n| mesh.nodes[n]);
        let u = h.map(|n| [s.state.u[3 * n], s.state.u[3 * n + 1], s.state.u[3 * n + 2]]);
        let gps = adhesim::element::hex8_geometry(&x).unwrap();
        worst = worst.max((volume_ratio(&gps, &u) - 1.0).abs());
    }
    worst
}

#[test]
fn block_under_large_shear_keeps_its_volume() {
    let mesh = generate::block([1.0, 1.0, 1.0], [4, 4, 4]);
    let s = sheared_block(&mesh, Formulation::FBar, NU);
    let dv = volume_change(&s, &mesh);
    eprintln!("large shear, ν = {NU}: max |J − 1| = {dv:.2e}");
    // κ/μ = 5000: the pressure, of the order of μ, changes the volume by ~2e-4.
    assert!(dv < 1e-3, "max |J − 1| = {dv}");
}

#[test]
fn fbar_patch_reproduces_a_large_homogeneous_deformation() {
    let mut mesh = generate::block([1.0, 1.0, 1.0], [3, 3, 3]);
    let boundary: std::collections::BTreeSet<usize> = mesh
        .boundary_faces()
        .iter()
        .flat_map(|f| f.nodes().to_vec())
        .collect();
    let mut rng = Rng(4242);
    for i in 0..mesh.num_nodes() {
        if !boundary.contains(&i) {
            for k in 0..3 {
                mesh.nodes[i][k] += 0.2 / 3.0 * rng.next();
            }
        }
    }
    let boundary: Vec<usize> = boundary.into_iter().collect();
    let err = homogeneous_patch_error(&mesh, &boundary, Formulation::FBar);
    // Newton stops at a relative residual of 1e-12; displacements are ~0.3 m.
    assert!(err < 1e-10, "max nodal error {err:e} m");
}
