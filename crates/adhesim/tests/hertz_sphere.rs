//! Hertz contact: a rigid sphere of radius R pressed by d into an elastic half-space,
//! frictionless, no adhesion. Linear theory: F = 4/3 E* √R d^(3/2), E* = E/(1 − ν²),
//! contact radius a = √(R d). The body is Blatz-Ko (small-strain E = 2.5 G, ν = ¼),
//! quasi-static, loaded in one step.
//!
//! Model. A quarter of the half-space (x ≥ 0, z ≥ 0, y ≤ 0) by symmetry, with the sphere's
//! centre above the corner x = z = 0. The half-space is truncated to a quarter ball of radius
//! 1000 a, clamped on its curved face; x is fixed on x = 0 and z on z = 0. The built-in
//! `block` is uniform, which cannot reach both a fine contact zone and a far boundary in a
//! test's time (a tensor-graded block of 40 a still over-estimates F by ~2 % from its size
//! alone), so the mesh is built here: a uniform cube of k³ cells (size h) around the contact
//! zone and shell layers whose radius grows by 1 + 1/k per layer, morphing from the cube's
//! faces to a sphere (elements of aspect ratio ~1 everywhere, sized ∝ distance to the load).
//!
//! Tolerance. Three meshes, h = a/2, a/4, a/6 (refined everywhere: core and shell growth).
//! What separates the finest meshes from the linear half-space solution (measured while
//! writing this test, by varying one parameter at a time):
//! - finite strain and exact contact geometry at a/R = 0.01: F is ≈ +0.3 % above linear
//!   Hertz (the excess scales like a/R: ≈ +1.5 % at a/R = 0.05);
//! - the clamped boundary at 1000 a: ≈ +0.1 % (∝ a/D: +0.35 % at D = 300 a);
//! - discretisation: with nodal contact forces the contact edge is sampled node by node, so
//!   the error is not monotone at the 0.1 % level once h ≤ a/4; h = a/2 is −1.3 %.
//!
//! The finest meshes are therefore asserted within 1 % of Hertz, the coarse one is asserted
//! to be worse than both, and the force differences between successive meshes must shrink.
//! The contact radius (outermost node with a positive normal force) must be within one
//! element size of a, and no node of the surface may penetrate the sphere.

use adhesim::contact::detect::{flat_quads, local_faces, tributary_areas};
use adhesim::contact::{
    ContactPair, InterfaceLaw, Master, PairDiscretisation, RigidMotion, RigidShape,
};
use adhesim::fbar::Formulation;
use adhesim::material::{BlatzKo, Hyperelastic, UncoupledNeoHookean};
use adhesim::mesh::{Face, Mesh};
use adhesim::problem::{Body, ContactSolver, Dirichlet, Problem, Table, TimeSettings};
use adhesim::time::Stepper;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

/// Sphere radius [m].
const R: f64 = 0.01;
/// Indentation [m]: d/R = 1e-4, a/R = 0.01.
const D: f64 = 1e-6;
/// Shear modulus [Pa].
const G: f64 = 1.0e6;
/// Radius of the truncated half-space, in contact radii.
const EXTENT: f64 = 1000.0;

/// Quarter of a half-space, radially graded: x ≥ 0, y ≤ 0, z ≥ 0, contact face y = 0.
///
/// Built in depth coordinates (x, −y, z): a uniform core cube [0, c]³ of k cells per edge,
/// and three shell blocks extruded from its faces x = c, −y = c, z = c in layers whose
/// radius grows geometrically to `outer` (factor ≈ `growth`), blending from the cube's faces
/// to a sphere over the first layers. Face sets (also node sets): `top` (y = 0), `sym_x`
/// (x = 0), `sym_z` (z = 0), `outer` (the sphere of radius `outer`).
fn graded_octant(c: f64, k: usize, growth: f64, outer: f64) -> Mesh {
    let layers = ((outer / c).ln() / growth.ln()).ceil() as usize;
    let g = (outer / c).powf(1.0 / layers as f64);
    // A cube corner sits √3 times farther out than a face centre; spreading the blend over
    // this many layers keeps every layer at least half its nominal thickness there.
    let blend = ((2.0 * (1.0 - 1.0 / 3f64.sqrt()) / (1.0 - 1.0 / g)).ceil() as usize).max(1);
    // Nodes keyed by (layer, i, j, l): layer 0 is the core grid, layer t ≥ 1 the t-th shell
    // surface over the cube-surface grid point (i, j, l) (one of them equal to k).
    let mut index: HashMap<[usize; 4], usize> = HashMap::new();
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    let mut node = |key: [usize; 4]| -> usize {
        *index.entry(key).or_insert_with(|| {
            let [t, i, j, l] = key;
            let q = [i, j, l].map(|v| v as f64 / k as f64);
            let p = if t == 0 {
                q.map(|v| v * c)
            } else {
                let rho = c * g.powi(t as i32);
                let s = (t as f64 / blend as f64).min(1.0);
                let nq = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                q.map(|v| rho * ((1.0 - s) * v + s * v / nq))
            };
            nodes.push([p[0], -p[1], p[2]]);
            nodes.len() - 1
        })
    };
    // Natural corners of a hex8 in VTK order.
    const CORNERS: [[usize; 3]; 8] = [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ];
    let mut hexes: Vec<[usize; 8]> = Vec::new();
    for i in 0..k {
        for j in 0..k {
            for l in 0..k {
                hexes.push(CORNERS.map(|o| node([0, i + o[0], j + o[1], l + o[2]])));
            }
        }
    }
    for axis in 0..3 {
        let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
        for u in 0..k {
            for v in 0..k {
                for t in 0..layers {
                    hexes.push(CORNERS.map(|o| {
                        let mut key = [t + o[2], 0, 0, 0];
                        key[1 + axis] = k;
                        key[1 + a1] = u + o[0];
                        key[1 + a2] = v + o[1];
                        node(key)
                    }));
                }
            }
        }
    }
    // The y flip mirrors every cell: restore a positive volume.
    for h in &mut hexes {
        let x = |n: usize| nodes[h[n]];
        let (e1, e2, e3) = (sub(x(1), x(0)), sub(x(3), x(0)), sub(x(4), x(0)));
        let vol = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0])
            + e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
        if vol < 0.0 {
            *h = [h[0], h[3], h[2], h[1], h[4], h[7], h[6], h[5]];
        }
    }
    let mut mesh = Mesh {
        nodes,
        ..Mesh::default()
    };
    mesh.add_cells(&adhesim::element::HEX8, hexes);
    let faces = mesh.boundary_faces();
    let pick = |on: &dyn Fn([f64; 3]) -> bool| -> Vec<Face> {
        faces
            .iter()
            .copied()
            .filter(|f| f.nodes().iter().all(|&n| on(mesh.nodes[n])))
            .collect()
    };
    let tol = 1e-9 * c;
    let top = pick(&|p| p[1].abs() <= tol);
    let sym_x = pick(&|p| p[0].abs() <= tol);
    let sym_z = pick(&|p| p[2].abs() <= tol);
    let far =
        pick(&|p| ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - outer).abs() <= 1e-9 * outer);
    assert_eq!(
        top.len() + sym_x.len() + sym_z.len() + far.len(),
        faces.len(),
        "unclassified boundary faces"
    );
    assert_eq!(top.len(), k * k + 2 * k * layers);
    mesh.set_faces("top", top);
    mesh.set_faces("sym_x", sym_x);
    mesh.set_faces("sym_z", sym_z);
    mesh.set_faces("outer", far);
    mesh
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn zero() -> Table {
    Table::constant(0.0)
}

fn fixed(nodes: Vec<usize>, components: [bool; 3]) -> Dirichlet {
    Dirichlet {
        nodes,
        components,
        translation: [zero(), zero(), zero()],
        rotation: None,
    }
}

/// What one indentation computed.
struct Indentation {
    /// Element size in the contact zone [m].
    h: f64,
    /// Force on the sphere, full model [N].
    force: f64,
    /// Reference radius of the outermost surface node with a positive normal force [m].
    radius: f64,
    /// Smallest gap between a surface node and the sphere at the end [m].
    min_gap: f64,
    dofs: usize,
    candidates: usize,
    newton: usize,
    seconds: f64,
}

/// Prints each run's force against Hertz's `f_hertz` [N], its contact radius in units of `a`
/// [m], its Newton iterations and its time, labelled `case` and the run's name.
fn report(case: &str, runs: &[(&str, &Indentation)], f_hertz: f64, a: f64) {
    for (name, r) in runs {
        eprintln!(
            "{case}, {name}: F = {:.5e} N ({:+.2} % off Hertz), contact radius {:.3} a, \
             {} Newton iterations in one step, {:.1} s",
            r.force,
            100.0 * (r.force / f_hertz - 1.0),
            r.radius / a,
            r.newton,
            r.seconds
        );
    }
}

/// Presses the sphere by D into the Blatz-Ko quarter half-space meshed with k cells across
/// the core cube of half-size 1.5 a (h = 1.5 a / k). Surface nodes within `detection` of the
/// sphere are contact candidates.
fn indent(k: usize, detection: f64, solver: ContactSolver) -> Indentation {
    indent_with(
        k,
        Arc::new(BlatzKo::new(G)),
        Formulation::Standard,
        detection,
        solver,
    )
}

/// As [`indent`] for any material and hexahedron formulation.
fn indent_with(
    k: usize,
    material: Arc<dyn Hyperelastic>,
    element: Formulation,
    detection: f64,
    solver: ContactSolver,
) -> Indentation {
    let a = (R * D).sqrt();
    let c = 1.5 * a;
    let mesh = graded_octant(c, k, 1.0 + 1.0 / k as f64, EXTENT * a);
    indent_on(mesh, c / k as f64, material, element, detection, solver)
}

/// As [`indent_with`] on a given mesh of the quarter half-space (with the face sets of
/// [`graded_octant`]) of element size `h` [m] in the contact zone.
fn indent_on(
    mesh: Mesh,
    h: f64,
    material: Arc<dyn Hyperelastic>,
    element: Formulation,
    detection: f64,
    solver: ContactSolver,
) -> Indentation {
    let top = mesh.node_sets["top"].clone();
    let area = tributary_areas(&mesh.face_sets["top"], &mesh.nodes, &top);
    let problem = Problem {
        name: "hertz".into(),
        bodies: vec![Body {
            name: "half_space".into(),
            mesh: mesh.clone(),
            material,
            density: 1000.0,
            initial_velocity: [0.0; 3],
            element,
            plane_strain: false,
        }],
        dirichlet: vec![
            fixed(mesh.node_sets["sym_x"].clone(), [true, false, false]),
            fixed(mesh.node_sets["sym_z"].clone(), [false, false, true]),
            fixed(mesh.node_sets["outer"].clone(), [true, true, true]),
        ],
        loads: vec![],
        gravity: Default::default(),
        // One quasi-static step: frictionless elastic contact does not depend on the path.
        time: TimeSettings {
            t_end: 1.0,
            dt: 1.0,
            quasi_static: true,
            contact_solver: solver,
            ..TimeSettings::default()
        },
        contacts: vec![ContactPair {
            name: "sphere".into(),
            slave_nodes: top.clone(),
            slave_area: area,
            master: Master::Rigid {
                shape: RigidShape::Sphere {
                    center: [0.0, R, 0.0],
                    radius: R,
                },
                motion: RigidMotion {
                    translation: [
                        zero(),
                        Table {
                            t: vec![0.0, 1.0],
                            v: vec![0.0, -D],
                        },
                        zero(),
                    ],
                    rotation: None,
                },
            },
            law: InterfaceLaw::rcc(0.0, None, None),
            // The no-penetration check below covers every surface node, candidate or not.
            detection_distance: detection,
            slave_quads: vec![],
            slave_faces: vec![],
            thickness_twins: vec![],
            discretisation: Default::default(),
        }],
    };
    let dofs = 3 * mesh.num_nodes();
    let clock = Instant::now();
    let mut s = Stepper::new(Arc::new(problem)).expect("valid mesh");
    let (mut candidates, mut newton) = (0, 0);
    while !s.finished() {
        let rep = s.step().expect("the indentation step converges");
        assert_eq!(rep.cutbacks, 0, "Δt was cut");
        candidates = rep.contact_points;
        newton += rep.newton_iterations;
    }
    let seconds = clock.elapsed().as_secs_f64();
    let mut fy = 0.0;
    let mut radius: f64 = 0.0;
    let mut min_gap = f64::INFINITY;
    let centre = [0.0, R - D, 0.0];
    for (i, nc) in s.contact[0].iter().enumerate() {
        fy += nc.force[1];
        let n = top[i];
        let x = mesh.nodes[n];
        if nc.r_dry[2] > 0.0 {
            radius = radius.max(x[0].hypot(x[2]));
        }
        let p: [f64; 3] = std::array::from_fn(|q| x[q] + s.state.u[3 * n + q]);
        let dp = sub(p, centre);
        min_gap = min_gap.min((dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]).sqrt() - R);
    }
    // fy is the force on the block (downwards); the sphere gets −fy; four quarters.
    Indentation {
        h,
        force: -4.0 * fy,
        radius,
        min_gap,
        dofs,
        candidates,
        newton,
        seconds,
    }
}

#[test]
fn hertz_force_and_contact_radius_converge_to_the_half_space_solution() {
    let a = (R * D).sqrt();
    let e_star = 2.5 * G / (1.0 - 0.25f64.powi(2));
    let f_hertz = 4.0 / 3.0 * e_star * R.sqrt() * D.powf(1.5);
    eprintln!(
        "Hertz: F = {f_hertz:.5e} N, a = {a:.4e} m (R = {R} m, d = {D:e} m, E* = {e_star:.4e} Pa)"
    );
    // Candidates: initial gap r²/2R < 0.75 d, i.e. r < 1.22 a.
    let runs: Vec<Indentation> = [3, 6, 9]
        .into_iter()
        .map(|k| indent(k, 0.75 * D, ContactSolver::GaussSeidel))
        .collect();
    let error = |r: &Indentation| r.force / f_hertz - 1.0;
    for r in &runs {
        eprintln!(
            "h = a/{:.0}: F = {:.5e} N (error {:+.2} %), contact radius {:.4e} m = {:.3} a, \
             {} dofs, {} contact candidates, {} Newton iterations, {:.1} s",
            a / r.h,
            r.force,
            100.0 * error(r),
            r.radius,
            r.radius / a,
            r.dofs,
            r.candidates,
            r.newton,
            r.seconds
        );
    }
    for r in &runs {
        assert!(
            r.min_gap > -1e-6 * D,
            "h = a/{:.0}: a surface node penetrates the sphere by {:e} m",
            a / r.h,
            -r.min_gap
        );
        assert!(
            (r.radius - a).abs() <= r.h,
            "h = a/{:.0}: contact radius {:e} m, a = {a:e} m",
            a / r.h,
            r.radius
        );
    }
    let (coarse, mid, fine) = (&runs[0], &runs[1], &runs[2]);
    // Successive refinements change the force less and less.
    assert!(
        (fine.force - mid.force).abs() < (mid.force - coarse.force).abs(),
        "no convergence: forces {:e}, {:e}, {:e}",
        coarse.force,
        mid.force,
        fine.force
    );
    // The refined meshes are closer to Hertz than the coarse one, and within the tolerance
    // explained at the top (≈ +0.4 % of model differences plus discretisation).
    for r in [mid, fine] {
        assert!(
            error(r).abs() < error(coarse).abs(),
            "h = a/{:.0} is no better than h = a/2",
            a / r.h
        );
        assert!(
            error(r).abs() < 0.01,
            "h = a/{:.0}: force error {:+.2} %",
            a / r.h,
            100.0 * error(r)
        );
    }
}

/// The same indentation with every one of the 2,219 surface nodes of the h = a/8 mesh a
/// contact candidate (the detection distance spans the whole face, so most candidates are
/// apart and must be found so): the contact solve without the Delassus operator handles them
/// in the same sparse Newton iterations. W would be 6,657² values (355 MB) built from 6,657
/// solves, which is why the Gauss-Seidel solver is not run here. Tolerance 3 %: the h = a/8
/// mesh is between the a/6 and a/9 meshes of the convergence test above (within 1 %), and
/// the candidates far from the sphere must not change the answer.
#[test]
fn hertz_with_two_thousand_contact_candidates() {
    hertz_with_every_surface_node_a_candidate(ContactSolver::Newton);
}

/// The same on the semismooth contact solve, which never forms W either.
#[test]
fn hertz_with_two_thousand_contact_candidates_semismooth() {
    hertz_with_every_surface_node_a_candidate(ContactSolver::Semismooth);
}

fn hertz_with_every_surface_node_a_candidate(solver: ContactSolver) {
    let a = (R * D).sqrt();
    let e_star = 2.5 * G / (1.0 - 0.25f64.powi(2));
    let f_hertz = 4.0 / 3.0 * e_star * R.sqrt() * D.powf(1.5);
    let r = indent(12, 1.0, solver);
    eprintln!(
        "{solver:?}, h = a/8, every surface node a candidate: F = {:.5e} N (error {:+.2} %), {} dofs, \
         {} contact candidates, {} Newton iterations, {:.1} s",
        r.force,
        100.0 * (r.force / f_hertz - 1.0),
        r.dofs,
        r.candidates,
        r.newton,
        r.seconds
    );
    assert!(r.candidates >= 2000, "{} candidates", r.candidates);
    assert!(
        (r.force / f_hertz - 1.0).abs() < 0.03,
        "force {:e} N against Hertz {f_hertz:e} N",
        r.force
    );
    assert!(
        (r.radius - a).abs() <= r.h,
        "contact radius {:e} m, a = {a:e} m",
        r.radius
    );
    assert!(r.min_gap > -1e-6 * D, "penetration {:e} m", -r.min_gap);
}

/// An uncoupled neo-Hookean half-space with the shear modulus G of this file and Poisson ratio
/// `nu`, and its Hertz force 4/3 E* √R d^(3/2) [N], E* = E/(1 − ν²).
fn nearly_incompressible(nu: f64) -> (Arc<dyn Hyperelastic>, f64) {
    let young = 2.0 * G * (1.0 + nu);
    let e_star = young / (1.0 - nu * nu);
    let f_hertz = 4.0 / 3.0 * e_star * R.sqrt() * D.powf(1.5);
    (
        Arc::new(UncoupledNeoHookean::from_young_poisson(young, nu)),
        f_hertz,
    )
}

/// Hertz on a nearly incompressible half-space (uncoupled neo-Hookean, ν = 0.4999, F-bar
/// hexahedra): F = 4/3 E* √R d^(3/2) with E* = E/(1 − ν²) ≈ 4μ. One mesh, h = a/4, within
/// 1 % in the Blatz-Ko study above, whose error budget (≈ +0.4 % of model differences, ≈ 1 % of
/// discretisation) applies here too; 3 % leaves room for what near-incompressibility adds to
/// the discretisation error of a low-order element. Full integration is shown beside it: it
/// locks and over-predicts the force.
#[test]
fn hertz_on_a_nearly_incompressible_half_space() {
    let nu = 0.4999;
    let (material, f_hertz) = nearly_incompressible(nu);
    let material = || material.clone();
    let fbar = indent_with(
        4,
        material(),
        Formulation::FBar,
        0.75 * D,
        ContactSolver::GaussSeidel,
    );
    let full = indent_with(
        4,
        material(),
        Formulation::Standard,
        0.75 * D,
        ContactSolver::GaussSeidel,
    );
    let a = (R * D).sqrt();
    report(
        &format!("ν = {nu}"),
        &[("F-bar", &fbar), ("full integration", &full)],
        f_hertz,
        a,
    );
    let err = fbar.force / f_hertz - 1.0;
    assert!(err.abs() < 0.03, "F-bar: force error {:+.2} %", 100.0 * err);
    assert!(
        fbar.min_gap > -1e-6 * D,
        "penetration {:e} m",
        -fbar.min_gap
    );
    assert!(
        (fbar.radius - a).abs() <= fbar.h,
        "contact radius {:e}",
        fbar.radius
    );
    assert!(
        full.force > fbar.force * 1.05,
        "full integration should lock: {:e} vs {:e}",
        full.force,
        fbar.force
    );
}

/// Hertz on the nearly incompressible half-space of the test above (ν = 0.4999), on
/// tetrahedra: the same graded mesh (k = 6, h = a/4) with each hexahedron split into six
/// tetrahedra, with the averaged-nodal-pressure element and with the linear tetrahedron.
/// Tolerance 3 %, as for the F-bar hexahedra above: ≈ +0.4 % of model differences (finite
/// strain, truncated half-space) and the discretisation error of a low-order element at
/// h = a/4 (+3.4 % at k = 4, +1.5 % at k = 6 when this test was written: converging).
#[test]
fn hertz_on_a_nearly_incompressible_half_space_of_tetrahedra() {
    let nu = 0.4999;
    let (material, f_hertz) = nearly_incompressible(nu);
    let material = || material.clone();
    let a = (R * D).sqrt();
    let (c, k) = (1.5 * a, 6);
    let hexes = graded_octant(c, k, 1.0 + 1.0 / k as f64, EXTENT * a);
    let mesh = hexes.split_hexes_into_tets();
    // Conforming split: every inner face is shared by two tetrahedra.
    assert_eq!(
        mesh.boundary_faces().len(),
        2 * hexes.boundary_faces().len()
    );
    let run = |element| {
        indent_on(
            mesh.clone(),
            c / k as f64,
            material(),
            element,
            0.75 * D,
            ContactSolver::GaussSeidel,
        )
    };
    let anp = run(Formulation::AveragedNodalPressure);
    let linear = run(Formulation::Standard);
    report(
        &format!("tetrahedra, ν = {nu}"),
        &[("averaged nodal pressure", &anp), ("linear tet4", &linear)],
        f_hertz,
        a,
    );
    let err = anp.force / f_hertz - 1.0;
    assert!(err.abs() < 0.03, "anp: force error {:+.2} %", 100.0 * err);
    assert!(anp.min_gap > -1e-6 * D, "penetration {:e} m", -anp.min_gap);
    assert!(
        (anp.radius - a).abs() <= anp.h,
        "contact radius {:e}",
        anp.radius
    );
    assert!(
        linear.force > 2.0 * f_hertz,
        "the linear tetrahedron should lock: {:e}",
        linear.force
    );
}

/// The quarter half-space of [`graded_octant`] turned into the other body of a two-body
/// Hertz contact: mirrored to y ≥ 0 (its cells and faces reordered to stay positively
/// oriented), and each node column lifted by the gap profile p(r) = r²/2R (continued by its
/// tangent beyond r = 10 a, so that the far cells are only sheared by a slope of 0.1), so
/// that its face `top` (now facing down) is Hertz's paraboloid.
fn paraboloid_octant(c: f64, k: usize, a: f64) -> Mesh {
    let mut mesh = graded_octant(c, k, 1.0 + 1.0 / k as f64, EXTENT * a);
    let r0 = 10.0 * a;
    let profile = |r: f64| {
        if r <= r0 {
            r * r / (2.0 * R)
        } else {
            r0 * r0 / (2.0 * R) + (r - r0) * r0 / R
        }
    };
    for x in &mut mesh.nodes {
        x[1] = -x[1] + profile(x[0].hypot(x[2]));
    }
    for block in &mut mesh.blocks {
        assert_eq!(block.element.nodes, 8, "the octant is made of hexahedra");
        for cell in block.connectivity.chunks_exact_mut(8) {
            let (lower, upper) = cell.split_at_mut(4);
            lower.swap_with_slice(upper);
        }
    }
    for faces in mesh.face_sets.values_mut() {
        for f in faces.iter_mut() {
            if let &[a0, a1, a2, a3] = f.nodes() {
                *f = Face::quad([a0, a3, a2, a1]);
            }
        }
    }
    mesh
}

/// Hertz between two soft bodies, on non-matching meshes with mortar contact: the
/// paraboloid body of [`paraboloid_octant`] (h = a/4) pressed by D into the quarter
/// half-space (h = a/4.7), both Blatz-Ko with G, so E* = E/(2(1 − ν²)) from the two. The
/// paraboloid's far boundary moves down by D, the half-space's is clamped. Tolerance 3 %:
/// the rigid-sphere test above reaches 1 % at these element sizes on one body; each
/// truncated body adds ≈ +0.1 % and the two meshes' discretisation errors add up.
/// Node-to-surface contact on the same meshes is printed beside it.
#[test]
fn hertz_between_two_soft_bodies_on_non_matching_mortar_meshes() {
    let e_star = 2.5 * G / (2.0 * (1.0 - 0.25f64.powi(2)));
    let f_hertz = 4.0 / 3.0 * e_star * R.sqrt() * D.powf(1.5);
    let force = two_body_hertz(PairDiscretisation::Mortar);
    let node_to_surface = two_body_hertz(PairDiscretisation::NodeToSurface);
    eprintln!(
        "Hertz {f_hertz:.5e} N; mortar {:+.2} %, node-to-surface {:+.2} %",
        100.0 * (force / f_hertz - 1.0),
        100.0 * (node_to_surface / f_hertz - 1.0)
    );
    assert!(
        (force / f_hertz - 1.0).abs() < 0.03,
        "F = {force:e}, Hertz {f_hertz:e}"
    );
}

/// The force [N] of the two-body indentation with the pair discretised by `discretisation`.
fn two_body_hertz(discretisation: PairDiscretisation) -> f64 {
    let a = (R * D).sqrt();
    let c = 1.5 * a;
    let lower = graded_octant(c, 7, 1.0 + 1.0 / 7.0, EXTENT * a);
    let upper = paraboloid_octant(c, 6, a);
    let off = lower.num_nodes();
    let shift = |ns: &[usize]| ns.iter().map(|n| n + off).collect::<Vec<_>>();
    let slave_nodes = shift(&upper.node_sets["top"]);
    let slave_faces = &upper.face_sets["top"];
    let local = local_faces(slave_faces, &upper.node_sets["top"]);
    let slave_area = tributary_areas(slave_faces, &upper.nodes, &upper.node_sets["top"]);
    let master: Vec<Face> = lower.face_sets["top"].clone();
    let body = |name: &str, mesh: &Mesh| Body {
        name: name.into(),
        mesh: mesh.clone(),
        material: Arc::new(BlatzKo::new(G)),
        density: 1000.0,
        initial_velocity: [0.0; 3],
        element: Formulation::Standard,
        plane_strain: false,
    };
    let mut push = fixed(shift(&upper.node_sets["outer"]), [true, true, true]);
    push.translation[1] = Table {
        t: vec![0.0, 1.0],
        v: vec![0.0, -D],
    };
    let problem = Problem {
        name: "hertz-two-bodies".into(),
        bodies: vec![body("half_space", &lower), body("paraboloid", &upper)],
        dirichlet: vec![
            fixed(lower.node_sets["sym_x"].clone(), [true, false, false]),
            fixed(lower.node_sets["sym_z"].clone(), [false, false, true]),
            fixed(lower.node_sets["outer"].clone(), [true, true, true]),
            fixed(shift(&upper.node_sets["sym_x"]), [true, false, false]),
            fixed(shift(&upper.node_sets["sym_z"]), [false, false, true]),
            push,
        ],
        loads: vec![],
        gravity: Default::default(),
        time: TimeSettings {
            t_end: 1.0,
            dt: 1.0,
            quasi_static: true,
            contact_solver: ContactSolver::Semismooth,
            ..TimeSettings::default()
        },
        contacts: vec![ContactPair {
            name: "hertz".into(),
            slave_nodes,
            slave_area,
            master: Master::Faces(master),
            law: InterfaceLaw::rcc(0.0, None, None),
            // Candidates: initial gap r²/2R < 1.5 d, i.e. r < 1.7 a.
            detection_distance: 1.5 * D,
            slave_quads: flat_quads(&local),
            slave_faces: local,
            thickness_twins: vec![],
            discretisation,
        }],
    };
    let clock = Instant::now();
    let mut s = Stepper::new(Arc::new(problem)).expect("valid meshes");
    let mut newton = 0;
    while !s.finished() {
        let rep = s.step().expect("the indentation step converges");
        newton += rep.newton_iterations;
    }
    // The force on the paraboloid, four quarters.
    let force = 4.0 * s.contact[0].iter().map(|c| c.force[1]).sum::<f64>();
    eprintln!(
        "two soft bodies, {discretisation:?}, h = a/4 on a/4.7: F = {force:.5e} N, \
         {newton} Newton iterations, {} dofs, {:.1} s",
        s.disc.num_dofs(),
        clock.elapsed().as_secs_f64()
    );
    force
}

/// Accuracy against cost of the element types on one problem (docs/elements.md): the
/// nearly incompressible Hertz indentation above (ν = 0.4999, rigid sphere, a/R = 0.01) on
/// the graded octant with k cells across the core (h = 1.5 a / k), as F-bar hexahedra, as
/// those hexahedra split into six linear tetrahedra (standard and averaged nodal pressure),
/// and as the split with a node at the middle of every edge (tet10, constant pressure per
/// element). Prints force error, contact radius, Newton iterations, unknowns and wall time
/// of each run; the k values come from `HERTZ_TABLE_K` (default "2 4 6").
#[test]
#[ignore = "a measurement: cargo test --release -p adhesim --test hertz_sphere element_cost_table -- --ignored --nocapture"]
fn element_cost_table() {
    let nu = 0.4999;
    let (material, f_hertz) = nearly_incompressible(nu);
    let a = (R * D).sqrt();
    let ks: Vec<usize> = std::env::var("HERTZ_TABLE_K")
        .unwrap_or_else(|_| "2 4 6".into())
        .split_whitespace()
        .map(|k| k.parse().unwrap())
        .collect();
    for k in ks {
        let c = 1.5 * a;
        let hexes = graded_octant(c, k, 1.0 + 1.0 / k as f64, EXTENT * a);
        let tets = hexes.split_hexes_into_tets();
        let tet10 = tets.with_mid_side_nodes();
        let run = |mesh: &Mesh, element| {
            indent_on(
                mesh.clone(),
                c / k as f64,
                material.clone(),
                element,
                0.75 * D,
                ContactSolver::Auto,
            )
        };
        for (name, mesh, element) in [
            ("hex8 F-bar", &hexes, Formulation::FBar),
            ("tet4", &tets, Formulation::Standard),
            ("tet4 anp", &tets, Formulation::AveragedNodalPressure),
            ("tet10 constant pressure", &tet10, Formulation::FBar),
        ] {
            let r = run(mesh, element);
            eprintln!(
                "k = {k} (h = a/{:.2}), {name}: {} cells, {} unknowns, F {:+.2} % off Hertz, \
                 contact radius {:.3} a, {} Newton iterations, {:.2} s",
                k as f64 / 1.5,
                mesh.blocks.iter().map(|b| b.len()).sum::<usize>(),
                r.dofs,
                100.0 * (r.force / f_hertz - 1.0),
                r.radius / a,
                r.newton,
                r.seconds
            );
        }
    }
}

/// The quarter hemisphere of tests/data/hertz-hemisphere.geo (R = 5 mm, apex at the origin,
/// flat top at y = R) from its Gmsh mesh `file` (second-order or the same lowered to first
/// order), in metres.
fn gmsh_hemisphere(file: &str) -> Mesh {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    let mut mesh = adhesim::mesh::gmsh::read(&path)
        .expect("the test's mesh")
        .body(None)
        .expect("one body")
        .mesh;
    for p in &mut mesh.nodes {
        *p = p.map(|x| x * 1e-3);
    }
    mesh
}

/// Hertz between two soft bodies, a Gmsh sphere on a block: the quarter hemisphere of
/// tests/data/hertz-hemisphere.geo (R = 5 mm, elements of a/3 at the apex) pressed by
/// d = 2 µm (a = √(R d) = 0.1 mm, a/R = 0.02) into the graded quarter half-space of
/// [`graded_octant`] (k = 3 cells across its core of 1.5 a, h = a/2, truncated at 1000 a),
/// both nearly incompressible (uncoupled neo-Hookean, ν = 0.4999, G = 1 MPa), so
/// E* = E/(2(1 − ν²)) from the two; mortar contact, the sphere's curved face the slave.
/// Second-order: both bodies tet10 with one pressure per element; first-order: the
/// hemisphere's mesh lowered to order 1 and the block's hexahedra split into tet4, both with
/// the averaged nodal pressure. The hemisphere held at its top is stiffer than Hertz's
/// half-space by about 1 % (tests/hertz_gmsh_tet10.rs); tolerance 2 % for tet10, and the
/// first-order meshes must be further off.
///
/// The block's far boundary moves and the sphere's top is held (see the comment there).
#[test]
fn hertz_gmsh_tet10_sphere_on_a_tet10_block() {
    let (r, d) = (5e-3f64, 2e-6f64);
    let (material, _) = nearly_incompressible(0.4999);
    let nu = 0.4999;
    let e_star = 2.0 * G * (1.0 + nu) / (2.0 * (1.0 - nu * nu));
    let f_hertz = 4.0 / 3.0 * e_star * r.sqrt() * d.powf(1.5);
    let a = (r * d).sqrt();
    let k = 3;
    let hexes = graded_octant(1.5 * a, k, 1.0 + 1.0 / k as f64, EXTENT * a);
    let mut errors = Vec::new();
    for (name, lower, file, element) in [
        (
            "tet10",
            hexes.with_mid_side_nodes(),
            "hertz-hemisphere-tet10.msh",
            Formulation::FBar,
        ),
        (
            "tet4 anp",
            hexes.split_hexes_into_tets(),
            "hertz-hemisphere-tet4.msh",
            Formulation::AveragedNodalPressure,
        ),
    ] {
        let upper = gmsh_hemisphere(file);
        let off = lower.num_nodes();
        let shift = |ns: &[usize]| ns.iter().map(|n| n + off).collect::<Vec<_>>();
        let slave_set = upper.node_sets["curved"].clone();
        let slave_faces = &upper.face_sets["curved"];
        let local = local_faces(slave_faces, &slave_set);
        let slave_area = tributary_areas(slave_faces, &upper.nodes, &slave_set);
        let body = |name: &str, mesh: &Mesh| Body {
            name: name.into(),
            mesh: mesh.clone(),
            material: material.clone(),
            density: 1000.0,
            initial_velocity: [0.0; 3],
            element,
            plane_strain: false,
        };
        // The block's far boundary moves up by d and the sphere's top is held. (Moving the
        // top of the sphere instead, whose elements there are 0.3-1 mm, makes the first
        // Newton iterate strain those elements alone by d/h: with κ = 5000 μ the pressure
        // this implies leaves the tangent indefinite, and the step is cut back to 1/16; the
        // far cells of the block are 25 mm thick.)
        let mut push = fixed(lower.node_sets["outer"].clone(), [true, true, true]);
        push.translation[1] = Table {
            t: vec![0.0, 1.0],
            v: vec![0.0, d],
        };
        let problem = Problem {
            name: "hertz-gmsh-two-bodies".into(),
            bodies: vec![body("block", &lower), body("sphere", &upper)],
            dirichlet: vec![
                fixed(lower.node_sets["sym_x"].clone(), [true, false, false]),
                fixed(lower.node_sets["sym_z"].clone(), [false, false, true]),
                push,
                fixed(shift(&upper.node_sets["sym_x"]), [true, false, false]),
                fixed(shift(&upper.node_sets["sym_z"]), [false, false, true]),
                fixed(shift(&upper.node_sets["top"]), [true, true, true]),
            ],
            loads: vec![],
            gravity: Default::default(),
            time: TimeSettings {
                t_end: 1.0,
                quasi_static: true,
                dt: 1.0,
                contact_solver: ContactSolver::Semismooth,
                ..TimeSettings::default()
            },
            contacts: vec![ContactPair {
                name: "hertz".into(),
                slave_nodes: shift(&slave_set),
                slave_area,
                master: Master::Faces(lower.face_sets["top"].clone()),
                law: InterfaceLaw::rcc(0.0, None, None),
                // Candidates: initial gap r²/2R < 3 d, i.e. r < 2.4 a.
                detection_distance: 3.0 * d,
                slave_quads: flat_quads(&local),
                slave_faces: local,
                thickness_twins: vec![],
                discretisation: PairDiscretisation::Mortar,
            }],
        };
        let clock = Instant::now();
        let mut s = Stepper::new(Arc::new(problem)).expect("valid meshes");
        let (mut newton, mut cutbacks, mut steps) = (0, 0, 0);
        while !s.finished() {
            let rep = s.step().expect("the indentation converges");
            newton += rep.newton_iterations;
            cutbacks += rep.cutbacks;
            steps += 1;
        }
        let force = 4.0 * s.contact[0].iter().map(|c| c.force[1]).sum::<f64>();
        let err = force / f_hertz - 1.0;
        eprintln!(
            "Gmsh sphere on a block, {name}, mortar: F = {force:.5e} N, {:+.2} % off Hertz \
             {f_hertz:.5e} N, {steps} steps, {cutbacks} cut-backs, {newton} Newton iterations \
             in the steps kept, {} unknowns, {:.1} s",
            100.0 * err,
            s.disc.num_dofs(),
            clock.elapsed().as_secs_f64()
        );
        errors.push(err);
    }
    assert!(errors[0].abs() < 0.02, "tet10 {:+.2} %", 100.0 * errors[0]);
    assert!(
        errors[1].abs() > errors[0].abs(),
        "first order {:+.2} % against tet10 {:+.2} %",
        100.0 * errors[1],
        100.0 * errors[0]
    );
}
