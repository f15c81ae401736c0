//! When the Newton loop keeps its factorisation of K̄ (`time.newton = "modified"`,
//! docs/scaling.md).
//!
//! The loop solves each correction with K̄ for the Gauss-Seidel contact solve, the
//! augmented-Lagrangian one and steps without contact. Solved with the factor of an earlier
//! iteration, or of the last step with the same Δt and contact cases, the iteration is a
//! modified Newton one: its fixed point (G(u) = Hᵀr with the contact law holding) does not
//! depend on the matrix, only its rate does. For the Gauss-Seidel solve the Delassus
//! operator W and the completion K̄⁻¹Hᵀ(r − r_prev) then come from the same kept factor,
//! which the solve already allows for (W may be reused from an earlier iteration or step).
//! The augmented-Lagrangian solve adds the contact law's stiffness to K̄, which jumps where a
//! point opens, closes, sticks or slides: its cases are part of the key a kept factor must
//! match ([`super::coupling::ContactCoupling::tangent_key`]).
//!
//! The semismooth solve keeps nothing: it factorises K̄ + Σ HᵀS₊H for each of its directions,
//! where a sticking or closed point enters with the stiffness 1/η of a regularisation η that
//! falls tenfold from one direction to the next, and any point whose case changes moves that
//! stiffness by up to 10⁸ ρ. On the pad at 1,024 contact nodes a factorisation kept from the
//! last direction, as GMRES's preconditioner, left a relative residual of 10⁻³ to 1 after
//! 20 iterations in most directions, where a new one reaches 10⁻⁶ in 2 to 8 (docs/scaling.md).

use crate::linalg::KrylovLimits;
use crate::problem::NewtonMethod;

/// Largest contraction ‖G − Hᵀr‖ₖ / ‖G − Hᵀr‖ₖ₋₁ of the Newton loop for which its kept
/// factor also serves the next correction. An iteration on a kept factor costs the assembly,
/// the contact solve and one solve; at 0.25 it gains a decade of the residual in 1.7 such
/// iterations, where full Newton, near the solution, gains several decades in one
/// iteration that also pays for the factorisation. A kept factor that contracts less is
/// replaced.
pub const NEWTON_CONTRACTION: f64 = 0.25;

/// Whether the Newton loop solves its next correction with the factor it has, under
/// `method`: the factor's key (None: no factor of the loop's own) must equal `key` (what the
/// matrix would now be built from, [`matrix_key`]), and the out-of-balance force must have
/// shrunk by [`NEWTON_CONTRACTION`] from the last corrected iterate's, `last_norm`, to `norm`
/// [N] (no last iterate in the attempt: the factor comes from the last step and is tried
/// once).
pub fn keep_for_correction(
    method: NewtonMethod,
    factor_key: Option<u64>,
    key: u64,
    last_norm: Option<f64>,
    norm: f64,
) -> bool {
    method == NewtonMethod::Modified
        && factor_key == Some(key)
        && last_norm.is_none_or(|last| norm <= NEWTON_CONTRACTION * last)
}

/// When GMRES stops on a correction under `time.newton = "preconditioned"`: at 10⁻³ of the
/// out-of-balance force it is given, or after 40 iterations, when K̄ is factorised afresh
/// instead. An inexact Newton correction to 10⁻³ keeps the iterations' rate well below the
/// factor 4 modified Newton accepts; on the frictionless pad at 10⁴ contact nodes, 10⁻³ took
/// 25 Newton iterations and 46 GMRES iterations, 10⁻⁴ 25 and 55, 10⁻⁶ 22 and 66, and 10⁻³
/// ran in 0.90 of 10⁻⁶'s wall time (docs/scaling.md).
pub const KRYLOV_CORRECTION: KrylovLimits = KrylovLimits {
    tol: 1e-3,
    max_iter: 40,
    restart: 40,
};

/// GMRES iterations of a correction above which the next correction factorises K̄ afresh:
/// the kept factor has drifted from K̄ (large strains, contact cases changed) and each
/// further iteration costs two triangular solves and a product with K̄.
pub const KRYLOV_REFRESH: usize = 12;

/// Whether a preconditioned correction may use the factorisation in use: one the Newton loop
/// made (`factor_key` is Some; the semismooth solve's factorisations, with its contact
/// blocks, are not kept) and not flagged for a `refresh`. Unlike [`keep_for_correction`],
/// neither Δt nor the contact cases need to match: GMRES solves with the iterate's own K̄, and
/// a factor that no longer fits shows as GMRES failing or slowing down.
pub fn keep_as_preconditioner(factor_key: Option<u64>, refresh: bool) -> bool {
    factor_key.is_some() && !refresh
}

/// The key of what K̄ is built from besides the iterate: the step size `dt` [s] (K̄'s mass
/// and damping terms) and the contact coupling's own key `coupling` (its cases), hashed.
pub fn matrix_key(dt: f64, coupling: u64) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    dt.to_bits().hash(&mut h);
    coupling.hash(&mut h);
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_newton_never_keeps_a_factor() {
        let k = matrix_key(0.1, 0);
        assert!(!keep_for_correction(
            NewtonMethod::Full,
            Some(k),
            k,
            None,
            0.0
        ));
        assert!(!keep_for_correction(
            NewtonMethod::Full,
            Some(k),
            k,
            Some(1.0),
            1e-9
        ));
    }

    #[test]
    fn modified_newton_keeps_a_fitting_factor_while_it_contracts() {
        let k = matrix_key(0.1, 7);
        let m = NewtonMethod::Modified;
        assert!(keep_for_correction(m, Some(k), k, None, 5.0));
        assert!(keep_for_correction(m, Some(k), k, Some(1.0), 0.25));
        assert!(!keep_for_correction(m, Some(k), k, Some(1.0), 0.26));
        assert!(!keep_for_correction(m, None, k, Some(1.0), 0.1));
        assert!(!keep_for_correction(
            m,
            Some(matrix_key(0.05, 7)),
            k,
            Some(1.0),
            0.1
        ));
        assert!(!keep_for_correction(
            m,
            Some(matrix_key(0.1, 8)),
            k,
            Some(1.0),
            0.1
        ));
    }
}
