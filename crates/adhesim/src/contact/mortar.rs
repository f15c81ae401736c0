//! Mortar (segment-to-segment) contact between two deformable bodies: the contact
//! conditions are integrated over the slave surface instead of being collocated at the slave
//! nodes (docs/contact-surfaces.md).
//!
//! At the start of a step each slave face is laid on its own plane with the master faces
//! that face it within the detection distance; the slave polygon is clipped by each master
//! polygon, and each overlap (a segment) is integrated by a rule exact to degree 5, which is
//! exact for the products of bilinear shape functions on parallelograms. Slave node j then
//! holds
//!
//! - C_j = ∫ φ_j dA over the covered part of its faces (the mortar measure),
//! - M_jl = ∫ ψ_j N_l dA for each master node l,
//! - D_jk = ∫ ψ_j N_k dA for each slave node k,
//!
//! with φ_j its weight on each flat piece of its faces (the face's own shape function on a
//! linear face) and ψ_j its multiplier function there: on a linear face covered by the master
//! surface the dual (biorthogonal) multiplier ψ_j = Σ_k a_jk φ_k with ∫ ψ_j φ_k = δ_jk ∫ φ_j
//! over the face ([`dual_coefficients`]), so that D_jk = δ_jk C_j; on a face the master covers
//! only in part, and on the flat pieces of quadratic faces, ψ_j = φ_j (standard multipliers).
//! Its contact site is the D_jk / C_j-weighted slave nodes (the node alone where its faces
//! are covered) against the M_jl / C_j-weighted master nodes: both sets of weights add up to
//! 1 (the master's may be negative), a uniform pressure p gives the nodal forces p ∫ N_k on
//! the slave side and p ∫ N_l on the master side (the consistent forces of that pressure,
//! which is what passes the contact patch test on non-matching meshes), and two surfaces that
//! stretch together have no relative slip (both weightings reproduce linear fields). The site
//! is keyed by its slave node j; its area is C_j in the reference configuration (the covered
//! measure scaled by each face's reference-to-current area ratio), so tractions stay nominal
//! as with node-to-surface.
//!
//! Dual multipliers keep a site's stencil to its node and the master nodes it overlaps (9 to
//! 16 on regular meshes) instead of the 9 slave nodes of its faces as well: the semismooth
//! solve's factorisations fill in less (docs/contact-surfaces.md, *Cost*).
//!
//! Self-contact is the same: the slave and master faces are of one body (one face set, or
//! two); a face sharing a node with a slave face (its neighbour on the surface) is left out
//! of its segments unless the surface folds back between them by more than 120° (the two
//! lips of a slit at its tip); on one face set the overlap of two faces facing each other is
//! integrated from one of them only.

use super::detect::Master;
use super::detect::{frame_from_normal, unit, ContactPair, ContactPoint, Discretisation, FaceGrid};
use super::polygon::{clip, counter_clockwise, polygon_quadrature, shape_at, Point2};
use crate::element::FaceType;
use crate::mesh::Face;
use crate::Vec3;
use std::collections::{BTreeMap, HashSet};

/// The mortar discretisation of a contact pair.
#[derive(Clone, Copy, Debug, Default)]
pub struct Mortar;

impl Discretisation for Mortar {
    fn sites(
        &self,
        pi: usize,
        pair: &ContactPair,
        reference: &[[f64; 3]],
        u0: &[f64],
        _t0: f64,
        _t1: f64,
    ) -> Vec<ContactPoint> {
        // The input refuses a mortar pair on a rigid master.
        let Master::Faces(faces) = &pair.master else {
            return Vec::new();
        };
        let pos =
            |n: usize| -> [f64; 3] { std::array::from_fn(|k| reference[n][k] + u0[3 * n + k]) };
        let grid = FaceGrid::new(faces, &pos, pair.detection_distance);
        let sides = Sides::new(pair, faces);
        let mut integrals = vec![NodeIntegrals::default(); pair.slave_nodes.len()];
        for face in &pair.slave_faces {
            for &piece in face.flat_pieces() {
                let slave = SlavePiece::new(pair, face, piece, &pos, &|n| reference[n]);
                let master = MasterSurface {
                    faces,
                    grid: &grid,
                    sides: &sides,
                    pos: &pos,
                    detection: pair.detection_distance,
                };
                slave.integrate(&master, &mut integrals);
            }
        }
        let normals = slave_normals(pair, &pos);
        let node_site =
            |li: usize| normals[li].and_then(|n| integrals[li].site(pi, pair, li, n, &pos));
        let mut out = Vec::new();
        for li in 0..pair.slave_nodes.len() {
            let twins = pair.thickness_twins.get(li).map_or(&[][..], |t| &t[..]);
            if twins.is_empty() {
                out.extend(node_site(li));
                continue;
            }
            // The line's first node stands for it.
            if twins.iter().any(|&j| j < li) {
                continue;
            }
            let line: Vec<usize> = std::iter::once(li).chain(twins.iter().copied()).collect();
            let found: Vec<Option<ContactPoint>> = line.iter().map(|&l| node_site(l)).collect();
            if found.iter().all(Option::is_some) {
                out.push(merge_line(pair, found.into_iter().flatten().collect()));
            } else {
                out.extend(found.into_iter().flatten());
            }
        }
        out
    }
}

/// Which faces are on both sides of the pair: in self-contact on one face set, each face is
/// a slave face and a master face, so that two faces facing each other would be integrated
/// twice, once from each; only one of the two passes is kept (one pass, as between two
/// bodies: redundant conditions would leave the contact solve without a unique answer).
struct Sides {
    /// The slave faces, by their sorted global nodes.
    slave: HashSet<Vec<usize>>,
    /// The master faces, by their sorted global nodes.
    master: HashSet<Vec<usize>>,
}

impl Sides {
    fn new(pair: &ContactPair, master: &[Face]) -> Self {
        let slave = pair
            .slave_faces
            .iter()
            .map(|f| key(f.nodes().iter().map(|&l| pair.slave_nodes[l])))
            .collect();
        let master = master
            .iter()
            .map(|f| key(f.nodes().iter().copied()))
            .collect();
        Sides { slave, master }
    }

    /// Whether the overlap of slave face `slave` with master face `master` (both by their
    /// sorted nodes) is integrated from this side: always, unless each is on both sides of
    /// the pair, in which case from the face whose sorted nodes come first.
    fn integrates(&self, slave: &[usize], master: &[usize]) -> bool {
        !(self.master.contains(slave) && self.slave.contains(master)) || slave < master
    }
}

/// A face's nodes sorted, without repeats (a triangle's repeated last node once).
fn key(nodes: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut k: Vec<usize> = nodes.collect();
    k.sort_unstable();
    k.dedup();
    k
}

/// What the segments give one slave node.
#[derive(Clone, Debug, Default)]
struct NodeIntegrals {
    /// ∫ N_j dA over the covered part of the node's faces, current configuration [m²].
    covered: f64,
    /// ∫ N_j dA over the whole of the node's faces, current configuration [m²].
    full: f64,
    /// The covered measure in the reference configuration [m²].
    nominal: f64,
    /// ∫ N_j N_l dA for each master node l [m²].
    master: BTreeMap<usize, f64>,
    /// ∫ N_j N_k dA over the covered part for each slave node k (global) [m²].
    slave: BTreeMap<usize, f64>,
}

impl NodeIntegrals {
    /// The node's contact site, if it is covered by the master surface and within the
    /// detection distance of it.
    fn site(
        &self,
        pi: usize,
        pair: &ContactPair,
        local: usize,
        slave_normal: [f64; 3],
        pos: &dyn Fn(usize) -> [f64; 3],
    ) -> Option<ContactPoint> {
        if !(self.covered > 1e-9 * self.full) {
            return None;
        }
        let weights = |m: &BTreeMap<usize, f64>| -> Vec<(usize, f64)> {
            m.iter().map(|(&n, &v)| (n, v / self.covered)).collect()
        };
        let (master, slave_weights) = (weights(&self.master), weights(&self.slave));
        let mean = |w: &[(usize, f64)]| -> [f64; 3] {
            let mut x = [0.0; 3];
            for &(n, wn) in w {
                let p = pos(n);
                (0..3).for_each(|k| x[k] += wn * p[k]);
            }
            x
        };
        let (xs, xm) = (mean(&slave_weights), mean(&master));
        let slave = pair.slave_nodes[local];
        let d0: [f64; 3] = (Vec3::from(xs) - Vec3::from(xm)).into();
        // N points from the master to the slave: against the slave's outward normal.
        let normal = [-slave_normal[0], -slave_normal[1], -slave_normal[2]];
        let gap = Vec3::from(d0).dot(&Vec3::from(normal));
        if gap.abs() > pair.detection_distance {
            return None;
        }
        Some(ContactPoint {
            pair: pi,
            local,
            slave,
            area: self.nominal,
            frame: frame_from_normal(normal),
            master,
            master_point_end: xm,
            d0,
            twins: Vec::new(),
            slave_weights,
        })
    }
}

/// A flat piece of a slave face ([`Face::flat_pieces`]: the face itself when it is linear)
/// laid on its plane. The contact pressure is interpolated on it linearly (bilinearly on a
/// quadrilateral) from the piece's corners, each corner standing for its node: with linear
/// faces that is the face's own shape functions (standard mortar); on a six-node triangle,
/// the hat functions of its four sub-triangles, which are positive with positive integrals
/// where the quadratic corner functions integrate to zero.
struct SlavePiece {
    /// Indices in the pair of the face's nodes.
    locals: Vec<usize>,
    /// Global indices of the face's nodes.
    nodes: Vec<usize>,
    /// The piece's corners, as positions in `nodes`.
    piece: &'static [usize],
    /// The face's type: how the piece's weights give the face's shape functions
    /// ([`FaceType::shape_on_piece`]).
    face_type: &'static FaceType,
    /// Centre [m] and unit outward normal of its plane, with two in-plane axes.
    centre: Vec3,
    normal: Vec3,
    axes: [Vec3; 2],
    /// Its corners on the plane, in the piece's order.
    corners: Vec<Point2>,
    /// Reference area over current area.
    area_ratio: f64,
}

/// The master surface a slave piece is integrated against: its `faces`, the grid that finds
/// those near a point, which pairs of faces are integrated (`sides`), the current nodal
/// positions `pos` [m] and the detection distance [m].
#[derive(Clone, Copy)]
struct MasterSurface<'a> {
    faces: &'a [Face],
    grid: &'a FaceGrid,
    sides: &'a Sides,
    pos: &'a dyn Fn(usize) -> [f64; 3],
    detection: f64,
}

impl SlavePiece {
    /// The piece `piece` of the slave face `face` (indices into the pair's slave nodes) at
    /// the positions `pos`, with reference positions `reference`.
    fn new(
        pair: &ContactPair,
        face: &Face,
        piece: &'static [usize],
        pos: &dyn Fn(usize) -> [f64; 3],
        reference: &dyn Fn(usize) -> [f64; 3],
    ) -> Self {
        let locals = face.nodes().to_vec();
        let nodes: Vec<usize> = locals.iter().map(|&l| pair.slave_nodes[l]).collect();
        let at = |f: &dyn Fn(usize) -> [f64; 3]| -> Vec<Vec3> {
            piece.iter().map(|&c| Vec3::from(f(nodes[c]))).collect()
        };
        let (x, x_ref) = (at(pos), at(reference));
        let (a, a_ref) = (twice_area_vector(&x), twice_area_vector(&x_ref));
        let normal = unit(a);
        let centre = x.iter().fold(Vec3::zeros(), |s, p| s + p) / x.len() as f64;
        let frame = frame_from_normal(normal.into());
        let axes = [Vec3::from(frame[0]), Vec3::from(frame[1])];
        let corners = x
            .iter()
            .map(|p| [(p - centre).dot(&axes[0]), (p - centre).dot(&axes[1])])
            .collect();
        SlavePiece {
            face_type: face.face_type(),
            locals,
            nodes,
            piece,
            centre,
            normal,
            axes,
            corners,
            area_ratio: a_ref.norm() / a.norm(),
        }
    }

    /// A point of space on the piece's plane.
    fn project(&self, x: [f64; 3]) -> Point2 {
        let d = Vec3::from(x) - self.centre;
        [d.dot(&self.axes[0]), d.dot(&self.axes[1])]
    }

    /// Adds this piece's segments with the `master` faces near it to the slave nodes'
    /// integrals: with the dual multipliers of the piece ([`dual_coefficients`]) when the
    /// piece is a whole linear face covered by the master surface, with the piece's own
    /// weights (standard multipliers) otherwise.
    fn integrate(&self, master: &MasterSurface<'_>, integrals: &mut [NodeIntegrals]) {
        let slave_polygon = counter_clockwise(self.corners.clone());
        let mut area = 0.0;
        for (p, w) in polygon_quadrature(&slave_polygon) {
            let phi = shape_at(&self.corners, p);
            for (c, &at) in self.piece.iter().enumerate() {
                integrals[self.locals[at]].full += w * phi[c];
            }
            area += w;
        }
        let points = self.segment_points(master, &slave_polygon);
        let covered: f64 = points.iter().map(|q| q.w).sum();
        let dual = (self.face_type.piece_is_face(self.piece)
            && covered >= (1.0 - FULLY_COVERED) * area)
            .then(|| dual_coefficients(&points))
            .flatten();
        for q in &points {
            self.add_point(q, master.faces[q.face].nodes(), dual.as_deref(), integrals);
        }
    }

    /// The quadrature points of this piece's segments with the master `faces` near it.
    fn segment_points(
        &self,
        master: &MasterSurface<'_>,
        slave_polygon: &[Point2],
    ) -> Vec<SegmentPoint> {
        let MasterSurface {
            faces,
            grid,
            sides,
            pos,
            detection,
        } = *master;
        let own = key(self.nodes.iter().copied());
        let (lo, hi) = self.bounding_box(pos);
        let mut points = Vec::new();
        for fi in grid.candidates_in_box(lo, hi) {
            if !sides.integrates(&own, &key(faces[fi].nodes().iter().copied())) {
                continue;
            }
            for piece in faces[fi].flat_pieces() {
                let Some(master) = self.facing(&faces[fi], piece, pos, detection) else {
                    continue;
                };
                let master_type = faces[fi].face_type();
                let segment = clip(slave_polygon, &counter_clockwise(master.clone()));
                if segment.is_empty() {
                    continue;
                }
                for (p, w) in polygon_quadrature(&segment) {
                    points.push(SegmentPoint {
                        w,
                        phi: shape_at(&self.corners, p),
                        face: fi,
                        master: master_type.shape_on_piece(piece, shape_at(&master, p)),
                    });
                }
            }
        }
        points
    }

    /// Adds the quadrature point `q` of a segment with a master face of nodes `master_nodes`
    /// to the integrals of this piece's nodes: C_j, its reference measure, M_jl = ∫ ψ_j N_l
    /// and D_jk = ∫ ψ_j N_k, with ψ_j the dual multiplier of coefficients `dual` (then
    /// D_jk = δ_jk C_j), or the piece's own weight of the node when `dual` is `None`.
    fn add_point(
        &self,
        q: &SegmentPoint,
        master_nodes: &[usize],
        dual: Option<&[Vec<f64>]>,
        integrals: &mut [NodeIntegrals],
    ) {
        let ns = match dual {
            Some(_) => Vec::new(),
            None => self.face_type.shape_on_piece(self.piece, q.phi.clone()),
        };
        for (c, &at) in self.piece.iter().enumerate() {
            let node = &mut integrals[self.locals[at]];
            let wc = q.w * q.phi[c];
            node.covered += wc;
            node.nominal += wc * self.area_ratio;
            match dual {
                Some(a) => {
                    let psi: f64 = a[c].iter().zip(&q.phi).map(|(a, p)| a * p).sum();
                    for (k, &m) in master_nodes.iter().enumerate() {
                        *node.master.entry(m).or_insert(0.0) += q.w * psi * q.master[k];
                    }
                    *node.slave.entry(self.nodes[at]).or_insert(0.0) += wc;
                }
                None => {
                    for (k, &m) in master_nodes.iter().enumerate() {
                        *node.master.entry(m).or_insert(0.0) += wc * q.master[k];
                    }
                    for (k, &n) in self.nodes.iter().enumerate() {
                        *node.slave.entry(n).or_insert(0.0) += wc * ns[k];
                    }
                }
            }
        }
    }

    /// The corners of the piece `piece` of master face `face` on this piece's plane, if it
    /// faces this piece (its normal against this one's) within `detection` [m] of its plane.
    /// A face sharing a node with this one (its neighbour on a self-contact surface) must
    /// face it across a fold sharper than 120°.
    fn facing(
        &self,
        face: &Face,
        piece: &[usize],
        pos: &dyn Fn(usize) -> [f64; 3],
        detection: f64,
    ) -> Option<Vec<Point2>> {
        let all = face.nodes();
        let ns: Vec<usize> = piece.iter().map(|&c| all[c]).collect();
        let x: Vec<Vec3> = ns.iter().map(|&n| Vec3::from(pos(n))).collect();
        let a = twice_area_vector(&x);
        let facing = a.dot(&self.normal) / a.norm();
        // A neighbour on the surface (a shared node) faces this face only across a fold
        // sharper than 120°, as the two lips of a slit do at its tip.
        let neighbour = all.iter().any(|n| self.nodes.contains(n));
        if !(facing < if neighbour { -0.5 } else { 0.0 }) {
            return None;
        }
        let height: Vec<f64> = x
            .iter()
            .map(|p| (p - self.centre).dot(&self.normal))
            .collect();
        let lowest = height.iter().copied().fold(f64::INFINITY, f64::min);
        let highest = height.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lowest > detection || highest < -detection {
            return None;
        }
        Some(ns.iter().map(|&n| self.project(pos(n))).collect())
    }

    /// The bounding box of the piece's corners [m].
    fn bounding_box(&self, pos: &dyn Fn(usize) -> [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &c in self.piece {
            let p = pos(self.nodes[c]);
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}

/// A slave piece whose covered measure is at least (1 − this) of its area counts as covered
/// by the master surface (round-off of the clipping aside) and takes dual multipliers.
const FULLY_COVERED: f64 = 1e-9;

/// A quadrature point of a segment (the overlap of a slave piece and a master piece).
struct SegmentPoint {
    /// Weight [m²].
    w: f64,
    /// The slave piece's own (linear or bilinear) weights at the point, one per corner.
    phi: Vec<f64>,
    /// The master face, by its index in the pair's master faces.
    face: usize,
    /// The master face's shape functions at the point, one per node.
    master: Vec<f64>,
}

/// The coefficients a_jk of the dual multipliers ψ_j = Σ_k a_jk φ_k of a slave piece with
/// weights φ over the quadrature points `points` (Popp, Gitterle, Gee and Wall 2010):
/// biorthogonal to the φ, ∫ ψ_j φ_k dA = δ_jk ∫ φ_j dA, so A = D M⁻¹ with
/// M_jk = ∫ φ_j φ_k dA and D = diag(∫ φ_j dA), both over the points. `None` when M is
/// singular. A site's slave side is then its node alone, and its master weights
/// ∫ ψ_j N_l / ∫ φ_j still add up to 1 but may be negative.
fn dual_coefficients(points: &[SegmentPoint]) -> Option<Vec<Vec<f64>>> {
    let n = points.first()?.phi.len();
    let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
    let mut d = vec![0.0; n];
    for q in points {
        for j in 0..n {
            d[j] += q.w * q.phi[j];
            for k in 0..n {
                m[(j, k)] += q.w * q.phi[j] * q.phi[k];
            }
        }
    }
    let inv = m.try_inverse()?;
    Some(
        (0..n)
            .map(|j| (0..n).map(|k| d[j] * inv[(j, k)]).collect())
            .collect(),
    )
}

/// Twice the area vector of a face with corners `x` (three or four): the cross product of
/// a triangle's edges or of a quadrilateral's diagonals [m²].
fn twice_area_vector(x: &[Vec3]) -> Vec3 {
    match x.len() {
        3 => (x[1] - x[0]).cross(&(x[2] - x[0])),
        _ => (x[2] - x[0]).cross(&(x[3] - x[1])),
    }
}

/// The unit outward normal of the slave surface at each slave node: the mean of its faces'
/// area vectors; `None` where the surface folds back on itself at the node (the mean is less
/// than half the faces' areas, as at the tip of a slit whose two lips are one face set),
/// which then has no site of its own.
fn slave_normals(pair: &ContactPair, pos: &dyn Fn(usize) -> [f64; 3]) -> Vec<Option<[f64; 3]>> {
    let mut sum = vec![(Vec3::zeros(), 0.0); pair.slave_nodes.len()];
    for q in &pair.slave_quads {
        let corners = if q[2] == q[3] { &q[..3] } else { &q[..] };
        let x: Vec<Vec3> = corners
            .iter()
            .map(|&l| Vec3::from(pos(pair.slave_nodes[l])))
            .collect();
        let a = twice_area_vector(&x);
        let mut seen: Vec<usize> = Vec::with_capacity(4);
        for &l in q {
            if !seen.contains(&l) {
                seen.push(l);
                sum[l].0 += a;
                sum[l].1 += a.norm();
            }
        }
    }
    sum.into_iter()
        .map(|(s, total)| (s.norm() >= 0.5 * total).then(|| unit(s).into()))
        .collect()
}

/// One site for the sites of the nodes of a line through a plane-strain slab: positions and
/// master weights shared equally, the mean normal kept in the x-y plane, the areas together
/// (as node-to-surface does, see [`ContactPoint::twins`]).
fn merge_line(pair: &ContactPair, sites: Vec<ContactPoint>) -> ContactPoint {
    let share = 1.0 / sites.len() as f64;
    let mean = |f: &dyn Fn(&ContactPoint) -> [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| sites.iter().map(|p| share * f(p)[k]).sum())
    };
    let normal = Vec3::from(mean(&|p| p.frame[2]));
    let in_plane = Vec3::new(normal[0], normal[1], 0.0);
    let normal = if in_plane.norm() > 0.0 {
        unit(in_plane)
    } else {
        unit(normal)
    };
    let merged = |of: &dyn Fn(&ContactPoint) -> &[(usize, f64)]| -> Vec<(usize, f64)> {
        let mut sum: BTreeMap<usize, f64> = BTreeMap::new();
        for (n, w) in sites.iter().flat_map(|p| of(p).iter().copied()) {
            *sum.entry(n).or_insert(0.0) += share * w;
        }
        sum.into_iter().collect()
    };
    let first = &sites[0];
    ContactPoint {
        pair: first.pair,
        local: first.local,
        slave: first.slave,
        area: sites.iter().map(|p| p.area).sum(),
        frame: frame_from_normal(normal.into()),
        master: merged(&|p| &p.master),
        master_point_end: mean(&|p| p.master_point_end),
        d0: mean(&|p| p.d0),
        twins: sites[1..]
            .iter()
            .map(|p| (pair.slave_nodes[p.local], p.local))
            .collect(),
        slave_weights: merged(&|p| &p.slave_weights),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::InterfaceLaw;

    /// A flat slave grid of nx × ny unit-less squares over [0, 1]² at height z (normal +z
    /// or −z) and the pair against a master grid of mx × my faces at z = 0 (normal +z).
    fn flat_pair(n: [usize; 2], m: [usize; 2], gap: f64) -> (ContactPair, Vec<[f64; 3]>) {
        let mut coords = Vec::new();
        let grid = |nx: usize, ny: usize, z: f64, coords: &mut Vec<[f64; 3]>| {
            let base = coords.len();
            for j in 0..=ny {
                for i in 0..=nx {
                    coords.push([i as f64 / nx as f64, j as f64 / ny as f64, z]);
                }
            }
            let id = move |i: usize, j: usize| base + j * (nx + 1) + i;
            (base, id)
        };
        let (mbase, mid) = grid(m[0], m[1], 0.0, &mut coords);
        let master: Vec<Face> = (0..m[1])
            .flat_map(|j| (0..m[0]).map(move |i| (i, j)))
            .map(|(i, j)| Face::quad([mid(i, j), mid(i + 1, j), mid(i + 1, j + 1), mid(i, j + 1)]))
            .collect();
        let _ = mbase;
        let (sbase, sid) = grid(n[0], n[1], gap, &mut coords);
        let slave_nodes: Vec<usize> = (sbase..coords.len()).collect();
        // Slave faces turn clockwise seen from +z: their outward normal is −z.
        let slave_quads: Vec<[usize; 4]> = (0..n[1])
            .flat_map(|j| (0..n[0]).map(move |i| (i, j)))
            .map(|(i, j)| {
                [sid(i, j), sid(i, j + 1), sid(i + 1, j + 1), sid(i + 1, j)].map(|g| g - sbase)
            })
            .collect();
        let pair = ContactPair {
            name: "p".into(),
            slave_area: vec![0.0; slave_nodes.len()],
            slave_nodes,
            master: Master::Faces(master),
            law: InterfaceLaw::rcc(0.0, None, None),
            detection_distance: 0.1,
            slave_faces: slave_quads.iter().map(|&q| Face::quad(q)).collect(),
            slave_quads,
            thickness_twins: Vec::new(),
            discretisation: Default::default(),
        };
        (pair, coords)
    }

    #[test]
    fn non_matching_flat_faces_give_consistent_measures_and_weights() {
        for (n, m) in [([4, 4], [13, 13]), ([7, 5], [3, 4]), ([2, 3], [2, 3])] {
            let (pair, coords) = flat_pair(n, m, 0.01);
            let u0 = vec![0.0; 3 * coords.len()];
            let sites = Mortar.sites(0, &pair, &coords, &u0, 0.0, 1.0);
            assert_eq!(sites.len(), pair.slave_nodes.len());
            // The measures add up to the slave surface's area, each being ∫ N_j (the
            // corner, edge and interior shares of a uniform grid).
            let total: f64 = sites.iter().map(|s| s.area).sum();
            assert!((total - 1.0).abs() < 1e-13, "{total}");
            let cell = 1.0 / (n[0] * n[1]) as f64;
            for s in &sites {
                let [x, y, _] = coords[s.slave];
                let on_edge = |v: f64| v.abs() < 1e-12 || (v - 1.0).abs() < 1e-12;
                let faces = [on_edge(x), on_edge(y)].iter().filter(|&&e| !e).count();
                let expected = cell * [0.25, 0.5, 1.0][faces];
                assert!(
                    (s.area - expected).abs() < 1e-14,
                    "{} vs {expected}",
                    s.area
                );
                // The slave surface is covered: dual multipliers, the slave side is the
                // node alone. The master weights are a partition of unity (some negative)
                // that reproduces linear fields, so the master point is the slave node's
                // own projection on the flat master: the normal gap is exact and there is no
                // tangential offset.
                assert_eq!(s.slave_weights, vec![(s.slave, 1.0)]);
                assert!((s.master.iter().map(|m| m.1).sum::<f64>() - 1.0).abs() < 1e-13);
                assert!(s.master_point_end[2].abs() < 1e-15);
                assert!(s.d0[0].abs() < 1e-13 && s.d0[1].abs() < 1e-13, "{:?}", s.d0);
                assert!((s.d0[2] - 0.01).abs() < 1e-15 && s.frame[2][2] > 0.999_999);
            }
            // Each master node's share of a uniform pressure, Σ_j C_j w_jl, is ∫ N_l over
            // the master surface.
            let mut share = BTreeMap::new();
            for s in &sites {
                for &(l, w) in &s.master {
                    *share.entry(l).or_insert(0.0) += s.area * w;
                }
            }
            let mcell = 1.0 / (m[0] * m[1]) as f64;
            for (&l, &a) in &share {
                let [x, y, _] = coords[l];
                let on_edge = |v: f64| v.abs() < 1e-12 || (v - 1.0).abs() < 1e-12;
                let faces = [on_edge(x), on_edge(y)].iter().filter(|&&e| !e).count();
                let expected = mcell * [0.25, 0.5, 1.0][faces];
                assert!(
                    (a - expected).abs() < 1e-13,
                    "master {l}: {a} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn dual_multipliers_are_biorthogonal_to_the_piece_weights() {
        // A distorted quadrilateral and a triangle, integrated over themselves.
        let quad = vec![[0.0, 0.0], [1.2, 0.1], [1.0, 0.9], [-0.1, 1.1]];
        let tri = vec![[0.0, 0.0], [1.0, 0.2], [0.3, 0.8]];
        for corners in [quad, tri] {
            let points: Vec<SegmentPoint> = polygon_quadrature(&corners)
                .into_iter()
                .map(|(p, w)| SegmentPoint {
                    w,
                    phi: shape_at(&corners, p),
                    face: 0,
                    master: Vec::new(),
                })
                .collect();
            let a = dual_coefficients(&points).unwrap();
            let n = corners.len();
            for j in 0..n {
                let integral = |f: &dyn Fn(&SegmentPoint) -> f64| -> f64 {
                    points.iter().map(|q| q.w * f(q)).sum()
                };
                let psi = |q: &SegmentPoint| -> f64 { (0..n).map(|k| a[j][k] * q.phi[k]).sum() };
                let measure = integral(&|q| q.phi[j]);
                for k in 0..n {
                    let product = integral(&|q| psi(q) * q.phi[k]);
                    let expected = if j == k { measure } else { 0.0 };
                    assert!((product - expected).abs() < 1e-14, "{j} {k}: {product}");
                }
                // ∫ ψ_j = ∫ φ_j: the site's measure is unchanged.
                assert!((integral(&psi) - measure).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn a_slave_face_partly_covered_keeps_the_standard_multipliers() {
        // The master covers [0, 1]²; the slave grid is shifted by half a face along x.
        let (pair, mut coords) = flat_pair([4, 4], [3, 3], 0.01);
        for c in coords.iter_mut().filter(|c| c[2] > 0.0) {
            c[0] += 0.125;
        }
        let u0 = vec![0.0; 3 * coords.len()];
        let sites = Mortar.sites(0, &pair, &coords, &u0, 0.0, 1.0);
        for s in &sites {
            let x = coords[s.slave][0];
            let positive = s.master.iter().all(|&(_, w)| w > 0.0);
            let sum = |w: &[(usize, f64)]| w.iter().map(|m| m.1).sum::<f64>();
            assert!(
                (sum(&s.master) - 1.0).abs() < 1e-13 && (sum(&s.slave_weights) - 1.0).abs() < 1e-13
            );
            if x > 1.0 {
                // Its faces reach beyond the master: standard weights, all positive.
                assert!(positive && s.slave_weights.len() > 1, "{x}: {s:?}");
            } else if x < 0.8 {
                // Its faces are covered: dual multipliers (the node at x = 0.875 has one
                // face of each kind).
                assert_eq!(s.slave_weights, vec![(s.slave, 1.0)]);
            }
        }
    }

    #[test]
    fn a_slave_beyond_the_detection_distance_has_no_site() {
        let (pair, coords) = flat_pair([3, 3], [4, 4], 0.2);
        let u0 = vec![0.0; 3 * coords.len()];
        assert!(Mortar.sites(0, &pair, &coords, &u0, 0.0, 1.0).is_empty());
    }
}
