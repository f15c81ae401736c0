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
use adhesim::mesh::{Face, Mesh};
use adhesim::problem::{Body, Dirichlet, NodalLoad, Problem, Rotation, Table};
use materials::build_material;
use meshes::build_mesh;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use time::validate_time;

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

mod materials;
mod meshes;
pub mod prepare;
mod time;

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
