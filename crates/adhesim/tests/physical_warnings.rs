//! The physical checks of a scenario (docs/running.md): the warnings a run prints before it
//! starts, on problems read from scenario text.

use adhesim::problem::Problem;
use adhesim::warnings::{cohesive_zone_length, physical_warnings};
use std::path::Path;

fn problem(text: &str) -> Problem {
    adhesim_io::scenario::parse(text, Path::new("test.toml"))
        .unwrap()
        .problem
}

const LAYER: &str = r#"
[[body]]
name = "layer"
mesh = { generator = "block", size = [0.03, 0.003, 0.001], divisions = [DIV, 6, 1] }
material = { model = "blatz-ko", g = 16e6 }
density = 1000.0
plane_strain = true

[[boundary]]
body = "layer"
set = "bottom"
fix = ["x", "y", "z"]
"#;

fn layer(div: usize) -> String {
    LAYER.replace("DIV", &div.to_string())
}

fn indentation(div: usize, cn: f64, depth: f64, mode: &str, dt: f64) -> String {
    format!(
        r#"
[time]
t_end = 4.0
dt = {dt}
mode = "{mode}"
{}
[[contact]]
name = "indentor"
slave = {{ body = "layer", set = "top" }}
master = {{ rigid = "cylinder", point = [0.015, 0.018, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.015 }}
motion = {{ displacement = {{ y = [[0.0, 0.0], [1.0, {}], [4.0, 0.0]] }} }}
friction = 0.0
adhesion = {{ w = 20.0, cn = {cn:e}, ct = 2e9, b = 0.1 }}
"#,
        layer(div),
        -depth
    )
}

fn has(w: &[String], what: &str) -> bool {
    w.iter().any(|s| s.contains(what))
}

#[test]
fn shipped_like_indentation_gives_no_warning() {
    let w = physical_warnings(&problem(&indentation(60, 2e9, 1e-3, "dynamic", 0.02)));
    assert!(w.is_empty(), "{w:?}");
}

#[test]
fn long_step_under_fast_loading_warns_about_waves() {
    // 1 mm in 1 ms: 1 m/s, far from slow against c ≈ 219 m/s.
    let text = indentation(60, 2e9, 1e-3, "dynamic", 0.02)
        .replace("[1.0, ", "[1e-3, ")
        .replace("[4.0, 0.0]", "[4e-3, 0.0]");
    let w = physical_warnings(&problem(&text));
    assert!(has(&w, "pressure wave"), "{w:?}");
    assert!(has(&w, "warning above 1000"), "{w:?}");
    // The same in quasi-static mode, or with a short step: no wave warning.
    let qs = text.replace("\"dynamic\"", "\"quasi-static\"");
    assert!(!has(&physical_warnings(&problem(&qs)), "pressure wave"));
    let short = text.replace("dt = 0.02", "dt = 1e-6");
    assert!(!has(&physical_warnings(&problem(&short)), "pressure wave"));
}

#[test]
fn initial_velocity_counts_as_fast_loading() {
    let text = format!(
        "[time]\nt_end = 1.0\ndt = 0.01\n{}",
        layer(10).replace("plane_strain = true", "initial_velocity = [0.0, -1.0, 0.0]")
    );
    let w = physical_warnings(&problem(&text));
    assert!(has(&w, "pressure wave"), "{w:?}");
    let slow = text.replace("-1.0", "-1e-4");
    assert!(physical_warnings(&problem(&slow)).is_empty());
}

#[test]
fn stiff_adhesive_links_warn() {
    let w = physical_warnings(&problem(&indentation(60, 2e15, 1e-3, "quasi-static", 0.02)));
    assert!(has(&w, "ill-conditioned"), "{w:?}");
    assert!(has(&w, "1e4"), "{w:?}");
    let w = physical_warnings(&problem(&indentation(60, 2e11, 1e-3, "quasi-static", 0.02)));
    assert!(!has(&w, "ill-conditioned"), "{w:?}");
}

#[test]
fn cohesive_zone_shorter_than_the_slave_elements_warns() {
    // Blatz-Ko G = 16 MPa: ν = 1/4, E = 40 MPa, E* = E/(1 − 1/16) = 42.667 MPa. With
    // C_n = 2e11 N/m³ the zone is 2.133e-4 m, below the 0.5 mm elements; with the shipped
    // 2e9 N/m³ it is 21 mm.
    assert!((cohesive_zone_length(40e6, 0.25, 2e11) - 2.1333333e-4).abs() < 1e-10);
    let w = physical_warnings(&problem(&indentation(60, 2e11, 1e-3, "quasi-static", 0.02)));
    assert!(has(&w, "cohesive zone E*/C_n = 2.133e-4 m"), "{w:?}");
    let w = physical_warnings(&problem(&indentation(60, 2e9, 1e-3, "quasi-static", 0.02)));
    assert!(!has(&w, "cohesive zone"), "{w:?}");
}

/// The contact half-width is compared with the in-plane element size where contact
/// starts. 120 elements over 30 mm: 0.25 mm edges in the plane, 1 mm along the cylinder's
/// axis; the surface's mean edge (0.625 mm) against √(2 R d) = 1.7 mm would have given
/// 2.8 elements and a false warning, the local edge against √(R d) = 1.2 mm gives 4.9.
#[test]
fn contact_width_uses_the_local_element_size() {
    let in_plane = 0.03 / 120.0;
    let a = (0.015f64 * 1e-4).sqrt();
    assert!(a / in_plane > 3.0);
    let w = physical_warnings(&problem(&indentation(120, 2e9, 1e-4, "quasi-static", 0.02)));
    assert!(!has(&w, "too coarse"), "{w:?}");
    // 40 elements (0.75 mm edges): 1.6 elements across, a warning that says so.
    let w = physical_warnings(&problem(&indentation(40, 2e9, 1e-4, "quasi-static", 0.02)));
    assert!(has(&w, "spans 1.63 slave elements"), "{w:?}");
}

#[test]
fn coarse_mesh_under_a_rigid_cylinder_warns() {
    // 6 elements over 30 mm: 5 mm in-plane edges, a = √(15·0.1) mm ≈ 1.2 mm.
    let w = physical_warnings(&problem(&indentation(6, 2e9, 1e-4, "quasi-static", 0.02)));
    assert!(has(&w, "too coarse"), "{w:?}");
    assert!(has(&w, "warning below 3"), "{w:?}");
    // Fine mesh, deep indentation: resolved.
    let w = physical_warnings(&problem(&indentation(120, 2e9, 1e-3, "quasi-static", 0.02)));
    assert!(!has(&w, "too coarse"), "{w:?}");
    // A rigid plane is never checked.
    let plane = indentation(6, 2e9, 1e-4, "quasi-static", 0.02).replace(
        r#"rigid = "cylinder", point = [0.015, 0.018, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.015"#,
        r#"rigid = "plane", point = [0.0, 0.003, 0.0], normal = [0.0, -1.0, 0.0]"#,
    );
    assert!(!has(&physical_warnings(&problem(&plane)), "too coarse"));
}
