//! Contact pairs and their kinematics: detection once per step (candidates within a
//! detection distance), closest-point projection, local frames (T₁, T₂, N), gaps and the
//! sparse operator H (rows T₁ᵀ, T₂ᵀ, Nᵀ applied to the slave node minus the master nodes
//! weighted by their shape functions at the projection).

use super::anisotropic::aligned_frame;
use super::law::InterfaceLaw;
use crate::mesh::Face;
use crate::prescribed::{rotate, Rotation, Table};
use crate::Vec3;
use std::collections::HashMap;

/// An analytic rigid surface, in its reference position. Slave nodes must stay on the side
/// the normal points to.
#[derive(Clone, Debug, PartialEq)]
pub enum RigidShape {
    /// Plane through `point` with unit normal `normal` (pointing towards the slave body).
    Plane {
        /// A point of the plane [m].
        point: [f64; 3],
        /// Unit normal towards the slave side.
        normal: [f64; 3],
    },
    /// Sphere; slave nodes stay outside.
    Sphere {
        /// Centre [m].
        center: [f64; 3],
        /// Radius [m].
        radius: f64,
    },
    /// Infinite circular cylinder; slave nodes stay outside.
    Cylinder {
        /// A point of the axis [m].
        point: [f64; 3],
        /// Unit axis direction.
        axis: [f64; 3],
        /// Radius [m].
        radius: f64,
    },
}

/// Prescribed rigid motion of a rigid surface: x(t) = R(t)(X − c) + c + T(t).
#[derive(Clone, Debug, PartialEq)]
pub struct RigidMotion {
    /// Translation per component [m].
    pub translation: [Table; 3],
    /// Optional rotation about an axis through `center` (reference position).
    pub rotation: Option<Rotation>,
}

impl RigidMotion {
    /// Maps a reference point X to its position at time t.
    pub fn apply(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let mut p = x;
        if let Some(r) = &self.rotation {
            let d = Vec3::from(x) - Vec3::from(r.center);
            let rd = rotate(d, r.axis.into(), r.angle.at(t));
            p = (rd + Vec3::from(r.center)).into();
        }
        std::array::from_fn(|k| p[k] + self.translation[k].at(t))
    }

    /// Maps a position at time t back to the reference point.
    pub fn inverse(&self, p: [f64; 3], t: f64) -> [f64; 3] {
        let mut x: [f64; 3] = std::array::from_fn(|k| p[k] - self.translation[k].at(t));
        if let Some(r) = &self.rotation {
            let d = Vec3::from(x) - Vec3::from(r.center);
            x = (rotate(d, r.axis.into(), -r.angle.at(t)) + Vec3::from(r.center)).into();
        }
        x
    }

    /// Rotates a direction from the reference orientation to time t.
    pub fn rotate_dir(&self, v: [f64; 3], t: f64) -> [f64; 3] {
        match &self.rotation {
            Some(r) => rotate(v.into(), r.axis.into(), r.angle.at(t)).into(),
            None => v,
        }
    }
}

/// The master side of a contact pair.
#[derive(Clone, Debug)]
pub enum Master {
    /// A rigid analytic surface with a prescribed motion.
    Rigid {
        /// Shape in its reference position.
        shape: RigidShape,
        /// Motion.
        motion: RigidMotion,
    },
    /// Boundary faces of a deformable body (global node indices, outward oriented).
    Faces(Vec<Face>),
}

/// A contact pair: slave nodes of one body against a master surface.
#[derive(Clone, Debug)]
pub struct ContactPair {
    /// Name used in outputs.
    pub name: String,
    /// Global indices of the slave nodes.
    pub slave_nodes: Vec<usize>,
    /// Tributary area of each slave node in the reference configuration [m²].
    pub slave_area: Vec<f64>,
    /// The master surface.
    pub master: Master,
    /// Friction and adhesion parameters.
    pub law: InterfaceLaw,
    /// Slave nodes farther than this from the master at the start of a step are not
    /// candidates (and lose their bond) [m].
    pub detection_distance: f64,
    /// The flat pieces of the slave faces ([`Face::flat_pieces`]) as indices into
    /// `slave_nodes` (a triangle repeats its last node), for maps of contact fields over the
    /// surface and the slave normals: [`flat_quads`] of `slave_faces`.
    pub slave_quads: Vec<[usize; 4]>,
    /// The slave faces with indices into `slave_nodes`, as the mesh holds them (mortar
    /// integrates over them).
    pub slave_faces: Vec<Face>,
    /// Plane strain: for each slave node, the other slave nodes on its line through the
    /// slab's thickness (same x and y), as indices into `slave_nodes`; empty lists for a 3D
    /// pair. Such a line is one contact point of the plane problem (see [`ContactPoint`]).
    pub thickness_twins: Vec<Vec<usize>>,
    /// How the pair's contact sites are found (node-to-surface or mortar).
    pub discretisation: super::discretisation::PairDiscretisation,
}

/// For a plane-strain slave surface (the plane being x-y): each node's twins, the other nodes
/// of `nodes` with the same reference x and y (to 1e-9 of the surface's extent).
pub fn thickness_twins(nodes: &[usize], coords: &[[f64; 3]]) -> Vec<Vec<usize>> {
    let extent = nodes
        .iter()
        .flat_map(|&n| coords[n][..2].iter().map(|c| c.abs()))
        .fold(0.0f64, f64::max);
    let tol = 1e-9 * extent.max(f64::MIN_POSITIVE);
    let key = |n: usize| {
        let c = coords[n];
        ((c[0] / tol).round() as i64, (c[1] / tol).round() as i64)
    };
    let mut lines: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, &n) in nodes.iter().enumerate() {
        lines.entry(key(n)).or_default().push(i);
    }
    nodes
        .iter()
        .enumerate()
        .map(|(i, &n)| lines[&key(n)].iter().copied().filter(|&j| j != i).collect())
        .collect()
}

/// The faces of `faces` whose nodes are all in `nodes`, with their nodes as indices into
/// `nodes` (the form of [`ContactPair::slave_faces`]).
pub fn local_faces(faces: &[Face], nodes: &[usize]) -> Vec<Face> {
    let index: HashMap<usize, usize> = nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
    faces
        .iter()
        .filter_map(|f| {
            let m: Option<Vec<usize>> = f.nodes().iter().map(|n| index.get(n).copied()).collect();
            m.map(|m| Face::new(f.face_type(), &m))
        })
        .collect()
}

/// The flat pieces of `faces` ([`Face::flat_pieces`]) as quadrangles of the faces' node
/// indices, a triangle repeating its last node.
pub fn flat_quads(faces: &[Face]) -> Vec<[usize; 4]> {
    let mut out = Vec::new();
    for f in faces {
        let ns = f.nodes();
        for piece in f.flat_pieces() {
            let at = |i: usize| ns[piece[i.min(piece.len() - 1)]];
            out.push([at(0), at(1), at(2), at(3)]);
        }
    }
    out
}

/// Tributary areas of the nodes of a face set [m²], in the order of `nodes`: the integral of
/// each node's hat function over the flat pieces of the faces ([`Face::flat_pieces`], the face
/// itself when it is linear), [`hat_integrals`] of each piece. A triangle gives each of its
/// corners a third of its area; a quadrilateral gives a quarter only when it is a
/// parallelogram. On a six-node triangle that gives a corner 1/12 of the face and a mid-side
/// node 1/4, on a flat, undistorted eight-node quadrilateral a corner 1/24 and a mid-side node
/// 5/24, on a nine-node one a corner 1/16, a mid-side node 1/8 and the centre 1/4: positive,
/// where the quadratic corner functions integrate to zero or less. These are the measures
/// mortar gives a fully covered slave node, and they add up to the pieces' areas.
pub fn tributary_areas(faces: &[Face], coords: &[[f64; 3]], nodes: &[usize]) -> Vec<f64> {
    let index: HashMap<usize, usize> = nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
    let mut area = vec![0.0; nodes.len()];
    for f in faces {
        let all = f.nodes();
        for piece in f.flat_pieces() {
            let ns: Vec<usize> = piece.iter().map(|&c| all[c]).collect();
            let x: Vec<Vec3> = ns.iter().map(|&n| Vec3::from(coords[n])).collect();
            for (n, a) in ns.iter().zip(hat_integrals(&x)) {
                if let Some(&i) = index.get(n) {
                    area[i] += a;
                }
            }
        }
    }
    area
}

/// ∫ φ_a dA over a flat piece with corners `x` (a triangle, or a quadrilateral
/// counter-clockwise) of each corner's hat function φ_a [m²], in the order of `x`.
///
/// A triangle's hats are its barycentric coordinates, each integrating to a third of its
/// area, exactly.
///
/// A quadrilateral's hats are the bilinear functions φ_a = (1 + ξ ξ_a)(1 + η η_a)/4 of the
/// natural coordinates (ξ, η) ∈ [−1, 1]² of its own bilinear map
/// x(ξ, η) = Σ_a φ_a x_a = x̄ + b ξ + c η + d ξη, and ∫ φ_a dA = ∫∫ φ_a (x_ξ × x_η)·n dξ dη,
/// n the unit normal of the cross product of its diagonals. The area vector
/// x_ξ × x_η = b × c + ξ b × d + η d × c is linear in (ξ, η) (its ξη term is d × d = 0), so
/// the integrand is a polynomial of degree at most 2 in ξ and in η (biquadratic), and the
/// 2 × 2 Gauss rule, exact to degree 3 in each, integrates it exactly. The constant part
/// (b × c)·n = A/4, A = |d₁ × d₂|/2 the area, is integrated apart (∫∫ φ_a = 1), so that a
/// parallelogram (d = 0) gets A/4 exactly as computed before this rule; the rule integrates
/// the rest, which vanishes there.
///
/// On a planar quadrilateral (x_ξ × x_η)·n is the area density, and the result is the
/// closed form ∫ φ_a dA = (A + T_a)/6, T_a the area of the triangle of corner a and its two
/// neighbours: A/4 only on a parallelogram (T_a = A/2). A warped quadrilateral is integrated
/// as its projection on the plane normal to n (the plane mortar lays a face on); its four
/// integrals add up to A, the projected area. A degenerate piece (no area) gives zeros.
pub fn hat_integrals(x: &[Vec3]) -> Vec<f64> {
    match x.len() {
        3 => {
            let area = 0.5 * (x[1] - x[0]).cross(&(x[2] - x[0])).norm();
            vec![area / 3.0; 3]
        }
        4 => {
            let twice_area = (x[2] - x[0]).cross(&(x[3] - x[1]));
            let norm = twice_area.norm();
            if norm == 0.0 {
                return vec![0.0; 4];
            }
            let n = twice_area / norm;
            let area = 0.5 * norm;
            // x_ξ = b + d η, x_η = c + d ξ.
            let b = (x[1] - x[0] + x[2] - x[3]) * 0.25;
            let c = (x[3] - x[0] + x[2] - x[1]) * 0.25;
            let d = (x[0] - x[1] + x[2] - x[3]) * 0.25;
            // The area density less its constant part A/4: p ξ + q η.
            let (p, q) = (b.cross(&d).dot(&n), d.cross(&c).dot(&n));
            const CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
            let g = 1.0 / 3f64.sqrt();
            let mut out = vec![area / 4.0; 4];
            // The 2 × 2 Gauss rule, weights 1.
            for (s, t) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
                let density = p * s + q * t;
                for (a, [sa, ta]) in CORNERS.iter().enumerate() {
                    out[a] += 0.25 * (1.0 + sa * s) * (1.0 + ta * t) * density;
                }
            }
            out
        }
        k => panic!("a flat piece has 3 or 4 corners, not {k}"),
    }
}

/// One candidate contact point of a step: frame, gap and the rows of H.
#[derive(Clone, Debug)]
pub struct ContactPoint {
    /// Pair index.
    pub pair: usize,
    /// Index of the slave node within the pair.
    pub local: usize,
    /// Global slave node.
    pub slave: usize,
    /// Tributary area [m²].
    pub area: f64,
    /// Local frame: rows T₁, T₂, N (unit, right-handed; N points from master to slave).
    pub frame: [[f64; 3]; 3],
    /// Master nodes and their weights (shape functions at the projection); empty for a
    /// rigid master.
    pub master: Vec<(usize, f64)>,
    /// Position of the master material point at the end of the step for a rigid master, at
    /// the start of the step for a deformable one (its motion then comes from u) [m].
    pub master_point_end: [f64; 3],
    /// Relative position slave − master at the start of the step, in global axes [m].
    pub d0: [f64; 3],
    /// Plane strain: the other slave nodes through the slab's thickness (global node, index in
    /// the pair), empty in 3D. The point then stands for the whole line: its slave
    /// displacement is the mean over `slave` and its twins, its force is shared equally
    /// among them, and its area is theirs together, so that the slab cannot be twisted out
    /// of its plane by contact.
    pub twins: Vec<(usize, usize)>,
    /// The slave side's own weights (global node, weight; adding up to 1) of a mortar site:
    /// its node alone (weight 1) where dual multipliers are used, a weighted mean of several
    /// slave nodes otherwise; empty for a node-to-surface site (the node alone or with its
    /// twins).
    pub slave_weights: Vec<(usize, f64)>,
}

impl ContactPoint {
    /// The slave nodes with their weights in the point's slave displacement: the node alone
    /// (weight 1), the node and its twins through a plane-strain slab (equal weights), or
    /// [`ContactPoint::slave_weights`] when given.
    pub fn slave_nodes(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        let alone = self.slave_weights.is_empty();
        let w = self.node_share();
        let node_and_twins = std::iter::once(self.slave)
            .chain(self.twins.iter().map(|t| t.0))
            .filter(move |_| alone)
            .map(move |s| (s, w));
        self.slave_weights.iter().copied().chain(node_and_twins)
    }

    /// The point's stencil: every node whose displacement enters its relative displacement,
    /// with its signed weight (the slave nodes of [`ContactPoint::slave_nodes`] with +w, the
    /// master nodes with −w), slave nodes first. H_α is the frame's rows times these weights:
    /// x_α = F_α Σ_n w_n u_n plus the constant part.
    pub fn stencil(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.slave_nodes()
            .chain(self.master.iter().map(|&(m, w)| (m, -w)))
    }

    /// H_α on the unknowns of a factorised system: node n's unknowns are those of its
    /// representative `rep[n]`, and the `fixed` unknowns are left out. Each unknown is listed
    /// once, in increasing order, with the coefficients of the point's three local components.
    pub fn h_terms(&self, rep: &[usize], fixed: &[bool]) -> Vec<(usize, [f64; 3])> {
        let mut terms: Vec<(usize, [f64; 3])> = Vec::new();
        for (node, w) in self.stencil() {
            for k in 0..3 {
                let i = 3 * rep[node] + k;
                if !fixed[i] {
                    terms.push((i, std::array::from_fn(|c| w * self.frame[c][k])));
                }
            }
        }
        terms.sort_by_key(|t| t.0);
        let mut merged: Vec<(usize, [f64; 3])> = Vec::with_capacity(terms.len());
        for (i, c) in terms {
            match merged.last_mut() {
                Some(last) if last.0 == i => (0..3).for_each(|k| last.1[k] += c[k]),
                _ => merged.push((i, c)),
            }
        }
        merged
    }

    /// Indices in the pair of the slave nodes the point stands for.
    pub fn locals(&self) -> impl Iterator<Item = usize> + '_ {
        std::iter::once(self.local).chain(self.twins.iter().map(|t| t.1))
    }

    /// The weight of each slave node in the point (1 in 3D, 1/n for a line of n nodes through
    /// a plane-strain slab): the share of the point's force each node carries.
    pub fn node_share(&self) -> f64 {
        1.0 / (1 + self.twins.len()) as f64
    }
    /// Local relative displacement x = (slip increment t₁, t₂, end gap n) for the end-of-step
    /// displacement `u` [m] (H applied to u plus the constant part).
    pub fn local_x(&self, reference: &[[f64; 3]], u: &[f64]) -> [f64; 3] {
        let d1 = Vec3::from(self.relative_position(reference, u));
        let f = self.frame.map(Vec3::from);
        let ds = d1 - Vec3::from(self.d0);
        [f[0].dot(&ds), f[1].dot(&ds), f[2].dot(&d1)]
    }

    fn relative_position(&self, reference: &[[f64; 3]], u: &[f64]) -> [f64; 3] {
        let mut xs = [0.0; 3];
        for (s, w) in self.slave_nodes() {
            for k in 0..3 {
                xs[k] += w * (reference[s][k] + u[3 * s + k]);
            }
        }
        if self.master.is_empty() {
            return (Vec3::from(xs) - Vec3::from(self.master_point_end)).into();
        }
        let mut xm = [0.0; 3];
        for &(m, w) in &self.master {
            for k in 0..3 {
                xm[k] += w * (reference[m][k] + u[3 * m + k]);
            }
        }
        (Vec3::from(xs) - Vec3::from(xm)).into()
    }

    /// Adds Hᵀ r (r in local axes) to a global vector.
    pub fn add_ht(&self, r: [f64; 3], out: &mut [f64]) {
        let f = &self.frame;
        let g: [f64; 3] = std::array::from_fn(|k| r[0] * f[0][k] + r[1] * f[1][k] + r[2] * f[2][k]);
        for (n, w) in self.stencil() {
            for k in 0..3 {
                out[3 * n + k] += w * g[k];
            }
        }
    }

    /// H v: the local components of a global displacement field v.
    pub fn apply_h(&self, v: &[f64]) -> [f64; 3] {
        let mut d = [0.0; 3];
        for (n, w) in self.stencil() {
            for k in 0..3 {
                d[k] += w * v[3 * n + k];
            }
        }
        let (f, d) = (self.frame.map(Vec3::from), Vec3::from(d));
        [f[0].dot(&d), f[1].dot(&d), f[2].dot(&d)]
    }
}

/// How a contact pair is discretised: the contact sites it has at the start of a step. A
/// discretisation is one file (node-to-surface: `node_to_surface.rs`).
pub trait Discretisation: std::fmt::Debug + Send + Sync {
    /// The candidate sites of pair `pair_index` (`pair`) at the start of a step [t0, t1] [s]
    /// from the reference coordinates [m] and the displacement `u0` [m].
    fn sites(
        &self,
        pair_index: usize,
        pair: &ContactPair,
        reference: &[[f64; 3]],
        u0: &[f64],
        t0: f64,
        t1: f64,
    ) -> Vec<ContactPoint>;
}

/// Closest point, outward unit normal and signed gap of a point (in the surface's
/// reference frame).
pub fn rigid_projection(shape: &RigidShape, x: [f64; 3]) -> ([f64; 3], [f64; 3], f64) {
    match shape {
        RigidShape::Plane { point, normal } => {
            let g = (Vec3::from(x) - Vec3::from(*point)).dot(&Vec3::from(*normal));
            (std::array::from_fn(|k| x[k] - g * normal[k]), *normal, g)
        }
        RigidShape::Sphere { center, radius } => {
            let d = Vec3::from(x) - Vec3::from(*center);
            let r = d.norm();
            let n: [f64; 3] = unit(d).into();
            (
                std::array::from_fn(|k| center[k] + radius * n[k]),
                n,
                r - radius,
            )
        }
        RigidShape::Cylinder {
            point,
            axis,
            radius,
        } => {
            let d = Vec3::from(x) - Vec3::from(*point);
            let along = d.dot(&Vec3::from(*axis));
            let radial = d - along * Vec3::from(*axis);
            let r = radial.norm();
            let n: [f64; 3] = unit(radial).into();
            (
                std::array::from_fn(|k| point[k] + along * axis[k] + radius * n[k]),
                n,
                r - radius,
            )
        }
    }
}

/// Closest-point projection of `x` on a face by its face type's projection
/// ([`crate::element::FaceType::project`]), kept on the face; returns the point, the face's
/// unit normal there and the nodal weights.
pub fn project_on_face(
    face: &Face,
    pos: &dyn Fn(usize) -> [f64; 3],
    x: [f64; 3],
) -> ([f64; 3], [f64; 3], Vec<f64>) {
    let p: Vec<Vec3> = face.nodes().iter().map(|&n| Vec3::from(pos(n))).collect();
    (face.face_type().project)(&p, Vec3::from(x))
}

/// A uniform grid over the master faces' bounding boxes (inflated by the detection
/// distance), so each slave node looks only at nearby faces.
pub(super) struct FaceGrid {
    cell: f64,
    map: HashMap<[i64; 3], Vec<usize>>,
}

impl FaceGrid {
    pub(super) fn new(faces: &[Face], pos: &dyn Fn(usize) -> [f64; 3], pad: f64) -> Self {
        let boxes: Vec<([f64; 3], [f64; 3])> = faces
            .iter()
            .map(|f| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for &n in f.nodes() {
                    let p = pos(n);
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k] - pad);
                        hi[k] = hi[k].max(p[k] + pad);
                    }
                }
                (lo, hi)
            })
            .collect();
        let mean = boxes
            .iter()
            .map(|(l, h)| (0..3).map(|k| h[k] - l[k]).fold(0.0, f64::max))
            .sum::<f64>()
            / boxes.len().max(1) as f64;
        let cell = mean.max(1e-12);
        let mut map: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, (lo, hi)) in boxes.iter().enumerate() {
            let a = lo.map(|v| (v / cell).floor() as i64);
            let b = hi.map(|v| (v / cell).floor() as i64);
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        map.entry([x, y, z]).or_default().push(i);
                    }
                }
            }
        }
        FaceGrid { cell, map }
    }

    pub(super) fn candidates(&self, x: [f64; 3]) -> &[usize] {
        let key = x.map(|v| (v / self.cell).floor() as i64);
        self.map.get(&key).map_or(&[], |v| v.as_slice())
    }

    /// The faces whose (inflated) boxes share a grid cell with the box [lo, hi] [m], each
    /// once, in increasing order.
    pub(super) fn candidates_in_box(&self, lo: [f64; 3], hi: [f64; 3]) -> Vec<usize> {
        let a = lo.map(|v| (v / self.cell).floor() as i64);
        let b = hi.map(|v| (v / self.cell).floor() as i64);
        let mut out = Vec::new();
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    out.extend(self.map.get(&[x, y, z]).into_iter().flatten().copied());
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Turns the frames of the points of orthotropic pairs to their material axes
/// ([`super::anisotropic`]); points where the axis is normal to the surface keep their frame.
pub fn align_frames(points: &mut [ContactPoint], pairs: &[ContactPair]) {
    for pt in points {
        if let Some(o) = &pairs[pt.pair].law.anisotropy {
            if let Some(frame) = aligned_frame(pt.frame[2], o.axis) {
                pt.frame = frame;
            }
        }
    }
}

/// Right-handed local frame (rows T₁, T₂, N) from a unit normal N. T₁ = N × e_z normalised
/// (so that for normals in the x-y plane of a plane-strain slab T₁ lies in that plane), or
/// N × e_x when N is close to e_z.
pub fn frame_from_normal(n: [f64; 3]) -> [[f64; 3]; 3] {
    let nv = Vec3::from(n);
    let t1 = if n[2].abs() < 0.9 {
        unit(nv.cross(&Vec3::z()))
    } else {
        unit(nv.cross(&Vec3::x()))
    };
    let t2 = nv.cross(&t1);
    [t1.into(), t2.into(), n]
}

/// `a` scaled to unit length; e_y for the zero vector.
pub(super) use crate::element::face::unit;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prescribed::Rotation;

    fn normalize(a: [f64; 3]) -> [f64; 3] {
        unit(Vec3::from(a)).into()
    }

    /// ‖a − b‖.
    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        (Vec3::from(a) - Vec3::from(b)).norm()
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        for n in [
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
            normalize([0.3, -0.4, 0.8]),
            normalize([1.0, 1.0, 0.0]),
        ] {
            let [t1, t2, nn] = frame_from_normal(n).map(Vec3::from);
            assert!((t1.norm() - 1.0).abs() < 1e-14 && (t2.norm() - 1.0).abs() < 1e-14);
            assert!(
                t1.dot(&t2).abs() < 1e-14 && t1.dot(&nn).abs() < 1e-14 && t2.dot(&nn).abs() < 1e-14
            );
            assert!((t1.cross(&t2) - nn).norm() < 1e-14, "T1 × T2 must be N");
        }
        // Normals in the x-y plane of a plane-strain slab keep T1 in that plane.
        let [t1, _, _] = frame_from_normal(normalize([0.6, 0.8, 0.0]));
        assert!(t1[2].abs() < 1e-15);
    }

    #[test]
    fn rigid_motion_inverse_undoes_apply() {
        let m = RigidMotion {
            translation: [
                Table {
                    t: vec![0.0, 1.0],
                    v: vec![0.0, 0.2],
                },
                Table::constant(-0.1),
                Table::constant(0.05),
            ],
            rotation: Some(Rotation {
                center: [0.1, 0.2, 0.3],
                axis: normalize([0.2, 1.0, -0.3]),
                angle: Table {
                    t: vec![0.0, 1.0],
                    v: vec![0.0, 1.3],
                },
            }),
        };
        let x = [0.4, -0.7, 0.25];
        for t in [0.0, 0.3, 1.0, 2.0] {
            let back = m.inverse(m.apply(x, t), t);
            assert!(dist(back, x) < 1e-14, "t = {t}");
        }
        // Distances between material points are preserved (rigid).
        let y = [0.0, 0.1, -0.2];
        let d0 = dist(x, y);
        let d1 = dist(m.apply(x, 0.6), m.apply(y, 0.6));
        assert!((d0 - d1).abs() < 1e-14);
    }

    #[test]
    fn rigid_shapes_give_signed_gaps_and_outward_normals() {
        let plane = RigidShape::Plane {
            point: [0.0, 1.0, 0.0],
            normal: [0.0, 1.0, 0.0],
        };
        let (p, n, g) = rigid_projection(&plane, [0.3, 1.25, -2.0]);
        assert_eq!((p, n), ([0.3, 1.0, -2.0], [0.0, 1.0, 0.0]));
        assert!((g - 0.25).abs() < 1e-15);
        let sphere = RigidShape::Sphere {
            center: [0.0; 3],
            radius: 2.0,
        };
        let (p, n, g) = rigid_projection(&sphere, [0.0, 0.0, 1.5]);
        assert!((g + 0.5).abs() < 1e-15 && n == [0.0, 0.0, 1.0] && (p[2] - 2.0).abs() < 1e-15);
        let cyl = RigidShape::Cylinder {
            point: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            radius: 1.0,
        };
        let (p, n, g) = rigid_projection(&cyl, [3.0, 0.0, 7.0]);
        assert!((g - 2.0).abs() < 1e-15 && n == [1.0, 0.0, 0.0] && p == [1.0, 0.0, 7.0]);
    }

    #[test]
    fn closest_point_on_a_warped_quad_is_orthogonal_and_weights_interpolate() {
        let nodes = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.1],
            [1.2, 1.0, -0.05],
            [0.1, 0.9, 0.0],
        ];
        let pos = |i: usize| nodes[i];
        let face = Face::quad([0, 1, 2, 3]);
        let x = [0.55, 0.4, 0.6];
        let (xm, n, w) = project_on_face(&face, &pos, x);
        // The weights are partition of unity and reproduce the projected point.
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let xi: [f64; 3] = std::array::from_fn(|k| (0..4).map(|i| w[i] * nodes[i][k]).sum());
        assert!(dist(xi, xm) < 1e-14);
        // x − x_m is orthogonal to the surface tangents at the projection (an interior
        // closest point), hence parallel to the normal.
        let (d, n) = (Vec3::from(x) - Vec3::from(xm), Vec3::from(n));
        assert!(d.cross(&n).norm() < 1e-9 * d.norm(), "not along the normal");
        assert!(
            d.dot(&n) > 0.0,
            "the point is on the outer side of a counter-clockwise face"
        );
        // A point beyond an edge projects onto the face boundary (clamped).
        let (_, _, w2) = project_on_face(&face, &pos, [-1.0, 0.5, 0.0]);
        assert!(w2[1].abs() < 1e-12 && w2[2].abs() < 1e-12);
    }

    /// Points (u, v) of a plane through (0.3, −1.2, 2.0) tilted against every axis.
    fn tilted(uv: &[[f64; 2]]) -> Vec<Vec3> {
        let e1 = Vec3::new(1.0, 2.0, -0.5).normalize();
        let e2 = e1.cross(&Vec3::new(0.3, -0.4, 1.0)).normalize();
        let o = Vec3::new(0.3, -1.2, 2.0);
        uv.iter().map(|&[u, v]| o + e1 * u + e2 * v).collect()
    }

    /// Area of the plane polygon `uv` (counter-clockwise), by the shoelace formula.
    fn shoelace(uv: &[[f64; 2]]) -> f64 {
        let n = uv.len();
        (0..n)
            .map(|i| {
                let (p, q) = (uv[i], uv[(i + 1) % n]);
                0.5 * (p[0] * q[1] - q[0] * p[1])
            })
            .sum()
    }

    #[test]
    fn hat_integrals_of_a_trapezoid_are_its_closed_form() {
        // Corners (0, 0), (2, 0), (1, 1), (0, 1): area 3/2, corner triangles 1, 1, 1/2, 1/2,
        // so ∫ φ_a dA = (A + T_a)/6 = 5/12, 5/12, 1/3, 1/3 (a quarter would be 3/8 each).
        let a = hat_integrals(&tilted(&[[0.0, 0.0], [2.0, 0.0], [1.0, 1.0], [0.0, 1.0]]));
        let exact = [5.0 / 12.0, 5.0 / 12.0, 1.0 / 3.0, 1.0 / 3.0];
        let off = (0..4).map(|k| (a[k] - exact[k]).abs()).fold(0.0, f64::max);
        eprintln!("trapezoid: {a:?}, largest error {off:.1e} m²");
        for (got, want) in a.iter().zip(exact) {
            assert!((got - want).abs() < 1e-15, "{a:?}");
        }
        // A convex quadrilateral with no parallel sides, against the closed form with its
        // triangle areas from the shoelace formula.
        let uv = [[0.1, -0.2], [2.1, 0.15], [1.3, 1.4], [-0.35, 0.7]];
        let a = hat_integrals(&tilted(&uv));
        let area = shoelace(&uv);
        for (k, got) in a.iter().enumerate() {
            let t = shoelace(&[uv[(k + 3) % 4], uv[k], uv[(k + 1) % 4]]);
            let want = (area + t) / 6.0;
            eprintln!(
                "corner {k}: {got:.15} against (A + T_a)/6 = {want:.15} ({:.1e} of A); \
                 a quarter would be off by {:+.2} %",
                (got - want).abs() / area,
                100.0 * (area / 4.0 - got) / got
            );
            assert!(
                (got - want).abs() < 1e-15 * area,
                "corner {k}: {got} against {want}"
            );
            // Not a quarter: these differ from A/4 by 4.8 and 7.1 % of A/4.
            assert!((got - area / 4.0).abs() > 0.04 * area / 4.0);
        }
        // And against an independent quadrature: the midpoint rule on 400 × 400 cells of
        // the natural square, with the norm of x_ξ × x_η as the area density (error
        // O(h²) ≈ 1e-6 of the area).
        let x = tilted(&uv);
        let m = 400;
        let h = 2.0 / m as f64;
        let mut fine = [0.0; 4];
        for i in 0..m {
            for j in 0..m {
                let (s, t) = (-1.0 + (i as f64 + 0.5) * h, -1.0 + (j as f64 + 0.5) * h);
                let x_s = ((x[1] - x[0]) * (1.0 - t) + (x[2] - x[3]) * (1.0 + t)) * 0.25;
                let x_t = ((x[3] - x[0]) * (1.0 - s) + (x[2] - x[1]) * (1.0 + s)) * 0.25;
                let da = x_s.cross(&x_t).norm() * h * h;
                let hat = [
                    (1.0 - s) * (1.0 - t),
                    (1.0 + s) * (1.0 - t),
                    (1.0 + s) * (1.0 + t),
                    (1.0 - s) * (1.0 + t),
                ];
                for k in 0..4 {
                    fine[k] += 0.25 * hat[k] * da;
                }
            }
        }
        let off = (0..4).map(|k| (a[k] - fine[k]).abs()).fold(0.0, f64::max);
        eprintln!(
            "midpoint rule 400 × 400: largest difference {:.1e} of A",
            off / area
        );
        for k in 0..4 {
            assert!(
                (a[k] - fine[k]).abs() < 1e-6 * area,
                "{a:?} against {fine:?}"
            );
        }
    }

    #[test]
    fn hat_integrals_add_up_to_the_area() {
        let uv = [[0.1, -0.2], [2.1, 0.15], [1.3, 1.4], [-0.35, 0.7]];
        let sum: f64 = hat_integrals(&tilted(&uv)).iter().sum();
        eprintln!(
            "planar: sum − area = {:.1e} of the area",
            (sum - shoelace(&uv)) / sum
        );
        assert!((sum - shoelace(&uv)).abs() < 1e-15 * sum);
        // A warped quadrilateral (corners not in one plane): its projection on the plane of
        // its diagonals, whose area is half the norm of their cross product.
        let x = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.2, 0.1, 0.3),
            Vec3::new(1.0, 1.1, -0.2),
            Vec3::new(-0.1, 0.8, 0.25),
        ];
        let a = hat_integrals(&x);
        let projected = 0.5 * (x[2] - x[0]).cross(&(x[3] - x[1])).norm();
        eprintln!(
            "warped: sum − projected area = {:.1e} m²",
            a.iter().sum::<f64>() - projected
        );
        assert!((a.iter().sum::<f64>() - projected).abs() < 1e-15);
        assert!(a.iter().all(|&v| v > 0.0));
        // A triangle: a third of its area to each corner, exactly.
        let t = [[0.2, 0.1], [1.9, -0.3], [0.7, 1.6]];
        let area = shoelace(&t);
        for v in hat_integrals(&tilted(&t)) {
            assert!((v - area / 3.0).abs() < 1e-15 * area);
        }
        // No area, no share.
        let flat = [0.0, 1.0, 2.0, 3.0].map(|u| Vec3::new(u, 2.0 * u, -u));
        assert_eq!(hat_integrals(&flat), vec![0.0; 4]);
    }

    #[test]
    fn hat_integrals_of_a_parallelogram_are_quarters() {
        let uv = [[0.0, 0.0], [2.0, 0.5], [2.7, 2.1], [0.7, 1.6]];
        let area = shoelace(&uv);
        let a = hat_integrals(&tilted(&uv));
        let off = a.iter().map(|v| (v - area / 4.0).abs()).fold(0.0, f64::max);
        eprintln!(
            "parallelogram: largest |∫ φ_a dA − A/4| = {:.1e} of A",
            off / area
        );
        for v in a {
            assert!(
                (v - area / 4.0).abs() < 4.0 * f64::EPSILON * area,
                "{v} against {}",
                area / 4.0
            );
        }
    }

    #[test]
    fn tributary_areas_of_quadratic_faces_are_their_pieces_hats() {
        // A flat 2 × 3 rectangle as a six-, eight- and nine-node face, its nodes where the
        // face types' natural coordinates put them.
        use crate::element::{QUAD8, QUAD8_NODE_XI, QUAD9, QUAD9_NODE_XI, TRI6};
        let on_square = |xi: &[[f64; 2]]| -> Vec<[f64; 3]> {
            let uv: Vec<[f64; 2]> = xi
                .iter()
                .map(|p| [1.0 + p[0], 1.5 * (1.0 + p[1])])
                .collect();
            tilted(&uv).iter().map(|x| [x[0], x[1], x[2]]).collect()
        };
        let check = |face: Face, coords: &[[f64; 3]], area: f64, expected: &[f64]| {
            let nodes: Vec<usize> = (0..expected.len()).collect();
            let a = tributary_areas(&[face], coords, &nodes);
            for (k, (got, want)) in a.iter().zip(expected).enumerate() {
                assert!(
                    (got - want * area).abs() < 1e-14,
                    "node {k}: {got} against {}",
                    want * area
                );
            }
        };
        let c8 = on_square(&QUAD8_NODE_XI);
        let (c, m) = (1.0 / 24.0, 5.0 / 24.0);
        check(
            Face::new(&QUAD8, &(0..8).collect::<Vec<_>>()),
            &c8,
            6.0,
            &[c, c, c, c, m, m, m, m],
        );
        let c9 = on_square(&QUAD9_NODE_XI);
        let (c, m, z) = (1.0 / 16.0, 1.0 / 8.0, 1.0 / 4.0);
        check(
            Face::new(&QUAD9, &(0..9).collect::<Vec<_>>()),
            &c9,
            6.0,
            &[c, c, c, c, m, m, m, m, z],
        );
        // The six-node triangle of corners (0, 0), (2, 0), (0, 3).
        let t6 = tilted(&[
            [0.0, 0.0],
            [2.0, 0.0],
            [0.0, 3.0],
            [1.0, 0.0],
            [1.0, 1.5],
            [0.0, 1.5],
        ]);
        let t6: Vec<[f64; 3]> = t6.iter().map(|x| [x[0], x[1], x[2]]).collect();
        let (c, m) = (1.0 / 12.0, 1.0 / 4.0);
        check(
            Face::new(&TRI6, &[0, 1, 2, 3, 4, 5]),
            &t6,
            3.0,
            &[c, c, c, m, m, m],
        );
        // A nine-node face with its nodes moved within its plane: its quarters are not
        // parallelograms, and each node collects (A + T_a)/6 of each quarter it is a corner of.
        let mut uv: Vec<[f64; 2]> = QUAD9_NODE_XI
            .iter()
            .map(|p| [1.0 + p[0], 1.5 * (1.0 + p[1])])
            .collect();
        let shifts = [
            [0.1, -0.2],
            [-0.15, 0.1],
            [0.2, 0.05],
            [-0.1, -0.2],
            [0.12, 0.2],
        ];
        for (k, d) in [4, 5, 6, 7, 8].into_iter().zip(shifts) {
            uv[k] = [uv[k][0] + d[0], uv[k][1] + d[1]];
        }
        let coords: Vec<[f64; 3]> = tilted(&uv).iter().map(|x| [x[0], x[1], x[2]]).collect();
        let a = tributary_areas(
            &[Face::new(&QUAD9, &(0..9).collect::<Vec<_>>())],
            &coords,
            &(0..9).collect::<Vec<_>>(),
        );
        let mut want = [0.0; 9];
        for piece in QUAD9.flat_pieces {
            let q: Vec<[f64; 2]> = piece.iter().map(|&k| uv[k]).collect();
            let area = shoelace(&q);
            for (k, &node) in piece.iter().enumerate() {
                want[node] += (area + shoelace(&[q[(k + 3) % 4], q[k], q[(k + 1) % 4]])) / 6.0;
            }
        }
        for k in 0..9 {
            assert!(
                (a[k] - want[k]).abs() < 1e-14,
                "node {k}: {} against {}",
                a[k],
                want[k]
            );
        }
        // They add up to the face's area, the octagon through its corners and mid-side nodes.
        let outline = [uv[0], uv[4], uv[1], uv[5], uv[2], uv[6], uv[3], uv[7]];
        assert!((a.iter().sum::<f64>() - shoelace(&outline)).abs() < 1e-14);
    }

    #[test]
    fn tributary_areas_add_up_to_the_face_area() {
        let coords = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 0.0, 3.0],
            [0.0, 0.0, 3.0],
            [4.0, 0.0, 0.0],
            [4.0, 0.0, 3.0],
        ];
        let faces = vec![Face::quad([0, 1, 2, 3]), Face::quad([1, 4, 5, 2])];
        let nodes = vec![0, 1, 2, 3, 4, 5];
        let a = tributary_areas(&faces, &coords, &nodes);
        assert!((a.iter().sum::<f64>() - 12.0).abs() < 1e-12);
        assert!((a[1] - 3.0).abs() < 1e-12 && (a[0] - 1.5).abs() < 1e-12);
    }
}
