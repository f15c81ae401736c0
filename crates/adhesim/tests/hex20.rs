//! The quadratic (serendipity) hexahedron (hex20) on the structured meshes of `generate`
//! with a node at the middle of every edge:
//!
//! - patch tests on a distorted mesh (straight-sided elements): a linear field in small
//!   strain and a large homogeneous deformation (standard and linear-pressure form) are
//!   reproduced to round-off and to the Newton tolerance;
//! - the element tangent against central differences of the internal force: standard, with
//!   the element-constant volume change (F-bar, Q2/P0) and with the linear one (Q2/P1, what
//!   `element = "fbar"` uses on a hex20);
//! - the consistent mass against a 4 × 4 × 4 Gauss rule, and its total ρV;
//! - a 3-D cantilever under a small tip load converges under refinement (1, 2, 4 layers),
//!   with its observed order and Richardson extrapolation, 2 layers within 2 %;
//! - ν = 0.4999: the linear-pressure form does not lock (within 3 % of the converged
//!   plane-strain cantilever with 4 layers, closer with 8) and keeps each element's volume
//!   under large shear;
//! - a Gmsh hex20 mesh is read with its mid-edge nodes at the middles of their edges;
//!   node-to-surface contact between two bodies on its eight-node faces is refused, and
//!   mortar between non-matching eight-node faces passes the contact patch test.

use adhesim::dilatation::{linear_dilatation_response, LinearDilatation};
use adhesim::element::{
    element_response, hex20_geometry, hex20_shape, Element, Hex20, HEX20, HEX20_EDGES, QUAD8,
};
use adhesim::fbar::{fbar_element_response, Formulation};
use adhesim::material::{Hyperelastic, NeoHookean, UncoupledNeoHookean};
use adhesim::mesh::Mesh;
use std::path::Path;
use std::sync::Arc;

mod common;
use common::*;

/// Moves every mid-edge node of every hex20 of `mesh` to the middle of its edge.
fn straighten_edges(mesh: &mut Mesh) {
    straighten_mid_edges::<20>(mesh, &HEX20, &HEX20_EDGES);
}

/// A unit cube of n³ hex20, every corner node off the boundary moved at random by up to
/// `shake` of a hexahedron's size and the mid-edge nodes kept at the middle of their
/// (straight) edges, and its boundary nodes.
fn shaken_cube(n: usize, shake: f64, seed: u64) -> (Mesh, Vec<usize>) {
    let mut mesh = Cells::Hex20.block([1.0; 3], [n, n, n]);
    let boundary = shake_interior(&mut mesh, n, shake, seed);
    straighten_edges(&mut mesh);
    assert!(adhesim::mesh::quality::inverted_cells(&mesh).is_empty());
    (mesh, boundary)
}

#[test]
fn mesh_of_hex20_is_conforming_and_its_faces_are_eight_node_quadrilaterals() {
    let mesh = Cells::Hex20.block([2.0, 1.0, 0.5], [4, 3, 2]);
    let hexes = Cells::Hex8.block([2.0, 1.0, 0.5], [4, 3, 2]);
    assert_eq!(mesh.cells_of::<20>(&HEX20).len(), hexes.hexes().len());
    // Nodes: the corners and one per edge of the hexahedral mesh (5·4·3 corners; edges
    // 4·4·3 + 5·3·3 + 5·4·2).
    assert_eq!(mesh.num_nodes(), 60 + 48 + 45 + 40);
    let boundary = mesh.boundary_faces();
    assert_eq!(boundary.len(), hexes.boundary_faces().len());
    assert!(boundary.iter().all(|f| *f.face_type() == QUAD8));
    adhesim::mesh::quality::check_faces_outward(&mesh).expect("outward face sets");
    for (name, faces) in &hexes.face_sets {
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
    eprintln!("hex20 small-strain patch: max nodal error {err:.2e} m");
    // Displacements ~1e-3 m; the solve is linear, so the error is round-off.
    assert!(err < 1e-13, "max nodal error {err:e} m");
}

#[test]
fn large_strain_patch_reproduces_a_homogeneous_deformation() {
    let (mesh, boundary) = shaken_cube(2, 0.2, 12);
    for element in [Formulation::Standard, Formulation::FBar] {
        let err = homogeneous_patch_error(&mesh, &boundary, element);
        eprintln!("hex20 large-strain patch, {element:?}: max nodal error {err:.2e} m");
        // Newton stops at a relative residual of 1e-12; displacements are ~0.3 m.
        assert!(err < 1e-10, "{element:?}: max nodal error {err:e} m");
    }
}

/// Largest |K_fd − K| / max |K| for the element kernel `response` at `u`, by central
/// differences of the force with a step of 1e-7 m on an element of size 1e-2 m.
fn tangent_error(
    response: impl Fn(&[[f64; 3]; 20], bool) -> adhesim::element::ElementResponse<20>,
    u: &[[f64; 3]; 20],
) -> f64 {
    let k = response(u, true).tangent.unwrap();
    let kmax = (0..20)
        .flat_map(|a| (0..20).map(move |b| (a, b)))
        .map(|(a, b)| k[a][b].abs().max())
        .fold(0.0, f64::max);
    let h = 1e-7;
    let mut err: f64 = 0.0;
    for b in 0..20 {
        for j in 0..3 {
            let (mut up, mut um) = (*u, *u);
            up[b][j] += h;
            um[b][j] -= h;
            let (fp, fm) = (response(&up, false).force, response(&um, false).force);
            for a in 0..20 {
                for i in 0..3 {
                    let fd = (fp[a][i] - fm[a][i]) / (2.0 * h);
                    err = err.max((fd - k[a][b][(i, j)]).abs());
                }
            }
        }
    }
    err / kmax
}

/// A curved hex20 of size `s` [m]: the natural cube skewed, every node moved at random by
/// up to 5 % of `s`.
fn curved_hex20(s: f64, rng: &mut Rng) -> [[f64; 3]; 20] {
    std::array::from_fn(|a| {
        let xi = HEX20.natural_nodes[a];
        let skewed = [
            xi[0] + 0.2 * xi[1],
            xi[1] + 0.1 * xi[2],
            xi[2] + 0.15 * xi[0],
        ];
        std::array::from_fn(|k| 0.5 * s * skewed[k] + 0.05 * s * rng.next())
    })
}

#[test]
fn tangent_matches_finite_differences_of_the_internal_force() {
    let s = 0.01;
    let mut rng = Rng(2024);
    let x = curved_hex20(s, &mut rng);
    let gps = hex20_geometry(&x).expect("a valid curved hex20");
    let lin = LinearDilatation::new(&gps, &x).expect("the Gauss points span the element");
    let u: [[f64; 3]; 20] = std::array::from_fn(|_| std::array::from_fn(|_| 0.1 * s * rng.next()));
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
        eprintln!("hex20 tangent vs central differences, {mat:?}: standard {standard:.1e}, F-bar {fbar:.1e}, linear pressure {linear:.1e}");
        // Central differences: truncation O(h²) ~ 1e-10 relative, round-off ~1e-9.
        assert!(
            standard < 1e-6 && fbar < 1e-6 && linear < 1e-6,
            "{mat:?}: {standard:e} {fbar:e} {linear:e}"
        );
    }
}

/// m_ab = ρ ∫ N_a N_b dV by the n × n × n Gauss-Legendre rule (n = 4: exact to degree 7 in
/// each coordinate) on the hex20 with nodes `x`.
fn mass_by_gauss(x: &[[f64; 3]; 20], density: f64) -> [[f64; 20]; 20] {
    let line = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    let mut m = [[0.0; 20]; 20];
    for &(a, wa) in &line {
        for &(b, wb) in &line {
            for &(c, wc) in &line {
                let (n, dn) = hex20_shape([a, b, c]);
                let mut j = nalgebra::Matrix3::<f64>::zeros();
                for (p, d) in x.iter().zip(&dn) {
                    for i in 0..3 {
                        for k in 0..3 {
                            j[(i, k)] += p[i] * d[k];
                        }
                    }
                }
                let w = wa * wb * wc * j.determinant() * density;
                for (p, np) in n.iter().enumerate() {
                    for (q, nq) in n.iter().enumerate() {
                        m[p][q] += w * np * nq;
                    }
                }
            }
        }
    }
    m
}

#[test]
fn consistent_mass_matches_a_higher_order_rule_and_adds_up_to_the_element_mass() {
    let density = 1000.0;
    // A parallelepiped: constant Jacobian, the products N_a N_b of degree 4 in each
    // coordinate, integrated exactly by both the 3- and the 4-point rules.
    let affine: [[f64; 3]; 20] = std::array::from_fn(|a| {
        let xi = HEX20.natural_nodes[a];
        [xi[0] + 0.3 * xi[1], 0.5 * xi[1] + 0.2 * xi[2], 0.8 * xi[2]]
    });
    // A straight-sided, trilinearly distorted element: det J of degree 2 in each coordinate,
    // so the 3-point rule is not exact for N_a N_b det J, but it is for det J alone.
    let mut distorted = affine;
    distorted[6] = [2.0, 1.1, 1.2];
    distorted[1] = [0.9, -0.6, -0.4];
    for (m, [i, j]) in HEX20_EDGES.iter().enumerate() {
        distorted[8 + m] = std::array::from_fn(|k| 0.5 * (distorted[*i][k] + distorted[*j][k]));
    }
    for (name, x, tolerance) in [("affine", affine, 1e-14), ("distorted", distorted, 1e-2)] {
        let gps = hex20_geometry(&x).unwrap();
        let m = <Hex20 as Element<20, 27>>::mass(&gps, density);
        let reference = mass_by_gauss(&x, density);
        let largest = reference
            .iter()
            .flatten()
            .fold(0.0f64, |s, v| s.max(v.abs()));
        let diff = (0..20)
            .flat_map(|a| (0..20).map(move |b| (a, b)))
            .map(|(a, b)| (m[a][b] - reference[a][b]).abs())
            .fold(0.0, f64::max);
        let volume: f64 = gps.iter().map(|g| g.weight).sum();
        let total: f64 = m.iter().flatten().sum();
        let total_reference: f64 = reference.iter().flatten().sum();
        eprintln!(
            "hex20 mass, {name}: max |m(3³) − m(4³)| / max m = {:.1e}; total {total:.12e} kg, ρV = {:.12e} kg, 4³ total {total_reference:.12e} kg",
            diff / largest,
            density * volume
        );
        assert!(diff < tolerance * largest, "{name}: {diff:e}");
        assert!(
            (total - density * volume).abs() < 1e-12 * total,
            "{name}: {total}"
        );
        assert!((total_reference - total).abs() < 1e-12 * total, "{name}");
    }
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
        .map(|&n| cantilever_3d(n, Cells::Hex20, Formulation::Standard))
        .collect();
    let order = ((d[1] - d[0]) / (d[2] - d[1])).log2();
    let converged = d[2] + (d[2] - d[1]) / (2f64.powf(order) - 1.0);
    let hex8 = cantilever_3d(2, Cells::Hex8, Formulation::Standard);
    eprintln!(
        "hex20 cantilever, 1, 2, 4 layers: {:.5} {:.5} {:.5}; observed order {order:.2}, \
         extrapolated {converged:.5}; 2 layers hex8 {hex8:.4}",
        d[0], d[1], d[2]
    );
    let err2 = (d[1] - converged).abs() / converged;
    assert!(
        err2 < 0.02,
        "2 layers: {err2:.4} off the extrapolated value"
    );
    // Euler-Bernoulli plus Timoshenko's shear term, 0.0078 for ν = 0.3, with the clamp's
    // restraint of the cross-section: within 1 % (as the tet10's).
    assert!((converged - 1.0078).abs() < 0.01, "{converged}");
}

/// ν = 0.4999 with `element = "fbar"`, which on a hex20 takes each Gauss point's volume
/// change from the linear L² projection of J over the element (Q2/P1, a pressure linear in
/// each element). The element-constant volume change (Q2/P0) was too soft in bending: a
/// dilatation varying linearly across an element cost it no volumetric energy (4 layers
/// 1.0469, 5.1 % above the converged answer; 8 layers 1.0095). With the linear one the
/// bending dilatation is penalised: within 3 % of the converged answer at 4 layers (it comes
/// slightly from below, as the standard hex20 does, and closer with 8 layers), and each
/// element keeps its volume under large shear.
#[test]
fn linear_pressure_form_does_not_lock_and_keeps_the_volume() {
    const NU: f64 = 0.4999;
    let plane = |ny: usize, element| {
        cantilever_beam_of(
            ny,
            Cells::Hex20,
            element,
            NU,
            Section::PlaneStrain { nu_load: NU },
        )
    };
    let linear: Vec<f64> = [4, 8].map(|n| plane(n, Formulation::FBar)).to_vec();
    // The converged answer of this model: 0.996 of Euler-Bernoulli (the F-bar hexahedra's
    // Richardson extrapolation in tests/fbar_locking.rs, an independent discretisation).
    let converged = 0.996;
    eprintln!(
        "plane-strain cantilever ν = {NU}, 4 and 8 layers: hex20 linear pressure {:.4} {:.4}",
        linear[0], linear[1]
    );
    assert!(
        (linear[0] - converged).abs() < 0.03 * converged,
        "hex20 with the linear pressure, 4 layers: {}",
        linear[0]
    );
    assert!(
        (linear[1] - converged).abs() < (linear[0] - converged).abs(),
        "closer with 8 layers: {linear:?}"
    );
    let mesh = Cells::Hex20.block([1.0; 3], [2, 2, 2]);
    let s = sheared_block(&mesh, Formulation::FBar, NU);
    let mut worst: f64 = 0.0;
    for c in mesh.cells_of::<20>(&HEX20) {
        let x = c.map(|n| mesh.nodes[n]);
        let u = c.map(|n| [s.state.u[3 * n], s.state.u[3 * n + 1], s.state.u[3 * n + 2]]);
        let gps = hex20_geometry(&x).unwrap();
        worst = worst.max((adhesim::fbar::volume_ratio(&gps, &u) - 1.0).abs());
    }
    eprintln!("hex20 linear pressure, large shear, ν = {NU}: max |v/V − 1| = {worst:.2e}");
    // κ/μ = 5000: a pressure of the order of μ changes the volume by ~2e-4.
    assert!(worst < 1e-3, "max |v/V − 1| = {worst}");
}

#[test]
fn gmsh_hex20_mesh_is_read_in_vtk_order() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/box_hex20.msh");
    let msh = adhesim::mesh::gmsh::read(&path).unwrap();
    let body = msh.body(None).unwrap();
    let mesh = &body.mesh;
    let cells = mesh.cells_of::<20>(&HEX20);
    assert_eq!((cells.len(), mesh.num_cells()), (12, 12));
    // Every mid-edge node at the middle of its two corners (the box is straight-sided):
    // a node taken from the wrong place of Gmsh's list would sit at another edge's middle.
    let mut worst: f64 = 0.0;
    for c in cells {
        for (m, [i, j]) in HEX20_EDGES.iter().enumerate() {
            let (a, b, mid) = (mesh.nodes[c[*i]], mesh.nodes[c[*j]], mesh.nodes[c[8 + m]]);
            for k in 0..3 {
                worst = worst.max((mid[k] - 0.5 * (a[k] + b[k])).abs());
            }
        }
    }
    assert!(
        worst < 1e-12,
        "a mid-edge node {worst} m off its edge's middle"
    );
    assert!(adhesim::mesh::quality::inverted_cells(mesh).is_empty());
    // The box: a 2 × 1 base with one side sheared by 0.2, 0.5 high.
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
        assert!(faces.iter().all(|f| *f.face_type() == QUAD8), "{set}");
    }
    adhesim::mesh::quality::check_faces_outward(mesh).expect("outward quad8 face sets");
    // The bottom's outward normal is −z, the top's +z.
    for (set, sign) in [("bottom", -1.0), ("top", 1.0)] {
        let f = mesh.face_sets[set][0];
        let x: Vec<nalgebra::Vector3<f64>> = f
            .corners()
            .iter()
            .map(|&n| nalgebra::Vector3::from(mesh.nodes[n]))
            .collect();
        let normal = (x[1] - x[0]).cross(&(x[2] - x[0]));
        assert!(sign * normal[2] > 0.0, "{set}");
    }
}

#[test]
fn node_to_surface_between_bodies_is_refused_on_eight_node_faces() {
    let e = parse_two_boxes("box_hex20.msh", "node-to-surface")
        .err()
        .expect("node-to-surface on quad8 faces is refused")
        .to_string();
    assert!(
        e.contains("quad8") && e.contains("hex20") && e.contains("mortar"),
        "{e}"
    );
    let problem = parse_two_boxes("box_hex20.msh", "mortar")
        .expect("mortar on quad8 faces")
        .problem;
    let pair = &problem.contacts[0];
    assert!(pair.slave_faces.iter().all(|f| *f.face_type() == QUAD8));
    // Tributary areas: each quad8 face gives its corners 1/24 and its mid-side nodes 5/24
    // of its area; they add up to the face set's area (2.1 m²).
    let total: f64 = pair.slave_area.iter().sum();
    assert!((total - 2.1).abs() < 1e-12, "{total}");
    assert!(pair.slave_area.iter().all(|&a| a > 0.0));
}

/// The contact patch test of tests/contact_patch.rs on hex20 blocks (Gmsh,
/// tests/data/patch_hex20.msh): a 1 × 0.5 × 1 m linear elastic block (E = 1 MPa, ν = 0.3) of
/// 3 × 2 × 3 cells under one of 4 × 2 × 4 cells (or the other way round), frictionless
/// mortar contact between their eight-node faces, symmetry on x = 0 and z = 0, the top
/// pushed down by 1 mm: the exact answer is a uniform pressure E δ / H = 1000 Pa.
fn hex20_patch(upper: &str, lower: &str) -> (f64, f64) {
    let offset = |block: &str| if block == "fine" { -2.0 } else { 0.0 };
    let body = |name: &str, block: &str, y: f64| {
        format!(
            r#"
[[body]]
name = "{name}"
mesh = {{ file = "patch_hex20.msh", volumes = ["{block}"] }}
material = {{ model = "linear-elastic", young = 1e6, poisson = 0.3 }}
density = 1000.0
offset = [{}, {y}, 0.0]
"#,
            offset(block)
        )
    };
    let fix = |name: &str, set: &str, fix: &str| {
        format!("[[boundary]]\nbody = \"{name}\"\nset = \"{set}\"\nfix = [{fix}]\n")
    };
    let mut text = String::from(
        "[time]\nt_end = 1.0\ndt = 1.0\nmode = \"quasi-static\"\nnewton_tol = 1e-12\ncontact_tol = 1e-12\n",
    );
    text += &body("lower", lower, 0.0);
    text += &body("upper", upper, 0.5);
    text += &fix("lower", &format!("{lower}_bottom"), "\"y\"");
    for (name, block) in [("lower", lower), ("upper", upper)] {
        text += &fix(name, &format!("{block}_left"), "\"x\"");
        text += &fix(name, &format!("{block}_back"), "\"z\"");
    }
    text += &fix("upper", &format!("{upper}_top"), "");
    text += "displacement = { y = [[0.0, 0.0], [1.0, -1e-3]] }\n";
    text += &format!(
        r#"[[contact]]
name = "interface"
slave = {{ body = "upper", set = "{upper}_bottom" }}
master = {{ body = "lower", set = "{lower}_top" }}
friction = 0.0
detection_distance = 0.01
discretisation = "mortar"
"#
    );
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/patch_hex20.toml");
    let problem = adhesim_io::scenario::parse(&text, &path).unwrap().problem;
    let pair = problem.contacts[0].clone();
    let mut s = adhesim::time::Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let sites = &s.contact[0];
    let force: f64 = sites.iter().map(|c| c.force[1]).sum();
    let worst = sites
        .iter()
        .zip(&pair.slave_area)
        .map(|(c, a)| ((c.force[1] / a) - 1000.0).abs() / 1000.0)
        .fold(0.0, f64::max);
    (worst, force)
}

#[test]
fn mortar_on_eight_node_faces_passes_the_contact_patch_test() {
    for (upper, lower) in [("fine", "coarse"), ("coarse", "fine")] {
        let (worst, force) = hex20_patch(upper, lower);
        eprintln!(
            "hex20 mortar patch, {upper} on {lower}: pressure error {worst:.1e}, force {force:.10} N"
        );
        assert!(
            worst < 1e-6,
            "{upper} on {lower}: pressure off by {worst:e}"
        );
        assert!(
            (force - 1000.0).abs() < 1e-8 * 1000.0,
            "{upper} on {lower}: {force}"
        );
    }
}
