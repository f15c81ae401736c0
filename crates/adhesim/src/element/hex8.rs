//! The trilinear 8-node hexahedron with 2×2×2 Gauss points.
//!
//! Nodes in VTK order: 0-3 the face ζ = −1 counter-clockwise seen from +ζ, 4-7 the face
//! ζ = +1 in the same order.

use crate::{Mat3, Vec3};

use super::{gauss_point, DegenerateElement, Element, ElementType, GaussPoint, Stabilisation};

/// The hex8 row of the element-type table.
pub static HEX8: ElementType = ElementType {
    name: "hex8",
    nodes: 8,
    natural_nodes: &HEX_NODE_XI,
    gauss_points: 8,
    gauss_rule: super::gauss_rule_of::<Hex8, 8, 8>,
    shape: super::shape_of::<Hex8, 8, 8>,
    faces: &[
        &[0, 3, 2, 1], // ζ = −1
        &[4, 5, 6, 7], // ζ = +1
        &[0, 1, 5, 4], // η = −1
        &[2, 3, 7, 6], // η = +1
        &[0, 4, 7, 3], // ξ = −1
        &[1, 2, 6, 5], // ξ = +1
    ],
    corner_frames: &[
        [0, 1, 3, 4],
        [1, 2, 0, 5],
        [2, 3, 1, 6],
        [3, 0, 2, 7],
        [4, 7, 5, 0],
        [5, 4, 6, 1],
        [6, 5, 7, 2],
        [7, 6, 4, 3],
    ],
    inverted_inside: |x| {
        let x: &[[f64; 3]; 8] = x.try_into().expect("a hex8 has 8 nodes");
        hex8_gauss_dets(x).iter().any(|&d| d <= 0.0)
    },
    vtk_type: 12,
    gmsh_type: 5,
    gmsh_nodes: &[0, 1, 2, 3, 4, 5, 6, 7],
};

/// The hex8 element at compile time.
pub struct Hex8;

impl Element<8, 8> for Hex8 {
    const TYPE: &'static ElementType = &HEX8;
    const STABILISATION: Stabilisation = Stabilisation::FBar;

    fn shape(xi: [f64; 3]) -> ([f64; 8], [[f64; 3]; 8]) {
        hex8_shape(xi)
    }

    fn gauss_rule() -> [([f64; 3], f64); 8] {
        hex8_gauss_points().map(|p| (p, 1.0))
    }
}

/// Natural coordinates of the hex8 nodes (VTK order).
pub const HEX_NODE_XI: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Hex8 shape functions and their natural derivatives at ξ.
pub fn hex8_shape(xi: [f64; 3]) -> ([f64; 8], [[f64; 3]; 8]) {
    let mut n = [0.0; 8];
    let mut dn = [[0.0; 3]; 8];
    for a in 0..8 {
        let [xa, ya, za] = HEX_NODE_XI[a];
        let (fx, fy, fz) = (1.0 + xi[0] * xa, 1.0 + xi[1] * ya, 1.0 + xi[2] * za);
        n[a] = 0.125 * fx * fy * fz;
        dn[a] = [
            0.125 * xa * fy * fz,
            0.125 * fx * ya * fz,
            0.125 * fx * fy * za,
        ];
    }
    (n, dn)
}

/// 2×2×2 Gauss points of the hex8 (unit weights).
pub fn hex8_gauss_points() -> [[f64; 3]; 8] {
    let g = 1.0 / 3f64.sqrt();
    let mut pts = [[0.0; 3]; 8];
    for (p, xi) in pts.iter_mut().zip(HEX_NODE_XI.iter()) {
        *p = [g * xi[0], g * xi[1], g * xi[2]];
    }
    pts
}

/// Gauss-point data of a hex8 with reference coordinates `x` [m].
pub fn hex8_geometry(x: &[[f64; 3]; 8]) -> Result<[GaussPoint<8>; 8], DegenerateElement> {
    Hex8::geometry(x)
}

/// Shape-function data at the centre (ξ = 0) of a hex8 with reference coordinates `x` [m],
/// weight 8 (the natural volume), as the F-bar element needs.
pub fn hex8_centre(x: &[[f64; 3]; 8]) -> Result<GaussPoint<8>, DegenerateElement> {
    let (n, dn) = hex8_shape([0.0; 3]);
    gauss_point(x, n, dn, 8.0)
}

/// Jacobian matrix ∂x/∂(ξ, η, ζ) (rows x, y, z) of a trilinear hex at natural point `xi`.
fn hex8_jacobian(x: &[[f64; 3]; 8], xi: [f64; 3]) -> Mat3 {
    let mut j = Mat3::zeros();
    for (a, n) in HEX_NODE_XI.iter().enumerate() {
        let f = [1.0 + n[0] * xi[0], 1.0 + n[1] * xi[1], 1.0 + n[2] * xi[2]];
        let grad = Vec3::new(
            0.125 * n[0] * f[1] * f[2],
            0.125 * n[1] * f[0] * f[2],
            0.125 * n[2] * f[0] * f[1],
        );
        j += Vec3::from(x[a]) * grad.transpose();
    }
    j
}

/// Jacobian determinants of a hex at the 2 × 2 × 2 Gauss points (±1/√3) [m³ per unit
/// natural volume]; each Gauss weight is 1.
pub fn hex8_gauss_dets(x: &[[f64; 3]; 8]) -> [f64; 8] {
    let g = 1.0 / 3f64.sqrt();
    HEX_NODE_XI.map(|n| hex8_jacobian(x, n.map(|s| s * g)).determinant())
}
