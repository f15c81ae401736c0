//! Face types: the boundary faces of the element types, each described once.
//!
//! A [`FaceType`] is to a cell face what an [`super::ElementType`] is to a cell: a static
//! description (its nodes, shape functions on its natural coordinates, a surface quadrature,
//! the flat pieces it is drawn and integrated on, its closest-point projection). Each element
//! type names the type of each of its faces ([`LocalFace`]); a mesh face is a face type and
//! its node indices ([`crate::mesh::Face`]). Code that treats faces asks their type, so a new
//! face type is one static with its functions, next to the element type it comes from:
//! quad4 (`hex8.rs`), tri3 (`tet4.rs`), tri6 (`tet10.rs`), quad8 (`hex20.rs`), quad9
//! (`hex27.rs`).

use crate::Vec3;

/// The largest node count of a face type (the nine-node quadrilateral).
pub const MAX_FACE_NODES: usize = 9;

/// Shape functions N_a and their derivatives (∂N_a/∂ξ, ∂N_a/∂η) at one point of a face's
/// natural coordinates, one entry per node.
pub type FaceShapeValues = (Vec<f64>, Vec<[f64; 2]>);

/// A closest-point projection on a face: the point [m], the face's unit normal there
/// (right-hand rule over the face's node order: outward on a boundary face) and the nodal
/// weights (the face's shape functions at the point).
pub type FaceProjection = ([f64; 3], [f64; 3], Vec<f64>);

/// One face type.
pub struct FaceType {
    /// Name, e.g. `"quad4"` (in messages).
    pub name: &'static str,
    /// The name a face of this type shows in its `Debug` form, as `Quad([0, 1, 2, 3])`: the
    /// `Debug` form of meshes and contact pairs is the checkpoint fingerprint of a problem,
    /// so the faces of the first face types keep the form they had.
    pub debug_name: &'static str,
    /// Number of nodes.
    pub nodes: usize,
    /// Number of corner nodes: the first `corners` nodes, counter-clockwise seen from
    /// outside; the others are mid-side nodes.
    pub corners: usize,
    /// Natural coordinates (ξ, η) of the nodes: the unit triangle ξ, η ≥ 0, ξ + η ≤ 1 for
    /// triangles, the square [−1, 1]² for quadrilaterals.
    pub natural_nodes: &'static [[f64; 2]],
    /// The flat pieces the face is drawn and integrated on (by mortar contact and the
    /// tributary areas), each a triangle or a quadrilateral counter-clockwise seen from
    /// outside, as positions in the face's node list: the face itself when it is linear.
    pub flat_pieces: &'static [&'static [usize]],
    /// Shape functions and their natural derivatives at (ξ, η).
    pub shape: fn(xi: [f64; 2]) -> FaceShapeValues,
    /// A surface quadrature: natural coordinates and weights (natural area) of its points.
    pub quadrature: fn() -> Vec<([f64; 2], f64)>,
    /// VTK cell type number for drawing the face.
    pub vtk_type: u8,
    /// Gmsh element type number (MSH 4.1) of the face as a surface element; Gmsh lists its
    /// nodes in the face type's order.
    pub gmsh_type: i32,
    /// Whether the face is of second order (has mid-side nodes).
    pub is_quadratic: bool,
    /// The closest point to `x` [m] on the face with node positions `p` [m], kept on the
    /// face.
    pub project: fn(p: &[Vec3], x: Vec3) -> FaceProjection,
}

/// The type's name: the `Debug` form must not depend on where its functions sit in memory.
impl std::fmt::Debug for FaceType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

impl PartialEq for FaceType {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for FaceType {}

impl std::hash::Hash for FaceType {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name.hash(state);
    }
}

impl FaceType {
    /// The face types of the element types of [`super::ELEMENT_TYPES`], each once, in the
    /// order of the table (quad4, tri3, tri6, quad8, quad9).
    pub fn all() -> Vec<&'static FaceType> {
        let mut out: Vec<&'static FaceType> = Vec::new();
        for t in super::ELEMENT_TYPES {
            for f in t.faces {
                if !out.contains(&f.face_type) {
                    out.push(f.face_type);
                }
            }
        }
        out
    }

    /// The face type of Gmsh element type number `gmsh_type`, if adhesim has it.
    pub fn from_gmsh(gmsh_type: i32) -> Option<&'static FaceType> {
        FaceType::all()
            .into_iter()
            .find(|t| t.gmsh_type == gmsh_type)
    }

    /// Whether the face's shape functions at a point of piece `piece` are the piece's own
    /// linear (bilinear) weights: the piece is the whole face.
    pub fn piece_is_face(&self, piece: &[usize]) -> bool {
        piece.len() == self.nodes
    }

    /// The face's shape functions (one per node) at the point of its flat piece `piece`
    /// (positions in the face's nodes) where the piece's own linear or bilinear weights are
    /// `w`: the piece's weights interpolate the natural coordinates of its corners.
    pub fn shape_on_piece(&self, piece: &[usize], w: Vec<f64>) -> Vec<f64> {
        if self.piece_is_face(piece) {
            return w;
        }
        let xi = |c: usize| self.natural_nodes[piece[c]];
        let at = |k: usize| {
            let mut s = w[0] * xi(0)[k];
            for c in 1..piece.len() {
                s += w[c] * xi(c)[k];
            }
            s
        };
        (self.shape)([at(0), at(1)]).0
    }
}

/// A face of an element type: its face type and the cell's local nodes, in the face type's
/// order (corners counter-clockwise seen from outside the cell, then mid-side nodes).
#[derive(Clone, Copy, Debug)]
pub struct LocalFace {
    /// The face's type.
    pub face_type: &'static FaceType,
    /// Local node indices in the cell.
    pub nodes: &'static [usize],
}

impl LocalFace {
    /// The face's corner nodes (local indices).
    pub fn corners(&self) -> &'static [usize] {
        &self.nodes[..self.face_type.corners]
    }
}

/// The closest point to `x` on the face with node positions `p` and shape functions
/// `shape`, by Gauss-Newton on ‖x − x(ξ, η)‖² from natural point `start`, each step's point
/// moved back onto the face by `keep_on_face` (at most 20 steps, stopping when a step moves
/// less than 1e-12 in natural coordinates).
pub fn gauss_newton_projection(
    p: &[Vec3],
    x: Vec3,
    shape: fn([f64; 2]) -> FaceShapeValues,
    start: [f64; 2],
    keep_on_face: fn(f64, f64) -> (f64, f64),
) -> FaceProjection {
    let eval = |a: f64, b: f64| {
        let (w, dw) = shape([a, b]);
        let comb = |c: &dyn Fn(usize) -> f64| -> Vec3 { (0..p.len()).map(|i| c(i) * p[i]).sum() };
        let (xm, ta, tb) = (comb(&|i| w[i]), comb(&|i| dw[i][0]), comb(&|i| dw[i][1]));
        (w, xm, ta, tb)
    };
    let [mut a, mut b] = start;
    for _ in 0..20 {
        let (_, xm, ta, tb) = eval(a, b);
        let r = x - xm;
        let (g1, g2) = (r.dot(&ta), r.dot(&tb));
        let (m11, m12, m22) = (ta.dot(&ta), ta.dot(&tb), tb.dot(&tb));
        let det = m11 * m22 - m12 * m12;
        if !(det > 0.0) {
            break;
        }
        let da = (m22 * g1 - m12 * g2) / det;
        let db = (m11 * g2 - m12 * g1) / det;
        let (a0, b0) = (a, b);
        (a, b) = keep_on_face(a + da, b + db);
        if (a - a0).abs() + (b - b0).abs() < 1e-12 {
            break;
        }
    }
    let (w, xm, ta, tb) = eval(a, b);
    let n = unit(ta.cross(&tb));
    (xm.into(), n.into(), w)
}

/// The point (ξ, η) moved onto the unit triangle: negative coordinates to 0, then scaled
/// back to ξ + η = 1 when beyond.
pub fn onto_triangle(a: f64, b: f64) -> (f64, f64) {
    let (a, b) = (a.max(0.0), b.max(0.0));
    if a + b > 1.0 {
        let s = a + b;
        (a / s, b / s)
    } else {
        (a, b)
    }
}

/// The point (ξ, η) clamped to the square [−1, 1]².
pub fn onto_square(a: f64, b: f64) -> (f64, f64) {
    (a.clamp(-1.0, 1.0), b.clamp(-1.0, 1.0))
}

/// `a` scaled to unit length; e_y for the zero vector.
pub(crate) fn unit(a: Vec3) -> Vec3 {
    let n = a.norm();
    if n > 0.0 {
        a / n
    } else {
        Vec3::y()
    }
}

/// The 3-point rule on the unit triangle, exact to degree 2: natural coordinates and
/// weights (natural area 1/2).
pub fn triangle_quadrature() -> Vec<([f64; 2], f64)> {
    let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
    vec![
        ([a, a], 1.0 / 6.0),
        ([b, a], 1.0 / 6.0),
        ([a, b], 1.0 / 6.0),
    ]
}

/// The n × n Gauss-Legendre rule on the square [−1, 1]² (n = 2 or 3), exact to degree
/// 2n − 1 in each coordinate: natural coordinates and weights (natural area 4).
pub fn square_quadrature(n: usize) -> Vec<([f64; 2], f64)> {
    let line: Vec<(f64, f64)> = match n {
        2 => {
            let g = 1.0 / 3f64.sqrt();
            vec![(-g, 1.0), (g, 1.0)]
        }
        _ => {
            let g = 0.6f64.sqrt();
            vec![(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)]
        }
    };
    let mut out = Vec::with_capacity(n * n);
    for &(y, wy) in &line {
        for &(x, wx) in &line {
            out.push(([x, y], wx * wy));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::ELEMENT_TYPES;
    use super::*;

    /// Every face type of the element table: its shape functions interpolate its nodes
    /// (δ_ab), add up to 1 with derivatives adding up to 0 and matching central differences
    /// (polynomials of degree ≤ 2 in each coordinate: exact to round-off, 1e-9 with a step of
    /// 1e-4); its quadrature weights add up to the natural area (the area of its flat pieces
    /// in natural coordinates); its projection of a node's position returns that node.
    #[test]
    fn face_types_are_consistent() {
        let types = ELEMENT_TYPES
            .iter()
            .flat_map(|t| t.faces.iter().map(|f| f.face_type));
        for ft in types {
            assert_eq!(ft.natural_nodes.len(), ft.nodes, "{}", ft.name);
            for (b, xb) in ft.natural_nodes.iter().enumerate() {
                let (n, dn) = (ft.shape)(*xb);
                assert_eq!((n.len(), dn.len()), (ft.nodes, ft.nodes));
                for (a, na) in n.iter().enumerate() {
                    let delta = if a == b { 1.0 } else { 0.0 };
                    assert!(
                        (na - delta).abs() < 1e-14,
                        "{}: N_{a}(ξ_{b}) = {na}",
                        ft.name
                    );
                }
            }
            let (x, y, h) = (0.23, 0.31, 1e-4);
            let (n, dn) = (ft.shape)([x, y]);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14, "{}", ft.name);
            let (np, nm) = ((ft.shape)([x + h, y]).0, (ft.shape)([x - h, y]).0);
            let (nq, nr) = ((ft.shape)([x, y + h]).0, (ft.shape)([x, y - h]).0);
            for a in 0..ft.nodes {
                assert!(
                    (dn[a][0] - (np[a] - nm[a]) / (2.0 * h)).abs() < 1e-9,
                    "{}",
                    ft.name
                );
                assert!(
                    (dn[a][1] - (nq[a] - nr[a]) / (2.0 * h)).abs() < 1e-9,
                    "{}",
                    ft.name
                );
            }
            let area: f64 = ft
                .flat_pieces
                .iter()
                .map(|piece| {
                    let q: Vec<[f64; 2]> = piece.iter().map(|&c| ft.natural_nodes[c]).collect();
                    let m = q.len();
                    0.5 * (0..m)
                        .map(|i| q[i][0] * q[(i + 1) % m][1] - q[(i + 1) % m][0] * q[i][1])
                        .sum::<f64>()
                })
                .sum();
            let weights: f64 = (ft.quadrature)().iter().map(|(_, w)| w).sum();
            assert!(
                (weights - area).abs() < 1e-14,
                "{}: {weights} {area}",
                ft.name
            );
            // A curved face: the natural coordinates as x, y and a bump as z.
            let p: Vec<Vec3> = ft
                .natural_nodes
                .iter()
                .map(|q| Vec3::new(q[0], q[1], 0.1 * q[0] * q[1]))
                .collect();
            for (b, pb) in p.iter().enumerate() {
                let (xm, _, w) = (ft.project)(&p, *pb);
                assert!(
                    (Vec3::from(xm) - pb).norm() < 1e-12,
                    "{}: node {b}",
                    ft.name
                );
                assert!((w[b] - 1.0).abs() < 1e-9, "{}: node {b}: {w:?}", ft.name);
            }
        }
    }
}
