//! Compressible neo-Hookean material.

use super::{inverse_and_det, lame_from_young_poisson, voigt_tangent, Hyperelastic};
use crate::{Mat3, Mat6};

/// Compressible neo-Hookean material:
///
/// W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²,  S = μ (I − C⁻¹) + λ ln J C⁻¹,  J = √det C.
///
/// Tangent, with A = C⁻¹: ℂ_ijkl = λ A_ij A_kl + (μ − λ ln J)(A_ik A_jl + A_il A_jk).
/// Small-strain limit: Lamé parameters (μ, λ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    /// Shear modulus μ [Pa].
    pub mu: f64,
    /// First Lamé parameter λ [Pa].
    pub lambda: f64,
}

impl NeoHookean {
    /// Material from Young's modulus `e` [Pa] and Poisson's ratio `nu` [-] (−1 < ν < ½).
    pub fn from_young_poisson(e: f64, nu: f64) -> Self {
        let (mu, lambda) = lame_from_young_poisson(e, nu);
        NeoHookean { mu, lambda }
    }
}

impl Hyperelastic for NeoHookean {
    /// W [J/m³]; +∞ when det C ≤ 0 (or is NaN).
    fn energy(&self, c: &Mat3) -> f64 {
        let i3 = c.determinant();
        if i3.is_nan() || i3 <= 0.0 {
            return f64::INFINITY;
        }
        let ln_j = 0.5 * i3.ln();
        0.5 * self.mu * (c.trace() - 3.0) - self.mu * ln_j + 0.5 * self.lambda * ln_j * ln_j
    }

    fn pk2(&self, c: &Mat3) -> Mat3 {
        let (a, det) = inverse_and_det(c);
        let ln_j = 0.5 * det.ln();
        Mat3::identity() * self.mu + a * (self.lambda * ln_j - self.mu)
    }

    fn pk2_and_tangent(&self, c: &Mat3) -> (Mat3, Mat6) {
        let (a, det) = inverse_and_det(c);
        let ln_j = 0.5 * det.ln();
        let s = Mat3::identity() * self.mu + a * (self.lambda * ln_j - self.mu);
        let (lambda, m) = (self.lambda, self.mu - self.lambda * ln_j);
        let d = voigt_tangent(|i, j, k, l| {
            lambda * a[(i, j)] * a[(k, l)] + m * (a[(i, k)] * a[(j, l)] + a[(i, l)] * a[(j, k)])
        });
        (s, d)
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

    /// A rubber-like material (ν = 0.45), where λ dominates the tangent.
    fn material() -> NeoHookean {
        NeoHookean::from_young_poisson(3.0e6, 0.45)
    }

    material_checks! {
        material: material(),
        small_strain: |m| (m.mu, m.lambda),
        seed: 21,
    }

    #[test]
    fn energy_is_infinite_where_j_is_not_positive() {
        let m = material();
        assert_eq!(m.energy(&Mat3::zeros()), f64::INFINITY);
        assert_eq!(m.energy(&-Mat3::identity()), f64::INFINITY);
    }

    #[test]
    fn from_young_poisson_uses_lame_parameters() {
        let m = NeoHookean::from_young_poisson(2.5, 0.25);
        assert!((m.mu - 1.0).abs() < 1e-15 && (m.lambda - 1.0).abs() < 1e-15);
    }
}
