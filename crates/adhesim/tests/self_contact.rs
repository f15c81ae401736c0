//! Self-contact on mortar sites: a block (2 × 1 × 1 m, linear elastic, E = 1 MPa, ν = 0.3)
//! with a slit on the plane y = 0.5 from x = 0 to x = 1.5 (nodes doubled there, the two lips
//! touching), compressed across the slit by 1 mm with symmetry conditions on x = 0 and z = 0.
//! The two arms are one body, so the lips are in contact with the body itself.
//!
//! Independent answer: frictionless lips under a uniaxial stress normal to them carry that
//! stress as an uncut block would, so the top's reaction is E δ/H times the top's area,
//! 2000 N, reproduced by hex8 elements exactly; without contact across the slit the arms
//! would bend and the reaction would be a fraction of it. Both forms of a self-contact pair
//! are run: one face set holding both lips (each overlap integrated from both sides, half
//! each), and two face sets, one lip against the other.

use adhesim::contact::detect::{flat_quads, local_faces, tributary_areas};
use adhesim::contact::{ContactPair, InterfaceLaw, Master, PairDiscretisation};
use adhesim::material::LinearElastic;
use adhesim::mesh::{generate, Face, Mesh};
use adhesim::problem::{Body, ContactSolver, Dirichlet, Problem, Table, TimeSettings};
use adhesim::time::Stepper;
use std::collections::HashMap;
use std::sync::Arc;

/// Slit plane [m], slit tip [m], push [m], height [m], Young's modulus [Pa], top area [m²].
const SLIT_Y: f64 = 0.5;
const TIP_X: f64 = 1.5;
const PUSH: f64 = 1e-3;
const HEIGHT: f64 = 1.0;
const YOUNG: f64 = 1e6;
const TOP_AREA: f64 = 2.0;

/// The block slit from x = 0 to `tip_x` [m] (cut through when `tip_x` is beyond its length,
/// 2 m, its two parts still one body), with node sets from coordinates and the face sets
/// `lower_lip` (facing +y) and `upper_lip` (facing −y).
fn slit_block(tip_x: f64) -> Mesh {
    let mut mesh = generate::block([2.0, HEIGHT, 1.0], [8, 4, 2]);
    let on_slit = |x: [f64; 3]| (x[1] - SLIT_Y).abs() < 1e-9 && x[0] < tip_x - 1e-9;
    let mut twin: HashMap<usize, usize> = HashMap::new();
    for n in 0..mesh.nodes.len() {
        if on_slit(mesh.nodes[n]) {
            twin.insert(n, mesh.nodes.len());
            let x = mesh.nodes[n];
            mesh.nodes.push(x);
        }
    }
    let nodes = mesh.nodes.clone();
    for block in &mut mesh.blocks {
        let per = block.element.nodes;
        for cell in block.connectivity.chunks_exact_mut(per) {
            let centre_y = cell.iter().map(|&n| nodes[n][1]).sum::<f64>() / per as f64;
            if centre_y > SLIT_Y {
                for n in cell.iter_mut() {
                    if let Some(&t) = twin.get(n) {
                        *n = t;
                    }
                }
            }
        }
    }
    let lips: Vec<Face> = mesh
        .boundary_faces()
        .into_iter()
        .filter(|f| {
            f.nodes()
                .iter()
                .all(|&n| (mesh.nodes[n][1] - SLIT_Y).abs() < 1e-9)
        })
        .collect();
    let (upper, lower): (Vec<Face>, Vec<Face>) = lips
        .into_iter()
        .partition(|f| f.nodes().iter().any(|n| twin.values().any(|t| t == n)));
    mesh.face_sets.clear();
    mesh.node_sets.clear();
    mesh.set_faces("lower_lip", lower);
    mesh.set_faces("upper_lip", upper);
    let select = |pred: &dyn Fn([f64; 3]) -> bool| -> Vec<usize> {
        (0..mesh.nodes.len())
            .filter(|&n| pred(mesh.nodes[n]))
            .collect()
    };
    let sets = [
        ("bottom", select(&|x| x[1].abs() < 1e-9)),
        ("top", select(&|x| (x[1] - HEIGHT).abs() < 1e-9)),
        ("left", select(&|x| x[0].abs() < 1e-9)),
        ("back", select(&|x| x[2].abs() < 1e-9)),
    ];
    for (name, ns) in sets {
        mesh.node_sets.insert(name.into(), ns);
    }
    mesh
}

fn held(nodes: Vec<usize>, components: [bool; 3], uy: Table) -> Dirichlet {
    Dirichlet {
        nodes,
        components,
        translation: [Table::constant(0.0), uy, Table::constant(0.0)],
        rotation: None,
    }
}

/// The self-contact pair of `slave` against `master` (face sets of `mesh`) with the law `law`.
fn pair(mesh: &Mesh, slave: &[&str], master: &[&str], law: InterfaceLaw) -> ContactPair {
    let faces = |sets: &[&str]| -> Vec<Face> {
        sets.iter()
            .flat_map(|s| mesh.face_sets[*s].clone())
            .collect()
    };
    let slave_faces = faces(slave);
    let mut slave_nodes: Vec<usize> = slave_faces
        .iter()
        .flat_map(|f| f.nodes().to_vec())
        .collect();
    slave_nodes.sort_unstable();
    slave_nodes.dedup();
    let local = local_faces(&slave_faces, &slave_nodes);
    ContactPair {
        name: "lips".into(),
        slave_area: tributary_areas(&slave_faces, &mesh.nodes, &slave_nodes),
        slave_nodes,
        master: Master::Faces(faces(master)),
        law,
        detection_distance: 0.05,
        slave_quads: flat_quads(&local),
        slave_faces: local,
        thickness_twins: vec![],
        discretisation: PairDiscretisation::Mortar,
    }
}

/// What a run of the slit block gives at its end.
struct Slit {
    /// The top's reaction [N], upwards positive.
    reaction: f64,
    /// Contact sites in the last step.
    sites: usize,
}

/// The block slit to `tip_x` [m] with the top moved by `top` [m] over time, in steps `dt`
/// [s], the lips a self-contact pair `slave` on `master` with the law `law`; `on_step` sees
/// the stepper and the top's reaction [N] after each step.
#[allow(clippy::too_many_arguments)]
fn run_slit(
    tip_x: f64,
    slave: &[&str],
    master: &[&str],
    solver: ContactSolver,
    law: InterfaceLaw,
    top: Table,
    dt: f64,
    on_step: &mut dyn FnMut(&Stepper, f64),
) -> Slit {
    let mesh = slit_block(tip_x);
    let t_end = *top.t.last().unwrap();
    let problem = Problem {
        name: "slit".into(),
        bodies: vec![Body {
            name: "block".into(),
            mesh: mesh.clone(),
            material: Arc::new(LinearElastic::from_young_poisson(YOUNG, 0.3)),
            density: 1000.0,
            initial_velocity: [0.0; 3],
            element: adhesim::fbar::Formulation::Standard,
            plane_strain: false,
        }],
        dirichlet: vec![
            held(
                mesh.node_sets["bottom"].clone(),
                [false, true, false],
                Table::constant(0.0),
            ),
            held(mesh.node_sets["top"].clone(), [false, true, false], top),
            held(
                mesh.node_sets["left"].clone(),
                [true, false, false],
                Table::constant(0.0),
            ),
            held(
                mesh.node_sets["back"].clone(),
                [false, false, true],
                Table::constant(0.0),
            ),
        ],
        loads: vec![],
        gravity: Default::default(),
        time: TimeSettings {
            t_end,
            dt,
            quasi_static: true,
            newton_tol: 1e-10,
            contact_tol: 1e-10,
            contact_solver: solver,
            ..TimeSettings::default()
        },
        contacts: vec![pair(&mesh, slave, master, law)],
    };
    let top_nodes = mesh.node_sets["top"].clone();
    let mut s = Stepper::new(Arc::new(problem)).expect("a valid mesh");
    let mut sites = 0;
    while !s.finished() {
        sites = match s.step() {
            Ok(r) => r.contact_points,
            Err(e) => panic!("{slave:?} on {master:?}, {solver:?}: {e:?}"),
        };
        let f = s.disc.assemble(&s.state.u, false).force;
        on_step(&s, -top_nodes.iter().map(|&n| f[3 * n + 1]).sum::<f64>());
    }
    let f = s.disc.assemble(&s.state.u, false).force;
    Slit {
        reaction: -top_nodes.iter().map(|&n| f[3 * n + 1]).sum::<f64>(),
        sites,
    }
}

/// The top's reaction [N] and the number of contact sites of the frictionless compression.
fn compress(slave: &[&str], master: &[&str], solver: ContactSolver) -> (f64, usize) {
    let push = Table {
        t: vec![0.0, 1.0],
        v: vec![0.0, -PUSH],
    };
    let law = InterfaceLaw::rcc(0.0, None, None);
    let r = run_slit(TIP_X, slave, master, solver, law, push, 1.0, &mut |_, _| {});
    (r.reaction, r.sites)
}

#[test]
fn a_slit_block_carries_the_uncut_stress_across_its_lips_in_self_contact() {
    let exact = YOUNG * PUSH / HEIGHT * TOP_AREA;
    for (slave, master) in [
        (&["upper_lip"][..], &["lower_lip"][..]),
        (
            &["lower_lip", "upper_lip"][..],
            &["lower_lip", "upper_lip"][..],
        ),
    ] {
        for solver in [ContactSolver::GaussSeidel, ContactSolver::Semismooth] {
            let (reaction, sites) = compress(slave, master, solver);
            eprintln!(
                "{slave:?} on {master:?}, {solver:?}: top reaction {reaction:.10} N \
                 (uncut {exact} N), {sites} sites"
            );
            assert!(sites > 0);
            assert!(
                (reaction / exact - 1.0).abs() < 1e-8,
                "{slave:?} on {master:?}, {solver:?}: {reaction} N"
            );
        }
    }
}

/// Interface of the cut block: C_n = C_t [N/m³] (the cut block's stiffness E/H = 10⁶ N/m³
/// exceeds the interface's steepest softening, 3 C_n, so that the pull is stable under
/// displacement control), w [J/m²], and w/b [1/s], fast against the pull.
const CUT_CN: f64 = 2e5;
const CUT_W: f64 = 0.05;
const CUT_W_OVER_B: f64 = 1e4;

/// Peak tensile reaction [N] and work of the tensile reaction over the pull [J] of a block
/// cut through on y = 0.5 (its two parts one body), its lips `slave` on `master`, pressed
/// 1 µm, bonded, then pulled 20 openings u_c = √(w/C_n) apart in 2000 steps.
fn cut_block_pull_off(slave: &[&str], master: &[&str], solver: ContactSolver) -> (f64, f64) {
    use adhesim::contact::RccParams;
    let bond = RccParams::new(CUT_W, CUT_CN, CUT_CN, CUT_W / CUT_W_OVER_B);
    let law = InterfaceLaw::rcc(0.0, Some(bond), None);
    let u_c = (CUT_W / CUT_CN).sqrt();
    let top = Table {
        t: vec![0.0, 0.1, 0.2, 1.2],
        v: vec![0.0, -1e-6, -1e-6, 20.0 * u_c],
    };
    let (mut history, mut bonded_at_hold) = (Vec::new(), 0);
    run_slit(
        5.0,
        slave,
        master,
        solver,
        law,
        top.clone(),
        5e-4,
        &mut |s, f| {
            history.push((top.at(s.state.t), f));
            if (s.state.t - 0.2).abs() < 1e-9 {
                bonded_at_hold = s.contact[0].iter().filter(|c| c.history.bonded()).count();
            }
        },
    );
    assert!(
        bonded_at_hold > 0,
        "{slave:?} on {master:?}: no site bonded"
    );
    // Pulling up: the lips hold the upper part down, a negative reaction.
    let tension = |f: f64| (-f).max(0.0);
    let peak = history.iter().map(|r| tension(r.1)).fold(0.0, f64::max);
    let work = history
        .windows(2)
        .filter(|p| p[1].0 > p[0].0)
        .map(|p| 0.5 * (tension(p[0].1) + tension(p[1].1)) * (p[1].0 - p[0].0))
        .sum();
    (peak, work)
}

/// Adhesive self-contact against the closed form of the interface: a block cut through by a
/// plane (its two parts one body, so the lips are in self-contact) is pressed, bonded and
/// pulled apart. It opens uniformly, so its interface follows the rate-independent RCC
/// limit: peak force A √(C_n w) and work of separation w A (A = 2 m², docs/model.md §6).
/// Tolerances 1 %: the peak is sampled at the steps (1 % of u_c of pull each), and the
/// force left at the end of the pull carries 0.25 % of the work.
#[test]
fn a_cut_block_bonded_to_itself_pulls_off_at_the_closed_form_peak_and_work() {
    let (peak_exact, work_exact) = (TOP_AREA * (CUT_CN * CUT_W).sqrt(), CUT_W * TOP_AREA);
    for (slave, master, solver) in [
        (
            &["upper_lip"][..],
            &["lower_lip"][..],
            ContactSolver::GaussSeidel,
        ),
        (
            &["lower_lip", "upper_lip"][..],
            &["lower_lip", "upper_lip"][..],
            ContactSolver::GaussSeidel,
        ),
        (
            &["lower_lip", "upper_lip"][..],
            &["lower_lip", "upper_lip"][..],
            ContactSolver::Semismooth,
        ),
    ] {
        let (peak, work) = cut_block_pull_off(slave, master, solver);
        eprintln!(
            "{slave:?} on {master:?}, {solver:?}: peak {peak:.6} N (A √(C_n w) = {peak_exact:.6}), \
             work {work:.6} J (w A = {work_exact:.6})"
        );
        assert!((peak / peak_exact - 1.0).abs() < 0.01, "peak {peak} N");
        assert!((work / work_exact - 1.0).abs() < 0.01, "work {work} J");
    }
}
