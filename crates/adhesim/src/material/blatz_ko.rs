//! Blatz-Ko material for foam-like rubbers.

use super::{inverse_and_det, voigt_tangent, Hyperelastic};
use crate::{Mat3, Mat6};

/// Blatz-Ko hyperelastic material (the special case f = 0, ν = ¼ of the general model):
///
/// W = G/2 (I₂/I₃ + 2√I₃ − 5),  S = G (J C⁻¹ − C⁻²),  J = √det C.
///
/// Tangent, with A = C⁻¹ and B = C⁻²:
/// ℂ_ijkl = G [J A_ij A_kl − J (A_ik A_jl + A_il A_jk) + A_ik B_jl + A_il B_jk + B_ik A_jl + B_il A_jk].
///
/// Small-strain limit: λ = μ = G, ν = ¼, E = 5G/2, K = 5G/3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlatzKo {
    /// Small-strain shear modulus G [Pa].
    pub g: f64,
}

impl BlatzKo {
    /// Blatz-Ko material with shear modulus `g` [Pa].
    pub fn new(g: f64) -> Self {
        BlatzKo { g }
    }
}

impl Hyperelastic for BlatzKo {
    /// W [J/m³]; +∞ when det C ≤ 0 (or is NaN).
    fn energy(&self, c: &Mat3) -> f64 {
        let i3 = c.determinant();
        if i3.is_nan() || i3 <= 0.0 {
            return f64::INFINITY;
        }
        let i1 = c.trace();
        let i2 = 0.5 * (i1 * i1 - (c * c).trace());
        0.5 * self.g * (i2 / i3 + 2.0 * i3.sqrt() - 5.0)
    }

    fn pk2(&self, c: &Mat3) -> Mat3 {
        let (a, det) = inverse_and_det(c);
        let jac = det.sqrt();
        (a * jac - a * a) * self.g
    }

    fn pk2_and_tangent(&self, c: &Mat3) -> (Mat3, Mat6) {
        let (a, det) = inverse_and_det(c);
        let jac = det.sqrt();
        let b = a * a;
        let s = (a * jac - b) * self.g;
        // ℂ = G [J A_ij A_kl + A_ik M_jl + M_ik A_jl + A_il M_jk + M_il A_jk], M = C⁻² − (J/2) C⁻¹.
        let p = a * (self.g * jac);
        let m = (b - a * (0.5 * jac)) * self.g;
        let d = voigt_tangent(|i, j, k, l| {
            p[(i, j)] * a[(k, l)]
                + a[(i, k)] * m[(j, l)]
                + m[(i, k)] * a[(j, l)]
                + a[(i, l)] * m[(j, k)]
                + m[(i, l)] * a[(j, k)]
        });
        (s, d)
    }

    fn shear_modulus(&self) -> f64 {
        self.g
    }

    fn bulk_modulus(&self) -> f64 {
        5.0 * self.g / 3.0
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    const G: f64 = 1.3e6;

    material_checks! {
        material: BlatzKo::new(G),
        small_strain: |_m| (G, G),
        seed: 11,
    }

    #[test]
    fn energy_is_infinite_where_j_is_not_positive() {
        let m = BlatzKo::new(G);
        assert_eq!(m.energy(&Mat3::zeros()), f64::INFINITY);
        assert_eq!(m.energy(&-Mat3::identity()), f64::INFINITY);
    }

    /// Uniaxial tension: C = diag(λ², λ^(−1/2), λ^(−1/2)) leaves the lateral faces traction
    /// free, S22 = S33 = 0, and P11 = λ S11 = G (λ^(−1/2) − λ^(−3)).
    #[test]
    fn uniaxial_tension_closed_form() {
        let m = BlatzKo::new(G);
        for n in 0..=48 {
            let stretch = 0.6 + 2.4 * n as f64 / 48.0;
            let lat = stretch.powf(-0.5);
            let c = Mat3::from_diagonal(&crate::Vec3::new(stretch * stretch, lat, lat));
            let s = m.pk2(&c);
            let scale = G * stretch.max(1.0 / stretch).powi(3);
            assert!(s[(1, 1)].abs() <= 1e-12 * scale, "S22 = {}", s[(1, 1)]);
            assert!(s[(2, 2)].abs() <= 1e-12 * scale, "S33 = {}", s[(2, 2)]);
            let p11 = G * (stretch.powf(-0.5) - stretch.powi(-3));
            assert!((stretch * s[(0, 0)] - p11).abs() <= 1e-12 * scale);
            assert!(s[(0, 1)] == 0.0 && s[(1, 2)] == 0.0 && s[(0, 2)] == 0.0);
        }
    }

    /// Cost of one `pk2` and one `pk2_and_tangent` call; run with
    /// `cargo test --release -- --ignored --nocapture bench_`.
    #[test]
    #[ignore]
    fn bench_pk2_and_tangent() {
        let m = BlatzKo::new(G);
        let cs = sample_c(1);
        let n = 2_000_000;
        let time = |f: &dyn Fn(&Mat3) -> f64| {
            let mut acc = 0.0;
            let t = std::time::Instant::now();
            for k in 0..n {
                acc += f(std::hint::black_box(&cs[k % cs.len()]));
            }
            std::hint::black_box(acc);
            t.elapsed().as_nanos() as f64 / n as f64
        };
        let ns_s = time(&|c| m.pk2(c)[(0, 0)]);
        let ns_d = time(&|c| {
            let (s, d) = m.pk2_and_tangent(c);
            s[(0, 0)] + d[(3, 5)]
        });
        println!("BlatzKo: pk2 {ns_s:.1} ns/call, pk2_and_tangent {ns_d:.1} ns/call");
    }
}
