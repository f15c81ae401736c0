//! The quadratic 20-node (serendipity) hexahedron with 3×3×3 Gauss points.
//!
//! Nodes in VTK order (VTK_QUADRATIC_HEXAHEDRON): the corners 0-7 as for the hex8, then the
//! mid-edge nodes of the edges 0-1, 1-2, 2-3, 3-0 (face ζ = −1), 4-5, 5-6, 6-7, 7-4 (face
//! ζ = +1) and 0-4, 1-5, 2-6, 3-7 (the vertical edges). Gmsh lists the mid-edge nodes by
//! corner pairs in another order (0-1, 0-3, 0-4, 1-2, 1-5, 2-3, 2-6, 3-7, 4-5, 4-7, 5-6,
//! 6-7): [`HEX20`]'s `gmsh_nodes` maps it. With ξ_a the node's natural coordinates, the shape
//! functions are ⅛ (1 + ξξ_a)(1 + ηη_a)(1 + ζζ_a)(ξξ_a + ηη_a + ζζ_a − 2) at a corner and
//! ¼ (1 − ξ²)(1 + ηη_a)(1 + ζζ_a) at the middle of an edge along ξ (likewise along η, ζ).
//!
//! The 3×3×3 rule is exact to degree 5 in each coordinate: the stiffness and the consistent
//! mass (products N_a N_b, degree 4 in each coordinate) of a parallelepiped element are
//! integrated exactly (the usual C3D20; the reduced 2×2×2 rule would leave hourglass modes).
//!
//! The faces are eight-node quadrilaterals ([`QUAD8`]).

use super::face::{
    gauss_newton_projection, onto_square, square_quadrature, FaceProjection, FaceType, LocalFace,
};
use super::hex8::HEX_CORNER_FRAMES;
use super::{DegenerateElement, Element, ElementType, GaussPoint, Lumping, Stabilisation};
use crate::Vec3;

/// The edges of the mid-edge nodes 8..19, by their end corners (VTK order).
pub const HEX20_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [4, 5],
    [5, 6],
    [6, 7],
    [7, 4],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// Natural coordinates of the hex20 nodes (VTK order).
pub const HEX20_NODE_XI: [[f64; 3]; 20] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// The hex20 row of the element-type table.
pub static HEX20: ElementType = ElementType {
    name: "hex20",
    nodes: 20,
    natural_nodes: &HEX20_NODE_XI,
    gauss_points: 27,
    gauss_rule: super::gauss_rule_of::<Hex20, 20, 27>,
    shape: super::shape_of::<Hex20, 20, 27>,
    // The hex8's faces, each followed by the mid-edge nodes of its edges in order.
    faces: &[
        quad8(&[0, 3, 2, 1, 11, 10, 9, 8]),   // ζ = −1
        quad8(&[4, 5, 6, 7, 12, 13, 14, 15]), // ζ = +1
        quad8(&[0, 1, 5, 4, 8, 17, 12, 16]),  // η = −1
        quad8(&[2, 3, 7, 6, 10, 19, 14, 18]), // η = +1
        quad8(&[0, 4, 7, 3, 16, 15, 19, 11]), // ξ = −1
        quad8(&[1, 2, 6, 5, 9, 18, 13, 17]),  // ξ = +1
    ],
    corner_frames: &HEX_CORNER_FRAMES,
    inverted_inside: |x| {
        let x: &[[f64; 3]; 20] = x.try_into().expect("a hex20 has 20 nodes");
        hex20_inverted(x)
    },
    vtk_type: 25,
    gmsh_type: 17,
    gmsh_nodes: &[
        0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15,
    ],
};

/// A hex20 face with local nodes `nodes`.
const fn quad8(nodes: &'static [usize]) -> LocalFace {
    LocalFace {
        face_type: &QUAD8,
        nodes,
    }
}

/// The hex20 element at compile time.
pub struct Hex20;

impl Element<20, 27> for Hex20 {
    const TYPE: &'static ElementType = &HEX20;
    const STABILISATION: Stabilisation = Stabilisation::LinearDilatation;
    /// The row sums would give the corners −ρV/8 each (for a parallelepiped).
    const LUMPING: Lumping = Lumping::DiagonalScaling;

    fn shape(xi: [f64; 3]) -> ([f64; 20], [[f64; 3]; 20]) {
        hex20_shape(xi)
    }

    fn gauss_rule() -> [([f64; 3], f64); 27] {
        let g = 0.6f64.sqrt();
        let line = [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)];
        std::array::from_fn(|q| {
            let (x, wx) = line[q % 3];
            let (y, wy) = line[(q / 3) % 3];
            let (z, wz) = line[q / 9];
            ([x, y, z], wx * wy * wz)
        })
    }
}

/// Hex20 shape functions and natural derivatives at ξ (VTK node order).
pub fn hex20_shape(xi: [f64; 3]) -> ([f64; 20], [[f64; 3]; 20]) {
    let mut n = [0.0; 20];
    let mut dn = [[0.0; 3]; 20];
    for (a, xa) in HEX20_NODE_XI.iter().enumerate() {
        // f_k = 1 + ξ_k ξ_a,k along the axes where the node is at ±1.
        let f: [f64; 3] = std::array::from_fn(|k| 1.0 + xi[k] * xa[k]);
        if a < 8 {
            let s = xi[0] * xa[0] + xi[1] * xa[1] + xi[2] * xa[2] - 2.0;
            n[a] = 0.125 * f[0] * f[1] * f[2] * s;
            dn[a] = std::array::from_fn(|k| {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                0.125 * xa[k] * f[i] * f[j] * (s + f[k])
            });
        } else {
            // The axis m along which the edge runs (ξ_a,m = 0), the two others i, j.
            let m = (0..3).find(|&k| xa[k] == 0.0).expect("a mid-edge node");
            let (i, j) = ((m + 1) % 3, (m + 2) % 3);
            let g = 1.0 - xi[m] * xi[m];
            n[a] = 0.25 * g * f[i] * f[j];
            dn[a][m] = -0.5 * xi[m] * f[i] * f[j];
            dn[a][i] = 0.25 * g * xa[i] * f[j];
            dn[a][j] = 0.25 * g * f[i] * xa[j];
        }
    }
    (n, dn)
}

/// Whether a hex20 with node coordinates `x` [m] has a Jacobian determinant ≤ 0 at one of
/// its nodes or Gauss points: a curved element folded by the mesher, or a mid-edge node
/// moved too far along its edge.
pub fn hex20_inverted(x: &[[f64; 3]; 20]) -> bool {
    let points = HEX20_NODE_XI
        .iter()
        .copied()
        .chain(Hex20::gauss_rule().map(|(p, _)| p));
    points
        .map(|p| {
            let (n, dn) = hex20_shape(p);
            super::gauss_point(x, n, dn, 1.0)
        })
        .any(|g| g.is_err())
}

/// Gauss-point data of a hex20 with reference coordinates `x` [m].
pub fn hex20_geometry(x: &[[f64; 3]; 20]) -> Result<[GaussPoint<20>; 27], DegenerateElement> {
    Hex20::geometry(x)
}

/// The eight-node (serendipity) quadrilateral face of the hex20: corners counter-clockwise
/// seen from outside, then the mid-side nodes of the edges 0-1, 1-2, 2-3 and 3-0; natural
/// coordinates (ξ, η) ∈ [−1, 1]².
///
/// It is drawn and integrated on five flat pieces: at each corner the triangle of the corner
/// and the two mid-side nodes next to it, and in the middle the quadrilateral of the four
/// mid-side nodes (in natural coordinates a square turned by 45°). The pressure of mortar
/// contact is interpolated on them by their linear (bilinear) hat functions, which are
/// nonnegative on each piece and have positive integrals: a corner gets 1/24 of a flat
/// face's area, a mid-side node 5/24. The quadratic serendipity functions could not serve:
/// those of the corners are negative over most of the face and integrate to −1/12 of it.
pub static QUAD8: FaceType = FaceType {
    name: "quad8",
    debug_name: "Quad8",
    nodes: 8,
    corners: 4,
    natural_nodes: &QUAD8_NODE_XI,
    flat_pieces: &[
        &[0, 4, 7],
        &[4, 1, 5],
        &[5, 2, 6],
        &[7, 6, 3],
        &[4, 5, 6, 7],
    ],
    shape: |[xi, eta]| {
        let (n, dn) = quad8_shape(xi, eta);
        (n.to_vec(), dn.to_vec())
    },
    quadrature: || square_quadrature(3),
    vtk_type: 23,
    gmsh_type: 16,
    is_quadratic: true,
    project: project_on_quad8,
};

/// Natural coordinates (ξ, η) of the eight-node quadrilateral's nodes.
pub const QUAD8_NODE_XI: [[f64; 2]; 8] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
];

/// Shape functions of the eight-node quadrilateral at (ξ, η) and their derivatives along ξ
/// and η: ¼ (1 + ξξ_a)(1 + ηη_a)(ξξ_a + ηη_a − 1) at a corner, ½ (1 − ξ²)(1 + ηη_a) at the
/// middle of an edge along ξ (likewise along η).
pub fn quad8_shape(xi: f64, eta: f64) -> ([f64; 8], [[f64; 2]; 8]) {
    let mut n = [0.0; 8];
    let mut dn = [[0.0; 2]; 8];
    for (a, &[xa, ya]) in QUAD8_NODE_XI.iter().enumerate() {
        let (fx, fy) = (1.0 + xi * xa, 1.0 + eta * ya);
        if a < 4 {
            let s = xi * xa + eta * ya - 1.0;
            n[a] = 0.25 * fx * fy * s;
            dn[a] = [0.25 * xa * fy * (s + fx), 0.25 * ya * fx * (s + fy)];
        } else if xa == 0.0 {
            n[a] = 0.5 * (1.0 - xi * xi) * fy;
            dn[a] = [-xi * fy, 0.5 * (1.0 - xi * xi) * ya];
        } else {
            n[a] = 0.5 * (1.0 - eta * eta) * fx;
            dn[a] = [0.5 * (1.0 - eta * eta) * xa, -eta * fx];
        }
    }
    (n, dn)
}

/// Closest-point projection of `x` on an eight-node quadrilateral with nodes `p` [m] by
/// Gauss-Newton in its natural coordinates from the centre, kept in the square.
fn project_on_quad8(p: &[Vec3], x: Vec3) -> FaceProjection {
    gauss_newton_projection(p, x, QUAD8.shape, [0.0, 0.0], onto_square)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The derivatives of the shape functions match central differences (quadratic in
    /// each coordinate, cubic overall: truncation ~h² = 1e-8 times a third derivative of
    /// order 1, so 1e-7).
    #[test]
    fn hex20_derivatives_match_central_differences() {
        let (xi, h) = ([0.23, -0.41, 0.67], 1e-4);
        let (_, dn) = hex20_shape(xi);
        for k in 0..3 {
            let (mut p, mut m) = (xi, xi);
            p[k] += h;
            m[k] -= h;
            let (np, nm) = (hex20_shape(p).0, hex20_shape(m).0);
            for a in 0..20 {
                let fd = (np[a] - nm[a]) / (2.0 * h);
                assert!((dn[a][k] - fd).abs() < 1e-7, "node {a}, axis {k}");
            }
        }
    }

    /// Each mid-edge node sits at the middle of its edge's corners, and each face's
    /// mid-side nodes at the middles of the face's edges in order.
    #[test]
    fn mid_edge_nodes_are_on_their_edges() {
        for (m, [i, j]) in HEX20_EDGES.iter().enumerate() {
            let mid: [f64; 3] =
                std::array::from_fn(|k| 0.5 * (HEX20_NODE_XI[*i][k] + HEX20_NODE_XI[*j][k]));
            assert_eq!(mid, HEX20_NODE_XI[8 + m], "edge {i}-{j}");
        }
        for f in HEX20.faces {
            for e in 0..4 {
                let (a, b) = (f.nodes[e], f.nodes[(e + 1) % 4]);
                let mid: [f64; 3] =
                    std::array::from_fn(|k| 0.5 * (HEX20_NODE_XI[a][k] + HEX20_NODE_XI[b][k]));
                assert_eq!(mid, HEX20_NODE_XI[f.nodes[4 + e]], "face {:?}", f.nodes);
            }
        }
    }

    /// A mid-edge node moved to within a quarter of its edge's length of a corner makes
    /// the Jacobian vanish at that corner: the straight element is valid, the distorted one
    /// not.
    #[test]
    fn a_mid_edge_node_past_the_quarter_point_inverts_the_element() {
        let mut x: [[f64; 3]; 20] = HEX20_NODE_XI;
        assert!(!hex20_inverted(&x));
        x[8] = [-0.6, -1.0, -1.0];
        assert!(hex20_inverted(&x));
    }
}
