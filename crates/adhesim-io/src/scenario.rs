//! Scenario files (TOML) parsed and validated into a [`Scenario`]: the [`Problem`] the stepper
//! solves and the [`OutputSettings`] of what the run writes.
//!
//! Parsing (serde) rejects unknown keys and wrong types with the line and column; validation
//! then checks values (positive moduli, time step, existing node sets, ...) and names the key
//! that is wrong and what would be valid. The format is documented in `docs/scenario.md`.

use crate::output::settings::{MapRequest, OutputSettings, Track};
use adhesim::contact::detect::{thickness_twins, tributary_areas};
use adhesim::contact::interface::Interface;
use adhesim::contact::law::Orthotropy;
use adhesim::contact::rcc::DEFAULT_BETA_EPS;
use adhesim::contact::{ContactPair, InterfaceLaw, Master, RccParams, RigidMotion, RigidShape};
use adhesim::material::{self, Hyperelastic};
use adhesim::mesh::generate::{self, FlatSide};
use adhesim::mesh::{gmsh, quality};
use adhesim::mesh::{Face, Mesh};
use adhesim::problem::{
    Body, ContactSolver, Dirichlet, NodalLoad, Problem, Rotation, Table, TimeSettings,
};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A scenario that could not be read or is invalid. The message names the file, the key or
/// line, and what would be valid.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct ScenarioError {
    /// The scenario file.
    pub file: PathBuf,
    /// What is wrong and what would be valid.
    pub message: String,
}

// ---------------------------------------------------------------------------------------
// The file as written (serde).

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileScenario {
    name: Option<String>,
    time: FileTime,
    #[serde(default)]
    gravity: Option<FileGravity>,
    #[serde(rename = "body")]
    bodies: Vec<FileBody>,
    #[serde(default, rename = "boundary")]
    boundaries: Vec<FileBoundary>,
    #[serde(default, rename = "load")]
    loads: Vec<FileLoad>,
    #[serde(default, rename = "contact")]
    contacts: Vec<FileContact>,
    #[serde(default, rename = "track")]
    tracks: Vec<FileTrack>,
    #[serde(default)]
    output: Option<FileOutput>,
    #[serde(default, rename = "map")]
    maps: Vec<FileMap>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileMap {
    contact: String,
    fields: Vec<String>,
    times: Vec<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileTime {
    t_end: f64,
    dt: f64,
    dt_min: Option<f64>,
    theta: Option<f64>,
    xi: Option<f64>,
    mode: Option<String>,
    newton_tol: Option<f64>,
    max_newton: Option<usize>,
    mass: Option<String>,
    rayleigh_alpha: Option<f64>,
    rayleigh_beta: Option<f64>,
    contact_solver: Option<String>,
    contact_tol: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileBody {
    name: String,
    mesh: FileMesh,
    material: FileMaterial,
    density: f64,
    #[serde(default)]
    initial_velocity: Option<[f64; 3]>,
    #[serde(default)]
    plane_strain: bool,
    #[serde(default)]
    offset: Option<[f64; 3]>,
    #[serde(default)]
    element: Option<String>,
}

/// `mesh = { generator = ..., ... }` (a built-in mesh) or `mesh = { file = ..., ... }` (a
/// Gmsh file).
#[derive(Debug)]
enum FileMesh {
    Generated(FileGenerator),
    File(FileMeshFile),
}

impl<'de> Deserialize<'de> for FileMesh {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let table = toml::Table::deserialize(d)?;
        let (gen, file) = (table.contains_key("generator"), table.contains_key("file"));
        let value = toml::Value::Table(table);
        match (gen, file) {
            (true, false) => value.try_into().map(FileMesh::Generated).map_err(D::Error::custom),
            (false, true) => value.try_into().map(FileMesh::File).map_err(D::Error::custom),
            (true, true) => Err(D::Error::custom(
                "give either `generator` (a built-in mesh) or `file` (a Gmsh .msh file), not both",
            )),
            (false, false) => Err(D::Error::custom(
                "a mesh needs `generator` (\"block\", \"disk\", \"half_disk\", \"quarter_hemisphere\") or `file` (a Gmsh MSH 4.1 file)",
            )),
        }
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileMeshFile {
    file: PathBuf,
    volumes: Option<Vec<String>>,
    scale: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields, tag = "generator", rename_all = "snake_case")]
enum FileGenerator {
    Block {
        size: [f64; 3],
        divisions: [usize; 3],
    },
    Disk {
        radius: f64,
        thickness: f64,
        n_quarter: usize,
        n_radial: usize,
    },
    HalfDisk {
        radius: f64,
        thickness: f64,
        n_quarter: usize,
        n_radial: usize,
        flat_side: String,
    },
    QuarterHemisphere {
        radius: f64,
        n: usize,
    },
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileMaterial {
    model: String,
    g: Option<f64>,
    young: Option<f64>,
    poisson: Option<f64>,
    c10: Option<f64>,
    c01: Option<f64>,
    d1: Option<f64>,
    kappa: Option<f64>,
    mu: Option<Vec<f64>>,
    alpha: Option<Vec<f64>>,
    prony: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(untagged)]
enum FileTable {
    Constant(f64),
    Points(Vec<[f64; 2]>),
}

/// `gravity = [gx, gy, gz]`, or tables per component as for loads.
#[derive(Deserialize, Debug)]
#[serde(
    untagged,
    expecting = "a vector [gx, gy, gz] [m/s²], or components over time such as \
                 { y = [[0.0, 0.0], [1.0, -9.81]] } (each x, y, z a number or [[t, g], ...])"
)]
enum FileGravity {
    Constant([f64; 3]),
    Tables(FileComponents),
}

#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
struct FileComponents {
    x: Option<FileTable>,
    y: Option<FileTable>,
    z: Option<FileTable>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileRotation {
    axis: [f64; 3],
    center: [f64; 3],
    angular_velocity: Option<f64>,
    start: Option<f64>,
    angle: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileBoundary {
    #[serde(default)]
    name: Option<String>,
    body: String,
    set: String,
    #[serde(default)]
    fix: Vec<String>,
    #[serde(default)]
    displacement: Option<FileComponents>,
    #[serde(default)]
    rotation: Option<FileRotation>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileLoad {
    body: String,
    set: String,
    force: FileComponents,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileContact {
    name: String,
    slave: FileSetRef,
    master: FileMaster,
    #[serde(default)]
    motion: Option<FileMotion>,
    friction: f64,
    #[serde(default)]
    adhesion: Option<FileAdhesion>,
    #[serde(default)]
    orthotropy: Option<FileOrthotropy>,
    #[serde(default)]
    detection_distance: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileOrthotropy {
    axis: [f64; 3],
    friction_2: f64,
    #[serde(default)]
    ct_2: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileSetRef {
    body: String,
    set: String,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileMaster {
    body: Option<String>,
    set: Option<String>,
    rigid: Option<String>,
    point: Option<[f64; 3]>,
    normal: Option<[f64; 3]>,
    center: Option<[f64; 3]>,
    axis: Option<[f64; 3]>,
    radius: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileMotion {
    #[serde(default)]
    displacement: Option<FileComponents>,
    #[serde(default)]
    rotation: Option<FileRotation>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileAdhesion {
    w: f64,
    cn: f64,
    ct: f64,
    b: f64,
    eps: Option<f64>,
    fatigue_energy: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileTrack {
    name: String,
    body: String,
    point: Option<[f64; 3]>,
    node: Option<usize>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileOutput {
    frame_interval: Option<f64>,
    figures: Option<bool>,
}

// ---------------------------------------------------------------------------------------
// Validation.

struct Ctx<'a> {
    file: &'a Path,
}

impl Ctx<'_> {
    fn err(&self, message: impl Into<String>) -> ScenarioError {
        ScenarioError {
            file: self.file.to_path_buf(),
            message: message.into(),
        }
    }
    fn positive(&self, key: &str, v: f64) -> Result<f64, ScenarioError> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("`{key}` must be a positive finite number, got {v}")))
        }
    }
    fn finite(&self, key: &str, v: f64) -> Result<f64, ScenarioError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(format!("`{key}` must be a finite number, got {v}")))
        }
    }
    fn finite3(&self, key: &str, v: [f64; 3]) -> Result<[f64; 3], ScenarioError> {
        for (k, c) in v.iter().enumerate() {
            self.finite(&format!("{key}[{k}]"), *c)?;
        }
        Ok(v)
    }
    fn count(&self, key: &str, n: usize, max: usize) -> Result<usize, ScenarioError> {
        if (1..=max).contains(&n) {
            Ok(n)
        } else {
            Err(self.err(format!(
                "`{key}` must be a whole number from 1 to {max}, got {n}"
            )))
        }
    }
}

pub mod prepare;

pub use prepare::Override;

/// How a scenario file is to be read: an optional named variant (`[variants.NAME]`) and
/// overrides of single keys, applied in that order.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Name of a `[variants.NAME]` table to apply (e.g. `coarse`).
    pub variant: Option<String>,
    /// `key=value` overrides (dotted keys, see [`prepare`]).
    pub overrides: Vec<Override>,
}

/// A validated scenario: the physics of the run and what it writes, apart.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// What the stepper solves.
    pub problem: Problem,
    /// What the run writes besides the history's own columns.
    pub output: OutputSettings,
}

/// Reads and validates a scenario file.
pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
    load_with(path, &LoadOptions::default())
}

/// Reads a scenario file, applies a variant and overrides, and validates it.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
        file: path.to_path_buf(),
        message: format!("cannot read the scenario file: {e}"),
    })?;
    parse_with(&text, path, options)
}

/// Parses and validates scenario text; `path` names the file in errors and sets the default
/// run name.
pub fn parse(text: &str, path: &Path) -> Result<Scenario, ScenarioError> {
    parse_with(text, path, &LoadOptions::default())
}

/// [`parse`] with a variant and overrides.
pub fn parse_with(
    text: &str,
    path: &Path,
    options: &LoadOptions,
) -> Result<Scenario, ScenarioError> {
    let ctx = Ctx { file: path };
    let hint = "(see docs/scenario.md for the valid keys and types)";
    let mut doc: toml::Table = toml::from_str(text)
        .map_err(|e| ctx.err(format!("{}\n{hint}", e.to_string().trim_end())))?;
    let prepared = prepare::prepare(&mut doc, options.variant.as_deref(), &options.overrides)
        .map_err(|e| ctx.err(e))?;
    // A document that pre-processing left as written is read from the text once more, so
    // that type errors point at their line; a changed one can only be read from the value.
    let raw: FileScenario = if prepared.changed {
        let applied: Vec<String> = options
            .variant
            .iter()
            .map(|v| format!("variant {v}"))
            .chain(
                options
                    .overrides
                    .iter()
                    .map(|o| format!("{}={}", o.key, o.value)),
            )
            .collect();
        FileScenario::deserialize(toml::Value::Table(doc)).map_err(|e| {
            let message = e.to_string();
            let why = if message.contains("floating point") && !prepared.fractional.is_empty() {
                format!(
                    "; expressions that gave fractional numbers: {} (keys that count, such \
                     as `divisions`, need whole numbers)",
                    prepared.fractional.join(", ")
                )
            } else {
                String::new()
            };
            ctx.err(format!(
                "{}{}{why}\n{hint}",
                message.trim_end(),
                if applied.is_empty() {
                    " (after evaluating parameters and expressions)".to_string()
                } else {
                    format!(" (after applying {})", applied.join(", "))
                }
            ))
        })?
    } else {
        toml::from_str(text)
            .map_err(|e| ctx.err(format!("{}\n{hint}", e.to_string().trim_end())))?
    };
    validate(raw, &ctx)
}

fn validate(raw: FileScenario, ctx: &Ctx) -> Result<Scenario, ScenarioError> {
    let name = raw.name.clone().unwrap_or_else(|| {
        ctx.file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "run".into())
    });
    if name.is_empty() || name.contains(['/', '\\']) {
        return Err(ctx.err(format!(
            "`name` must be a non-empty file stem without slashes, got {name:?}"
        )));
    }
    let time = validate_time(&raw.time, ctx)?;
    if raw.bodies.is_empty() {
        return Err(ctx.err("at least one [[body]] is needed"));
    }
    let mut bodies = Vec::new();
    let mut body_index: BTreeMap<String, usize> = BTreeMap::new();
    let mut dirichlet = Vec::new();
    // Reaction names, one per entry of `dirichlet` ("" for the plane-strain constraints).
    let mut boundary_names: Vec<String> = Vec::new();
    for (i, b) in raw.bodies.iter().enumerate() {
        let key = format!("body[{i}]");
        if body_index.insert(b.name.clone(), i).is_some() {
            return Err(ctx.err(format!(
                "`{key}.name`: the body name {:?} is used twice; names must be unique",
                b.name
            )));
        }
        let mut mesh = build_mesh(&b.mesh, &format!("{key}.mesh"), ctx)?;
        if mesh.num_cells() == 0 || mesh.num_nodes() == 0 {
            return Err(ctx.err(format!(
                "`{key}.mesh` of body {:?} has no elements; a body needs at least one hexahedron or tetrahedron",
                b.name
            )));
        }
        if let Some(off) = b.offset {
            mesh.translate(ctx.finite3(&format!("{key}.offset"), off)?);
        }
        let material = build_material(&b.material, &format!("{key}.material"), ctx)?;
        let density = ctx.positive(&format!("{key}.density"), b.density)?;
        let element = match b.element.as_deref() {
            None | Some("standard") => adhesim::fbar::Formulation::Standard,
            Some("fbar") => {
                if material.small_strain() {
                    return Err(ctx.err(format!(
                        "`{key}.element` = \"fbar\" needs a finite-strain material; \"linear-elastic\" uses linear kinematics"
                    )));
                }
                adhesim::fbar::Formulation::FBar
            }
            Some("anp") => {
                if !adhesim::anp::has_volumetric_split(&*material) {
                    return Err(ctx.err(format!(
                        "`{key}.element` = \"anp\" needs a material with a bulk modulus split off: \"uncoupled-neo-hookean\", \"mooney-rivlin\" or \"ogden\" (optionally viscoelastic)"
                    )));
                }
                adhesim::fbar::Formulation::AveragedNodalPressure
            }
            Some(other) => {
                return Err(ctx.err(format!(
                    "`{key}.element` = {other:?}; valid values are \"standard\" (full integration), \"fbar\" (locking-free hexahedra) and \"anp\" (locking-free tetrahedra by averaged nodal pressure, F-bar hexahedra)"
                )))
            }
        };
        let initial_velocity = ctx.finite3(
            &format!("{key}.initial_velocity"),
            b.initial_velocity.unwrap_or([0.0; 3]),
        )?;
        bodies.push(Body {
            name: b.name.clone(),
            mesh,
            material,
            density,
            initial_velocity,
            element,
            plane_strain: b.plane_strain,
        });
    }
    let offsets = {
        let mut o = Vec::new();
        let mut n = 0;
        for b in &bodies {
            o.push(n);
            n += b.mesh.num_nodes();
        }
        o
    };
    // Plane strain: out-of-plane displacement fixed on every node of the body.
    for (i, b) in raw.bodies.iter().enumerate() {
        if b.plane_strain {
            let nodes = (0..bodies[i].mesh.num_nodes())
                .map(|n| n + offsets[i])
                .collect();
            boundary_names.push(String::new());
            dirichlet.push(Dirichlet {
                nodes,
                components: [false, false, true],
                translation: [
                    Table::constant(0.0),
                    Table::constant(0.0),
                    Table::constant(0.0),
                ],
                rotation: None,
            });
        }
    }
    let find_set =
        |key: &str, body: &str, set: &str| -> Result<Vec<usize>, ScenarioError> {
            let bi = *body_index.get(body).ok_or_else(|| {
                ctx.err(format!(
                    "`{key}.body` = {body:?} is not a body of this scenario; bodies are: {}",
                    body_index.keys().cloned().collect::<Vec<_>>().join(", ")
                ))
            })?;
            let mesh = &bodies[bi].mesh;
            let nodes =
                mesh.node_sets.get(set).ok_or_else(|| {
                    ctx.err(format!(
                "`{key}.set` = {set:?} is not a node set of body {body:?}; its sets are: {}",
                mesh.node_sets.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
                })?;
            if nodes.is_empty() {
                return Err(ctx.err(format!("`{key}.set` = {set:?} of body {body:?} is empty")));
            }
            Ok(nodes.iter().map(|n| n + offsets[bi]).collect())
        };
    for (i, bc) in raw.boundaries.iter().enumerate() {
        let key = format!("boundary[{i}]");
        let nodes = find_set(&key, &bc.body, &bc.set)?;
        let mut components = [false; 3];
        let zero = || {
            [
                Table::constant(0.0),
                Table::constant(0.0),
                Table::constant(0.0),
            ]
        };
        let mut translation = zero();
        for c in &bc.fix {
            let k = axis_index(c).ok_or_else(|| {
                ctx.err(format!(
                    "`{key}.fix` holds {c:?}; valid entries are \"x\", \"y\", \"z\""
                ))
            })?;
            components[k] = true;
        }
        if let Some(d) = &bc.displacement {
            for (k, (cname, t)) in [("x", &d.x), ("y", &d.y), ("z", &d.z)]
                .into_iter()
                .enumerate()
            {
                if let Some(t) = t {
                    if components[k] {
                        return Err(ctx.err(format!("`{key}`: component {cname} is both in `fix` and in `displacement`; give it once")));
                    }
                    components[k] = true;
                    translation[k] = build_table(t, &format!("{key}.displacement.{cname}"), ctx)?;
                }
            }
        }
        let rotation = match &bc.rotation {
            None => None,
            Some(r) => {
                components = [true; 3];
                Some(build_rotation(r, &format!("{key}.rotation"), ctx)?)
            }
        };
        if components == [false; 3] {
            return Err(ctx.err(format!(
                "`{key}` prescribes nothing: give `fix`, `displacement` or `rotation`"
            )));
        }
        let default_name = format!("{}.{}", bc.body, bc.set);
        let name = match &bc.name {
            Some(n) => {
                if n.is_empty() || n.contains(['\n', '\r', ',', '"']) {
                    return Err(ctx.err(format!(
                        "`{key}.name` = {n:?}: give a non-empty name without commas, quotes \
                         or line breaks (it heads history columns)"
                    )));
                }
                if boundary_names.contains(n) {
                    return Err(ctx.err(format!(
                        "`{key}.name`: the boundary name {n:?} is used twice; names must be unique"
                    )));
                }
                n.clone()
            }
            None if boundary_names.contains(&default_name) => format!("{default_name}.{i}"),
            None => default_name,
        };
        boundary_names.push(name);
        dirichlet.push(Dirichlet {
            nodes,
            components,
            translation,
            rotation,
        });
    }
    let mut loads = Vec::new();
    for (i, l) in raw.loads.iter().enumerate() {
        let key = format!("load[{i}]");
        let nodes = find_set(&key, &l.body, &l.set)?;
        let mut total_force = [
            Table::constant(0.0),
            Table::constant(0.0),
            Table::constant(0.0),
        ];
        for (k, (cname, t)) in [("x", &l.force.x), ("y", &l.force.y), ("z", &l.force.z)]
            .into_iter()
            .enumerate()
        {
            if let Some(t) = t {
                total_force[k] = build_table(t, &format!("{key}.force.{cname}"), ctx)?;
            }
        }
        loads.push(NodalLoad { nodes, total_force });
    }
    let plane_strain: Vec<bool> = raw.bodies.iter().map(|b| b.plane_strain).collect();
    let mut contacts = Vec::new();
    for (i, c) in raw.contacts.iter().enumerate() {
        contacts.push(build_contact(
            c,
            &format!("contact[{i}]"),
            &bodies,
            &body_index,
            &offsets,
            &plane_strain,
            ctx,
        )?);
    }
    {
        let mut names = std::collections::BTreeSet::new();
        for (i, c) in contacts.iter().enumerate() {
            if !names.insert(c.name.clone()) {
                return Err(ctx.err(format!(
                    "`contact[{i}].name`: the name {:?} is used twice; names must be unique",
                    c.name
                )));
            }
        }
    }
    let mut tracks = Vec::new();
    for (i, t) in raw.tracks.iter().enumerate() {
        let key = format!("track[{i}]");
        if t.name.is_empty() || t.name.contains([',', '"', '\n']) {
            return Err(ctx.err(format!(
                "`{key}.name` must be non-empty and hold no comma or quote, got {:?}",
                t.name
            )));
        }
        if raw.tracks[..i].iter().any(|o| o.name == t.name) {
            return Err(ctx.err(format!(
                "`{key}.name`: the track name {:?} is used twice; names must be unique",
                t.name
            )));
        }
        let bi = *body_index.get(&t.body).ok_or_else(|| {
            ctx.err(format!(
                "`{key}.body` = {:?} is not a body of this scenario; bodies are: {}",
                t.body,
                body_index.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })?;
        let mesh = &bodies[bi].mesh;
        let local = match (t.point, t.node) {
            (Some(p), None) => nearest_node(mesh, ctx.finite3(&format!("{key}.point"), p)?),
            (None, Some(n)) if n < mesh.num_nodes() => n,
            (None, Some(n)) => {
                return Err(ctx.err(format!("`{key}.node` = {n} is out of range: body {:?} has {} nodes (0 to {})", t.body, mesh.num_nodes(), mesh.num_nodes() - 1)))
            }
            _ => return Err(ctx.err(format!("`{key}` needs exactly one of `point` (a position [m]; the nearest node is tracked) or `node` (an index)"))),
        };
        tracks.push(Track {
            name: t.name.clone(),
            node: local + offsets[bi],
        });
    }
    let gravity = match &raw.gravity {
        None => adhesim::gravity::Gravity::default(),
        Some(FileGravity::Constant(g)) => {
            adhesim::gravity::Gravity::constant(ctx.finite3("gravity", *g)?)
        }
        Some(FileGravity::Tables(c)) => {
            let mut g = adhesim::gravity::Gravity::default();
            for (k, (cname, t)) in [("x", &c.x), ("y", &c.y), ("z", &c.z)]
                .into_iter()
                .enumerate()
            {
                if let Some(t) = t {
                    g.components[k] = build_table(t, &format!("gravity.{cname}"), ctx)?;
                }
            }
            g
        }
    };
    let frame_interval = match raw.output.as_ref().and_then(|o| o.frame_interval) {
        None => 0.0,
        Some(v) if v.is_finite() && v >= 0.0 => v,
        Some(v) => {
            return Err(ctx.err(format!(
                "`output.frame_interval` must be ≥ 0 (0 = every step), got {v}"
            )))
        }
    };
    let mut maps = Vec::new();
    for (i, m) in raw.maps.iter().enumerate() {
        let key = format!("map[{i}]");
        let pair = contacts
            .iter()
            .position(|c| c.name == m.contact)
            .ok_or_else(|| {
                ctx.err(format!(
                    "`{key}.contact` = {:?} is not a contact pair of this scenario; pairs are: {}",
                    m.contact,
                    contacts
                        .iter()
                        .map(|c| c.name.clone())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
        let valid = crate::output::maps::map_fields(contacts[pair].law.history_fields());
        if m.fields.is_empty() {
            return Err(ctx.err(format!(
                "`{key}.fields` is empty; valid fields are: {}",
                valid.join(", ")
            )));
        }
        for f in &m.fields {
            if !valid.contains(&f.as_str()) {
                return Err(ctx.err(format!(
                    "`{key}.fields` holds {f:?}; valid fields are: {}",
                    valid.join(", ")
                )));
            }
        }
        if m.times.is_empty() {
            return Err(ctx.err(format!(
                "`{key}.times` is empty; give the times [s] of the maps"
            )));
        }
        for (j, t) in m.times.iter().enumerate() {
            ctx.finite(&format!("{key}.times[{j}]"), *t)?;
            if j > 0 && *t <= m.times[j - 1] {
                return Err(ctx.err(format!("`{key}.times` must increase strictly")));
            }
        }
        maps.push(MapRequest {
            pair,
            fields: m.fields.clone(),
            times: m.times.clone(),
        });
    }
    let figures = raw.output.as_ref().and_then(|o| o.figures).unwrap_or(true);
    Ok(Scenario {
        problem: Problem {
            name,
            bodies,
            dirichlet,
            loads,
            gravity,
            time,
            contacts,
        },
        output: OutputSettings {
            frame_interval,
            figures,
            maps,
            boundary_names,
            tracks,
        },
    })
}

fn axis_index(c: &str) -> Option<usize> {
    match c {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    }
}

fn nearest_node(mesh: &Mesh, p: [f64; 3]) -> usize {
    let d2 = |x: &[f64; 3]| (0..3).map(|k| (x[k] - p[k]).powi(2)).sum::<f64>();
    (0..mesh.num_nodes())
        .min_by(|&a, &b| d2(&mesh.nodes[a]).total_cmp(&d2(&mesh.nodes[b])))
        .unwrap_or(0)
}

fn validate_time(t: &FileTime, ctx: &Ctx) -> Result<TimeSettings, ScenarioError> {
    let d = TimeSettings::default();
    let t_end = ctx.positive("time.t_end", t.t_end)?;
    let dt = ctx.positive("time.dt", t.dt)?;
    if dt > t_end {
        return Err(ctx.err(format!(
            "`time.dt` ({dt} s) must not exceed `time.t_end` ({t_end} s)"
        )));
    }
    let dt_min = ctx.positive(
        "time.dt_min",
        t.dt_min.unwrap_or((dt * 1e-6).min(d.dt_min.max(dt * 1e-9))),
    )?;
    if dt_min > dt {
        return Err(ctx.err(format!(
            "`time.dt_min` ({dt_min}) must not exceed `time.dt` ({dt})"
        )));
    }
    let theta = t.theta.unwrap_or(d.theta);
    if !(theta > 0.0 && theta <= 1.0) {
        return Err(ctx.err(format!(
            "`time.theta` must be in (0, 1] (½ = trapezoidal, 1 = backward Euler), got {theta}"
        )));
    }
    let xi = t.xi.unwrap_or(d.xi);
    if !(0.0..=1.0).contains(&xi) {
        return Err(ctx.err(format!("`time.xi` must be in [0, 1], got {xi}")));
    }
    let quasi_static = match t.mode.as_deref() {
        None | Some("dynamic") => false,
        Some("quasi-static") => true,
        Some(m) => {
            return Err(ctx.err(format!(
                "`time.mode` = {m:?}; valid values are \"dynamic\" and \"quasi-static\""
            )))
        }
    };
    let lumped_mass = match t.mass.as_deref() {
        None | Some("consistent") => false,
        Some("lumped") => true,
        Some(m) => {
            return Err(ctx.err(format!(
                "`time.mass` = {m:?}; valid values are \"consistent\" and \"lumped\""
            )))
        }
    };
    let newton_tol = t.newton_tol.unwrap_or(d.newton_tol);
    if !(newton_tol > 0.0 && newton_tol < 1.0) {
        return Err(ctx.err(format!(
            "`time.newton_tol` must be in (0, 1), got {newton_tol}"
        )));
    }
    let max_newton = ctx.count(
        "time.max_newton",
        t.max_newton.unwrap_or(d.max_newton),
        1000,
    )?;
    let alpha = t.rayleigh_alpha.unwrap_or(0.0);
    let beta = t.rayleigh_beta.unwrap_or(0.0);
    for (k, v) in [("time.rayleigh_alpha", alpha), ("time.rayleigh_beta", beta)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(ctx.err(format!("`{k}` must be ≥ 0, got {v}")));
        }
    }
    let contact_solver = match t.contact_solver.as_deref() {
        None => d.contact_solver,
        Some("newton") => ContactSolver::Newton,
        Some("gauss-seidel") => ContactSolver::GaussSeidel,
        Some("semismooth") => ContactSolver::Semismooth,
        Some("auto") => ContactSolver::Auto,
        Some(m) => {
            return Err(ctx.err(format!(
                "`time.contact_solver` = {m:?}; valid values are \"auto\", \"semismooth\", \"gauss-seidel\" and \"newton\""
            )))
        }
    };
    let contact_tol = t.contact_tol.unwrap_or(d.contact_tol);
    if !(contact_tol > 0.0 && contact_tol < 1.0) {
        return Err(ctx.err(format!(
            "`time.contact_tol` must be in (0, 1), got {contact_tol}"
        )));
    }
    Ok(TimeSettings {
        t_end,
        dt,
        dt_min,
        theta,
        xi,
        quasi_static,
        newton_tol,
        max_newton,
        lumped_mass,
        rayleigh: (alpha, beta),
        contact_solver,
        contact_tol,
    })
}

/// Largest element count per direction a generator accepts (guards against typos that
/// would exhaust memory).
const MAX_DIVISIONS: usize = 2000;

/// Largest number of cells a generated mesh may have (a typo such as
/// `divisions = [100000, 100000, 1]` would otherwise allocate for ever).
const MAX_CELLS: u128 = 5_000_000;

impl Ctx<'_> {
    /// Rejects a generated mesh of more than [`MAX_CELLS`] cells before it is built.
    fn cell_limit(&self, key: &str, what: &str, cells: u128) -> Result<(), ScenarioError> {
        if cells > MAX_CELLS {
            Err(self.err(format!(
                "`{key}`: {what} give {cells} cells, more than the limit of {MAX_CELLS}; use fewer divisions"
            )))
        } else {
            Ok(())
        }
    }
}

fn build_mesh(m: &FileMesh, key: &str, ctx: &Ctx) -> Result<Mesh, ScenarioError> {
    let m = match m {
        FileMesh::Generated(g) => g,
        FileMesh::File(f) => return import_mesh(f, key, ctx),
    };
    Ok(match m {
        FileGenerator::Block { size, divisions } => {
            for k in 0..3 {
                ctx.positive(&format!("{key}.size[{k}]"), size[k])?;
                ctx.count(
                    &format!("{key}.divisions[{k}]"),
                    divisions[k],
                    MAX_DIVISIONS,
                )?;
            }
            let cells: u128 = divisions.iter().map(|&d| d as u128).product();
            ctx.cell_limit(
                &format!("{key}.divisions"),
                &format!("{divisions:?}"),
                cells,
            )?;
            generate::block(*size, *divisions)
        }
        FileGenerator::Disk {
            radius,
            thickness,
            n_quarter,
            n_radial,
        } => {
            ctx.positive(&format!("{key}.radius"), *radius)?;
            ctx.positive(&format!("{key}.thickness"), *thickness)?;
            ctx.count(&format!("{key}.n_quarter"), *n_quarter, MAX_DIVISIONS)?;
            ctx.count(&format!("{key}.n_radial"), *n_radial, MAX_DIVISIONS)?;
            ctx.cell_limit(
                key,
                &format!("n_quarter = {n_quarter}, n_radial = {n_radial}"),
                disk_cells(*n_quarter, *n_radial),
            )?;
            generate::disk(*radius, *thickness, *n_quarter, *n_radial)
        }
        FileGenerator::HalfDisk {
            radius,
            thickness,
            n_quarter,
            n_radial,
            flat_side,
        } => {
            ctx.positive(&format!("{key}.radius"), *radius)?;
            ctx.positive(&format!("{key}.thickness"), *thickness)?;
            ctx.count(&format!("{key}.n_quarter"), *n_quarter, MAX_DIVISIONS)?;
            ctx.count(&format!("{key}.n_radial"), *n_radial, MAX_DIVISIONS)?;
            ctx.cell_limit(
                key,
                &format!("n_quarter = {n_quarter}, n_radial = {n_radial}"),
                disk_cells(*n_quarter, *n_radial) / 2,
            )?;
            let side = match flat_side.as_str() {
                "top" => FlatSide::Top,
                "bottom" => FlatSide::Bottom,
                s => {
                    return Err(ctx.err(format!(
                        "`{key}.flat_side` = {s:?}; valid values are \"top\" and \"bottom\""
                    )))
                }
            };
            generate::half_disk(*radius, *thickness, *n_quarter, *n_radial, side)
        }
        FileGenerator::QuarterHemisphere { radius, n } => {
            ctx.positive(&format!("{key}.radius"), *radius)?;
            ctx.count(&format!("{key}.n"), *n, MAX_DIVISIONS)?;
            ctx.cell_limit(
                &format!("{key}.n"),
                &format!("n = {n}"),
                4 * (*n as u128).pow(3),
            )?;
            generate::quarter_hemisphere(*radius, *n)
        }
    })
}

/// Cells of a disk O-grid: an n × n core and four n_radial × n rim blocks (n = n_quarter
/// rounded up to even).
fn disk_cells(n_quarter: usize, n_radial: usize) -> u128 {
    let n = (n_quarter + n_quarter % 2) as u128;
    n * n + 4 * n * n_radial as u128
}

/// Reads a body's mesh from a Gmsh file, relative to the scenario's folder, scales it and
/// checks its cells before anything runs.
fn import_mesh(f: &FileMeshFile, key: &str, ctx: &Ctx) -> Result<Mesh, ScenarioError> {
    let scale = ctx.positive(&format!("{key}.scale"), f.scale.unwrap_or(1.0))?;
    let path = ctx
        .file
        .parent()
        .map(|dir| dir.join(&f.file))
        .unwrap_or_else(|| f.file.clone());
    if !path.is_file() {
        return Err(ctx.err(format!(
            "`{key}.file`: no mesh file at {} (paths are relative to the scenario's folder)",
            path.display()
        )));
    }
    let fail = |e: gmsh::GmshError| ctx.err(format!("`{key}.file`: {e}"));
    let msh = gmsh::read(&path).map_err(fail)?;
    if let Some(sel) = &f.volumes {
        let available = msh.physical_volumes();
        let list = || {
            if available.is_empty() {
                "the file has no physical volumes".to_string()
            } else {
                format!(
                    "its physical volumes are: {}",
                    available
                        .iter()
                        .map(|v| format!("{v:?}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        };
        if sel.is_empty() {
            return Err(ctx.err(format!("`{key}.volumes` is empty: name at least one physical volume of {} ({}), or leave `volumes` out to take every volume element", path.display(), list())));
        }
        if let Some(v) = sel.iter().find(|v| !available.contains(v)) {
            return Err(ctx.err(format!(
                "`{key}.volumes`: {v:?} is not a physical volume of {}; {}",
                path.display(),
                list()
            )));
        }
    }
    let body = msh.body(f.volumes.as_deref()).map_err(fail)?;
    let mut mesh = body.mesh;
    for p in &mut mesh.nodes {
        *p = p.map(|x| x * scale);
    }
    let bad = quality::inverted_cells(&mesh);
    if !bad.is_empty() {
        let mut tags: Vec<String> = bad
            .iter()
            .take(20)
            .map(|&c| body.cell_tags[c].to_string())
            .collect();
        if bad.len() > 20 {
            tags.push(format!("and {} more", bad.len() - 20));
        }
        return Err(ctx.err(format!(
            "`{key}.file`: {} has {} inverted or degenerate element(s) (Jacobian ≤ 0); Gmsh element tags: {}",
            path.display(),
            bad.len(),
            tags.join(", ")
        )));
    }
    Ok(mesh)
}

fn build_material(
    m: &FileMaterial,
    key: &str,
    ctx: &Ctx,
) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
    if matches!(
        m.model.as_str(),
        "uncoupled-neo-hookean" | "mooney-rivlin" | "ogden"
    ) {
        let elastic = build_uncoupled_material(m, key, ctx)?;
        let Some(prony) = &m.prony else {
            return Ok(elastic);
        };
        if prony.is_empty() || prony.len() > 12 {
            return Err(ctx.err(format!(
                "`{key}.prony` needs 1 to 12 terms [[g1, tau1], ...], got {}",
                prony.len()
            )));
        }
        let mut terms = Vec::new();
        for (i, &[g, tau]) in prony.iter().enumerate() {
            if !(g > 0.0 && g < 1.0) {
                return Err(ctx.err(format!(
                    "`{key}.prony[{i}]`: the relative modulus g must be in (0, 1), got {g}"
                )));
            }
            ctx.positive(&format!("{key}.prony[{i}] (relaxation time tau [s])"), tau)?;
            terms.push(material::PronyTerm { g, tau });
        }
        let total: f64 = terms.iter().map(|t| t.g).sum();
        if total >= 1.0 {
            return Err(ctx.err(format!(
                "`{key}.prony`: the relative moduli add up to {total}; their sum must stay below 1 (the long-term shear modulus is μ (1 − Σ g))"
            )));
        }
        return Ok(Arc::new(material::Viscoelastic { elastic, terms }));
    }
    let extra = [
        ("c10", m.c10.is_some()),
        ("c01", m.c01.is_some()),
        ("d1", m.d1.is_some()),
        ("kappa", m.kappa.is_some()),
        ("mu", m.mu.is_some()),
        ("alpha", m.alpha.is_some()),
        ("prony", m.prony.is_some()),
    ];
    if let Some((name, _)) = extra.iter().find(|(_, given)| *given) {
        return Err(ctx.err(format!(
            "`{key}.{name}` is not used by model {:?}; it belongs to \"uncoupled-neo-hookean\", \"mooney-rivlin\" or \"ogden\"",
            m.model
        )));
    }
    let young_poisson = || -> Result<(f64, f64), ScenarioError> {
        let e = m.young.ok_or_else(|| {
            ctx.err(format!(
                "`{key}` with model {:?} needs `young` [Pa] and `poisson`",
                m.model
            ))
        })?;
        let nu = m.poisson.ok_or_else(|| {
            ctx.err(format!(
                "`{key}` with model {:?} needs `young` [Pa] and `poisson`",
                m.model
            ))
        })?;
        ctx.positive(&format!("{key}.young"), e)?;
        if !(nu > -1.0 && nu < 0.5) {
            return Err(ctx.err(format!("`{key}.poisson` must be in (−1, 0.5), got {nu}")));
        }
        if m.g.is_some() {
            return Err(ctx.err(format!(
                "`{key}.g` is not used by model {:?}; give `young` and `poisson`",
                m.model
            )));
        }
        Ok((e, nu))
    };
    Ok(match m.model.as_str() {
        "blatz-ko" => {
            if m.young.is_some() || m.poisson.is_some() {
                return Err(ctx.err(format!("`{key}`: the Blatz-Ko model takes only `g` (shear modulus [Pa]); its Poisson ratio is ¼")));
            }
            let g = m.g.ok_or_else(|| ctx.err(format!("`{key}` with model \"blatz-ko\" needs `g` (shear modulus [Pa])")))?;
            Arc::new(material::BlatzKo { g: ctx.positive(&format!("{key}.g"), g)? })
        }
        "neo-hookean" => {
            let (e, nu) = young_poisson()?;
            Arc::new(material::NeoHookean::from_young_poisson(e, nu))
        }
        "saint-venant-kirchhoff" => {
            let (e, nu) = young_poisson()?;
            Arc::new(material::SaintVenantKirchhoff::from_young_poisson(e, nu))
        }
        "linear-elastic" => {
            let (e, nu) = young_poisson()?;
            Arc::new(material::LinearElastic::from_young_poisson(e, nu))
        }
        other => {
            return Err(ctx.err(format!(
                "`{key}.model` = {other:?}; valid models are \"blatz-ko\", \"neo-hookean\", \"saint-venant-kirchhoff\", \"linear-elastic\", \"uncoupled-neo-hookean\", \"mooney-rivlin\", \"ogden\""
            )))
        }
    })
}

/// The nearly incompressible (uncoupled) models: the isochoric parameters and a bulk modulus,
/// `kappa` [Pa] or the Abaqus `d1` [1/Pa] (κ = 2/D₁); the neo-Hookean one also accepts
/// `young` and `poisson` (ν < ½).
fn build_uncoupled_material(
    m: &FileMaterial,
    key: &str,
    ctx: &Ctx,
) -> Result<Arc<dyn Hyperelastic>, ScenarioError> {
    let model = m.model.as_str();
    let allowed: &[&str] = match model {
        "uncoupled-neo-hookean" => &["c10", "kappa", "d1", "young", "poisson"],
        "mooney-rivlin" => &["c10", "c01", "kappa", "d1"],
        _ => &["mu", "alpha", "kappa", "d1"],
    };
    let given = [
        ("g", m.g.is_some()),
        ("young", m.young.is_some()),
        ("poisson", m.poisson.is_some()),
        ("c10", m.c10.is_some()),
        ("c01", m.c01.is_some()),
        ("d1", m.d1.is_some()),
        ("kappa", m.kappa.is_some()),
        ("mu", m.mu.is_some()),
        ("alpha", m.alpha.is_some()),
    ];
    if let Some((name, _)) = given.iter().find(|(name, g)| *g && !allowed.contains(name)) {
        return Err(ctx.err(format!(
            "`{key}.{name}` is not used by model {model:?}; its keys are {}",
            allowed.join(", ")
        )));
    }
    let bulk = |required: bool| -> Result<Option<f64>, ScenarioError> {
        match (m.kappa, m.d1) {
            (Some(_), Some(_)) => Err(ctx.err(format!(
                "`{key}`: give the bulk modulus either as `kappa` [Pa] or as `d1` [1/Pa] (κ = 2/D1), not both"
            ))),
            (Some(k), None) => Ok(Some(ctx.positive(&format!("{key}.kappa"), k)?)),
            (None, Some(d1)) => Ok(Some(material::bulk_from_d1(
                ctx.positive(&format!("{key}.d1"), d1)?,
            ))),
            (None, None) if required => Err(ctx.err(format!(
                "`{key}` with model {model:?} needs a bulk modulus: `kappa` [Pa] or `d1` [1/Pa] (κ = 2/D1)"
            ))),
            (None, None) => Ok(None),
        }
    };
    let need = |v: Option<f64>, name: &str| -> Result<f64, ScenarioError> {
        let v = v.ok_or_else(|| {
            ctx.err(format!(
                "`{key}` with model {model:?} needs `{name}` [Pa]; its keys are {}",
                allowed.join(", ")
            ))
        })?;
        ctx.finite(&format!("{key}.{name}"), v)
    };
    Ok(match model {
        "uncoupled-neo-hookean" => {
            if m.young.is_some() || m.poisson.is_some() {
                if m.c10.is_some() || m.kappa.is_some() || m.d1.is_some() {
                    return Err(ctx.err(format!(
                        "`{key}`: give either `young` and `poisson`, or `c10` and `kappa` (or `d1`), not both"
                    )));
                }
                let e = ctx.positive(&format!("{key}.young"), need(m.young, "young")?)?;
                let nu = m
                    .poisson
                    .ok_or_else(|| ctx.err(format!("`{key}` with `young` needs `poisson` too")))?;
                if !(nu > -1.0 && nu < 0.5) {
                    return Err(ctx.err(format!(
                        "`{key}.poisson` must be in (−1, 0.5), got {nu}; for incompressibility use e.g. 0.4999"
                    )));
                }
                Arc::new(material::UncoupledNeoHookean::from_young_poisson(e, nu))
            } else {
                let c10 = ctx.positive(&format!("{key}.c10"), need(m.c10, "c10")?)?;
                let kappa = bulk(true)?.unwrap_or(0.0);
                Arc::new(material::UncoupledNeoHookean { c10, kappa })
            }
        }
        "mooney-rivlin" => {
            let c10 = need(m.c10, "c10")?;
            let c01 = m
                .c01
                .map_or(Ok(0.0), |v| ctx.finite(&format!("{key}.c01"), v))?;
            if c10 + c01 <= 0.0 {
                return Err(ctx.err(format!(
                    "`{key}`: the shear modulus 2 (c10 + c01) must be positive, got c10 = {c10}, c01 = {c01}"
                )));
            }
            let kappa = bulk(true)?.unwrap_or(0.0);
            Arc::new(material::MooneyRivlin { c10, c01, kappa })
        }
        _ => {
            let (mu, alpha) = match (&m.mu, &m.alpha) {
                (Some(mu), Some(alpha)) => (mu.clone(), alpha.clone()),
                _ => {
                    return Err(ctx.err(format!(
                        "`{key}` with model \"ogden\" needs `mu = [μ1, ...]` [Pa] and `alpha = [α1, ...]` of the same length"
                    )))
                }
            };
            if mu.is_empty() || mu.len() != alpha.len() || mu.len() > 6 {
                return Err(ctx.err(format!(
                    "`{key}.mu` and `{key}.alpha` must have the same length, 1 to 6 terms; got {} and {}",
                    mu.len(),
                    alpha.len()
                )));
            }
            for (i, (&mi, &ai)) in mu.iter().zip(&alpha).enumerate() {
                ctx.finite(&format!("{key}.mu[{i}]"), mi)?;
                if !ai.is_finite() || ai == 0.0 {
                    return Err(ctx.err(format!(
                        "`{key}.alpha[{i}]` must be a finite non-zero number, got {ai}"
                    )));
                }
                if mi * ai <= 0.0 {
                    return Err(ctx.err(format!(
                        "`{key}`: term {i} has μ·α = {} ≤ 0; each term needs μᵢαᵢ > 0 to be stable in the small-strain limit",
                        mi * ai
                    )));
                }
            }
            let kappa = bulk(true)?.unwrap_or(0.0);
            Arc::new(material::Ogden { mu, alpha, kappa })
        }
    })
}

fn build_table(t: &FileTable, key: &str, ctx: &Ctx) -> Result<Table, ScenarioError> {
    match t {
        FileTable::Constant(v) => Ok(Table::constant(ctx.finite(key, *v)?)),
        FileTable::Points(p) => {
            if p.is_empty() {
                return Err(ctx.err(format!(
                    "`{key}` is an empty table; give a number or [[t, value], ...]"
                )));
            }
            for (i, [t, v]) in p.iter().enumerate() {
                ctx.finite(&format!("{key}[{i}]"), *t)?;
                ctx.finite(&format!("{key}[{i}]"), *v)?;
                if i > 0 && *t <= p[i - 1][0] {
                    return Err(ctx.err(format!("`{key}`: times must increase strictly, but entry {i} has t = {t} after t = {}", p[i - 1][0])));
                }
            }
            Ok(Table {
                t: p.iter().map(|e| e[0]).collect(),
                v: p.iter().map(|e| e[1]).collect(),
            })
        }
    }
}

fn build_rotation(r: &FileRotation, key: &str, ctx: &Ctx) -> Result<Rotation, ScenarioError> {
    let axis = ctx.finite3(&format!("{key}.axis"), r.axis)?;
    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if !(len > 0.0) {
        return Err(ctx.err(format!("`{key}.axis` must be a non-zero vector")));
    }
    let center = ctx.finite3(&format!("{key}.center"), r.center)?;
    let angle = match (&r.angle, r.angular_velocity) {
        (Some(a), None) => {
            if r.start.is_some() {
                return Err(ctx.err(format!("`{key}.start` goes with `angular_velocity`, not with `angle`")));
            }
            build_table(&FileTable::Points(a.clone()), &format!("{key}.angle"), ctx)?
        }
        (None, Some(w)) => {
            let w = ctx.finite(&format!("{key}.angular_velocity"), w)?;
            let start = ctx.finite(&format!("{key}.start"), r.start.unwrap_or(0.0))?;
            // θ(t) = ω (t − start) for t > start: a two-point table extrapolated linearly
            // would hold its end value, so give it a far end point.
            let far = start + 1e6;
            Table { t: vec![start, far], v: vec![0.0, w * (far - start)] }
        }
        _ => return Err(ctx.err(format!("`{key}` needs exactly one of `angular_velocity` [rad/s] (with optional `start` [s]) or `angle` (a table [[t, rad], ...])"))),
    };
    Ok(Rotation {
        center,
        axis: axis.map(|a| a / len),
        angle,
    })
}

fn build_contact(
    c: &FileContact,
    key: &str,
    bodies: &[Body],
    body_index: &BTreeMap<String, usize>,
    offsets: &[usize],
    plane_strain: &[bool],
    ctx: &Ctx,
) -> Result<ContactPair, ScenarioError> {
    if c.name.is_empty() || c.name.contains([',', '"', '\n', '.']) {
        return Err(ctx.err(format!(
            "`{key}.name` must be non-empty and hold no comma, dot or quote, got {:?}",
            c.name
        )));
    }
    let lookup = |k: &str, body: &str| -> Result<usize, ScenarioError> {
        body_index.get(body).copied().ok_or_else(|| {
            ctx.err(format!(
                "`{k}` = {body:?} is not a body of this scenario; bodies are: {}",
                body_index.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })
    };
    let face_set = |k: &str, bi: usize, set: &str| -> Result<Vec<Face>, ScenarioError> {
        let mesh = &bodies[bi].mesh;
        match mesh.face_sets.get(set) {
            Some(f) if !f.is_empty() => Ok(f.clone()),
            Some(_) => Err(ctx.err(format!("`{k}` = {set:?} is an empty face set"))),
            None => Err(ctx.err(format!(
                "`{k}` = {set:?} is not a face set of body {:?}; its face sets are: {}",
                bodies[bi].name,
                mesh.face_sets
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    };
    let sb = lookup(&format!("{key}.slave.body"), &c.slave.body)?;
    let slave_faces = face_set(&format!("{key}.slave.set"), sb, &c.slave.set)?;
    let mesh = &bodies[sb].mesh;
    let local_nodes = match mesh.node_sets.get(&c.slave.set) {
        Some(n) => n.clone(),
        None => {
            let mut n: Vec<usize> = slave_faces
                .iter()
                .flat_map(|f| f.nodes().to_vec())
                .collect();
            n.sort_unstable();
            n.dedup();
            n
        }
    };
    let area = tributary_areas(&slave_faces, &mesh.nodes, &local_nodes);
    let slave_quads = {
        let index: BTreeMap<usize, usize> = local_nodes
            .iter()
            .enumerate()
            .map(|(i, &n)| (n, i))
            .collect();
        slave_faces
            .iter()
            .filter_map(|f| {
                let q = match f {
                    Face::Quad(n) => *n,
                    Face::Tri(n) => [n[0], n[1], n[2], n[2]],
                };
                let m = q.map(|n| index.get(&n).copied());
                m.iter()
                    .all(Option::is_some)
                    .then(|| m.map(|i| i.unwrap_or(0)))
            })
            .collect()
    };
    let slave_nodes: Vec<usize> = local_nodes.iter().map(|n| n + offsets[sb]).collect();
    let mean_edge = {
        let mut sum = 0.0;
        let mut count = 0;
        for f in &slave_faces {
            let ns = f.nodes();
            for i in 0..ns.len() {
                let (a, b) = (mesh.nodes[ns[i]], mesh.nodes[ns[(i + 1) % ns.len()]]);
                sum +=
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
                count += 1;
            }
        }
        sum / count.max(1) as f64
    };
    let m = &c.master;
    let master = match (&m.body, &m.rigid) {
        (Some(body), None) => {
            let mb = lookup(&format!("{key}.master.body"), body)?;
            if mb == sb {
                return Err(ctx.err(format!("`{key}`: slave and master are both on body {body:?}; self-contact is not supported, the master must be another body")));
            }
            let set = m.set.as_deref().ok_or_else(|| ctx.err(format!("`{key}.master` on a body needs `set` (a face set of that body)")))?;
            if m.point.is_some() || m.normal.is_some() || m.center.is_some() || m.axis.is_some() || m.radius.is_some() {
                return Err(ctx.err(format!("`{key}.master`: a deformable master takes only `body` and `set`")));
            }
            if c.motion.is_some() {
                return Err(ctx.err(format!("`{key}.motion` applies to rigid masters only; move a deformable master with [[boundary]] conditions")));
            }
            let faces = face_set(&format!("{key}.master.set"), mb, set)?;
            let off = offsets[mb];
            Master::Faces(
                faces
                    .into_iter()
                    .map(|f| match f {
                        Face::Quad(n) => Face::Quad(n.map(|i| i + off)),
                        Face::Tri(n) => Face::Tri(n.map(|i| i + off)),
                    })
                    .collect(),
            )
        }
        (None, Some(kind)) => {
            if m.set.is_some() {
                return Err(ctx.err(format!("`{key}.master.set` goes with `body`, not with `rigid`")));
            }
            let need3 = |name: &str, v: Option<[f64; 3]>| -> Result<[f64; 3], ScenarioError> {
                let v = v.ok_or_else(|| ctx.err(format!("`{key}.master` with rigid = {kind:?} needs `{name}`")))?;
                ctx.finite3(&format!("{key}.master.{name}"), v)
            };
            let unit = |name: &str, v: [f64; 3]| -> Result<[f64; 3], ScenarioError> {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if l > 0.0 { Ok(v.map(|a| a / l)) } else { Err(ctx.err(format!("`{key}.master.{name}` must be a non-zero vector"))) }
            };
            let radius = || -> Result<f64, ScenarioError> {
                let r = m.radius.ok_or_else(|| ctx.err(format!("`{key}.master` with rigid = {kind:?} needs `radius` [m]")))?;
                ctx.positive(&format!("{key}.master.radius"), r)
            };
            let shape = match kind.as_str() {
                "plane" => RigidShape::Plane { point: need3("point", m.point)?, normal: unit("normal", need3("normal", m.normal)?)? },
                "sphere" => RigidShape::Sphere { center: need3("center", m.center)?, radius: radius()? },
                "cylinder" => RigidShape::Cylinder { point: need3("point", m.point)?, axis: unit("axis", need3("axis", m.axis)?)?, radius: radius()? },
                other => return Err(ctx.err(format!("`{key}.master.rigid` = {other:?}; valid shapes are \"plane\", \"sphere\", \"cylinder\""))),
            };
            let mut translation = [Table::constant(0.0), Table::constant(0.0), Table::constant(0.0)];
            let mut rotation = None;
            if let Some(mo) = &c.motion {
                if let Some(d) = &mo.displacement {
                    for (k, (cname, t)) in [("x", &d.x), ("y", &d.y), ("z", &d.z)].into_iter().enumerate() {
                        if let Some(t) = t {
                            translation[k] = build_table(t, &format!("{key}.motion.displacement.{cname}"), ctx)?;
                        }
                    }
                }
                if let Some(r) = &mo.rotation {
                    rotation = Some(build_rotation(r, &format!("{key}.motion.rotation"), ctx)?);
                }
            }
            Master::Rigid { shape, motion: RigidMotion { translation, rotation } }
        }
        _ => return Err(ctx.err(format!("`{key}.master` needs exactly one of `body` (+ `set`: a deformable master) or `rigid` (\"plane\", \"sphere\", \"cylinder\")"))),
    };
    let mu = c.friction;
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(ctx.err(format!(
            "`{key}.friction` must be a finite number ≥ 0 (0 = frictionless), got {mu}"
        )));
    }
    let adhesion = match &c.adhesion {
        None => None,
        Some(a) => {
            // w = 0 is allowed: no adhesion energy, β never grows (the dry interface), which
            // lets a study switch adhesion off with one value.
            if !(a.w.is_finite() && a.w >= 0.0) {
                return Err(ctx.err(format!(
                    "`{key}.adhesion.w` must be a finite number ≥ 0 [J/m²] (0 = no adhesion), got {}",
                    a.w
                )));
            }
            let w = a.w;
            let cn = ctx.positive(&format!("{key}.adhesion.cn"), a.cn)?;
            if !(a.ct.is_finite() && a.ct >= 0.0) {
                return Err(ctx.err(format!(
                    "`{key}.adhesion.ct` must be a finite number ≥ 0 [N/m³], got {}",
                    a.ct
                )));
            }
            if !(a.b.is_finite() && a.b >= 0.0) {
                return Err(ctx.err(format!("`{key}.adhesion.b` must be a finite number ≥ 0 [N·s/m] (0 = rate-independent), got {}", a.b)));
            }
            let eps = a.eps.unwrap_or(DEFAULT_BETA_EPS);
            if !(eps > 0.0 && eps < 1.0) {
                return Err(ctx.err(format!("`{key}.adhesion.eps` must be in (0, 1), got {eps}")));
            }
            let fatigue_energy = match a.fatigue_energy {
                None => f64::INFINITY,
                Some(d) => ctx.positive(&format!("{key}.adhesion.fatigue_energy"), d)?,
            };
            Some(RccParams {
                w,
                cn,
                ct: a.ct,
                ct2: a.ct,
                b: a.b,
                eps,
                fatigue_energy,
            })
        }
    };
    let mut adhesion = adhesion;
    let anisotropy = match &c.orthotropy {
        None => None,
        Some(o) => {
            let k = format!("{key}.orthotropy");
            let len = o.axis.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(len.is_finite() && len > 0.0) {
                return Err(ctx.err(format!(
                    "`{k}.axis` must be a non-zero direction (the first material axis of the master surface, global components), got {:?}",
                    o.axis
                )));
            }
            let mu2 = o.friction_2;
            if !(mu2.is_finite() && mu2 >= 0.0) {
                return Err(ctx.err(format!(
                    "`{k}.friction_2` must be a finite number ≥ 0 (the friction coefficient along the second axis), got {mu2}"
                )));
            }
            if mu2 != mu && (mu == 0.0 || mu2 == 0.0) {
                return Err(ctx.err(format!(
                    "`{key}.friction` ({mu}) and `{k}.friction_2` ({mu2}) must both be positive for an elliptic friction cone (or equal)"
                )));
            }
            if let Some(ct2) = o.ct_2 {
                match adhesion.as_mut() {
                    None => {
                        return Err(ctx.err(format!(
                            "`{k}.ct_2` needs an `adhesion` block on the pair (it is the tangential adhesive stiffness along the second axis)"
                        )))
                    }
                    Some(a) if ct2.is_finite() && ct2 >= 0.0 => a.ct2 = ct2,
                    Some(_) => {
                        return Err(ctx.err(format!(
                            "`{k}.ct_2` must be a finite number ≥ 0 [N/m³], got {ct2}"
                        )))
                    }
                }
            }
            Some(Orthotropy {
                axis: o.axis.map(|v| v / len),
                mu2,
            })
        }
    };
    // A plane-strain slave against a plane-strain body or a rigid surface is a plane problem:
    // each line of slave nodes through the thickness is one contact point.
    let master_in_plane = m.body.as_ref().map_or(true, |b| {
        body_index.get(b).is_some_and(|&i| plane_strain[i])
    });
    let thickness_twins = if plane_strain[sb] && master_in_plane {
        thickness_twins(&local_nodes, &bodies[sb].mesh.nodes)
    } else {
        vec![Vec::new(); local_nodes.len()]
    };
    let detection_distance = match c.detection_distance {
        Some(d) => ctx.positive(&format!("{key}.detection_distance"), d)?,
        None => 0.5 * mean_edge,
    };
    Ok(ContactPair {
        name: c.name.clone(),
        slave_nodes,
        slave_area: area,
        master,
        law: InterfaceLaw::rcc(mu, adhesion, anisotropy),
        detection_distance,
        slave_quads,
        thickness_twins,
    })
}
