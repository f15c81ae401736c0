//! The triquadratic hexahedron (hex27) on the structured meshes of `generate` (each hex8 given
//! a node at the middle of every edge, the centre of every face and its centre) and from Gmsh:
//!
//! - patch tests on a distorted mesh (straight-sided elements): a linear field in small
//!   strain and a large homogeneous deformation, standard and with the linear volume change;
//! - the element tangent against central differences of the internal force, standard, with
//!   the element-constant and with the linear volume change;
//! - a Gmsh file of hex27 and quad9 written by Gmsh 4.15 (tests/data/box_hex27.py): nodes in
//!   their places, volume, face sets;
//! - the square cantilever (ν = 0.3) at 1 and 2 layers, and the plane-strain one at
//!   ν = 0.4999 with the linear volume change (Q2/P1, stable on this element): deflection and
//!   the pressure's oscillation at the clamp against the hex20's (tests/hex20_pressure.rs).

use adhesim::dilatation::{linear_dilatation_response, LinearDilatation};
use adhesim::element::{element_response, hex27_geometry, HEX20_EDGES, HEX27, QUAD9};
use adhesim::fbar::{fbar_element_response, Formulation};
use adhesim::material::{Hyperelastic, NeoHookean, UncoupledNeoHookean};
use adhesim::mesh::Mesh;
use std::path::Path;
use std::sync::Arc;

mod common;
use common::*;

/// A unit cube of n³ hex27, every node off the boundary moved at random by up to `shake` of a
/// cell and the mid-edge, face and centre nodes then put back where a straight-sided cell
/// has them; and the nodes of its boundary faces.
fn shaken_cube(n: usize, shake: f64, seed: u64) -> (Mesh, Vec<usize>) {
    let mut mesh = Cells::Hex20.block([1.0; 3], [n, n, n]);
    shake_interior(&mut mesh, n, shake, seed);
    straighten_mid_edges::<20>(&mut mesh, &adhesim::element::HEX20, &HEX20_EDGES);
    let mesh = mesh.with_face_and_centre_nodes();
    assert!(adhesim::mesh::quality::inverted_cells(&mesh).is_empty());
    let boundary: std::collections::BTreeSet<usize> = mesh
        .boundary_faces()
        .iter()
        .flat_map(|f| f.nodes().to_vec())
        .collect();
    (mesh, boundary.into_iter().collect())
}

#[test]
fn mesh_of_hex27_is_conforming_and_its_faces_are_nine_node_quadrilaterals() {
    let mesh = Cells::Hex27.block([2.0, 1.0, 0.5], [4, 3, 2]);
    assert_eq!(mesh.cells_of::<27>(&HEX27).len(), 24);
    // Nodes: the lattice of a 9 × 7 × 5 grid.
    assert_eq!(mesh.num_nodes(), 9 * 7 * 5);
    let boundary = mesh.boundary_faces();
    assert_eq!(boundary.len(), 2 * (4 * 3 + 3 * 2 + 4 * 2));
    assert!(boundary.iter().all(|f| *f.face_type() == QUAD9));
    adhesim::mesh::quality::check_faces_outward(&mesh).expect("outward face sets");
    for faces in mesh.face_sets.values() {
        assert!(faces.iter().all(|f| *f.face_type() == QUAD9));
    }
    // Node sets hold their faces' centres: the left face, 7 × 5 nodes.
    assert_eq!(mesh.node_sets["left"].len(), 7 * 5);
    let material: Arc<dyn Hyperelastic> = Arc::new(NeoHookean::from_young_poisson(1.0, 0.3));
    let disc = adhesim::assembly::Discretisation::new(&[(&mesh, material)]).unwrap();
    assert!((disc.volume() - 1.0).abs() < 1e-12);
}

#[test]
fn small_strain_patch_reproduces_a_linear_field() {
    let (mesh, boundary) = shaken_cube(2, 0.2, 11);
    let err = linear_patch_error(&mesh, &boundary);
    eprintln!("hex27 linear patch: {err:.1e} m");
    assert!(err < 1e-13, "{err}");
}

#[test]
fn large_strain_patch_reproduces_a_homogeneous_deformation() {
    let (mesh, boundary) = shaken_cube(2, 0.2, 5);
    for element in [Formulation::Standard, Formulation::FBar] {
        let err = homogeneous_patch_error(&mesh, &boundary, element);
        eprintln!("hex27 homogeneous patch, {element:?}: {err:.1e} m");
        assert!(err < 1e-10, "{element:?}: {err}");
    }
}

fn tangent_error(
    response: impl Fn(&[[f64; 3]; 27], bool) -> adhesim::element::ElementResponse<27>,
    u: &[[f64; 3]; 27],
) -> f64 {
    let k = response(u, true).tangent.unwrap();
    let kmax = (0..27)
        .flat_map(|a| (0..27).map(move |b| (a, b)))
        .map(|(a, b)| k[a][b].abs().max())
        .fold(0.0, f64::max);
    let h = 1e-7;
    let mut err: f64 = 0.0;
    for b in 0..27 {
        for j in 0..3 {
            let (mut up, mut um) = (*u, *u);
            up[b][j] += h;
            um[b][j] -= h;
            let (fp, fm) = (response(&up, false).force, response(&um, false).force);
            for a in 0..27 {
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
    // A curved hex27: the natural cube skewed, every node moved at random by up to 5 % of s.
    let x: [[f64; 3]; 27] = std::array::from_fn(|a| {
        let xi = HEX27.natural_nodes[a];
        let skewed = [
            xi[0] + 0.2 * xi[1],
            xi[1] + 0.1 * xi[2],
            xi[2] + 0.15 * xi[0],
        ];
        std::array::from_fn(|k| 0.5 * s * skewed[k] + 0.05 * s * rng.next())
    });
    let gps = hex27_geometry(&x).expect("a valid curved hex27");
    let lin = LinearDilatation::new(&gps, &x).expect("the Gauss points span the element");
    let u: [[f64; 3]; 27] = std::array::from_fn(|_| std::array::from_fn(|_| 0.1 * s * rng.next()));
    let materials: Vec<Box<dyn Hyperelastic>> = vec![
        Box::new(NeoHookean::from_young_poisson(2.0e6, 0.3)),
        Box::new(UncoupledNeoHookean::from_young_poisson(2.0e6, 0.45)),
        Box::new(adhesim::material::BlatzKo { g: 1.0e6 }),
    ];
    for mat in &materials {
        let standard = tangent_error(|u, t| element_response(&gps, u, mat.as_ref(), t), &u);
        let fbar = tangent_error(|u, t| fbar_element_response(&gps, u, mat.as_ref(), t), &u);
        let linear = tangent_error(
            |u, t| linear_dilatation_response(&gps, &lin, u, mat.as_ref(), t, None),
            &u,
        );
        eprintln!("hex27 tangent vs central differences, {mat:?}: standard {standard:.1e}, constant θ {fbar:.1e}, linear θ {linear:.1e}");
        assert!(
            standard < 1e-6 && fbar < 1e-6 && linear < 1e-6,
            "{mat:?}: {standard:e} {fbar:e} {linear:e}"
        );
    }
}

#[test]
fn gmsh_hex27_mesh_is_read_in_vtk_order() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/box_hex27.msh");
    let msh = adhesim::mesh::gmsh::read(&path).unwrap();
    let body = msh.body(None).unwrap();
    let mesh = &body.mesh;
    let cells = mesh.cells_of::<27>(&HEX27);
    assert_eq!((cells.len(), mesh.num_cells()), (12, 12));
    // Every node where its natural coordinates put it on the straight-sided cell: the
    // trilinear map of the corners (a node taken from the wrong place of Gmsh's list would
    // sit at another edge's or face's centre).
    let mut worst: f64 = 0.0;
    for c in cells {
        for (a, xi) in HEX27.natural_nodes.iter().enumerate() {
            let (n, _) = adhesim::element::hex8_shape(*xi);
            for k in 0..3 {
                let x: f64 = (0..8).map(|b| n[b] * mesh.nodes[c[b]][k]).sum();
                worst = worst.max((mesh.nodes[c[a]][k] - x).abs());
            }
        }
    }
    assert!(worst < 1e-12, "a node {worst} m off its place");
    assert!(adhesim::mesh::quality::inverted_cells(mesh).is_empty());
    let material: Arc<dyn Hyperelastic> = Arc::new(NeoHookean::from_young_poisson(1.0, 0.3));
    let disc = adhesim::assembly::Discretisation::new(&[(mesh, material)]).unwrap();
    assert!(
        (disc.volume() - 0.5 * 2.1).abs() < 1e-12,
        "{}",
        disc.volume()
    );
    for set in ["bottom", "top"] {
        let faces = &mesh.face_sets[set];
        assert_eq!(faces.len(), 6, "{set}");
        assert!(faces.iter().all(|f| *f.face_type() == QUAD9), "{set}");
    }
    adhesim::mesh::quality::check_faces_outward(mesh).expect("outward quad9 face sets");
}

/// Square cantilever (L/h = 10, ν = 0.3, small tip load): 1 and 2 layers against
/// Euler-Bernoulli, beside the hex20.
#[test]
fn cantilever_is_close_to_beam_theory() {
    for ny in [1, 2] {
        let hex27 = cantilever_beam_of(
            ny,
            Cells::Hex27,
            Formulation::Standard,
            0.3,
            Section::Square,
        );
        let hex20 = cantilever_beam_of(
            ny,
            Cells::Hex20,
            Formulation::Standard,
            0.3,
            Section::Square,
        );
        eprintln!(
            "square cantilever, {ny} layers: hex27 {hex27:.5}, hex20 {hex20:.5} of Euler-Bernoulli"
        );
        assert!((hex27 - 1.0).abs() < 0.02, "{ny}: {hex27}");
    }
    // ν = 0.4999, plane strain, the linear volume change: within 3 % of the converged 0.996
    // (tests/hex20.rs, tests/fbar_locking.rs) at 4 layers.
    let nearly = cantilever_beam_of(
        4,
        Cells::Hex27,
        Formulation::FBar,
        0.4999,
        Section::PlaneStrain { nu_load: 0.4999 },
    );
    eprintln!("plane-strain cantilever ν = 0.4999, 4 layers, hex27 Q2/P1: {nearly:.4}");
    assert!((nearly / 0.996 - 1.0).abs() < 0.03, "{nearly}");
}
