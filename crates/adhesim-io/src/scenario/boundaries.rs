//! What the scenario prescribes on the bodies: the `[[boundary]]` conditions (with the
//! plane-strain constraints), the `[[load]]` entries and `gravity`, and the tables over time
//! and rotations they are written with.

use super::bodies::Bodies;
use super::{Ctx, FileBoundary, FileComponents, FileGravity, FileLoad, FileRotation};
use super::{FileTable, ScenarioError};
use adhesim::gravity::Gravity;
use adhesim::problem::{Dirichlet, NodalLoad, Rotation, Table};

/// The prescribed displacements of a scenario and the reaction name of each.
pub(super) struct Constraints {
    /// The plane-strain constraints, then the `[[boundary]]` conditions in file order.
    pub(super) dirichlet: Vec<Dirichlet>,
    /// Reaction names, one per entry of `dirichlet` ("" for the plane-strain constraints).
    pub(super) names: Vec<String>,
}

impl Constraints {
    /// Plane strain: out-of-plane displacement fixed on every node of each plane-strain body.
    pub(super) fn plane_strain(bodies: &Bodies) -> Self {
        let mut constraints = Constraints {
            dirichlet: Vec::new(),
            names: Vec::new(),
        };
        for (i, b) in bodies.list.iter().enumerate() {
            if b.plane_strain {
                let nodes = (0..b.mesh.num_nodes())
                    .map(|n| n + bodies.offsets[i])
                    .collect();
                constraints.names.push(String::new());
                constraints.dirichlet.push(Dirichlet {
                    nodes,
                    components: [false, false, true],
                    translation: zero_tables(),
                    rotation: None,
                });
            }
        }
        constraints
    }

    /// Adds the `[[boundary]]` conditions, each with a unique reaction name.
    pub(super) fn add_boundaries(
        &mut self,
        raw: &[FileBoundary],
        bodies: &Bodies,
        ctx: &Ctx,
    ) -> Result<(), ScenarioError> {
        for (i, bc) in raw.iter().enumerate() {
            let key = format!("boundary[{i}]");
            let nodes = bodies.node_set(&key, &bc.body, &bc.set, ctx)?;
            let dirichlet = prescribed(bc, nodes, &key, ctx)?;
            let name = self.boundary_name(bc, i, &key, ctx)?;
            self.names.push(name);
            self.dirichlet.push(dirichlet);
        }
        Ok(())
    }

    /// The reaction name of boundary `i`: its `name`, or `body.set` (with `.i` appended when
    /// an earlier condition has that name).
    fn boundary_name(
        &self,
        bc: &FileBoundary,
        i: usize,
        key: &str,
        ctx: &Ctx,
    ) -> Result<String, ScenarioError> {
        let default_name = format!("{}.{}", bc.body, bc.set);
        Ok(match &bc.name {
            Some(n) => {
                if n.is_empty() || n.contains(['\n', '\r', ',', '"']) {
                    return Err(ctx.err(format!(
                        "`{key}.name` = {n:?}: give a non-empty name without commas, quotes \
                         or line breaks (it heads history columns)"
                    )));
                }
                if self.names.contains(n) {
                    return Err(ctx.err(format!(
                        "`{key}.name`: the boundary name {n:?} is used twice; names must be unique"
                    )));
                }
                n.clone()
            }
            None if self.names.contains(&default_name) => format!("{default_name}.{i}"),
            None => default_name,
        })
    }
}

/// What a boundary condition prescribes on `nodes` (global indices): the held components
/// (x, y, z), their displacements [m] over time, and a rotation (which holds all three).
fn prescribed(
    bc: &FileBoundary,
    nodes: Vec<usize>,
    key: &str,
    ctx: &Ctx,
) -> Result<Dirichlet, ScenarioError> {
    let mut components = [false; 3];
    let mut translation = zero_tables();
    for c in &bc.fix {
        let k = axis_index(c).ok_or_else(|| {
            ctx.err(format!(
                "`{key}.fix` holds {c:?}; valid entries are \"x\", \"y\", \"z\""
            ))
        })?;
        components[k] = true;
    }
    if let Some(d) = &bc.displacement {
        for (k, (cname, t)) in named_components(d).into_iter().enumerate() {
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
    Ok(Dirichlet {
        nodes,
        components,
        translation,
        rotation,
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

/// The `[[load]]` entries: total forces [N] over time, spread over the nodes of a set.
pub(super) fn build_loads(
    raw: &[FileLoad],
    bodies: &Bodies,
    ctx: &Ctx,
) -> Result<Vec<NodalLoad>, ScenarioError> {
    let mut loads = Vec::new();
    for (i, l) in raw.iter().enumerate() {
        let key = format!("load[{i}]");
        let nodes = bodies.node_set(&key, &l.body, &l.set, ctx)?;
        let total_force = build_components(&l.force, &format!("{key}.force"), ctx)?;
        loads.push(NodalLoad { nodes, total_force });
    }
    Ok(loads)
}

/// `gravity` [m/s²]: none when left out, a constant vector, or a table per component.
pub(super) fn build_gravity(
    raw: Option<&FileGravity>,
    ctx: &Ctx,
) -> Result<Gravity, ScenarioError> {
    Ok(match raw {
        None => Gravity::default(),
        Some(FileGravity::Constant(g)) => Gravity::constant(ctx.finite3("gravity", *g)?),
        Some(FileGravity::Tables(c)) => Gravity {
            components: build_components(c, "gravity", ctx)?,
        },
    })
}

/// Three tables that are zero at every time.
pub(super) fn zero_tables() -> [Table; 3] {
    [
        Table::constant(0.0),
        Table::constant(0.0),
        Table::constant(0.0),
    ]
}

/// The x, y and z entries of a table of components, with their names.
fn named_components(c: &FileComponents) -> [(&'static str, Option<&FileTable>); 3] {
    [
        ("x", c.x.as_ref()),
        ("y", c.y.as_ref()),
        ("z", c.z.as_ref()),
    ]
}

/// The x, y and z tables of the components at `key` (each at `key.x`, ...), zero where
/// left out.
pub(super) fn build_components(
    c: &FileComponents,
    key: &str,
    ctx: &Ctx,
) -> Result<[Table; 3], ScenarioError> {
    let mut tables = zero_tables();
    for (k, (cname, t)) in named_components(c).into_iter().enumerate() {
        if let Some(t) = t {
            tables[k] = build_table(t, &format!("{key}.{cname}"), ctx)?;
        }
    }
    Ok(tables)
}

/// A value over time: a constant, or points [[t, value], ...] at strictly increasing times
/// [s].
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

/// A rotation about `axis` (normalised) through `center` [m], by `angular_velocity`
/// [rad/s] from `start` [s] or by an `angle` table [[t, rad], ...].
pub(super) fn build_rotation(
    r: &FileRotation,
    key: &str,
    ctx: &Ctx,
) -> Result<Rotation, ScenarioError> {
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
