//! Orthotropic interfaces (docs/model.md §5.5): Coulomb friction with an elliptic cone,
//! μ₁ and μ₂ along two material axes of the master surface, and orthotropic tangential
//! adhesion, C_t1 and C_t2 along the same axes.
//!
//! Each contact point's local frame is turned so that t₁ follows the first material axis
//! ([`align_frames`]); t₂ = n × t₁ is the second. In the scaled variables
//! r' = T⁻¹ r, x' = T x with T = diag(1, s, 1) and s = μ₂/μ₁, the elliptic cone
//! {r_n ≥ 0, (r_t1/μ₁)² + (r_t2/μ₂)² ≤ r_n²} becomes the circular cone of μ₁, and the power
//! r·x = r'·x' is unchanged. The law of maximal dissipation therefore maps onto the isotropic
//! one: the slip x_t of a sliding point is normal to the ellipse, x_t ∝ −(r_t1/μ₁², r_t2/μ₂²),
//! and the bi-potential of the anisotropic law is the isotropic one in the scaled variables.
//! The solvers solve the scaled problem and map the result back; with μ₁ = μ₂ they take the
//! isotropic path unchanged. μ₁ and μ₂ must both be positive (s finite and non-zero).
//!
//! This module is plain algebra on local vectors; the law (`law.rs`: `InterfaceLaw::
//! tangent_scale`, `natural_map_defect`) and the detection (`detect::align_frames`) use it.

use crate::{Mat3, Vec3};
use nalgebra::Vector3;

/// The material axes and second friction coefficient of an orthotropic interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orthotropy {
    /// First material axis of the master surface, global components; at each contact point
    /// t₁ is its projection on the tangent plane.
    pub axis: [f64; 3],
    /// Friction coefficient μ₂ along the second axis t₂ = n × t₁ [-] (μ₁ is the pair's
    /// friction coefficient, `InterfaceLaw::mu`).
    pub mu2: f64,
}

/// The local frame (rows t₁, t₂, n) of a point with unit normal `normal` on an orthotropic
/// master with first axis `axis`: t₁ the normalised projection of `axis` on the tangent plane,
/// t₂ = n × t₁. None when `axis` is (nearly) normal to the surface.
pub fn aligned_frame(normal: [f64; 3], axis: [f64; 3]) -> Option<[[f64; 3]; 3]> {
    let (n, a) = (Vector3::from(normal), Vector3::from(axis));
    let projected = a - n * a.dot(&n);
    let len = projected.norm();
    if len.is_nan() || len <= 1e-6 * a.norm() {
        return None;
    }
    let t1 = projected / len;
    let t2 = n.cross(&t1);
    Some([t1.into(), t2.into(), normal])
}

/// The scaling T = diag(1, s, 1) applied to a local vector.
pub fn scale(v: Vec3, s: f64) -> Vec3 {
    Vec3::new(v[0], s * v[1], v[2])
}

/// T⁻¹ applied to a local vector.
pub fn unscale(v: Vec3, s: f64) -> Vec3 {
    Vec3::new(v[0], v[1] / s, v[2])
}

/// T M T for a local 3×3 matrix M (a compliance such as W).
pub fn scale_matrix(m: Mat3, s: f64) -> Mat3 {
    let t = Vec3::new(1.0, s, 1.0);
    Mat3::from_fn(|i, j| t[i] * m[(i, j)] * t[j])
}

/// T⁻¹ M T⁻¹ for a local 3×3 matrix M (a stiffness −∂r/∂x seen in the scaled variables).
pub fn unscale_matrix(m: Mat3, s: f64) -> Mat3 {
    let t = Vec3::new(1.0, s, 1.0);
    Mat3::from_fn(|i, j| m[(i, j)] / (t[i] * t[j]))
}

/// Friction force (t₁, t₂ components) [N] of a point sliding in the unit direction `slip` of the
/// tangent plane under the normal force `rn` [N], by maximal dissipation on the elliptic cone:
/// r_t = −r_n (μ₁² d₁, μ₂² d₂)/√(μ₁² d₁² + μ₂² d₂²). A closed form for tests and figures.
pub fn sliding_friction(mu1: f64, mu2: f64, rn: f64, slip: [f64; 2]) -> [f64; 2] {
    let m = (mu1 * slip[0]).hypot(mu2 * slip[1]);
    [-rn * mu1 * mu1 * slip[0] / m, -rn * mu2 * mu2 * slip[1] / m]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_follows_the_axis_projected_on_the_tangent_plane() {
        let n = [0.0, 1.0, 0.0];
        let f = aligned_frame(n, [2.0, 0.5, 0.0]).unwrap();
        assert_eq!(f[0], [1.0, 0.0, 0.0]);
        assert_eq!(f[1], [0.0, 0.0, -1.0]);
        // Right-handed: t₁ × t₂ = n.
        let t1t2 = Vector3::from(f[0]).cross(&Vector3::from(f[1]));
        assert_eq!(<[f64; 3]>::from(t1t2), n);
        assert!(aligned_frame(n, [0.0, 3.0, 0.0]).is_none());
    }

    /// Maximal dissipation: the force lies on the ellipse and its normal there is the slip.
    #[test]
    fn sliding_friction_is_on_the_ellipse_with_the_slip_as_its_normal() {
        let (mu1, mu2, rn) = (0.6, 0.2, 3.0);
        for deg in [0.0f64, 20.0, 45.0, 80.0, 90.0] {
            let d = [deg.to_radians().cos(), deg.to_radians().sin()];
            let f = sliding_friction(mu1, mu2, rn, d);
            let e = (f[0] / mu1).hypot(f[1] / mu2) / rn;
            assert!((e - 1.0).abs() < 1e-14, "{deg}°: {e}");
            // Outward normal of the ellipse at −f: (f₁/μ₁², f₂/μ₂²) up to sign, parallel to d.
            let n = [-f[0] / (mu1 * mu1), -f[1] / (mu2 * mu2)];
            assert!((n[0] * d[1] - n[1] * d[0]).abs() < 1e-12, "{deg}°");
            assert!(n[0] * d[0] + n[1] * d[1] > 0.0);
        }
    }
}
