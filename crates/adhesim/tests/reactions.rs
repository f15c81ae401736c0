//! Reactions on prescribed boundaries and rigid masters, checked against equilibrium and a
//! closed form.
//!
//! 1. Two identical linear-elastic blocks stacked and compressed by a prescribed
//!    displacement δ of the upper block's top, on frictionless symmetry rollers: a uniform
//!    uniaxial stress state, exactly representable by the elements, so the top reaction is
//!    F = −E A δ / (H₁ + H₂), and it equals the contact force the interface carries.
//! 2. The coarse twist of the paper's example 4.4: the reaction moment of the turned top face
//!    balances the moment Σ r × f of the contact forces on the bottom face, both taken about
//!    the top face's centroid and summed independently here from the stepper's state.

use adhesim::time::Stepper;
use adhesim_io::output::csv::read_history;
use adhesim_io::run::{run_with, Outcome, RunControl, Silent};
use adhesim_io::scenario::{load_with, LoadOptions};
use std::path::Path;
use std::sync::Arc;

const E: f64 = 1e6;
const DELTA: f64 = 1e-7;
const H: f64 = 0.004;
const A: f64 = 0.01 * 0.01;

fn block_scenario() -> String {
    format!(
        r#"
name = "stack"
[time]
t_end = 1.0
dt = 0.5
mode = "quasi-static"
newton_tol = 1e-10
[[body]]
name = "lower"
mesh = {{ generator = "block", size = [0.01, {H}, 0.01], divisions = [2, 2, 2] }}
material = {{ model = "linear-elastic", young = {E}, poisson = 0.3 }}
density = 1000.0
[[body]]
name = "upper"
mesh = {{ generator = "block", size = [0.01, {H}, 0.01], divisions = [2, 2, 2] }}
material = {{ model = "linear-elastic", young = {E}, poisson = 0.3 }}
density = 1000.0
offset = [0.0, {H}, 0.0]
[[boundary]]
name = "base"
body = "lower"
set = "bottom"
fix = ["y"]
[[boundary]]
body = "upper"
set = "top"
displacement = {{ y = [[0.0, 0.0], [1.0, -{DELTA}]] }}
[[boundary]]
body = "lower"
set = "left"
fix = ["x"]
[[boundary]]
body = "lower"
set = "back"
fix = ["z"]
[[boundary]]
body = "upper"
set = "left"
fix = ["x"]
[[boundary]]
body = "upper"
set = "back"
fix = ["z"]
[[contact]]
name = "interface"
slave = {{ body = "upper", set = "bottom" }}
master = {{ body = "lower", set = "top" }}
friction = 0.0
detection_distance = 1e-3
[output]
figures = false
"#
    )
}

#[test]
fn compressed_stack_reaction_matches_contact_force_and_closed_form() {
    let dir = std::env::temp_dir().join("adhesim-test-reactions-stack");
    let _ = std::fs::remove_dir_all(&dir);
    let problem = adhesim_io::scenario::parse(&block_scenario(), Path::new("stack.toml")).unwrap();
    let s = run_with(problem, None, &dir, &mut Silent, &RunControl::default()).unwrap();
    assert_eq!(s.outcome, Outcome::Finished);
    let (columns, rows) = read_history(dir.join("history.csv")).unwrap();
    let col = |name: &str| {
        columns
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name} in {columns:?}"))
    };
    let last = rows.last().unwrap();
    let top = last[col("upper.top.Fy")];
    let base = last[col("base.Fy")];
    let contact = last[col("interface.fy")];
    // Uniaxial stress σ = E δ / (H₁ + H₂) over the section A; the top is pushed down.
    let closed_form = -E * A * DELTA / (2.0 * H);
    eprintln!("top {top:.9e} N, base {base:.9e} N, contact {contact:.9e} N, closed form {closed_form:.9e} N");
    // The elements hold the uniform state exactly: only the Newton tolerance (1e-10
    // relative) and round-off separate the numbers, so 1e-8 relative is a tight bound.
    let tol = 1e-8 * closed_form.abs();
    assert!(
        (top - closed_form).abs() < tol,
        "top {top} vs {closed_form}"
    );
    assert!(
        (base + closed_form).abs() < tol,
        "base {base} vs {}",
        -closed_form
    );
    assert!(
        (contact + top).abs() < tol,
        "contact {contact} vs top {top}"
    );
    // The prescribed displacement is a column, and the rollers carry nothing.
    assert_eq!(last[col("upper.top.uy")], -DELTA);
    for roller in [
        "lower.left.Fx",
        "lower.back.Fz",
        "upper.left.Fx",
        "upper.back.Fz",
    ] {
        assert!(
            last[col(roller)].abs() < tol,
            "{roller} = {}",
            last[col(roller)]
        );
    }
    // Halfway, half the displacement and half the force (linear problem).
    let half = &rows[1];
    assert_eq!(half[col("upper.top.uy")], -DELTA / 2.0);
    assert!((half[col("upper.top.Fy")] - closed_form / 2.0).abs() < tol);
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[test]
fn twist_reaction_moment_balances_the_contact_moment() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/paper/twist-3d.toml");
    let opts = LoadOptions {
        variant: Some("coarse".into()),
        overrides: vec![],
    };
    let mut problem = load_with(&path, &opts).unwrap().problem;
    // 1 ms of twisting after the 5 ms press.
    problem.time.t_end = 6e-3;
    let block = &problem.bodies[0].mesh;
    let top: Vec<usize> = block.node_sets["top"].clone();
    let centre: [f64; 3] = std::array::from_fn(|k| {
        top.iter().map(|&n| block.nodes[n][k]).sum::<f64>() / top.len() as f64
    });
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let x = |n: usize| -> [f64; 3] {
        std::array::from_fn(|k| s.disc.reference[n][k] + s.state.u[3 * n + k])
    };
    let moment_about_centre = |forces: &mut dyn Iterator<Item = (usize, [f64; 3])>| {
        let (mut f, mut m) = ([0.0; 3], [0.0; 3]);
        for (n, force) in forces {
            let r: [f64; 3] = std::array::from_fn(|k| x(n)[k] - centre[k]);
            let rf = cross(r, force);
            for k in 0..3 {
                f[k] += force[k];
                m[k] += rf[k];
            }
        }
        (f, m)
    };
    let reactions = s.reactions();
    let (f_top, m_top) = moment_about_centre(
        &mut top
            .iter()
            .map(|&n| (n, std::array::from_fn(|k| reactions[3 * n + k]))),
    );
    let pair = &s.problem.contacts[0];
    let (f_contact, m_contact) = moment_about_centre(
        &mut pair
            .slave_nodes
            .iter()
            .zip(&s.contact[0])
            .map(|(&n, c)| (n, c.force)),
    );
    eprintln!(
        "top: F {f_top:?} N, M {m_top:?} N·m; contact: F {f_contact:?} N, M {m_contact:?} N·m"
    );
    // Pair totals: on the plane y = 0 the tangential resultant is the x, z part of the
    // resultant contact force, and tiny next to the sum of the nodal tangential force norms
    // (the nodal forces turn round the centre and cancel).
    let totals = adhesim_io::output::pair_totals(&s.contact[0]);
    let get = |name: &str| {
        let i = adhesim_io::output::PAIR_TOTAL_FIELDS
            .iter()
            .position(|f| *f == name);
        totals[i.unwrap()]
    };
    let norm_sum = get("ft_norm_sum");
    assert!(norm_sum > 1e6, "{norm_sum}");
    for (t, f) in [
        ("ft_x", f_contact[0]),
        ("ft_y", 0.0),
        ("ft_z", f_contact[2]),
    ] {
        assert!(
            (get(t) - f).abs() < 1e-12 * norm_sum,
            "{t} = {} vs {f}",
            get(t)
        );
    }
    assert!(get("ft_x").hypot(get("ft_z")) < 1e-6 * norm_sum);
    // The twist loads the interface: a torque about the vertical axis.
    assert!(m_contact[1].abs() > 1e3, "{m_contact:?}");
    // Balance up to the inertia of the block (dynamic run; mass 0.3 g against forces of
    // 1e7 N) and the Newton tolerance: 1e-6 of the force and moment scales.
    let (fs, ms) = (f_contact[1].abs(), m_contact[1].abs());
    for k in 0..3 {
        assert!(
            (f_top[k] + f_contact[k]).abs() < 1e-6 * fs,
            "F{k}: {f_top:?} vs {f_contact:?}"
        );
        assert!(
            (m_top[k] + m_contact[k]).abs() < 1e-6 * ms,
            "M{k}: {m_top:?} vs {m_contact:?}"
        );
    }
}

/// Boundary names head history columns: a name given twice is an error naming the key, and
/// two unnamed boundaries on one set get distinct default names.
#[test]
fn boundary_names_are_unique() {
    let two_named = block_scenario().replacen(
        "[[boundary]]\nbody = \"lower\"\nset = \"left\"",
        "[[boundary]]\nname = \"base\"\nbody = \"lower\"\nset = \"left\"",
        1,
    );
    let err = adhesim_io::scenario::parse(&two_named, Path::new("stack.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`boundary[2].name`") && err.contains("\"base\""),
        "{err}"
    );
    let same_set = block_scenario().replacen("set = \"back\"", "set = \"left\"", 1);
    let p = adhesim_io::scenario::parse(&same_set, Path::new("stack.toml")).unwrap();
    let names = &p.output.boundary_names;
    assert!(names.contains(&"lower.left".to_string()), "{names:?}");
    assert!(names.contains(&"lower.left.3".to_string()), "{names:?}");
}
