//! A block dragged over a deformable block on mortar contact (non-matching meshes: 4 × 4
//! slave faces of 0.125 m over master faces of 0.22 × 0.2 m), pressed by 5 mm and slid by
//! 0.8 m, more than three master faces, so that its sites move from face to face.
//!
//! Independent answer: once the whole interface slides, Coulomb's law at every site makes
//! the tangential force μ times the normal force, and quasi-static equilibrium makes the
//! reactions on the dragged top face carry the same ratio. Tolerance 1 %: the sites' slip
//! directions stray a little from the drag direction, so that ‖Σ r_t‖ is slightly below
//! Σ ‖r_t‖ = μ Σ r_n (0.3 % measured).

use adhesim_io::run::{run, Outcome, Silent};
use std::path::Path;

const MU: f64 = 0.3;

const SCENARIO: &str = r#"
[time]
t_end = 1.0
dt = 0.02
mode = "quasi-static"
newton_tol = 1e-10
[[body]]
name = "lower"
mesh = { generator = "block", size = [2.0, 0.5, 1.0], divisions = [9, 2, 5] }
material = { model = "neo-hookean", young = 1e6, poisson = 0.3 }
density = 1000.0
[[body]]
name = "upper"
mesh = { generator = "block", size = [0.5, 0.25, 0.5], divisions = [4, 2, 4] }
material = { model = "neo-hookean", young = 1e6, poisson = 0.3 }
density = 1000.0
offset = [0.3, 0.5, 0.25]
[[boundary]]
body = "lower"
set = "bottom"
fix = ["x", "y", "z"]
[[boundary]]
body = "upper"
set = "top"
fix = ["z"]
displacement = { y = [[0.0, 0.0], [0.2, -5e-3], [1.0, -5e-3]], x = [[0.0, 0.0], [0.2, 0.0], [1.0, 0.8]] }
[[contact]]
name = "interface"
slave = { body = "upper", set = "bottom" }
master = { body = "lower", set = "top" }
friction = 0.3
detection_distance = 0.02
discretisation = "mortar"
"#;

#[test]
fn a_block_dragged_over_a_soft_block_slides_at_mu_times_the_normal_force() {
    let scenario = adhesim_io::scenario::parse(SCENARIO, Path::new("drag.toml")).unwrap();
    let out = std::env::temp_dir().join("adhesim-test-mortar-drag");
    let _ = std::fs::remove_dir_all(&out);
    let summary = run(scenario, None, &out, &mut Silent).unwrap();
    assert_eq!(summary.outcome, Outcome::Finished);
    let (cols, rows) = adhesim_io::output::csv::read_history(out.join("history.csv")).unwrap();
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    let (t, fx, fy, fn_) = (
        col("t"),
        col("upper.top.Fx"),
        col("upper.top.Fy"),
        col("interface.fy"),
    );
    let sliding: Vec<&Vec<f64>> = rows.iter().filter(|r| r[t] > 0.3).collect();
    assert!(sliding.len() > 30);
    for r in sliding {
        let ratio = r[fx] / -r[fy];
        assert!(
            (ratio / MU - 1.0).abs() < 0.01,
            "t = {}: Fx/Fy = {ratio}",
            r[t]
        );
        // What holds the top is what the interface carries on the slave block (Newton
        // tolerance 1e-10).
        assert!(
            (r[fn_] + r[fy]).abs() < 1e-6 * r[fn_],
            "t = {}: {} vs {}",
            r[t],
            r[fn_],
            r[fy]
        );
    }
}
