//! Deformable on deformable: two Blatz-Ko blocks with non-matching meshes pressed together,
//! with node-to-surface contact and with mortar. The support reaction under the lower block balances the force
//! applied on the upper one, the contact forces act equal and opposite on the two bodies,
//! and the contact pressure is symmetric about the blocks' mid-planes.

use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;

const SCENARIO: &str = r#"
[time]
t_end = 1.0
dt = 0.2
mode = "quasi-static"
newton_tol = 1e-10
[[body]]
name = "lower"
mesh = { generator = "block", size = [0.01, 0.005, 0.01], divisions = [4, 2, 4] }
material = { model = "blatz-ko", g = 1e6 }
density = 1000.0
[[body]]
name = "upper"
mesh = { generator = "block", size = [0.01, 0.005, 0.01], divisions = [5, 2, 5] }
material = { model = "blatz-ko", g = 1e6 }
density = 1000.0
offset = [0.0, 0.005, 0.0]
[[boundary]]
body = "lower"
set = "bottom"
fix = ["x", "y", "z"]
[[boundary]]
body = "upper"
set = "top"
fix = ["x", "z"]
displacement = { y = [[0.0, 0.0], [1.0, -1e-4]] }
[[contact]]
name = "interface"
slave = { body = "upper", set = "bottom" }
master = { body = "lower", set = "top" }
friction = 0.3
detection_distance = 1e-3
"#;

#[test]
fn pressed_blocks_balance_forces_and_share_a_symmetric_pressure() {
    for discretisation in ["node-to-surface", "mortar"] {
        eprintln!("{discretisation}:");
        pressed_blocks(discretisation);
    }
}

fn pressed_blocks(discretisation: &str) {
    let text = format!("{SCENARIO}discretisation = {discretisation:?}\n");
    let problem = adhesim_io::scenario::parse(&text, Path::new("two_blocks.toml"))
        .unwrap()
        .problem;
    let lower = &problem.bodies[0].mesh;
    let upper = &problem.bodies[1].mesh;
    let off = lower.num_nodes();
    let bottom: Vec<usize> = lower.node_sets["bottom"].clone();
    let top: Vec<usize> = upper.node_sets["top"].iter().map(|n| n + off).collect();
    let mut s = Stepper::new(Arc::new(problem.clone())).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let f = s.disc.assemble(&s.state.u, false).force;
    let applied: f64 = top.iter().map(|&n| f[3 * n + 1]).sum();
    let support: f64 = bottom.iter().map(|&n| f[3 * n + 1]).sum();
    let contact: f64 = s.contact[0].iter().map(|c| c.force[1]).sum();
    eprintln!("applied {applied:.6e} N, support {support:.6e} N, contact {contact:.6e} N");
    assert!(
        applied < -1.0,
        "the upper block should be compressed: {applied}"
    );
    // Quasi-static equilibrium: what holds the top equals what holds the bottom and what
    // the interface carries (Newton tolerance 1e-10 relative).
    assert!(
        (applied + support).abs() < 1e-8 * applied.abs(),
        "{applied} vs {support}"
    );
    assert!(
        (contact + applied).abs() < 1e-8 * applied.abs(),
        "contact {contact} vs applied {applied}"
    );
    // Equal and opposite on the two bodies: Hᵀr summed over all nodes of both bodies.
    let mut ht = vec![0.0; s.disc.num_dofs()];
    for (i, c) in s.contact[0].iter().enumerate() {
        let node = problem.contacts[0].slave_nodes[i];
        for k in 0..3 {
            ht[3 * node + k] += c.force[k];
        }
    }
    let on_upper: f64 = (off..s.disc.num_nodes).map(|n| ht[3 * n + 1]).sum();
    assert!((on_upper - contact).abs() < 1e-12 * contact.abs());
    // Mirror symmetry x → L − x and z → L − z of the slave nodes' normal forces.
    let nodes = &problem.contacts[0].slave_nodes;
    let pos = |i: usize| problem.bodies[1].mesh.nodes[nodes[i] - off];
    let mut worst: f64 = 0.0;
    let fmax = s.contact[0]
        .iter()
        .map(|c| c.force[1].abs())
        .fold(0.0, f64::max);
    for i in 0..nodes.len() {
        let p = pos(i);
        for mirror in [[0.01 - p[0], p[1], p[2]], [p[0], p[1], 0.01 - p[2]]] {
            let j = (0..nodes.len()).find(|&j| {
                let q = pos(j);
                (q[0] - mirror[0]).abs() < 1e-9 && (q[2] - mirror[2]).abs() < 1e-9
            });
            let j = j.expect("mirror node exists");
            worst = worst.max((s.contact[0][i].force[1] - s.contact[0][j].force[1]).abs() / fmax);
        }
    }
    eprintln!("pressure asymmetry {worst:e} of the largest nodal force");
    assert!(worst < 1e-6, "pressure asymmetry {worst:e}");
}
