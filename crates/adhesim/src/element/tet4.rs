//! The linear 4-node tetrahedron with one Gauss point.
//!
//! Nodes in VTK order, (x1−x0)·((x2−x0)×(x3−x0)) > 0.

use super::face::{triangle_quadrature, unit, FaceProjection, FaceType, LocalFace};
use super::{DegenerateElement, Element, ElementType, GaussPoint, Stabilisation};
use crate::Vec3;

/// The linear triangular face of the tet4: corners counter-clockwise seen from outside,
/// natural coordinates (ξ, η) on the unit triangle, drawn and integrated as itself.
pub static TRI3: FaceType = FaceType {
    name: "tri3",
    debug_name: "Tri",
    nodes: 3,
    corners: 3,
    natural_nodes: &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
    flat_pieces: &[&[0, 1, 2]],
    shape: |[xi, eta]| {
        (
            vec![1.0 - xi - eta, xi, eta],
            vec![[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]],
        )
    },
    quadrature: triangle_quadrature,
    vtk_type: 5,
    gmsh_type: 2,
    is_quadratic: false,
    project: project_on_tri3,
};

/// A tet4 face with local nodes `nodes`.
const fn tri3(nodes: &'static [usize]) -> LocalFace {
    LocalFace {
        face_type: &TRI3,
        nodes,
    }
}

/// Closest-point projection of `x` on the triangle with corners `p` [m], in closed form
/// (the plane's barycentric coordinates moved onto the triangle).
fn project_on_tri3(p: &[Vec3], x: Vec3) -> FaceProjection {
    let (p0, p1, p2) = (p[0], p[1], p[2]);
    let (e1, e2) = (p1 - p0, p2 - p0);
    let n: [f64; 3] = unit(e1.cross(&e2)).into();
    let r = x - p0;
    let (m11, m12, m22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let (g1, g2) = (r.dot(&e1), r.dot(&e2));
    let det = m11 * m22 - m12 * m12;
    let mut a = (m22 * g1 - m12 * g2) / det;
    let mut b = (m11 * g2 - m12 * g1) / det;
    a = a.max(0.0);
    b = b.max(0.0);
    let s = a + b;
    if s > 1.0 {
        a /= s;
        b /= s;
    }
    let w = vec![1.0 - a - b, a, b];
    let xm = std::array::from_fn(|k| w[0] * p[0][k] + w[1] * p[1][k] + w[2] * p[2][k]);
    (xm, n, w)
}

/// The tet4 row of the element-type table.
pub static TET4: ElementType = ElementType {
    name: "tet4",
    nodes: 4,
    natural_nodes: &[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ],
    gauss_points: 1,
    gauss_rule: super::gauss_rule_of::<Tet4, 4, 1>,
    shape: super::shape_of::<Tet4, 4, 1>,
    faces: &[
        tri3(&[0, 2, 1]),
        tri3(&[0, 1, 3]),
        tri3(&[1, 2, 3]),
        tri3(&[0, 3, 2]),
    ],
    corner_frames: &[[0, 1, 2, 3]],
    inverted_inside: |_| false,
    vtk_type: 10,
    gmsh_type: 4,
    gmsh_nodes: &[0, 1, 2, 3],
};

/// The tet4 element at compile time.
pub struct Tet4;

impl Element<4, 1> for Tet4 {
    const TYPE: &'static ElementType = &TET4;
    const STABILISATION: Stabilisation = Stabilisation::NodalPressure;

    fn shape(xi: [f64; 3]) -> ([f64; 4], [[f64; 3]; 4]) {
        tet4_shape(xi)
    }

    fn gauss_rule() -> [([f64; 3], f64); 1] {
        [([0.25; 3], 1.0 / 6.0)]
    }

    /// The exact consistent mass ρV/20 (1 + δ_ab) [kg].
    fn mass(gps: &[GaussPoint<4>; 1], density: f64) -> [[f64; 4]; 4] {
        let v = gps[0].weight;
        let mut m = [[0.0; 4]; 4];
        for (a, row) in m.iter_mut().enumerate() {
            for (b, mab) in row.iter_mut().enumerate() {
                *mab = density * v / 20.0 * if a == b { 2.0 } else { 1.0 };
            }
        }
        m
    }
}

/// Tet4 shape functions and natural derivatives (ξ = barycentric coordinates 1..3).
pub fn tet4_shape(xi: [f64; 3]) -> ([f64; 4], [[f64; 3]; 4]) {
    let n = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    let dn = [
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    (n, dn)
}

/// Gauss-point data of a tet4 with reference coordinates `x` [m] (one point, weight 1/6).
pub fn tet4_geometry(x: &[[f64; 3]; 4]) -> Result<[GaussPoint<4>; 1], DegenerateElement> {
    Tet4::geometry(x)
}
