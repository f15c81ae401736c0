//! Total-Lagrangian solid elements: trilinear hex8 (2×2×2 Gauss) and linear tet4 (1 point).
//! Reference-configuration data (shape-function gradients, weights) are computed once; the
//! kernels turn nodal displacements into internal force, consistent tangent (material +
//! geometric) and strain energy.

use crate::material::Hyperelastic;
use crate::{Mat3, Vec3};
use nalgebra::SMatrix;

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

/// 2×2×2 Gauss points of the hex8 (unit weights).
pub fn hex8_gauss_points() -> [[f64; 3]; 8] {
    let g = 1.0 / 3f64.sqrt();
    let mut pts = [[0.0; 3]; 8];
    for (p, xi) in pts.iter_mut().zip(HEX_NODE_XI.iter()) {
        *p = [g * xi[0], g * xi[1], g * xi[2]];
    }
    pts
}

/// Reference-configuration data at one Gauss point of an element with N nodes.
#[derive(Clone, Copy, Debug)]
pub struct GaussPoint<const N: usize> {
    /// Shape functions N_a.
    pub shape: [f64; N],
    /// Reference gradients ∂N_a/∂X [1/m].
    pub grad: [[f64; 3]; N],
    /// Quadrature weight times reference Jacobian determinant [m³].
    pub weight: f64,
}

/// Error when a reference element is degenerate or inverted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DegenerateElement {
    /// Smallest reference Jacobian determinant found [m³ per unit natural volume].
    pub det: f64,
}

fn gauss_point<const N: usize>(
    x: &[[f64; 3]; N],
    shape: [f64; N],
    dn: [[f64; 3]; N],
    w: f64,
) -> Result<GaussPoint<N>, DegenerateElement> {
    let mut j = Mat3::zeros();
    for a in 0..N {
        for i in 0..3 {
            for k in 0..3 {
                j[(i, k)] += x[a][i] * dn[a][k];
            }
        }
    }
    let det = j.determinant();
    if !(det > 0.0) {
        return Err(DegenerateElement { det });
    }
    let jinv_t = j
        .try_inverse()
        .ok_or(DegenerateElement { det })?
        .transpose();
    let mut grad = [[0.0; 3]; N];
    for a in 0..N {
        let g = jinv_t * Vec3::from(dn[a]);
        grad[a] = [g[0], g[1], g[2]];
    }
    Ok(GaussPoint {
        shape,
        grad,
        weight: w * det,
    })
}

/// Gauss-point data of a hex8 with reference coordinates `x` [m].
pub fn hex8_geometry(x: &[[f64; 3]; 8]) -> Result<[GaussPoint<8>; 8], DegenerateElement> {
    let pts = hex8_gauss_points();
    let mut out = [GaussPoint {
        shape: [0.0; 8],
        grad: [[0.0; 3]; 8],
        weight: 0.0,
    }; 8];
    for (o, p) in out.iter_mut().zip(pts) {
        let (n, dn) = hex8_shape(p);
        *o = gauss_point(x, n, dn, 1.0)?;
    }
    Ok(out)
}

/// Shape-function data at the centre (ξ = 0) of a hex8 with reference coordinates `x` [m],
/// weight 8 (the natural volume), as the F-bar element needs.
pub fn hex8_centre(x: &[[f64; 3]; 8]) -> Result<GaussPoint<8>, DegenerateElement> {
    let (n, dn) = hex8_shape([0.0; 3]);
    gauss_point(x, n, dn, 8.0)
}

/// Gauss-point data of a tet4 with reference coordinates `x` [m] (one point, weight 1/6).
pub fn tet4_geometry(x: &[[f64; 3]; 4]) -> Result<[GaussPoint<4>; 1], DegenerateElement> {
    let (n, dn) = tet4_shape([0.25; 3]);
    Ok([gauss_point(x, n, dn, 1.0 / 6.0)?])
}

/// Consistent mass coefficients m_ab = ∫ ρ N_a N_b dV₀ [kg] (each multiplies the 3×3
/// identity). For tet4 the exact closed form ρV/20 (1 + δ_ab) is used.
pub fn consistent_mass<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    density: f64,
) -> [[f64; N]; N] {
    let mut m = [[0.0; N]; N];
    if N == 4 && G == 1 {
        let v = gps[0].weight;
        for a in 0..N {
            for b in 0..N {
                m[a][b] = density * v / 20.0 * if a == b { 2.0 } else { 1.0 };
            }
        }
        return m;
    }
    for gp in gps {
        for a in 0..N {
            for b in 0..N {
                m[a][b] += density * gp.shape[a] * gp.shape[b] * gp.weight;
            }
        }
    }
    m
}

/// What the element kernel computes at a given displacement.
pub struct ElementResponse<const N: usize> {
    /// Internal nodal forces [N].
    pub force: [[f64; 3]; N],
    /// Tangent blocks K[a][b] = ∂f_a/∂u_b [N/m] (only when requested).
    pub tangent: Option<Box<[[Mat3; N]; N]>>,
    /// Strain energy [J].
    pub energy: f64,
    /// Smallest J = det F over the Gauss points.
    pub min_j: f64,
}

type Bmat = SMatrix<f64, 6, 3>;

#[inline]
fn b_matrix(f: &Mat3, g: &[f64; 3]) -> Bmat {
    let mut b = Bmat::zeros();
    for i in 0..3 {
        b[(0, i)] = f[(i, 0)] * g[0];
        b[(1, i)] = f[(i, 1)] * g[1];
        b[(2, i)] = f[(i, 2)] * g[2];
        b[(3, i)] = f[(i, 0)] * g[1] + f[(i, 1)] * g[0];
        b[(4, i)] = f[(i, 1)] * g[2] + f[(i, 2)] * g[1];
        b[(5, i)] = f[(i, 0)] * g[2] + f[(i, 2)] * g[0];
    }
    b
}

/// Displacement gradient H = ∂u/∂X at a Gauss point.
#[inline]
pub fn displacement_gradient<const N: usize>(gp: &GaussPoint<N>, u: &[[f64; 3]; N]) -> Mat3 {
    let mut h = Mat3::zeros();
    for a in 0..N {
        for i in 0..3 {
            for k in 0..3 {
                h[(i, k)] += u[a][i] * gp.grad[a][k];
            }
        }
    }
    h
}

/// The committed internal variables of an element's Gauss points and the step size Δt [s],
/// with the viscoelastic model they belong to.
pub(crate) type ViscousHistory<'a> = Option<((&'a [f64], f64), &'a crate::material::Viscoelastic)>;

/// The material at one Gauss point `q` of an element, shared by all element kernels: the
/// energy W(C) [J/m³], the stress S [Pa] and, when `with_tangent`, the tangent D [Pa], with
/// the viscous part of that point when `viscous` holds the element's history.
pub(crate) fn material_point(
    material: &dyn Hyperelastic,
    c: &Mat3,
    q: usize,
    viscous: ViscousHistory<'_>,
    with_tangent: bool,
) -> (f64, Mat3, Option<crate::Mat6>) {
    let (mut s, mut d) = if with_tangent {
        let (s, d) = material.pk2_and_tangent(c);
        (s, Some(d))
    } else {
        (material.pk2(c), None)
    };
    if let Some(((hist, dt), ve)) = viscous {
        let len = ve.history_len();
        ve.add_viscous(c, &hist[q * len..(q + 1) * len], dt, &mut s, d.as_mut());
    }
    (material.energy(c), s, d)
}

/// Internal force, (optionally) tangent, energy and min J of one element.
///
/// Finite-strain materials use F = I + H, C = FᵀF; a small-strain material gets
/// C = I + H + Hᵀ (i.e. E = ε), B at F = I and no geometric stiffness.
pub fn element_response<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
) -> ElementResponse<N> {
    element_response_with_history(gps, u, material, with_tangent, None)
}

/// As [`element_response`], for a viscoelastic material: `history` holds the committed
/// internal variables of the element's Gauss points one after the other and the step size
/// Δt [s] (`None`: elastic response).
pub fn element_response_with_history<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
    history: Option<(&[f64], f64)>,
) -> ElementResponse<N> {
    let viscous = history.zip(material.viscoelastic());
    let small = material.small_strain();
    let mut force = [[0.0; 3]; N];
    let mut tangent = if with_tangent {
        Some(Box::new([[Mat3::zeros(); N]; N]))
    } else {
        None
    };
    let mut energy = 0.0;
    let mut min_j = f64::INFINITY;
    for (q, gp) in gps.iter().enumerate() {
        let h = displacement_gradient(gp, u);
        let f = Mat3::identity() + h;
        let j = f.determinant();
        min_j = min_j.min(j);
        let (fb, c) = if small {
            (Mat3::identity(), Mat3::identity() + h + h.transpose())
        } else {
            (f, f.transpose() * f)
        };
        if !small && !(j > 0.0) {
            energy = f64::NAN;
            continue;
        }
        let (w_point, s, d) = material_point(material, &c, q, viscous, with_tangent);
        energy += w_point * gp.weight;
        let w = gp.weight;
        let bs: [Bmat; N] = std::array::from_fn(|a| b_matrix(&fb, &gp.grad[a]));
        let sv = nalgebra::Vector6::new(
            s[(0, 0)],
            s[(1, 1)],
            s[(2, 2)],
            s[(0, 1)],
            s[(1, 2)],
            s[(0, 2)],
        );
        for a in 0..N {
            let fa = bs[a].transpose() * sv;
            for i in 0..3 {
                force[a][i] += w * fa[i];
            }
        }
        if let (Some(kt), Some(d)) = (tangent.as_mut(), d) {
            let dbs: [Bmat; N] = std::array::from_fn(|b| d * bs[b]);
            for a in 0..N {
                let sga = s * Vec3::from(gp.grad[a]);
                for b in a..N {
                    let mut kab = bs[a].transpose() * dbs[b];
                    if !small {
                        let geo = sga.dot(&Vec3::from(gp.grad[b]));
                        for i in 0..3 {
                            kab[(i, i)] += geo;
                        }
                    }
                    kt[a][b] += w * kab;
                }
            }
        }
    }
    if let Some(kt) = tangent.as_mut() {
        for a in 0..N {
            for b in 0..a {
                kt[a][b] = kt[b][a].transpose();
            }
        }
    }
    ElementResponse {
        force,
        tangent,
        energy,
        min_j,
    }
}

/// C = FᵀF at each Gauss point (finite strain).
pub fn gauss_point_c<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
) -> [Mat3; G] {
    std::array::from_fn(|q| {
        let f = Mat3::identity() + displacement_gradient(&gps[q], u);
        f.transpose() * f
    })
}

/// Cauchy stress σ = J⁻¹ F S Fᵀ averaged over the Gauss points (volume-weighted) [Pa], and
/// the mean J. Small-strain materials report σ = S(ε).
pub fn element_cauchy_stress<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
) -> (Mat3, f64) {
    let mut sigma = Mat3::zeros();
    let mut jsum = 0.0;
    let mut vol = 0.0;
    for gp in gps {
        let h = displacement_gradient(gp, u);
        let f = Mat3::identity() + h;
        let j = f.determinant();
        let cauchy = if material.small_strain() {
            material.pk2(&(Mat3::identity() + h + h.transpose()))
        } else {
            f * material.pk2(&(f.transpose() * f)) * f.transpose() / j
        };
        sigma += cauchy * gp.weight;
        jsum += j * gp.weight;
        vol += gp.weight;
    }
    (sigma / vol, jsum / vol)
}

/// Von Mises equivalent stress of a Cauchy stress [Pa].
pub fn von_mises(s: &Mat3) -> f64 {
    let d = [
        s[(0, 0)] - s[(1, 1)],
        s[(1, 1)] - s[(2, 2)],
        s[(2, 2)] - s[(0, 0)],
    ];
    let sh = s[(0, 1)].powi(2) + s[(1, 2)].powi(2) + s[(0, 2)].powi(2);
    (0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 3.0 * sh).sqrt()
}
