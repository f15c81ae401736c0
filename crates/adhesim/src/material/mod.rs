//! Hyperelastic materials behind one trait, written in terms of the right Cauchy-Green tensor
//! C = FᵀF.
//!
//! Voigt notation used for tangents: index order (11, 22, 33, 12, 23, 13). The tangent
//! `D` maps a Green-Lagrange strain increment written with engineering shears,
//! dE_v = (dE11, dE22, dE33, 2dE12, 2dE23, 2dE13), to the PK2 stress increment
//! dS_v = (dS11, dS22, dS33, dS12, dS23, dS13): dS_v = D dE_v, i.e. D_IJ = ℂ_ijkl = 2 ∂S_ij/∂C_kl.

use crate::{Mat3, Mat6};

/// A hyperelastic material: strain energy W(C) per unit reference volume.
pub trait Hyperelastic: Send + Sync + std::fmt::Debug {
    /// Strain energy per unit reference volume W(C) [J/m³].
    fn energy(&self, c: &Mat3) -> f64;
    /// Second Piola-Kirchhoff stress S = 2 ∂W/∂C [Pa].
    fn pk2(&self, c: &Mat3) -> Mat3;
    /// S and the material tangent D = 2 ∂S/∂C in Voigt form (see module docs) [Pa].
    fn pk2_and_tangent(&self, c: &Mat3) -> (Mat3, Mat6);
    /// True for the small-strain linear elastic material: the element then uses linear
    /// kinematics (ε = sym ∇u in place of E, B evaluated at F = I, no geometric stiffness).
    fn small_strain(&self) -> bool {
        false
    }
    /// Small-strain shear modulus [Pa], for wave-speed and time-step estimates.
    fn shear_modulus(&self) -> f64;
    /// Small-strain bulk modulus [Pa], for wave-speed and time-step estimates.
    fn bulk_modulus(&self) -> f64;
    /// The isochoric part (S_iso, D_iso) of S and D, for materials with a volumetric/isochoric
    /// split (`None` otherwise).
    fn isochoric_pk2_and_tangent(&self, _c: &Mat3) -> Option<(Mat3, Mat6)> {
        None
    }
    /// The viscoelastic model, for materials with internal variables (`None`: elastic).
    fn viscoelastic(&self) -> Option<&Viscoelastic> {
        None
    }
}

mod blatz_ko;
mod linear_elastic;
mod mooney_rivlin;
mod neo_hookean;
mod ogden;
mod saint_venant_kirchhoff;
#[cfg(test)]
mod test_support;
mod uncoupled;
mod uncoupled_neo_hookean;
mod viscoelastic;

pub use blatz_ko::BlatzKo;
pub use linear_elastic::LinearElastic;
pub use mooney_rivlin::MooneyRivlin;
pub use neo_hookean::NeoHookean;
pub use ogden::Ogden;
pub use saint_venant_kirchhoff::SaintVenantKirchhoff;
pub use uncoupled::bulk_from_d1;
pub use uncoupled_neo_hookean::UncoupledNeoHookean;
pub use viscoelastic::{to_voigt, PronyTerm, Viscoelastic};

/// Tensor index pairs (i, j) of the six Voigt components, in the order (11, 22, 33, 12, 23, 13).
pub const VOIGT_PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

/// Lamé parameters (μ, λ) [Pa] from Young's modulus `e` [Pa] and Poisson's ratio `nu` [-]:
/// μ = E / (2(1 + ν)), λ = Eν / ((1 + ν)(1 − 2ν)).
///
/// Meaningful for E > 0 and −1 < ν < ½; ν = ½ gives an infinite λ (checking the range is the
/// caller's job, e.g. when a scenario is validated).
pub fn lame_from_young_poisson(e: f64, nu: f64) -> (f64, f64) {
    let mu = e / (2.0 * (1.0 + nu));
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (mu, lambda)
}

/// Voigt 6×6 matrix of a 4th-order tensor with minor and major symmetries, given as a function
/// `t(i, j, k, l)` of its indices (0-based). Evaluates the 21 entries of the upper triangle once
/// and mirrors them, so `t` needs to be correct only up to those symmetries.
#[inline(always)]
pub fn voigt_tangent(t: impl Fn(usize, usize, usize, usize) -> f64) -> Mat6 {
    let mut d = Mat6::zeros();
    for (a, &(i, j)) in VOIGT_PAIRS.iter().enumerate() {
        for (b, &(k, l)) in VOIGT_PAIRS.iter().enumerate().skip(a) {
            let v = t(i, j, k, l);
            d[(a, b)] = v;
            d[(b, a)] = v;
        }
    }
    d
}

/// Isotropic linear elastic tangent λ δ_ij δ_kl + μ (δ_ik δ_jl + δ_il δ_jk) in Voigt form [Pa].
pub fn isotropic_tangent(mu: f64, lambda: f64) -> Mat6 {
    let mut d = Mat6::zeros();
    for a in 0..3 {
        for b in 0..3 {
            d[(a, b)] = lambda;
        }
        d[(a, a)] = lambda + 2.0 * mu;
        d[(a + 3, a + 3)] = mu;
    }
    d
}

/// Inverse and determinant of a 3×3 matrix by the adjugate. Never panics: a singular matrix
/// gives a determinant of 0 and a non-finite inverse.
#[inline(always)]
pub(crate) fn inverse_and_det(m: &Mat3) -> (Mat3, f64) {
    let c00 = m[(1, 1)] * m[(2, 2)] - m[(1, 2)] * m[(2, 1)];
    let c01 = m[(1, 2)] * m[(2, 0)] - m[(1, 0)] * m[(2, 2)];
    let c02 = m[(1, 0)] * m[(2, 1)] - m[(1, 1)] * m[(2, 0)];
    let det = m[(0, 0)] * c00 + m[(0, 1)] * c01 + m[(0, 2)] * c02;
    let r = 1.0 / det;
    let inv = Mat3::new(
        c00 * r,
        (m[(0, 2)] * m[(2, 1)] - m[(0, 1)] * m[(2, 2)]) * r,
        (m[(0, 1)] * m[(1, 2)] - m[(0, 2)] * m[(1, 1)]) * r,
        c01 * r,
        (m[(0, 0)] * m[(2, 2)] - m[(0, 2)] * m[(2, 0)]) * r,
        (m[(0, 2)] * m[(1, 0)] - m[(0, 0)] * m[(1, 2)]) * r,
        c02 * r,
        (m[(0, 1)] * m[(2, 0)] - m[(0, 0)] * m[(2, 1)]) * r,
        (m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)]) * r,
    );
    (inv, det)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lame_parameters_known_values() {
        // E = 5G/2, ν = 1/4 gives λ = μ = G (the Blatz-Ko small-strain limit).
        let (mu, lambda) = lame_from_young_poisson(2.5e6, 0.25);
        assert!((mu - 1.0e6).abs() < 1e-6 && (lambda - 1.0e6).abs() < 1e-6);
        // ν = 0: λ = 0, μ = E/2.
        let (mu, lambda) = lame_from_young_poisson(3.0, 0.0);
        assert!((mu - 1.5).abs() < 1e-15 && lambda == 0.0);
        // ν = 0.3, E = 1: μ = 1/2.6, λ = 0.3/(1.3·0.4).
        let (mu, lambda) = lame_from_young_poisson(1.0, 0.3);
        assert!((mu - 1.0 / 2.6).abs() < 1e-15 && (lambda - 0.3 / 0.52).abs() < 1e-15);
    }

    #[test]
    fn inverse_and_det_match_nalgebra() {
        let m = Mat3::new(2.0, 0.3, -0.1, 0.4, 1.5, 0.2, -0.3, 0.1, 0.9);
        let (inv, det) = inverse_and_det(&m);
        assert!((det - m.determinant()).abs() < 1e-14);
        assert!((inv * m - Mat3::identity()).amax() < 1e-14);
        let (inv, det) = inverse_and_det(&Mat3::zeros());
        assert!(det == 0.0 && !inv[(0, 0)].is_finite());
    }

    #[test]
    fn voigt_tangent_layout() {
        // δ_ik δ_jl + δ_il δ_jk puts 2 on the normal diagonal and 1 on the shear diagonal.
        let delta = |a: usize, b: usize| if a == b { 1.0 } else { 0.0 };
        let d = voigt_tangent(|i, j, k, l| delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k));
        assert_eq!(d, isotropic_tangent(1.0, 0.0));
        // (i, j, k, l) ↦ a distinct value per Voigt pair lands in the right slot.
        let code = |i: usize, j: usize| VOIGT_PAIRS.iter().position(|&p| p == (i, j)).unwrap();
        let d = voigt_tangent(|i, j, k, l| (10 * code(i, j) + code(k, l)) as f64);
        for a in 0..6 {
            for b in a..6 {
                assert_eq!(d[(a, b)], (10 * a + b) as f64);
                assert_eq!(d[(b, a)], (10 * a + b) as f64);
            }
        }
    }
}
