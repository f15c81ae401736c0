//! The averaged-nodal-pressure tetrahedron (`element = "anp"`) on tetrahedral meshes of
//! nearly incompressible solids (the structured hexahedral meshes of `generate`, each hex
//! split into six tetrahedra).
//!
//! - The assembled force is the gradient of the assembled energy and the assembled tangent
//!   (with its couplings between neighbouring patches) the gradient of the force, by central
//!   finite differences on a distorted mesh at a large displacement.
//! - A patch test: a homogeneous finite deformation is reproduced on a distorted mesh.
//! - A block under large simple shear at ν = 0.4999 keeps its volume (|J̄ − 1| < 1e-3).
//! - The plane-strain cantilever of tests/fbar_locking.rs at ν = 0.4999: within 5 % of the
//!   converged answer at 16 layers through the thickness, where the linear tetrahedron is
//!   locked; and a 3-D cantilever with 4 layers.
//! - Viscoelastic relaxation under homogeneous uniaxial stretch: the same forces as the
//!   F-bar hexahedron.
//! - The scenario key `element = "anp"` and its error for materials without a split.

use adhesim::anp::NodalPatches;
use adhesim::assembly::Discretisation;
use adhesim::fbar::Formulation;
use adhesim::material::{Hyperelastic, MooneyRivlin, UncoupledNeoHookean};
use adhesim::mesh::{generate, Mesh};
use adhesim::problem::{Dirichlet, Table};
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

const NU: f64 = 0.4999;
const ANP: Formulation = Formulation::AveragedNodalPressure;

/// A unit cube of n³ hexahedra split into tetrahedra, interior nodes moved at random by up
/// to `shake` of an element size.
fn shaken_tet_cube(n: usize, shake: f64, seed: u64) -> (Mesh, Vec<usize>) {
    let mut mesh = generate::block([1.0, 1.0, 1.0], [n, n, n]).split_hexes_into_tets();
    let boundary = shake_interior(&mut mesh, n, shake, seed);
    (mesh, boundary)
}

#[test]
fn split_mesh_is_conforming_and_keeps_the_volume() {
    let hexes = generate::block([2.0, 1.0, 0.5], [4, 3, 2]);
    let tets = hexes.split_hexes_into_tets();
    assert_eq!(tets.tets().len(), 6 * hexes.hexes().len());
    let material: Arc<dyn Hyperelastic> =
        Arc::new(UncoupledNeoHookean::from_young_poisson(1.0, 0.3));
    let disc = Discretisation::new(&[(&tets, material)]).expect("positive tetrahedra");
    assert!((disc.volume() - 1.0).abs() < 1e-12);
    // Conforming: the boundary is the block's, two triangles per quad.
    assert_eq!(
        tets.boundary_faces().len(),
        2 * hexes.boundary_faces().len()
    );
    for (name, faces) in &hexes.face_sets {
        assert_eq!(tets.face_sets[name].len(), 2 * faces.len(), "{name}");
    }
}

/// Central differences of the assembled energy (→ force) and force (→ tangent).
fn check_derivatives(material: Arc<dyn Hyperelastic>) {
    let (mesh, _) = shaken_tet_cube(2, 0.3, 77);
    let disc = Discretisation::with_formulations(&[(&mesh, material)], &[ANP]).unwrap();
    let plain = Discretisation::new(&[(&mesh, disc.materials[0].clone())]).unwrap();
    // The patches couple neighbours of neighbours: a wider pattern than the elements'.
    assert!(disc.pattern.nnz() > plain.pattern.nnz());
    let mut rng = Rng(99);
    let u: Vec<f64> = (0..disc.num_dofs()).map(|_| 0.08 * rng.next()).collect();
    let a = disc.assemble(&u, true);
    let n = disc.num_dofs();
    let fmax = a.force.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut kmax = 0.0f64;
    let mut worst_k = 0.0f64;
    let mut worst_f = 0.0f64;
    let h = 1e-6;
    for j in 0..n {
        let (mut up, mut um) = (u.clone(), u.clone());
        up[j] += h;
        um[j] -= h;
        let (ap, am) = (disc.assemble(&up, false), disc.assemble(&um, false));
        worst_f = worst_f.max(((ap.energy - am.energy) / (2.0 * h) - a.force[j]).abs());
        let mut e = vec![0.0; n];
        e[j] = 1.0;
        let mut col = vec![0.0; n];
        disc.pattern.symmetric_matvec(&a.tangent, &e, &mut col);
        for (i, k) in col.iter().enumerate() {
            let fd = (ap.force[i] - am.force[i]) / (2.0 * h);
            kmax = kmax.max(k.abs());
            worst_k = worst_k.max((fd - k).abs());
        }
    }
    eprintln!(
        "{:?}: force error {worst_f:.1e} of {fmax:.1e}, tangent error {worst_k:.1e} of {kmax:.1e}",
        disc.materials[0]
    );
    // Central differences with h = 1e-6 at displacements ~0.1: truncation O(h²) and
    // round-off ~1e-16 |f| / h, both far below 1e-6 relative.
    assert!(worst_f < 1e-6 * fmax, "force: {worst_f:e} vs {fmax:e}");
    assert!(worst_k < 1e-6 * kmax, "tangent: {worst_k:e} vs {kmax:e}");
}

#[test]
fn force_and_tangent_are_the_derivatives_of_the_energy() {
    check_derivatives(Arc::new(UncoupledNeoHookean::from_young_poisson(
        1.0e6, 0.49,
    )));
    check_derivatives(Arc::new(MooneyRivlin {
        c10: 0.3e6,
        c01: 0.1e6,
        kappa: 50.0e6,
    }));
}

#[test]
fn patch_reproduces_a_large_homogeneous_deformation() {
    let (mesh, boundary) = shaken_tet_cube(3, 0.1, 4242);
    let err = homogeneous_patch_error(&mesh, &boundary, ANP);
    // Newton stops at a relative residual of 1e-12; displacements are ~0.3 m.
    assert!(err < 1e-10, "max nodal error {err:e} m");
}

/// Largest |J − 1| over the nodal patches and over the elements' J̄ (the mean of their
/// nodes' J, the volume change their material sees).
fn volume_change(disc: &Discretisation, u: &[f64]) -> (f64, f64) {
    let patches: &NodalPatches = disc.patches.as_ref().expect("anp elements");
    let state = patches.state(&disc.tets().nodes, &disc.tets().gauss, u);
    let nodal = state
        .nodal_ratio
        .iter()
        .fold(0.0f64, |m, j| m.max((j - 1.0).abs()));
    let element = disc
        .tets()
        .nodes
        .iter()
        .map(|t| {
            t.iter()
                .map(|&n| state.nodal_ratio[patches.patch_of[n] as usize])
                .sum::<f64>()
                / 4.0
        })
        .fold(0.0f64, |m, j| m.max((j - 1.0).abs()));
    (nodal, element)
}

#[test]
fn block_under_large_shear_keeps_its_volume() {
    let mesh = generate::block([1.0, 1.0, 1.0], [4, 4, 4]).split_hexes_into_tets();
    let s = sheared_block(&mesh, ANP, NU);
    let material: Arc<dyn Hyperelastic> =
        Arc::new(UncoupledNeoHookean::from_young_poisson(1.0e6, NU));
    let disc = Discretisation::with_formulations(&[(&mesh, material)], &[ANP]).unwrap();
    let (nodal, element) = volume_change(&disc, &s.state.u);
    eprintln!("large shear, ν = {NU}: max |J_a − 1| = {nodal:.2e}, max |J̄_e − 1| = {element:.2e}");
    // κ/μ = 5000: a pressure of the order of μ changes the volume by ~2e-4. The elements'
    // J̄ (what their stress is computed with) stays within 1e-3; the largest nodal |J_a − 1|
    // is at the ends of the clamped edges, where the free sides meet the clamp (the
    // pressure of simple shear with free sides is singular there) and a patch holds one or
    // two elements.
    assert!(element < 1e-3, "max |J̄_e − 1| = {element}");
    assert!(nodal < 2e-3, "max |J_a − 1| = {nodal}");
}

/// The plane-strain cantilever of tests/fbar_locking.rs (L/h = 10, a small tip shear load,
/// linear regime) on `ny` hexahedral layers each split into tetrahedra. Returns the tip
/// deflection in units of the Euler-Bernoulli value.
fn cantilever(ny: usize, element: Formulation) -> f64 {
    cantilever_nu(ny, element, NU)
}

fn cantilever_nu(ny: usize, element: Formulation, nu: f64) -> f64 {
    cantilever_beam(ny, true, element, nu, Section::PlaneStrain { nu_load: NU })
}

#[test]
fn tet_cantilever_does_not_lock() {
    let anp: Vec<f64> = [4, 8, 16].iter().map(|&n| cantilever(n, ANP)).collect();
    let linear16 = cantilever(16, Formulation::Standard);
    eprintln!(
        "plane-strain tet cantilever ν = {NU}: anp ny = 4, 8, 16: {:.4} {:.4} {:.4}; \
         linear tet4 ny = 16: {linear16:.4}",
        anp[0], anp[1], anp[2]
    );
    // The converged answer of this model: 0.996 of Euler-Bernoulli, the Richardson
    // extrapolation of the F-bar hexahedra of tests/fbar_locking.rs (docs/elements.md), an
    // independent discretisation of the same continuum problem (±0.3 %).
    let converged = 0.996;
    assert!(
        anp.windows(2).all(|w| w[1] > w[0]),
        "not converging: {anp:?}"
    );
    let err16 = (anp[2] - converged).abs() / converged;
    assert!(err16 < 0.05, "anp at 16 layers: {err16:.3} off");
    assert!(linear16 < 0.1 * converged, "linear tet4: {linear16}");
    // The same beam in 3-D (square section, sides free), 4 layers: the linear tetrahedron
    // is locked, the averaged-nodal-pressure one carries most of the bending.
    let (anp3, linear3) = (
        cantilever_3d(4, ANP, true),
        cantilever_3d(4, Formulation::Standard, true),
    );
    eprintln!("3-D tet cantilever, 4 layers: anp {anp3:.4}, linear tet4 {linear3:.4}");
    assert!(anp3 > 0.75 && linear3 < 0.05, "{anp3} {linear3}");
    // What remains at 4 layers is the tetrahedron's bending error, which the compressible
    // material shows too (ν = 0.3, against the 16-layer answer of the same element).
    let compressible = |n, element| cantilever_nu(n, element, 0.3);
    let (anp_c, linear_c) = (
        compressible(4, ANP) / compressible(16, ANP),
        compressible(4, Formulation::Standard) / compressible(16, Formulation::Standard),
    );
    eprintln!(
        "ν = 0.3, 4 layers, per the 16-layer value: anp {anp_c:.3}, linear tet4 {linear_c:.3}"
    );
    assert!(anp_c > linear_c && anp_c < 1.0, "{anp_c} {linear_c}");
}

/// A 3-D cantilever, square section h × h, L = 10 h, sides free, clamped at x = 0, a small
/// tip shear load; returns the tip deflection per Euler-Bernoulli PL³/(3EI).
fn cantilever_3d(ny: usize, element: Formulation, tets: bool) -> f64 {
    cantilever_beam(ny, tets, element, NU, Section::Square)
}

#[test]
fn scenario_key_selects_the_element_and_refuses_materials_without_a_split() {
    let text = |material: &str| {
        format!(
            r#"name = "t"
[time]
t_end = 1.0
dt = 0.5
mode = "quasi-static"
[[body]]
name = "b"
mesh = {{ generator = "block", size = [1.0, 1.0, 1.0], divisions = [1, 1, 1] }}
material = {material}
element = "anp"
density = 1000.0
"#
        )
    };
    let path = std::path::Path::new("anp.toml");
    let ok = adhesim_io::scenario::parse(
        &text(r#"{ model = "mooney-rivlin", c10 = 0.3e6, c01 = 0.1e6, kappa = 1e9 }"#),
        path,
    )
    .expect("a valid scenario")
    .problem;
    assert_eq!(ok.bodies[0].element, ANP);
    let err = adhesim_io::scenario::parse(&text(r#"{ model = "blatz-ko", g = 1e6 }"#), path)
        .expect_err("Blatz-Ko has no volumetric split")
        .to_string();
    assert!(
        err.contains("element") && err.contains("uncoupled-neo-hookean"),
        "{err}"
    );
}

/// Relaxation of a unit cube (symmetry supports on x = 0, y = 0, z = 0) stretched by 20 % in
/// x over 0.1 s and held to t = 1 s, steps of 10 ms; nearly incompressible (κ = 10⁴ μ₀)
/// neo-Hookean with two Prony terms. Returns the axial force on the x = 1 face after every
/// step [N].
fn relaxation(mesh: Mesh, element: Formulation) -> Vec<f64> {
    use adhesim::material::{PronyTerm, Viscoelastic};
    let mu0 = 1.0e6;
    let material: Arc<dyn Hyperelastic> = Arc::new(Viscoelastic {
        elastic: Arc::new(UncoupledNeoHookean {
            c10: mu0 / 2.0,
            kappa: 1.0e4 * mu0,
        }),
        terms: vec![
            PronyTerm { g: 0.3, tau: 0.1 },
            PronyTerm { g: 0.2, tau: 1.0 },
        ],
    });
    let mut p = one_body(mesh.clone(), material, 1000.0, quasi_static(1.0, 0.01));
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-10;
    for (set, k) in [("left", 0), ("bottom", 1), ("back", 2)] {
        let mut c = [false; 3];
        c[k] = true;
        p.dirichlet.push(fixed(mesh.node_sets[set].clone(), c));
    }
    let right = mesh.node_sets["right"].clone();
    p.dirichlet.push(Dirichlet {
        nodes: right.clone(),
        components: [true, false, false],
        translation: [
            Table {
                t: vec![0.0, 0.1],
                v: vec![0.0, 0.2],
            },
            Table::constant(0.0),
            Table::constant(0.0),
        ],
        rotation: None,
    });
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    let mut out = Vec::new();
    while !s.finished() {
        s.step().expect("relaxation step converges");
        let f = s.snapshot().f_int0;
        out.push(right.iter().map(|&n| f[3 * n]).sum::<f64>());
    }
    out
}

#[test]
fn viscoelastic_relaxation_matches_the_fbar_hexahedron() {
    // Uniaxial stretch is homogeneous: the six tetrahedra of a cube and the F-bar hexahedron
    // (checked against closed forms in tests/viscoelastic.rs) both represent it exactly, so
    // their forces must agree to the Newton tolerance at every step; the viscous part of the
    // averaged-nodal-pressure element acts on its isochoric stress as for the other elements.
    // So must the hex20 with its linear volume change (`element = "fbar"`), whose internal
    // variables are advanced at its points' F̄, and the standard hex20. (The one-hex20 runs
    // cut their first step in two, so they are compared with each other, not with the hex8.)
    let cube = generate::block([1.0, 1.0, 1.0], [1, 1, 1]);
    let hex = relaxation(cube.clone(), Formulation::FBar);
    let tet = relaxation(cube.split_hexes_into_tets(), ANP);
    let hex20 = relaxation(cube.with_mid_side_nodes(), Formulation::FBar);
    let standard20 = relaxation(cube.with_mid_side_nodes(), Formulation::Standard);
    let peak = hex.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let off = |one: &[f64], other: &[f64]| {
        assert_eq!(one.len(), other.len(), "the same steps");
        one.iter()
            .zip(other)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
    };
    let (worst, worst20) = (off(&hex, &tet), off(&standard20, &hex20));
    eprintln!(
        "relaxation: peak {peak:.4e} N, end {:.4e} N, max difference tets/hex {worst:.1e} N, hex20 linear θ/standard {worst20:.1e} N",
        hex[hex.len() - 1]
    );
    assert!(worst < 1e-6 * peak, "{worst} of {peak}");
    assert!(worst20 < 1e-6 * peak, "hex20: {worst20} of {peak}");
    let end20 = hex20[hex20.len() - 1];
    assert!(
        (end20 - hex[hex.len() - 1]).abs() < 1e-2 * peak,
        "hex20 at 1 s: {end20}"
    );
    // It relaxed: by t = 1 s the fast term is gone and part of the slow one.
    assert!(hex[hex.len() - 1] < 0.75 * peak, "{hex:?}");
}
