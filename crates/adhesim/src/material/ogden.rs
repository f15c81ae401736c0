//! Nearly incompressible Ogden material (uncoupled form, N terms).

use super::uncoupled::{self, Isochoric, Tensor4};
use crate::Mat3;

/// Ogden with a volumetric/isochoric split, in the Abaqus convention (`HYPERELASTIC, OGDEN`):
///
/// W = Σᵢ 2μᵢ/αᵢ² (λ̄₁^αᵢ + λ̄₂^αᵢ + λ̄₃^αᵢ − 3) + κ/2 (J − 1)²,
///
/// λ̄ₖ = J^(−1/3) λₖ the isochoric principal stretches. Small-strain shear modulus μ = Σ μᵢ,
/// bulk modulus κ (Abaqus: κ = 2/D₁). One term with α = 2 is the neo-Hookean solid with
/// C₁₀ = μ/2; α = −2 gives the C₀₁ term of Mooney-Rivlin with C₀₁ = μ/2.
///
/// Written with C̄'s eigenvalues cₖ = λ̄ₖ², W̄ = Σᵢ 2μᵢ/αᵢ² tr(C̄^(αᵢ/2)) so that
/// S̄ = Σᵢ 2μᵢ/αᵢ C̄^(αᵢ/2 − 1); its derivative ℂ̄ = 2 ∂S̄/∂C̄ is the Daleckii-Krein form
/// ℂ̄_ijkl = 2 Σ_ab g[c_a, c_b] Q_ia Q_jb ½ (Q_ka Q_lb + Q_kb Q_la) with g(c) = Σᵢ 2μᵢ/αᵢ c^(αᵢ/2 − 1),
/// Q the eigenvectors and g[c_a, c_b] the divided difference (g′ at coincident eigenvalues).
#[derive(Debug, Clone, PartialEq)]
pub struct Ogden {
    /// μᵢ [Pa] (Σ μᵢ > 0).
    pub mu: Vec<f64>,
    /// αᵢ [-] (non-zero).
    pub alpha: Vec<f64>,
    /// Bulk modulus κ [Pa].
    pub kappa: f64,
}

impl Ogden {
    /// g(c) = Σᵢ 2μᵢ/αᵢ c^(αᵢ/2 − 1), the eigenvalue function of S̄.
    fn g(&self, c: f64) -> f64 {
        self.mu
            .iter()
            .zip(&self.alpha)
            .map(|(m, a)| 2.0 * m / a * c.powf(0.5 * a - 1.0))
            .sum()
    }

    /// g′(c).
    fn dg(&self, c: f64) -> f64 {
        self.mu
            .iter()
            .zip(&self.alpha)
            .map(|(m, a)| 2.0 * m / a * (0.5 * a - 1.0) * c.powf(0.5 * a - 2.0))
            .sum()
    }

    /// Divided difference g[x, y]; the derivative at the midpoint when x and y are close
    /// (error O((x − y)²), while the quotient would lose digits to cancellation).
    fn divided(&self, x: f64, y: f64) -> f64 {
        if (x - y).abs() <= 1e-5 * x.abs().max(y.abs()) {
            self.dg(0.5 * (x + y))
        } else {
            (self.g(x) - self.g(y)) / (x - y)
        }
    }

    fn eigen(cbar: &Mat3) -> ([f64; 3], Mat3) {
        let e = nalgebra::SymmetricEigen::new(*cbar);
        (
            [e.eigenvalues[0], e.eigenvalues[1], e.eigenvalues[2]],
            e.eigenvectors,
        )
    }
}

impl Isochoric for Ogden {
    fn iso_energy(&self, cbar: &Mat3) -> f64 {
        let (c, _) = Self::eigen(cbar);
        self.mu
            .iter()
            .zip(&self.alpha)
            .map(|(m, a)| {
                2.0 * m / (a * a) * (c.iter().map(|ck| ck.powf(0.5 * a)).sum::<f64>() - 3.0)
            })
            .sum()
    }

    fn iso_stress(&self, cbar: &Mat3) -> Mat3 {
        let (c, q) = Self::eigen(cbar);
        let gd = Mat3::from_diagonal(&nalgebra::Vector3::new(
            self.g(c[0]),
            self.g(c[1]),
            self.g(c[2]),
        ));
        q * gd * q.transpose()
    }

    fn iso_stress_and_tangent(&self, cbar: &Mat3) -> (Mat3, Option<Tensor4>) {
        let (c, q) = Self::eigen(cbar);
        let gd = Mat3::from_diagonal(&nalgebra::Vector3::new(
            self.g(c[0]),
            self.g(c[1]),
            self.g(c[2]),
        ));
        let s = q * gd * q.transpose();
        let mut dd = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                dd[a][b] = self.divided(c[a], c[b]);
            }
        }
        let mut t = [[0.0; 9]; 9];
        for (p, row) in t.iter_mut().enumerate() {
            let (i, j) = (p / 3, p % 3);
            for (r, v) in row.iter_mut().enumerate() {
                let (k, l) = (r / 3, r % 3);
                let mut sum = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        sum += dd[a][b]
                            * q[(i, a)]
                            * q[(j, b)]
                            * (q[(k, a)] * q[(l, b)] + q[(k, b)] * q[(l, a)]);
                    }
                }
                *v = sum; // 2 · ½ (…)
            }
        }
        (s, Some(t))
    }
}

uncoupled::uncoupled_hyperelastic!(Ogden, |m| m.mu.iter().sum());

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{MooneyRivlin, UncoupledNeoHookean};
    use super::*;
    use crate::material::Hyperelastic;

    /// Ogden's three-term fit of Treloar's rubber data (Ogden 1972: μₚ = 0.63, 0.0012,
    /// −0.01 MPa with W = Σ μₚ/αₚ (…)), converted to the convention here (μᵢ = μₚαₚ/2),
    /// nearly incompressible.
    fn material() -> Ogden {
        Ogden {
            mu: vec![0.4095e6, 0.003e6, 0.01e6],
            alpha: vec![1.3, 5.0, -2.0],
            kappa: 1.0e9,
        }
    }

    material_checks! {
        material: material(),
        compressible: Ogden { kappa: 1.0e6, ..material() },
        small_strain: |m| (m.mu.iter().sum::<f64>(), m.kappa - 2.0 * m.mu.iter().sum::<f64>() / 3.0),
        seed: 51,
    }

    #[test]
    fn tangent_at_coincident_stretches() {
        // Equal eigenvalues (pure dilatation, then an axisymmetric stretch) take the limit
        // branch of the divided difference; compare with FD of the stress there.
        let m = Ogden {
            kappa: 1.0e6,
            ..material()
        };
        for c in [
            Mat3::identity() * 1.3,
            Mat3::from_diagonal(&nalgebra::Vector3::new(1.5, 0.8, 0.8)),
        ] {
            let (_, d) = m.pk2_and_tangent(&c);
            let h = 1e-6;
            for a in 0..6 {
                let col = (voigt(&m.pk2(&perturb(&c, a, h))) - voigt(&m.pk2(&perturb(&c, a, -h))))
                    / (2.0 * h);
                let err = (col - d.column(a)).amax() / d.amax();
                assert!(err < 1e-6, "column {a}: {err:e}");
            }
        }
    }

    #[test]
    fn two_terms_reduce_to_mooney_rivlin() {
        // α = 2, μ₁ = 2 C₁₀: 2μ₁/4 tr C̄ = C₁₀ Ī₁. α = −2, μ₂ = 2 C₀₁: 2μ₂/4 tr C̄⁻¹ = C₀₁ Ī₂,
        // since tr C̄⁻¹ = Ī₂ when det C̄ = 1.
        let mr = MooneyRivlin {
            c10: 0.3e6,
            c01: 0.1e6,
            kappa: 1.0e8,
        };
        let og = Ogden {
            mu: vec![2.0 * mr.c10, 2.0 * mr.c01],
            alpha: vec![2.0, -2.0],
            kappa: mr.kappa,
        };
        let nh = UncoupledNeoHookean {
            c10: mr.c10,
            kappa: mr.kappa,
        };
        let og1 = Ogden {
            mu: vec![2.0 * mr.c10],
            alpha: vec![2.0],
            kappa: mr.kappa,
        };
        for c in sample_c(56) {
            let tol = 1e-10 * mr.pk2(&c).amax();
            assert!((og.pk2(&c) - mr.pk2(&c)).amax() <= tol);
            assert!((og.energy(&c) - mr.energy(&c)).abs() <= 1e-10 * mr.energy(&c).abs());
            assert!((og1.pk2(&c) - nh.pk2(&c)).amax() <= tol);
            let (d1, d2) = (og.pk2_and_tangent(&c).1, mr.pk2_and_tangent(&c).1);
            assert!((d1 - d2).amax() <= 1e-8 * d2.amax());
        }
    }
}
