//! Finite-strain viscoelasticity (Prony series on the isochoric stress) on one hex8 under
//! uniaxial stress: relaxation against the closed form of linear viscoelasticity (small
//! strain), against an independently integrated ODE (large strain), creep converging in Δt,
//! and the internal variables carried through a snapshot.

use adhesim::fbar::Formulation;
use adhesim::material::{Hyperelastic, PronyTerm, UncoupledNeoHookean, Viscoelastic};
use adhesim::mesh::{generate, Mesh};
use adhesim::problem::{Dirichlet, NodalLoad, Problem, Table};
use adhesim::time::Stepper;
use std::sync::Arc;

mod common;
use common::*;

/// Instantaneous shear modulus μ₀ [Pa].
const MU0: f64 = 1.0e6;

fn terms() -> Vec<PronyTerm> {
    vec![
        PronyTerm { g: 0.3, tau: 0.1 },
        PronyTerm { g: 0.2, tau: 1.0 },
    ]
}

/// Nearly incompressible (κ = 10⁴ μ₀) neo-Hookean with the Prony terms above.
fn material() -> Arc<dyn Hyperelastic> {
    Arc::new(Viscoelastic {
        elastic: Arc::new(UncoupledNeoHookean {
            c10: MU0 / 2.0,
            kappa: 1.0e4 * MU0,
        }),
        terms: terms(),
    })
}

/// A unit cube, one element, on symmetry supports (x = 0, y = 0, z = 0 faces roll), so that
/// a load on x = 1 gives uniaxial stress.
fn bar(dt: f64, t_end: f64, element: Formulation) -> (Problem, Mesh) {
    let mesh = generate::block([1.0, 1.0, 1.0], [1, 1, 1]);
    let mut p = one_body(mesh.clone(), material(), 1000.0, quasi_static(t_end, dt));
    p.bodies[0].element = element;
    p.time.newton_tol = 1e-8;
    p.dirichlet
        .push(fixed(mesh.node_sets["left"].clone(), [true, false, false]));
    p.dirichlet.push(fixed(
        mesh.node_sets["bottom"].clone(),
        [false, true, false],
    ));
    p.dirichlet
        .push(fixed(mesh.node_sets["back"].clone(), [false, false, true]));
    (p, mesh)
}

/// Prescribes u_x(t) on the x = 1 face; returns (t, nominal stress P₁₁ = axial force per
/// reference area) after every step.
fn stretch_history(u: Table, dt: f64, t_end: f64) -> Vec<(f64, f64)> {
    let (mut p, mesh) = bar(dt, t_end, Formulation::Standard);
    let right = mesh.node_sets["right"].clone();
    p.dirichlet.push(Dirichlet {
        nodes: right.clone(),
        components: [true, false, false],
        translation: [u, Table::constant(0.0), Table::constant(0.0)],
        rotation: None,
    });
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    let mut out = Vec::new();
    while !s.finished() {
        s.step().expect("step converges");
        let f = s.snapshot().f_int0;
        out.push((s.state.t, right.iter().map(|&n| f[3 * n]).sum::<f64>()));
    }
    out
}

#[test]
fn small_strain_relaxation_follows_the_prony_series() {
    // Strain ε₀ = 1e-4 ramped over the first step t_r, then held. Linear viscoelasticity with
    // an (almost) incompressible bulk: E(t) = 3 μ(t), μ(t) = μ₀ [1 − Σ gᵢ (1 − e^(−t/τᵢ))]; the
    // response to the ramp is, for t ≥ t_r,
    // σ(t) = 3 ε₀ [μ∞ + Σ μ₀ gᵢ (τᵢ/t_r)(e^(t_r/τᵢ) − 1) e^(−t/τᵢ)].
    // Differences: O(ε₀) geometric nonlinearity, O(μ/κ) = 1e-4 compressibility and the
    // O((Δt/τ)²/24) ≈ 1e-4 error of the time integration: 1e-3 relative to σ(0).
    let (eps, dt, t_end) = (1e-4, 0.005, 2.0);
    let hist = stretch_history(
        Table {
            t: vec![0.0, dt],
            v: vec![0.0, eps],
        },
        dt,
        t_end,
    );
    let g_sum: f64 = terms().iter().map(|t| t.g).sum();
    let exact = |t: f64| {
        3.0 * eps
            * (MU0 * (1.0 - g_sum)
                + terms()
                    .iter()
                    .map(|p| {
                        MU0 * p.g * (p.tau / dt) * ((dt / p.tau).exp() - 1.0) * (-t / p.tau).exp()
                    })
                    .sum::<f64>())
    };
    let scale = 3.0 * eps * MU0;
    let mut worst: f64 = 0.0;
    for &(t, p11) in &hist {
        worst = worst.max((p11 - exact(t)).abs() / scale);
    }
    let (t_last, p_last) = hist[hist.len() - 1];
    eprintln!(
        "relaxation: max error {worst:.2e} of 3 μ₀ ε₀; σ(t_end = {t_last})/σ₀ = {:.4} (exact {:.4})",
        p_last / scale,
        exact(t_last) / scale
    );
    assert!(worst < 1e-3, "max relative error {worst:e}");
    // The stress did relax: at t = 2 s the fast term is gone and the slow one mostly.
    assert!(p_last < 0.6 * hist[0].1);
}

/// Independent reference for the incompressible uniaxial stretch λ(t): the Prony internal
/// variables of the 11 and 22 components, qᵢ′ = −qᵢ/τᵢ + gᵢ dS_iso/dt, integrated by RK4
/// with a step of `h` [s]; returns the nominal stress P₁₁(t) at the requested times.
fn reference_uniaxial(lambda: impl Fn(f64) -> f64, times: &[f64], h: f64) -> Vec<f64> {
    // Incompressible neo-Hookean, J = 1: S_iso = μ₀ (I − ⅓ I₁ C⁻¹), C = diag(λ², 1/λ, 1/λ).
    let s_iso = |t: f64| {
        let l = lambda(t);
        let i1 = l * l + 2.0 / l;
        [MU0 * (1.0 - i1 / (3.0 * l * l)), MU0 * (1.0 - i1 * l / 3.0)]
    };
    let ds = |t: f64| {
        let e = 1e-7;
        let (a, b) = (s_iso(t + e), s_iso(t - e));
        [(a[0] - b[0]) / (2.0 * e), (a[1] - b[1]) / (2.0 * e)]
    };
    let tm = terms();
    let m = tm.len();
    let rhs = |t: f64, q: &[f64]| -> Vec<f64> {
        let d = ds(t);
        (0..2 * m)
            .map(|k| {
                let (i, c) = (k / 2, k % 2);
                -q[k] / tm[i].tau + tm[i].g * d[c]
            })
            .collect()
    };
    let mut q = vec![0.0; 2 * m];
    let mut t = 0.0;
    let mut out = Vec::new();
    let g_sum: f64 = tm.iter().map(|p| p.g).sum();
    for &target in times {
        while t < target - 1e-12 {
            let hh = h.min(target - t);
            let k1 = rhs(t, &q);
            let y2: Vec<f64> = q.iter().zip(&k1).map(|(a, b)| a + 0.5 * hh * b).collect();
            let k2 = rhs(t + 0.5 * hh, &y2);
            let y3: Vec<f64> = q.iter().zip(&k2).map(|(a, b)| a + 0.5 * hh * b).collect();
            let k3 = rhs(t + 0.5 * hh, &y3);
            let y4: Vec<f64> = q.iter().zip(&k3).map(|(a, b)| a + hh * b).collect();
            let k4 = rhs(t + hh, &y4);
            for k in 0..2 * m {
                q[k] += hh / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]);
            }
            t += hh;
        }
        let s = s_iso(t);
        let sp: Vec<f64> = (0..2)
            .map(|c| (1.0 - g_sum) * s[c] + (0..m).map(|i| q[2 * i + c]).sum::<f64>())
            .collect();
        // σ₂₂ = 0 fixes the pressure: σ₁₁ = λ² S′₁₁ − S′₂₂/λ; P₁₁ = σ₁₁/λ.
        let l = lambda(t);
        out.push((l * l * sp[0] - sp[1] / l) / l);
    }
    out
}

#[test]
fn large_strain_relaxation_matches_an_independent_ode_solution() {
    // Isochoric uniaxial stretch to λ = 2 over 0.5 s, held to 2 s: the faces x = 1, y = 1,
    // z = 1 follow F = diag(λ, λ^(−1/2), λ^(−1/2)) at every step end (J = 1, so the pressure,
    // which the bulk modulus fixes, drops out of σ₁₁ − σ₂₂). The normal stress difference from
    // the reaction forces is compared with the reference's λ² S′₁₁ − S′₂₂/λ (σ₂₂ = 0 there).
    // Prescribing the lateral faces keeps the Newton start free of a spurious volume change,
    // which for κ = 10⁴ μ₀ would make the tangent indefinite.
    // Tolerance 2e-3 of the peak: the second-order time integration, (Δt/τ)²/24 ≈ 4e-4 for
    // τ = 0.1 s, Δt = 0.01 s; the reference is RK4 at 1e-4 s.
    let (dt, t_end, t_ramp, stretch) = (0.01, 2.0, 0.5, 1.0);
    let lambda = |t: f64| 1.0 + stretch * (t / t_ramp).min(1.0);
    let knots: Vec<f64> = (0..=50).map(|k| k as f64 * t_ramp / 50.0).collect();
    let table = |f: &dyn Fn(f64) -> f64| Table {
        t: knots.clone(),
        v: knots.iter().map(|&t| f(lambda(t))).collect(),
    };
    let (mut p, mesh) = bar(dt, t_end, Formulation::Standard);
    let (right, top, front) = (
        mesh.node_sets["right"].clone(),
        mesh.node_sets["top"].clone(),
        mesh.node_sets["front"].clone(),
    );
    let lateral = |l: f64| l.powf(-0.5) - 1.0;
    for (nodes, k, tab) in [
        (right.clone(), 0, table(&|l| l - 1.0)),
        (top.clone(), 1, table(&lateral)),
        (front.clone(), 2, table(&lateral)),
    ] {
        let mut translation = [
            Table::constant(0.0),
            Table::constant(0.0),
            Table::constant(0.0),
        ];
        let mut components = [false; 3];
        translation[k] = tab;
        components[k] = true;
        p.dirichlet.push(Dirichlet {
            nodes,
            components,
            translation,
            rotation: None,
        });
    }
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    let mut hist = Vec::new();
    while !s.finished() {
        s.step().expect("step converges");
        let f = s.snapshot().f_int0;
        let l = lambda(s.state.t);
        let fx: f64 = right.iter().map(|&n| f[3 * n]).sum();
        let fy: f64 = top.iter().map(|&n| f[3 * n + 1]).sum();
        // Current areas: x face λ₂λ₃ = 1/λ, y face λ₁λ₃ = √λ.
        hist.push((s.state.t, fx * l - fy / l.sqrt()));
    }
    let times: Vec<f64> = hist.iter().map(|h| h.0).collect();
    let reference: Vec<f64> = reference_uniaxial(lambda, &times, 1e-4)
        .iter()
        .zip(&times)
        .map(|(p11, &t)| p11 * lambda(t))
        .collect();
    let peak = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst: f64 = 0.0;
    for ((_, d), r) in hist.iter().zip(&reference) {
        worst = worst.max((d - r).abs() / peak);
    }
    let (t_last, d_last) = hist[hist.len() - 1];
    eprintln!(
        "σ₁₁ − σ₂₂ at t = {t_last}: {d_last:.6e} Pa (reference {:.6e}), peak {peak:.6e}",
        reference[reference.len() - 1]
    );
    eprintln!("large-strain relaxation: max error {worst:.2e} of the peak {peak:.4e} Pa");
    assert!(worst < 2e-3, "max error {worst:e} of the peak");
}

/// Axial displacement of the loaded face at t = 1 s under a constant nominal stress
/// 0.5 μ₀ applied over the first 10 ms.
fn creep(dt: f64, element: Formulation) -> f64 {
    let (mut p, mesh) = bar(dt, 1.0, element);
    let right = mesh.node_sets["right"].clone();
    p.loads.push(NodalLoad {
        nodes: right.clone(),
        total_force: [
            Table {
                t: vec![0.0, 0.01],
                v: vec![0.0, 0.5 * MU0],
            },
            Table::constant(0.0),
            Table::constant(0.0),
        ],
    });
    let mut s = Stepper::new(Arc::new(p)).unwrap();
    while !s.finished() {
        s.step().expect("creep step converges");
    }
    right.iter().map(|&n| s.state.u[3 * n]).sum::<f64>() / right.len() as f64
}

#[test]
fn creep_converges_in_the_time_step() {
    for element in [Formulation::Standard, Formulation::FBar] {
        let dts = [0.01, 0.005, 0.0025];
        let u: Vec<f64> = dts.iter().map(|&dt| creep(dt, element)).collect();
        let order = ((u[0] - u[1]) / (u[1] - u[2])).abs().log2();
        eprintln!("creep {element:?}: u(1 s) = {u:?}, observed order {order:.2}");
        assert!(order > 0.9, "order {order}: {u:?}");
        // It crept: the long-term compliance is 1/(1 − Σg) = 2 times the instantaneous one.
        assert!(u[2] > 0.1, "{u:?}");
    }
}

#[test]
fn internal_variables_survive_a_snapshot() {
    // Run 10 steps, snapshot, continue in a fresh stepper: the next steps match bit for bit.
    let mk = || {
        let (mut p, mesh) = bar(0.02, 0.4, Formulation::FBar);
        p.loads.push(NodalLoad {
            nodes: mesh.node_sets["right"].clone(),
            total_force: [
                Table {
                    t: vec![0.0, 0.1],
                    v: vec![0.0, 0.3 * MU0],
                },
                Table::constant(0.0),
                Table::constant(0.0),
            ],
        });
        Stepper::new(Arc::new(p)).unwrap()
    };
    let mut a = mk();
    for _ in 0..10 {
        a.step().unwrap();
    }
    let snap = a.snapshot();
    assert!(snap.material_history.iter().any(|&v| v != 0.0));
    let mut b = mk();
    b.restore(snap).unwrap();
    while !a.finished() {
        a.step().unwrap();
        b.step().unwrap();
        assert_eq!(a.state.u, b.state.u);
    }
}
