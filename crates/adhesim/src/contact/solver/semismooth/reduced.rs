//! Semismooth (generalised) Newton method for the reduced dry contact problem x = q + W r of
//! [`crate::contact::solver::reduced`], on the bi-potential natural map (an Alart–Curnier-type
//! method written with De Saxcé's modified relative displacement instead of the augmented
//! Lagrangian):
//!
//! F_α(r) = r_α − P_K(r_α − ρ_α (x_α + μ_α‖x_α,t‖ n)),   x = q + W r,
//!
//! with ρ_α = 3/λ_max(W_αα) ([`RHO_FACTOR`]). F = 0 is the Signorini–Coulomb law at every point. F is
//! piecewise smooth; an element of its generalised Jacobian is, block by block,
//!
//! ∂F_α/∂r_β = δ_αβ (I − P'_α) + ρ_α P'_α D_α W_αβ,
//!
//! where P'_α = [`projection_jacobian`] at the trial force and D_α = ∂(x + μ‖x_t‖n)/∂x
//! = I + μ n (x_t/‖x_t‖, 0)ᵀ (the second term dropped at ‖x_t‖ = 0). The Newton system has the
//! sparsity of W in 3×3 blocks and is solved by a sparse LU factorisation.
//!
//! Regularisation: W is singular whenever there are more contact components than degrees of
//! freedom (rigid bodies with many contacts), and so is J where such contacts stick. The
//! Newton matrix therefore uses W + ηI (a proximal, Levenberg–Marquardt-like term), with
//! η = λ̄ · min(η_rel, e): λ̄ the mean of 1/ρ_α, e the current relative error, and η_rel
//! divided by 10 after a full step, multiplied by 10 after a shortened or failed one (within
//! [10⁻¹², 1]). As e → 0 the step tends to the plain semismooth Newton step.
//!
//! Globalisation: a backtracking (Armijo) line search on θ = ½‖F‖²; for the unregularised
//! direction (J d = −F) θ'(r; d) = −2θ, and a step t is accepted when
//! θ(r + t d) ≤ (1 − 2σt) θ(r), σ = 10⁻⁴. When the system is singular, its solution is not
//! finite, or no step down to 2⁻²⁰ is accepted, a nonlinear Gauss–Seidel sweep
//! ([`gauss_seidel_sweep`]) is taken instead and Newton resumes from there.
//!
//! The iteration stops on Siconos's relative error
//! ([`crate::contact::solver::natural_map`]), ρ = 1.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{Argsort, Pair, SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Spec};

use crate::linalg::faer_call;

use crate::contact::cone::{
    bipotential_trial, dry_projection, modified_displacement_jacobian, projection_jacobian,
};
use crate::contact::solver::gauss_seidel::reduced::{gauss_seidel_sweep, point_rhos};
use crate::contact::solver::natural_map::{
    natural_map_point, natural_map_residual, relative_error,
};
use crate::contact::solver::reduced::{BlockSparseDelassus, ReducedSolution};

type M3 = [[f64; 3]; 3];

/// ρ_α of the natural map as a multiple of 1/λ_max(W_αα). On the fclib problems 3 converged
/// on all five (1 stalls on spheres-in-a-box near 2e-6; 10 stalls on Capsules near 1e-6).
const RHO_FACTOR: f64 = 3.0;
/// Armijo constant σ of the line search.
pub(super) const ARMIJO: f64 = 1e-4;
/// Regularisation η of the Newton matrix, relative to the mean of 1/ρ_α: its start,
/// bounds, and the factors applied after a full step and after a shortened or failed one.
pub(super) const ETA_START: f64 = 1e-2;
pub(super) const ETA_MIN: f64 = 1e-12;
pub(super) const ETA_MAX: f64 = 1.0;
pub(super) const ETA_DOWN: f64 = 0.1;
pub(super) const ETA_UP: f64 = 10.0;
/// Largest Newton matrix (rows) factorised as a dense matrix rather than a sparse one.
const DENSE_MAX: usize = 48;
/// Smallest step length tried before a Gauss–Seidel sweep is taken instead.
const MIN_STEP: f64 = 1.0 / (1u64 << 20) as f64;

/// Counts of what [`semismooth_newton`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NewtonCounts {
    /// Newton steps accepted by the line search.
    pub newton_steps: usize,
    /// Gauss–Seidel sweeps taken instead of a failed Newton step.
    pub fallback_sweeps: usize,
}

/// F(r) with ρ per point into `f`, and x = q + W r into `x`; returns θ = ½‖F‖².
fn natural_map_rho(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    rho: &[f64],
    r: &[[f64; 3]],
    x: &mut [[f64; 3]],
    f: &mut [[f64; 3]],
) -> f64 {
    w.apply(r, q, x);
    let mut theta = 0.0;
    for p in 0..r.len() {
        f[p] = natural_map_point(r[p], x[p], mu[p], rho[p]);
        for a in 0..3 {
            theta += 0.5 * f[p][a] * f[p][a];
        }
    }
    theta
}

/// The Newton matrix's sparsity (that of W in 3×3 blocks, the same at every iteration), the
/// order its values are listed in, its symbolic LU factorisation (supernodal: the simplicial
/// one spent 83 % of the time on spheres-in-a-box) and the numeric factors' storage: set up
/// once per solve.
struct JacobianPattern {
    symbolic: SymbolicSparseColMat<usize>,
    order: Argsort<usize>,
    lu: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    mem: MemBuffer,
}

impl JacobianPattern {
    /// The analysis of the pattern of the listed `entries` of an `n` × `n` matrix.
    fn new(n: usize, entries: &[Pair<usize, usize>]) -> Option<Self> {
        let (symbolic, order) = SymbolicSparseColMat::try_new_from_indices(n, n, entries).ok()?;
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let lu = factorize_symbolic_lu(symbolic.as_ref(), params).ok()?;
        let req = StackReq::any_of(&[
            lu.factorize_numeric_lu_scratch::<f64>(Par::Seq, Spec::default()),
            lu.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Some(JacobianPattern {
            symbolic,
            order,
            lu,
            numeric: NumericLu::new(),
            mem: MemBuffer::try_new(req).ok()?,
        })
    }

    /// Solves J d = `rhs` in place for J with `entries_values` listed in the analysed order;
    /// false if the factorisation fails.
    fn solve(&mut self, entries_values: &[f64], rhs: &mut [f64]) -> bool {
        let Ok(jac) =
            SparseColMat::new_from_argsort(self.symbolic.clone(), &self.order, entries_values)
        else {
            return false;
        };
        let a: SparseColMatRef<'_, usize, f64> = jac.as_ref();
        faer_call(Par::Seq, || {
            let stack = MemStack::new(&mut self.mem);
            let Ok(lu) = self.lu.factorize_numeric_lu(
                &mut self.numeric,
                a,
                Par::Seq,
                stack,
                Spec::default(),
            ) else {
                return false;
            };
            let n = rhs.len();
            let stack = MemStack::new(&mut self.mem);
            lu.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(rhs, n, 1),
                Par::Seq,
                stack,
            );
            true
        })
    }
}

/// The Newton direction d with J d = −F at (r, x), or `None` if the factorisation fails or d
/// is not finite. J is factorised as a dense matrix when `dense`, else as a sparse one whose
/// symbolic analysis `pattern` holds (made on first use).
#[allow(clippy::too_many_arguments)]
fn newton_direction(
    w: &BlockSparseDelassus,
    mu: &[f64],
    rho: &[f64],
    r: &[[f64; 3]],
    x: &[[f64; 3]],
    f: &[[f64; 3]],
    eta: f64,
    dense: bool,
    pattern: &mut Option<JacobianPattern>,
) -> Option<Vec<f64>> {
    let n = w.points();
    let mut entries: Vec<Pair<usize, usize>> = Vec::with_capacity(9 * w.block_count());
    let mut values: Vec<f64> = Vec::with_capacity(9 * w.block_count());
    for p in 0..n {
        let mu_p = mu[p].max(0.0);
        let r_star = bipotential_trial(r[p].into(), x[p].into(), mu_p, rho[p]);
        let (_, case) = dry_projection(r_star, mu_p);
        let jp = projection_jacobian(r_star, mu_p, case);
        let d = modified_displacement_jacobian(x[p].into(), mu_p);
        // ρ P' D.
        let mut pd: M3 = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                pd[a][b] = rho[p] * (0..3).map(|k| jp[(a, k)] * d[(k, b)]).sum::<f64>();
            }
        }
        for (j, wb) in w.row(p) {
            for a in 0..3 {
                for b in 0..3 {
                    let mut v: f64 = (0..3).map(|k| pd[a][k] * wb[k][b]).sum();
                    if j == p {
                        v += if a == b { 1.0 } else { 0.0 } - jp[(a, b)] + eta * pd[a][b];
                    }
                    entries.push(Pair::new(3 * p + a, 3 * j + b));
                    values.push(v);
                }
            }
        }
    }
    let mut d: Vec<f64> = (0..3 * n).map(|i| -f[i / 3][i % 3]).collect();
    if dense {
        let mut jac = faer::Mat::<f64>::zeros(3 * n, 3 * n);
        for (e, v) in entries.iter().zip(&values) {
            jac[(e.row, e.col)] += v;
        }
        faer_call(Par::Seq, || {
            jac.partial_piv_lu()
                .solve_in_place(MatMut::from_column_major_slice_mut(&mut d, 3 * n, 1))
        });
    } else {
        if pattern.is_none() {
            *pattern = JacobianPattern::new(3 * n, &entries);
        }
        if !pattern.as_mut()?.solve(&values, &mut d) {
            return None;
        }
    }
    d.iter().all(|v| v.is_finite()).then_some(d)
}

/// Semismooth Newton from `r_start` until Siconos's relative error is ≤ `tol` or `max_iter`
/// iterations (Newton steps plus fallback sweeps). See the module documentation.
///
/// # Panics
/// If `q`, `mu` or `r_start` do not have one entry per point.
pub fn semismooth_newton(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    r_start: &[[f64; 3]],
    tol: f64,
    max_iter: usize,
) -> (ReducedSolution, NewtonCounts) {
    newton_impl(w, q, mu, r_start, tol, max_iter, true)
}

/// [`semismooth_newton`], with the regularisation of the Newton matrix switched by `regularise`.
fn newton_impl(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    r_start: &[[f64; 3]],
    tol: f64,
    max_iter: usize,
    regularise: bool,
) -> (ReducedSolution, NewtonCounts) {
    let n = w.points();
    assert!(q.len() == n && mu.len() == n && r_start.len() == n);
    // The point solver of the fallback sweeps keeps its own safe ρ (< 2/λ_max).
    let rho_sweep = point_rhos(w);
    let rho: Vec<f64> = rho_sweep.iter().map(|r| RHO_FACTOR * r).collect();
    let eta_scale = if n > 0 && regularise {
        rho.iter().map(|r| 1.0 / r).sum::<f64>() / n as f64
    } else {
        0.0
    };
    let mut r = r_start.to_vec();
    let mut x = vec![[0.0; 3]; n];
    let mut f = vec![[0.0; 3]; n];
    let mut r_try = vec![[0.0; 3]; n];
    let mut x_try = vec![[0.0; 3]; n];
    let mut f_try = vec![[0.0; 3]; n];
    let mut counts = NewtonCounts::default();
    let mut iterations = 0;
    let mut eta_rel = ETA_START;
    // A few contacts: a dense LU costs less than setting up the sparse one.
    let dense = 3 * n <= DENSE_MAX;
    let mut pattern = None;
    let mut theta = natural_map_rho(w, q, mu, &rho, &r, &mut x, &mut f);
    loop {
        let residual = natural_map_residual(&r, &x, mu);
        let error = relative_error(residual, q, &r, &x);
        if error <= tol || iterations >= max_iter {
            let solution = ReducedSolution {
                r,
                x,
                iterations,
                residual,
                error,
                converged: error <= tol,
            };
            return (solution, counts);
        }
        iterations += 1;
        let mut accepted = false;
        let eta = eta_scale * eta_rel.min(error);
        if let Some(d) = newton_direction(w, mu, &rho, &r, &x, &f, eta, dense, &mut pattern) {
            let mut t = 1.0;
            while t >= MIN_STEP {
                for p in 0..n {
                    for a in 0..3 {
                        r_try[p][a] = r[p][a] + t * d[3 * p + a];
                    }
                }
                let theta_try = natural_map_rho(w, q, mu, &rho, &r_try, &mut x_try, &mut f_try);
                if theta_try <= (1.0 - 2.0 * ARMIJO * t) * theta {
                    std::mem::swap(&mut r, &mut r_try);
                    std::mem::swap(&mut x, &mut x_try);
                    std::mem::swap(&mut f, &mut f_try);
                    theta = theta_try;
                    accepted = true;
                    eta_rel = if t == 1.0 {
                        (eta_rel * ETA_DOWN).max(ETA_MIN)
                    } else {
                        (eta_rel * ETA_UP).min(ETA_MAX)
                    };
                    counts.newton_steps += 1;
                    break;
                }
                t *= 0.5;
            }
        }
        if !accepted {
            eta_rel = (eta_rel * ETA_UP).min(ETA_MAX);
            gauss_seidel_sweep(w, q, mu, &rho_sweep, &mut r);
            counts.fallback_sweeps += 1;
            theta = natural_map_rho(w, q, mu, &rho, &r, &mut x, &mut f);
        }
    }
}

/// Proximal-point iteration around [`semismooth_newton`]: from the current r_k, the problem
/// with W + ηI and q − η r_k (the same law, x = q + W r + η (r − r_k)) is solved by
/// [`semismooth_newton`] to `tol`, and r_k is replaced by its solution, until Siconos's error
/// of the original problem is ≤ `tol`. A fixed point r = r_k solves the original problem;
/// W + ηI is positive definite, so each inner problem is well posed even when W is singular.
/// η = λ̄ η_rel with λ̄ the mean of λ_max(W_αα); η_rel starts at 1, is divided by 10 after an
/// inner solve that converged in at most 10 iterations, and multiplied by 10 (up to 1) after
/// one that did not converge. `iterations` counts the inner iterations in total.
pub fn proximal_newton(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    r_start: &[[f64; 3]],
    tol: f64,
    max_iter: usize,
) -> (ReducedSolution, NewtonCounts) {
    let n = w.points();
    assert!(q.len() == n && mu.len() == n && r_start.len() == n);
    let rho = point_rhos(w);
    let lam = if n > 0 {
        rho.iter().map(|r| 1.0 / r).sum::<f64>() / n as f64
    } else {
        0.0
    };
    let mut r = r_start.to_vec();
    let mut x = vec![[0.0; 3]; n];
    let mut counts = NewtonCounts::default();
    let mut iterations = 0;
    let mut eta_rel: f64 = 1.0;
    loop {
        w.apply(&r, q, &mut x);
        let residual = natural_map_residual(&r, &x, mu);
        let error = relative_error(residual, q, &r, &x);
        if error <= tol || iterations >= max_iter {
            let solution = ReducedSolution {
                r,
                x,
                iterations,
                residual,
                error,
                converged: error <= tol,
            };
            return (solution, counts);
        }
        let eta = lam * eta_rel;
        let w_eta = w.with_diagonal_shift(eta);
        let q_eta: Vec<[f64; 3]> = q
            .iter()
            .zip(&r)
            .map(|(q, r)| std::array::from_fn(|a| q[a] - eta * r[a]))
            .collect();
        let budget = (max_iter - iterations).min(PROX_INNER);
        let inner_tol = tol.max(PROX_FORCING * error);
        let (inner, c) = newton_impl(&w_eta, &q_eta, mu, &r, inner_tol, budget, false);
        iterations += inner.iterations.max(1);
        counts.newton_steps += c.newton_steps;
        counts.fallback_sweeps += c.fallback_sweeps;
        eta_rel = if inner.converged && inner.iterations <= 10 {
            (eta_rel * 0.1).max(1e-12)
        } else if inner.converged {
            eta_rel
        } else {
            (eta_rel * 10.0).min(1.0)
        };
        r = inner.r;
    }
}

/// Inner tolerance of [`proximal_newton`] relative to the current error of the original
/// problem (never below the requested tolerance).
const PROX_FORCING: f64 = 0.1;
/// Largest number of iterations of one inner solve of [`proximal_newton`].
const PROX_INNER: usize = 50;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::solver::gauss_seidel::reduced::gauss_seidel_blocks;
    use crate::contact::solver::reduced::test_support::{random_spd, Lcg};

    fn problem(n: usize, seed: u64) -> (BlockSparseDelassus, Vec<[f64; 3]>) {
        let mut rng = Lcg(seed);
        let a = random_spd(&mut rng, 3 * n, 0.2);
        let mut rnd = || rng.next_centered();
        let q = (0..n).map(|_| [rnd(), rnd(), rnd() - 0.3]).collect();
        (BlockSparseDelassus::from_dense(n, &a), q)
    }

    /// Newton reaches 1e-12 on coupled problems with sticking, sliding and open points, and its
    /// forces agree with Gauss–Seidel's to 1e-8 (both converged to 1e-12 on a problem whose
    /// solution is unique: W positive definite and μ small).
    #[test]
    fn newton_matches_gauss_seidel() {
        for seed in 1..6 {
            let (w, q) = problem(8, seed);
            let mu = vec![0.3; 8];
            let r0 = vec![[0.0; 3]; 8];
            let (newton, counts) = semismooth_newton(&w, &q, &mu, &r0, 1e-12, 100);
            assert!(newton.converged, "seed {seed}: error {}", newton.error);
            assert!(counts.newton_steps > 0);
            let gs = gauss_seidel_blocks(&w, &q, &mu, &r0, 1e-12, 100_000);
            assert!(gs.converged);
            for (a, b) in newton.r.iter().zip(&gs.r) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() < 1e-8, "seed {seed}: {a:?} vs {b:?}");
                }
            }
        }
    }

    /// A singular W (rank 12 of 24: more contact components than degrees of freedom, as for
    /// rigid bodies) with mixed open and pressed points: the proximal iteration reaches 1e-10
    /// (the plain Newton matrix is singular wherever such points stick).
    #[test]
    fn proximal_newton_solves_singular_problem() {
        let n = 8;
        let m = 3 * n;
        let k = 12;
        let mut s = 5u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let b: Vec<f64> = (0..m * k).map(|_| rnd()).collect();
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] = (0..k).map(|l| b[i * k + l] * b[j * k + l]).sum::<f64>();
            }
        }
        let w = BlockSparseDelassus::from_dense(n, &a);
        let q: Vec<[f64; 3]> = (0..n)
            .map(|p| {
                [
                    0.1 * rnd(),
                    0.1 * rnd(),
                    if p % 3 == 0 { 0.2 } else { -0.5 },
                ]
            })
            .collect();
        let mu = vec![0.3; n];
        let (sol, _) = proximal_newton(&w, &q, &mu, &vec![[0.0; 3]; n], 1e-10, 2000);
        assert!(sol.converged, "error {}", sol.error);
        assert!(sol.r.iter().any(|r| r[2] > 0.0));
    }

    /// The generalised Jacobian agrees with central differences of F where F is smooth, through
    /// both the dense and the sparse factorisation.
    #[test]
    fn jacobian_matches_finite_differences() {
        let (w, q) = problem(3, 7);
        let mu = vec![0.4; 3];
        let rho = point_rhos(&w);
        let r: Vec<[f64; 3]> = vec![[0.05, -0.02, 0.3], [0.2, 0.1, 0.25], [0.0, 0.01, 0.02]];
        let mut x = vec![[0.0; 3]; 3];
        let mut f = vec![[0.0; 3]; 3];
        natural_map_rho(&w, &q, &mu, &rho, &r, &mut x, &mut f);
        // newton_direction solves J d = −F: with F replaced by the finite-difference column
        // J e_k (step 1e-7, truncation error ~1e-14), the solution must be d = −e_k (to 1e-6,
        // the rounding of the differences, 1e-16/1e-7, amplified by the conditioning of J).
        let h = 1e-7;
        for k in 0..9 {
            let mut rp = r.clone();
            let mut rm = r.clone();
            rp[k / 3][k % 3] += h;
            rm[k / 3][k % 3] -= h;
            let (mut xp, mut fp) = (vec![[0.0; 3]; 3], vec![[0.0; 3]; 3]);
            let (mut xm, mut fm) = (vec![[0.0; 3]; 3], vec![[0.0; 3]; 3]);
            natural_map_rho(&w, &q, &mu, &rho, &rp, &mut xp, &mut fp);
            natural_map_rho(&w, &q, &mu, &rho, &rm, &mut xm, &mut fm);
            let col: Vec<[f64; 3]> = (0..3)
                .map(|p| std::array::from_fn(|a| (fp[p][a] - fm[p][a]) / (2.0 * h)))
                .collect();
            // Both factorisations: dense (a few contacts) and sparse.
            for dense in [true, false] {
                let d = newton_direction(&w, &mu, &rho, &r, &x, &col, 0.0, dense, &mut None)
                    .expect("regular");
                for (i, v) in d.iter().enumerate() {
                    let expect = if i == k { -1.0 } else { 0.0 };
                    assert!(
                        (v - expect).abs() < 1e-6,
                        "dense {dense}, column {k}, entry {i}: {v}"
                    );
                }
            }
        }
    }
}
