//! Helpers of the contact laws' unit tests: small vectors and matrices, a deterministic
//! random generator, relative comparisons and the paper-like RCC interface.

use super::history::LawPointHistory;
use super::interface::PointSolution;
use super::rcc::{BondState, RccParams};
use crate::{Mat3, Vec3};

/// The RCC history a point's solution leads to.
pub(crate) fn end(s: &PointSolution) -> BondState {
    BondState::decode(&s.history)
}

/// A local vector from its components.
pub(crate) fn v3(a: f64, b: f64, c: f64) -> Vec3 {
    Vec3::new(a, b, c)
}

/// Deterministic generator for randomised tests (splitmix64).
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }

    /// Random symmetric positive definite matrix with eigenvalues in [lo, hi].
    pub(crate) fn spd(&mut self, lo: f64, hi: f64) -> Mat3 {
        let mut q = [Vec3::zeros(); 3];
        for row in q.iter_mut() {
            for v in row.iter_mut() {
                *v = self.uniform(-1.0, 1.0);
            }
        }
        // Gram-Schmidt on the rows.
        for i in 0..3 {
            for k in 0..i {
                let d = q[i].dot(&q[k]);
                q[i] -= q[k] * d;
            }
            let n = q[i].norm();
            q[i] /= n;
        }
        let l = [lo, self.uniform(lo, hi), hi];
        Mat3::from_fn(|i, j| (0..3).map(|k| q[k][i] * l[k] * q[k][j]).sum())
    }
}

pub(crate) fn diag(a: f64, b: f64, c: f64) -> Mat3 {
    Mat3::from_diagonal(&v3(a, b, c))
}

pub(crate) fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

pub(crate) fn assert_vec_close(a: Vec3, b: Vec3, tol: f64) {
    let s = a.norm().max(b.norm()).max(f64::MIN_POSITIVE);
    assert!((a - b).norm() <= tol * s, "{a:?} vs {b:?} (tol {tol})");
}

/// Paper-like interface: w = 20 J/m², C_n = C_t = 2e9 N/m³ (x_c = 0.1 mm), b = 0.1 N·s/m.
pub(crate) fn paper_rcc() -> RccParams {
    RccParams::new(20.0, 2e9, 2e9, 0.1)
}
