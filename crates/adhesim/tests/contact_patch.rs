//! The contact patch test on non-matching meshes: a linear elastic block (1 × 0.5 × 1 m,
//! E = 1 MPa, ν = 0.3) on a block of the same size and material, frictionless, with
//! symmetry conditions on the faces x = 0 and z = 0 of both and the top pushed down by 1 mm.
//! The exact answer is a uniaxial stress: a uniform contact pressure E δ / H = 1000 Pa over
//! the whole interface (H = 1 m, both blocks) and a total force of 1000 N.
//!
//! Mortar contact passes it to round-off whatever the meshes and the contact solver:
//! pressure uniform to 1e-6 relative and force to 1e-8. The Newton and contact tolerances are
//! 1e-12, far below these, except for the augmented-Lagrangian solve (`newton`), whose
//! multiplier ρ of a thousand times the stiffness at a point leaves a round-off floor near
//! 1e-9: it runs at 1e-9 (its force then comes out within 2e-10; at 1e-8 the force is within
//! that tolerance, 1.03e-8 on the matching meshes with dual multipliers). Node-to-surface contact,
//! shown beside it, passes only on matching meshes.
//!
//! The same test with both blocks of second-order tetrahedra (six-node triangle faces):
//! a site's pressure is its force over its measure (the integral of its multiplier function),
//! and no site may pull. And with both blocks of 27-node hexahedra (nine-node quadrilateral
//! faces), structured and with the interface nodes moved within the interface.

use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;

/// The exact contact pressure [Pa].
const PRESSURE: f64 = 1000.0;

fn scenario(slave: usize, master: usize, discretisation: &str, solver: &str) -> String {
    let tol = if solver == "newton" { 1e-9 } else { 1e-12 };
    format!(
        r#"
[time]
t_end = 1.0
dt = 1.0
mode = "quasi-static"
newton_tol = {tol:e}
contact_solver = "{solver}"
contact_tol = {tol:e}
[[body]]
name = "lower"
mesh = {{ generator = "block", size = [1.0, 0.5, 1.0], divisions = [{master}, 2, {master}] }}
material = {{ model = "linear-elastic", young = 1e6, poisson = 0.3 }}
density = 1000.0
[[body]]
name = "upper"
mesh = {{ generator = "block", size = [1.0, 0.5, 1.0], divisions = [{slave}, 2, {slave}] }}
material = {{ model = "linear-elastic", young = 1e6, poisson = 0.3 }}
density = 1000.0
offset = [0.0, 0.5, 0.0]
[[boundary]]
body = "lower"
set = "bottom"
fix = ["y"]
[[boundary]]
body = "upper"
set = "top"
fix = []
displacement = {{ y = [[0.0, 0.0], [1.0, -1e-3]] }}
[[boundary]]
body = "lower"
set = "left"
fix = ["x"]
[[boundary]]
body = "upper"
set = "left"
fix = ["x"]
[[boundary]]
body = "lower"
set = "back"
fix = ["z"]
[[boundary]]
body = "upper"
set = "back"
fix = ["z"]
[[contact]]
name = "interface"
slave = {{ body = "upper", set = "bottom" }}
master = {{ body = "lower", set = "top" }}
friction = 0.0
detection_distance = 0.01
discretisation = "{discretisation}"
"#
    )
}

/// Largest relative deviation of the slave nodes' pressure from the exact one, and the total
/// contact force [N].
fn patch(slave: usize, master: usize, discretisation: &str, solver: &str) -> (f64, f64) {
    let text = scenario(slave, master, discretisation, solver);
    let problem = adhesim_io::scenario::parse(&text, Path::new("patch.toml"))
        .unwrap()
        .problem;
    let pair = problem.contacts[0].clone();
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let sites = &s.contact[0];
    let force: f64 = sites.iter().map(|c| c.force[1]).sum();
    let worst = sites
        .iter()
        .zip(&pair.slave_area)
        .map(|(c, a)| ((c.force[1] / a) - PRESSURE).abs() / PRESSURE)
        .fold(0.0, f64::max);
    (worst, force)
}

#[test]
fn mortar_passes_the_contact_patch_test_on_non_matching_meshes() {
    for (slave, master) in [(7, 10), (10, 7), (4, 13), (10, 10)] {
        for solver in ["gauss-seidel", "semismooth", "newton"] {
            let (worst, force) = patch(slave, master, "mortar", solver);
            eprintln!(
                "mortar {slave}×{slave} on {master}×{master}, {solver}: pressure error \
                 {worst:.1e}, force {force:.10} N"
            );
            assert!(
                worst < 1e-6,
                "{slave} on {master}, {solver}: pressure off by {worst:e}"
            );
            let force_error = (force - PRESSURE).abs() / PRESSURE;
            assert!(
                force_error < 1e-8,
                "{slave} on {master}, {solver}: force {force}"
            );
        }
    }
}

#[test]
fn node_to_surface_fails_it_where_the_meshes_do_not_match() {
    for (slave, master) in [(7, 10), (10, 7)] {
        let (worst, force) = patch(slave, master, "node-to-surface", "gauss-seidel");
        eprintln!(
            "node-to-surface {slave}×{slave} on {master}×{master}: {worst:.1e}, {force:.6} N"
        );
        assert!(worst > 0.01, "{slave} on {master}: {worst}");
    }
    let (worst, force) = patch(10, 10, "node-to-surface", "gauss-seidel");
    eprintln!("node-to-surface 10×10 on 10×10: {worst:.1e}, {force:.6} N");
    assert!(worst < 1e-6 && (force - PRESSURE).abs() < 1e-8 * PRESSURE);
    let (worst, force) = patch(4, 13, "node-to-surface", "gauss-seidel");
    eprintln!("node-to-surface 4×4 on 13×13: {worst:.1e}, {force:.6} N");
    // The master nodes sink into the coarse slave faces: a fifth of the force is lost.
    assert!(worst > 0.1 && force < 0.9 * PRESSURE, "{worst}, {force}");
}

mod common;

use adhesim::contact::detect::{flat_quads, local_faces, tributary_areas};
use adhesim::contact::{ContactPair, InterfaceLaw, Master, PairDiscretisation};
use adhesim::material::LinearElastic;
use adhesim::mesh::Mesh;
use adhesim::problem::{Body, ContactSolver, Problem, TimeSettings};
use common::{fixed, ramp, Cells};

/// The patch test with both blocks of the cells `cells` (`slave` and `master` hexahedra
/// across, each split into six tetrahedra for tet4 and tet10), built here because the
/// scenario's generator makes hexahedra only. Returns, per slave node, its site's normal
/// force [N] and the site's measure [m²] (the integral of the node's multiplier function,
/// for a six-node triangle a corner 1/12 of the face and a mid-side node 1/4), and the
/// total force [N].
fn quadratic_patch(
    cells: Cells,
    slave: usize,
    master: usize,
    discretisation: PairDiscretisation,
    solver: ContactSolver,
) -> (Vec<(f64, f64)>, f64) {
    quadratic_patch_on(
        cells.block([1.0, 0.5, 1.0], [slave, 2, slave]),
        cells.block([1.0, 0.5, 1.0], [master, 2, master]),
        discretisation,
        solver,
    )
}

/// Moves the `nodes` of a 1 × 0.5 × 1 block of `n` × 2 × `n` cells at random by up to `shake`
/// of a cell's size along each axis, except along the axes of the block's faces they are on
/// (an interface node stays in the interface's plane); one draw of `seed`'s sequence per node
/// and axis, in the order given.
fn shake_along_faces(
    mesh: &mut Mesh,
    nodes: impl IntoIterator<Item = usize>,
    n: usize,
    shake: f64,
    seed: u64,
) {
    let on = |name: &str| -> std::collections::HashSet<usize> {
        mesh.node_sets[name].iter().copied().collect()
    };
    let fixed_axis = [
        [on("left"), on("right")],
        [on("bottom"), on("top")],
        [on("back"), on("front")],
    ];
    let h = [1.0 / n as f64, 0.25, 1.0 / n as f64];
    let mut rng = common::Rng(seed);
    for i in nodes {
        for k in 0..3 {
            let shift = shake * h[k] * rng.next();
            if !fixed_axis[k].iter().any(|s| s.contains(&i)) {
                mesh.nodes[i][k] += shift;
            }
        }
    }
}

/// The tet10 block of `n` × 2 × `n` hexahedra split, its corner nodes moved at random by up
/// to a fifth of a hexahedron's size along the faces they are on (the interface nodes within
/// the interface's plane) and its mid-side nodes put back at the middle of their edges: an
/// unstructured interface, straight-sided elements.
fn shaken_tet10_block(n: usize, seed: u64) -> Mesh {
    let mut mesh = Cells::Tet10.block([1.0, 0.5, 1.0], [n, 2, n]);
    let cells = mesh.cells_of::<10>(&adhesim::element::TET10).to_vec();
    let corners: std::collections::BTreeSet<usize> =
        cells.iter().flat_map(|c| c[..4].to_vec()).collect();
    shake_along_faces(&mut mesh, corners, n, 0.2, seed);
    for c in &cells {
        for (m, [i, j]) in adhesim::element::TET10_EDGES.iter().enumerate() {
            let (a, b) = (mesh.nodes[c[*i]], mesh.nodes[c[*j]]);
            mesh.nodes[c[4 + m]] = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
        }
    }
    assert!(adhesim::mesh::quality::inverted_cells(&mesh).is_empty());
    mesh
}

/// [`quadratic_patch`] on the meshes `upper` (slave) and `lower` (master), both 1 × 0.5 × 1
/// with their corner at the origin (the upper one is lifted here).
fn quadratic_patch_on(
    mut upper: Mesh,
    lower: Mesh,
    discretisation: PairDiscretisation,
    solver: ContactSolver,
) -> (Vec<(f64, f64)>, f64) {
    upper.nodes.iter_mut().for_each(|x| x[1] += 0.5);
    let off = lower.num_nodes();
    let shift = |ns: &[usize]| ns.iter().map(|n| n + off).collect::<Vec<_>>();
    let slave_set = upper.node_sets["bottom"].clone();
    let slave_faces = &upper.face_sets["bottom"];
    let local = local_faces(slave_faces, &slave_set);
    let slave_area = tributary_areas(slave_faces, &upper.nodes, &slave_set);
    let material = Arc::new(LinearElastic::from_young_poisson(1e6, 0.3));
    let body = |name: &str, mesh: &Mesh| Body {
        name: name.into(),
        mesh: mesh.clone(),
        material: material.clone(),
        density: 1000.0,
        initial_velocity: [0.0; 3],
        element: Default::default(),
        plane_strain: false,
    };
    let mut push = fixed(shift(&upper.node_sets["top"]), [false, true, false]);
    push.translation[1] = ramp(-1e-3);
    let tol = if solver == ContactSolver::Newton {
        1e-8
    } else {
        1e-12
    };
    let problem = Problem {
        name: "patch".into(),
        bodies: vec![body("lower", &lower), body("upper", &upper)],
        dirichlet: vec![
            fixed(lower.node_sets["bottom"].clone(), [false, true, false]),
            fixed(lower.node_sets["left"].clone(), [true, false, false]),
            fixed(lower.node_sets["back"].clone(), [false, false, true]),
            fixed(shift(&upper.node_sets["left"]), [true, false, false]),
            fixed(shift(&upper.node_sets["back"]), [false, false, true]),
            push,
        ],
        loads: vec![],
        gravity: Default::default(),
        time: TimeSettings {
            t_end: 1.0,
            dt: 1.0,
            quasi_static: true,
            newton_tol: tol,
            contact_tol: tol,
            contact_solver: solver,
            ..TimeSettings::default()
        },
        contacts: vec![ContactPair {
            name: "interface".into(),
            slave_nodes: shift(&slave_set),
            slave_area: slave_area.clone(),
            master: Master::Faces(lower.face_sets["top"].clone()),
            law: InterfaceLaw::rcc(0.0, None, None),
            detection_distance: 0.01,
            slave_quads: flat_quads(&local),
            slave_faces: local,
            thickness_twins: vec![],
            discretisation,
        }],
    };
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let sites: Vec<(f64, f64)> = s.contact[0]
        .iter()
        .zip(&slave_area)
        .map(|(c, &a)| (c.force[1], a))
        .collect();
    let force = sites.iter().map(|s| s.0).sum();
    (sites, force)
}

/// Largest relative deviation of the sites' pressure (force over measure) from the exact
/// one, and the most negative site force [N].
fn pressure_error(sites: &[(f64, f64)]) -> (f64, f64) {
    let worst = sites
        .iter()
        .map(|&(f, a)| (f / a - PRESSURE).abs() / PRESSURE)
        .fold(0.0, f64::max);
    let lowest = sites.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
    (worst, lowest)
}

/// The structured patch tests of the quadratic cells `cells` (named `name`, the meshes
/// described by `meshes`) with mortar and each contact solver: the total force to 1e-8, every
/// site's pressure to 1e-6, and no site pulls.
fn mortar_passes_on_structured_meshes(cells: Cells, name: &str, meshes: &str) {
    for (slave, master) in [(2, 3), (3, 2), (1, 4), (3, 3)] {
        for solver in [
            ContactSolver::GaussSeidel,
            ContactSolver::Semismooth,
            ContactSolver::Newton,
        ] {
            let (sites, force) =
                quadratic_patch(cells, slave, master, PairDiscretisation::Mortar, solver);
            let (worst, lowest) = pressure_error(&sites);
            eprintln!(
                "{name} mortar {slave}×{slave} on {master}×{master}{meshes}, {solver:?}: {} \
                 sites, pressure error {worst:.1e}, lowest site force {lowest:.4} N, force \
                 {force:.10} N",
                sites.len()
            );
            let force_error = (force - PRESSURE).abs() / PRESSURE;
            assert!(
                force_error < 1e-8,
                "{slave} on {master}, {solver:?}: force {force}"
            );
            assert!(
                worst < 1e-6,
                "{slave} on {master}, {solver:?}: pressure off by {worst:e}"
            );
            assert!(lowest > 0.0, "{slave} on {master}: a site pulls");
        }
    }
}

#[test]
fn mortar_passes_the_contact_patch_test_on_quadratic_faces() {
    mortar_passes_on_structured_meshes(Cells::Tet10, "tet10", " (hexahedra split)");
    // Unstructured interfaces: both blocks' nodes moved within their faces.
    for (slave, master) in [(2, 3), (3, 2)] {
        let (sites, force) = quadratic_patch_on(
            shaken_tet10_block(slave, 7),
            shaken_tet10_block(master, 8),
            PairDiscretisation::Mortar,
            ContactSolver::Semismooth,
        );
        let (worst, lowest) = pressure_error(&sites);
        eprintln!(
            "tet10 mortar, shaken {slave}×{slave} on shaken {master}×{master}, Semismooth: \
             pressure error {worst:.1e}, lowest site force {lowest:.4} N, force {force:.10} N"
        );
        assert!((force - PRESSURE).abs() < 1e-8 * PRESSURE, "force {force}");
        assert!(worst < 1e-6, "pressure off by {worst:e}");
        assert!(lowest > 0.0);
    }
    for (slave, master) in [(2, 3), (3, 2), (1, 4), (3, 3)] {
        let (sites, force) = quadratic_patch(
            Cells::Tet10,
            slave,
            master,
            PairDiscretisation::NodeToSurface,
            ContactSolver::GaussSeidel,
        );
        let (worst, lowest) = pressure_error(&sites);
        eprintln!(
            "tet10 node-to-surface {slave}×{slave} on {master}×{master}: pressure error \
             {worst:.1e}, lowest site force {lowest:.4} N, force {force:.6} N"
        );
    }
}

/// The hex27 block of `n` × 2 × `n` hexahedra whose nodes were moved at random by up to
/// `shake` of a hexahedron's size along the faces they are on (the interface nodes within the
/// interface's plane) before the mid-edge, face-centre and cell-centre nodes were added where
/// a straight-sided cell has them: an unstructured interface of nine-node faces.
fn shaken_hex27_block(n: usize, shake: f64, seed: u64) -> Mesh {
    let mut mesh = Cells::Hex8.block([1.0, 0.5, 1.0], [n, 2, n]);
    let all = 0..mesh.num_nodes();
    shake_along_faces(&mut mesh, all, n, shake, seed);
    let mesh = mesh.with_mid_side_nodes().with_face_and_centre_nodes();
    assert!(adhesim::mesh::quality::inverted_cells(&mesh).is_empty());
    mesh
}

/// The integral over the faces `faces` of each node of `nodes`' weight on their flat pieces
/// (the mortar measure of a fully covered slave node): a triangle piece gives each of its
/// nodes a third of its area, a quadrilateral piece ∫ φ_a dA of its bilinear hat φ_a, by the
/// 2 × 2 Gauss rule, exact for a flat piece (φ_a and the area density both bilinear). On a
/// parallelogram that is a quarter of its area. Written here apart from `tributary_areas`,
/// which must give the same (the test checks it).
fn piece_measures(faces: &[adhesim::mesh::Face], x: &[[f64; 3]], nodes: &[usize]) -> Vec<f64> {
    use nalgebra::Vector3;
    let index: std::collections::HashMap<usize, usize> =
        nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
    let mut measure = vec![0.0; nodes.len()];
    let g = 1.0 / 3f64.sqrt();
    for f in faces {
        for piece in f.flat_pieces() {
            let ns: Vec<usize> = piece.iter().map(|&c| f.nodes()[c]).collect();
            let p: Vec<Vector3<f64>> = ns.iter().map(|&n| Vector3::from(x[n])).collect();
            let mut share = vec![0.0; ns.len()];
            if ns.len() == 3 {
                let area = 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
                share.iter_mut().for_each(|s| *s = area / 3.0);
            } else {
                for (s, t) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
                    let hat = [
                        0.25 * (1.0 - s) * (1.0 - t),
                        0.25 * (1.0 + s) * (1.0 - t),
                        0.25 * (1.0 + s) * (1.0 + t),
                        0.25 * (1.0 - s) * (1.0 + t),
                    ];
                    let ds = 0.25 * ((p[1] - p[0]) * (1.0 - t) + (p[2] - p[3]) * (1.0 + t));
                    let dt = 0.25 * ((p[3] - p[0]) * (1.0 - s) + (p[2] - p[1]) * (1.0 + s));
                    let jac = ds.cross(&dt).norm();
                    for a in 0..4 {
                        share[a] += hat[a] * jac;
                    }
                }
            }
            for (n, s) in ns.iter().zip(share) {
                if let Some(&i) = index.get(n) {
                    measure[i] += s;
                }
            }
        }
    }
    measure
}

/// The contact patch test with both blocks of 27-node hexahedra (nine-node faces on both
/// sides of the interface): mortar recovers the uniform pressure and the total force as on
/// the six-node faces above, to the same tolerances (1e-6 on the pressure, 1e-8 on the force:
/// far above the 1e-12 Newton and contact tolerances, 1e-8 for the augmented Lagrangian), and
/// no site pulls. A site's measure is the integral of its multiplier function, the bilinear
/// hat of the face's quarters (a corner 1/16 of a flat face, a mid-side node 1/8, the centre
/// 1/4).
///
/// On unstructured interfaces (nodes moved within the faces, the faces' quarters no longer
/// parallelograms) the shape functions are not polynomials of the physical coordinates in
/// which mortar integrates the overlaps (a rule exact to degree 5), and the pressure is
/// uniform only to that rule's error: 1.3e-6 and 1.4e-5 with the nodes moved by up to a
/// fifth of a cell (test: 1e-4), falling with the distortion (1.6e-8 and 4.3e-7 at a
/// twentieth; test: 1e-6, as on straight meshes). The tributary areas are the integrals of
/// the hats there too, equal to `piece_measures` to 5.0e-16 (test: 1e-13; a quarter of each
/// quarter's area, as they were, put the same forces off by 1.8 and 4.8 % at a fifth).
///
/// Node-to-surface on the same meshes does not pass: a site's pressure is off by more than
/// 10 % on every mesh, matching ones included (its forces follow the quad9's consistent
/// loads, 1/36, 1/9 and 4/9 of a face for a corner, a mid-side node and the centre, not the
/// tributary areas); a scenario refuses it between two bodies on quad9 faces
/// (tests/hex27.rs).
#[test]
fn mortar_passes_the_contact_patch_test_on_nine_node_faces() {
    mortar_passes_on_structured_meshes(Cells::Hex27, "hex27", "");
    // Unstructured interfaces: both blocks' nodes moved within their faces. The quarters of
    // the slave faces are no longer parallelograms: a site's pressure is its force over the
    // integral of its hat (`piece_measures`), which its tributary area must equal.
    for (shake, tol) in [(0.2, 1e-4), (0.05, 1e-6)] {
        for (slave, master) in [(2, 3), (3, 2)] {
            let upper = shaken_hex27_block(slave, shake, 7);
            let measure = piece_measures(
                &upper.face_sets["bottom"],
                &upper.nodes,
                &upper.node_sets["bottom"],
            );
            let (sites, force) = quadratic_patch_on(
                upper,
                shaken_hex27_block(master, shake, 8),
                PairDiscretisation::Mortar,
                ContactSolver::Semismooth,
            );
            let (by_tributary_area, _) = pressure_error(&sites);
            let area_error = sites
                .iter()
                .zip(&measure)
                .map(|(s, &m)| (s.1 - m).abs() / m)
                .fold(0.0, f64::max);
            assert!(area_error < 1e-13, "tributary areas off by {area_error:e}");
            let sites: Vec<(f64, f64)> =
                sites.iter().zip(&measure).map(|(s, &m)| (s.0, m)).collect();
            let (worst, lowest) = pressure_error(&sites);
            eprintln!(
            "hex27 mortar, {slave}×{slave} on {master}×{master} shaken by {shake}, Semismooth: \
             pressure error {worst:.1e} (over the tributary areas {by_tributary_area:.1e}, \
             which differ from the integrals by {area_error:.1e}), \
             lowest site force {lowest:.4} N, force {force:.10} N"
        );
            assert!((force - PRESSURE).abs() < 1e-8 * PRESSURE, "force {force}");
            assert!(worst < tol, "{shake}: pressure off by {worst:e}");
            assert!(lowest > 0.0);
        }
    }
    for (slave, master) in [(2, 3), (3, 2), (1, 4), (3, 3)] {
        let (sites, force) = quadratic_patch(
            Cells::Hex27,
            slave,
            master,
            PairDiscretisation::NodeToSurface,
            ContactSolver::GaussSeidel,
        );
        let (worst, lowest) = pressure_error(&sites);
        eprintln!(
            "hex27 node-to-surface {slave}×{slave} on {master}×{master}: pressure error \
             {worst:.1e}, lowest site force {lowest:.4} N, force {force:.6} N"
        );
        assert!(worst > 0.1, "{slave} on {master}: {worst}");
    }
}
