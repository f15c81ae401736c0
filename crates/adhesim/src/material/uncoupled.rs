//! Volumetric/isochoric ("uncoupled") split shared by the nearly incompressible materials:
//!
//! W(C) = W̄(C̄) + U(J),  C̄ = J^(−2/3) C,  J = √det C,  U(J) = κ/2 (J − 1)² = (J − 1)²/D₁.
//!
//! With S̄ = 2 ∂W̄/∂C̄ and ℂ̄ = 4 ∂²W̄/∂C̄∂C̄ (the fictitious stress and elasticity of the
//! isochoric part), the stress and tangent are (Holzapfel, *Nonlinear Solid Mechanics*, 2000,
//! §6.4 and §6.6):
//!
//! S = S_iso + S_vol,  S_iso = J^(−2/3) ℙ:S̄,  S_vol = J p C⁻¹,  p = U′(J) = κ (J − 1),
//!
//! ℂ = J^(−4/3) ℙ:ℂ̄:ℙᵀ + ⅔ (S̄:C̄) ℙ̃ − ⅔ (C⁻¹⊗S_iso + S_iso⊗C⁻¹)
//!   + J (p + J U″) C⁻¹⊗C⁻¹ − 2 J p C⁻¹⊙C⁻¹,
//!
//! where ℙ = 𝕀 − ⅓ C⁻¹⊗C, ℙ̃ = C⁻¹⊙C⁻¹ − ⅓ C⁻¹⊗C⁻¹ and (A⊙A)_ijkl = ½(A_ik A_jl + A_il A_jk).

use super::{inverse_and_det, voigt_tangent};
use crate::{Mat3, Mat6};

/// A 4th-order tensor as a 9×9 array indexed by (3i + j, 3k + l).
pub(crate) type Tensor4 = [[f64; 9]; 9];

/// The isochoric part W̄(C̄) of an uncoupled material.
pub(crate) trait Isochoric {
    /// W̄ [J/m³] at the isochoric right Cauchy-Green tensor C̄ (det C̄ = 1).
    fn iso_energy(&self, cbar: &Mat3) -> f64;
    /// S̄ = 2 ∂W̄/∂C̄ [Pa].
    fn iso_stress(&self, cbar: &Mat3) -> Mat3;
    /// S̄ and ℂ̄ = 2 ∂S̄/∂C̄ [Pa] (`None` when ℂ̄ = 0).
    fn iso_stress_and_tangent(&self, cbar: &Mat3) -> (Mat3, Option<Tensor4>);
}

/// `Hyperelastic` for a material whose isochoric part implements [`Isochoric`] and whose bulk
/// modulus is its field `kappa`: energy, stress and tangent through this module's split, and
/// the small-strain shear modulus given as a function of the material.
macro_rules! uncoupled_hyperelastic {
    ($material:ty, $shear_modulus:expr) => {
        impl $crate::material::Hyperelastic for $material {
            /// W [J/m³]; +∞ when det C ≤ 0 (or is NaN).
            fn energy(&self, c: &$crate::Mat3) -> f64 {
                $crate::material::uncoupled::energy(self, self.kappa, c)
            }

            fn pk2(&self, c: &$crate::Mat3) -> $crate::Mat3 {
                $crate::material::uncoupled::pk2(self, self.kappa, c)
            }

            fn pk2_and_tangent(&self, c: &$crate::Mat3) -> ($crate::Mat3, $crate::Mat6) {
                $crate::material::uncoupled::pk2_and_tangent(self, self.kappa, c)
            }

            fn shear_modulus(&self) -> f64 {
                let shear: fn(&$material) -> f64 = $shear_modulus;
                shear(self)
            }

            fn bulk_modulus(&self) -> f64 {
                self.kappa
            }

            fn isochoric_pk2_and_tangent(
                &self,
                c: &$crate::Mat3,
            ) -> Option<($crate::Mat3, $crate::Mat6)> {
                Some($crate::material::uncoupled::pk2_and_tangent(self, 0.0, c))
            }
        }
    };
}
pub(crate) use uncoupled_hyperelastic;

/// W(C) = W̄(C̄) + κ/2 (J − 1)²; +∞ when det C ≤ 0 (or is NaN).
pub(crate) fn energy(iso: &impl Isochoric, kappa: f64, c: &Mat3) -> f64 {
    let i3 = c.determinant();
    if i3.is_nan() || i3 <= 0.0 {
        return f64::INFINITY;
    }
    let j = i3.sqrt();
    let cbar = c * j.powf(-2.0 / 3.0);
    iso.iso_energy(&cbar) + 0.5 * kappa * (j - 1.0) * (j - 1.0)
}

/// S_iso = J^(−2/3) ℙ:S̄ = J^(−2/3) S̄ − ⅓ (S̄:C̄) C⁻¹ [Pa].
fn iso_pk2(sbar: &Mat3, cbar: &Mat3, a: &Mat3, j23: f64) -> Mat3 {
    sbar * j23 - a * (sbar.dot(cbar) / 3.0)
}

/// S = S_iso + S_vol [Pa].
pub(crate) fn pk2(iso: &impl Isochoric, kappa: f64, c: &Mat3) -> Mat3 {
    let (a, det) = inverse_and_det(c);
    let j = det.sqrt();
    let j23 = j.powf(-2.0 / 3.0);
    let cbar = c * j23;
    let sbar = iso.iso_stress(&cbar);
    iso_pk2(&sbar, &cbar, &a, j23) + a * (j * kappa * (j - 1.0))
}

/// S and the Voigt tangent D = 2 ∂S/∂C [Pa].
pub(crate) fn pk2_and_tangent(iso: &impl Isochoric, kappa: f64, c: &Mat3) -> (Mat3, Mat6) {
    let (a, det) = inverse_and_det(c);
    let j = det.sqrt();
    let j23 = j.powf(-2.0 / 3.0);
    let cbar = c * j23;
    let (sbar, cfict) = iso.iso_stress_and_tangent(&cbar);
    let s_iso = iso_pk2(&sbar, &cbar, &a, j23);
    let p = kappa * (j - 1.0);
    let s = s_iso + a * (j * p);
    let tr = sbar.dot(&cbar);
    // ℙ:ℂ̄:ℙᵀ = X − ⅓ A⊗(C:X) − ⅓ (X:C)⊗A + ⅑ (C:X:C) A⊗A, with X = ℂ̄.
    let projected = cfict.map(|x| {
        let mut cx = [0.0; 9]; // (C:X)_kl
        let mut xc = [0.0; 9]; // (X:C)_ij
        for p in 0..9 {
            for q in 0..9 {
                let (cp, cq) = (c[(p / 3, p % 3)], c[(q / 3, q % 3)]);
                cx[q] += cp * x[p][q];
                xc[p] += x[p][q] * cq;
            }
        }
        let cxc: f64 = (0..9).map(|q| cx[q] * c[(q / 3, q % 3)]).sum();
        let mut out = [[0.0; 9]; 9];
        for p in 0..9 {
            let ap = a[(p / 3, p % 3)];
            for q in 0..9 {
                let aq = a[(q / 3, q % 3)];
                out[p][q] = x[p][q] - (ap * cx[q] + xc[p] * aq) / 3.0 + cxc * ap * aq / 9.0;
            }
        }
        out
    });
    let j43 = j23 * j23;
    let vol_aa = j * (p + j * kappa); // J (p + J U″)
    let d = voigt_tangent(|i, jj, k, l| {
        let sym = 0.5 * (a[(i, k)] * a[(jj, l)] + a[(i, l)] * a[(jj, k)]);
        let aa = a[(i, jj)] * a[(k, l)];
        let mut v = 2.0 / 3.0 * tr * (sym - aa / 3.0)
            - 2.0 / 3.0 * (a[(i, jj)] * s_iso[(k, l)] + s_iso[(i, jj)] * a[(k, l)])
            + vol_aa * aa
            - 2.0 * j * p * sym;
        if let Some(pr) = &projected {
            v += j43 * pr[3 * i + jj][3 * k + l];
        }
        v
    });
    (s, d)
}

/// κ [Pa] from either `kappa` or the Abaqus compressibility D₁ [1/Pa] (κ = 2/D₁).
pub fn bulk_from_d1(d1: f64) -> f64 {
    2.0 / d1
}
