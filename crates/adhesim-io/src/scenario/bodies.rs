//! The `[[body]]` entries: mesh, material, density, element kinematics and initial velocity
//! of each body, and how the other sections refer to bodies and their sets by name.

use super::materials::build_material;
use super::meshes::build_mesh;
use super::{Ctx, FileBody, ScenarioError};
use adhesim::fbar::Formulation;
use adhesim::material::Hyperelastic;
use adhesim::mesh::{Face, Mesh};
use adhesim::problem::Body;
use std::collections::BTreeMap;

/// The bodies of a scenario, with the name of each and where its nodes start in the
/// problem's global node numbering.
pub(super) struct Bodies {
    /// The bodies in file order.
    pub(super) list: Vec<Body>,
    /// Index in `list` of each body name.
    index: BTreeMap<String, usize>,
    /// Global index of each body's first node (the nodes of body `i` follow those of the
    /// bodies before it).
    pub(super) offsets: Vec<usize>,
}

impl Bodies {
    /// Builds the `[[body]]` entries (at least one, with distinct names) in file order.
    pub(super) fn build(raw: &[FileBody], ctx: &Ctx) -> Result<Self, ScenarioError> {
        if raw.is_empty() {
            return Err(ctx.err("at least one [[body]] is needed"));
        }
        let mut list = Vec::new();
        let mut index: BTreeMap<String, usize> = BTreeMap::new();
        for (i, b) in raw.iter().enumerate() {
            let key = format!("body[{i}]");
            if index.insert(b.name.clone(), i).is_some() {
                return Err(ctx.err(format!(
                    "`{key}.name`: the body name {:?} is used twice; names must be unique",
                    b.name
                )));
            }
            list.push(build_body(b, &key, ctx)?);
        }
        let offsets = node_offsets(&list);
        Ok(Bodies {
            list,
            index,
            offsets,
        })
    }

    /// Index of the body called `name`, which the scenario gives at `key` (e.g.
    /// `contact[0].slave.body`).
    pub(super) fn body(&self, key: &str, name: &str, ctx: &Ctx) -> Result<usize, ScenarioError> {
        self.index.get(name).copied().ok_or_else(|| {
            ctx.err(format!(
                "`{key}` = {name:?} is not a body of this scenario; bodies are: {}",
                self.index.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })
    }

    /// Whether the body called `name` exists and is in plane strain.
    pub(super) fn in_plane_strain(&self, name: &str) -> bool {
        self.index
            .get(name)
            .is_some_and(|&i| self.list[i].plane_strain)
    }

    /// Global indices of the nodes of the non-empty node set `set` of body `body`, which
    /// the entry at `key` (e.g. `boundary[0]`) names in its `body` and `set` keys.
    pub(super) fn node_set(
        &self,
        key: &str,
        body: &str,
        set: &str,
        ctx: &Ctx,
    ) -> Result<Vec<usize>, ScenarioError> {
        let bi = self.body(&format!("{key}.body"), body, ctx)?;
        let mesh = &self.list[bi].mesh;
        let nodes = mesh.node_sets.get(set).ok_or_else(|| {
            ctx.err(format!(
                "`{key}.set` = {set:?} is not a node set of body {body:?}; its sets are: {}",
                mesh.node_sets
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        if nodes.is_empty() {
            return Err(ctx.err(format!("`{key}.set` = {set:?} of body {body:?} is empty")));
        }
        Ok(nodes.iter().map(|n| n + self.offsets[bi]).collect())
    }

    /// The faces (body-local node indices) of the non-empty face set `set` of body `bi`,
    /// which the scenario names at `key`.
    pub(super) fn face_set(
        &self,
        key: &str,
        bi: usize,
        set: &str,
        ctx: &Ctx,
    ) -> Result<Vec<Face>, ScenarioError> {
        let mesh = &self.list[bi].mesh;
        match mesh.face_sets.get(set) {
            Some(f) if !f.is_empty() => Ok(f.clone()),
            Some(_) => Err(ctx.err(format!("`{key}` = {set:?} is an empty face set"))),
            None => Err(ctx.err(format!(
                "`{key}` = {set:?} is not a face set of body {:?}; its face sets are: {}",
                self.list[bi].name,
                mesh.face_sets
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }
}

/// One `[[body]]` entry, at `key` (`body[i]`).
fn build_body(b: &FileBody, key: &str, ctx: &Ctx) -> Result<Body, ScenarioError> {
    let mesh = body_mesh(b, key, ctx)?;
    let material = build_material(&b.material, &format!("{key}.material"), ctx)?;
    let density = ctx.positive(&format!("{key}.density"), b.density)?;
    let element = element_formulation(b.element.as_deref(), &*material, key, ctx)?;
    let initial_velocity = ctx.finite3(
        &format!("{key}.initial_velocity"),
        b.initial_velocity.unwrap_or([0.0; 3]),
    )?;
    Ok(Body {
        name: b.name.clone(),
        mesh,
        material,
        density,
        initial_velocity,
        element,
        plane_strain: b.plane_strain,
    })
}

/// The body's mesh, with at least one cell, moved by its `offset` [m].
fn body_mesh(b: &FileBody, key: &str, ctx: &Ctx) -> Result<Mesh, ScenarioError> {
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
    Ok(mesh)
}

/// The element kinematics `element` asks for, checked against the body's material.
fn element_formulation(
    element: Option<&str>,
    material: &dyn Hyperelastic,
    key: &str,
    ctx: &Ctx,
) -> Result<Formulation, ScenarioError> {
    match element {
        None | Some("standard") => Ok(Formulation::Standard),
        Some("fbar") => {
            if material.small_strain() {
                return Err(ctx.err(format!(
                    "`{key}.element` = \"fbar\" needs a finite-strain material; \"linear-elastic\" uses linear kinematics"
                )));
            }
            Ok(Formulation::FBar)
        }
        Some("anp") => {
            if !adhesim::anp::has_volumetric_split(material) {
                return Err(ctx.err(format!(
                    "`{key}.element` = \"anp\" needs a material with a bulk modulus split off: \"uncoupled-neo-hookean\", \"mooney-rivlin\" or \"ogden\" (optionally viscoelastic)"
                )));
            }
            Ok(Formulation::AveragedNodalPressure)
        }
        Some(other) => Err(ctx.err(format!(
            "`{key}.element` = {other:?}; valid values are \"standard\" (full integration), \"fbar\" (locking-free hexahedra) and \"anp\" (locking-free tetrahedra by averaged nodal pressure, F-bar hexahedra)"
        ))),
    }
}

/// Global index of each body's first node.
fn node_offsets(bodies: &[Body]) -> Vec<usize> {
    let mut o = Vec::new();
    let mut n = 0;
    for b in bodies {
        o.push(n);
        n += b.mesh.num_nodes();
    }
    o
}
