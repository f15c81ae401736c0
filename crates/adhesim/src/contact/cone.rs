//! Coulomb's friction cone and the bi-potential projection onto it (docs/model.md §5): the dry
//! part of every interface law, as pure functions of local vectors ordered (t₁, t₂, n), with
//! r_n > 0 compression and x the local relative displacement (slip increment, end gap).
//!
//! **Sign of the sliding projection.** The paper's eq 32 prints `+ μ n`; with `r_n > 0` as
//! compression that leaves the cone, so `− μ n` is used, as docs/model.md says.

use crate::{Mat3, Vec3};

/// Which case of the bi-potential projection the dry part fell into. Whether the point is
/// bonded is reported separately ([`super::interface::PointSolution::bonded`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactState {
    /// Separating: r̄ = 0 (the gap is open).
    Apart,
    /// Sticking: r̄ inside the Coulomb cone, no slip.
    Stick,
    /// Sliding: r̄ on the boundary of the cone, opposing the slip.
    Slide,
}

/// Projection of `r_star` [N] onto the Coulomb cone K_μ = {r_n ≥ 0, ‖r_t‖ ≤ μ r_n}
/// (docs/model.md §5), with the case it fell into.
///
/// - separating, `μ‖r*_t‖ < −r*_n`: `r = 0`;
/// - sticking, `‖r*_t‖ ≤ μ r*_n`: `r = r*`;
/// - sliding otherwise: `r_n = (r*_n + μ‖r*_t‖)/(1 + μ²)`, `r_t = μ r_n r*_t/‖r*_t‖`.
///
/// `μ = 0` is frictionless contact: `r_t = 0`, `r_n = max(r*_n, 0)`.
pub fn dry_projection(r_star: Vec3, mu: f64) -> (Vec3, ContactState) {
    let mu = mu.max(0.0);
    let st = r_star[0].hypot(r_star[1]);
    let sn = r_star[2];
    if mu * st < -sn {
        return (Vec3::zeros(), ContactState::Apart);
    }
    if st <= mu * sn {
        return (r_star, ContactState::Stick);
    }
    // Sliding: here st > μ s_n and μ st ≥ −s_n, which together give st > 0.
    let rn = ((sn + mu * st) / (1.0 + mu * mu)).max(0.0);
    if st > 0.0 {
        let k = mu * rn / st;
        (
            Vec3::new(k * r_star[0], k * r_star[1], rn),
            ContactState::Slide,
        )
    } else {
        (Vec3::new(0.0, 0.0, rn), ContactState::Slide)
    }
}

/// Bi-potential trial force r* = r̄ − ρ (x + μ‖x_t‖ n) [N] (docs/model.md §5, paper eq 30), from the
/// dry force `r_dry` [N], the local relative displacement `x` [m] and ρ [N/m].
pub fn bipotential_trial(r_dry: Vec3, x: Vec3, mu: f64, rho: f64) -> Vec3 {
    let mu = mu.max(0.0);
    let xt = x[0].hypot(x[1]);
    r_dry - rho * Vec3::new(x[0], x[1], x[2] + mu * xt)
}

/// D = ∂x̂/∂x of the modified relative displacement x̂ = x + μ‖x_t‖n at `x` [m] with the
/// friction coefficient `mu` ≥ 0: I + μ n (x_t/‖x_t‖, 0)ᵀ, the second term dropped at x_t = 0.
pub fn modified_displacement_jacobian(x: Vec3, mu: f64) -> Mat3 {
    let mut d = Mat3::identity();
    let xt = x[0].hypot(x[1]);
    if xt > 0.0 && mu > 0.0 {
        d[(2, 0)] = mu * x[0] / xt;
        d[(2, 1)] = mu * x[1] / xt;
    }
    d
}

/// Relative distance from the cone's surface within which a sticking trial force takes the
/// sliding case's Jacobian ([`jacobian_case`]). A force that ended the last step sliding lies
/// on the surface to the contact law's tolerance (10⁻⁸ relative by default) and, with no slip
/// yet in the new step, is the next step's trial force; 10⁻⁶ covers it with a margin. On the
/// pad pressed onto a rigid plane with μ = 0.3 (bench/febio/pad.toml, 3,136 contact nodes)
/// 10⁻⁹, 10⁻⁶ and 10⁻³ gave the same semismooth directions.
pub const SLIDE_TIE: f64 = 1e-6;

/// The case whose Jacobian a semismooth Newton method takes at `r_star` [N], given the case
/// `state` [`dry_projection`] found, friction coefficient `mu`: a sticking trial force on the
/// cone's surface (‖r*_t‖ ≥ (1 − [`SLIDE_TIE`]) μ r*_n, r*_t ≠ 0) takes the sliding one.
/// There both cases' Jacobians belong to the projection's generalised Jacobian, so either
/// gives a semismooth Newton direction; the sliding one lets the point slip in that very
/// direction. At the start of a loading step every point that was sliding is such a force;
/// with the sticking Jacobian the slip zone would be found again one ring of points per
/// direction.
pub fn jacobian_case(r_star: Vec3, mu: f64, state: ContactState) -> ContactState {
    let st = r_star[0].hypot(r_star[1]);
    let on_surface = mu > 0.0 && st > 0.0 && st >= (1.0 - SLIDE_TIE) * mu * r_star[2];
    if state == ContactState::Stick && on_surface {
        ContactState::Slide
    } else {
        state
    }
}

/// Jacobian of [`dry_projection`] at `r_star` in the given case (symmetric, eigenvalues in
/// [0, 1]).
pub fn projection_jacobian(r_star: Vec3, mu: f64, case: ContactState) -> Mat3 {
    match case {
        ContactState::Apart => Mat3::zeros(),
        ContactState::Stick => Mat3::identity(),
        ContactState::Slide => {
            let s = r_star[0].hypot(r_star[1]);
            let q = 1.0 + mu * mu;
            if s.is_nan() || s <= 0.0 {
                let mut j = Mat3::zeros();
                j[(2, 2)] = 1.0 / q;
                return j;
            }
            let t = [r_star[0] / s, r_star[1] / s];
            let rn = ((r_star[2] + mu * s) / q).max(0.0);
            let mut j = Mat3::zeros();
            for a in 0..2 {
                for b in 0..2 {
                    let delta = if a == b { 1.0 } else { 0.0 };
                    j[(a, b)] = mu * mu * t[a] * t[b] / q + mu * rn / s * (delta - t[a] * t[b]);
                }
                j[(a, 2)] = mu * t[a] / q;
                j[(2, a)] = mu * t[a] / q;
            }
            j[(2, 2)] = 1.0 / q;
            j
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::test_support::*;
    use std::f64::consts::PI;

    // ------------------------------------------------------------------ projection

    #[test]
    fn projection_cases_match_hand_values() {
        // Separating: μ‖r*_t‖ = 0.05 < 1 = −r*_n.
        let (r, c) = dry_projection(v3(0.1, 0.0, -1.0), 0.5);
        assert_eq!((r, c), (Vec3::zeros(), ContactState::Apart));
        // Sticking: ‖r*_t‖ = 0.5 ≤ 1 = μ r*_n.
        let (r, c) = dry_projection(v3(0.3, 0.4, 2.0), 0.5);
        assert_eq!((r, c), (v3(0.3, 0.4, 2.0), ContactState::Stick));
        // Sliding (docs/model.md §5.1): μ = 1, r* = (2, 0, 0) → r_n = 1, r_t = (1, 0).
        let (r, c) = dry_projection(v3(2.0, 0.0, 0.0), 1.0);
        assert_eq!(c, ContactState::Slide);
        assert_vec_close(r, v3(1.0, 0.0, 1.0), 1e-15);
        // Sliding: μ = 0.5, r* = (3, 4, 1): r_n = (1 + 2.5)/1.25 = 2.8, r_t = 1.4 (0.6, 0.8).
        let (r, c) = dry_projection(v3(3.0, 4.0, 1.0), 0.5);
        assert_eq!(c, ContactState::Slide);
        assert_vec_close(r, v3(0.84, 1.12, 2.8), 1e-15);
        // Sliding from below the apex plane: μ = 2, r* = (3, 0, −1): r_n = (−1 + 6)/5 = 1.
        let (r, c) = dry_projection(v3(3.0, 0.0, -1.0), 2.0);
        assert_eq!(c, ContactState::Slide);
        assert_vec_close(r, v3(2.0, 0.0, 1.0), 1e-15);
    }

    #[test]
    fn forces_on_the_cone_take_the_sliding_jacobian() {
        let mu = 0.5;
        // On the surface (‖r*_t‖ = 1 = μ r*_n): dry_projection says sticking, the Jacobian
        // is the sliding one, and the projection is continuous there (both cases give r*).
        let on = v3(0.6, 0.8, 2.0);
        let (r, c) = dry_projection(on, mu);
        assert_eq!((r, c), (on, ContactState::Stick));
        assert_eq!(jacobian_case(on, mu, c), ContactState::Slide);
        let slid = Vec3::new(0.6, 0.8, 2.0 - 1e-12);
        assert_vec_close(dry_projection(slid, mu).0, on, 1e-12);
        // Just inside the tolerance still slides; clearly inside sticks.
        let near = v3(0.6, 0.8, 2.0 * (1.0 + 0.5 * SLIDE_TIE));
        assert_eq!(
            jacobian_case(near, mu, ContactState::Stick),
            ContactState::Slide
        );
        let inside = v3(0.6, 0.8, 2.0 * (1.0 + 2.0 * SLIDE_TIE));
        assert_eq!(
            jacobian_case(inside, mu, ContactState::Stick),
            ContactState::Stick
        );
        // No tangential force, no friction, other cases: unchanged.
        assert_eq!(
            jacobian_case(v3(0.0, 0.0, 1.0), mu, ContactState::Stick),
            ContactState::Stick
        );
        assert_eq!(
            jacobian_case(on, 0.0, ContactState::Stick),
            ContactState::Stick
        );
        assert_eq!(
            jacobian_case(on, mu, ContactState::Apart),
            ContactState::Apart
        );
        assert_eq!(
            jacobian_case(on, mu, ContactState::Slide),
            ContactState::Slide
        );
    }

    #[test]
    fn projection_frictionless() {
        let (r, c) = dry_projection(v3(1.0, -2.0, 3.0), 0.0);
        assert_eq!((r, c), (v3(0.0, 0.0, 3.0), ContactState::Slide));
        let (r, c) = dry_projection(v3(1.0, -2.0, -3.0), 0.0);
        assert_eq!((r, c), (Vec3::zeros(), ContactState::Apart));
        let (r, c) = dry_projection(v3(0.0, 0.0, 3.0), 0.0);
        assert_eq!((r, c), (v3(0.0, 0.0, 3.0), ContactState::Stick));
        // Negative μ is treated as 0.
        assert_eq!(dry_projection(v3(1.0, 0.0, 1.0), -0.5).0, v3(0.0, 0.0, 1.0));
    }

    #[test]
    fn sliding_projection_is_orthogonal_closed_form() {
        // r* − r = (‖r*_t‖ − μ r*_n)/(1 + μ²) (t̂, −μ): normal to the cone's generator (μ t̂, 1)
        // through r, and r itself lies on that generator.
        let mu = 0.7;
        let rs = v3(1.5, -2.0, 0.4);
        let (r, c) = dry_projection(rs, mu);
        assert_eq!(c, ContactState::Slide);
        let st = rs[0].hypot(rs[1]);
        let t = [rs[0] / st, rs[1] / st];
        let k = (st - mu * rs[2]) / (1.0 + mu * mu);
        let y = rs - r;
        assert_vec_close(y, v3(k * t[0], k * t[1], -k * mu), 1e-14);
        let gen = v3(mu * t[0], mu * t[1], 1.0);
        assert!(y.dot(&gen).abs() <= 1e-14 * rs.norm());
        let rn = r[2];
        assert_vec_close(r, rn * gen, 1e-14);
    }

    #[test]
    fn paper_plus_sign_would_leave_the_cone() {
        // Eq 32 as printed: r = r* − (‖r*_t‖ − μ r*_n)/(1 + μ²) (t̂ + μ n).
        let (mu, rs) = (1.0, v3(2.0, 0.0, 0.0));
        let k = (2.0 - mu * 0.0) / (1.0 + mu * mu);
        let printed = [rs[0] - k, rs[1], rs[2] - k * mu];
        assert!(printed[2] < 0.0, "printed sign gives r_n = {}", printed[2]);
        let (ours, _) = dry_projection(rs, mu);
        assert!(ours[2] > 0.0 && (ours[0].hypot(ours[1]) - mu * ours[2]).abs() < 1e-15);
    }

    #[test]
    fn projection_random_properties() {
        let mut rng = Rng(7);
        let mut hits = [0usize; 3];
        for i in 0..20_000 {
            let mu = if i % 10 == 0 {
                0.0
            } else {
                rng.uniform(0.0, 1.5)
            };
            let mag = 10f64.powf(rng.uniform(-6.0, 6.0));
            let rs = v3(
                mag * rng.uniform(-1.0, 1.0),
                mag * rng.uniform(-1.0, 1.0),
                mag * rng.uniform(-1.0, 1.0),
            );
            let (r, c) = dry_projection(rs, mu);
            hits[c as usize] += 1;
            let s = rs.norm();
            let tol = 1e-12 * s;
            // In the cone.
            assert!(r[2] >= 0.0);
            assert!(r[0].hypot(r[1]) <= mu * r[2] + tol, "{rs:?} μ={mu}");
            // Idempotent.
            let (rr, cc) = dry_projection(r, mu);
            assert!((rr - r).norm() <= tol, "idempotence {rs:?} μ={mu}");
            if r.norm() > 0.0 {
                assert_ne!(cc, ContactState::Apart);
            }
            // Moreau: y = r* − r lies in the polar cone {μ‖y_t‖ ≤ −y_n} and y ⊥ r.
            let y = rs - r;
            assert!(mu * y[0].hypot(y[1]) + y[2] <= tol, "polar {rs:?} μ={mu}");
            assert!(
                y.dot(&r).abs() <= 1e-12 * s * s,
                "orthogonality {rs:?} μ={mu}"
            );
            // Nearest point: no random point of the cone is closer.
            let d = y.norm();
            for _ in 0..4 {
                let kn = mag * rng.uniform(0.0, 2.0);
                let ang = rng.uniform(0.0, 2.0 * PI);
                let kt = mu * kn * rng.uniform(0.0, 1.0);
                let k = v3(kt * ang.cos(), kt * ang.sin(), kn);
                assert!((rs - k).norm() >= d - tol);
            }
        }
        assert!(hits.iter().all(|&h| h > 1000), "all cases hit: {hits:?}");
    }

    #[test]
    fn bipotential_trial_by_hand() {
        // r* = r̄ − ρ (x + μ‖x_t‖ n): ‖x_t‖ = 5e-3, μ‖x_t‖ = 2.5e-3.
        let r = bipotential_trial(v3(1.0, 2.0, 3.0), v3(3e-3, -4e-3, 1e-3), 0.5, 100.0);
        assert_vec_close(r, v3(0.7, 2.4, 3.0 - 0.35), 1e-15);
    }
}
