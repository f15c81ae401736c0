//! Physical plausibility warnings: settings that are valid but are likely to give a poor or
//! slow solution. They never stop a run; `adhesim run` and `adhesim check` print them once.
//!
//! - the time step is much longer than the time a pressure wave needs to cross the smallest
//!   element, in a dynamic run whose loading is not slow (see [`DT_WAVE_RATIO`]);
//! - the adhesive normal stiffness C_n of a contact pair is so large, compared with the
//!   stiffness of the slave body at a node, that the contact solve is ill-conditioned
//!   (see [`CN_STIFFNESS_RATIO`]);
//! - the adhesive cohesive zone E*/C_n is shorter than the slave elements
//!   ([`cohesive_zone_length`]): the peak adhesive traction then falls between nodes and the
//!   de-bonding front jumps from node to node;
//! - a rigid sphere or cylinder indents the slave surface over a contact half-width √(R d) of
//!   fewer than [`MIN_ELEMENTS_ACROSS_CONTACT`] slave elements, measured where the contact
//!   starts (the local element size, not the mean over the surface).

use crate::contact::interface::{Interface, PairScales};
pub use crate::contact::rcc::{cohesive_zone_length, CN_STIFFNESS_RATIO};
use crate::contact::{Master, RigidShape};
use crate::mesh::Mesh;
use crate::problem::{Problem, Table};

/// Warn when Δt exceeds this many times the wave transit time of the smallest element.
pub const DT_WAVE_RATIO: f64 = 1000.0;

/// The wave warning is left out when every prescribed speed (initial velocities, prescribed
/// displacements, rigid-master motions) is below this fraction of the pressure-wave speed:
/// the loading is then slow, and not resolving waves is intended.
pub const SLOW_LOADING_MACH: f64 = 1e-3;

/// Warn when the estimated contact half-width holds fewer slave elements than this.
pub const MIN_ELEMENTS_ACROSS_CONTACT: f64 = 3.0;

/// The warnings for a validated problem, each stating the number that triggered it and the
/// threshold. Empty when nothing looks suspicious.
pub fn physical_warnings(problem: &Problem) -> Vec<String> {
    let mut out = Vec::new();
    wave_warning(problem, &mut out);
    contact_warnings(problem, &mut out);
    out
}

/// Smallest distance between two nodes of one cell (the shortest element edge) [m].
fn smallest_edge(mesh: &Mesh) -> f64 {
    let mut h = f64::INFINITY;
    let mut visit = |cell: &[usize]| {
        for a in 0..cell.len() {
            for b in a + 1..cell.len() {
                let d = dist(mesh.nodes[cell[a]], mesh.nodes[cell[b]]);
                if d > 0.0 && d < h {
                    h = d;
                }
            }
        }
    };
    for (_, c) in mesh.cells() {
        visit(c);
    }
    h
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Largest |slope| of a table [unit/s].
fn max_rate(t: &Table) -> f64 {
    let mut r: f64 = 0.0;
    for k in 1..t.t.len() {
        let dt = t.t[k] - t.t[k - 1];
        if dt > 0.0 {
            r = r.max(((t.v[k] - t.v[k - 1]) / dt).abs());
        }
    }
    r
}

/// Largest speed of a translation given per component by tables [m/s].
fn max_speed(tables: &[Table; 3]) -> f64 {
    tables
        .iter()
        .map(|t| max_rate(t).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The fastest prescribed speed of the problem [m/s]: initial velocities, prescribed
/// translations and rotations (ω times the largest extent of the model), rigid-master motions.
fn fastest_prescribed_speed(problem: &Problem) -> f64 {
    let extent = {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for b in &problem.bodies {
            for p in &b.mesh.nodes {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        if lo[0].is_finite() {
            dist(lo, hi)
        } else {
            0.0
        }
    };
    let mut v: f64 = 0.0;
    for b in &problem.bodies {
        let iv = b.initial_velocity;
        v = v.max((iv[0] * iv[0] + iv[1] * iv[1] + iv[2] * iv[2]).sqrt());
    }
    for d in &problem.dirichlet {
        v = v.max(max_speed(&d.translation));
        if let Some(r) = &d.rotation {
            v = v.max(max_rate(&r.angle) * extent);
        }
    }
    for c in &problem.contacts {
        if let Master::Rigid { motion, .. } = &c.master {
            v = v.max(max_speed(&motion.translation));
            if let Some(r) = &motion.rotation {
                v = v.max(max_rate(&r.angle) * extent);
            }
        }
    }
    v
}

fn wave_warning(problem: &Problem, out: &mut Vec<String>) {
    if problem.time.quasi_static {
        return;
    }
    let dt = problem.time.dt;
    // The body and element with the shortest transit time h / c.
    let mut best: Option<(f64, f64, &str)> = None; // (transit time, wave speed, body)
    for b in &problem.bodies {
        let g = b.material.shear_modulus();
        let k = b.material.bulk_modulus();
        let c = ((k + 4.0 / 3.0 * g) / b.density).sqrt();
        let h = smallest_edge(&b.mesh);
        let transit = h / c;
        if transit.is_finite() && transit > 0.0 && best.is_none_or(|(t, _, _)| transit < t) {
            best = Some((transit, c, &b.name));
        }
    }
    let Some((transit, c, body)) = best else {
        return;
    };
    let ratio = dt / transit;
    if ratio <= DT_WAVE_RATIO {
        return;
    }
    let v = fastest_prescribed_speed(problem);
    if v < SLOW_LOADING_MACH * c && problem.loads.is_empty() {
        // Slow prescribed motion and no applied forces: not resolving waves is intended.
        return;
    }
    out.push(format!(
        "Δt = {dt:.3e} s is {ratio:.0} times (warning above {DT_WAVE_RATIO:.0}) the time a pressure wave needs to cross the smallest element ({transit:.3e} s; body {body:?}, wave speed {c:.4} m/s): inertia effects at the element scale are not resolved (fine for slow loading; for impact or waves reduce dt)"
    ));
}

fn contact_warnings(problem: &Problem, out: &mut Vec<String>) {
    let offsets = problem.node_offsets();
    let body_of = |global: usize| -> usize { offsets.partition_point(|&o| o <= global) - 1 };
    for pair in &problem.contacts {
        let Some(&first) = pair.slave_nodes.first() else {
            continue;
        };
        let bi = body_of(first);
        let body = &problem.bodies[bi];
        let coord = |global: usize| body.mesh.nodes[global - offsets[bi]];
        let h = mean_slave_edge(pair, body, offsets[bi]);
        if !(h > 0.0 && h.is_finite()) {
            continue;
        }
        // The law's own checks (e.g. stiff adhesive links).
        let areas: Vec<f64> = pair
            .slave_area
            .iter()
            .copied()
            .filter(|a| *a > 0.0)
            .collect();
        let g = body.material.shear_modulus();
        let k = body.material.bulk_modulus();
        let scales = PairScales {
            name: &pair.name,
            mean_area: if areas.is_empty() {
                None
            } else {
                Some(areas.iter().sum::<f64>() / areas.len() as f64)
            },
            young: 9.0 * k * g / (3.0 * k + g),
            poisson: (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
            edge: h,
        };
        pair.law.warnings(&scales, out);
        // Contact zone resolution under a rigid sphere or cylinder.
        if let Master::Rigid { shape, motion } = &pair.master {
            let radius = match *shape {
                RigidShape::Sphere { radius, .. } | RigidShape::Cylinder { radius, .. } => radius,
                RigidShape::Plane { .. } => continue,
            };
            let gap = pair
                .slave_nodes
                .iter()
                .map(|&n| distance_outside(shape, coord(n)))
                .fold(f64::INFINITY, f64::min)
                .max(0.0);
            // Largest travel of the master: the displacement at every table time.
            let mut times: Vec<f64> = motion
                .translation
                .iter()
                .flat_map(|t| t.t.iter().copied())
                .collect();
            times.push(0.0);
            let travel = times
                .iter()
                .map(|&t| {
                    let u: [f64; 3] = std::array::from_fn(|k| motion.translation[k].at(t));
                    (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
                })
                .fold(0.0, f64::max);
            let depth = travel - gap;
            if depth.is_nan() || depth <= 0.0 {
                continue;
            }
            let half_width = (radius * depth).sqrt();
            // The element size where contact starts: around the slave node nearest to the
            // master, leaving out edges along a cylinder's axis (they do not cut the zone).
            let nearest = (0..pair.slave_nodes.len()).min_by(|&i, &j| {
                let d = |i: usize| distance_outside(shape, coord(pair.slave_nodes[i]));
                d(i).total_cmp(&d(j))
            });
            let along = match *shape {
                RigidShape::Cylinder { axis, .. } => Some(axis),
                _ => None,
            };
            let local = nearest
                .map(|i| local_slave_edge(pair, i, &coord, along))
                .filter(|l| *l > 0.0 && l.is_finite())
                .unwrap_or(h);
            let across = half_width / local;
            if across < MIN_ELEMENTS_ACROSS_CONTACT {
                out.push(format!(
                    "contact {:?}: the contact half-width under the rigid master, about √(R d) = {half_width:.3e} m (R = {radius:.3e} m, indentation d = {depth:.3e} m), spans {across:.2} slave elements (slave edge {local:.3e} m where contact starts; warning below {MIN_ELEMENTS_ACROSS_CONTACT:.0}): the mesh is too coarse to resolve the contact zone; refine the slave surface",
                    pair.name
                ));
            }
        }
    }
}

/// Distance of `x` outside a rigid sphere or cylinder in its reference position [m]
/// (negative inside); 0 for a plane, which is not checked.
fn distance_outside(shape: &RigidShape, x: [f64; 3]) -> f64 {
    match *shape {
        RigidShape::Sphere { center, radius } => dist(x, center) - radius,
        RigidShape::Cylinder {
            point,
            axis,
            radius,
        } => {
            let d = [x[0] - point[0], x[1] - point[1], x[2] - point[2]];
            let along = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
            let r = [
                d[0] - along * axis[0],
                d[1] - along * axis[1],
                d[2] - along * axis[2],
            ];
            (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt() - radius
        }
        RigidShape::Plane { .. } => 0.0,
    }
}

/// Mean length of the slave face edges that meet at slave node `local` (index into the
/// pair's slave nodes) [m], leaving out edges within about 25° of `along` when given; NaN when
/// there is none.
fn local_slave_edge(
    pair: &crate::contact::ContactPair,
    local: usize,
    coord: &dyn Fn(usize) -> [f64; 3],
    along: Option<[f64; 3]>,
) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for q in &pair.slave_quads {
        let mut nodes = q.to_vec();
        nodes.dedup();
        if nodes.len() > 1 && nodes[0] == nodes[nodes.len() - 1] {
            nodes.pop();
        }
        for i in 0..nodes.len() {
            let (a, b) = (nodes[i], nodes[(i + 1) % nodes.len()]);
            if a != local && b != local {
                continue;
            }
            let (Some(&ga), Some(&gb)) = (pair.slave_nodes.get(a), pair.slave_nodes.get(b)) else {
                continue;
            };
            let (pa, pb) = (coord(ga), coord(gb));
            let len = dist(pa, pb);
            if let Some(ax) = along {
                let n = dist(ax, [0.0; 3]);
                let cos =
                    ((pb[0] - pa[0]) * ax[0] + (pb[1] - pa[1]) * ax[1] + (pb[2] - pa[2]) * ax[2])
                        / (len * n);
                if cos.abs() > 0.9 {
                    continue;
                }
            }
            if len > 0.0 {
                sum += len;
                count += 1;
            }
        }
    }
    if count == 0 {
        f64::NAN
    } else {
        sum / count as f64
    }
}

/// Mean edge length of the slave faces of a pair [m]: over the edges of the faces whose
/// nodes are all slave nodes.
fn mean_slave_edge(
    pair: &crate::contact::ContactPair,
    body: &crate::problem::Body,
    offset: usize,
) -> f64 {
    let mut sum = 0.0;
    let mut count = 0usize;
    for q in &pair.slave_quads {
        let nodes: Vec<usize> = {
            let mut v = q.to_vec();
            v.dedup();
            if v.len() > 1 && v[0] == v[v.len() - 1] {
                v.pop();
            }
            v
        };
        for i in 0..nodes.len() {
            let (a, b) = (nodes[i], nodes[(i + 1) % nodes.len()]);
            let (Some(&ga), Some(&gb)) = (pair.slave_nodes.get(a), pair.slave_nodes.get(b)) else {
                continue;
            };
            let (Some(pa), Some(pb)) = (
                body.mesh.nodes.get(ga.wrapping_sub(offset)),
                body.mesh.nodes.get(gb.wrapping_sub(offset)),
            ) else {
                continue;
            };
            sum += dist(*pa, *pb);
            count += 1;
        }
    }
    if count == 0 {
        f64::NAN
    } else {
        sum / count as f64
    }
}
