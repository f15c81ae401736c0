//! The quadratic tetrahedron (tet10) on the structured meshes of `generate`, each hexahedron
//! split into six tetrahedra with a node at the middle of every edge:
//!
//! - patch tests on a distorted mesh (straight-sided elements): a linear field in small
//!   strain and a large homogeneous deformation are reproduced to the Newton tolerance;
//! - the element tangent against central differences of the internal force, with and
//!   without the element-constant volume change (`element = "fbar"`);
//! - a 3-D cantilever under a small tip load converges under refinement, its observed order
//!   from three meshes (Richardson), and 2 layers through the thickness are within 2 % of
//!   the extrapolated value, where the linear and the averaged-nodal-pressure tetrahedra are
//!   far off;
//! - ν = 0.4999: the constant-pressure form (F-bar, `element = "fbar"`) does not lock (the
//!   plane-strain cantilever within 3 % of the converged answer) and keeps each element's
//!   volume to 1e-3 under large shear.

use adhesim::element::{element_response, tet10_geometry, Tet10, TET10};
use adhesim::fbar::{fbar_element_response, volume_ratio, Formulation};
use adhesim::material::{Hyperelastic, NeoHookean, UncoupledNeoHookean};
use adhesim::mesh::Mesh;
use std::sync::Arc;

mod common;
use common::*;

/// A unit cube of n³ hexahedra as tet10, every corner node off the boundary moved at random
/// by up to `shake` of a hexahedron's size and the mid-side nodes kept at the middle of their
/// (straight) edges, and the boundary nodes. (A curved tet10 has a Jacobian of degree 3,
/// which the 4-point rule does not integrate exactly, so curved elements pass the patch
/// test only approximately, as with the usual C3D10.)
fn shaken_cube(n: usize, shake: f64, seed: u64) -> (Mesh, Vec<usize>) {
    let mut mesh = Cells::Tet10.block([1.0; 3], [n, n, n]);
    let boundary = shake_interior(&mut mesh, n, shake, seed);
    straighten_mid_edges::<10>(&mut mesh, &TET10, &adhesim::element::TET10_EDGES);
    assert!(adhesim::mesh::quality::inverted_cells(&mesh).is_empty());
    (mesh, boundary)
}

#[test]
fn mesh_of_tet10_is_conforming_and_its_faces_are_six_node_triangles() {
    let mesh = Cells::Tet10.block([2.0, 1.0, 0.5], [4, 3, 2]);
    let tets = Cells::Tet4.block([2.0, 1.0, 0.5], [4, 3, 2]);
    assert_eq!(mesh.cells_of::<10>(&TET10).len(), tets.tets().len());
    // Euler: nodes = corners + edges of the tet mesh, each edge's middle node shared.
    let boundary = mesh.boundary_faces();
    assert_eq!(boundary.len(), tets.boundary_faces().len());
    assert!(boundary.iter().all(|f| f.is_quadratic()));
    adhesim::mesh::quality::check_faces_outward(&mesh).expect("outward face sets");
    for (name, faces) in &tets.face_sets {
        assert_eq!(mesh.face_sets[name].len(), faces.len(), "{name}");
    }
    let material: Arc<dyn Hyperelastic> = Arc::new(NeoHookean::from_young_poisson(1.0, 0.3));
    let disc = adhesim::assembly::Discretisation::new(&[(&mesh, material)]).unwrap();
    assert!((disc.volume() - 1.0).abs() < 1e-12);
}

#[test]
fn small_strain_patch_reproduces_a_linear_field() {
    let (mesh, boundary) = shaken_cube(2, 0.2, 11);
    let err = linear_patch_error(&mesh, &boundary);
    // Displacements ~1e-3 m; the solve is linear, so the error is round-off.
    assert!(err < 1e-13, "max nodal error {err:e} m");
}

#[test]
fn large_strain_patch_reproduces_a_homogeneous_deformation() {
    let (mesh, boundary) = shaken_cube(2, 0.2, 12);
    for element in [Formulation::Standard, Formulation::FBar] {
        let err = homogeneous_patch_error(&mesh, &boundary, element);
        // Newton stops at a relative residual of 1e-12; displacements are ~0.3 m.
        assert!(err < 1e-10, "{element:?}: max nodal error {err:e} m");
    }
}

/// Largest |K_fd − K| / max |K| for the element kernel `response` at `u`, by central
/// differences of the force with a step of 1e-7 m on an element of size 1e-2 m.
fn tangent_error(
    response: impl Fn(&[[f64; 3]; 10], bool) -> adhesim::element::ElementResponse<10>,
    u: &[[f64; 3]; 10],
) -> f64 {
    let k = response(u, true).tangent.unwrap();
    let kmax = (0..10)
        .flat_map(|a| (0..10).map(move |b| (a, b)))
        .map(|(a, b)| k[a][b].abs().max())
        .fold(0.0, f64::max);
    let h = 1e-7;
    let mut err: f64 = 0.0;
    for b in 0..10 {
        for j in 0..3 {
            let (mut up, mut um) = (*u, *u);
            up[b][j] += h;
            um[b][j] -= h;
            let (fp, fm) = (response(&up, false).force, response(&um, false).force);
            for a in 0..10 {
                for i in 0..3 {
                    let fd = (fp[a][i] - fm[a][i]) / (2.0 * h);
                    err = err.max((fd - k[a][b][(i, j)]).abs());
                }
            }
        }
    }
    err / kmax
}

#[test]
fn tangent_matches_finite_differences_of_the_internal_force() {
    let s = 0.01;
    let mut rng = Rng(2024);
    // A curved tet10: corners of a skewed tetrahedron, mid-side nodes off their edges.
    let corners = [
        [0.0, 0.0, 0.0],
        [s, 0.1 * s, 0.0],
        [0.2 * s, s, 0.1 * s],
        [0.1 * s, 0.2 * s, s],
    ];
    let mut x = [[0.0; 3]; 10];
    x[..4].copy_from_slice(&corners);
    for (m, [i, j]) in [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]]
        .iter()
        .enumerate()
    {
        x[4 + m] = std::array::from_fn(|k| {
            0.5 * (corners[*i][k] + corners[*j][k]) + 0.05 * s * rng.next()
        });
    }
    let gps = tet10_geometry(&x).expect("a valid curved tet10");
    let u: [[f64; 3]; 10] = std::array::from_fn(|_| std::array::from_fn(|_| 0.1 * s * rng.next()));
    let materials: Vec<Box<dyn Hyperelastic>> = vec![
        Box::new(NeoHookean::from_young_poisson(2.0e6, 0.3)),
        Box::new(UncoupledNeoHookean::from_young_poisson(2.0e6, 0.45)),
        Box::new(adhesim::material::BlatzKo { g: 1.0e6 }),
    ];
    for mat in &materials {
        let standard = tangent_error(|u, t| element_response(&gps, u, mat.as_ref(), t), &u);
        let fbar = tangent_error(|u, t| fbar_element_response(&gps, u, mat.as_ref(), t), &u);
        // Central differences: truncation O(h²) ~ 1e-10 relative, round-off ~1e-9.
        assert!(
            standard < 1e-6 && fbar < 1e-6,
            "{mat:?}: {standard:e} {fbar:e}"
        );
    }
}

#[test]
fn mass_adds_up_to_the_element_mass() {
    let x: [[f64; 3]; 10] = std::array::from_fn(|a| TET10.natural_nodes[a].map(|c| 2.0 * c));
    let gps = tet10_geometry(&x).unwrap();
    let m = <Tet10 as adhesim::element::Element<10, 4>>::mass(&gps, 1000.0);
    let total: f64 = m.iter().flatten().sum();
    // Volume 8/6 m³ at 1000 kg/m³.
    assert!((total - 8000.0 / 6.0).abs() < 1e-9 * total, "{total}");
}

/// Tip deflection of the square-section cantilever (L/h = 10, ν = 0.3, small tip load) per
/// Euler-Bernoulli, `ny` layers through the thickness.
fn cantilever_3d(ny: usize, cells: Cells, element: Formulation) -> f64 {
    cantilever_beam_of(ny, cells, element, 0.3, Section::Square)
}

#[test]
fn cantilever_converges_and_two_layers_are_within_two_percent() {
    let d: Vec<f64> = [1, 2, 4]
        .iter()
        .map(|&n| cantilever_3d(n, Cells::Tet10, Formulation::Standard))
        .collect();
    let order = ((d[1] - d[0]) / (d[2] - d[1])).log2();
    let converged = d[2] + (d[2] - d[1]) / (2f64.powf(order) - 1.0);
    let tet4 = cantilever_3d(2, Cells::Tet4, Formulation::Standard);
    let hex8 = cantilever_3d(2, Cells::Hex8, Formulation::Standard);
    eprintln!(
        "tet10 cantilever, 1, 2, 4 layers: {:.5} {:.5} {:.5}; observed order {order:.2}, \
         extrapolated {converged:.5}; 2 layers: tet4 {tet4:.4}, hex8 {hex8:.4}",
        d[0], d[1], d[2]
    );
    assert!(
        d.windows(2).all(|w| w[1] > w[0]),
        "not converging from below: {d:?}"
    );
    // Quadratic elements: the tip deflection (a compliance) converges at about h², less
    // than the smooth h⁴ because of the clamp's corner singularities.
    assert!(order > 1.5, "observed order {order}");
    let err2 = (d[1] - converged).abs() / converged;
    assert!(
        err2 < 0.02,
        "2 layers: {err2:.4} off the extrapolated value"
    );
    // Euler-Bernoulli plus Timoshenko's shear term, (E/(κG)) (h/L)²/4 = 0.0078 for
    // ν = 0.3 (κ = 5/6), with the clamp's restraint of the cross-section: within 1 %.
    assert!((converged - 1.0078).abs() < 0.01, "{converged}");
    assert!(tet4 < 0.6 * converged, "linear tet4 at 2 layers: {tet4}");
}

#[test]
fn constant_pressure_form_does_not_lock_and_keeps_the_volume() {
    const NU: f64 = 0.4999;
    let plane = |ny: usize, element| {
        cantilever_beam_of(
            ny,
            Cells::Tet10,
            element,
            NU,
            Section::PlaneStrain { nu_load: NU },
        )
    };
    let (fbar, standard) = (plane(4, Formulation::FBar), plane(4, Formulation::Standard));
    // The converged answer of this model: 0.996 of Euler-Bernoulli (the F-bar hexahedra's
    // Richardson extrapolation in tests/fbar_locking.rs, an independent discretisation).
    let converged = 0.996;
    eprintln!(
        "plane-strain cantilever ν = {NU}, 4 layers: tet10 F-bar {fbar:.4}, standard {standard:.4}"
    );
    assert!(
        (fbar - converged).abs() < 0.03 * converged,
        "F-bar tet10: {fbar}"
    );
    let mesh = Cells::Tet10.block([1.0; 3], [3, 3, 3]);
    let s = sheared_block(&mesh, Formulation::FBar, NU);
    let mut worst: f64 = 0.0;
    for c in mesh.cells_of::<10>(&TET10) {
        let x = c.map(|n| mesh.nodes[n]);
        let u = c.map(|n| [s.state.u[3 * n], s.state.u[3 * n + 1], s.state.u[3 * n + 2]]);
        let gps = tet10_geometry(&x).unwrap();
        worst = worst.max((volume_ratio(&gps, &u) - 1.0).abs());
    }
    eprintln!("large shear, ν = {NU}: max |θ − 1| = {worst:.2e}");
    // κ/μ = 5000: a pressure of the order of μ changes the volume by ~2e-4.
    assert!(worst < 1e-3, "max |θ − 1| = {worst}");
}
