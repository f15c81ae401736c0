//! Error measure of a dry frictional contact solution: the natural-map residual of the
//! bi-potential form of the Signorini–Coulomb law, as reported by Siconos and used for the fclib
//! problems.
//!
//! At one contact point, with local components ordered (t1, t2, n), `r_n > 0` compression and
//! `x` the local relative displacement (or velocity) with `x_n ≥ 0` apart, the law holds iff
//!
//! F(r, x) = r − P_K(r − ρ (x + μ‖x_t‖ n)) = 0
//!
//! for any ρ > 0, where P_K is the projection onto the Coulomb cone K_μ
//! (`cone::dry_projection`) and `x + μ‖x_t‖ n` is the bi-potential's modified relative
//! displacement (`cone::bipotential_trial`).
//!
//! # Normalisation
//! [`natural_map_residual`] returns the plain Euclidean norm over all points,
//! ‖F‖ = (Σ_α ‖F_α‖²)^½ with ρ = 1, so forces and displacements are added as numbers: this is
//! Siconos's measure for its dimensionless problems. [`relative_error`] divides it by
//! max(‖q‖, ‖r‖, ‖x‖) (q = x at r = 0, the free relative displacement), the normalisation of
//! Siconos 4.4's `fc3d_compute_error`, and returns the raw norm when all three vanish.

use crate::contact::law::{natural_map_defect, InterfaceLaw};

/// Natural-map defect F = r − P_K(r − ρ(x + μ‖x_t‖n)) at one point, components (t1, t2, n),
/// for the force `r` [N], local relative displacement `x` [m], friction coefficient `mu` and
/// ρ [N/m].
pub fn natural_map_point(r: [f64; 3], x: [f64; 3], mu: f64, rho: f64) -> [f64; 3] {
    natural_map_defect(&InterfaceLaw::coulomb(mu), rho, r.into(), x.into()).into()
}

/// ‖F‖ over all points with ρ = 1 (unnormalised; see the module documentation):
/// (Σ_α ‖r_α − P_K(r_α − (x_α + μ_α‖x_α,t‖n))‖²)^½. `r`, `x` and `mu` have one entry per point.
///
/// # Panics
/// If the three slices differ in length.
pub fn natural_map_residual(r: &[[f64; 3]], x: &[[f64; 3]], mu: &[f64]) -> f64 {
    assert!(
        r.len() == x.len() && r.len() == mu.len(),
        "natural_map_residual: one r, x and mu per point"
    );
    r.iter()
        .zip(x)
        .zip(mu)
        .map(|((&r, &x), &mu)| {
            let f = natural_map_point(r, x, mu, 1.0);
            f[0] * f[0] + f[1] * f[1] + f[2] * f[2]
        })
        .sum::<f64>()
        .sqrt()
}

/// Siconos's relative error: `residual` / max(‖q‖, ‖r‖, ‖x‖), with the Euclidean norms of the
/// free relative displacement q, the force r and the relative displacement x over all points;
/// `residual` itself when all three norms are zero.
pub fn relative_error(residual: f64, q: &[[f64; 3]], r: &[[f64; 3]], x: &[[f64; 3]]) -> f64 {
    let norm = |v: &[[f64; 3]]| -> f64 {
        v.iter()
            .map(|a| a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
            .sum::<f64>()
            .sqrt()
    };
    let scale = norm(q).max(norm(r)).max(norm(x));
    if scale > 0.0 {
        residual / scale
    } else {
        residual
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact solutions of the three cases give F = 0 to rounding (tolerance 1e-15 on values of
    /// order 1), for several ρ.
    #[test]
    fn zero_at_exact_solutions() {
        let mu = 0.4;
        // Apart: no force, positive gap, any slip.
        let apart = ([0.0; 3], [0.3, -0.2, 0.05]);
        // Stick: force strictly inside the cone, no relative displacement.
        let stick = ([0.1, -0.2, 1.0], [0.0; 3]);
        // Slide: force on the cone opposing the slip, zero gap.
        let slip = [0.6, 0.8];
        let rn = 2.0;
        let slide = (
            [-mu * rn * slip[0], -mu * rn * slip[1], rn],
            [0.5 * slip[0], 0.5 * slip[1], 0.0],
        );
        for (r, x) in [apart, stick, slide] {
            for rho in [0.1, 1.0, 7.0] {
                let f = natural_map_point(r, x, mu, rho);
                assert!(f.iter().all(|v| v.abs() < 1e-15), "{r:?} {x:?} {f:?}");
            }
        }
        let res = natural_map_residual(
            &[apart.0, stick.0, slide.0],
            &[apart.1, stick.1, slide.1],
            &[mu, mu, mu],
        );
        assert!(res < 1e-15);
    }

    /// Violations give the closed-form defect.
    #[test]
    fn positive_when_violated() {
        let mu = 0.5;
        // Penetration without force: r = 0, x = (0, 0, −d): F = −P_K((0, 0, d)) = (0, 0, −d).
        let d = 0.3;
        let f = natural_map_point([0.0; 3], [0.0, 0.0, -d], mu, 1.0);
        assert!((f[2] + d).abs() < 1e-15 && f[0] == 0.0 && f[1] == 0.0);
        // Tension with an open gap g: r = (0, 0, −s), x = (0, 0, g): r* = (0, 0, −s − g) is
        // projected to 0, so F = r and ‖F‖ = s.
        let s = 2.0;
        let res = natural_map_residual(&[[0.0, 0.0, -s]], &[[0.0, 0.0, 0.1]], &[mu]);
        assert!((res - s).abs() < 1e-15);
        // Slide in the wrong direction: force along the slip instead of against it.
        let f = natural_map_point([0.5, 0.0, 1.0], [0.2, 0.0, 0.0], mu, 1.0);
        assert!(f.iter().map(|v| v * v).sum::<f64>() > 1e-3);
        // Sticking force outside the cone with no slip.
        let f = natural_map_point([1.0, 0.0, 1.0], [0.0; 3], mu, 1.0);
        assert!(f.iter().map(|v| v * v).sum::<f64>() > 1e-3);
    }

    /// The residual sums the points' squares: two points with defects 3 and 4 give 5.
    #[test]
    fn residual_is_euclidean_over_points() {
        let res = natural_map_residual(
            &[[0.0; 3], [0.0; 3]],
            &[[0.0, 0.0, -3.0], [0.0, 0.0, -4.0]],
            &[0.3, 0.3],
        );
        assert!((res - 5.0).abs() < 1e-14);
        let q = [[0.0, 0.0, -3.0], [0.0, 0.0, -4.0]];
        let rel = relative_error(res, &q, &[[0.0; 3]; 2], &q);
        assert!((rel - 1.0).abs() < 1e-14);
        assert_eq!(relative_error(2.0, &[], &[], &[]), 2.0);
    }
}
