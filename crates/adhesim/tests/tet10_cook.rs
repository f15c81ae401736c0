//! Cook's membrane (plane strain, E = 250, ν = 0.4999, a shear load on its free edge) on
//! ten-node tetrahedra with the locking-free option (`element = "fbar"`: element-mean
//! dilatation): the tip deflection converges to the reference value of the F-bar hex8 test
//! (tests/fbar_locking.rs: 7.771, CalculiX's 20-node hexahedra refined to 256² and
//! extrapolated, the set-up checked against the converged value of FinEALE's example;
//! docs/elements.md); the standard tet10 is stiffer on the same mesh.

use adhesim::fbar::Formulation;
use adhesim::material::UncoupledNeoHookean;
use adhesim::mesh::generate;
use adhesim::problem::{NodalLoad, Table};
use std::sync::Arc;

mod common;
use common::*;

/// Converged vertical deflection of the top right corner (48, 60) for F = 100 (see
/// tests/fbar_locking.rs and bench/cook/run.sh).
const COOK_REFERENCE: f64 = 7.771;

/// The membrane's vertical corner deflection per F = 100 on n × n quadrilaterals, each cut
/// into six tetrahedra with mid-side nodes, one layer thick, with the element kinematics
/// `element`. The load is 1e-4 of the benchmark's (linear regime): a uniform shear
/// traction on the face x = 48, lumped to its consistent nodal forces (a six-node
/// triangle's corners take none, each mid-side node a third).
fn cook_tet10(n: usize, element: Formulation) -> f64 {
    let mut mesh = generate::block([1.0, 1.0, 1.0], [n, n, 1]);
    for x in &mut mesh.nodes {
        let (xi, eta) = (x[0], x[1]);
        *x = [48.0 * xi, 44.0 * xi + eta * (44.0 - 28.0 * xi), x[2]];
    }
    let mesh = mesh.split_hexes_into_tets().with_mid_side_nodes();
    let material = UncoupledNeoHookean::from_young_poisson(250.0, 0.4999);
    let mut p = one_body(
        mesh.clone(),
        Arc::new(material),
        1.0,
        quasi_static(1.0, 1.0),
    );
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-10;
    p.dirichlet
        .push(fixed((0..mesh.num_nodes()).collect(), [false, false, true]));
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true, true, false]));
    let scale = 1e-4;
    // The face x = 48 is 16 × 1: traction F / 16 per unit area.
    let traction = 100.0 * scale / 16.0;
    for face in &mesh.face_sets["right"] {
        let n6 = face.nodes();
        assert_eq!(face.face_type().name, adhesim::element::TRI6.name);
        let x = |k: usize| mesh.nodes[n6[k]];
        let (a, b) = (sub(x(1), x(0)), sub(x(2), x(0)));
        let area = 0.5 * norm(cross(a, b));
        for &mid in &n6[3..] {
            p.loads.push(NodalLoad {
                nodes: vec![mid],
                total_force: [
                    Table::constant(0.0),
                    ramp(traction * area / 3.0),
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
    assert_eq!(corner.len(), 3, "the corner's nodes at z = 0, 1/2, 1");
    let s = solve(p);
    corner.iter().map(|&i| s.state.u[3 * i + 1]).sum::<f64>() / corner.len() as f64 / scale
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

#[test]
fn cooks_membrane_on_locking_free_tet10_converges_to_the_reference() {
    let ns = [4, 8, 16, 32];
    let fbar: Vec<f64> = ns
        .iter()
        .map(|&n| cook_tet10(n, Formulation::FBar))
        .collect();
    let standard = cook_tet10(8, Formulation::Standard);
    for (n, f) in ns.iter().zip(&fbar) {
        eprintln!(
            "tet10, element-mean dilatation, {n}×{n}: {f:.4} ({:+.2} % of {COOK_REFERENCE})",
            100.0 * (f / COOK_REFERENCE - 1.0)
        );
    }
    eprintln!(
        "tet10, standard, 8×8: {standard:.4} ({:+.2} %)",
        100.0 * (standard / COOK_REFERENCE - 1.0)
    );
    let finest = *fbar.last().unwrap();
    assert!(
        (finest / COOK_REFERENCE - 1.0).abs() < 0.01,
        "32×32: {finest}"
    );
    assert!(fbar
        .windows(2)
        .all(|w| (w[1] - COOK_REFERENCE).abs() < (w[0] - COOK_REFERENCE).abs()));
    // The standard tet10 (4-point rule) locks mildly at ν = 0.4999: stiffer than the
    // locking-free one on the same mesh.
    assert!(
        standard < fbar[1],
        "standard {standard} against {}",
        fbar[1]
    );
}
