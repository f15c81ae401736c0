//! Saint Venant-Kirchhoff material: Hooke's law written in Green-Lagrange strain.

use super::{isotropic_tangent, lame_from_young_poisson, Hyperelastic};
use crate::{Mat3, Mat6};

/// Saint Venant-Kirchhoff material:
///
/// W = λ/2 (tr E)² + μ E:E,  S = λ tr(E) I + 2μ E,  E = ½ (C − I),
///
/// with the constant tangent ℂ_ijkl = λ δ_ij δ_kl + μ (δ_ik δ_jl + δ_il δ_jk).
/// W is a polynomial in C, finite for every C (including det C ≤ 0); it is not suited to
/// large compressions (the stress vanishes again as J → 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaintVenantKirchhoff {
    /// Shear modulus μ [Pa].
    pub mu: f64,
    /// First Lamé parameter λ [Pa].
    pub lambda: f64,
}

impl SaintVenantKirchhoff {
    /// Material from Young's modulus `e` [Pa] and Poisson's ratio `nu` [-] (−1 < ν < ½).
    pub fn from_young_poisson(e: f64, nu: f64) -> Self {
        let (mu, lambda) = lame_from_young_poisson(e, nu);
        SaintVenantKirchhoff { mu, lambda }
    }
}

/// Green-Lagrange strain E = ½ (C − I) [-].
#[inline(always)]
fn green_lagrange(c: &Mat3) -> Mat3 {
    (c - Mat3::identity()) * 0.5
}

/// W = λ/2 (tr E)² + μ E:E with E = ½ (C − I) [J/m³].
#[inline(always)]
pub(super) fn quadratic_energy(mu: f64, lambda: f64, c: &Mat3) -> f64 {
    let e = green_lagrange(c);
    let tr = e.trace();
    0.5 * lambda * tr * tr + mu * e.norm_squared()
}

/// S = λ tr(E) I + 2μ E with E = ½ (C − I) [Pa].
#[inline(always)]
pub(super) fn linear_stress(mu: f64, lambda: f64, c: &Mat3) -> Mat3 {
    let e = green_lagrange(c);
    Mat3::identity() * (lambda * e.trace()) + e * (2.0 * mu)
}

impl Hyperelastic for SaintVenantKirchhoff {
    /// W [J/m³]; finite for every C.
    fn energy(&self, c: &Mat3) -> f64 {
        quadratic_energy(self.mu, self.lambda, c)
    }

    fn pk2(&self, c: &Mat3) -> Mat3 {
        linear_stress(self.mu, self.lambda, c)
    }

    fn pk2_and_tangent(&self, c: &Mat3) -> (Mat3, Mat6) {
        (
            linear_stress(self.mu, self.lambda, c),
            isotropic_tangent(self.mu, self.lambda),
        )
    }

    fn shear_modulus(&self) -> f64 {
        self.mu
    }

    fn bulk_modulus(&self) -> f64 {
        self.lambda + 2.0 * self.mu / 3.0
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    fn material() -> SaintVenantKirchhoff {
        SaintVenantKirchhoff::from_young_poisson(2.0e11, 0.3)
    }

    material_checks! {
        material: material(),
        small_strain: |m| (m.mu, m.lambda),
        seed: 31,
    }

    #[test]
    fn energy_of_a_zero_deformation_is_finite() {
        assert!(material().energy(&Mat3::zeros()).is_finite());
    }

    #[test]
    fn from_young_poisson_uses_lame_parameters() {
        let m = SaintVenantKirchhoff::from_young_poisson(2.5, 0.25);
        assert!((m.mu - 1.0).abs() < 1e-15 && (m.lambda - 1.0).abs() < 1e-15);
        assert!(!m.small_strain());
    }
}
