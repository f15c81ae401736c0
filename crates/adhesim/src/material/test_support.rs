//! Shared checks for the material tests: deterministic random deformations and central finite
//! differences of W (for S) and of S (for D) in the Voigt convention of the module docs.

use super::{isotropic_tangent, Hyperelastic, VOIGT_PAIRS};
use crate::{Mat3, Mat6};
use nalgebra::{UnitQuaternion, Vector4, Vector6};

/// Relative FD step: h = STEP · max|C|. Central differences then carry a truncation error of
/// O(h²) ≈ 1e-12 and a round-off error of O(ε_machine / h) ≈ 1e-10, relative to the scale of
/// the differentiated quantity; observed errors are below 1e-9 (≤ 5e-10 over all materials).
pub const STEP: f64 = 1e-6;
/// Tolerance on FD comparisons, relative to the largest entry of the exact result (or the shear
/// modulus if larger). Three orders above what the step allows, far below any formula error.
pub const FD_TOL: f64 = 1e-6;
/// Number of random deformations per FD check.
pub const SAMPLES: usize = 24;

/// Small deterministic generator (SplitMix64), so the tests need no external randomness.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform sample in [a, b).
    pub fn uniform(&mut self, a: f64, b: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        a + (b - a) * u
    }

    /// Random rotation matrix (from a normalised random quaternion).
    pub fn rotation(&mut self) -> Mat3 {
        loop {
            let q = Vector4::from_fn(|_, _| self.uniform(-1.0, 1.0));
            let n = q.norm();
            if n > 0.1 && n <= 1.0 {
                return UnitQuaternion::from_quaternion(nalgebra::Quaternion::from(q))
                    .to_rotation_matrix()
                    .into_inner();
            }
        }
    }

    /// Random deformation gradient F = R U with det F = `j`: U has random principal directions
    /// and principal stretches drawn in [0.7, 1.5), then rescaled isotropically to hit `j`.
    pub fn deformation(&mut self, j: f64) -> Mat3 {
        let q = self.rotation();
        let s = [
            self.uniform(0.7, 1.5),
            self.uniform(0.7, 1.5),
            self.uniform(0.7, 1.5),
        ];
        let scale = (j / (s[0] * s[1] * s[2])).cbrt();
        let u = q * Mat3::from_diagonal(&nalgebra::Vector3::new(s[0], s[1], s[2])) * q.transpose();
        self.rotation() * u * scale
    }
}

/// `SAMPLES` right Cauchy-Green tensors C = FᵀF with J = det F spread geometrically over
/// [0.5, 2] (both ends included).
pub fn sample_c(seed: u64) -> Vec<Mat3> {
    let mut rng = Rng::new(seed);
    (0..SAMPLES)
        .map(|n| {
            let j = 0.5 * 4f64.powf(n as f64 / (SAMPLES - 1) as f64);
            let f = rng.deformation(j);
            let c = f.transpose() * f;
            assert!((c.determinant().sqrt() - j).abs() < 1e-12 * j);
            c
        })
        .collect()
}

/// Voigt vector (S11, S22, S33, S12, S23, S13) of a symmetric tensor.
pub fn voigt(s: &Mat3) -> Vector6<f64> {
    Vector6::from_fn(|a, _| s[VOIGT_PAIRS[a]])
}

/// C + 2 dE for a Green-Lagrange increment with Voigt component `a` equal to `h`
/// (engineering shear: a shear component h means dE_ij = dE_ji = h/2).
pub fn perturb(c: &Mat3, a: usize, h: f64) -> Mat3 {
    let (i, j) = VOIGT_PAIRS[a];
    let mut p = *c;
    if i == j {
        p[(i, i)] += 2.0 * h;
    } else {
        p[(i, j)] += h;
        p[(j, i)] += h;
    }
    p
}

/// Largest entry of |a − b| divided by max(max|b|, floor).
fn rel_err<const R: usize, const K: usize>(
    a: &nalgebra::SMatrix<f64, R, K>,
    b: &nalgebra::SMatrix<f64, R, K>,
    floor: f64,
) -> f64 {
    (a - b).amax() / b.amax().max(floor)
}

/// S_v against central differences of W: S_v[a] = (W(C + 2dE) − W(C − 2dE)) / 2h, and the S
/// returned with the tangent against `pk2`. Returns the largest relative FD error seen.
pub fn check_stress_fd(m: &dyn Hyperelastic, seed: u64) -> f64 {
    let mut worst: f64 = 0.0;
    for c in sample_c(seed) {
        let h = STEP * c.amax();
        let s = m.pk2(&c);
        let fd = Vector6::from_fn(|a, _| {
            (m.energy(&perturb(&c, a, h)) - m.energy(&perturb(&c, a, -h))) / (2.0 * h)
        });
        let err = rel_err(&fd, &voigt(&s), m.shear_modulus());
        assert!(err < FD_TOL, "S vs FD of W: rel. error {err:e} at C = {c}");
        assert!(
            (s - s.transpose()).amax() <= 1e-14 * s.amax(),
            "S not symmetric"
        );
        let (s2, _) = m.pk2_and_tangent(&c);
        assert!((s2 - s).amax() <= 1e-14 * s.amax().max(m.shear_modulus()));
        worst = worst.max(err);
    }
    worst
}

/// D against central differences of S: column a of D is (S_v(C + 2dE) − S_v(C − 2dE)) / 2h
/// with dE the Voigt unit increment a. Also checks major symmetry of D. Returns the largest
/// relative FD error seen.
pub fn check_tangent_fd(m: &dyn Hyperelastic, seed: u64) -> f64 {
    let mut worst: f64 = 0.0;
    for c in sample_c(seed) {
        let h = STEP * c.amax();
        let (_, d) = m.pk2_and_tangent(&c);
        let mut fd = Mat6::zeros();
        for a in 0..6 {
            let col = (voigt(&m.pk2(&perturb(&c, a, h))) - voigt(&m.pk2(&perturb(&c, a, -h))))
                / (2.0 * h);
            fd.set_column(a, &col);
        }
        let err = rel_err(&fd, &d, m.shear_modulus());
        assert!(err < FD_TOL, "D vs FD of S: rel. error {err:e} at C = {c}");
        assert!(
            (d - d.transpose()).amax() <= 1e-14 * d.amax(),
            "D not symmetric"
        );
        worst = worst.max(err);
    }
    worst
}

/// W(I) = 0 and S(I) = 0 (to round-off relative to the shear modulus).
pub fn check_reference_state(m: &dyn Hyperelastic) {
    let i = Mat3::identity();
    let g = m.shear_modulus();
    assert!(m.energy(&i).abs() <= 1e-14 * g, "W(I) = {}", m.energy(&i));
    assert!(m.pk2(&i).amax() <= 1e-14 * g, "S(I) = {}", m.pk2(&i));
    assert!(m.pk2_and_tangent(&i).0.amax() <= 1e-14 * g);
}

/// D(I) equals the isotropic linear elastic tangent with (μ, λ), and the reported small-strain
/// moduli are G = μ and K = λ + 2μ/3.
pub fn check_small_strain_limit(m: &dyn Hyperelastic, mu: f64, lambda: f64) {
    let (_, d) = m.pk2_and_tangent(&Mat3::identity());
    let expected = isotropic_tangent(mu, lambda);
    assert!(
        (d - expected).amax() <= 1e-14 * expected.amax(),
        "D(I) = {d} expected {expected}"
    );
    assert!((m.shear_modulus() - mu).abs() <= 1e-14 * mu);
    let k = lambda + 2.0 * mu / 3.0;
    assert!((m.bulk_modulus() - k).abs() <= 1e-14 * k);
}

/// Isotropy: W(QᵀCQ) = W(C) and S(QᵀCQ) = Qᵀ S(C) Q for random rotations Q, to 1e-12 relative.
pub fn check_objectivity(m: &dyn Hyperelastic, seed: u64) {
    let mut rng = Rng::new(seed ^ 0x5EED);
    let g = m.shear_modulus();
    for c in sample_c(seed) {
        let q = rng.rotation();
        let cr = q.transpose() * c * q;
        let (w, wr) = (m.energy(&c), m.energy(&cr));
        assert!((w - wr).abs() <= 1e-12 * w.abs().max(g), "W {w} vs {wr}");
        let (s, sr) = (m.pk2(&c), m.pk2(&cr));
        let expected = q.transpose() * s * q;
        assert!((sr - expected).amax() <= 1e-12 * s.amax().max(g));
    }
}

/// No panic on det C ≤ 0: energy is +∞ or finite (never NaN), stresses may be non-finite.
pub fn check_degenerate_inputs(m: &dyn Hyperelastic) {
    for c in [
        Mat3::zeros(),
        -Mat3::identity(),
        Mat3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, -0.5)),
    ] {
        let w = m.energy(&c);
        assert!(!w.is_nan(), "W = NaN for det C ≤ 0");
        let _ = m.pk2(&c);
        let _ = m.pk2_and_tangent(&c);
    }
}

/// The checks every hyperelastic material passes, written as tests into the calling module
/// (which imports this module's functions): stress against finite differences of the energy
/// and tangent against finite differences of the stress (for `material` and, where given, a
/// `compressible` variant whose isochoric part is not drowned by the bulk modulus), a
/// stress-free reference state, the small-strain limit with shear modulus μ and Lamé λ
/// computed from the material bound to the given name, objectivity, and degenerate inputs
/// that do not panic. `seed` (and the next four) pick the random deformations.
macro_rules! material_checks {
    (
        material: $material:expr,
        $(compressible: $variant:expr,)?
        small_strain: |$m:ident| ($mu:expr, $lambda:expr),
        seed: $seed:expr $(,)?
    ) => {
        #[test]
        fn stress_matches_fd_of_energy() {
            check_stress_fd(&$material, $seed);
            $(check_stress_fd(&$variant, $seed + 1);)?
        }

        #[test]
        fn tangent_matches_fd_of_stress() {
            check_tangent_fd(&$material, $seed + 2);
            $(check_tangent_fd(&$variant, $seed + 3);)?
        }

        #[test]
        fn reference_state_is_stress_free() {
            check_reference_state(&$material);
        }

        #[test]
        fn small_strain_limit_is_isotropic_elasticity() {
            let $m = $material;
            check_small_strain_limit(&$m, $mu, $lambda);
        }

        #[test]
        fn isotropic() {
            check_objectivity(&$material, $seed + 4);
        }

        #[test]
        fn degenerate_inputs_do_not_panic() {
            check_degenerate_inputs(&$material);
        }
    };
}
pub(crate) use material_checks;
