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

use super::detect::{ContactPair, ContactPoint};
use super::law::{bipotential_trial, dry_projection, InterfaceLaw};
use nalgebra::Vector3;

/// The material axes and second friction coefficient of an orthotropic interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orthotropy {
    /// First material axis of the master surface, global components; at each contact point
    /// t₁ is its projection on the tangent plane.
    pub axis: [f64; 3],
    /// Friction coefficient μ₂ along the second axis t₂ = n × t₁ [-] (μ₁ is
    /// [`InterfaceLaw::mu`]).
    pub mu2: f64,
}

/// The scale s = μ₂/μ₁ of the second tangential axis that maps the law's cone on the circular
/// cone of μ₁: 1 for an isotropic law (and for μ₁ = μ₂).
pub fn tangent_scale(law: &InterfaceLaw) -> f64 {
    match &law.anisotropy {
        Some(o) if o.mu2 != law.mu && law.mu > 0.0 && o.mu2 > 0.0 => o.mu2 / law.mu,
        _ => 1.0,
    }
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

/// Turns the frames of the points of orthotropic pairs to their material axes (points where
/// the axis is normal to the surface keep their frame).
pub fn align_frames(points: &mut [ContactPoint], pairs: &[ContactPair]) {
    for pt in points {
        if let Some(o) = &pairs[pt.pair].law.anisotropy {
            if let Some(frame) = aligned_frame(pt.frame[2], o.axis) {
                pt.frame = frame;
            }
        }
    }
}

/// The scaling T = diag(1, s, 1) applied to a local vector.
pub fn scale(v: [f64; 3], s: f64) -> [f64; 3] {
    [v[0], s * v[1], v[2]]
}

/// T⁻¹ applied to a local vector.
pub fn unscale(v: [f64; 3], s: f64) -> [f64; 3] {
    [v[0], v[1] / s, v[2]]
}

/// T M T for a local 3×3 matrix M (a compliance such as W).
pub fn scale_matrix(m: [[f64; 3]; 3], s: f64) -> [[f64; 3]; 3] {
    let t = [1.0, s, 1.0];
    std::array::from_fn(|i| std::array::from_fn(|j| t[i] * m[i][j] * t[j]))
}

/// T⁻¹ M T⁻¹ for a local 3×3 matrix M (a stiffness −∂r/∂x seen in the scaled variables).
pub fn unscale_matrix(m: [[f64; 3]; 3], s: f64) -> [[f64; 3]; 3] {
    let t = [1.0, s, 1.0];
    std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] / (t[i] * t[j])))
}

/// The defect r̄ − P_K(r̄ − ρ x̂) [N] of the law's bi-potential condition at a dry force `r_dry`
/// [N] and local relative displacement `x` [m], with `rho` [N/m]: zero exactly at a solution.
/// For an orthotropic law it is evaluated in the scaled variables and mapped back by T.
pub fn natural_map_defect(law: &InterfaceLaw, rho: f64, r_dry: [f64; 3], x: [f64; 3]) -> [f64; 3] {
    let s = tangent_scale(law);
    let (r, y) = if s == 1.0 {
        (r_dry, x)
    } else {
        (unscale(r_dry, s), scale(x, s))
    };
    let p = dry_projection(bipotential_trial(r, y, law.mu, rho), law.mu).0;
    let d = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
    if s == 1.0 {
        d
    } else {
        scale(d, s)
    }
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
    use crate::contact::law::{solve_point, BondState, PointProblem, RccParams};
    use crate::contact::newton::augmented_point;

    fn law(mu1: f64, mu2: f64) -> InterfaceLaw {
        InterfaceLaw {
            mu: mu1,
            adhesion: None,
            anisotropy: Some(Orthotropy {
                axis: [1.0, 0.0, 0.0],
                mu2,
            }),
        }
    }

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

    /// A point pushed along the plane with a stiff compliance slides; its friction force is
    /// on the ellipse, opposite to the slip's dual direction, as the closed form says, for
    /// slips along each axis and at 45°.
    #[test]
    fn sliding_point_lands_on_the_ellipse_with_the_maximal_dissipation_direction() {
        let (mu1, mu2) = (0.6, 0.2);
        let l = law(mu1, mu2);
        let c = 1e-6; // compliance [m/N]
        for angle in [0.0f64, 45.0, 90.0, 30.0] {
            let a = angle.to_radians();
            // Free displacement: pressed 1 mm into the plane and pushed 10 mm along (cos, sin).
            let x_free = [1e-2 * a.cos(), 1e-2 * a.sin(), -1e-3];
            let p = PointProblem {
                w_aa: [[c, 0.0, 0.0], [0.0, c, 0.0], [0.0, 0.0, c]],
                x_free,
                law: &l,
                bond0: BondState::default(),
                dt: 1e-3,
                area: 1e-6,
                rho: 1.0 / c,
            };
            let sol = solve_point(&p, [0.0; 3], 1e-12, 100);
            assert!(sol.converged, "{angle}°");
            let rn = sol.r_dry[2];
            assert!((rn - 1e-3 / c).abs() < 1e-9 * rn, "{angle}°: r_n {rn}");
            // On the ellipse.
            let e = (sol.r_dry[0] / mu1).hypot(sol.r_dry[1] / mu2) / rn;
            assert!((e - 1.0).abs() < 1e-10, "{angle}°: {e}");
            // The slip direction and the force by maximal dissipation.
            let slip_len = sol.x[0].hypot(sol.x[1]);
            let d = [sol.x[0] / slip_len, sol.x[1] / slip_len];
            let expect = sliding_friction(mu1, mu2, rn, d);
            for k in 0..2 {
                assert!(
                    (sol.r_dry[k] - expect[k]).abs() < 1e-9 * rn,
                    "{angle}°: r_t {:?} vs {expect:?}",
                    sol.r_dry
                );
            }
            // The Newton solve's law agrees at the same x with λ = r̄ (a fixed point).
            let ap = augmented_point(
                &l,
                BondState::default(),
                1e-3,
                1e-6,
                1.0 / c,
                sol.r_dry,
                sol.x,
            );
            for k in 0..3 {
                assert!(
                    (ap.solution.r_dry[k] - sol.r_dry[k]).abs() < 1e-9 * rn,
                    "{angle}°"
                );
            }
            let defect = natural_map_defect(&l, 1.0 / c, sol.r_dry, sol.x);
            assert!(
                defect.iter().all(|v| v.abs() < 1e-9 * rn),
                "{angle}°: {defect:?}"
            );
        }
    }

    /// μ₁ = μ₂ and C_t1 = C_t2 on aligned axes give the isotropic law's solution.
    #[test]
    fn equal_coefficients_reproduce_the_isotropic_law() {
        let mut rcc = RccParams::new(20.0, 2e9, 2e9, 0.1);
        rcc.ct2 = rcc.ct;
        let iso = InterfaceLaw {
            mu: 0.4,
            adhesion: Some(rcc),
            anisotropy: None,
        };
        let ortho = InterfaceLaw {
            anisotropy: Some(Orthotropy {
                axis: [1.0, 0.0, 0.0],
                mu2: 0.4,
            }),
            ..iso
        };
        let w = [[2e-6, 3e-7, 1e-7], [3e-7, 1e-6, -2e-7], [1e-7, -2e-7, 3e-6]];
        for x_free in [
            [1e-4, -3e-5, -2e-5],
            [2e-6, 1e-6, 5e-6],
            [1e-3, 1e-3, -1e-6],
        ] {
            let bond0 = BondState {
                beta: 0.7,
                ut: [1e-6, -2e-6],
                damage: 0.0,
            };
            let p = |law| PointProblem {
                w_aa: w,
                x_free,
                law,
                bond0,
                dt: 1e-3,
                area: 1e-6,
                rho: 0.0,
            };
            let a = solve_point(&p(&iso), [0.0; 3], 1e-12, 200);
            let b = solve_point(&p(&ortho), [0.0; 3], 1e-12, 200);
            assert_eq!(a, b);
        }
    }

    /// Orthotropic tangential adhesion: a bonded point stretched along t₁ or t₂ carries
    /// −C_ti u_i β² A, the law's energy gradient.
    #[test]
    fn orthotropic_adhesion_stiffness_per_axis() {
        let mut rcc = RccParams::new(20.0, 2e9, 4e9, 0.0);
        rcc.ct2 = 1e9;
        let area = 1e-6;
        let bond = BondState {
            beta: 1.0,
            ut: [0.0; 2],
            damage: 0.0,
        };
        let u = 1e-7; // well inside the bond's strength: β stays 1
        for (k, ct) in [(0usize, 4e9), (1, 1e9)] {
            let mut x = [0.0; 3];
            x[k] = u;
            let r = crate::contact::law::adhesive_response(&rcc, bond, 1e-3, area, x);
            assert_eq!(r.beta, 1.0);
            let expect = -ct * u * area;
            assert!(
                (r.force[k] - expect).abs() < 1e-12 * expect.abs(),
                "axis {k}"
            );
            assert_eq!(r.force[1 - k], 0.0);
            assert!((r.secant_stiffness[k][k] - ct * area).abs() < 1e-6);
            // −∂φ/∂x_k by central differences.
            let h = 1e-10;
            let (mut xp, mut xm) = (x, x);
            xp[k] += h;
            xm[k] -= h;
            let fd = -(crate::contact::law::adhesive_response(&rcc, bond, 1e-3, area, xp).energy
                - crate::contact::law::adhesive_response(&rcc, bond, 1e-3, area, xm).energy)
                / (2.0 * h);
            assert!(
                (fd - r.force[k]).abs() < 1e-6 * r.force[k].abs(),
                "axis {k}: {fd}"
            );
        }
    }
}
