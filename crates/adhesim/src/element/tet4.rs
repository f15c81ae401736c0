//! The linear 4-node tetrahedron with one Gauss point.
//!
//! Nodes in VTK order, (x1−x0)·((x2−x0)×(x3−x0)) > 0.

use super::{DegenerateElement, Element, ElementType, GaussPoint, Stabilisation};

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
    faces: &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[0, 3, 2]],
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
