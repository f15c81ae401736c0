//! Tractions on a contact surface: a linear-elastic pad pressed flat onto a rigid frictionless
//! plane, free to expand sideways (symmetry rollers), is in uniform uniaxial stress
//! σ = E δ / H. Its contact pressure (nodal normal force over tributary area) is σ at every
//! slave node, edges and corners included, while the nodal forces are not uniform: an edge
//! node carries half the force of an interior node, a corner node a quarter.

use adhesim_io::output::csv::read_history;
use adhesim_io::run::{run_with, Outcome, RunControl, Silent};
use std::path::Path;

const E: f64 = 2e6;
const DELTA: f64 = 2e-7;
const H: f64 = 0.002;

fn scenario() -> String {
    format!(
        r#"
name = "pad"
[time]
t_end = 1.0
dt = 1.0
mode = "quasi-static"
newton_tol = 1e-10
[[body]]
name = "pad"
mesh = {{ generator = "block", size = [0.006, {H}, 0.004], divisions = [3, 2, 2] }}
material = {{ model = "linear-elastic", young = {E}, poisson = 0.3 }}
density = 1000.0
[[boundary]]
body = "pad"
set = "top"
displacement = {{ y = [[0.0, 0.0], [1.0, -{DELTA}]] }}
[[boundary]]
body = "pad"
set = "left"
fix = ["x"]
[[boundary]]
body = "pad"
set = "back"
fix = ["z"]
[[contact]]
name = "ground"
slave = {{ body = "pad", set = "bottom" }}
master = {{ rigid = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
friction = 0.0
detection_distance = 1e-4
[[map]]
contact = "ground"
fields = ["pn", "rn", "tt"]
times = [1.0]
[[track]]
name = "corner"
body = "pad"
point = [0.006, 0.0, 0.004]
[output]
figures = false
"#
    )
}

#[test]
fn uniformly_pressed_pad_shows_uniform_pressure() {
    let dir = std::env::temp_dir().join("adhesim-test-tractions-pad");
    let _ = std::fs::remove_dir_all(&dir);
    let problem = adhesim_io::scenario::parse(&scenario(), Path::new("pad.toml")).unwrap();
    let s = run_with(problem, None, &dir, &mut Silent, &RunControl::default()).unwrap();
    assert_eq!(s.outcome, Outcome::Finished);
    let (columns, rows) = read_history(dir.join("maps/ground_t1.csv")).unwrap_or_else(|e| {
        let listing: Vec<_> = std::fs::read_dir(dir.join("maps")).unwrap().collect();
        panic!("{e}: {listing:?}")
    });
    let col = |name: &str| columns.iter().position(|c| c == name).unwrap();
    let sigma = E * DELTA / H;
    assert_eq!(rows.len(), 4 * 3, "slave nodes");
    let mut rn: Vec<f64> = Vec::new();
    for r in &rows {
        let pn = r[col("pn")];
        // Uniform stress, represented exactly by the elements: the pressure is σ to the
        // Newton tolerance (1e-10); 1e-6 relative is the issue's bound.
        assert!((pn - sigma).abs() < 1e-6 * sigma, "pn {pn} vs σ {sigma}");
        assert!(
            r[col("tt")].abs() < 1e-6 * sigma,
            "frictionless: tt {}",
            r[col("tt")]
        );
        rn.push(r[col("rn")]);
    }
    // Nodal forces: interior σa, edge σa/2, corner σa/4 with a the area of one face
    // (2 mm × 2 mm), so they span a factor 4.
    let a = 0.002 * 0.002;
    let (lo, hi) = rn
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(
        (lo - sigma * a / 4.0).abs() < 1e-6 * sigma * a,
        "corner force {lo}"
    );
    assert!(
        (hi - sigma * a).abs() < 1e-6 * sigma * a,
        "interior force {hi}"
    );
    // The tracked corner node's pressure in history.csv is σ as well.
    let (hc, hr) = read_history(dir.join("history.csv")).unwrap();
    let pn = hr.last().unwrap()[hc.iter().position(|c| c == "corner.pn").unwrap()];
    assert!((pn - sigma).abs() < 1e-6 * sigma, "corner.pn {pn}");
}
