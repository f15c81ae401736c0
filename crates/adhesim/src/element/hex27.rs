//! The triquadratic 27-node (Lagrange) hexahedron with 3×3×3 Gauss points.
//!
//! Nodes in VTK order (VTK_TRIQUADRATIC_HEXAHEDRON, cell type 29): the hex20's twenty (the
//! corners, then the mid-edge nodes of [`HEX20_EDGES`]), then the centres of the faces
//! ξ = −1, ξ = +1, η = −1, η = +1, ζ = −1, ζ = +1, then the element's centre. Gmsh (type 12)
//! lists the mid-edge nodes as for its hex20 and the face centres in the order ζ = −1,
//! η = −1, ξ = −1, ξ = +1, η = +1, ζ = +1: [`HEX27`]'s `gmsh_nodes` maps both. The shape
//! functions are the products ℓ_a(ξ) ℓ_b(η) ℓ_c(ζ) of the 1-D quadratic Lagrange polynomials
//! ℓ₋(s) = s(s − 1)/2, ℓ₀(s) = 1 − s², ℓ₊(s) = s(s + 1)/2.
//!
//! The 3×3×3 rule is exact to degree 5 in each coordinate: the stiffness of a straight-sided
//! element (degree 4 per coordinate after the cofactors of a trilinear map) and the
//! consistent mass of a parallelepiped (N_a N_b, degree 4) are integrated exactly. The
//! locking-free option is the hex20's volume change linear in the element
//! ([`crate::dilatation`]): on the 27-node brick, Q2/P1 is the classic inf-sup stable pair.
//! The lumped mass is the row sums (the default [`super::Lumping`]): for a tensor-product
//! Lagrange element they are the products of the 1-D Simpson weights (1/6, 2/3, 1/6 of each
//! side), all positive, i.e. the nodal Gauss-Lobatto quadrature.
//!
//! The faces are nine-node quadrilaterals ([`QUAD9`]).

use super::face::{
    gauss_newton_projection, onto_square, square_quadrature, FaceProjection, FaceType, LocalFace,
};
use super::hex20::HEX20_NODE_XI;
use super::hex8::HEX_CORNER_FRAMES;
use super::{DegenerateElement, Element, ElementType, GaussPoint, Stabilisation};
use crate::Vec3;

/// Natural coordinates of the hex27 nodes (VTK order).
pub const HEX27_NODE_XI: [[f64; 3]; 27] = {
    let mut x = [[0.0; 3]; 27];
    let mut a = 0;
    while a < 20 {
        x[a] = HEX20_NODE_XI[a];
        a += 1;
    }
    x[20] = [-1.0, 0.0, 0.0];
    x[21] = [1.0, 0.0, 0.0];
    x[22] = [0.0, -1.0, 0.0];
    x[23] = [0.0, 1.0, 0.0];
    x[24] = [0.0, 0.0, -1.0];
    x[25] = [0.0, 0.0, 1.0];
    x[26] = [0.0, 0.0, 0.0];
    x
};

/// The hex27 row of the element-type table.
pub static HEX27: ElementType = ElementType {
    name: "hex27",
    nodes: 27,
    natural_nodes: &HEX27_NODE_XI,
    gauss_points: 27,
    gauss_rule: super::gauss_rule_of::<Hex27, 27, 27>,
    shape: super::shape_of::<Hex27, 27, 27>,
    // The hex20's faces, each followed by its centre.
    faces: &[
        quad9(&[0, 3, 2, 1, 11, 10, 9, 8, 24]),   // ζ = −1
        quad9(&[4, 5, 6, 7, 12, 13, 14, 15, 25]), // ζ = +1
        quad9(&[0, 1, 5, 4, 8, 17, 12, 16, 22]),  // η = −1
        quad9(&[2, 3, 7, 6, 10, 19, 14, 18, 23]), // η = +1
        quad9(&[0, 4, 7, 3, 16, 15, 19, 11, 20]), // ξ = −1
        quad9(&[1, 2, 6, 5, 9, 18, 13, 17, 21]),  // ξ = +1
    ],
    corner_frames: &HEX_CORNER_FRAMES,
    inverted_inside: |x| {
        let x: &[[f64; 3]; 27] = x.try_into().expect("a hex27 has 27 nodes");
        hex27_inverted(x)
    },
    vtk_type: 29,
    gmsh_type: 12,
    gmsh_nodes: &[
        0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20,
        25, 26,
    ],
};

/// A hex27 face with local nodes `nodes`.
const fn quad9(nodes: &'static [usize]) -> LocalFace {
    LocalFace {
        face_type: &QUAD9,
        nodes,
    }
}

/// The hex27 element at compile time.
pub struct Hex27;

impl Element<27, 27> for Hex27 {
    const TYPE: &'static ElementType = &HEX27;
    const STABILISATION: Stabilisation = Stabilisation::LinearDilatation;

    fn shape(xi: [f64; 3]) -> ([f64; 27], [[f64; 3]; 27]) {
        hex27_shape(xi)
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

/// The 1-D quadratic Lagrange polynomial of the node at `c` ∈ {−1, 0, 1} and its derivative
/// at s.
fn lagrange(c: f64, s: f64) -> (f64, f64) {
    if c < -0.5 {
        (0.5 * s * (s - 1.0), s - 0.5)
    } else if c > 0.5 {
        (0.5 * s * (s + 1.0), s + 0.5)
    } else {
        (1.0 - s * s, -2.0 * s)
    }
}

/// Hex27 shape functions and natural derivatives at ξ (VTK node order).
pub fn hex27_shape(xi: [f64; 3]) -> ([f64; 27], [[f64; 3]; 27]) {
    let mut n = [0.0; 27];
    let mut dn = [[0.0; 3]; 27];
    for (a, xa) in HEX27_NODE_XI.iter().enumerate() {
        let l: [(f64, f64); 3] = std::array::from_fn(|k| lagrange(xa[k], xi[k]));
        n[a] = l[0].0 * l[1].0 * l[2].0;
        dn[a] = [
            l[0].1 * l[1].0 * l[2].0,
            l[0].0 * l[1].1 * l[2].0,
            l[0].0 * l[1].0 * l[2].1,
        ];
    }
    (n, dn)
}

/// Whether a hex27 with node coordinates `x` [m] has a Jacobian determinant ≤ 0 at one of
/// its nodes or Gauss points (a curved element folded by the mesher, a mid-edge or face node
/// moved too far).
pub fn hex27_inverted(x: &[[f64; 3]; 27]) -> bool {
    HEX27_NODE_XI
        .iter()
        .copied()
        .chain(Hex27::gauss_rule().map(|(p, _)| p))
        .map(|p| {
            let (n, dn) = hex27_shape(p);
            super::gauss_point(x, n, dn, 1.0)
        })
        .any(|g| g.is_err())
}

/// Gauss-point data of a hex27 with reference coordinates `x` [m].
pub fn hex27_geometry(x: &[[f64; 3]; 27]) -> Result<[GaussPoint<27>; 27], DegenerateElement> {
    Hex27::geometry(x)
}

/// The nine-node (Lagrange) quadrilateral face of the hex27: corners counter-clockwise seen
/// from outside, the mid-side nodes of the edges 0-1, 1-2, 2-3 and 3-0, then the centre
/// (the same order in Gmsh, type 10, and VTK, VTK_BIQUADRATIC_QUAD = 28); natural
/// coordinates (ξ, η) ∈ [−1, 1]².
///
/// It is drawn and integrated on its four quarters (corner, mid-side, centre, mid-side),
/// whose bilinear hat functions are nonnegative with positive integrals (a corner 1/16 of a
/// flat face's area, a mid-side node 1/8, the centre 1/4), as the quad8's five pieces are.
/// (Its own corner functions are not positive either: they integrate to 1/36 of the face but
/// change sign.)
pub static QUAD9: FaceType = FaceType {
    name: "quad9",
    debug_name: "Quad9",
    nodes: 9,
    corners: 4,
    natural_nodes: &QUAD9_NODE_XI,
    flat_pieces: &[&[0, 4, 8, 7], &[4, 1, 5, 8], &[8, 5, 2, 6], &[7, 8, 6, 3]],
    shape: |[xi, eta]| {
        let (n, dn) = quad9_shape(xi, eta);
        (n.to_vec(), dn.to_vec())
    },
    quadrature: || square_quadrature(3),
    vtk_type: 28,
    gmsh_type: 10,
    is_quadratic: true,
    project: project_on_quad9,
};

/// Natural coordinates (ξ, η) of the nine-node quadrilateral's nodes.
pub const QUAD9_NODE_XI: [[f64; 2]; 9] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
];

/// Shape functions of the nine-node quadrilateral at (ξ, η), ℓ_a(ξ) ℓ_b(η), and their
/// derivatives along ξ and η.
pub fn quad9_shape(xi: f64, eta: f64) -> ([f64; 9], [[f64; 2]; 9]) {
    let mut n = [0.0; 9];
    let mut dn = [[0.0; 2]; 9];
    for (a, &[xa, ya]) in QUAD9_NODE_XI.iter().enumerate() {
        let ((lx, dlx), (ly, dly)) = (lagrange(xa, xi), lagrange(ya, eta));
        n[a] = lx * ly;
        dn[a] = [dlx * ly, lx * dly];
    }
    (n, dn)
}

/// Closest-point projection of `x` on a nine-node quadrilateral with nodes `p` [m] by
/// Gauss-Newton in its natural coordinates from the centre, kept in the square.
fn project_on_quad9(p: &[Vec3], x: Vec3) -> FaceProjection {
    gauss_newton_projection(p, x, QUAD9.shape, [0.0, 0.0], onto_square)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The derivatives of the shape functions match central differences.
    #[test]
    fn hex27_and_quad9_derivatives_match_central_differences() {
        let (xi, h) = ([0.23, -0.41, 0.67], 1e-4);
        let (_, dn) = hex27_shape(xi);
        for k in 0..3 {
            let (mut p, mut m) = (xi, xi);
            p[k] += h;
            m[k] -= h;
            let (np, nm) = (hex27_shape(p).0, hex27_shape(m).0);
            for a in 0..27 {
                let fd = (np[a] - nm[a]) / (2.0 * h);
                assert!((dn[a][k] - fd).abs() < 1e-7, "node {a}, axis {k}");
            }
        }
        let (_, dn) = quad9_shape(0.3, -0.7);
        for k in 0..2 {
            let d = [h * (1 - k) as f64, h * k as f64];
            let np = quad9_shape(0.3 + d[0], -0.7 + d[1]).0;
            let nm = quad9_shape(0.3 - d[0], -0.7 - d[1]).0;
            for a in 0..9 {
                assert!((dn[a][k] - (np[a] - nm[a]) / (2.0 * h)).abs() < 1e-7);
            }
        }
    }

    /// The node order is VTK's: the natural coordinates of VTK 9.3's
    /// vtkTriQuadraticHexahedron (its parametric coordinates mapped from [0, 1] to [−1, 1])
    /// past the hex20's nodes are the centres of the faces ξ = ∓1, η = ∓1, ζ = ∓1, then the
    /// centre; and the `gmsh_nodes` map takes Gmsh 4.15's reference hexahedron of 27 nodes
    /// (`getElementProperties(12)`) onto them.
    #[test]
    fn node_orders_are_vtk_and_gmsh() {
        let gmsh: [[f64; 3]; 27] = [
            [-1.0, -1.0, -1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
            [0.0, -1.0, -1.0],
            [-1.0, 0.0, -1.0],
            [-1.0, -1.0, 0.0],
            [1.0, 0.0, -1.0],
            [1.0, -1.0, 0.0],
            [0.0, 1.0, -1.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [0.0, -1.0, 1.0],
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.0, -1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0],
        ];
        for (a, &g) in HEX27.gmsh_nodes.iter().enumerate() {
            assert_eq!(HEX27_NODE_XI[a], gmsh[g], "node {a}");
        }
        // Each face's mid-side nodes at the middles of its edges, its last node at its centre.
        for f in HEX27.faces {
            for e in 0..4 {
                let (a, b) = (f.nodes[e], f.nodes[(e + 1) % 4]);
                let mid: [f64; 3] =
                    std::array::from_fn(|k| 0.5 * (HEX27_NODE_XI[a][k] + HEX27_NODE_XI[b][k]));
                assert_eq!(mid, HEX27_NODE_XI[f.nodes[4 + e]], "face {:?}", f.nodes);
            }
            let centre: [f64; 3] = std::array::from_fn(|k| {
                f.nodes[..4]
                    .iter()
                    .map(|&c| HEX27_NODE_XI[c][k])
                    .sum::<f64>()
                    / 4.0
            });
            assert_eq!(centre, HEX27_NODE_XI[f.nodes[8]], "face {:?}", f.nodes);
        }
    }

    /// The quarters' hat functions give a flat unit face's corners 1/16 of its area, the
    /// mid-side nodes 1/8 and the centre 1/4, all positive, adding up to the area.
    #[test]
    fn quad9_pieces_share_the_area_positively() {
        let mut share = [0.0; 9];
        for piece in QUAD9.flat_pieces {
            for &a in piece.iter() {
                share[a] += 0.25 * 0.25; // a quarter's area (1/4) shared by its 4 nodes
            }
        }
        assert_eq!(share.iter().sum::<f64>(), 1.0);
        assert_eq!(
            (share[0], share[4], share[8]),
            (1.0 / 16.0, 1.0 / 8.0, 1.0 / 4.0)
        );
    }

    /// A mid-edge node moved past the quarter point of its edge inverts the element.
    #[test]
    fn a_mid_edge_node_past_the_quarter_point_inverts_the_element() {
        let mut x: [[f64; 3]; 27] = HEX27_NODE_XI;
        assert!(!hex27_inverted(&x));
        x[8] = [-0.6, -1.0, -1.0];
        assert!(hex27_inverted(&x));
    }
}
