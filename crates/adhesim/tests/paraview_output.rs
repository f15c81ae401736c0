//! ParaView-native frames read back by real readers: VTK's own XML multiblock reader (the
//! one ParaView uses) and meshio, both driven by `tests/python/read_frames.py`. Every frame
//! must show one data set per body and one per contact pair, each with exactly its own
//! arrays, the mesh's point and cell counts, the contact surface as faces, ids in range,
//! and contact forces that add up to the pair totals of history.csv.
//!
//! Needs python3 with `vtk` and `meshio` (`.ci/run` installs them). Without them the test
//! says so and passes, unless the environment variable `CI` is set, where it fails.

use adhesim_io::output::csv::read_history;
use adhesim_io::run::{run_with, Outcome, RunControl, Silent};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

/// Two blocks pressed together (node-to-face pair `interface`) and a rigid plane beside the
/// upper block that it never reaches (pair `side`: no candidate, gap undefined).
const SCENARIO: &str = r#"
name = "frames"
[time]
t_end = 1.0
dt = 0.25
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
[[contact]]
name = "side"
slave = { body = "upper", set = "front" }
master = { rigid = "plane", point = [0.0, 0.0, 0.02], normal = [0.0, 0.0, -1.0] }
friction = 0.0
detection_distance = 1e-3
[output]
figures = false
frame_interval = 0.25
"#;

const BODY_POINT: [&str; 3] = ["u", "v", "node_id"];
const BODY_CELL: [&str; 4] = ["cauchy", "von_mises", "J", "body_id"];
const CONTACT_POINT: [&str; 19] = [
    "node_id",
    "area",
    "beta",
    "rn",
    "rn_dry",
    "rn_adh",
    "rt",
    "rt_adh",
    "contact_force",
    "pn",
    "pn_adh",
    "tt",
    "tt_adh",
    "traction",
    "gap",
    "slip",
    "ut",
    "state",
    "damage",
];
const CONTACT_CELL: [&str; 2] = ["pair_id", "body_id"];

fn python_readers_available() -> bool {
    Command::new("python3")
        .args(["-c", "import vtkmodules.vtkIOXML, meshio, numpy"])
        .output()
        .is_ok_and(|o| o.status.success())
}

fn names(v: &Value) -> BTreeSet<String> {
    v.as_object().unwrap().keys().cloned().collect()
}

fn set(list: &[&str]) -> BTreeSet<String> {
    list.iter().map(|s| s.to_string()).collect()
}

#[test]
fn vtk_and_meshio_read_every_data_set_of_every_frame() {
    if !python_readers_available() {
        let msg = "python3 with the `vtk` and `meshio` packages is needed \
                   (pip install vtk==9.3.1 meshio==5.3.5)";
        assert!(std::env::var_os("CI").is_none(), "{msg}");
        eprintln!("SKIPPED: {msg}");
        return;
    }
    let dir = std::env::temp_dir().join("adhesim-test-paraview-output");
    let _ = std::fs::remove_dir_all(&dir);
    let problem = adhesim_io::scenario::parse(SCENARIO, Path::new("frames.toml")).unwrap();
    let summary = run_with(problem, None, &dir, &mut Silent, &RunControl::default()).unwrap();
    assert_eq!(summary.outcome, Outcome::Finished);
    assert_eq!(summary.frames, 5);

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/read_frames.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg(&dir)
        .arg("frames")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "read_frames.py failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let seen: Value = serde_json::from_slice(&out.stdout).unwrap();
    eprintln!("readers: {}", seen["versions"]);

    let (columns, rows) = read_history(dir.join("history.csv")).unwrap();
    let col = |name: &str| columns.iter().position(|c| c == name).unwrap();

    // (group, name, points, cells, VTK cell types, id ranges) of each data set:
    // lower 5×3×5 nodes, 4×2×4 hexahedra; upper 6×3×6 nodes, 5×2×5 hexahedra; its bottom
    // 6×6 nodes, 5×5 quadrilaterals; its front 6×3 nodes, 5×2 quadrilaterals.
    let expected = [
        ("bodies", "lower", 75, 32, vec![12], [(0, 74), (0, 0)]),
        ("bodies", "upper", 108, 50, vec![12], [(75, 182), (1, 1)]),
        (
            "contacts",
            "interface",
            36,
            25,
            vec![9],
            [(75, 182), (0, 0)],
        ),
        ("contacts", "side", 18, 10, vec![9], [(75, 182), (1, 1)]),
    ];
    for reader in ["vtk", "meshio"] {
        let frames = seen[reader].as_array().unwrap();
        assert_eq!(frames.len(), 5, "{reader}: frames");
        for (f, frame) in frames.iter().enumerate() {
            let t = frame["time"].as_f64().unwrap();
            assert_eq!(t, rows[f][col("t")], "{reader}: time of frame {f}");
            let datasets = frame["datasets"].as_array().unwrap();
            assert_eq!(datasets.len(), expected.len(), "{reader}, frame {f}");
            for (d, (group, name, points, cells, types, ids)) in datasets.iter().zip(&expected) {
                let what = format!("{reader}, frame {f}, {name}");
                assert_eq!(d["group"], *group, "{what}");
                assert_eq!(d["name"], *name, "{what}");
                assert_eq!(d["points"], *points, "{what}: points");
                assert_eq!(d["cells"], *cells, "{what}: cells");
                assert_eq!(
                    d["cell_types"],
                    serde_json::json!(types),
                    "{what}: cell types"
                );
                let is_body = *group == "bodies";
                let (pa, ca) = if is_body {
                    (set(&BODY_POINT), set(&BODY_CELL))
                } else {
                    (set(&CONTACT_POINT), set(&CONTACT_CELL))
                };
                assert_eq!(names(&d["point_arrays"]), pa, "{what}: point arrays");
                assert_eq!(names(&d["cell_arrays"]), ca, "{what}: cell arrays");
                for vector in ["u", "v", "rt", "contact_force", "traction", "ut"] {
                    if let Some(c) = d["point_arrays"].get(vector) {
                        assert_eq!(c, 3, "{what}: components of {vector}");
                    }
                }
                // Only the gap of a node that is not a contact candidate is NaN (the side pair's nodes
                // never are, the interface's are not before the first step).
                let nan: Vec<&str> = d["nan_arrays"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_str().unwrap())
                    .collect();
                // (The interface's nodes are all candidates once the blocks touch.)
                let gap_may_be_nan = *name == "side" || (*name == "interface" && f == 0);
                let allowed: &[&str] = if gap_may_be_nan { &["gap"] } else { &[] };
                assert_eq!(nan, allowed, "{what}: arrays with NaN");
                let (node, body) = (ids[0], ids[1]);
                let range = d["ids"]["node_id"].as_array().unwrap();
                let (lo, hi) = (range[0].as_i64().unwrap(), range[1].as_i64().unwrap());
                if is_body {
                    assert_eq!((lo, hi), node, "{what}: node ids");
                } else {
                    assert!(lo >= node.0 && hi <= node.1, "{what}: node ids {lo}..{hi}");
                }
                let id_name = if is_body { "body_id" } else { "pair_id" };
                assert_eq!(
                    d["ids"][id_name],
                    serde_json::json!([body.0, body.1]),
                    "{what}: {id_name}"
                );
                if !is_body {
                    // Contact forces read back add up to the pair's totals in history.csv
                    // (same doubles summed in another order: 1e-12 relative).
                    let sums = d["sums"]["contact_force"].as_array().unwrap();
                    for (k, axis) in ["fx", "fy", "fz"].iter().enumerate() {
                        let from_file = sums[k].as_f64().unwrap();
                        let from_history = rows[f][col(&format!("{name}.{axis}"))];
                        assert!(
                            (from_file - from_history).abs()
                                <= 1e-12 * from_history.abs().max(1e-9),
                            "{what}: sum of contact_force {axis} {from_file} vs history \
                             {from_history}"
                        );
                    }
                }
            }
        }
    }
    // The interface carries load at the end (the blocks are pressed 0.1 mm together).
    let last = rows.last().unwrap();
    assert!(
        last[col("interface.fy")] > 1.0,
        "{}",
        last[col("interface.fy")]
    );
}
