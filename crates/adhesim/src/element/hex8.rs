//! The trilinear 8-node hexahedron with 2×2×2 Gauss points.
//!
//! Nodes in VTK order: 0-3 the face ζ = −1 counter-clockwise seen from +ζ, 4-7 the face
//! ζ = +1 in the same order.

use crate::{Mat3, Vec3};

use super::face::{square_quadrature, unit, FaceProjection, FaceType, LocalFace};
use super::{gauss_point, DegenerateElement, Element, ElementType, GaussPoint, Stabilisation};

/// The bilinear quadrilateral face of the hex8: corners counter-clockwise seen from outside,
/// natural coordinates (ξ, η) ∈ [−1, 1]², drawn and integrated as itself.
pub static QUAD4: FaceType = FaceType {
    name: "quad4",
    debug_name: "Quad",
    nodes: 4,
    corners: 4,
    natural_nodes: &[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
    flat_pieces: &[&[0, 1, 2, 3]],
    shape: |[xi, eta]| {
        let (n, dn) = quad4_shape_and_derivatives(xi, eta);
        (n.to_vec(), dn.to_vec())
    },
    quadrature: || square_quadrature(2),
    vtk_type: 9,
    gmsh_type: 3,
    is_quadratic: false,
    project: project_on_quad4,
};

/// A hex8 face with local nodes `nodes`.
const fn quad4(nodes: &'static [usize]) -> LocalFace {
    LocalFace {
        face_type: &QUAD4,
        nodes,
    }
}

/// Bilinear shape functions of a quadrilateral at (ξ, η) ∈ [−1, 1]².
pub fn quad4_shape(xi: f64, eta: f64) -> [f64; 4] {
    [
        0.25 * (1.0 - xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 + eta),
        0.25 * (1.0 - xi) * (1.0 + eta),
    ]
}

/// [`quad4_shape`] and the derivatives (∂N_a/∂ξ, ∂N_a/∂η).
fn quad4_shape_and_derivatives(xi: f64, eta: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    let da = [
        -0.25 * (1.0 - eta),
        0.25 * (1.0 - eta),
        0.25 * (1.0 + eta),
        -0.25 * (1.0 + eta),
    ];
    let db = [
        -0.25 * (1.0 - xi),
        -0.25 * (1.0 + xi),
        0.25 * (1.0 + xi),
        0.25 * (1.0 - xi),
    ];
    (
        quad4_shape(xi, eta),
        std::array::from_fn(|a| [da[a], db[a]]),
    )
}

/// Closest-point projection of `x` on the bilinear quadrilateral with corners `p` [m]: Newton
/// (Gauss-Newton on ‖x − x(ξ,η)‖²) from the centre, each step clamped to the face.
fn project_on_quad4(p: &[Vec3], x: Vec3) -> FaceProjection {
    let (mut a, mut b) = (0.0f64, 0.0f64);
    let eval = |a: f64, b: f64| {
        let (w, d) = quad4_shape_and_derivatives(a, b);
        let comb =
            |c: [f64; 4]| -> Vec3 { Vec3::from_fn(|k, _| (0..4).map(|i| c[i] * p[i][k]).sum()) };
        (w, comb(w), comb(d.map(|d| d[0])), comb(d.map(|d| d[1])))
    };
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
        a = (a + da).clamp(-1.0, 1.0);
        b = (b + db).clamp(-1.0, 1.0);
        if da.abs() + db.abs() < 1e-12 {
            break;
        }
    }
    let (w, xm, ta, tb) = eval(a, b);
    let n = unit(ta.cross(&tb));
    (xm.into(), n.into(), w.to_vec())
}

/// The hex8 row of the element-type table.
/// The corner frames of a hexahedron (VTK order): each corner with its three neighbours
/// along the edges, right-handed; hex20 shares its corners'.
pub(super) const HEX_CORNER_FRAMES: [[usize; 4]; 8] = [
    [0, 1, 3, 4],
    [1, 2, 0, 5],
    [2, 3, 1, 6],
    [3, 0, 2, 7],
    [4, 7, 5, 0],
    [5, 4, 6, 1],
    [6, 5, 7, 2],
    [7, 6, 4, 3],
];

pub static HEX8: ElementType = ElementType {
    name: "hex8",
    nodes: 8,
    natural_nodes: &HEX_NODE_XI,
    gauss_points: 8,
    gauss_rule: super::gauss_rule_of::<Hex8, 8, 8>,
    shape: super::shape_of::<Hex8, 8, 8>,
    faces: &[
        quad4(&[0, 3, 2, 1]), // ζ = −1
        quad4(&[4, 5, 6, 7]), // ζ = +1
        quad4(&[0, 1, 5, 4]), // η = −1
        quad4(&[2, 3, 7, 6]), // η = +1
        quad4(&[0, 4, 7, 3]), // ξ = −1
        quad4(&[1, 2, 6, 5]), // ξ = +1
    ],
    corner_frames: &HEX_CORNER_FRAMES,
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
