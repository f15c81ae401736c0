//! Patch test: on a distorted hex mesh, a homogeneous deformation u = A·X prescribed on the
//! boundary is reproduced at every interior node to round-off, for a linear and a strongly
//! nonlinear (Blatz-Ko, 30 % stretch) material.

use adhesim::material::{BlatzKo, Hyperelastic, LinearElastic};
use adhesim::mesh::generate;
use adhesim::problem::{Dirichlet, Table};
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

fn run_patch(material: Arc<dyn Hyperelastic>, a: [[f64; 3]; 3]) -> f64 {
    let mut mesh = generate::block([1.0, 1.0, 1.0], [3, 3, 3]);
    let boundary: std::collections::BTreeSet<usize> = mesh
        .boundary_faces()
        .iter()
        .flat_map(|f| f.nodes().to_vec())
        .collect();
    let mut rng = Rng(777);
    let h = 1.0 / 3.0;
    for i in 0..mesh.num_nodes() {
        if !boundary.contains(&i) {
            for k in 0..3 {
                mesh.nodes[i][k] += 0.2 * h * rng.next();
            }
        }
    }
    let field =
        |x: [f64; 3]| -> [f64; 3] { std::array::from_fn(|i| (0..3).map(|j| a[i][j] * x[j]).sum()) };
    let mut p = one_body(mesh.clone(), material, 1000.0, quasi_static(1.0, 1.0));
    for &n in &boundary {
        let u = field(mesh.nodes[n]);
        p.dirichlet.push(Dirichlet {
            nodes: vec![n],
            components: [true; 3],
            translation: u.map(|v| Table {
                t: vec![0.0, 1.0],
                v: vec![0.0, v],
            }),
            rotation: None,
        });
    }
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    s.step().unwrap();
    let mut err: f64 = 0.0;
    for i in 0..mesh.num_nodes() {
        let ue = field(mesh.nodes[i]);
        for k in 0..3 {
            err = err.max((s.state.u[3 * i + k] - ue[k]).abs());
        }
    }
    err
}

#[test]
fn linear_elastic_patch_reproduces_a_linear_field() {
    let a = [[1e-3, 2e-4, 0.0], [0.0, -5e-4, 3e-4], [1e-4, 0.0, 2e-3]];
    let err = run_patch(Arc::new(LinearElastic::from_young_poisson(1e6, 0.3)), a);
    assert!(
        err < 1e-13,
        "max nodal error {err:e} m for displacements ~1e-3 m"
    );
}

#[test]
fn blatz_ko_patch_reproduces_a_large_homogeneous_deformation() {
    // F = I + A: 30 % stretch, 20 % shear.
    let a = [[0.3, 0.2, 0.0], [0.0, -0.1, 0.05], [0.0, 0.0, 0.1]];
    let err = run_patch(Arc::new(BlatzKo { g: 1e6 }), a);
    // Newton stops at a relative residual of 1e-12; displacements are ~0.3 m.
    assert!(err < 1e-10, "max nodal error {err:e} m");
}
