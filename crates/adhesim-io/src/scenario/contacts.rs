//! The `[[contact]]` pairs: the slave side, the master (a face set of another body or a
//! moving rigid shape), friction, adhesion, orthotropy and the detection distance.

use super::bodies::Bodies;
use super::boundaries::{build_components, build_rotation, zero_tables};
use super::{Ctx, FileAdhesion, FileContact, FileMaster, FileMotion, FileOrthotropy};
use super::{FileSetRef, ScenarioError};
use adhesim::contact::detect::{flat_quads, local_faces, thickness_twins, tributary_areas};
use adhesim::contact::law::Orthotropy;
use adhesim::contact::rcc::DEFAULT_BETA_EPS;
use adhesim::contact::{
    ContactPair, InterfaceLaw, Master, PairDiscretisation, RccParams, RigidMotion, RigidShape,
};
use adhesim::element::{FaceType, ELEMENT_TYPES};
use adhesim::mesh::Face;
use std::collections::BTreeMap;

/// The type of the first second-order face of `faces`, if any.
fn quadratic_face_type(faces: &[Face]) -> Option<&'static FaceType> {
    faces.iter().map(Face::face_type).find(|t| t.is_quadratic)
}

/// The names of the element types that have faces of type `face_type`, joined by "or".
fn element_types_with(face_type: &FaceType) -> String {
    let names: Vec<&str> = ELEMENT_TYPES
        .iter()
        .filter(|t| t.faces.iter().any(|f| f.face_type == face_type))
        .map(|t| t.name)
        .collect();
    names.join(" or ")
}

/// The `[[contact]]` pairs in file order, with distinct names.
pub(super) fn build_contacts(
    raw: &[FileContact],
    bodies: &Bodies,
    ctx: &Ctx,
) -> Result<Vec<ContactPair>, ScenarioError> {
    let mut contacts = Vec::new();
    for (i, c) in raw.iter().enumerate() {
        contacts.push(build_contact(c, &format!("contact[{i}]"), bodies, ctx)?);
    }
    let mut names = std::collections::BTreeSet::new();
    for (i, c) in contacts.iter().enumerate() {
        if !names.insert(c.name.clone()) {
            return Err(ctx.err(format!(
                "`contact[{i}].name`: the name {:?} is used twice; names must be unique",
                c.name
            )));
        }
    }
    Ok(contacts)
}

/// One contact pair, at `key` (`contact[i]`).
fn build_contact(
    c: &FileContact,
    key: &str,
    bodies: &Bodies,
    ctx: &Ctx,
) -> Result<ContactPair, ScenarioError> {
    if c.name.is_empty() || c.name.contains([',', '"', '\n', '.']) {
        return Err(ctx.err(format!(
            "`{key}.name` must be non-empty and hold no comma, dot or quote, got {:?}",
            c.name
        )));
    }
    let slave = Slave::build(&c.slave, key, bodies, ctx)?;
    let discretisation = build_discretisation(c, key, ctx)?;
    let master = build_master(c, key, slave.body, discretisation, bodies, ctx)?;
    let quadratic_master = match &master {
        Master::Faces(f) => quadratic_face_type(f),
        Master::Rigid { .. } => None,
    };
    if discretisation != PairDiscretisation::Mortar && matches!(master, Master::Faces(_)) {
        let found =
            (slave.quadratic.map(|t| ("slave", t))).or(quadratic_master.map(|t| ("master", t)));
        if let Some((side, t)) = found {
            return Err(ctx.err(format!(
                "`{key}.{side}.set` holds second-order faces ({}, of {} elements); between two bodies node-to-surface contact does not pass the contact patch test with them: set `{key}.discretisation = \"mortar\"`",
                t.name,
                element_types_with(t)
            )));
        }
    }
    let mu = c.friction;
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(ctx.err(format!(
            "`{key}.friction` must be a finite number ≥ 0 (0 = frictionless), got {mu}"
        )));
    }
    let mut adhesion = match &c.adhesion {
        None => None,
        Some(a) => Some(build_adhesion(a, key, ctx)?),
    };
    let anisotropy = match &c.orthotropy {
        None => None,
        Some(o) => Some(build_orthotropy(o, key, mu, &mut adhesion, ctx)?),
    };
    let thickness_twins = slave.thickness_twins(c.master.body.as_deref(), bodies);
    let detection_distance = match c.detection_distance {
        Some(d) => ctx.positive(&format!("{key}.detection_distance"), d)?,
        None => 0.5 * slave.mean_edge,
    };
    Ok(ContactPair {
        name: c.name.clone(),
        slave_nodes: slave.nodes,
        slave_area: slave.area,
        master,
        law: InterfaceLaw::rcc(mu, adhesion, anisotropy),
        detection_distance,
        slave_quads: flat_quads(&slave.faces),
        slave_faces: slave.faces,
        thickness_twins,
        discretisation,
    })
}

/// The pair's `discretisation` (node-to-surface when absent).
fn build_discretisation(
    c: &FileContact,
    key: &str,
    ctx: &Ctx,
) -> Result<PairDiscretisation, ScenarioError> {
    let Some(name) = c.discretisation.as_deref() else {
        return Ok(PairDiscretisation::default());
    };
    let Some(&(_, d)) = PairDiscretisation::NAMES.iter().find(|(n, _)| *n == name) else {
        let valid: Vec<String> = PairDiscretisation::NAMES
            .iter()
            .map(|(n, _)| format!("{n:?}"))
            .collect();
        return Err(ctx.err(format!(
            "`{key}.discretisation` = {name:?}; valid values are {}",
            valid.join(", ")
        )));
    };
    Ok(d)
}

/// The slave side of a pair: a face set of one body and the nodes on it.
struct Slave {
    /// Index of the slave body.
    body: usize,
    /// Body-local indices of the slave nodes: the node set of the face set's name if the
    /// body has one, otherwise the nodes of the faces, sorted.
    local_nodes: Vec<usize>,
    /// Global indices of the slave nodes.
    nodes: Vec<usize>,
    /// Tributary area [m²] of each slave node.
    area: Vec<f64>,
    /// The slave faces with indices into the slave nodes; faces with a node outside the
    /// slave nodes are left out.
    faces: Vec<Face>,
    /// The type of the face set's first second-order face, if it has one.
    quadratic: Option<&'static FaceType>,
    /// Mean edge length [m] of the slave faces.
    mean_edge: f64,
}

impl Slave {
    /// The slave side `s` of the pair at `key`.
    fn build(s: &FileSetRef, key: &str, bodies: &Bodies, ctx: &Ctx) -> Result<Self, ScenarioError> {
        let sb = bodies.body(&format!("{key}.slave.body"), &s.body, ctx)?;
        let faces = bodies.face_set(&format!("{key}.slave.set"), sb, &s.set, ctx)?;
        let mesh = &bodies.list[sb].mesh;
        manifold(
            &faces,
            &mesh.nodes,
            &format!("{key}.slave.set"),
            &s.set,
            ctx,
        )?;
        let local_nodes = match mesh.node_sets.get(&s.set) {
            Some(n) => n.clone(),
            None => {
                let mut n: Vec<usize> = faces.iter().flat_map(|f| f.nodes().to_vec()).collect();
                n.sort_unstable();
                n.dedup();
                n
            }
        };
        let area = tributary_areas(&faces, &mesh.nodes, &local_nodes);
        let quadratic = quadratic_face_type(&faces);
        let faces_local = local_faces(&faces, &local_nodes);
        let nodes = local_nodes.iter().map(|n| n + bodies.offsets[sb]).collect();
        let mean_edge = mean_edge(&faces, &mesh.nodes);
        Ok(Slave {
            body: sb,
            local_nodes,
            nodes,
            area,
            faces: faces_local,
            quadratic,
            mean_edge,
        })
    }

    /// The slave nodes through the thickness of each slave node (empty lists unless the
    /// problem is plane: a plane-strain slave against a plane-strain body, `master_body`, or
    /// a rigid surface, where each line of slave nodes through the thickness is one contact
    /// point).
    fn thickness_twins(&self, master_body: Option<&str>, bodies: &Bodies) -> Vec<Vec<usize>> {
        let master_in_plane = master_body.map_or(true, |b| bodies.in_plane_strain(b));
        let slave = &bodies.list[self.body];
        if slave.plane_strain && master_in_plane {
            thickness_twins(&self.local_nodes, &slave.mesh.nodes)
        } else {
            vec![Vec::new(); self.local_nodes.len()]
        }
    }
}

/// Checks that the contact surface `faces` (of the face set `set`, named at `key`) is a
/// manifold: no edge between two corners is shared by more than two of its faces (as where
/// two parts of a body touch along an edge only), since a site's normal and the mortar
/// segments need one surface on each side of an edge.
fn manifold(
    faces: &[Face],
    nodes: &[[f64; 3]],
    key: &str,
    set: &str,
    ctx: &Ctx,
) -> Result<(), ScenarioError> {
    match non_manifold_edge(faces) {
        None => Ok(()),
        Some(([a, b], count)) => Err(ctx.err(format!(
            "`{key}` = {set:?} is not a manifold surface: the edge from {:?} to {:?} is shared by {count} of its faces; a contact surface may have at most two faces at an edge (split the set, or mesh the parts so that they do not meet along an edge only)",
            nodes[a], nodes[b]
        ))),
    }
}

/// An edge (its two corner nodes, sorted) shared by more than two of `faces`, with the
/// number of faces sharing it; the first such edge in node order.
fn non_manifold_edge(faces: &[Face]) -> Option<([usize; 2], usize)> {
    let mut count: BTreeMap<[usize; 2], usize> = BTreeMap::new();
    for f in faces {
        let c = f.corners();
        for k in 0..c.len() {
            let (a, b) = (c[k], c[(k + 1) % c.len()]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    count.into_iter().find(|&(_, n)| n > 2)
}

/// Mean length [m] of the faces' edges (0 without faces).
fn mean_edge(faces: &[Face], nodes: &[[f64; 3]]) -> f64 {
    let mut sum = 0.0;
    let mut count = 0;
    for f in faces {
        let ns = f.corners();
        for i in 0..ns.len() {
            let (a, b) = (nodes[ns[i]], nodes[ns[(i + 1) % ns.len()]]);
            sum += ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
            count += 1;
        }
    }
    sum / count.max(1) as f64
}

/// The master of the pair at `key` discretised by `d`: a face set of a body (the slave body
/// `sb` itself with mortar only), or a rigid shape with its motion (not with mortar).
fn build_master(
    c: &FileContact,
    key: &str,
    sb: usize,
    d: PairDiscretisation,
    bodies: &Bodies,
    ctx: &Ctx,
) -> Result<Master, ScenarioError> {
    let m = &c.master;
    match (&m.body, &m.rigid) {
        (Some(body), None) => deformable_master(c, body, key, sb, d, bodies, ctx),
        (None, Some(kind)) => {
            if d == PairDiscretisation::Mortar {
                return Err(ctx.err(format!(
                    "`{key}.discretisation` = \"mortar\" needs a deformable master (`master.body` and `master.set`); against a rigid surface use \"node-to-surface\", which is exact there"
                )));
            }
            if m.set.is_some() {
                return Err(ctx.err(format!("`{key}.master.set` goes with `body`, not with `rigid`")));
            }
            let shape = rigid_shape(m, kind, key, ctx)?;
            let motion = rigid_motion(c.motion.as_ref(), key, ctx)?;
            Ok(Master::Rigid { shape, motion })
        }
        _ => Err(ctx.err(format!("`{key}.master` needs exactly one of `body` (+ `set`: a deformable master) or `rigid` (\"plane\", \"sphere\", \"cylinder\")"))),
    }
}

/// A deformable master: the face set `set` of body `body` (the slave body `sb` itself only
/// with mortar, `d`), in global node indices.
fn deformable_master(
    c: &FileContact,
    body: &str,
    key: &str,
    sb: usize,
    d: PairDiscretisation,
    bodies: &Bodies,
    ctx: &Ctx,
) -> Result<Master, ScenarioError> {
    let m = &c.master;
    let mb = bodies.body(&format!("{key}.master.body"), body, ctx)?;
    if mb == sb && d != PairDiscretisation::Mortar {
        return Err(ctx.err(format!("`{key}`: slave and master are both on body {body:?}; self-contact needs `discretisation = \"mortar\"` (node-to-surface would find each slave node's own faces)")));
    }
    let set = m.set.as_deref().ok_or_else(|| {
        ctx.err(format!(
            "`{key}.master` on a body needs `set` (a face set of that body)"
        ))
    })?;
    if m.point.is_some()
        || m.normal.is_some()
        || m.center.is_some()
        || m.axis.is_some()
        || m.radius.is_some()
    {
        return Err(ctx.err(format!(
            "`{key}.master`: a deformable master takes only `body` and `set`"
        )));
    }
    if c.motion.is_some() {
        return Err(ctx.err(format!("`{key}.motion` applies to rigid masters only; move a deformable master with [[boundary]] conditions")));
    }
    let faces = bodies.face_set(&format!("{key}.master.set"), mb, set, ctx)?;
    manifold(
        &faces,
        &bodies.list[mb].mesh.nodes,
        &format!("{key}.master.set"),
        set,
        ctx,
    )?;
    let off = bodies.offsets[mb];
    Ok(Master::Faces(
        faces
            .into_iter()
            .map(|f| f.map_nodes(|i| i + off))
            .collect(),
    ))
}

/// The rigid shape `kind` of the master `m`: a plane (point and unit normal), a sphere
/// (center and radius) or a cylinder (point, unit axis and radius), in metres.
fn rigid_shape(
    m: &FileMaster,
    kind: &str,
    key: &str,
    ctx: &Ctx,
) -> Result<RigidShape, ScenarioError> {
    let need3 = |name: &str, v: Option<[f64; 3]>| -> Result<[f64; 3], ScenarioError> {
        let v = v.ok_or_else(|| {
            ctx.err(format!(
                "`{key}.master` with rigid = {kind:?} needs `{name}`"
            ))
        })?;
        ctx.finite3(&format!("{key}.master.{name}"), v)
    };
    let unit = |name: &str, v: [f64; 3]| -> Result<[f64; 3], ScenarioError> {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if l > 0.0 {
            Ok(v.map(|a| a / l))
        } else {
            Err(ctx.err(format!("`{key}.master.{name}` must be a non-zero vector")))
        }
    };
    let radius = || -> Result<f64, ScenarioError> {
        let r = m.radius.ok_or_else(|| {
            ctx.err(format!(
                "`{key}.master` with rigid = {kind:?} needs `radius` [m]"
            ))
        })?;
        ctx.positive(&format!("{key}.master.radius"), r)
    };
    Ok(match kind {
        "plane" => RigidShape::Plane { point: need3("point", m.point)?, normal: unit("normal", need3("normal", m.normal)?)? },
        "sphere" => RigidShape::Sphere { center: need3("center", m.center)?, radius: radius()? },
        "cylinder" => RigidShape::Cylinder { point: need3("point", m.point)?, axis: unit("axis", need3("axis", m.axis)?)?, radius: radius()? },
        other => return Err(ctx.err(format!("`{key}.master.rigid` = {other:?}; valid shapes are \"plane\", \"sphere\", \"cylinder\""))),
    })
}

/// The `motion` of a rigid master: displacements [m] over time and an optional rotation
/// (none when left out).
fn rigid_motion(
    motion: Option<&FileMotion>,
    key: &str,
    ctx: &Ctx,
) -> Result<RigidMotion, ScenarioError> {
    let mut translation = zero_tables();
    let mut rotation = None;
    if let Some(mo) = motion {
        if let Some(d) = &mo.displacement {
            translation = build_components(d, &format!("{key}.motion.displacement"), ctx)?;
        }
        if let Some(r) = &mo.rotation {
            rotation = Some(build_rotation(r, &format!("{key}.motion.rotation"), ctx)?);
        }
    }
    Ok(RigidMotion {
        translation,
        rotation,
    })
}

/// The RCC adhesion parameters of the pair at `key`: energy `w` [J/m²], stiffnesses `cn`
/// and `ct` [N/m³], viscosity `b` [N·s/m], `eps` and the fatigue energy (infinite when left
/// out). `ct2` starts equal to `ct`.
fn build_adhesion(a: &FileAdhesion, key: &str, ctx: &Ctx) -> Result<RccParams, ScenarioError> {
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
        return Err(ctx.err(format!(
            "`{key}.adhesion.b` must be a finite number ≥ 0 [N·s/m] (0 = rate-independent), got {}",
            a.b
        )));
    }
    let eps = a.eps.unwrap_or(DEFAULT_BETA_EPS);
    if !(eps > 0.0 && eps < 1.0) {
        return Err(ctx.err(format!("`{key}.adhesion.eps` must be in (0, 1), got {eps}")));
    }
    let fatigue_energy = match a.fatigue_energy {
        None => f64::INFINITY,
        Some(d) => ctx.positive(&format!("{key}.adhesion.fatigue_energy"), d)?,
    };
    Ok(RccParams {
        w,
        cn,
        ct: a.ct,
        ct2: a.ct,
        b: a.b,
        eps,
        fatigue_energy,
    })
}

/// The orthotropy of the pair at `key` (friction `mu` along the first axis): the unit first
/// axis, the friction along the second, and `ct_2` [N/m³], which sets the adhesion's `ct2`.
fn build_orthotropy(
    o: &FileOrthotropy,
    key: &str,
    mu: f64,
    adhesion: &mut Option<RccParams>,
    ctx: &Ctx,
) -> Result<Orthotropy, ScenarioError> {
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
    Ok(Orthotropy {
        axis: o.axis.map(|v| v / len),
        mu2,
    })
}
