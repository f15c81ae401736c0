//! Node-to-surface contact, single pass: each slave node of a pair is projected on the master
//! surface (a rigid analytic shape, or the closest face of a deformable body) at the start of
//! a step, and a candidate within the detection distance is one contact site with the node's
//! tributary area. On a plane-strain slave surface the nodes of one line through the slab's
//! thickness make one site when all of them are candidates ([`ContactPoint::twins`]).

use super::detect::{
    frame_from_normal, project_on_face, rigid_projection, unit, ContactPair, ContactPoint,
    Discretisation, FaceGrid, Master,
};
use crate::Vec3;

/// The node-to-surface discretisation of a contact pair.
#[derive(Clone, Copy, Debug, Default)]
pub struct NodeToSurface;

impl Discretisation for NodeToSurface {
    fn sites(
        &self,
        pi: usize,
        pair: &ContactPair,
        reference: &[[f64; 3]],
        u0: &[f64],
        t0: f64,
        t1: f64,
    ) -> Vec<ContactPoint> {
        let pos =
            |n: usize| -> [f64; 3] { std::array::from_fn(|k| reference[n][k] + u0[3 * n + k]) };
        let mut out = Vec::new();
        let grid = match &pair.master {
            Master::Faces(faces) => Some(FaceGrid::new(faces, &pos, pair.detection_distance)),
            Master::Rigid { .. } => None,
        };
        let project = |li: usize| project_slave(pair, grid.as_ref(), &pos, li, t0, t1);
        for li in 0..pair.slave_nodes.len() {
            let twins = pair.thickness_twins.get(li).map_or(&[][..], |t| &t[..]);
            if twins.is_empty() {
                out.extend(project(li).map(|p| p.point(pi, pair, li)));
                continue;
            }
            // The line's first node stands for it.
            if twins.iter().any(|&j| j < li) {
                continue;
            }
            let line: Vec<usize> = std::iter::once(li).chain(twins.iter().copied()).collect();
            let found: Vec<Option<Projection>> = line.iter().map(|&l| project(l)).collect();
            if found.iter().all(Option::is_some) {
                let found: Vec<Projection> = found.into_iter().flatten().collect();
                out.push(line_point(pi, pair, &line, &found));
            } else {
                for (&l, p) in line.iter().zip(found) {
                    out.extend(p.map(|p| p.point(pi, pair, l)));
                }
            }
        }
        out
    }
}

/// A slave node's closest point on the master surface at the start of a step.
struct Projection {
    /// Unit normal of the master surface there (towards the slave side).
    normal: [f64; 3],
    /// Master nodes and weights (empty for a rigid master).
    master: Vec<(usize, f64)>,
    /// Slave node position at the start of the step [m].
    slave: [f64; 3],
    /// Master point at the start of the step [m].
    start: [f64; 3],
    /// Master point at the end of the step (rigid) or at its start (deformable) [m].
    end: [f64; 3],
}

impl Projection {
    /// The contact point of this node alone.
    fn point(self, pair_index: usize, pair: &ContactPair, local: usize) -> ContactPoint {
        ContactPoint {
            pair: pair_index,
            local,
            slave: pair.slave_nodes[local],
            area: pair.slave_area[local],
            frame: frame_from_normal(self.normal),
            master: self.master,
            master_point_end: self.end,
            d0: (Vec3::from(self.slave) - Vec3::from(self.start)).into(),
            twins: Vec::new(),
            slave_weights: Vec::new(),
        }
    }
}

/// The projection of slave node `local` of `pair`, if it is a candidate: within the detection
/// distance of the master surface and not too far behind it.
fn project_slave(
    pair: &ContactPair,
    grid: Option<&FaceGrid>,
    pos: &dyn Fn(usize) -> [f64; 3],
    local: usize,
    t0: f64,
    t1: f64,
) -> Option<Projection> {
    let s = pair.slave_nodes[local];
    let xs = pos(s);
    match &pair.master {
        Master::Rigid { shape, motion } => {
            // Work in the surface's reference frame.
            let xr = motion.inverse(xs, t0);
            let (proj, normal, gap) = rigid_projection(shape, xr);
            if gap > pair.detection_distance {
                return None;
            }
            Some(Projection {
                normal: motion.rotate_dir(normal, t0),
                master: Vec::new(),
                slave: xs,
                start: motion.apply(proj, t0),
                end: motion.apply(proj, t1),
            })
        }
        Master::Faces(faces) => {
            let grid = grid.expect("a face grid for a master made of faces");
            let mut best: Option<(f64, [f64; 3], Vec<(usize, f64)>, [f64; 3])> = None;
            for &fi in grid.candidates(xs) {
                let face = &faces[fi];
                if face.nodes().contains(&s) {
                    continue;
                }
                let (xm, normal, weights) = project_on_face(face, pos, xs);
                let d = Vec3::from(xs) - Vec3::from(xm);
                let dist = d.norm();
                let gap = d.dot(&Vec3::from(normal));
                // Accept points on the outer side (or slightly penetrated) whose projection
                // is close to the face.
                if dist > pair.detection_distance || gap < -pair.detection_distance {
                    continue;
                }
                if best.as_ref().map_or(true, |b| dist < b.0) {
                    let nodes: Vec<(usize, f64)> =
                        face.nodes().iter().copied().zip(weights).collect();
                    best = Some((dist, normal, nodes, xm));
                }
            }
            best.map(|(_, normal, master, xm)| Projection {
                normal,
                master,
                slave: xs,
                start: xm,
                end: xm,
            })
        }
    }
}

/// One contact point for the nodes `line` (indices in `pair`) through a plane-strain slab,
/// from their projections: mean positions, master weights shared equally, the normal of the
/// mean projection kept in the x-y plane, the nodes' areas together.
fn line_point(
    pair_index: usize,
    pair: &ContactPair,
    line: &[usize],
    found: &[Projection],
) -> ContactPoint {
    let share = 1.0 / line.len() as f64;
    let mean = |f: &dyn Fn(&Projection) -> [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| found.iter().map(|p| share * f(p)[k]).sum())
    };
    let normal = Vec3::from(mean(&|p| p.normal));
    let in_plane = Vec3::new(normal[0], normal[1], 0.0);
    let normal = if in_plane.norm() > 0.0 {
        unit(in_plane)
    } else {
        unit(normal)
    };
    let mut master: Vec<(usize, f64)> = Vec::new();
    for (m, w) in found.iter().flat_map(|p| p.master.iter().copied()) {
        match master.iter_mut().find(|e| e.0 == m) {
            Some(e) => e.1 += share * w,
            None => master.push((m, share * w)),
        }
    }
    ContactPoint {
        pair: pair_index,
        local: line[0],
        slave: pair.slave_nodes[line[0]],
        area: line.iter().map(|&l| pair.slave_area[l]).sum(),
        frame: frame_from_normal(normal.into()),
        master,
        master_point_end: mean(&|p| p.end),
        d0: (Vec3::from(mean(&|p| p.slave)) - Vec3::from(mean(&|p| p.start))).into(),
        twins: line[1..]
            .iter()
            .map(|&l| (pair.slave_nodes[l], l))
            .collect(),
        slave_weights: Vec::new(),
    }
}
