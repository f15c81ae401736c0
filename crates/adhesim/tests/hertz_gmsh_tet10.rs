//! Hertz contact on a Gmsh mesh of second-order tetrahedra: a quarter of a hemisphere
//! (R = 5 mm, tests/data/hertz-hemisphere.geo, x = 0 and z = 0 symmetry planes, its flat top
//! held) pressed by d onto a rigid, frictionless flat, against 4/3 E* √R d^(3/2),
//! E* = E/(1 − ν²), contact radius a = √(R d) = 0.1 mm (a/R = 0.02).
//!
//! Nearly incompressible: uncoupled neo-Hookean, μ = 0.6 MPa, κ = 3 GPa (ν = 0.4999). The
//! tet10 mesh (tet10 with the element-constant volume change, `element = "fbar"`) and the
//! same mesh lowered to linear tetrahedra (the averaged nodal pressure, `element = "anp"`):
//! the apex elements are 0.033 mm, a third of the contact radius, growing to 1 mm.
//!
//! What separates the answer from linear Hertz besides the discretisation: the body is a
//! hemisphere held at a distance R, not a half-space (stiffer by roughly 0.4 a/R ≈ 1 %: the
//! far-field displacement F/(π E* R) of a half-space that the held top suppresses, over d),
//! and finite strain at a/R = 0.02. Refined meshes of the same .geo (apex elements 0.1 to
//! 0.0125 mm, `hertz_on_other_gmsh_meshes`) put tet10 at +1.1 to +1.2 % on the finest two,
//! which is that offset; the test asks 2 %, and that the linear tetrahedra are further off.

use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Sphere radius [m], indentation [m].
const R: f64 = 5e-3;
const D: f64 = 2e-6;
/// Shear and bulk moduli [Pa].
const MU: f64 = 0.6e6;
const KAPPA: f64 = 3e9;

fn scenario(mesh: &str, element: &str) -> String {
    format!(
        r#"
[time]
t_end = 1.0
dt = 1.0
mode = "quasi-static"
[[body]]
name = "cap"
mesh = {{ file = "{mesh}", scale = 1e-3 }}
material = {{ model = "uncoupled-neo-hookean", c10 = {c10:e}, kappa = {KAPPA:e} }}
element = "{element}"
density = 970.0
[[boundary]]
body = "cap"
set = "top"
fix = ["x", "y", "z"]
[[boundary]]
body = "cap"
set = "sym_x"
fix = ["x"]
[[boundary]]
body = "cap"
set = "sym_z"
fix = ["z"]
[[contact]]
name = "flat"
slave = {{ body = "cap", set = "curved" }}
master = {{ rigid = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
motion = {{ displacement = {{ y = [[0.0, 0.0], [1.0, {D:e}]] }} }}
friction = 0.0
detection_distance = {det:e}
"#,
        c10 = MU / 2.0,
        det = 5.0 * D,
    )
}

/// The Hertz force [N] of the whole sphere.
fn hertz() -> f64 {
    let nu = (3.0 * KAPPA - 2.0 * MU) / (2.0 * (3.0 * KAPPA + MU));
    let e = 2.0 * MU * (1.0 + nu);
    let e_star = e / (1.0 - nu * nu);
    4.0 / 3.0 * e_star * R.sqrt() * D.powf(1.5)
}

/// Force [N] (four quarters), unknowns and wall time [s] of the indentation on `mesh`.
fn indent(mesh: &str, element: &str) -> (f64, usize, f64) {
    indent_in(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data"),
        mesh,
        element,
    )
}

/// [`indent`] on the mesh `mesh` of the directory `dir`.
fn indent_in(dir: &Path, mesh: &str, element: &str) -> (f64, usize, f64) {
    let text = scenario(mesh, element);
    let clock = Instant::now();
    let problem = adhesim_io::scenario::parse(&text, &dir.join("hertz.toml"))
        .unwrap()
        .problem;
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    let mut newton = 0;
    while !s.finished() {
        newton += s
            .step()
            .expect("the indentation converges")
            .newton_iterations;
    }
    let force = 4.0 * s.contact[0].iter().map(|c| c.force[1]).sum::<f64>();
    let wall = clock.elapsed().as_secs_f64();
    eprintln!(
        "{mesh} ({element}): F = {force:.5e} N, {:+.2} % off Hertz, {newton} Newton \
         iterations, {} unknowns, {wall:.2} s",
        100.0 * (force / hertz() - 1.0),
        s.disc.num_dofs()
    );
    (force, s.disc.num_dofs(), wall)
}

#[test]
fn hertz_on_a_gmsh_tet10_hemisphere() {
    let f_hertz = hertz();
    eprintln!("Hertz: {f_hertz:.5e} N");
    let (tet10, _, _) = indent("hertz-hemisphere-tet10.msh", "fbar");
    let (anp, _, _) = indent("hertz-hemisphere-tet4.msh", "anp");
    let (e10, e4) = (tet10 / f_hertz - 1.0, anp / f_hertz - 1.0);
    assert!(e10.abs() < 0.02, "tet10 {:+.2} % off Hertz", 100.0 * e10);
    assert!(
        e4.abs() > e10.abs(),
        "the linear tetrahedra ({:+.2} %) should be further off than tet10 ({:+.2} %)",
        100.0 * e4,
        100.0 * e10
    );
}

/// The same indentation on meshes made elsewhere (the .geo with other sizes), for the
/// refinement study of docs/elements.md: every `hertz-hemisphere-*-tet10.msh` and
/// `-tet4.msh` pair in the directory `HERTZ_GMSH_DIR`.
#[test]
#[ignore = "a measurement: HERTZ_GMSH_DIR=dir cargo test --release -p adhesim --test hertz_gmsh_tet10 -- --ignored --nocapture"]
fn hertz_on_other_gmsh_meshes() {
    let dir = std::path::PathBuf::from(std::env::var("HERTZ_GMSH_DIR").expect("HERTZ_GMSH_DIR"));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with("-tet10.msh"))
        .collect();
    names.sort();
    eprintln!("Hertz: {:.5e} N", hertz());
    for n in names {
        indent_in(&dir, &n, "fbar");
        indent_in(&dir, &n.replace("-tet10.msh", "-tet4.msh"), "anp");
    }
}
