//! The contact solve without the Delassus operator (docs/contact-solver.md): the contact
//! conditions enter the step's own Newton loop, so that a Newton iteration costs one sparse
//! factorisation whatever the number of contact points and the memory grows linearly with them.
//!
//! At every contact point α the dry force is written through the bi-potential projection with
//! a multiplier estimate λ_α (docs/model.md §5):
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

use crate::contact::anisotropic::{scale, scale_matrix, unscale};
use crate::contact::cone::{bipotential_trial, dry_projection, ContactState};
use crate::contact::history::PointHistory;
use crate::contact::interface::{Interface, PointSolution};
use crate::contact::law::InterfaceLaw;
use crate::{Mat3, Vec3};

/// The contact law linearised at one point for one Newton iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AugmentedPoint {
    /// The point's forces, the history the step leads to and case at the current displacement.
    pub solution: PointSolution,
    /// −∂r/∂x used in the Newton matrix [N/m], symmetric positive semi-definite.
    pub stiffness: Mat3,
    /// Change λ − r̄ a multiplier update would make [N]; zero at a solution.
    pub defect: Vec3,
    /// Potential of the point's contact forces at x with λ fixed [J]: ∂/∂x = −(r̄ + r̃).
    pub energy: f64,
}

/// The bi-potential projection P_K(r − ρ x̂) of a dry force `r` [N] at `x` [m]: `r` is a
/// solution of the dry contact law at `x` exactly when this returns `r` (docs/model.md §5).
pub fn bipotential_projection(mu: f64, rho: f64, r: Vec3, x: Vec3) -> Vec3 {
    dry_projection(bipotential_trial(r, x, mu, rho), mu).0
}

/// The dry force of the augmented Lagrangian (Alart & Curnier 1991) for multiplier `lambda`
/// [N] at `x` [m], with `rho` [N/m]: r_n = max(0, λ_n − ρ x_n), and r_t the projection of
/// λ_t − ρ x_t on the disk of radius μ max(λ_n, 0) (the friction threshold from the multiplier,
/// so that r_n depends on x_n only and r_t on x_t only). Returns r, its case, −∂r/∂x
/// (symmetric positive semi-definite) and the potential φ(x) [J] with ∂φ/∂x = −r:
/// φ = (r_n² + ‖λ_t − ρx_t‖² − dist(λ_t − ρx_t, disk)²)/(2ρ), convex.
///
/// r is a fixed point (r = λ, so the threshold is μ r_n) exactly when r_n ≥ 0, x_n ≥ 0,
/// r_n x_n = 0, ‖r_t‖ ≤ μ r_n, and x_t = 0 inside the disk or x_t = −κ r_t (κ ≥ 0) on its
/// rim: Signorini and Coulomb, the solutions of the bi-potential condition r = P_K(r − ρ x̂)
/// as well (docs/contact-solver.md).
pub fn augmented_dry_force(mu: f64, rho: f64, lambda: Vec3, x: Vec3) -> DryForce {
    let mu = mu.max(0.0);
    let trial_n = lambda[2] - rho * x[2];
    let rn = trial_n.max(0.0);
    let mut stiffness = Mat3::zeros();
    // At the kink (a closed gap with no force, e.g. a body resting on a surface at the start)
    // the generalised Jacobian may be either 0 or ρ: the contact one predicts better.
    if trial_n >= 0.0 {
        stiffness[(2, 2)] = rho;
    }
    let tau = [lambda[0] - rho * x[0], lambda[1] - rho * x[1]];
    let norm_tau = tau[0].hypot(tau[1]);
    let radius = mu * lambda[2].max(0.0);
    let (rt, sliding, tangential_energy) = if mu == 0.0 {
        // Frictionless: no tangential force whatever τ, and no tangential stiffness (the
        // disk's test below would call τ = 0 sticking and pin the tangential motion for an
        // iteration).
        ([0.0, 0.0], true, 0.0)
    } else if norm_tau <= radius {
        stiffness[(0, 0)] = rho;
        stiffness[(1, 1)] = rho;
        (tau, false, 0.5 * norm_tau * norm_tau)
    } else {
        let t = [tau[0] / norm_tau, tau[1] / norm_tau];
        let k = rho * radius / norm_tau;
        for a in 0..2 {
            for b in 0..2 {
                let delta = if a == b { 1.0 } else { 0.0 };
                stiffness[(a, b)] = k * (delta - t[a] * t[b]);
            }
        }
        (
            [radius * t[0], radius * t[1]],
            true,
            radius * norm_tau - 0.5 * radius * radius,
        )
    };
    let state = if rn == 0.0 {
        ContactState::Apart
    } else if sliding {
        ContactState::Slide
    } else {
        ContactState::Stick
    };
    DryForce {
        force: Vec3::new(rt[0], rt[1], rn),
        state,
        stiffness,
        energy: (0.5 * rn * rn + tangential_energy) / rho,
    }
}

/// The augmented-Lagrangian dry force at one point (see [`augmented_dry_force`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DryForce {
    /// r̄ in the local frame [N].
    pub force: Vec3,
    /// Apart (r_n = 0), stick (r_t inside the disk) or slide.
    pub state: ContactState,
    /// −∂r̄/∂x [N/m].
    pub stiffness: Mat3,
    /// Potential φ with ∂φ/∂x = −r̄ [J].
    pub energy: f64,
}

/// The contact law at one point: dry force through the projection of λ − ρ x̂, the law's
/// adhesive force at x, and their stiffness for the Newton matrix.
///
/// `history0` is the law's history of the point frozen at the start of the step, `dt` [s] the
/// step, `area` [m²] the tributary area,
/// `rho` [N/m] the augmentation parameter, `lambda` [N] the multiplier and `x` [m] the local
/// relative displacement (slip increment t₁, t₂; end gap n).
///
/// The stiffness leaves out the non-symmetric parts of −∂r/∂x (the μ‖x_t‖ term of x̂ and the
/// softening of β₁): they change the convergence rate, not the solution.
pub fn augmented_point(
    law: &InterfaceLaw,
    history0: PointHistory,
    dt: f64,
    area: f64,
    rho: f64,
    lambda: Vec3,
    x: Vec3,
) -> AugmentedPoint {
    let s = law.tangent_scale();
    let dry = if s == 1.0 {
        augmented_dry_force(law.mu, rho, lambda, x)
    } else {
        // Orthotropic: the isotropic law of μ₁ in the scaled variables λ' = T⁻¹λ, x' = Tx;
        // r = T r', −∂r/∂x = T (−∂r'/∂x') T, the potential is the same.
        let d = augmented_dry_force(law.mu, rho, unscale(lambda, s), scale(x, s));
        DryForce {
            force: scale(d.force, s),
            stiffness: scale_matrix(d.stiffness, s),
            ..d
        }
    };
    let (r_dry, state, mut stiffness) = (dry.force, dry.state, dry.stiffness);
    let (history, r_adh, adhesive_energy) = match law.adhesive_response(&history0, dt, area, x) {
        Some(resp) => {
            stiffness += resp.secant_stiffness;
            (resp.history, resp.force, resp.energy)
        }
        None => (PointHistory::default(), Vec3::zeros(), 0.0),
    };
    AugmentedPoint {
        solution: PointSolution {
            r_dry,
            r_adh,
            x,
            history,
            state,
            iterations: 1,
            converged: true,
        },
        stiffness,
        defect: lambda - r_dry,
        energy: dry.energy + adhesive_energy,
    }
}

/// ‖(λ_α − r̄_α)_α‖ [N] over the points: how much a multiplier update would change them.
pub fn defect_norm(evals: &[AugmentedPoint]) -> f64 {
    evals
        .iter()
        .flat_map(|e| e.defect.iter())
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {

    /// Frictionless, the tangential force is zero whatever τ, so −∂r/∂x has no tangential
    /// part: at τ = 0 (a closed point with no slip yet) the law neither sticks nor pins the
    /// tangential motion. Checked against central differences of the force.
    #[test]
    fn a_frictionless_point_has_no_tangential_stiffness() {
        let (rho, lambda) = (1e6, Vec3::new(0.0, 0.0, 2.0));
        for x in [Vec3::new(0.0, 0.0, -1e-6), Vec3::new(3e-7, -1e-7, -1e-6)] {
            let d = augmented_dry_force(0.0, rho, lambda, x);
            assert_eq!(d.state, ContactState::Slide);
            assert_eq!((d.force[0], d.force[1]), (0.0, 0.0));
            let h = 1e-9;
            for k in 0..3 {
                let (mut xp, mut xm) = (x, x);
                xp[k] += h;
                xm[k] -= h;
                let fp = augmented_dry_force(0.0, rho, lambda, xp).force;
                let fm = augmented_dry_force(0.0, rho, lambda, xm).force;
                for i in 0..3 {
                    let fd = -(fp[i] - fm[i]) / (2.0 * h);
                    assert!(
                        (d.stiffness[(i, k)] - fd).abs() <= 1e-6 * rho,
                        "{i}{k}: {d:?}"
                    );
                }
            }
        }
    }

    use super::*;
    use crate::contact::cone::ContactState;
    use crate::contact::history::LawPointHistory;
    use crate::contact::rcc::{adhesive_response, BondState, RccParams};
    use crate::contact::solver::site_stiffness::RHO_FACTOR;
    use crate::Vec2;

    fn dry(mu: f64) -> InterfaceLaw {
        InterfaceLaw::rcc(mu, None, None)
    }

    /// One point on a spring k pushed into a rigid wall, x_n = x_free + r_n/k: the
    /// augmented-Lagrangian loop (the frozen-multiplier problem solved exactly, then the
    /// multiplier update) reaches the exact force −k x_free, the error contracting by
    /// k/(k + ρ) per update as the closed form of the iteration says.
    #[test]
    fn multiplier_updates_converge_to_the_contact_force() {
        let k = 2.0e5;
        let rho = RHO_FACTOR * k;
        let x_free = -3e-4;
        let exact = -k * x_free;
        let law = dry(0.9);
        let mut lambda = Vec3::zeros();
        let mut errors = Vec::new();
        for _ in 0..4 {
            // In contact r_n = λ_n − ρ x_n, so x_n = x_free + r_n/k gives:
            let xn = (k * x_free + lambda[2]) / (k + rho);
            let ev = augmented_point(
                &law,
                PointHistory::default(),
                1e-3,
                1.0,
                rho,
                lambda,
                Vec3::new(0.0, 0.0, xn),
            );
            assert_eq!(ev.solution.state, ContactState::Stick);
            assert_eq!(ev.stiffness[(2, 2)], rho);
            lambda = augmented_dry_force(law.mu, rho, lambda, Vec3::new(0.0, 0.0, xn)).force;
            errors.push((lambda[2] - exact).abs());
        }
        let rate = k / (k + rho);
        for w in errors.windows(2) {
            assert!(
                (w[1] - rate * w[0]).abs() <= 1e-9 * exact + 1e-6 * w[0],
                "{errors:?}"
            );
        }
        assert!(errors[3] < 1e-9 * exact, "{errors:?}");
    }

    #[test]
    fn a_fixed_point_satisfies_the_coulomb_law_in_every_case() {
        let law = dry(0.5);
        let rho = 1e3;
        let at = |lambda: Vec3, x: Vec3| {
            augmented_point(&law, PointHistory::default(), 1e-3, 1.0, rho, lambda, x)
        };
        // Apart: positive gap, zero multiplier.
        let ev = at(Vec3::zeros(), Vec3::new(1e-3, 0.0, 2e-3));
        assert_eq!(ev.solution.state, ContactState::Apart);
        assert_eq!(ev.defect, Vec3::zeros());
        // Stick: closed, no slip, force inside the cone.
        let ev = at(Vec3::new(0.1, -0.2, 1.0), Vec3::zeros());
        assert_eq!(ev.solution.state, ContactState::Stick);
        assert_eq!(ev.defect, Vec3::zeros());
        assert_eq!(ev.stiffness[(0, 0)], rho);
        // Slide: on the cone, opposing the slip, with x_n = 0.
        let lam = Vec3::new(-0.3, -0.4, 1.0); // |r_t| = 0.5 = μ r_n
        let ev = at(lam, Vec3::new(3e-4, 4e-4, 0.0));
        assert_eq!(ev.solution.state, ContactState::Slide);
        let d = ev.defect.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(d < 1e-12, "defect {d}");
        // The wrong direction of slip is not a fixed point.
        let ev = at(lam, Vec3::new(-3e-4, -4e-4, 0.0));
        assert!(ev.defect.iter().any(|v| v.abs() > 1e-3));
    }

    #[test]
    fn adhesion_adds_its_force_and_secant_stiffness() {
        let a = RccParams::new(20.0, 2e9, 1e9, 0.1);
        let law = InterfaceLaw::rcc(0.0, Some(a), None);
        let bond0 = BondState {
            beta: 1.0,
            ut: Vec2::new(1e-7, 0.0),
            damage: 0.0,
        };
        let x = Vec3::new(1e-7, 0.0, 5e-8);
        let ev = augmented_point(&law, bond0.encode(), 1e-4, 2e-6, 1e3, Vec3::zeros(), x);
        let resp = adhesive_response(&a, bond0, 1e-4, 2e-6, x);
        assert_eq!(ev.solution.r_adh, resp.force);
        assert!(resp.force[2] < 0.0 && resp.force[0] < 0.0);
        assert_eq!(ev.stiffness[(2, 2)], resp.secant_stiffness[(2, 2)]);
        assert_eq!(ev.solution.state, ContactState::Apart);
    }
}
