//! Orthotropic friction through the whole solver, on the shipped scenario
//! scenarios/interface/orthotropic-drag.toml: a pad pressed on a rigid flat with μ₁ = 0.6
//! along x and μ₂ = 0.2 along z, dragged in the direction θ.
//!
//! Independent answer: once every node slides in the drag direction d = (cos θ, sin θ), each
//! node's friction force is where the elliptic cone's normal is d (maximal dissipation), so
//! the resultant is F_t = −N (μ₁² cos θ, μ₂² sin θ)/√(μ₁² cos² θ + μ₂² sin² θ), with N the
//! total normal force, whatever the pressure distribution.

use adhesim::contact::anisotropic::{sliding_friction, Orthotropy};
use adhesim::contact::history::{LawPointHistory, PointHistory};
use adhesim::contact::law::{natural_map_defect, InterfaceLaw};
use adhesim::contact::rcc::{adhesive_response, BondState, RccParams};
use adhesim::contact::solver::augmented_lagrangian::point::augmented_point;
use adhesim::contact::solver::gauss_seidel::point::{solve_point, PointProblem};
use adhesim::time::Stepper;
use adhesim::{mat3_from_rows, Mat3, Vec2, Vec3};
use std::path::Path;
use std::sync::Arc;

const MU1: f64 = 0.6;
const MU2: f64 = 0.2;

/// (N, F_x, F_z) of the pair at the end of the drag, and whether every node slides then.
fn drag(angle_deg: f64, edit: impl Fn(String) -> String) -> (f64, f64, f64, bool) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/interface/orthotropic-drag.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = edit(text.replace("drag_angle = 45.0", &format!("drag_angle = {angle_deg:?}")));
    let problem = adhesim_io::scenario::parse(&text, &path)
        .unwrap_or_else(|e| panic!("{e}"))
        .problem;
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    while !s.finished() {
        s.step().unwrap();
    }
    let nodes = &s.contact[0];
    let total = |k: usize| nodes.iter().map(|c| c.force[k]).sum::<f64>();
    let all_slide = nodes.iter().all(|c| c.state == 3);
    (total(1), total(0), total(2), all_slide)
}

#[test]
fn dragged_pad_follows_the_elliptic_cone() {
    for angle in [0.0f64, 30.0, 45.0, 90.0] {
        let (n, fx, fz, all_slide) = drag(angle, |t| t);
        assert!(all_slide, "{angle}°: not every node slides");
        let th = angle.to_radians();
        let m = (MU1 * th.cos()).hypot(MU2 * th.sin());
        let expect = [-MU1 * MU1 * th.cos() / m, -MU2 * MU2 * th.sin() / m];
        eprintln!(
            "θ = {angle}°: F_t/N = ({:.9}, {:.9}), closed form ({:.9}, {:.9})",
            fx / n,
            fz / n,
            expect[0],
            expect[1]
        );
        // Each committed step meets the contact law to 1e-8 of the force scale and the
        // equilibrium to 1e-8 (time.newton_tol): 1e-6 leaves room for both.
        assert!(
            (fx / n - expect[0]).abs() < 1e-6,
            "{angle}°: F_x/N {}",
            fx / n
        );
        assert!(
            (fz / n - expect[1]).abs() < 1e-6,
            "{angle}°: F_z/N {}",
            fz / n
        );
    }
}

#[test]
fn equal_coefficients_on_material_axes_reproduce_the_isotropic_law() {
    // μ₂ = μ₁: the same law, but the local frames follow the material axis instead of the
    // default tangents, so the results agree to round-off only.
    let ortho = drag(30.0, |t| t.replace("friction_2 = 0.2", "friction_2 = 0.6"));
    let iso = drag(30.0, |t| {
        let line = "orthotropy = { axis = [1.0, 0.0, 0.0], friction_2 = 0.2 }";
        assert!(t.contains(line));
        t.replace(line, "")
    });
    for (a, b, what) in [
        (ortho.0, iso.0, "N"),
        (ortho.1, iso.1, "F_x"),
        (ortho.2, iso.2, "F_z"),
    ] {
        assert!((a - b).abs() < 1e-9 * iso.0.abs(), "{what}: {a} vs {b}");
    }
    // And the isotropic friction force is along the slip: |F_t| = μ N.
    let ft = iso.1.hypot(iso.2);
    assert!((ft / iso.0 - MU1).abs() < 1e-6, "{}", ft / iso.0);
}

// The law at one point: the Gauss-Seidel point solve and the Newton solve's law.

fn law(mu1: f64, mu2: f64) -> InterfaceLaw {
    InterfaceLaw::rcc(
        mu1,
        None,
        Some(Orthotropy {
            axis: [1.0, 0.0, 0.0],
            mu2,
        }),
    )
}

/// A point pushed along the plane with a stiff compliance slides; its friction force is
/// on the ellipse, opposite to the slip's dual direction, as the closed form says, for
/// slips along each axis and at 45°.
#[test]
fn sliding_point_lands_on_the_ellipse_with_the_maximal_dissipation_direction() {
    let (mu1, mu2) = (0.6, 0.2);
    let l = law(mu1, mu2);
    let c = 1e-6; // compliance [m/N]
    for angle in [0.0f64, 45.0, 90.0, 30.0] {
        let a = angle.to_radians();
        // Free displacement: pressed 1 mm into the plane and pushed 10 mm along (cos, sin).
        let x_free = Vec3::new(1e-2 * a.cos(), 1e-2 * a.sin(), -1e-3);
        let p = PointProblem {
            w_aa: Mat3::from_diagonal_element(c),
            x_free,
            law: &l,
            history0: PointHistory::default(),
            dt: 1e-3,
            area: 1e-6,
            rho: 1.0 / c,
        };
        let sol = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(sol.converged, "{angle}°");
        let rn = sol.r_dry[2];
        assert!((rn - 1e-3 / c).abs() < 1e-9 * rn, "{angle}°: r_n {rn}");
        // On the ellipse.
        let e = (sol.r_dry[0] / mu1).hypot(sol.r_dry[1] / mu2) / rn;
        assert!((e - 1.0).abs() < 1e-10, "{angle}°: {e}");
        // The slip direction and the force by maximal dissipation.
        let slip_len = sol.x[0].hypot(sol.x[1]);
        let d = [sol.x[0] / slip_len, sol.x[1] / slip_len];
        let expect = sliding_friction(mu1, mu2, rn, d);
        for k in 0..2 {
            assert!(
                (sol.r_dry[k] - expect[k]).abs() < 1e-9 * rn,
                "{angle}°: r_t {:?} vs {expect:?}",
                sol.r_dry
            );
        }
        // The Newton solve's law agrees at the same x with λ = r̄ (a fixed point).
        let ap = augmented_point(
            &l,
            PointHistory::default(),
            1e-3,
            1e-6,
            1.0 / c,
            sol.r_dry,
            sol.x,
        );
        for k in 0..3 {
            assert!(
                (ap.solution.r_dry[k] - sol.r_dry[k]).abs() < 1e-9 * rn,
                "{angle}°"
            );
        }
        let defect = natural_map_defect(&l, 1.0 / c, sol.r_dry, sol.x);
        assert!(
            defect.iter().all(|v| v.abs() < 1e-9 * rn),
            "{angle}°: {defect:?}"
        );
    }
}

/// μ₁ = μ₂ and C_t1 = C_t2 on aligned axes give the isotropic law's solution.
#[test]
fn equal_coefficients_reproduce_the_isotropic_law() {
    let mut rcc = RccParams::new(20.0, 2e9, 2e9, 0.1);
    rcc.ct2 = rcc.ct;
    let iso = InterfaceLaw::rcc(0.4, Some(rcc), None);
    let ortho = InterfaceLaw {
        anisotropy: Some(Orthotropy {
            axis: [1.0, 0.0, 0.0],
            mu2: 0.4,
        }),
        ..iso.clone()
    };
    let w = mat3_from_rows([[2e-6, 3e-7, 1e-7], [3e-7, 1e-6, -2e-7], [1e-7, -2e-7, 3e-6]]);
    for x_free in [
        Vec3::new(1e-4, -3e-5, -2e-5),
        Vec3::new(2e-6, 1e-6, 5e-6),
        Vec3::new(1e-3, 1e-3, -1e-6),
    ] {
        let bond0 = BondState {
            beta: 0.7,
            ut: Vec2::new(1e-6, -2e-6),
            damage: 0.0,
        };
        let p = |law| PointProblem {
            w_aa: w,
            x_free,
            law,
            history0: bond0.encode(),
            dt: 1e-3,
            area: 1e-6,
            rho: 0.0,
        };
        let a = solve_point(&p(&iso), Vec3::zeros(), 1e-12, 200);
        let b = solve_point(&p(&ortho), Vec3::zeros(), 1e-12, 200);
        assert_eq!(a, b);
    }
}

/// Orthotropic tangential adhesion: a bonded point stretched along t₁ or t₂ carries
/// −C_ti u_i β² A, the law's energy gradient.
#[test]
fn orthotropic_adhesion_stiffness_per_axis() {
    let mut rcc = RccParams::new(20.0, 2e9, 4e9, 0.0);
    rcc.ct2 = 1e9;
    let area = 1e-6;
    let bond = BondState {
        beta: 1.0,
        ut: Vec2::zeros(),
        damage: 0.0,
    };
    let u = 1e-7; // well inside the bond's strength: β stays 1
    for (k, ct) in [(0usize, 4e9), (1, 1e9)] {
        let mut x = Vec3::zeros();
        x[k] = u;
        let r = adhesive_response(&rcc, bond, 1e-3, area, x);
        assert_eq!(BondState::from(&r.history).beta, 1.0);
        let expect = -ct * u * area;
        assert!(
            (r.force[k] - expect).abs() < 1e-12 * expect.abs(),
            "axis {k}"
        );
        assert_eq!(r.force[1 - k], 0.0);
        assert!((r.secant_stiffness[(k, k)] - ct * area).abs() < 1e-6);
        // −∂φ/∂x_k by central differences.
        let h = 1e-10;
        let (mut xp, mut xm) = (x, x);
        xp[k] += h;
        xm[k] -= h;
        let fd = -(adhesive_response(&rcc, bond, 1e-3, area, xp).energy
            - adhesive_response(&rcc, bond, 1e-3, area, xm).energy)
            / (2.0 * h);
        assert!(
            (fd - r.force[k]).abs() < 1e-6 * r.force[k].abs(),
            "axis {k}: {fd}"
        );
    }
}
