//! The quadratic 10-node tetrahedron with a 4-point Gauss rule.
//!
//! Nodes in VTK order: the corners 0-3 as for the tet4, then the mid-side nodes of the edges
//! 0-1, 1-2, 0-2, 0-3, 1-3 and 2-3. (Gmsh lists the last two the other way round, edges 2-3
//! then 1-3: [`TET10`]'s `gmsh_nodes` undoes it.) In barycentric coordinates
//! L₀ = 1 − ξ − η − ζ, L₁ = ξ, L₂ = η, L₃ = ζ the shape functions are L_i (2 L_i − 1) at the
//! corners and 4 L_i L_j at the middle of edge i-j.
//!
//! The 4-point rule is exact to degree 2: it integrates the stiffness of a straight-sided
//! element exactly in small strain (the products of the linear shape-function gradients), as
//! the usual C3D10 does. The mass needs degree 4 and has its own closed form.

use super::face::{
    gauss_newton_projection, onto_triangle, triangle_quadrature, FaceProjection, FaceType,
    LocalFace,
};
use super::{DegenerateElement, Element, ElementType, GaussPoint, Lumping, Stabilisation};
use crate::Vec3;

/// The six-node triangular face of the tet10: corners counter-clockwise seen from outside,
/// then the mid-side nodes of the edges 0-1, 1-2 and 2-0. It is drawn and integrated on its
/// four sub-triangles (corner, mid, mid at each corner, and the middle one), whose hat
/// functions are positive where the quadratic corner functions integrate to zero.
pub static TRI6: FaceType = FaceType {
    name: "tri6",
    debug_name: "Tri6",
    nodes: 6,
    corners: 3,
    natural_nodes: &TRI6_NODE_XI,
    flat_pieces: &[&[0, 3, 5], &[3, 1, 4], &[5, 4, 2], &[3, 4, 5]],
    shape: |[xi, eta]| {
        let (n, dn) = tri6_shape(xi, eta);
        (n.to_vec(), dn.to_vec())
    },
    quadrature: triangle_quadrature,
    vtk_type: 22,
    gmsh_type: 9,
    is_quadratic: true,
    project: project_on_tri6,
};

/// A tet10 face with local nodes `nodes`.
const fn tri6(nodes: &'static [usize]) -> LocalFace {
    LocalFace {
        face_type: &TRI6,
        nodes,
    }
}

/// Closest-point projection of `x` on a six-node triangle with nodes `p` [m] by Gauss-Newton
/// in its natural coordinates from the centroid, kept in the triangle.
fn project_on_tri6(p: &[Vec3], x: Vec3) -> FaceProjection {
    gauss_newton_projection(p, x, TRI6.shape, [1.0 / 3.0, 1.0 / 3.0], onto_triangle)
}

/// The edges of the mid-side nodes 4..9, by their end corners.
pub const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// The tet10 row of the element-type table.
pub static TET10: ElementType = ElementType {
    name: "tet10",
    nodes: 10,
    natural_nodes: &[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.0, 0.5],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
    ],
    gauss_points: 4,
    gauss_rule: super::gauss_rule_of::<Tet10, 10, 4>,
    shape: super::shape_of::<Tet10, 10, 4>,
    // The tet4's faces, each followed by the mid-side nodes of its edges in order.
    faces: &[
        tri6(&[0, 2, 1, 6, 5, 4]),
        tri6(&[0, 1, 3, 4, 8, 7]),
        tri6(&[1, 2, 3, 5, 9, 8]),
        tri6(&[0, 3, 2, 7, 9, 6]),
    ],
    corner_frames: &[[0, 1, 2, 3]],
    inverted_inside: |x| {
        let x: &[[f64; 3]; 10] = x.try_into().expect("a tet10 has 10 nodes");
        tet10_inverted(x)
    },
    vtk_type: 24,
    gmsh_type: 11,
    gmsh_nodes: &[0, 1, 2, 3, 4, 5, 6, 7, 9, 8],
};

/// The tet10 element at compile time.
pub struct Tet10;

/// Barycentric coordinate of the 4-point rule's point nearest its corner.
const GAUSS_A: f64 = 0.585_410_196_624_968_5;
/// The other three barycentric coordinates of each point of the 4-point rule.
const GAUSS_B: f64 = 0.138_196_601_125_010_5;

impl Element<10, 4> for Tet10 {
    const TYPE: &'static ElementType = &TET10;
    const STABILISATION: Stabilisation = Stabilisation::FBar;
    /// The row sums would give the corners −ρV/20 each.
    const LUMPING: Lumping = Lumping::DiagonalScaling;

    fn shape(xi: [f64; 3]) -> ([f64; 10], [[f64; 3]; 10]) {
        tet10_shape(xi)
    }

    fn gauss_rule() -> [([f64; 3], f64); 4] {
        let (a, b) = (GAUSS_A, GAUSS_B);
        [
            ([b, b, b], 1.0 / 24.0),
            ([a, b, b], 1.0 / 24.0),
            ([b, a, b], 1.0 / 24.0),
            ([b, b, a], 1.0 / 24.0),
        ]
    }

    /// The consistent mass of a straight-sided tet10 of the element's volume V (the sum of
    /// the Gauss weights) [kg]: ρV/420 times 6 on the corners' diagonal, 1 between corners,
    /// −4 between a corner and the mid-side nodes of its edges, −6 between a corner and the
    /// mid-side nodes of the other edges, 32 on the mid-side nodes' diagonal, 16 between
    /// mid-side nodes of edges that meet and 8 between those of opposite edges. (A curved
    /// tet10 gets the mass of the straight one of the same volume.)
    fn mass(gps: &[GaussPoint<10>; 4], density: f64) -> [[f64; 10]; 10] {
        let volume: f64 = gps.iter().map(|g| g.weight).sum();
        let scale = density * volume / 420.0;
        std::array::from_fn(|a| std::array::from_fn(|b| scale * mass_coefficient(a, b)))
    }
}

/// The coefficient of nodes a and b in 420/(ρV) times the straight tet10's mass.
fn mass_coefficient(a: usize, b: usize) -> f64 {
    let edge = |m: usize| TET10_EDGES[m - 4];
    match (a < 4, b < 4) {
        (true, true) => {
            if a == b {
                6.0
            } else {
                1.0
            }
        }
        (true, false) | (false, true) => {
            let (c, m) = if a < 4 { (a, b) } else { (b, a) };
            if edge(m).contains(&c) {
                -4.0
            } else {
                -6.0
            }
        }
        (false, false) => {
            if a == b {
                32.0
            } else if edge(a).iter().any(|c| edge(b).contains(c)) {
                16.0
            } else {
                8.0
            }
        }
    }
}

/// Tet10 shape functions and natural derivatives at ξ (VTK node order).
pub fn tet10_shape(xi: [f64; 3]) -> ([f64; 10], [[f64; 3]; 10]) {
    let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    let dl = [
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut n = [0.0; 10];
    let mut dn = [[0.0; 3]; 10];
    for i in 0..4 {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
        dn[i] = dl[i].map(|d| (4.0 * l[i] - 1.0) * d);
    }
    for (m, &[i, j]) in TET10_EDGES.iter().enumerate() {
        n[4 + m] = 4.0 * l[i] * l[j];
        dn[4 + m] = std::array::from_fn(|k| 4.0 * (l[j] * dl[i][k] + l[i] * dl[j][k]));
    }
    (n, dn)
}

/// Whether a tet10 with node coordinates `x` [m] has a Jacobian determinant ≤ 0 at one of its
/// nodes or Gauss points: a curved element folded by the mesher, or a mid-side node moved past
/// the quarter point of its edge.
pub fn tet10_inverted(x: &[[f64; 3]; 10]) -> bool {
    let points = TET10
        .natural_nodes
        .iter()
        .copied()
        .chain(Tet10::gauss_rule().map(|(p, _)| p));
    points
        .map(|p| {
            let (n, dn) = tet10_shape(p);
            super::gauss_point(x, n, dn, 1.0)
        })
        .any(|g| g.is_err())
}

/// Shape functions of the six-node triangle at natural point (ξ, η) (corners 0-2, then the
/// mid-side nodes of the edges 0-1, 1-2 and 2-0) and their derivatives along ξ and η.
pub fn tri6_shape(xi: f64, eta: f64) -> ([f64; 6], [[f64; 2]; 6]) {
    let l = [1.0 - xi - eta, xi, eta];
    let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let mut n = [0.0; 6];
    let mut dn = [[0.0; 2]; 6];
    for i in 0..3 {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
        dn[i] = dl[i].map(|d| (4.0 * l[i] - 1.0) * d);
    }
    for (m, (i, j)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
        n[3 + m] = 4.0 * l[i] * l[j];
        dn[3 + m] = std::array::from_fn(|k| 4.0 * (l[j] * dl[i][k] + l[i] * dl[j][k]));
    }
    (n, dn)
}

/// Natural coordinates (ξ, η) of the six-node triangle's nodes.
pub const TRI6_NODE_XI: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [0.5, 0.0],
    [0.5, 0.5],
    [0.0, 0.5],
];

/// Gauss-point data of a tet10 with reference coordinates `x` [m].
pub fn tet10_geometry(x: &[[f64; 3]; 10]) -> Result<[GaussPoint<10>; 4], DegenerateElement> {
    Tet10::geometry(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form mass against a degree-7 conical product rule on the unit tetrahedron
    /// (4 × 4 × 4 Gauss-Legendre points on the cube, collapsed): the products N_a N_b are of
    /// degree 4, so both are exact; 1e-15 is round-off on entries of order 1/420.
    #[test]
    fn the_closed_form_mass_is_the_integral_of_the_shape_products() {
        let g = [
            (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
            (0.330_009_478_207_571_87, 0.326_072_577_431_273_07),
            (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
            (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
        ];
        let mut m = [[0.0; 10]; 10];
        for &(u, wu) in &g {
            for &(v, wv) in &g {
                for &(w, ww) in &g {
                    let xi = [u, v * (1.0 - u), w * (1.0 - u) * (1.0 - v)];
                    let jac = (1.0 - u) * (1.0 - u) * (1.0 - v);
                    let (n, _) = tet10_shape(xi);
                    for a in 0..10 {
                        for b in 0..10 {
                            m[a][b] += wu * wv * ww * jac * n[a] * n[b];
                        }
                    }
                }
            }
        }
        let volume = 1.0 / 6.0;
        for a in 0..10 {
            for b in 0..10 {
                let closed = volume / 420.0 * mass_coefficient(a, b);
                assert!(
                    (m[a][b] - closed).abs() < 1e-15,
                    "m[{a}][{b}] = {} against {closed}",
                    m[a][b]
                );
            }
        }
    }

    /// The six-node triangle's shape functions interpolate its nodes, add up to 1, and their
    /// derivatives match central differences (quadratic functions: the difference is exact up
    /// to round-off, 1e-9 for a step of 1e-4).
    #[test]
    fn tri6_shape_functions_interpolate_and_differentiate() {
        for (b, xb) in TRI6_NODE_XI.iter().enumerate() {
            let (n, _) = tri6_shape(xb[0], xb[1]);
            for (a, na) in n.iter().enumerate() {
                assert!((na - if a == b { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        let (x, y, h) = (0.23, 0.31, 1e-4);
        let (n, dn) = tri6_shape(x, y);
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let (np, _) = tri6_shape(x + h, y);
        let (nm, _) = tri6_shape(x - h, y);
        let (nq, _) = tri6_shape(x, y + h);
        let (nr, _) = tri6_shape(x, y - h);
        for a in 0..6 {
            assert!((dn[a][0] - (np[a] - nm[a]) / (2.0 * h)).abs() < 1e-9);
            assert!((dn[a][1] - (nq[a] - nr[a]) / (2.0 * h)).abs() < 1e-9);
        }
    }

    /// A mid-side node moved past the quarter point of its edge towards a corner makes the
    /// Jacobian vanish at that corner: the straight element is valid, the distorted one not.
    #[test]
    fn a_mid_side_node_past_the_quarter_point_inverts_the_element() {
        let mut x: [[f64; 3]; 10] = std::array::from_fn(|a| TET10.natural_nodes[a]);
        assert!(!tet10_inverted(&x));
        x[4] = [0.2, 0.0, 0.0];
        assert!(tet10_inverted(&x));
    }
}
