//! Scenario files (TOML) parsed and validated into a [`Scenario`]: the [`Problem`] the stepper
//! solves and the [`OutputSettings`] of what the run writes.
//!
//! Parsing (serde) rejects unknown keys and wrong types with the line and column; validation
//! then checks values (positive moduli, time step, existing node sets, ...) and names the key
//! that is wrong and what would be valid. The format is documented in `docs/scenario.md`.

use crate::output::settings::OutputSettings;
use adhesim::problem::Problem;
use bodies::Bodies;
use boundaries::Constraints;
use serde::Deserialize;
use std::path::{Path, PathBuf};

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
    newton: Option<String>,
    predictor: Option<String>,
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
                "a mesh needs `generator` (\"block\", \"disk\", \"half_disk\", \"quarter_hemisphere\", \"tube\") or `file` (a Gmsh MSH 4.1 file)",
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
    Tube {
        inner: [f64; 2],
        outer: [f64; 2],
        thickness: f64,
        n_around: usize,
        n_radial: usize,
        grip: Option<f64>,
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
    #[serde(default)]
    discretisation: Option<String>,
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

mod bodies;
mod boundaries;
mod contacts;
mod materials;
mod meshes;
mod outputs;
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

/// The scenario read top-down, section by section, in the order in which its checks are
/// reported.
fn validate(raw: FileScenario, ctx: &Ctx) -> Result<Scenario, ScenarioError> {
    let name = scenario_name(raw.name.as_deref(), ctx)?;
    let time = time::validate_time(&raw.time, ctx)?;
    let bodies = Bodies::build(&raw.bodies, ctx)?;
    let mut constraints = Constraints::plane_strain(&bodies);
    constraints.add_boundaries(&raw.boundaries, &bodies, ctx)?;
    let loads = boundaries::build_loads(&raw.loads, &bodies, ctx)?;
    let contacts = contacts::build_contacts(&raw.contacts, &bodies, ctx)?;
    let tracks = outputs::build_tracks(&raw.tracks, &bodies, ctx)?;
    let gravity = boundaries::build_gravity(raw.gravity.as_ref(), ctx)?;
    let frame_interval = outputs::frame_interval(raw.output.as_ref(), ctx)?;
    let maps = outputs::build_maps(&raw.maps, &contacts, ctx)?;
    let figures = raw.output.as_ref().and_then(|o| o.figures).unwrap_or(true);
    Ok(Scenario {
        problem: Problem {
            name,
            bodies: bodies.list,
            dirichlet: constraints.dirichlet,
            loads,
            gravity,
            time,
            contacts,
        },
        output: OutputSettings {
            frame_interval,
            figures,
            maps,
            boundary_names: constraints.names,
            tracks,
        },
    })
}

/// The run's name: `name`, or the scenario file's stem ("run" without one); a non-empty
/// file stem without slashes.
fn scenario_name(name: Option<&str>, ctx: &Ctx) -> Result<String, ScenarioError> {
    let name = name.map(str::to_string).unwrap_or_else(|| {
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
    Ok(name)
}
