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

/// Rotation by `angle` [rad] about the unit axis `k` (Rodrigues).
fn rotation(k: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let mut r = [[0.0; 3]; 3];
    let cross = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { 1.0 } else { 0.0 };
            r[i][j] = c * id + s * cross[i][j] + (1.0 - c) * k[i] * k[j];
        }
    }
    r
}

fn apply(r: &[[f64; 3]; 3], x: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|j| r[i][j] * x[j]).sum())
}

/// The drag problem turned rigidly by `r`: every node, and every prescribed displacement
/// (each boundary of the scenario prescribes all three components, with tables on the same
/// times, so the turned tables are the same combinations of the original ones).
fn turned(mut problem: adhesim::problem::Problem, r: &[[f64; 3]; 3]) -> adhesim::problem::Problem {
    for body in &mut problem.bodies {
        for x in &mut body.mesh.nodes {
            *x = apply(r, *x);
        }
    }
    for d in &mut problem.dirichlet {
        assert!(d.components.iter().all(|&c| c) && d.rotation.is_none());
        let times: Vec<f64> = d.translation.iter().flat_map(|t| t.t.clone()).collect();
        let mut times = times;
        times.sort_by(f64::total_cmp);
        times.dedup();
        let original = d.translation.clone();
        for (i, table) in d.translation.iter_mut().enumerate() {
            table.t = times.clone();
            table.v = times
                .iter()
                .map(|&t| (0..3).map(|j| r[i][j] * original[j].at(t)).sum())
                .collect();
        }
    }
    problem
}

/// Per step: the magnitude of the top face's reaction [N], of the interface force [N], the
/// least frictional dissipation of a site over the step [J] (−r_t · Δslip) and the sites'
/// total [J].
fn drag_record(problem: adhesim::problem::Problem) -> Vec<(f64, f64, f64, f64)> {
    let top = problem.dirichlet[1].nodes.clone();
    let mut s = adhesim::time::Stepper::new(std::sync::Arc::new(problem)).unwrap();
    let mut rows = Vec::new();
    let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    while !s.finished() {
        s.step().unwrap_or_else(|e| panic!("{e:?}"));
        let f = s.disc.assemble(&s.state.u, false).force;
        let reaction: [f64; 3] = std::array::from_fn(|k| top.iter().map(|&n| f[3 * n + k]).sum());
        let sites = &s.contact[0];
        let interface: [f64; 3] = std::array::from_fn(|k| sites.iter().map(|c| c.force[k]).sum());
        let dissipation: Vec<f64> = sites
            .iter()
            .map(|c| -(c.r_dry[0] * c.slip[0] + c.r_dry[1] * c.slip[1]))
            .collect();
        let least = dissipation.iter().copied().fold(f64::INFINITY, f64::min);
        rows.push((
            norm(reaction),
            norm(interface),
            least,
            dissipation.iter().sum(),
        ));
    }
    rows
}

/// Frame indifference and dissipation: the whole drag turned rigidly by 30° about (1, 1, 1)
/// gives the same force magnitudes at every step (to 1e-8 of the force: both runs converge
/// to the Newton tolerance 1e-10 with their own round-off), and friction never feeds
/// energy in: −r_t · Δslip ≥ 0 at every site and step (to round-off of the largest term).
#[test]
fn the_drag_turned_rigidly_gives_the_same_forces_and_friction_dissipates() {
    let scenario = adhesim_io::scenario::parse(SCENARIO, Path::new("drag.toml")).unwrap();
    let k = 1.0 / 3f64.sqrt();
    let r = rotation([k, k, k], 30f64.to_radians());
    let straight = drag_record(scenario.problem.clone());
    let turned = drag_record(turned(scenario.problem, &r));
    assert_eq!(straight.len(), turned.len());
    let scale = straight.iter().map(|r| r.0).fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for (a, b) in straight.iter().zip(&turned) {
        worst = worst.max((a.0 - b.0).abs().max((a.1 - b.1).abs()) / scale);
        for least in [a.2, b.2] {
            assert!(
                least >= -1e-12 * scale,
                "a site's friction did work {least} J"
            );
        }
    }
    // Dragged 0.8 m at μ N: the friction's work is μ N times the slip, 0.8 m less the
    // blocks' shear under μ N (a few mm, under 1 % of the drag).
    let total: f64 = straight.iter().map(|r| r.3).sum();
    eprintln!(
        "largest difference of force magnitudes, turned against straight: {worst:.2e} of \
         {scale:.4} N; frictional dissipation {total:.3} J"
    );
    assert!(worst < 1e-8);
    let normal = straight.last().unwrap().1 / (1.0 + MU * MU).sqrt();
    let sliding_work = MU * normal * 0.8;
    assert!(
        (total / sliding_work - 1.0).abs() < 0.01,
        "{total} J against {sliding_work} J"
    );
}
