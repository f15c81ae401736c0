//! Nearly incompressible neo-Hookean material (uncoupled form).

use super::uncoupled::{self, Isochoric, Tensor4};
use crate::Mat3;

/// Neo-Hookean with a volumetric/isochoric split, as in Abaqus (`NEO HOOKE`) and FEBio
/// (`uncoupled` materials):
///
/// W = C₁₀ (Ī₁ − 3) + κ/2 (J − 1)²,  Ī₁ = J^(−2/3) tr C.
///
/// Small-strain shear modulus μ = 2 C₁₀, bulk modulus κ (Abaqus: κ = 2/D₁). Fictitious stress
/// S̄ = 2 C₁₀ I, fictitious elasticity ℂ̄ = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UncoupledNeoHookean {
    /// C₁₀ = μ/2 [Pa].
    pub c10: f64,
    /// Bulk modulus κ [Pa].
    pub kappa: f64,
}

impl UncoupledNeoHookean {
    /// From Young's modulus `e` [Pa] and Poisson's ratio `nu` (−1 < ν < ½) in the small-strain
    /// limit: μ = E / (2(1 + ν)), κ = E / (3(1 − 2ν)).
    pub fn from_young_poisson(e: f64, nu: f64) -> Self {
        UncoupledNeoHookean {
            c10: e / (4.0 * (1.0 + nu)),
            kappa: e / (3.0 * (1.0 - 2.0 * nu)),
        }
    }
}

impl Isochoric for UncoupledNeoHookean {
    fn iso_energy(&self, cbar: &Mat3) -> f64 {
        self.c10 * (cbar.trace() - 3.0)
    }

    fn iso_stress(&self, _cbar: &Mat3) -> Mat3 {
        Mat3::identity() * (2.0 * self.c10)
    }

    fn iso_stress_and_tangent(&self, cbar: &Mat3) -> (Mat3, Option<Tensor4>) {
        (self.iso_stress(cbar), None)
    }
}

uncoupled::uncoupled_hyperelastic!(UncoupledNeoHookean, |m| 2.0 * m.c10);

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::MooneyRivlin;
    use super::*;
    use crate::material::Hyperelastic;

    /// PDMS-like: E = 1 MPa, ν = 0.4999.
    fn material() -> UncoupledNeoHookean {
        UncoupledNeoHookean::from_young_poisson(1.0e6, 0.4999)
    }

    material_checks! {
        material: material(),
        compressible: UncoupledNeoHookean::from_young_poisson(1.0e6, 0.3),
        small_strain: |m| (2.0 * m.c10, m.kappa - 4.0 * m.c10 / 3.0),
        seed: 31,
    }

    #[test]
    fn young_poisson_conversion() {
        let m = UncoupledNeoHookean::from_young_poisson(2.6, 0.3);
        assert!((2.0 * m.c10 - 1.0).abs() < 1e-15);
        assert!((m.kappa - 2.6 / 1.2).abs() < 1e-15);
    }

    #[test]
    fn equals_mooney_rivlin_without_second_invariant() {
        let m = material();
        let mr = MooneyRivlin {
            c10: m.c10,
            c01: 0.0,
            kappa: m.kappa,
        };
        for c in sample_c(36) {
            assert!((m.pk2(&c) - mr.pk2(&c)).amax() <= 1e-12 * m.pk2(&c).amax());
            assert!((m.energy(&c) - mr.energy(&c)).abs() <= 1e-12 * m.energy(&c).abs());
        }
    }
}
