//! Helpers shared by the verification tests.
#![allow(dead_code)]

use adhesim::fbar::Formulation;
use adhesim::material::{Hyperelastic, UncoupledNeoHookean};
use adhesim::mesh::{generate, Mesh};
use adhesim::problem::{Body, Dirichlet, NodalLoad, Problem, Table, TimeSettings};
use adhesim::time::Stepper;
use adhesim_io::scenario::{load_with, LoadOptions, Override};
use std::path::Path;
use std::sync::Arc;

/// The scenario `file` of the repository (its path from the repository's root) with the
/// `--set`-style overrides `sets`.
pub fn scenario(file: &str, sets: &[&str]) -> Problem {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(file);
    let options = LoadOptions {
        variant: None,
        overrides: sets.iter().map(|s| Override::parse(s).unwrap()).collect(),
    };
    load_with(&path, &options)
        .unwrap_or_else(|e| panic!("{e}"))
        .problem
}

/// Deterministic pseudo-random numbers in [−1, 1) (xorshift), so tests are repeatable.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

pub fn zero3() -> [Table; 3] {
    [
        Table::constant(0.0),
        Table::constant(0.0),
        Table::constant(0.0),
    ]
}

/// Fixes the given components of a node set at zero.
pub fn fixed(nodes: Vec<usize>, components: [bool; 3]) -> Dirichlet {
    Dirichlet {
        nodes,
        components,
        translation: zero3(),
        rotation: None,
    }
}

/// A one-body problem with no boundary conditions yet.
pub fn one_body(
    mesh: Mesh,
    material: Arc<dyn Hyperelastic>,
    density: f64,
    time: TimeSettings,
) -> Problem {
    Problem {
        name: "test".into(),
        bodies: vec![Body {
            name: "body".into(),
            mesh,
            material,
            density,
            initial_velocity: [0.0; 3],
            element: Default::default(),
            plane_strain: false,
        }],
        dirichlet: vec![],
        loads: vec![],
        gravity: Default::default(),
        time,
        contacts: vec![],
    }
}

pub fn quasi_static(t_end: f64, dt: f64) -> TimeSettings {
    TimeSettings {
        t_end,
        dt,
        quasi_static: true,
        newton_tol: 1e-12,
        ..TimeSettings::default()
    }
}

/// The table 0 at t = 0 rising linearly to `v` at t = 1.
pub fn ramp(v: f64) -> Table {
    Table {
        t: vec![0.0, 1.0],
        v: vec![0.0, v],
    }
}

/// Runs a quasi-static problem to its end; returns the stepper.
pub fn solve(p: Problem) -> Stepper {
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    while !s.finished() {
        s.step().expect("quasi-static load step converges");
    }
    s
}

/// Moves every node of `mesh` off its boundary at random by up to `shake` / `n` in each
/// direction (`n` elements along the unit cube's side) and returns the boundary nodes.
pub fn shake_interior(mesh: &mut Mesh, n: usize, shake: f64, seed: u64) -> Vec<usize> {
    let boundary: std::collections::BTreeSet<usize> = mesh
        .boundary_faces()
        .iter()
        .flat_map(|f| f.nodes().to_vec())
        .collect();
    let mut rng = Rng(seed);
    for i in 0..mesh.num_nodes() {
        if !boundary.contains(&i) {
            for k in 0..3 {
                mesh.nodes[i][k] += shake / n as f64 * rng.next();
            }
        }
    }
    boundary.into_iter().collect()
}

/// Puts the mid-edge nodes of the `N`-node cells of type `element` (corners first, then one
/// node per edge of `edges`) back at the middle of their straight edges.
pub fn straighten_mid_edges<const N: usize>(
    mesh: &mut Mesh,
    element: &adhesim::element::ElementType,
    edges: &[[usize; 2]],
) {
    let corners = N - edges.len();
    let cells = mesh.cells_of::<N>(element).to_vec();
    for c in &cells {
        for (m, [i, j]) in edges.iter().enumerate() {
            let (a, b) = (mesh.nodes[c[*i]], mesh.nodes[c[*j]]);
            mesh.nodes[c[corners + m]] = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
        }
    }
}

/// Prescribes u = A x on the `boundary` nodes of `mesh` for a body of `material` with element
/// kinematics `element`, solves, and returns the largest nodal error against A x [m].
fn patch_error(
    mesh: &Mesh,
    boundary: &[usize],
    material: Arc<dyn Hyperelastic>,
    element: Formulation,
    a: [[f64; 3]; 3],
) -> f64 {
    let field =
        |x: [f64; 3]| -> [f64; 3] { std::array::from_fn(|i| (0..3).map(|j| a[i][j] * x[j]).sum()) };
    let mut p = one_body(mesh.clone(), material, 1000.0, quasi_static(1.0, 1.0));
    p.bodies[0].element = element;
    for &n in boundary {
        p.dirichlet.push(Dirichlet {
            nodes: vec![n],
            components: [true; 3],
            translation: field(mesh.nodes[n]).map(ramp),
            rotation: None,
        });
    }
    let s = solve(p);
    let mut err: f64 = 0.0;
    for (i, &x) in mesh.nodes.iter().enumerate() {
        for (k, uk) in field(x).iter().enumerate() {
            err = err.max((s.state.u[3 * i + k] - uk).abs());
        }
    }
    err
}

/// Patch test: prescribes u = A x on the `boundary` nodes of `mesh` (A with stretches and
/// shears of 10-30 % and J ≠ 1) for a nearly incompressible neo-Hookean body of elements
/// `element`, and returns the largest nodal error against A x [m] (the element must
/// reproduce the homogeneous deformation exactly, to the Newton tolerance).
pub fn homogeneous_patch_error(mesh: &Mesh, boundary: &[usize], element: Formulation) -> f64 {
    let a = [[0.3, 0.2, 0.0], [0.0, -0.1, 0.05], [0.1, 0.0, 0.1]];
    let material: Arc<dyn Hyperelastic> =
        Arc::new(UncoupledNeoHookean::from_young_poisson(1.0e6, 0.45));
    patch_error(mesh, boundary, material, element, a)
}

/// Small-strain patch test: u = A x (strains of 1e-4 to 2e-3) prescribed on the `boundary`
/// nodes of a linear elastic body (E = 1 MPa, ν = 0.3); the largest nodal error [m].
pub fn linear_patch_error(mesh: &Mesh, boundary: &[usize]) -> f64 {
    let a = [
        [1e-3, 2e-4, -3e-4],
        [5e-4, -1e-3, 1e-4],
        [-2e-4, 3e-4, 2e-3],
    ];
    let material: Arc<dyn Hyperelastic> = Arc::new(
        adhesim::material::LinearElastic::from_young_poisson(1e6, 0.3),
    );
    patch_error(mesh, boundary, material, Formulation::Standard, a)
}

/// The cross-section of [`cantilever_beam`].
#[derive(Clone, Copy)]
pub enum Section {
    /// A slab one element thick with every node held out of plane; the tip load aims at
    /// Euler-Bernoulli's δ = 1e-3 L for E′ = E/(1 − ν_load²).
    PlaneStrain { nu_load: f64 },
    /// A square h × h section with free sides (`ny` elements across each way); the tip load
    /// aims at δ = 1e-3 L for E.
    Square,
}

/// A cantilever (L = 1 m, h = 0.1 m, `ny` elements through the height and 10 `ny` along,
/// hexahedra or each split into tetrahedra) of a neo-Hookean material with E = 1 MPa and
/// Poisson ratio `nu`, clamped at x = 0, under a small tip shear load (linear regime).
/// Returns the mean tip deflection in units of 1e-3 L (1 is Euler-Bernoulli's answer, for a
/// plane-strain section when `nu_load` = `nu`).
pub fn cantilever_beam(
    ny: usize,
    tets: bool,
    element: Formulation,
    nu: f64,
    section: Section,
) -> f64 {
    let cells = if tets { Cells::Tet4 } else { Cells::Hex8 };
    cantilever_beam_of(ny, cells, element, nu, section)
}

/// The cells of a structured test mesh.
#[derive(Clone, Copy, Debug)]
pub enum Cells {
    /// The generator's hexahedra.
    Hex8,
    /// Each hexahedron split into six tetrahedra.
    Tet4,
    /// The tetrahedra with a node at the middle of each edge.
    Tet10,
    /// The hexahedra with a node at the middle of each edge.
    Hex20,
    /// The hex20 with a node at the centre of each face and of each cell.
    Hex27,
}

impl Cells {
    /// The block `size` [m] with `divisions` hexahedra per direction, in these cells.
    pub fn block(self, size: [f64; 3], divisions: [usize; 3]) -> Mesh {
        let hexes = generate::block(size, divisions);
        match self {
            Cells::Hex8 => hexes,
            Cells::Tet4 => hexes.split_hexes_into_tets(),
            Cells::Tet10 => hexes.split_hexes_into_tets().with_mid_side_nodes(),
            Cells::Hex20 => hexes.with_mid_side_nodes(),
            Cells::Hex27 => hexes.with_mid_side_nodes().with_face_and_centre_nodes(),
        }
    }
}

/// [`cantilever_beam`] in the cells `cells`.
pub fn cantilever_beam_of(
    ny: usize,
    cells: Cells,
    element: Formulation,
    nu: f64,
    section: Section,
) -> f64 {
    let (l, h, e) = (1.0, 0.1, 1.0e6);
    // Plane strain bends with E′ = E/(1 − ν²).
    let (depth, nz, plane_strain_factor) = match section {
        Section::PlaneStrain { nu_load } => (h / ny as f64, 1, 1.0 - nu_load * nu_load),
        Section::Square => (h, ny, 1.0),
    };
    let mesh = cells.block([l, h, depth], [10 * ny, ny, nz]);
    let material = UncoupledNeoHookean::from_young_poisson(e, nu);
    let mut p = one_body(
        mesh.clone(),
        Arc::new(material),
        1000.0,
        quasi_static(1.0, 1.0),
    );
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-10;
    let left = mesh.node_sets["left"].clone();
    match section {
        Section::PlaneStrain { .. } => {
            p.dirichlet
                .push(fixed((0..mesh.num_nodes()).collect(), [false, false, true]));
            p.dirichlet.push(fixed(left, [true, true, false]));
        }
        Section::Square => p.dirichlet.push(fixed(left, [true, true, true])),
    }
    let right = mesh.node_sets["right"].clone();
    let inertia = depth * h.powi(3) / 12.0;
    let p_tip = 1e-3 * l * 3.0 * e / plane_strain_factor * inertia / l.powi(3);
    p.loads.push(NodalLoad {
        nodes: right.clone(),
        total_force: [Table::constant(0.0), ramp(-p_tip), Table::constant(0.0)],
    });
    let s = solve(p);
    let tip = right.iter().map(|&n| s.state.u[3 * n + 1]).sum::<f64>() / right.len() as f64;
    -tip / (1e-3 * l)
}

/// A unit cube `mesh` of elements `element` and a nearly incompressible neo-Hookean material
/// (E = 1 MPa, Poisson ratio `nu`): bottom clamped, top moved sideways by 0.6 (shear strain
/// 0.6) with its height held, sides free, in four quasi-static increments. Returns the
/// solved stepper.
pub fn sheared_block(mesh: &Mesh, element: Formulation, nu: f64) -> Stepper {
    let material = UncoupledNeoHookean::from_young_poisson(1.0e6, nu);
    let mut p = one_body(
        mesh.clone(),
        Arc::new(material),
        1000.0,
        quasi_static(1.0, 0.25),
    );
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-10;
    p.dirichlet
        .push(fixed(mesh.node_sets["bottom"].clone(), [true; 3]));
    p.dirichlet.push(Dirichlet {
        nodes: mesh.node_sets["top"].clone(),
        components: [true; 3],
        translation: [ramp(0.6), Table::constant(0.0), Table::constant(0.0)],
        rotation: None,
    });
    solve(p)
}

/// Two bodies of the Gmsh mesh `mesh` (a file in tests/data), one on top of the other, in
/// frictionless contact from the upper one's `bottom` to the lower one's `top` with the
/// discretisation `discretisation`, parsed as a scenario file of tests/data would be.
pub fn parse_two_boxes(
    mesh: &str,
    discretisation: &str,
) -> Result<adhesim_io::scenario::Scenario, adhesim_io::scenario::ScenarioError> {
    let text = format!(
        r#"
name = "boxes"
[time]
t_end = 1.0
dt = 1.0
mode = "quasi-static"
[[body]]
name = "lower"
mesh = {{ file = "{mesh}" }}
material = {{ model = "neo-hookean", young = 1e6, poisson = 0.3 }}
density = 1000.0
[[body]]
name = "upper"
mesh = {{ file = "{mesh}" }}
material = {{ model = "neo-hookean", young = 1e6, poisson = 0.3 }}
density = 1000.0
[[contact]]
name = "c"
slave = {{ body = "upper", set = "bottom" }}
master = {{ body = "lower", set = "top" }}
friction = 0.0
discretisation = "{discretisation}"
"#
    );
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/boxes.toml");
    adhesim_io::scenario::parse(&text, &path)
}
