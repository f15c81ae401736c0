//! Nearly incompressible Mooney-Rivlin material (uncoupled form).

use super::uncoupled::{self, Isochoric, Tensor4};
use crate::Mat3;

/// Mooney-Rivlin with a volumetric/isochoric split, as in Abaqus and FEBio:
///
/// W = C₁₀ (Ī₁ − 3) + C₀₁ (Ī₂ − 3) + κ/2 (J − 1)²,
///
/// Ī₁ = tr C̄, Ī₂ = ½ (Ī₁² − tr C̄²), C̄ = J^(−2/3) C. Small-strain shear modulus
/// μ = 2 (C₁₀ + C₀₁), bulk modulus κ (Abaqus: κ = 2/D₁). C₀₁ = 0 is the uncoupled
/// neo-Hookean solid ([`UncoupledNeoHookean`](super::UncoupledNeoHookean)).
///
/// Fictitious stress and elasticity: S̄ = 2 C₁₀ I + 2 C₀₁ (Ī₁ I − C̄),
/// ℂ̄ = 4 C₀₁ (I⊗I − 𝕀) with 𝕀_ijkl = ½ (δ_ik δ_jl + δ_il δ_jk).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MooneyRivlin {
    /// C₁₀ [Pa].
    pub c10: f64,
    /// C₀₁ [Pa].
    pub c01: f64,
    /// Bulk modulus κ [Pa].
    pub kappa: f64,
}

impl Isochoric for MooneyRivlin {
    fn iso_energy(&self, cbar: &Mat3) -> f64 {
        let i1 = cbar.trace();
        let i2 = 0.5 * (i1 * i1 - (cbar * cbar).trace());
        self.c10 * (i1 - 3.0) + self.c01 * (i2 - 3.0)
    }

    fn iso_stress(&self, cbar: &Mat3) -> Mat3 {
        let i1 = cbar.trace();
        Mat3::identity() * (2.0 * self.c10 + 2.0 * self.c01 * i1) - cbar * (2.0 * self.c01)
    }

    fn iso_stress_and_tangent(&self, cbar: &Mat3) -> (Mat3, Option<Tensor4>) {
        let s = self.iso_stress(cbar);
        if self.c01 == 0.0 {
            return (s, None);
        }
        let delta = |a: usize, b: usize| if a == b { 1.0 } else { 0.0 };
        let mut t = [[0.0; 9]; 9];
        for (p, row) in t.iter_mut().enumerate() {
            let (i, j) = (p / 3, p % 3);
            for (q, v) in row.iter_mut().enumerate() {
                let (k, l) = (q / 3, q % 3);
                let sym = 0.5 * (delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k));
                *v = 4.0 * self.c01 * (delta(i, j) * delta(k, l) - sym);
            }
        }
        (s, Some(t))
    }
}

uncoupled::uncoupled_hyperelastic!(MooneyRivlin, |m| 2.0 * (m.c10 + m.c01));

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;
    use crate::material::Hyperelastic;

    /// A rubber with a strong second invariant term and ν ≈ 0.4999 (κ/μ = 5000).
    fn material() -> MooneyRivlin {
        MooneyRivlin {
            c10: 0.3e6,
            c01: 0.2e6,
            kappa: 5.0e9,
        }
    }

    material_checks! {
        material: material(),
        compressible: MooneyRivlin { kappa: 1.0e6, ..material() },
        small_strain: |m| (2.0 * (m.c10 + m.c01), m.kappa - 4.0 * (m.c10 + m.c01) / 3.0),
        seed: 41,
    }

    #[test]
    fn incompressible_uniaxial_stress_matches_the_closed_form() {
        // Isochoric uniaxial stretch λ: Cauchy σ = 2 (λ² − 1/λ)(C₁₀ + C₀₁/λ) (Rivlin), the
        // lateral stress being zero once the pressure is eliminated: σ₁₁ − σ₂₂ of the model
        // must match, the volumetric part adding the same pressure to both.
        let m = material();
        for lambda in [0.6, 0.9, 1.3, 2.0] {
            let f = Mat3::from_diagonal(&nalgebra::Vector3::new(
                lambda,
                lambda.powf(-0.5),
                lambda.powf(-0.5),
            ));
            let s = m.pk2(&(f.transpose() * f));
            let sigma = f * s * f.transpose();
            let expected = 2.0 * (lambda * lambda - 1.0 / lambda) * (m.c10 + m.c01 / lambda);
            let got = sigma[(0, 0)] - sigma[(1, 1)];
            assert!(
                (got - expected).abs() < 1e-9 * expected.abs(),
                "{got} vs {expected}"
            );
        }
    }
}
