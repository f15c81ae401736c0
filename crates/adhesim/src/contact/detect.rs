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

/// Tributary areas of the nodes of a face set: the area of each flat piece of each face
/// ([`Face::flat_pieces`], the face itself when it is linear) split equally among the
/// piece's corners [m²], in the order of `nodes`. On a six-node triangle that gives a corner
/// 1/12 of the face and a mid-side node 1/4 (the integrals of the sub-triangles' hat
/// functions): positive, where the quadratic corner functions integrate to zero.
pub fn tributary_areas(faces: &[Face], coords: &[[f64; 3]], nodes: &[usize]) -> Vec<f64> {
    let index: HashMap<usize, usize> = nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
    let mut area = vec![0.0; nodes.len()];
    for f in faces {
        let all = f.nodes();
        for piece in f.flat_pieces() {
            let ns: Vec<usize> = piece.iter().map(|&c| all[c]).collect();
            let a = face_area(&ns, coords);
            for n in &ns {
                if let Some(&i) = index.get(n) {
                    area[i] += a / ns.len() as f64;
                }
            }
        }
    }
    area
}

fn face_area(ns: &[usize], x: &[[f64; 3]]) -> f64 {
    let c = |i: usize| Vec3::from(x[ns[i]]);
    match ns.len() {
        3 => 0.5 * (c(1) - c(0)).cross(&(c(2) - c(0))).norm(),
        _ => 0.5 * (c(2) - c(0)).cross(&(c(3) - c(1))).norm(),
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
