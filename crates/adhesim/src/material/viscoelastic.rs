//! Finite-strain viscoelasticity: a Prony series on the isochoric stress (Simo 1987, *Comput.
//! Methods Appl. Mech. Engrg.* 60:153; Holzapfel 2000, *Nonlinear Solid Mechanics* §6.10).

use super::Hyperelastic;
use crate::{Mat3, Mat6};
use std::sync::Arc;

/// One Prony term: relative modulus g [-] and relaxation time τ [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PronyTerm {
    /// Relative modulus gᵢ (fraction of the instantaneous isochoric stress that relaxes).
    pub g: f64,
    /// Relaxation time τᵢ [s].
    pub tau: f64,
}

/// An uncoupled hyperelastic material (its parameters are the instantaneous response) whose
/// isochoric stress relaxes by a Prony series, as in Abaqus' and FEBio's Prony input:
///
/// S = S_vol + (1 − Σ gᵢ) S_iso + Σ Qᵢ,  Q̇ᵢ + Qᵢ/τᵢ = gᵢ Ṡ_iso,  Qᵢ(0) = 0,
///
/// so that a sudden deformation meets the full elastic response and the shear modulus relaxes
/// as μ(t) = μ₀ [1 − Σ gᵢ (1 − e^(−t/τᵢ))] to μ₀ (1 − Σ gᵢ); the bulk response is elastic.
///
/// Time integration over a step Δt (second order, exact for a stress history linear in time
/// within the step), with ξᵢ = e^(−Δt/(2τᵢ)):
///
/// Qᵢⁿ⁺¹ = ξᵢ² Qᵢⁿ + ξᵢ gᵢ (S_isoⁿ⁺¹ − S_isoⁿ),
///
/// and the consistent tangent D = D_el − Σ gᵢ (1 − ξᵢ) D_iso. The internal variables, per
/// Gauss point, are Qᵢⁿ and S_isoⁿ of the last converged step (6 values each, Voigt order).
#[derive(Debug, Clone)]
pub struct Viscoelastic {
    /// The instantaneous elastic material (must have a volumetric/isochoric split).
    pub elastic: Arc<dyn Hyperelastic>,
    /// The Prony terms.
    pub terms: Vec<PronyTerm>,
}

/// A symmetric tensor's components in Voigt order (11, 22, 33, 12, 23, 13).
pub fn to_voigt(s: &Mat3) -> [f64; 6] {
    [
        s[(0, 0)],
        s[(1, 1)],
        s[(2, 2)],
        s[(0, 1)],
        s[(1, 2)],
        s[(0, 2)],
    ]
}

fn from_voigt(v: &[f64]) -> Mat3 {
    Mat3::new(v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2])
}

impl Viscoelastic {
    /// Number of history values per Gauss point: 6 per term and 6 for S_iso.
    pub fn history_len(&self) -> usize {
        6 * (self.terms.len() + 1)
    }

    /// The isochoric stress and tangent of the elastic part at C.
    fn iso(&self, c: &Mat3) -> (Mat3, Mat6) {
        self.elastic
            .isochoric_pk2_and_tangent(c)
            .expect("a viscoelastic material is built on an uncoupled one")
    }

    /// Adds the viscous part to the elastic stress `s` (and tangent `d`) at C, for a step of
    /// Δt = `dt` [s] from the committed history `h` (length [`Self::history_len`]).
    pub fn add_viscous(&self, c: &Mat3, h: &[f64], dt: f64, s: &mut Mat3, d: Option<&mut Mat6>) {
        let (s_iso, d_iso) = self.iso(c);
        let m = self.terms.len();
        let s_iso_n = from_voigt(&h[6 * m..6 * m + 6]);
        let mut tangent_factor = 0.0;
        for (i, term) in self.terms.iter().enumerate() {
            let xi = (-dt / (2.0 * term.tau)).exp();
            let q_n = from_voigt(&h[6 * i..6 * i + 6]);
            // (1 − g) S_iso + Q = S_iso − g S_iso + ξ² Qⁿ + ξ g (S_iso − S_isoⁿ).
            *s += q_n * (xi * xi) - s_iso_n * (xi * term.g) + s_iso * (term.g * (xi - 1.0));
            tangent_factor += term.g * (xi - 1.0);
        }
        if let Some(d) = d {
            *d += d_iso * tangent_factor;
        }
    }

    /// Advances the history `h` to the end of a converged step of Δt = `dt` [s] at C.
    pub fn commit(&self, c: &Mat3, h: &mut [f64], dt: f64) {
        let (s_iso, _) = self.iso(c);
        let m = self.terms.len();
        let s_iso_n = from_voigt(&h[6 * m..6 * m + 6]);
        for (i, term) in self.terms.iter().enumerate() {
            let xi = (-dt / (2.0 * term.tau)).exp();
            let q =
                from_voigt(&h[6 * i..6 * i + 6]) * (xi * xi) + (s_iso - s_iso_n) * (xi * term.g);
            h[6 * i..6 * i + 6].copy_from_slice(&to_voigt(&q));
        }
        h[6 * m..6 * m + 6].copy_from_slice(&to_voigt(&s_iso));
    }
}

/// Without history (e.g. for wave speeds and the initial tangent) the material answers with
/// its instantaneous elastic response.
impl Hyperelastic for Viscoelastic {
    fn energy(&self, c: &Mat3) -> f64 {
        self.elastic.energy(c)
    }
    fn pk2(&self, c: &Mat3) -> Mat3 {
        self.elastic.pk2(c)
    }
    fn pk2_and_tangent(&self, c: &Mat3) -> (Mat3, Mat6) {
        self.elastic.pk2_and_tangent(c)
    }
    fn shear_modulus(&self) -> f64 {
        self.elastic.shear_modulus()
    }
    fn bulk_modulus(&self) -> f64 {
        self.elastic.bulk_modulus()
    }
    fn isochoric_pk2_and_tangent(&self, c: &Mat3) -> Option<(Mat3, Mat6)> {
        self.elastic.isochoric_pk2_and_tangent(c)
    }
    fn viscoelastic(&self) -> Option<&Viscoelastic> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::UncoupledNeoHookean;
    use super::*;

    fn material() -> Viscoelastic {
        Viscoelastic {
            elastic: Arc::new(UncoupledNeoHookean::from_young_poisson(1.0e6, 0.45)),
            terms: vec![
                PronyTerm { g: 0.3, tau: 0.1 },
                PronyTerm { g: 0.2, tau: 2.0 },
            ],
        }
    }

    #[test]
    fn viscous_tangent_matches_fd_of_the_viscous_stress() {
        // The stress of one step from a non-trivial history, as a function of C, against its
        // tangent (FD in the Voigt convention of the material checks).
        let m = material();
        let dt = 0.05;
        for (k, c0) in sample_c(61).into_iter().enumerate().take(8) {
            let mut h = vec![0.0; m.history_len()];
            m.commit(&c0, &mut h, dt);
            let c = sample_c(62)[k];
            let stress = |c: &Mat3| {
                let mut s = m.elastic.pk2(c);
                m.add_viscous(c, &h, dt, &mut s, None);
                s
            };
            let (mut s, mut d) = m.elastic.pk2_and_tangent(&c);
            m.add_viscous(&c, &h, dt, &mut s, Some(&mut d));
            assert!((s - stress(&c)).amax() < 1e-12 * s.amax());
            let step = STEP * c.amax();
            for a in 0..6 {
                let col = (voigt(&stress(&perturb(&c, a, step)))
                    - voigt(&stress(&perturb(&c, a, -step))))
                    / (2.0 * step);
                let err = (col - d.column(a)).amax() / d.amax();
                assert!(err < FD_TOL, "column {a}: {err:e}");
            }
        }
    }

    #[test]
    fn history_decays_exponentially_under_a_held_deformation() {
        // After a jump to C and holding it, Qᵢ = gᵢ ξᵢ S_iso e^(−(t − Δt)/τᵢ): with S_iso fixed,
        // each committed step multiplies Qᵢ by e^(−Δt/τᵢ) exactly.
        let m = material();
        let c = sample_c(63)[5];
        let dt = 0.01;
        let mut h = vec![0.0; m.history_len()];
        m.commit(&c, &mut h, dt);
        let (s_iso, _) = m.iso(&c);
        for n in 1..50 {
            m.commit(&c, &mut h, dt);
            for (i, t) in m.terms.iter().enumerate() {
                let q = from_voigt(&h[6 * i..6 * i + 6]);
                let expected =
                    s_iso * (t.g * (-dt / (2.0 * t.tau)).exp() * (-(n as f64) * dt / t.tau).exp());
                assert!((q - expected).amax() <= 1e-12 * s_iso.amax());
            }
        }
    }
}
