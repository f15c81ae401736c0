//! Small-strain isotropic linear elasticity.

use super::saint_venant_kirchhoff::{linear_stress, quadratic_energy};
use super::{isotropic_tangent, lame_from_young_poisson, Hyperelastic};
use crate::{Mat3, Mat6};

/// Isotropic linear elastic material for small strains.
///
/// It uses the Saint Venant-Kirchhoff formulas, fed by the element with C = I + 2ε where ε is
/// the small strain, so that E = ε and
///
/// W = λ/2 (tr ε)² + μ ε:ε,  σ = λ tr(ε) I + 2μ ε,  ℂ = λ δ_ij δ_kl + μ (δ_ik δ_jl + δ_il δ_jk).
///
/// [`Hyperelastic::small_strain`] returns true, which tells the element to use linear kinematics.
/// W is finite for every C.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Shear modulus μ [Pa].
    pub mu: f64,
    /// First Lamé parameter λ [Pa].
    pub lambda: f64,
}

impl LinearElastic {
    /// Material from Young's modulus `e` [Pa] and Poisson's ratio `nu` [-] (−1 < ν < ½).
    pub fn from_young_poisson(e: f64, nu: f64) -> Self {
        let (mu, lambda) = lame_from_young_poisson(e, nu);
        LinearElastic { mu, lambda }
    }
}

impl Hyperelastic for LinearElastic {
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

    fn small_strain(&self) -> bool {
        true
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

    fn material() -> LinearElastic {
        LinearElastic::from_young_poisson(7.0e10, 0.33)
    }

    material_checks! {
        material: material(),
        small_strain: |m| (m.mu, m.lambda),
        seed: 41,
    }

    #[test]
    fn energy_of_a_zero_deformation_is_finite() {
        assert!(material().energy(&Mat3::zeros()).is_finite());
    }

    #[test]
    fn is_small_strain_and_from_young_poisson_uses_lame_parameters() {
        let m = LinearElastic::from_young_poisson(2.5, 0.25);
        assert!((m.mu - 1.0).abs() < 1e-15 && (m.lambda - 1.0).abs() < 1e-15);
        assert!(m.small_strain());
    }

    /// With C = I + 2ε the stress is Hooke's law σ = λ tr(ε) I + 2μ ε and W = ½ σ:ε.
    #[test]
    fn hooke_law_from_small_strain() {
        let m = material();
        let eps = Mat3::new(1e-3, 2e-4, -3e-4, 2e-4, -5e-4, 1e-4, -3e-4, 1e-4, 2e-4);
        let c = Mat3::identity() + eps * 2.0;
        let sigma = Mat3::identity() * (m.lambda * eps.trace()) + eps * (2.0 * m.mu);
        assert!((m.pk2(&c) - sigma).amax() <= 1e-12 * sigma.amax());
        let w = 0.5 * sigma.component_mul(&eps).sum();
        assert!((m.energy(&c) - w).abs() <= 1e-12 * w.abs());
        // σ_v = D ε_v with engineering shears.
        let (_, d) = m.pk2_and_tangent(&c);
        let eps_v = nalgebra::Vector6::new(
            eps[(0, 0)],
            eps[(1, 1)],
            eps[(2, 2)],
            2.0 * eps[(0, 1)],
            2.0 * eps[(1, 2)],
            2.0 * eps[(0, 2)],
        );
        assert!((d * eps_v - voigt(&sigma)).amax() <= 1e-12 * sigma.amax());
    }
}
