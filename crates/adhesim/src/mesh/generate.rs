//! Built-in all-hex mesh generators.
//!
//! Conventions shared by every generator:
//! - All coordinates are in metres.
//! - y is the vertical ("up") axis.
//! - Plane-strain bodies (disk, half disk) lie in the x-y plane and are extruded over
//!   z ∈ [0, t] with exactly one element through the thickness t.
//! - Cells are Hex8 in VTK order with positive Jacobian; coincident nodes are merged and every
//!   node belongs to at least one cell.
//! - Boundary face sets are outward oriented; [`Mesh::set_faces`] also creates a node set of
//!   the same name. Extra node sets name individual points (e.g. `center`, `apex`).
//!
//! The round bodies use an O-grid: a central, slightly bulged square (a cube in 3-D) meshed
//! by transfinite interpolation, surrounded by blocks whose straight radial grid lines join
//! the central block to the exact circle (sphere). No cell is degenerate and no cell has a
//! corner angle far from 90°.

use super::{Face, Mesh};
use crate::element::HEX8;
use std::collections::HashMap;
use std::f64::consts::FRAC_PI_4;

/// Relative tolerance (times the body's length scale) used to merge coincident nodes and to
/// recognise nodes on named surfaces.
const REL_TOL: f64 = 1e-9;

/// Half side of the central square of the 2-D O-grid, as a fraction of the radius.
const DISK_CORE_HALF_SIDE: f64 = 0.3;
/// Bulge of the central square's sides towards the circle through its corners (0 = straight
/// sides, 1 = circular arcs).
const DISK_CORE_BULGE: f64 = 0.4;
/// Half side of the central cube of the 3-D O-grid, as a fraction of the radius.
const BALL_CORE_HALF_SIDE: f64 = 0.35;
/// Bulge of the central cube's faces towards the sphere through its corners.
const BALL_CORE_BULGE: f64 = 0.45;

/// Which face of a [`half_disk`] is the flat (diameter) face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlatSide {
    /// Flat face on top (at y = 0), body below it (y ≤ 0), curved face pointing down: a
    /// plane-strain indentor.
    Top,
    /// Flat face at the bottom (at y = 0), body above it (y ≥ 0), curved face pointing up: a
    /// semi-cylinder lying on its flat side.
    Bottom,
}

/// Axis-aligned box [0, Lx] × [0, Ly] × [0, Lz] with nx × ny × nz equal hexes.
///
/// `size` = [Lx, Ly, Lz] in metres, `divisions` = [nx, ny, nz].
///
/// Face sets (each also a node set): `left` (x = 0), `right` (x = Lx), `bottom` (y = 0),
/// `top` (y = Ly), `back` (z = 0), `front` (z = Lz). Together they cover the boundary.
///
/// # Panics
/// If a size is not positive and finite or a division count is zero.
pub fn block(size: [f64; 3], divisions: [usize; 3]) -> Mesh {
    for k in 0..3 {
        assert_length("block", "size", size[k]);
        assert!(divisions[k] > 0, "block: divisions[{k}] must be at least 1");
    }
    let mut mesh = Mesh {
        nodes: grid_points(divisions)
            .map(|q| [size[0] * q[0], size[1] * q[1], size[2] * q[2]])
            .collect(),
        ..Mesh::default()
    };
    mesh.add_cells(&HEX8, grid_hexes(divisions));
    let [lx, ly, lz] = size;
    let on = |axis: usize, value: f64| {
        let tol = REL_TOL * size[axis];
        move |p: [f64; 3]| (p[axis] - value).abs() <= tol
    };
    let left = on(0, 0.0);
    let right = on(0, lx);
    let bottom = on(1, 0.0);
    let top = on(1, ly);
    let back = on(2, 0.0);
    let front = on(2, lz);
    name_boundary_faces(
        &mut mesh,
        &[
            ("left", &left),
            ("right", &right),
            ("bottom", &bottom),
            ("top", &top),
            ("back", &back),
            ("front", &front),
        ],
    );
    mesh
}

/// Solid disk of radius R centred on the z axis, extruded over z ∈ [0, t] with one element
/// through the thickness (plane-strain slab).
///
/// O-grid: a central bulged square of n × n cells and four ring blocks of n × `n_radial`
/// cells, where n = `n_quarter` rounded up to an even number (so that the centre and the
/// points (0, ±R) are nodes). The circle is split into 4·n equal arcs whose end nodes lie
/// exactly on it; the mesh area is that of the inscribed 4n-gon.
///
/// Face sets: `curved` (rim), `front` (z = t), `back` (z = 0); together they cover the
/// boundary. Node sets (besides those of the face sets): `center` (x = y = 0), `top_point`
/// (0, R), `bottom_point` (0, −R), each one node per z layer.
///
/// # Panics
/// If `radius` or `thickness` is not positive and finite, or a count is zero.
pub fn disk(radius: f64, thickness: f64, n_quarter: usize, n_radial: usize) -> Mesh {
    assert_length("disk", "radius", radius);
    assert_length("disk", "thickness", thickness);
    let plane = disk_plane("disk", &DiskOGrid::new(radius), n_quarter, n_radial);
    let mut mesh = extrude(&plane, thickness);
    let tol = REL_TOL * radius;
    let curved = move |p: [f64; 3]| (p[0].hypot(p[1]) - radius).abs() <= tol;
    let z_tol = REL_TOL * thickness;
    let back = move |p: [f64; 3]| p[2].abs() <= z_tol;
    let front = move |p: [f64; 3]| (p[2] - thickness).abs() <= z_tol;
    name_boundary_faces(
        &mut mesh,
        &[("curved", &curved), ("front", &front), ("back", &back)],
    );
    let center = nodes_near(&mesh, [0.0, 0.0], tol);
    let top_point = nodes_near(&mesh, [0.0, radius], tol);
    let bottom_point = nodes_near(&mesh, [0.0, -radius], tol);
    mesh.set_nodes("center", center);
    mesh.set_nodes("top_point", top_point);
    mesh.set_nodes("bottom_point", bottom_point);
    mesh
}

/// Half of a [`disk`] cut along y = 0, extruded over z ∈ [0, t] with one element through the
/// thickness (plane-strain slab).
///
/// With [`FlatSide::Top`] the body lies in y ≤ 0 (curved face down, an indentor); with
/// [`FlatSide::Bottom`] it lies in y ≥ 0 (curved face up). The mesh is exactly the
/// corresponding half of `disk(radius, thickness, n_quarter, n_radial)`: `n_quarter` is
/// rounded up to an even n and the half circle has 2·n arcs.
///
/// Face sets: `flat` (y = 0) plus the alias `top` ([`FlatSide::Top`]) or `bottom`
/// ([`FlatSide::Bottom`]) naming the same faces, `curved`, `front` (z = t), `back` (z = 0);
/// `flat`, `curved`, `front` and `back` cover the boundary. Node sets (besides those of the
/// face sets): `apex` (the curved face's extreme point, (0, −R) or (0, R)) and `center`
/// (x = y = 0), each one node per z layer.
///
/// # Panics
/// If `radius` or `thickness` is not positive and finite, or a count is zero.
pub fn half_disk(
    radius: f64,
    thickness: f64,
    n_quarter: usize,
    n_radial: usize,
    flat_side: FlatSide,
) -> Mesh {
    assert_length("half_disk", "radius", radius);
    assert_length("half_disk", "thickness", thickness);
    let full = disk_plane("half_disk", &DiskOGrid::new(radius), n_quarter, n_radial);
    let mut plane = full.keep_quads(|c| c[1] > 0.0);
    if flat_side == FlatSide::Top {
        plane.mirror_y();
    }
    let mut mesh = extrude(&plane, thickness);
    let tol = REL_TOL * radius;
    let flat = move |p: [f64; 3]| p[1].abs() <= tol;
    let curved = move |p: [f64; 3]| (p[0].hypot(p[1]) - radius).abs() <= tol;
    let z_tol = REL_TOL * thickness;
    let back = move |p: [f64; 3]| p[2].abs() <= z_tol;
    let front = move |p: [f64; 3]| (p[2] - thickness).abs() <= z_tol;
    name_boundary_faces(
        &mut mesh,
        &[
            ("flat", &flat),
            ("curved", &curved),
            ("front", &front),
            ("back", &back),
        ],
    );
    let (alias, apex_y) = match flat_side {
        FlatSide::Top => ("top", -radius),
        FlatSide::Bottom => ("bottom", radius),
    };
    let flat_faces = mesh.face_sets["flat"].clone();
    mesh.set_faces(alias, flat_faces);
    let apex = nodes_near(&mesh, [0.0, apex_y], tol);
    let center = nodes_near(&mesh, [0.0, 0.0], tol);
    mesh.set_nodes("apex", apex);
    mesh.set_nodes("center", center);
    mesh
}

/// A tube of elliptic cross-section lying along z: the region between the inner ellipse of
/// semi-axes `inner` = [a, b] [m] (along x and y) and the outer one `outer` = [A, B] [m],
/// centred on the z axis, extruded over z ∈ [0, `thickness`] with one element through the
/// thickness (a plane-strain slab). Equal semi-axes give a circular ring; a flat inner
/// ellipse (b ≪ a) a channel.
///
/// Grid: `n_around` elements around (rounded up to a multiple of 4, so that the points
/// (±a, 0) and (0, ±b) are nodes) and `n_radial` layers between the ellipses. Node (k, j)
/// sits at ((a + s(A − a)) cos θ, (b + s(B − b)) sin θ) with θ = 2πk/n_around and
/// s = j/n_radial, which puts the nodes closer together where the inner ellipse curves
/// most (at its ends on the x axis).
///
/// Face sets: `inner`, `outer`, `front` (z = t), `back` (z = 0); together they cover the
/// boundary. Node sets (besides those of the face sets): `top_grip` and `bottom_grip`, the
/// outer surface's nodes with |x| ≤ `grip` / 2 [m] above and below the x axis, where plates
/// glued to the tube would hold it.
///
/// # Panics
/// If a length is not positive and finite, the outer ellipse does not enclose the inner
/// one, or a count is zero.
pub fn tube(
    inner: [f64; 2],
    outer: [f64; 2],
    thickness: f64,
    n_around: usize,
    n_radial: usize,
    grip: f64,
) -> Mesh {
    for (what, v) in [
        ("inner[0]", inner[0]),
        ("inner[1]", inner[1]),
        ("outer[0]", outer[0]),
        ("outer[1]", outer[1]),
        ("thickness", thickness),
        ("grip", grip),
    ] {
        assert_length("tube", what, v);
    }
    assert!(
        outer[0] > inner[0] && outer[1] > inner[1],
        "tube: the outer semi-axes must exceed the inner ones"
    );
    assert!(
        n_around > 0 && n_radial > 0,
        "tube: counts must be at least 1"
    );
    let mut mesh = extrude(&tube_plane(inner, outer, n_around, n_radial), thickness);
    let on_ellipse =
        |ab: [f64; 2]| move |p: [f64; 3]| ((p[0] / ab[0]).hypot(p[1] / ab[1]) - 1.0).abs() <= 1e-9;
    let (on_inner, on_outer) = (on_ellipse(inner), on_ellipse(outer));
    let z_tol = REL_TOL * thickness;
    let back = move |p: [f64; 3]| p[2].abs() <= z_tol;
    let front = move |p: [f64; 3]| (p[2] - thickness).abs() <= z_tol;
    name_boundary_faces(
        &mut mesh,
        &[
            ("inner", &on_inner),
            ("outer", &on_outer),
            ("front", &front),
            ("back", &back),
        ],
    );
    let gripped = |above: bool| -> Vec<usize> {
        mesh.node_sets["outer"]
            .iter()
            .copied()
            .filter(|&i| {
                let p = mesh.nodes[i];
                p[0].abs() <= 0.5 * grip && (p[1] > 0.0) == above
            })
            .collect()
    };
    let (top, bottom) = (gripped(true), gripped(false));
    mesh.set_nodes("top_grip", top);
    mesh.set_nodes("bottom_grip", bottom);
    mesh
}

/// The plane grid of [`tube`]: `n_around` (rounded up to a multiple of 4) by `n_radial`
/// quads, counter-clockwise.
fn tube_plane(inner: [f64; 2], outer: [f64; 2], n_around: usize, n_radial: usize) -> PlaneMesh {
    let n = n_around.div_ceil(4) * 4;
    let id = |k: usize, j: usize| (k % n) * (n_radial + 1) + j;
    let mut nodes = Vec::with_capacity(n * (n_radial + 1));
    for k in 0..n {
        let theta = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        for j in 0..=n_radial {
            let s = j as f64 / n_radial as f64;
            let a = inner[0] + s * (outer[0] - inner[0]);
            let b = inner[1] + s * (outer[1] - inner[1]);
            nodes.push([a * theta.cos(), b * theta.sin()]);
        }
    }
    let quads = (0..n)
        .flat_map(|k| {
            (0..n_radial).map(move |j| [id(k, j), id(k, j + 1), id(k + 1, j + 1), id(k + 1, j)])
        })
        .collect();
    PlaneMesh { nodes, quads }
}

/// Quarter of a solid hemisphere of radius R hanging below the plane y = 0: the ball's
/// octant x ≥ 0, y ≤ 0, z ≥ 0, curved face down, all hex.
///
/// 3-D O-grid: a central bulged cube of n × n × n cells and three shell blocks of
/// n × n × n cells (n = `n`) whose straight radial grid lines join the cube to the sphere.
/// The sphere is covered by 3·n² bilinear faces whose nodes lie exactly on it.
///
/// Face sets: `flat` and its alias `top` (y = 0), `curved` (sphere), `sym_x` (x = 0),
/// `sym_z` (z = 0); `flat`, `curved`, `sym_x` and `sym_z` cover the boundary. Node sets
/// (besides those of the face sets): `apex` (0, −R, 0) and `center` (the origin).
///
/// # Panics
/// If `radius` is not positive and finite or `n` is zero.
pub fn quarter_hemisphere(radius: f64, n: usize) -> Mesh {
    assert_length("quarter_hemisphere", "radius", radius);
    assert!(n > 0, "quarter_hemisphere: n must be at least 1");
    let grid = BallOGrid::new(radius);
    let mut mesh = ball_octant_hexes(&grid, n);
    let tol = REL_TOL * radius;
    let flat = move |p: [f64; 3]| p[1].abs() <= tol;
    let sym_x = move |p: [f64; 3]| p[0].abs() <= tol;
    let sym_z = move |p: [f64; 3]| p[2].abs() <= tol;
    let curved = move |p: [f64; 3]| (norm(p) - radius).abs() <= tol;
    name_boundary_faces(
        &mut mesh,
        &[
            ("flat", &flat),
            ("sym_x", &sym_x),
            ("sym_z", &sym_z),
            ("curved", &curved),
        ],
    );
    let flat_faces = mesh.face_sets["flat"].clone();
    mesh.set_faces("top", flat_faces);
    let apex = nodes_within(&mesh, [0.0, -radius, 0.0], tol);
    let center = nodes_within(&mesh, [0.0, 0.0, 0.0], tol);
    mesh.set_nodes("apex", apex);
    mesh.set_nodes("center", center);
    mesh
}

/// Cells and nodes (no sets) of the ball octant x ≥ 0, y ≤ 0, z ≥ 0 (see
/// [`quarter_hemisphere`]).
fn ball_octant_hexes(grid: &BallOGrid, n: usize) -> Mesh {
    let mut merger = NodeMerger::new(REL_TOL * grid.radius);
    let mut mesh = Mesh::default();
    let mut hexes = Vec::new();
    add_hex_block(&mut merger, &mut hexes, [n; 3], |q| grid.core(q));
    for axis in 0..3 {
        add_hex_block(&mut merger, &mut hexes, [n; 3], |q| grid.shell(axis, q));
    }
    mesh.add_cells(&HEX8, hexes);
    // The blocks are built in the octant y ≥ 0; mirror to y ≤ 0 and restore the orientation.
    mesh.nodes = merger
        .into_nodes()
        .into_iter()
        .map(|p| [p[0], -p[1], p[2]].map(|x| snap_zero(x, grid.radius)))
        .collect();
    for h in mesh.hexes_mut() {
        *h = [h[0], h[3], h[2], h[1], h[4], h[7], h[6], h[5]];
    }
    mesh
}

/// Panics with a clear message unless `value` is a positive, finite length.
fn assert_length(generator: &str, name: &str, value: f64) {
    assert!(
        value.is_finite() && value > 0.0,
        "{generator}: {name} must be positive and finite, got {value}"
    );
}

/// i / n as a float (exactly 1 for i = n).
fn fraction(i: usize, n: usize) -> f64 {
    i as f64 / n as f64
}

fn norm(p: [f64; 3]) -> f64 {
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()
}

/// Merges points closer than `tol` (max-norm) into one node, using a hash grid of cell `tol`.
struct NodeMerger {
    tol: f64,
    nodes: Vec<[f64; 3]>,
    buckets: HashMap<[i64; 3], Vec<usize>>,
}

impl NodeMerger {
    fn new(tol: f64) -> Self {
        NodeMerger {
            tol,
            nodes: Vec::new(),
            buckets: HashMap::new(),
        }
    }

    fn bucket(&self, p: [f64; 3]) -> [i64; 3] {
        p.map(|x| (x / self.tol).floor() as i64)
    }

    /// Index of the node at `p`, created if no node lies within the tolerance.
    fn insert(&mut self, p: [f64; 3]) -> usize {
        let b = self.bucket(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = [b[0] + dx, b[1] + dy, b[2] + dz];
                    if let Some(ids) = self.buckets.get(&key) {
                        for &i in ids {
                            let q = self.nodes[i];
                            if (0..3).all(|k| (p[k] - q[k]).abs() <= self.tol) {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        let id = self.nodes.len();
        self.nodes.push(p);
        self.buckets.entry(b).or_default().push(id);
        id
    }

    fn into_nodes(self) -> Vec<[f64; 3]> {
        self.nodes
    }
}

/// A 2-D quadrilateral mesh in the x-y plane; quads counter-clockwise.
struct PlaneMesh {
    nodes: Vec<[f64; 2]>,
    quads: Vec<[usize; 4]>,
}

impl PlaneMesh {
    /// The sub-mesh of the quads whose centroid satisfies `keep`, without unused nodes.
    fn keep_quads(&self, keep: impl Fn([f64; 2]) -> bool) -> PlaneMesh {
        let kept: Vec<[usize; 4]> = self
            .quads
            .iter()
            .filter(|q| {
                let mut c = [0.0; 2];
                for &i in q.iter() {
                    c[0] += 0.25 * self.nodes[i][0];
                    c[1] += 0.25 * self.nodes[i][1];
                }
                keep(c)
            })
            .copied()
            .collect();
        let mut new_id = vec![usize::MAX; self.nodes.len()];
        let mut nodes = Vec::new();
        for q in &kept {
            for &i in q {
                if new_id[i] == usize::MAX {
                    new_id[i] = nodes.len();
                    nodes.push(self.nodes[i]);
                }
            }
        }
        let quads = kept.iter().map(|q| q.map(|i| new_id[i])).collect();
        PlaneMesh { nodes, quads }
    }

    /// Reflects the mesh in the x axis (y → −y), keeping the quads counter-clockwise.
    fn mirror_y(&mut self) {
        for p in &mut self.nodes {
            // 0 − y rather than −y: nodes on the axis keep y = +0.
            p[1] = 0.0 - p[1];
        }
        for q in &mut self.quads {
            *q = [q[0], q[3], q[2], q[1]];
        }
    }
}

/// Extrudes a plane mesh over z ∈ [0, thickness] with one hex per quad. Node i of the plane
/// mesh becomes node i (z = 0) and node i + N (z = thickness).
fn extrude(plane: &PlaneMesh, thickness: f64) -> Mesh {
    let n = plane.nodes.len();
    let mut mesh = Mesh::default();
    for z in [0.0, thickness] {
        mesh.nodes
            .extend(plane.nodes.iter().map(|p| [p[0], p[1], z]));
    }
    let hexes = plane.quads.iter().map(|q| {
        [
            q[0],
            q[1],
            q[2],
            q[3],
            q[0] + n,
            q[1] + n,
            q[2] + n,
            q[3] + n,
        ]
    });
    mesh.add_cells(&HEX8, hexes);
    mesh
}

/// A named surface: the name of a face set and the predicate its nodes satisfy.
type SurfaceRule<'a> = (&'a str, &'a dyn Fn([f64; 3]) -> bool);

/// Assigns every boundary face to the first rule whose predicate holds at all its nodes and
/// stores the resulting face sets (and node sets) under the rules' names.
fn name_boundary_faces(mesh: &mut Mesh, rules: &[SurfaceRule]) {
    let mut sets: Vec<Vec<Face>> = vec![Vec::new(); rules.len()];
    for face in mesh.boundary_faces() {
        let rule = rules
            .iter()
            .position(|(_, on)| face.nodes().iter().all(|&i| on(mesh.nodes[i])));
        if let Some(r) = rule {
            sets[r].push(face);
        }
    }
    for ((name, _), faces) in rules.iter().zip(sets) {
        mesh.set_faces(name, faces);
    }
}

/// Nodes whose (x, y) lies within `tol` of `xy` (all z layers).
fn nodes_near(mesh: &Mesh, xy: [f64; 2], tol: f64) -> Vec<usize> {
    (0..mesh.nodes.len())
        .filter(|&i| {
            let p = mesh.nodes[i];
            (p[0] - xy[0]).abs() <= tol && (p[1] - xy[1]).abs() <= tol
        })
        .collect()
}

/// Nodes within `tol` (max-norm) of the point `p`.
fn nodes_within(mesh: &Mesh, p: [f64; 3], tol: f64) -> Vec<usize> {
    (0..mesh.nodes.len())
        .filter(|&i| (0..3).all(|k| (mesh.nodes[i][k] - p[k]).abs() <= tol))
        .collect()
}

/// Transfinite (Coons) interpolation on the unit square of a map known on its boundary:
/// `edge(u, v)` is only called with u or v equal to 0 or 1.
fn coons(edge: &dyn Fn(f64, f64) -> [f64; 2], u: f64, v: f64) -> [f64; 2] {
    let (l, r, b, t) = (edge(0.0, v), edge(1.0, v), edge(u, 0.0), edge(u, 1.0));
    let (c00, c10, c01, c11) = (
        edge(0.0, 0.0),
        edge(1.0, 0.0),
        edge(0.0, 1.0),
        edge(1.0, 1.0),
    );
    let mut p = [0.0; 2];
    for k in 0..2 {
        p[k] = (1.0 - u) * l[k] + u * r[k] + (1.0 - v) * b[k] + v * t[k]
            - ((1.0 - u) * (1.0 - v) * c00[k]
                + u * (1.0 - v) * c10[k]
                + (1.0 - u) * v * c01[k]
                + u * v * c11[k]);
    }
    p
}

/// Transfinite (Gordon–Hall) interpolation on the unit cube of a map known on its surface:
/// `surface(q)` is only called with at least one coordinate of q equal to 0 or 1.
fn gordon_hall(surface: &dyn Fn([f64; 3]) -> [f64; 3], q: [f64; 3]) -> [f64; 3] {
    let weight = |x: f64, side: usize| if side == 0 { 1.0 - x } else { x };
    let at = |fixed: &[(usize, usize)]| {
        let mut r = q;
        for &(axis, side) in fixed {
            r[axis] = side as f64;
        }
        surface(r)
    };
    let mut p = [0.0; 3];
    let mut add = |w: f64, x: [f64; 3]| {
        for k in 0..3 {
            p[k] += w * x[k];
        }
    };
    for (i, &qi) in q.iter().enumerate() {
        for a in 0..2 {
            add(weight(qi, a), at(&[(i, a)]));
        }
    }
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        for a in 0..2 {
            for b in 0..2 {
                add(-weight(q[i], a) * weight(q[j], b), at(&[(i, a), (j, b)]));
            }
        }
    }
    for a in 0..2 {
        for b in 0..2 {
            for c in 0..2 {
                let w = weight(q[0], a) * weight(q[1], b) * weight(q[2], c);
                add(w, at(&[(0, a), (1, b), (2, c)]));
            }
        }
    }
    p
}

/// Parameters (i/n₀, j/n₁, k/n₂) of the nodes of a structured n₀ × n₁ × n₂ grid on the unit
/// cube, i fastest: node (i, j, k) has index i + (n₀ + 1)(j + (n₁ + 1) k).
fn grid_points(n: [usize; 3]) -> impl Iterator<Item = [f64; 3]> {
    (0..=n[2]).flat_map(move |k| {
        (0..=n[1]).flat_map(move |j| {
            (0..=n[0]).map(move |i| [fraction(i, n[0]), fraction(j, n[1]), fraction(k, n[2])])
        })
    })
}

/// Hexes (VTK order) of the structured grid of [`grid_points`].
fn grid_hexes(n: [usize; 3]) -> Vec<[usize; 8]> {
    let id = |i: usize, j: usize, k: usize| i + (n[0] + 1) * (j + (n[1] + 1) * k);
    let mut hexes = Vec::with_capacity(n[0] * n[1] * n[2]);
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let (i1, j1, k1) = (i + 1, j + 1, k + 1);
                hexes.push([
                    id(i, j, k),
                    id(i1, j, k),
                    id(i1, j1, k),
                    id(i, j1, k),
                    id(i, j, k1),
                    id(i1, j, k1),
                    id(i1, j1, k1),
                    id(i, j1, k1),
                ]);
            }
        }
    }
    hexes
}

/// Quads (counter-clockwise in the parameter plane) of the structured n₀ × n₁ grid of
/// [`grid_points`] with n₂ = 0.
fn grid_quads(n: [usize; 2]) -> Vec<[usize; 4]> {
    let id = |i: usize, j: usize| i + (n[0] + 1) * j;
    let mut quads = Vec::with_capacity(n[0] * n[1]);
    for j in 0..n[1] {
        for i in 0..n[0] {
            quads.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    quads
}

/// Adds an `n[0]` × `n[1]` block of quads mapped from the unit square by `map`, which must be
/// orientation preserving (counter-clockwise from the u direction to the v direction).
fn add_quad_block(
    merger: &mut NodeMerger,
    quads: &mut Vec<[usize; 4]>,
    n: [usize; 2],
    map: impl Fn(f64, f64) -> [f64; 2],
) {
    let ids: Vec<usize> = grid_points([n[0], n[1], 0])
        .map(|q| {
            let p = map(q[0], q[1]);
            merger.insert([p[0], p[1], 0.0])
        })
        .collect();
    quads.extend(grid_quads(n).iter().map(|q| q.map(|l| ids[l])));
}

/// Adds an `n[0]` × `n[1]` × `n[2]` block of hexes mapped from the unit cube by `map`, which
/// must be orientation preserving.
fn add_hex_block(
    merger: &mut NodeMerger,
    hexes: &mut Vec<[usize; 8]>,
    n: [usize; 3],
    map: impl Fn([f64; 3]) -> [f64; 3],
) {
    let ids: Vec<usize> = grid_points(n).map(|q| merger.insert(map(q))).collect();
    hexes.extend(grid_hexes(n).iter().map(|h| h.map(|l| ids[l])));
}

/// Rotates a plane point by `quarter` · 90° counter-clockwise (exactly).
fn rotate_quarter(p: [f64; 2], quarter: usize) -> [f64; 2] {
    match quarter % 4 {
        0 => p,
        1 => [-p[1], p[0]],
        2 => [-p[0], -p[1]],
        _ => [p[1], -p[0]],
    }
}

/// Geometry of the 2-D O-grid of a disk of radius R: a central square of half side a whose
/// sides bulge towards the circle through its corners, and four ring blocks (right, top,
/// left, bottom) with straight radial grid lines.
struct DiskOGrid {
    radius: f64,
    half_side: f64,
    bulge: f64,
}

impl DiskOGrid {
    fn new(radius: f64) -> Self {
        DiskOGrid {
            radius,
            half_side: DISK_CORE_HALF_SIDE * radius,
            bulge: DISK_CORE_BULGE,
        }
    }

    /// Point of the central block's boundary for a point c on the square |c|∞ = a: moved
    /// radially a fraction `bulge` of the way to the circle of radius a√2.
    fn core_boundary(&self, c: [f64; 2]) -> [f64; 2] {
        let corner_radius = self.half_side * std::f64::consts::SQRT_2;
        let s = (1.0 - self.bulge) + self.bulge * corner_radius / c[0].hypot(c[1]);
        [c[0] * s, c[1] * s]
    }

    /// Central block, (u, v) ∈ [0, 1]² ↦ point.
    fn core(&self, u: f64, v: f64) -> [f64; 2] {
        let a = self.half_side;
        let edge = |u: f64, v: f64| self.core_boundary([a * (2.0 * u - 1.0), a * (2.0 * v - 1.0)]);
        coons(&edge, u, v)
    }

    /// Ring block `quarter` (0 right, 1 top, 2 left, 3 bottom); r ∈ [0, 1] runs outwards,
    /// s ∈ [0, 1] counter-clockwise along the arc of 90° centred on the block's axis.
    fn ring(&self, quarter: usize, r: f64, s: f64) -> [f64; 2] {
        let a = self.half_side;
        let inner = self.core_boundary([a, a * (2.0 * s - 1.0)]);
        let angle = FRAC_PI_4 * (2.0 * s - 1.0);
        let outer = [self.radius * angle.cos(), self.radius * angle.sin()];
        let p = [
            (1.0 - r) * inner[0] + r * outer[0],
            (1.0 - r) * inner[1] + r * outer[1],
        ];
        rotate_quarter(p, quarter)
    }
}

/// The 2-D O-grid quad mesh of a disk (see [`disk`]).
fn disk_plane(generator: &str, grid: &DiskOGrid, n_quarter: usize, n_radial: usize) -> PlaneMesh {
    assert!(n_quarter > 0, "{generator}: n_quarter must be at least 1");
    assert!(n_radial > 0, "{generator}: n_radial must be at least 1");
    let n = n_quarter + n_quarter % 2;
    let radius = grid.radius;
    let mut merger = NodeMerger::new(REL_TOL * radius);
    let mut quads = Vec::new();
    add_quad_block(&mut merger, &mut quads, [n, n], |u, v| grid.core(u, v));
    for quarter in 0..4 {
        add_quad_block(&mut merger, &mut quads, [n_radial, n], |r, s| {
            grid.ring(quarter, r, s)
        });
    }
    let nodes = merger
        .into_nodes()
        .into_iter()
        .map(|p| [snap_zero(p[0], radius), snap_zero(p[1], radius)])
        .collect();
    PlaneMesh { nodes, quads }
}

/// `x`, or exactly 0 if |x| is round-off relative to the length scale.
fn snap_zero(x: f64, scale: f64) -> f64 {
    if x.abs() <= 1e-14 * scale {
        0.0
    } else {
        x
    }
}

/// `p` with its components cyclically shifted so that `p[0]` lands on `axis`.
fn cyclic(axis: usize, p: [f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for k in 0..3 {
        out[(axis + k) % 3] = p[k];
    }
    out
}

/// tan(π u / 4), exactly 1 at u = 1: equal-angle spacing on a quarter arc.
fn tan_quarter(u: f64) -> f64 {
    if u >= 1.0 {
        1.0
    } else {
        (FRAC_PI_4 * u).tan()
    }
}

/// Geometry of the 3-D O-grid of the ball octant x, y, z ≥ 0 of radius R: a central cube
/// [0, a]³ whose three outer faces bulge towards the sphere through the corner (a, a, a), and
/// three shell blocks (one per axis) with straight radial grid lines to the sphere.
struct BallOGrid {
    radius: f64,
    half_side: f64,
    bulge: f64,
}

impl BallOGrid {
    fn new(radius: f64) -> Self {
        BallOGrid {
            radius,
            half_side: BALL_CORE_HALF_SIDE * radius,
            bulge: BALL_CORE_BULGE,
        }
    }

    /// Point of the bulged outer surface for a point c with max(c) = a.
    fn bulged(&self, c: [f64; 3]) -> [f64; 3] {
        let corner_radius = self.half_side * 3f64.sqrt();
        let s = (1.0 - self.bulge) + self.bulge * corner_radius / norm(c);
        c.map(|x| x * s)
    }

    /// Boundary of the central block for q on the surface of the unit cube: the bulged outer
    /// faces (a coordinate equal to 1), and on the symmetry planes the Coons patch of the
    /// bulged edges and the straight axis segments.
    fn core_surface(&self, q: [f64; 3]) -> [f64; 3] {
        let a = self.half_side;
        if q.iter().any(|&x| x >= 1.0) {
            return self.bulged(q.map(|x| a * x));
        }
        let zero = (0..3).find(|&k| q[k] <= 0.0).unwrap_or(0);
        let (i, j) = ((zero + 1) % 3, (zero + 2) % 3);
        let axis_end = a * ((1.0 - self.bulge) + self.bulge * 3f64.sqrt());
        let edge = |s: f64, t: f64| {
            let mut r = [0.0; 3];
            r[i] = s;
            r[j] = t;
            let p = if s >= 1.0 || t >= 1.0 {
                self.bulged(r.map(|x| a * x))
            } else {
                r.map(|x| axis_end * x)
            };
            [p[i], p[j]]
        };
        let p2 = coons(&edge, q[i], q[j]);
        let mut p = [0.0; 3];
        p[i] = p2[0];
        p[j] = p2[1];
        p
    }

    /// Central block, q ∈ [0, 1]³ ↦ point.
    fn core(&self, q: [f64; 3]) -> [f64; 3] {
        gordon_hall(&|r| self.core_surface(r), q)
    }

    /// Shell block around `axis`: q = (r, u, v), r outwards, (u, v) across the block, mapped
    /// to the axes (axis, axis + 1, axis + 2) cyclically.
    fn shell(&self, axis: usize, q: [f64; 3]) -> [f64; 3] {
        let [r, u, v] = q;
        let inner = self.bulged(cyclic(axis, [1.0, u, v]).map(|x| self.half_side * x));
        let dir = cyclic(axis, [1.0, tan_quarter(u), tan_quarter(v)]);
        let scale = self.radius / norm(dir);
        let outer = dir.map(|x| x * scale);
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = (1.0 - r) * inner[k] + r * outer[k];
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::quality::{
        cell_min_jacobian_ratio, check_faces_outward, hex_volume, inverted_cells,
    };
    use std::collections::HashSet;
    use std::f64::consts::PI;

    fn min_ratio(mesh: &Mesh) -> f64 {
        cell_min_jacobian_ratio(mesh)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    fn volume(mesh: &Mesh) -> f64 {
        (0..mesh.hexes().len()).map(|c| hex_volume(mesh, c)).sum()
    }

    /// Pairs of distinct nodes closer than `tol` (max-norm), found with a hash grid.
    fn close_node_pairs(nodes: &[[f64; 3]], tol: f64) -> Vec<(usize, usize)> {
        let cell = |p: [f64; 3]| p.map(|x| (x / tol).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, &p) in nodes.iter().enumerate() {
            grid.entry(cell(p)).or_default().push(i);
        }
        let mut pairs = Vec::new();
        for (i, &p) in nodes.iter().enumerate() {
            let c = cell(p);
            for d in 0..27i64 {
                let key = [c[0] + d % 3 - 1, c[1] + (d / 3) % 3 - 1, c[2] + d / 9 - 1];
                for &j in grid.get(&key).map(Vec::as_slice).unwrap_or(&[]) {
                    let q = nodes[j];
                    if j > i && (0..3).all(|k| (p[k] - q[k]).abs() < tol) {
                        pairs.push((i, j));
                    }
                }
            }
        }
        pairs
    }

    /// Checks shared by every generator: valid cells, no duplicate or unused nodes, outward
    /// face sets that exactly partition the boundary (`covering`), node sets matching faces.
    /// Nodes closer than 10⁻⁶ `scale` count as duplicates.
    fn check_mesh(mesh: &Mesh, covering: &[&str], scale: f64) {
        assert!(inverted_cells(mesh).is_empty(), "inverted cells");
        assert!(close_node_pairs(&mesh.nodes, 1e-6 * scale).is_empty());
        let mut used = vec![false; mesh.nodes.len()];
        for h in mesh.hexes() {
            for &i in h {
                used[i] = true;
            }
        }
        assert!(used.iter().all(|&u| u), "unused nodes");
        check_faces_outward(mesh).unwrap();
        let mut union: Vec<Face> = covering
            .iter()
            .flat_map(|name| mesh.face_sets[*name].iter().copied())
            .collect();
        union.sort_by(|a, b| a.nodes().cmp(b.nodes()));
        assert_eq!(
            union,
            mesh.boundary_faces(),
            "sets {covering:?} vs boundary"
        );
        let negative_zero = |x: &f64| *x == 0.0 && x.is_sign_negative();
        assert!(
            !mesh.nodes.iter().flatten().any(negative_zero),
            "-0 coordinate"
        );
        for (name, faces) in &mesh.face_sets {
            let from_faces: HashSet<usize> = faces
                .iter()
                .flat_map(|f| f.nodes().iter().copied())
                .collect();
            let set: HashSet<usize> = mesh.node_sets[name].iter().copied().collect();
            assert_eq!(from_faces, set, "node set {name}");
            assert!(!faces.is_empty(), "empty face set {name}");
        }
    }

    fn coords<'a>(mesh: &'a Mesh, set: &str) -> impl Iterator<Item = [f64; 3]> + 'a {
        mesh.node_sets[set].iter().map(move |&i| mesh.nodes[i])
    }

    /// Relative area deficit of a regular polygon with `n` sides inscribed in a circle.
    fn polygon_deficit(n: usize) -> f64 {
        let h = 2.0 * PI / n as f64;
        1.0 - h.sin() / h
    }

    #[test]
    fn block_is_exact_and_fully_named() {
        for (size, div) in [
            ([1.0, 1.0, 1.0], [1, 1, 1]),
            ([0.02, 0.01, 0.001], [3, 2, 1]),
            ([2.0, 0.5, 0.3], [5, 7, 4]),
        ] {
            let m = block(size, div);
            let [nx, ny, nz] = div;
            assert_eq!(m.num_nodes(), (nx + 1) * (ny + 1) * (nz + 1));
            assert_eq!(m.num_cells(), nx * ny * nz);
            let names = ["left", "right", "bottom", "top", "back", "front"];
            check_mesh(&m, &names, size[0]);
            assert!((min_ratio(&m) - 1.0).abs() < 1e-12);
            let exact = size[0] * size[1] * size[2];
            assert!((volume(&m) - exact).abs() < 1e-12 * exact);
            let expected_faces = [ny * nz, ny * nz, nx * nz, nx * nz, nx * ny, nx * ny];
            for (k, name) in names.iter().enumerate() {
                assert_eq!(m.face_sets[*name].len(), expected_faces[k], "{name}");
                let (axis, value) = (k / 2, if k % 2 == 0 { 0.0 } else { size[k / 2] });
                assert!(coords(&m, name).all(|p| p[axis] == value), "{name}");
            }
        }
    }

    #[test]
    #[should_panic(expected = "divisions[1] must be at least 1")]
    fn block_rejects_zero_divisions() {
        block([1.0, 1.0, 1.0], [1, 0, 1]);
    }

    #[test]
    #[should_panic(expected = "size must be positive")]
    fn block_rejects_non_positive_size() {
        block([1.0, -1.0, 1.0], [1, 1, 1]);
    }

    #[test]
    #[should_panic(expected = "disk: radius must be positive")]
    fn disk_rejects_zero_radius() {
        disk(0.0, 0.001, 4, 4);
    }

    #[test]
    fn tube_volume_sets_and_grips() {
        let (inner, outer, t) = ([0.01, 0.002], [0.016, 0.008], 0.001);
        for (n_around, n_radial) in [(8, 1), (30, 3), (96, 4)] {
            let m = tube(inner, outer, t, n_around, n_radial, 0.016);
            check_mesh(&m, &["inner", "outer", "front", "back"], outer[0]);
            let n = n_around.div_ceil(4) * 4;
            assert_eq!(m.num_cells(), n * n_radial);
            // Both rims are affine images of a regular n-gon inscribed in a circle, so the
            // annulus holds exactly (n/2) sin(2π/n) (AB − ab) t.
            let polygon = 0.5 * n as f64 * (2.0 * PI / n as f64).sin();
            let exact = polygon * (outer[0] * outer[1] - inner[0] * inner[1]) * t;
            assert!(
                (volume(&m) / exact - 1.0).abs() < 1e-12,
                "({n_around},{n_radial})"
            );
            assert_eq!(m.face_sets["inner"].len(), n);
            assert_eq!(m.face_sets["outer"].len(), n);
            let on = |ab: [f64; 2], p: [f64; 3]| {
                ((p[0] / ab[0]).hypot(p[1] / ab[1]) - 1.0).abs() < 1e-12
            };
            assert!(coords(&m, "inner").all(|p| on(inner, p)));
            assert!(coords(&m, "outer").all(|p| on(outer, p)));
            for (set, up) in [("top_grip", true), ("bottom_grip", false)] {
                let pts: Vec<[f64; 3]> = coords(&m, set).collect();
                assert!(!pts.is_empty(), "{set}");
                assert!(pts
                    .iter()
                    .all(|p| on(outer, *p) && p[0].abs() <= 0.008 && (p[1] > 0.0) == up));
            }
        }
    }

    #[test]
    fn disk_quality_volume_and_sets() {
        let (r, t) = (0.01, 0.001);
        let mut last_error = f64::INFINITY;
        for (nq, nr) in [(2, 1), (4, 4), (8, 4), (16, 8)] {
            let m = disk(r, t, nq, nr);
            check_mesh(&m, &["curved", "front", "back"], r);
            assert_eq!(m.num_cells(), nq * nq + 4 * nq * nr);
            assert!(min_ratio(&m) >= 0.8, "({nq},{nr}): {}", min_ratio(&m));
            assert!(m.nodes.iter().all(|p| p[2] == 0.0 || p[2] == t));
            // The rim is an inscribed 4nq-gon: the area deficit is exactly the polygon's.
            let sides = 4 * nq;
            assert_eq!(m.face_sets["curved"].len(), sides);
            let error = 1.0 - volume(&m) / (PI * r * r * t);
            assert!(
                (error - polygon_deficit(sides)).abs() < 1e-12,
                "({nq},{nr})"
            );
            assert!(error > 0.0 && error < last_error);
            last_error = error;
            assert!(coords(&m, "curved").all(|p| (p[0].hypot(p[1]) - r).abs() <= 1e-12 * r));
            assert!(coords(&m, "front").all(|p| p[2] == t));
            assert!(coords(&m, "back").all(|p| p[2] == 0.0));
            for (set, y) in [("center", 0.0), ("top_point", r), ("bottom_point", -r)] {
                let pts: Vec<[f64; 3]> = coords(&m, set).collect();
                assert_eq!(pts.len(), 2, "{set}");
                assert!(
                    pts.iter().all(|p| p[0] == 0.0 && p[1] == y),
                    "{set}: {pts:?}"
                );
            }
        }
    }

    #[test]
    fn disk_rounds_odd_n_quarter_up() {
        let odd = disk(1.0, 0.1, 3, 2);
        let even = disk(1.0, 0.1, 4, 2);
        assert_eq!(odd.num_cells(), even.num_cells());
        assert_eq!(odd.face_sets["curved"].len(), 16);
        assert_eq!(disk(1.0, 0.1, 1, 1).face_sets["curved"].len(), 8);
    }

    #[test]
    fn half_disk_quality_volume_and_sets() {
        let (r, t) = (0.005, 0.002);
        for side in [FlatSide::Top, FlatSide::Bottom] {
            let (alias, sign) = match side {
                FlatSide::Top => ("top", -1.0),
                FlatSide::Bottom => ("bottom", 1.0),
            };
            let mut last_error = f64::INFINITY;
            for (nq, nr) in [(2, 2), (4, 4), (8, 4), (16, 8)] {
                let m = half_disk(r, t, nq, nr, side);
                check_mesh(&m, &["flat", "curved", "front", "back"], r);
                assert_eq!(m.num_cells(), disk(r, t, nq, nr).num_cells() / 2);
                assert!(min_ratio(&m) >= 0.8, "{side:?} ({nq},{nr})");
                assert!(m.nodes.iter().all(|p| sign * p[1] >= 0.0));
                assert_eq!(m.face_sets[alias], m.face_sets["flat"]);
                assert_eq!(m.node_sets[alias], m.node_sets["flat"]);
                let other = if alias == "top" { "bottom" } else { "top" };
                assert!(!m.face_sets.contains_key(other));
                let sides = 4 * nq;
                let error = 1.0 - volume(&m) / (0.5 * PI * r * r * t);
                assert!((error - polygon_deficit(sides)).abs() < 1e-12);
                assert!(error > 0.0 && error < last_error);
                last_error = error;
                assert!(coords(&m, "curved").all(|p| (p[0].hypot(p[1]) - r).abs() <= 1e-12 * r));
                assert!(coords(&m, "flat").all(|p| p[1] == 0.0));
                assert_eq!(m.face_sets["flat"].len(), nq + 2 * nr);
                for (set, y) in [("apex", sign * r), ("center", 0.0)] {
                    let pts: Vec<[f64; 3]> = coords(&m, set).collect();
                    assert_eq!(pts.len(), 2, "{set}");
                    assert!(pts.iter().all(|p| p[0] == 0.0 && p[1] == y), "{set}");
                }
            }
        }
    }

    #[test]
    fn quarter_hemisphere_quality_volume_and_sets() {
        let r = 0.01;
        let mut last_error = f64::INFINITY;
        for n in [1, 2, 4, 8] {
            let m = quarter_hemisphere(r, n);
            check_mesh(&m, &["flat", "curved", "sym_x", "sym_z"], r);
            assert_eq!(m.num_cells(), 4 * n * n * n);
            assert!(min_ratio(&m) >= 0.65, "n = {n}: {}", min_ratio(&m));
            assert!(m
                .nodes
                .iter()
                .all(|p| p[0] >= 0.0 && p[1] <= 0.0 && p[2] >= 0.0));
            assert_eq!(m.face_sets["top"], m.face_sets["flat"]);
            assert!(coords(&m, "curved").all(|p| (norm(p) - r).abs() <= 1e-12 * r));
            assert!(coords(&m, "flat").all(|p| p[1] == 0.0));
            assert!(coords(&m, "sym_x").all(|p| p[0] == 0.0));
            assert!(coords(&m, "sym_z").all(|p| p[2] == 0.0));
            assert_eq!(m.face_sets["curved"].len(), 3 * n * n);
            let apex: Vec<[f64; 3]> = coords(&m, "apex").collect();
            assert_eq!(apex, vec![[0.0, -r, 0.0]]);
            let center: Vec<[f64; 3]> = coords(&m, "center").collect();
            assert_eq!(center, vec![[0.0, 0.0, 0.0]]);
            // Every curved face has its nodes on the sphere within a cap of half angle θ, so
            // the faceted body lies between the spheres of radius R cos θ and R.
            let max_cap = m.face_sets["curved"]
                .iter()
                .map(|f| {
                    let ps: Vec<[f64; 3]> = f.nodes().iter().map(|&i| m.nodes[i]).collect();
                    let mut c = [0.0; 3];
                    for p in &ps {
                        (0..3).for_each(|k| c[k] += p[k]);
                    }
                    let cn = norm(c);
                    ps.iter()
                        .map(|p| ((0..3).map(|k| p[k] * c[k]).sum::<f64>() / (cn * r)).acos())
                        .fold(0.0, f64::max)
                })
                .fold(0.0, f64::max);
            let exact = PI * r * r * r / 6.0;
            let error = 1.0 - volume(&m) / exact;
            let bound = 1.0 - max_cap.cos().powi(3);
            assert!(error > 0.0 && error <= bound, "n = {n}: {error} vs {bound}");
            assert!(error < last_error);
            last_error = error;
        }
    }

    #[test]
    #[should_panic(expected = "half_disk: n_radial must be at least 1")]
    fn half_disk_rejects_zero_radial_count() {
        half_disk(1.0, 0.1, 4, 0, FlatSide::Top);
    }

    #[test]
    fn extreme_aspect_ratios_keep_sets_apart() {
        let m = disk(1.0, 1e-12, 4, 2);
        check_mesh(&m, &["curved", "front", "back"], 1e-7);
        assert_eq!(m.face_sets["front"].len(), m.num_cells());
        let m = block([1e3, 1e-6, 1.0], [2, 3, 1]);
        let names = ["left", "right", "bottom", "top", "back", "front"];
        check_mesh(&m, &names, 1e-8);
        assert_eq!(m.face_sets["top"].len(), 2);
    }

    #[test]
    fn test_helper_finds_duplicate_nodes() {
        let nodes = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0 + 1e-9, 0.0, 0.0]];
        assert_eq!(close_node_pairs(&nodes, 1e-6), vec![(1, 2)]);
    }

    #[test]
    fn node_merger_merges_within_tolerance_only() {
        let mut merger = NodeMerger::new(1e-6);
        let a = merger.insert([1.0, 2.0, 3.0]);
        let b = merger.insert([1.0 + 5e-7, 2.0 - 5e-7, 3.0]);
        let c = merger.insert([1.0 + 2e-6, 2.0, 3.0]);
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(merger.into_nodes().len(), 2);
    }
}
