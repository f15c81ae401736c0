//! The contact solve without the Delassus operator (docs/contact-solver.md): the contact
//! conditions enter the step's own Newton loop, so that a Newton iteration costs one sparse
//! factorisation whatever the number of contact points and the memory grows linearly with them.
//!
//! At every contact point α the dry force is written through the bi-potential projection with
//! a multiplier estimate λ_α (model.md §5):
//!
//!   r̄_α(u) = P_K(λ_α − ρ_α x̂_α(u)),   x̂ = x + μ‖x_t‖ n,
//!
//! and the adhesive force r̃_α(u) = r̃(β₁(x), x) is the RCC law evaluated at x(u). The Newton
//! correction solves (K̄ + Σ H_αᵀ k_α H_α) Δu = Hᵀ r − G(u), where k_α = −∂r_α/∂x (the
//! projection's generalised Jacobian times ρ_α plus the adhesive secant stiffness) enters the
//! sparse matrix. Between Newton iterations the multiplier is updated by the same projection at
//! the new displacement, λ_α ← P_K(λ_α − ρ_α x̂_α(u)) (an augmented-Lagrangian update), so a
//! fixed point (u, λ) has r̄ = λ = P_K(λ − ρ x̂): exactly the bi-potential solution of the
//! Gauss-Seidel solver, for any ρ > 0. ρ_α is a large multiple of the stiffness K̄ shows at the
//! point, so that each update contracts the multiplier error by about 1/(1 + that multiple).
//!
//! Everything here is pure: the stepper owns the loop.

use super::detect::ContactPoint;
use super::law::{
    adhesive_response, bipotential_trial, dry_projection, projection_jacobian, BondState,
    InterfaceLaw, PointSolution,
};
use crate::linalg::BlockPattern;

/// ρ_α as a multiple of the stiffness K̄ shows at contact point α: each multiplier update
/// contracts the error by about 1/(1 + this) at an isolated point.
pub const RHO_FACTOR: f64 = 100.0;

/// The contact law linearised at one point for one Newton iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AugmentedPoint {
    /// The point's forces, β₁, bond stretch and case at the current displacement.
    pub solution: PointSolution,
    /// −∂r/∂x used in the Newton matrix [N/m], symmetric positive semi-definite.
    pub stiffness: [[f64; 3]; 3],
    /// Natural-map defect λ − P_K(λ − ρ x̂) of the multiplier [N]; zero at a solution.
    pub defect: [f64; 3],
}

/// The dry force P_K(λ − ρ x̂) for multiplier `lambda` [N] at `x` [m] (the multiplier update).
pub fn updated_multiplier(mu: f64, rho: f64, lambda: [f64; 3], x: [f64; 3]) -> [f64; 3] {
    dry_projection(bipotential_trial(lambda, x, mu, rho), mu).0
}

/// The contact law at one point: dry force through the projection of λ − ρ x̂, RCC adhesive
/// force at x, and their stiffness for the Newton matrix.
///
/// `bond0` is the committed bond state, `dt` [s] the step, `area` [m²] the tributary area,
/// `rho` [N/m] the augmentation parameter, `lambda` [N] the multiplier and `x` [m] the local
/// relative displacement (slip increment t₁, t₂; end gap n).
///
/// The stiffness leaves out the non-symmetric parts of −∂r/∂x (the μ‖x_t‖ term of x̂ and the
/// softening of β₁): they change the convergence rate, not the solution.
pub fn augmented_point(
    law: &InterfaceLaw,
    bond0: BondState,
    dt: f64,
    area: f64,
    rho: f64,
    lambda: [f64; 3],
    x: [f64; 3],
) -> AugmentedPoint {
    let mu = law.mu.max(0.0);
    let r_star = bipotential_trial(lambda, x, mu, rho);
    let (r_dry, state) = dry_projection(r_star, mu);
    let jac = projection_jacobian(r_star, mu, state);
    let mut stiffness = jac.map(|row| row.map(|v| rho * v));
    let (beta, ut, r_adh) = match &law.adhesion {
        Some(a) => {
            let resp = adhesive_response(a, bond0, dt, area, x);
            for (srow, arow) in stiffness.iter_mut().zip(resp.secant_stiffness) {
                for (s, a) in srow.iter_mut().zip(arow) {
                    *s += a;
                }
            }
            (resp.beta, resp.ut, resp.force)
        }
        None => (0.0, [0.0; 2], [0.0; 3]),
    };
    AugmentedPoint {
        solution: PointSolution {
            r_dry,
            r_adh,
            x,
            beta,
            ut,
            state,
            iterations: 1,
            converged: true,
        },
        stiffness,
        defect: std::array::from_fn(|k| lambda[k] - r_dry[k]),
    }
}

/// Upper bound of the stiffness [N/m] that K̄ shows at a contact point: 1/(e K̄⁻¹ e) ≤ e K̄ e
/// along any unit direction e, taken as 1/(1/k_s + Σ_m w_m²/k_m) from the largest free diagonal
/// entry of K̄ at the slave node (k_s) and at each master node (k_m). `diagonal` holds K̄_ii;
/// constrained unknowns are skipped. Returns `None` when every unknown involved is constrained.
pub fn point_stiffness(pt: &ContactPoint, diagonal: &[f64], constrained: &[bool]) -> Option<f64> {
    let node_k = |n: usize| -> Option<f64> {
        (0..3)
            .filter(|&k| !constrained[3 * n + k])
            .map(|k| diagonal[3 * n + k])
            .filter(|v| v.is_finite() && *v > 0.0)
            .reduce(f64::max)
    };
    let mut compliance = node_k(pt.slave).map_or(0.0, |k| 1.0 / k);
    for &(m, w) in &pt.master {
        if let Some(k) = node_k(m) {
            compliance += w * w / k;
        }
    }
    (compliance > 0.0).then(|| 1.0 / compliance)
}

/// Node couplings (slave, master node) that H_αᵀ k H_α adds to the element pattern.
pub fn couplings(points: &[ContactPoint]) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for pt in points {
        for (i, &(m, _)) in pt.master.iter().enumerate() {
            pairs.push((pt.slave, m));
            for &(m2, _) in &pt.master[..i] {
                pairs.push((m, m2));
            }
        }
    }
    pairs
}

/// Adds H_αᵀ k_α H_α of every point to the upper-triangle `values` of `pattern` (which must
/// hold [`couplings`]).
pub fn add_contact_tangent(
    points: &[ContactPoint],
    stiffness: &[[[f64; 3]; 3]],
    pattern: &BlockPattern,
    values: &mut [f64],
) {
    for (pt, k) in points.iter().zip(stiffness) {
        if k.iter().flatten().all(|&v| v == 0.0) {
            continue;
        }
        // G = Fᵀ k F in global axes (F has rows T₁, T₂, N).
        let f = &pt.frame;
        let mut kf = [[0.0; 3]; 3];
        for a in 0..3 {
            for j in 0..3 {
                kf[a][j] = (0..3).map(|b| k[a][b] * f[b][j]).sum();
            }
        }
        let mut g = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                g[i][j] = (0..3).map(|a| f[a][i] * kf[a][j]).sum();
            }
        }
        // H = [I at the slave, −w_m I at master node m] before the rotation.
        let nodes: Vec<(usize, f64)> = std::iter::once((pt.slave, 1.0))
            .chain(pt.master.iter().map(|&(m, w)| (m, -w)))
            .collect();
        for &(a, ca) in &nodes {
            for &(b, cb) in &nodes {
                if a > b {
                    continue;
                }
                let rank = pattern
                    .rank(a, b)
                    .expect("the pattern holds the contact couplings");
                let c = ca * cb;
                for kk in 0..3 {
                    let rows = if a == b { kk + 1 } else { 3 };
                    for i in 0..rows {
                        values[pattern.position(rank, b, i, kk)] += c * g[i][kk];
                    }
                }
            }
        }
    }
}

/// Natural-map residual ‖(λ_α − P_K(λ_α − ρ_α x̂_α))_α‖ [N] over the points.
pub fn defect_norm(evals: &[AugmentedPoint]) -> f64 {
    evals
        .iter()
        .flat_map(|e| e.defect)
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::law::{ContactState, RccParams};

    fn dry(mu: f64) -> InterfaceLaw {
        InterfaceLaw { mu, adhesion: None }
    }

    /// One point on a spring k against a rigid wall, x = x_free + r/k: the augmented-Lagrangian
    /// loop (Newton on x with the multiplier frozen, then the multiplier update) reaches the
    /// exact stick force −k x_free, the error contracting by about k/(k + ρ) per update.
    #[test]
    fn multiplier_updates_converge_to_the_stick_force() {
        let k = 2.0e5;
        let rho = RHO_FACTOR * k;
        let x_free = [1e-4, -2e-5, -3e-4]; // pushed into the wall, sliding sideways
        let law = dry(0.9);
        let exact = x_free.map(|v| -k * v);
        let mut lambda = [0.0; 3];
        let mut x = x_free;
        let mut errors = Vec::new();
        for _ in 0..5 {
            // Newton on x = x_free + r(x)/k with the multiplier frozen (a few steps: the
            // dropped μ‖x_t‖ term makes the stiffness inexact).
            for _ in 0..20 {
                let ev = augmented_point(&law, BondState::default(), 1e-3, 1.0, rho, lambda, x);
                let r = ev.solution.r_dry;
                for a in 0..3 {
                    x[a] += (r[a] - k * (x[a] - x_free[a])) / (k + ev.stiffness[a][a]);
                }
            }
            lambda = updated_multiplier(law.mu, rho, lambda, x);
            let e = (0..3)
                .map(|a| (lambda[a] - exact[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            errors.push(e);
        }
        let size = exact.iter().map(|v| v * v).sum::<f64>().sqrt();
        // Each update gains about two digits (1 + RHO_FACTOR = 101); allow a factor 2.
        let rate = 2.0 / (1.0 + RHO_FACTOR);
        for w in errors.windows(2) {
            assert!(w[1] <= rate * w[0] || w[1] < 1e-12 * size, "{errors:?}");
        }
        assert!(errors[4] < 1e-9 * size, "{errors:?}");
    }

    #[test]
    fn a_fixed_point_satisfies_the_coulomb_law_in_every_case() {
        let law = dry(0.5);
        let rho = 1e3;
        // Apart: positive gap, zero multiplier.
        let ev = augmented_point(
            &law,
            BondState::default(),
            1e-3,
            1.0,
            rho,
            [0.0; 3],
            [1e-3, 0.0, 2e-3],
        );
        assert_eq!(ev.solution.state, ContactState::Apart);
        assert_eq!(ev.defect, [0.0; 3]);
        // Stick: closed, no slip, force inside the cone.
        let lam = [0.1, -0.2, 1.0];
        let ev = augmented_point(&law, BondState::default(), 1e-3, 1.0, rho, lam, [0.0; 3]);
        assert_eq!(ev.solution.state, ContactState::Stick);
        assert_eq!(ev.defect, [0.0; 3]);
        assert_eq!(ev.stiffness[0][0], rho);
        // Slide: on the cone, opposing the slip, with x_n = 0.
        let lam = [-0.3, -0.4, 1.0]; // |r_t| = 0.5 = μ r_n
        let slip = [3e-4, 4e-4, 0.0];
        let ev = augmented_point(&law, BondState::default(), 1e-3, 1.0, rho, lam, slip);
        assert_eq!(ev.solution.state, ContactState::Slide);
        let d = ev.defect.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(d < 1e-12, "defect {d}");
        // The wrong direction of slip is not a fixed point.
        let ev = augmented_point(
            &law,
            BondState::default(),
            1e-3,
            1.0,
            rho,
            lam,
            [-3e-4, -4e-4, 0.0],
        );
        assert!(ev.defect.iter().any(|v| v.abs() > 1e-3));
    }

    #[test]
    fn adhesion_adds_its_force_and_secant_stiffness() {
        let a = RccParams::new(20.0, 2e9, 1e9, 0.1);
        let law = InterfaceLaw {
            mu: 0.0,
            adhesion: Some(a),
        };
        let bond0 = BondState {
            beta: 1.0,
            ut: [1e-7, 0.0],
        };
        let x = [1e-7, 0.0, 5e-8];
        let ev = augmented_point(&law, bond0, 1e-4, 2e-6, 1e3, [0.0; 3], x);
        let resp = adhesive_response(&a, bond0, 1e-4, 2e-6, x);
        assert_eq!(ev.solution.r_adh, resp.force);
        assert!(resp.force[2] < 0.0 && resp.force[0] < 0.0);
        assert_eq!(ev.stiffness[2][2], resp.secant_stiffness[2][2]);
        assert_eq!(ev.solution.state, ContactState::Apart);
    }
}
