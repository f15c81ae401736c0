//! A body's `mesh`: one of the built-in generators or a Gmsh file.

use super::{Ctx, FileGenerator, FileMesh, FileMeshFile, ScenarioError};
use adhesim::mesh::generate::{self, FlatSide};
use adhesim::mesh::Mesh;
use adhesim::mesh::{gmsh, quality};
use std::path::Path;

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

/// The mesh of the table at `key` (`body[i].mesh`), generated or read, in metres.
pub(super) fn build_mesh(m: &FileMesh, key: &str, ctx: &Ctx) -> Result<Mesh, ScenarioError> {
    let m = match m {
        FileMesh::Generated(g) => g,
        FileMesh::File(f) => return import_mesh(f, key, ctx),
    };
    match m {
        FileGenerator::Block { size, divisions } => block(*size, *divisions, key, ctx),
        FileGenerator::Disk {
            radius,
            thickness,
            n_quarter,
            n_radial,
        } => {
            check_disk(*radius, *thickness, *n_quarter, *n_radial, 1, key, ctx)?;
            Ok(generate::disk(*radius, *thickness, *n_quarter, *n_radial))
        }
        FileGenerator::HalfDisk {
            radius,
            thickness,
            n_quarter,
            n_radial,
            flat_side,
        } => {
            check_disk(*radius, *thickness, *n_quarter, *n_radial, 2, key, ctx)?;
            let side = match flat_side.as_str() {
                "top" => FlatSide::Top,
                "bottom" => FlatSide::Bottom,
                s => {
                    return Err(ctx.err(format!(
                        "`{key}.flat_side` = {s:?}; valid values are \"top\" and \"bottom\""
                    )))
                }
            };
            Ok(generate::half_disk(
                *radius, *thickness, *n_quarter, *n_radial, side,
            ))
        }
        FileGenerator::QuarterHemisphere { radius, n } => {
            ctx.positive(&format!("{key}.radius"), *radius)?;
            ctx.count(&format!("{key}.n"), *n, MAX_DIVISIONS)?;
            ctx.cell_limit(
                &format!("{key}.n"),
                &format!("n = {n}"),
                4 * (*n as u128).pow(3),
            )?;
            Ok(generate::quarter_hemisphere(*radius, *n))
        }
        FileGenerator::Tube {
            inner,
            outer,
            thickness,
            n_around,
            n_radial,
            grip,
        } => tube(
            *inner,
            *outer,
            *thickness,
            [*n_around, *n_radial],
            *grip,
            key,
            ctx,
        ),
    }
}

/// A tube between the ellipses of semi-axes `inner` and `outer` [m], `thickness` [m] thick,
/// with `counts` = [n_around, n_radial] elements and the gripped arcs `grip` [m] wide
/// (default: the outer semi-axis along x).
fn tube(
    inner: [f64; 2],
    outer: [f64; 2],
    thickness: f64,
    counts: [usize; 2],
    grip: Option<f64>,
    key: &str,
    ctx: &Ctx,
) -> Result<Mesh, ScenarioError> {
    for k in 0..2 {
        ctx.positive(&format!("{key}.inner[{k}]"), inner[k])?;
        ctx.positive(&format!("{key}.outer[{k}]"), outer[k])?;
        if outer[k] <= inner[k] {
            return Err(ctx.err(format!(
                "`{key}.outer[{k}]` = {} must exceed `{key}.inner[{k}]` = {}: the outer ellipse encloses the inner one",
                outer[k], inner[k]
            )));
        }
    }
    ctx.positive(&format!("{key}.thickness"), thickness)?;
    let grip = ctx.positive(&format!("{key}.grip"), grip.unwrap_or(outer[0]))?;
    ctx.count(&format!("{key}.n_around"), counts[0], MAX_DIVISIONS)?;
    ctx.count(&format!("{key}.n_radial"), counts[1], MAX_DIVISIONS)?;
    ctx.cell_limit(
        key,
        &format!("n_around = {}, n_radial = {}", counts[0], counts[1]),
        (counts[0] as u128 + 3) * counts[1] as u128,
    )?;
    Ok(generate::tube(
        inner, outer, thickness, counts[0], counts[1], grip,
    ))
}

/// A block of `size` [m] cut into `divisions` hexahedra per direction.
fn block(
    size: [f64; 3],
    divisions: [usize; 3],
    key: &str,
    ctx: &Ctx,
) -> Result<Mesh, ScenarioError> {
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
    Ok(generate::block(size, divisions))
}

/// Checks the keys of a disk or half disk: radius and thickness [m], the element counts,
/// and the number of cells they give (those of the whole disk divided by `parts`: 1 for a
/// disk, 2 for a half disk).
fn check_disk(
    radius: f64,
    thickness: f64,
    n_quarter: usize,
    n_radial: usize,
    parts: u128,
    key: &str,
    ctx: &Ctx,
) -> Result<(), ScenarioError> {
    ctx.positive(&format!("{key}.radius"), radius)?;
    ctx.positive(&format!("{key}.thickness"), thickness)?;
    ctx.count(&format!("{key}.n_quarter"), n_quarter, MAX_DIVISIONS)?;
    ctx.count(&format!("{key}.n_radial"), n_radial, MAX_DIVISIONS)?;
    ctx.cell_limit(
        key,
        &format!("n_quarter = {n_quarter}, n_radial = {n_radial}"),
        disk_cells(n_quarter, n_radial) / parts,
    )
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
        check_volumes(&msh, sel, &path, key, ctx)?;
    }
    let body = msh.body(f.volumes.as_deref()).map_err(fail)?;
    let mut mesh = body.mesh;
    for p in &mut mesh.nodes {
        *p = p.map(|x| x * scale);
    }
    check_inverted(&mesh, &body.cell_tags, &path, key, ctx)?;
    Ok(mesh)
}

/// Checks that `volumes` (the selection `sel`) names at least one physical volume of the
/// file at `path`, and only such volumes.
fn check_volumes(
    msh: &gmsh::MshFile,
    sel: &[String],
    path: &Path,
    key: &str,
    ctx: &Ctx,
) -> Result<(), ScenarioError> {
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
    Ok(())
}

/// Rejects a mesh with inverted or degenerate cells, naming up to 20 of them by their Gmsh
/// tags (`cell_tags`, one per cell).
fn check_inverted(
    mesh: &Mesh,
    cell_tags: &[u64],
    path: &Path,
    key: &str,
    ctx: &Ctx,
) -> Result<(), ScenarioError> {
    let bad = quality::inverted_cells(mesh);
    if bad.is_empty() {
        return Ok(());
    }
    let mut tags: Vec<String> = bad
        .iter()
        .take(20)
        .map(|&c| cell_tags[c].to_string())
        .collect();
    if bad.len() > 20 {
        tags.push(format!("and {} more", bad.len() - 20));
    }
    Err(ctx.err(format!(
        "`{key}.file`: {} has {} inverted or degenerate element(s) (Jacobian ≤ 0); Gmsh element tags: {}",
        path.display(),
        bad.len(),
        tags.join(", ")
    )))
}
