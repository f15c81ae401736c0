//! The plane-strain thickness ties: against a rigid surface each through-thickness line of
//! nodes moves as one, and a 3D body touching the slab unties it.

use adhesim::problem::Problem;
use adhesim::time::{thickness_ties, Constraints};

/// A plane-strain slab (4 × 2 × 1 hexes, bottom clamped) with `contact`: its problem and
/// the representatives of its nodes.
fn slab_ties(contact: &str) -> (Problem, Vec<usize>) {
    let text = format!(
        r#"
[time]
t_end = 1.0
dt = 0.1

[[body]]
name = "slab"
mesh = {{ generator = "block", size = [0.004, 0.001, 0.0005], divisions = [4, 2, 1] }}
material = {{ model = "blatz-ko", g = 1e6 }}
density = 1000.0
plane_strain = true

[[boundary]]
body = "slab"
set = "bottom"
fix = ["x", "y", "z"]
{contact}
"#
    );
    let problem = adhesim_io::scenario::parse(&text, std::path::Path::new("ties.toml"))
        .unwrap()
        .problem;
    let n: usize = problem.bodies.iter().map(|b| b.mesh.num_nodes()).sum();
    let fixed = Constraints::new(&problem.dirichlet, 3 * n);
    let rep = thickness_ties(&problem, fixed.mask());
    (problem, rep)
}

/// Against a rigid surface every line of the slab is tied to its node at the smaller
/// index, at the same x and y; a 3D body pressing the slab leaves it node by node.
#[test]
fn plane_strain_lines_are_tied_unless_a_3d_body_touches_the_slab() {
    let rigid = r#"
[[contact]]
name = "plate"
slave = { body = "slab", set = "top" }
master = { rigid = "plane", point = [0.0, 0.0012, 0.0], normal = [0.0, -1.0, 0.0] }
friction = 0.3
"#;
    let (problem, rep) = slab_ties(rigid);
    let nodes = &problem.bodies[0].mesh.nodes;
    assert_eq!(rep.len(), nodes.len());
    let tied: Vec<usize> = (0..rep.len()).filter(|&n| rep[n] != n).collect();
    // 5 × 3 lines of two nodes: one of each pair is tied.
    assert_eq!(tied.len(), 15);
    for &n in &tied {
        let (a, b) = (nodes[n], nodes[rep[n]]);
        assert!(rep[n] < n && rep[rep[n]] == rep[n]);
        assert!(a[0] == b[0] && a[1] == b[1] && a[2] != b[2], "{a:?} {b:?}");
    }
    let block = r#"
[[body]]
name = "block"
mesh = { generator = "block", size = [0.002, 0.001, 0.0005], divisions = [2, 1, 1] }
offset = [0.001, 0.0011, 0.0]
material = { model = "blatz-ko", g = 1e6 }
density = 1000.0

[[contact]]
name = "press"
slave = { body = "block", set = "bottom" }
master = { body = "slab", set = "top" }
friction = 0.3
"#;
    let (_, rep) = slab_ties(block);
    assert!((0..rep.len()).all(|n| rep[n] == n), "no ties: {rep:?}");
}
