//! The element tangent is the derivative of the element internal force: compared with
//! central finite differences on a distorted hex8, a tet4 and (with the linear volume
//! change) a curved hex20, at large random displacements, for every material.

use adhesim::dilatation::{linear_dilatation_response, LinearDilatation};
use adhesim::element::{
    element_response, hex20_geometry, hex8_geometry, tet4_geometry, ElementResponse, GaussPoint,
    HEX20,
};
use adhesim::fbar::fbar_element_response;
use adhesim::material::{
    BlatzKo, Hyperelastic, LinearElastic, MooneyRivlin, NeoHookean, Ogden, SaintVenantKirchhoff,
    UncoupledNeoHookean,
};

mod common;
use common::Rng;

fn materials() -> Vec<Box<dyn Hyperelastic>> {
    vec![
        Box::new(BlatzKo { g: 1.0e6 }),
        Box::new(NeoHookean::from_young_poisson(2.0e6, 0.3)),
        Box::new(SaintVenantKirchhoff::from_young_poisson(2.0e6, 0.3)),
        Box::new(LinearElastic::from_young_poisson(2.0e6, 0.3)),
        Box::new(UncoupledNeoHookean::from_young_poisson(2.0e6, 0.45)),
        Box::new(MooneyRivlin {
            c10: 0.3e6,
            c01: 0.1e6,
            kappa: 2.0e7,
        }),
        Box::new(Ogden {
            mu: vec![0.4e6, 0.01e6],
            alpha: vec![1.3, -2.0],
            kappa: 2.0e7,
        }),
    ]
}

/// Largest |K_fd − K| relative to max |K|, and the energy-force consistency error.
fn check<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    mat: &dyn Hyperelastic,
) -> (f64, f64) {
    check_kernel(|u, t| element_response(gps, u, mat, t), u, mat)
}

/// As [`check`] for any element kernel `response(u, with_tangent)`.
fn check_kernel<const N: usize>(
    response: impl Fn(&[[f64; 3]; N], bool) -> ElementResponse<N>,
    u: &[[f64; 3]; N],
    mat: &dyn Hyperelastic,
) -> (f64, f64) {
    let r = response(u, true);
    let k = r.tangent.unwrap();
    let kmax = (0..N)
        .flat_map(|a| (0..N).map(move |b| (a, b)))
        .map(|(a, b)| k[a][b].abs().max())
        .fold(0.0, f64::max);
    let h = 1e-7; // displacement step [m] for elements of size ~1e-2 m: relative 1e-5
    let mut err_k: f64 = 0.0;
    let mut err_f: f64 = 0.0;
    let fmax = r
        .force
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-30);
    for b in 0..N {
        for kk in 0..3 {
            let mut up = *u;
            let mut um = *u;
            up[b][kk] += h;
            um[b][kk] -= h;
            let rp = response(&up, false);
            let rm = response(&um, false);
            for a in 0..N {
                for i in 0..3 {
                    let fd = (rp.force[a][i] - rm.force[a][i]) / (2.0 * h);
                    err_k = err_k.max((fd - k[a][b][(i, kk)]).abs() / kmax);
                }
            }
            if !mat.small_strain() {
                // The force is the gradient of the energy.
                let fd = (rp.energy - rm.energy) / (2.0 * h);
                err_f = err_f.max((fd - r.force[b][kk]).abs() / fmax);
            }
        }
    }
    (err_k, err_f)
}

#[test]
fn hex8_tangent_matches_finite_differences_of_the_internal_force() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    let s = 0.01; // element size [m]
    for trial in 0..5 {
        // A distorted reference hex: unit cube nodes moved by up to 15 %.
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
            let c = adhesim::element::HEX_NODE_XI[a];
            std::array::from_fn(|k| s * (0.5 * (c[k] + 1.0) + 0.15 * rng.next()))
        });
        let gps = hex8_geometry(&x).expect("valid distorted hex");
        // Large displacements: up to 20 % of the element size.
        let u: [[f64; 3]; 8] =
            std::array::from_fn(|_| std::array::from_fn(|_| 0.2 * s * rng.next()));
        for mat in materials() {
            let (ek, ef) = check(&gps, &u, mat.as_ref());
            // Central differences with h = 1e-5 relative: truncation ~1e-10, round-off
            // ~1e-16/1e-5; 1e-6 leaves a wide margin yet catches any wrong term.
            assert!(ek < 1e-6, "trial {trial} {mat:?}: tangent error {ek:e}");
            assert!(
                ef < 1e-6,
                "trial {trial} {mat:?}: force vs energy error {ef:e}"
            );
        }
    }
}

#[test]
fn fbar_hex8_tangent_matches_finite_differences_of_the_internal_force() {
    // The F-bar tangent couples all 8 nodes through the element's volume ratio θ: the full
    // 24×24 matrix is compared, and the force against FD of the element energy Σ w W(F̄).
    let mut rng = Rng(0x51ed_2701_b00c_fa1e);
    let s = 0.01;
    for trial in 0..5 {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
            let c = adhesim::element::HEX_NODE_XI[a];
            std::array::from_fn(|k| s * (0.5 * (c[k] + 1.0) + 0.15 * rng.next()))
        });
        let gps = hex8_geometry(&x).expect("valid distorted hex");
        let u: [[f64; 3]; 8] =
            std::array::from_fn(|_| std::array::from_fn(|_| 0.2 * s * rng.next()));
        for mat in materials() {
            let m = mat.as_ref();
            let (ek, ef) = check_kernel(|u, t| fbar_element_response(&gps, u, m, t), &u, m);
            // Same tolerance and reasoning as for the standard hex8.
            assert!(
                ek < 1e-6,
                "trial {trial} {mat:?}: F-bar tangent error {ek:e}"
            );
            assert!(
                ef < 1e-6,
                "trial {trial} {mat:?}: F-bar force vs energy {ef:e}"
            );
        }
    }
}

#[test]
fn linear_dilatation_hex20_tangent_matches_finite_differences_of_the_internal_force() {
    // The volume change θ_g of each Gauss point is the L² projection of J onto the linear
    // functions of the element: every point's θ depends on every node. Full 60×60 matrix
    // and force against FD of the energy, on a curved, skewed hex20.
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let s = 0.01;
    for trial in 0..2 {
        let x: [[f64; 3]; 20] = std::array::from_fn(|a| {
            let c = HEX20.natural_nodes[a];
            let skewed = [c[0] + 0.2 * c[1], c[1] + 0.1 * c[2], c[2] + 0.15 * c[0]];
            std::array::from_fn(|k| 0.5 * s * skewed[k] + 0.05 * s * rng.next())
        });
        let gps = hex20_geometry(&x).expect("valid curved hex20");
        let lin = LinearDilatation::new(&gps, &x).expect("the Gauss points span the element");
        let u: [[f64; 3]; 20] =
            std::array::from_fn(|_| std::array::from_fn(|_| 0.1 * s * rng.next()));
        for mat in materials() {
            let m = mat.as_ref();
            let kernel =
                |u: &[[f64; 3]; 20], t| linear_dilatation_response(&gps, &lin, u, m, t, None);
            let (ek, ef) = check_kernel(kernel, &u, m);
            eprintln!(
                "hex20 linear dilatation, trial {trial}, {mat:?}: tangent {ek:.1e}, force {ef:.1e}"
            );
            // Same tolerance and reasoning as for the standard hex8.
            assert!(ek < 1e-6, "trial {trial} {mat:?}: tangent error {ek:e}");
            assert!(ef < 1e-6, "trial {trial} {mat:?}: force vs energy {ef:e}");
        }
    }
}

#[test]
fn fbar_of_a_homogeneous_deformation_is_the_standard_element() {
    // Under a homogeneous F every point has J = θ, so F̄ = F: forces must coincide.
    let s = 0.01;
    let x: [[f64; 3]; 8] =
        std::array::from_fn(|a| adhesim::element::HEX_NODE_XI[a].map(|c| 0.5 * s * (c + 1.0)));
    let gps = hex8_geometry(&x).unwrap();
    let h = [[0.1, 0.05, -0.02], [0.03, -0.08, 0.04], [0.0, 0.02, 0.12]];
    let u: [[f64; 3]; 8] =
        std::array::from_fn(|a| std::array::from_fn(|i| (0..3).map(|k| h[i][k] * x[a][k]).sum()));
    let mat = UncoupledNeoHookean::from_young_poisson(1.0e6, 0.4999);
    let r1 = element_response(&gps, &u, &mat, false);
    let r2 = fbar_element_response(&gps, &u, &mat, false);
    let fmax = r1
        .force
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for a in 0..8 {
        for i in 0..3 {
            assert!((r1.force[a][i] - r2.force[a][i]).abs() < 1e-10 * fmax);
        }
    }
    assert!((r1.energy - r2.energy).abs() < 1e-10 * r1.energy);
}

#[test]
fn tet4_tangent_matches_finite_differences_of_the_internal_force() {
    let mut rng = Rng(12345);
    let s = 0.01;
    let x = [
        [0.0, 0.0, 0.0],
        [s, 0.1 * s, 0.0],
        [0.2 * s, s, 0.1 * s],
        [0.1 * s, 0.2 * s, s],
    ];
    let gps = tet4_geometry(&x).unwrap();
    let u: [[f64; 3]; 4] = std::array::from_fn(|_| std::array::from_fn(|_| 0.2 * s * rng.next()));
    for mat in materials() {
        let (ek, ef) = check(&gps, &u, mat.as_ref());
        assert!(ek < 1e-6 && ef < 1e-6, "{mat:?}: {ek:e} {ef:e}");
    }
}

#[test]
fn inverted_reference_elements_are_rejected() {
    let mut x: [[f64; 3]; 8] = std::array::from_fn(|a| adhesim::element::HEX_NODE_XI[a]);
    x.swap(0, 1);
    assert!(hex8_geometry(&x).is_err());
}
