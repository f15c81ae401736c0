//! The contact problem of a Newton iteration solved without the Delassus operator: a
//! semismooth Newton method on the contact forces whose directions solve the mixed system in
//! (displacement, force) (docs/contact-solver.md).
//!
//! Within a Newton iteration of the step, K̄ is fixed and the local relative displacements are
//! affine in the contact forces r (total, local frames):
//!
//!   K̄ δu = Hᵀ (r − r₀),   x = x₀ + H δu   (so x = x₀ + W (r − r₀), W = H K̄⁻¹ Hᵀ never formed),
//!
//! and each point's law is written as the bi-potential natural map of its dry part
//! y = r − r̃(x) (r̃ the RCC adhesive force, smooth given β₁(x)):
//!
//!   Φ_α(r_α, x_α) = y − P_K(y − ρ_α (x + μ‖x_t‖n)) = 0.
//!
//! A generalised Jacobian of Φ_α is dΦ = A_α dr + B_α dx with A = I − P' and
//! B = A k̃ + ρ P' D ([`linearise_point`]). The semismooth Newton direction d of the reduced
//! problem, (A + B W) d = −Φ, is the force part of the solution of
//!
//!   ⎡ K̄    −Hᵀ  ⎤ ⎡ δu ⎤   ⎡ 0 ⎤
//!   ⎣ B H   A + ηB⎦ ⎣ d  ⎦ = ⎣ −Φ⎦,
//!
//! whose δu part gives x's change along d, H δu = W d, so that the line search on
//! θ = ½‖Φ‖² evaluates trial points without any further solve. [`solve_mixed`] takes the
//! directions from a [`MixedDirection`]: [`LuDirection`] factorises the whole matrix by sparse
//! LU; the time stepper eliminates the forces point by point and solves the rest with its
//! sparse Cholesky factorisation and GMRES (`super::coupling`). ηB is a proximal
//! regularisation (x + η r in place of x), which keeps the matrix regular when sticking points
//! are more than the unknowns can satisfy, and vanishes as the residual does.

use faer::sparse::{Pair, SymbolicSparseColMat};

use super::reduced::{ARMIJO, ETA_DOWN, ETA_MAX, ETA_MIN, ETA_START, ETA_UP};
use crate::contact::anisotropic::{scale, unscale};
use crate::contact::cone::{
    bipotential_trial, dry_projection, jacobian_case, modified_displacement_jacobian,
    projection_jacobian,
};
use crate::contact::history::PointHistory;
use crate::contact::interface::{Interface, PointSolution};
use crate::contact::law::InterfaceLaw;
use crate::linalg::{metis_dof_ordering, BlockPattern};
use crate::sparse_lu::OrderedLu;
use crate::{Mat3, Vec3};

type V3 = [f64; 3];

/// How [`solve_mixed`] shortens its steps and lowers its regularisation (the Armijo constant
/// and η's bounds and factors, relative to the mean 1/ρ, are those of [`super::reduced`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MixedSchedule {
    /// Shortest step length the line search tries.
    pub min_step: f64,
    /// Whether the caller's measure is relative (dimensionless). Then η's level is at most
    /// the measure, as in [`super::reduced::semismooth_newton`]; otherwise at most ‖Φ‖
    /// relative to the forces' norm.
    pub relative_measure: bool,
}

/// The time stepper's schedule: its measure is a force [N].
pub const STEPPER_SCHEDULE: MixedSchedule = MixedSchedule {
    min_step: 1.0 / 1024.0,
    relative_measure: false,
};

/// The schedule of a relative measure, with the reduced method's shortest step: on the
/// degenerate problems of rigid bodies with more contacts than freedoms (fclib's
/// spheres-in-a-box) the line search needs steps down to 2⁻²⁰ and η that follows the error.
pub const RELATIVE_SCHEDULE: MixedSchedule = MixedSchedule {
    min_step: 1.0 / (1u64 << 20) as f64,
    relative_measure: true,
};

/// Relative round-off of the natural map: the solve stops once the measure is below this
/// fraction of the forces' norm, whatever the tolerance asked.
const ROUND_OFF: f64 = 1e-13;

/// The natural map of one point linearised at (r, x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLinearisation {
    /// Φ = y − P_K(y − ρ x̂) [N] with y = r − r̃(x).
    pub phi: V3,
    /// ∂Φ/∂r [-].
    pub a: Mat3,
    /// ∂Φ/∂x [N/m] (with the adhesive stiffness at fixed β₁).
    pub b: Mat3,
    /// B without the change of x̂'s normal component with the slip (D = I): what makes B
    /// unsymmetric for a sliding point [N/m].
    pub b_plain: Mat3,
    /// The point's forces, the history the step leads to and case at (r, x).
    pub solution: PointSolution,
}

/// [`PointLinearisation`] of the law `law` at total force `r` [N] and local relative
/// displacement `x` [m], for a point whose law's history is frozen at `history0`, step `dt`
/// [s], tributary area `area` [m²] and natural-map parameter `rho` [N/m]. An orthotropic law
/// is linearised in its scaled variables (y' = T⁻¹y, x' = Tx) and mapped back: Φ = TΦ',
/// A = T A' T⁻¹, B_dry = T B' T.
pub fn linearise_point(
    law: &InterfaceLaw,
    history0: PointHistory,
    dt: f64,
    area: f64,
    rho: f64,
    r: V3,
    x: V3,
) -> PointLinearisation {
    let mu = law.mu.max(0.0);
    let (r, x) = (Vec3::from(r), Vec3::from(x));
    let (r_adh, k_adh, history) = match law.adhesive_response(&history0, dt, area, x) {
        Some(resp) => (resp.force, resp.secant_stiffness, resp.history),
        None => (Vec3::zeros(), Mat3::zeros(), PointHistory::default()),
    };
    let y = r - r_adh;
    let s = law.tangent_scale();
    let (ys, xs) = (unscale(y, s), scale(x, s));
    let r_star = bipotential_trial(ys, xs, mu, rho);
    let (proj, state) = dry_projection(r_star, mu);
    let pj = projection_jacobian(r_star, mu, jacobian_case(r_star, mu, state));
    let d = modified_displacement_jacobian(xs, mu);
    let t = Mat3::from_diagonal(&scale(Vec3::repeat(1.0), s));
    let t_inv = Mat3::from_diagonal(&unscale(Vec3::repeat(1.0), s));
    let a = t * (Mat3::identity() - pj) * t_inv;
    let b = a * k_adh + t * (rho * pj * d) * t;
    let b_plain = a * k_adh + t * (rho * pj) * t;
    let phi = scale(ys - proj, s).into();
    PointLinearisation {
        phi,
        a,
        b,
        b_plain,
        solution: PointSolution {
            r_dry: y,
            r_adh,
            x,
            history,
            state,
            iterations: 1,
            converged: true,
        },
    }
}

/// H_α v for a point whose H is listed as (unknown, coefficients of the three local
/// components).
pub fn apply_h_terms(h: &[(usize, V3)], v: &[f64]) -> V3 {
    let mut out = [0.0; 3];
    for &(i, c) in h {
        for k in 0..3 {
            out[k] += c[k] * v[i];
        }
    }
    out
}

/// Adds H_αᵀ f to `out`, H_α listed as in [`apply_h_terms`].
pub fn add_ht_terms(h: &[(usize, V3)], f: V3, out: &mut [f64]) {
    for &(i, c) in h {
        out[i] += c[0] * f[0] + c[1] * f[1] + c[2] * f[2];
    }
}

/// K̄ (symmetric, upper triangle in compressed columns) and H of the mixed system.
pub struct MixedOperator<'a> {
    /// Column pointers of K̄'s upper triangle (n + 1).
    pub col_ptr: &'a [usize],
    /// Row indices of K̄'s upper triangle.
    pub row_idx: &'a [usize],
    /// Values of K̄'s upper triangle [N/m].
    pub values: &'a [f64],
    /// H of each point: the unknowns it reads with the coefficients of its three local
    /// components (x_α = Σ h u_i), each unknown listed once.
    pub h: &'a [Vec<(usize, V3)>],
}

impl MixedOperator<'_> {
    fn n(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// H_α v for point `p`.
    pub fn apply_h(&self, p: usize, v: &[f64]) -> V3 {
        apply_h_terms(&self.h[p], v)
    }

    /// The mixed matrix's entries in a fixed order (K̄, then point by point −Hᵀ, B H and
    /// A + ηB), with their values for the linearisations `lin` and regularisation `eta` [m/N].
    fn entries(&self, lin: &[PointLinearisation], eta: f64) -> (Vec<Pair<usize, usize>>, Vec<f64>) {
        let n = self.n();
        let h_count: usize = self.h.iter().map(|h| h.len()).sum();
        let cap = 2 * self.values.len() + 6 * h_count + 9 * self.h.len();
        let mut entries = Vec::with_capacity(cap);
        let mut values = Vec::with_capacity(cap);
        for j in 0..n {
            for q in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[q];
                entries.push(Pair::new(i, j));
                values.push(self.values[q]);
                if i != j {
                    entries.push(Pair::new(j, i));
                    values.push(self.values[q]);
                }
            }
        }
        for (p, (h, l)) in self.h.iter().zip(lin).enumerate() {
            let row = n + 3 * p;
            for &(i, c) in h {
                let bh = l.b * nalgebra::Vector3::from(c);
                for k in 0..3 {
                    entries.push(Pair::new(i, row + k));
                    values.push(-c[k]);
                    entries.push(Pair::new(row + k, i));
                    values.push(bh[k]);
                }
            }
            let diag = l.a + eta * l.b;
            for a in 0..3 {
                for b in 0..3 {
                    entries.push(Pair::new(row + a, row + b));
                    values.push(diag[(a, b)]);
                }
            }
        }
        (entries, values)
    }
}

/// The mixed matrix's pattern, the order its entries are listed in and its LU analysis
/// (columns in METIS nested-dissection order of the node graph, each contact point a node
/// joined to the nodes it reads), made once and reused while the pattern stays.
pub struct MixedPattern {
    entries: Vec<Pair<usize, usize>>,
    /// Position of each listed entry among the compressed columns' values (repeated entries
    /// share one).
    slot: Vec<usize>,
    /// The compressed columns' values, summed from the entries.
    values: Vec<f64>,
    lu: OrderedLu,
}

impl MixedPattern {
    fn new(op: &MixedOperator, entries: Vec<Pair<usize, usize>>) -> Result<Self, String> {
        let fail = |e: &dyn std::fmt::Debug| format!("mixed contact matrix analysis: {e:?}");
        let (n, m) = (op.n(), op.h.len());
        let dim = n + 3 * m;
        let (symbolic, _) =
            SymbolicSparseColMat::try_new_from_indices(dim, dim, &entries).map_err(|e| fail(&e))?;
        let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
        let slot = entries
            .iter()
            .map(|e| {
                let start = col_ptr[e.col];
                let rows = &row_idx[start..col_ptr[e.col + 1]];
                start + rows.binary_search(&e.row).expect("entry in its column")
            })
            .collect();
        let nodes = n / 3;
        let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); nodes + m];
        for j in 0..n {
            for &i in &op.row_idx[op.col_ptr[j]..op.col_ptr[j + 1]] {
                nbrs[j / 3].push(i / 3);
            }
        }
        for (p, h) in op.h.iter().enumerate() {
            nbrs[nodes + p].extend(h.iter().map(|&(i, _)| i / 3));
        }
        for (b, list) in nbrs.iter_mut().enumerate() {
            list.push(b);
            list.sort_unstable();
            list.dedup();
        }
        let graph = BlockPattern::from_neighbours(nodes + m, nbrs);
        let (fwd, inv) = metis_dof_ordering(&graph).map_err(|e| fail(&e))?;
        let values = vec![0.0; row_idx.len()];
        let lu = OrderedLu::analyse(col_ptr.to_vec(), row_idx.to_vec(), fwd, inv)
            .map_err(|e| fail(&e))?;
        Ok(MixedPattern {
            entries,
            slot,
            values,
            lu,
        })
    }

    /// Solves the matrix with `values` (in the analysed order) against `rhs` in place; false
    /// if the factorisation fails or the solution is not finite.
    fn solve(&mut self, values: &[f64], rhs: &mut [f64]) -> bool {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (&q, v) in self.slot.iter().zip(values) {
            self.values[q] += v;
        }
        if self.lu.factorise(&self.values).is_err() {
            return false;
        }
        self.lu.solve_in_place(rhs);
        rhs.iter().all(|v| v.is_finite())
    }
}

/// What [`solve_mixed`] keeps between calls: the LU analysis (redone when the entries
/// differ) and the regularisation's current level.
pub struct MixedWorkspace {
    /// The LU analysis of the mixed matrix (when the LU computes the directions).
    pub pattern: Option<MixedPattern>,
    /// The regularisation's level η / mean(1/ρ).
    pub eta_rel: f64,
}

impl Default for MixedWorkspace {
    fn default() -> Self {
        MixedWorkspace {
            pattern: None,
            eta_rel: ETA_START,
        }
    }
}

impl MixedWorkspace {
    /// Resets the regularisation to its starting level (at the start of a step, so that a
    /// step's iterates depend only on the step's data and a resumed run repeats them).
    pub fn start_step(&mut self) {
        self.eta_rel = ETA_START;
    }
}

/// What [`solve_mixed`] found.
#[derive(Clone, Debug)]
pub struct MixedSolution {
    /// Total contact force of each point (local frame) [N].
    pub r: Vec<V3>,
    /// Each point's law at the solution.
    pub points: Vec<PointSolution>,
    /// Change of the unknowns δu = K̄⁻¹(Hᵀ(r − r₀) + m) [m], m the direction's out-of-balance
    /// force ([`MixedDirection::momentum`]; zero for most).
    pub du: Vec<f64>,
    /// The caller's measure of the residual at the end [N].
    pub residual: f64,
    /// Newton steps taken (each one LU factorisation).
    pub iterations: usize,
    /// Whether the measure is ≤ the tolerance.
    pub converged: bool,
}

/// A semismooth Newton direction of the mixed system: the displacement part δu, the force
/// part d and x's change along it, H δu (= W d).
pub struct Direction {
    /// δu [m] on the unknowns of the system.
    pub du: Vec<f64>,
    /// d [N] per point, local frames.
    pub d: Vec<V3>,
    /// H δu [m] per point.
    pub x: Vec<V3>,
}

/// A way of computing the direction of the mixed system for the points' linearisations.
pub trait MixedDirection {
    /// Number of unknowns of the displacement part.
    fn unknowns(&self) -> usize;
    /// Smallest regularisation η, relative to the mean 1/ρ, this way can work with.
    fn eta_floor(&self) -> f64 {
        ETA_MIN
    }
    /// The out-of-balance force m the directions also remove, on the unknowns [N] (empty
    /// when the displacement part has no right-hand side of its own).
    fn momentum(&self) -> &[f64] {
        &[]
    }
    /// The direction for the linearisations `lin` with regularisation `eta` [m/N], of the
    /// mixed system whose displacement part has the right-hand side `momentum` m; `None` when
    /// it cannot be computed (a singular matrix, values that are not finite).
    fn direction(
        &mut self,
        lin: &[PointLinearisation],
        eta: f64,
        momentum: f64,
    ) -> Result<Option<Direction>, String>;
}

/// The direction from a sparse LU factorisation of the whole mixed matrix.
pub struct LuDirection<'a, 'b> {
    /// K̄ and H.
    pub op: &'a MixedOperator<'b>,
    /// The LU analysis, redone when the entries differ.
    pub pattern: &'a mut Option<MixedPattern>,
    /// The out-of-balance force m on the unknowns [N] (empty: none).
    pub momentum: &'a [f64],
}

impl MixedDirection for LuDirection<'_, '_> {
    fn unknowns(&self) -> usize {
        self.op.n()
    }

    fn momentum(&self) -> &[f64] {
        self.momentum
    }

    fn direction(
        &mut self,
        lin: &[PointLinearisation],
        eta: f64,
        momentum: f64,
    ) -> Result<Option<Direction>, String> {
        let (n, m) = (self.op.n(), lin.len());
        let (entries, values) = self.op.entries(lin, eta);
        if self.pattern.as_ref().is_none_or(|pt| pt.entries != entries) {
            *self.pattern = Some(MixedPattern::new(self.op, entries)?);
        }
        let mut sol = vec![0.0; n + 3 * m];
        for (v, f) in sol.iter_mut().zip(self.momentum) {
            *v = momentum * f;
        }
        for (p, l) in lin.iter().enumerate() {
            for k in 0..3 {
                sol[n + 3 * p + k] = -l.phi[k];
            }
        }
        let pattern = self.pattern.as_mut().expect("set above");
        if !pattern.solve(&values, &mut sol) {
            return Ok(None);
        }
        let d = (0..m)
            .map(|p| std::array::from_fn(|k| sol[n + 3 * p + k]))
            .collect();
        sol.truncate(n);
        let x = (0..m).map(|p| self.op.apply_h(p, &sol)).collect();
        Ok(Some(Direction { du: sol, d, x }))
    }
}

/// Semismooth Newton on the contact forces from `r0` (where the local displacements are `x0`
/// [m]) until `measure` of the points' solutions is ≤ `tol` [N] or `max_iter` steps, with
/// directions from `dir`; `law(p, r, x)` linearises point p's law with its natural-map
/// parameter `rho[p]` [N/m]. `measure` is the caller's residual (e.g. the natural map with
/// another ρ; Φ's norm with these ρ is the merit of the line search). A direction whose
/// displacement part has an out-of-balance force m of its own removes it as well: what is
/// left of it, s m with s = Π(1 − t) over the steps t taken, adds ½ (s ‖m‖)² to the merit and
/// must be ≤ `tol` too. `schedule` says how steps are shortened and η lowered; `eta_rel`
/// carries the regularisation level from call to call.
#[allow(clippy::too_many_arguments)]
pub fn solve_mixed(
    dir: &mut impl MixedDirection,
    law: impl Fn(usize, V3, V3) -> PointLinearisation,
    measure: impl Fn(&[PointSolution]) -> f64,
    rho: &[f64],
    r0: &[V3],
    x0: &[V3],
    tol: f64,
    max_iter: usize,
    schedule: MixedSchedule,
    eta_rel: &mut f64,
) -> Result<MixedSolution, String> {
    let (n, m) = (dir.unknowns(), r0.len());
    let eval = |r: &[V3], x: &[V3]| -> (Vec<PointLinearisation>, f64) {
        let lin: Vec<_> = (0..m).map(|p| law(p, r[p], x[p])).collect();
        let theta = lin.iter().flat_map(|l| l.phi).map(|v| 0.5 * v * v).sum();
        (lin, theta)
    };
    // η in units of compliance: 1/ρ on average.
    let eta_scale = if m > 0 {
        rho.iter().map(|r| 1.0 / r).sum::<f64>() / m as f64
    } else {
        0.0
    };
    let (mut r, mut x) = (r0.to_vec(), x0.to_vec());
    let mut du = vec![0.0; n];
    let (mut lin, mut theta) = eval(&r, &x);
    let (mut iterations, mut stalled, mut failed) = (0, false, false);
    // The part of the out-of-balance force m still to remove: s m, with s = Π(1 − t) over
    // the steps t taken. It enters the merit as ½ (s ‖m‖)².
    let m_norm = crate::linalg::norm(dir.momentum());
    let mut s = 1.0;
    loop {
        let points: Vec<PointSolution> = lin.iter().map(|l| l.solution).collect();
        let measured = measure(&points);
        // Round-off of the forces bounds the measure from below: a step whose force scale
        // is still zero (nothing loaded yet) cannot ask for less.
        let force = r.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
        let floor = ROUND_OFF * force;
        let converged = measured <= tol.max(floor) && s * m_norm <= tol.max(floor);
        if converged || iterations >= max_iter || stalled {
            return Ok(MixedSolution {
                r,
                points,
                du,
                residual: measured,
                iterations,
                converged,
            });
        }
        let residual = (2.0 * theta).sqrt();
        let momentum_merit = |s: f64| 0.5 * (s * m_norm).powi(2);
        iterations += 1;
        // The regularisation vanishes with the residual relative to the forces, unless the
        // last step failed (then it is raised).
        let level = if failed {
            *eta_rel
        } else {
            eta_rel.min(if schedule.relative_measure {
                measured
            } else {
                residual / (force + residual)
            })
        };
        let level = level.max(dir.eta_floor());
        let mut accepted = false;
        if let Some(step) = dir.direction(&lin, eta_scale * level, s)? {
            let mut t = 1.0;
            while t >= schedule.min_step {
                let r_try: Vec<V3> = (0..m)
                    .map(|p| std::array::from_fn(|k| r[p][k] + t * step.d[p][k]))
                    .collect();
                let x_try: Vec<V3> = (0..m)
                    .map(|p| std::array::from_fn(|k| x[p][k] + t * step.x[p][k]))
                    .collect();
                let (lin_try, theta_try) = eval(&r_try, &x_try);
                let merit = theta + momentum_merit(s);
                if theta_try + momentum_merit((1.0 - t) * s) <= (1.0 - 2.0 * ARMIJO * t) * merit {
                    (r, x, lin, theta) = (r_try, x_try, lin_try, theta_try);
                    s *= 1.0 - t;
                    for (u, dd) in du.iter_mut().zip(&step.du) {
                        *u += t * dd;
                    }
                    *eta_rel = if t == 1.0 {
                        (*eta_rel * ETA_DOWN).max(ETA_MIN)
                    } else {
                        (*eta_rel * ETA_UP).min(ETA_MAX)
                    };
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
        }
        failed = !accepted;
        if failed {
            // A failed step at the largest η ends the solve.
            stalled = *eta_rel >= ETA_MAX;
            *eta_rel = (*eta_rel * ETA_UP).min(ETA_MAX);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::reduced::semismooth_newton;
    use super::*;
    use crate::contact::anisotropic::Orthotropy;
    use crate::contact::history::LawPointHistory;
    use crate::contact::rcc::{BondState, RccParams};
    use crate::contact::solver::reduced::test_support::{random_spd, Lcg};
    use crate::contact::solver::reduced::BlockSparseDelassus;
    use crate::Vec2;

    /// Central differences of Φ with respect to r (columns of A) and x (columns of B).
    fn fd_jacobians(f: impl Fn(V3, V3) -> V3, r: V3, x: V3, hr: f64, hx: f64) -> (Mat3, Mat3) {
        let mut a = Mat3::zeros();
        let mut b = Mat3::zeros();
        for j in 0..3 {
            let (mut rp, mut rm, mut xp, mut xm) = (r, r, x, x);
            rp[j] += hr;
            rm[j] -= hr;
            xp[j] += hx;
            xm[j] -= hx;
            let (fp, fm) = (f(rp, x), f(rm, x));
            let (gp, gm) = (f(r, xp), f(r, xm));
            for i in 0..3 {
                a[(i, j)] = (fp[i] - fm[i]) / (2.0 * hr);
                b[(i, j)] = (gp[i] - gm[i]) / (2.0 * hx);
            }
        }
        (a, b)
    }

    /// A and B are the derivatives of Φ (to 1e-6 of their size, the central differences'
    /// truncation error at steps of 1e-6 of the variables) away from the kinks of the
    /// projection: sticking, sliding and separating points, dry and bonded (β held at its
    /// ceiling 1, where the adhesive stiffness at fixed β is the whole derivative), isotropic
    /// and orthotropic.
    #[test]
    fn linearisation_matches_finite_differences() {
        let rcc = RccParams::new(1.0, 1e6, 5e5, 0.0);
        let bonded = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        }
        .encode();
        let laws = [
            InterfaceLaw::coulomb(0.3),
            InterfaceLaw::rcc(0.5, Some(rcc), None),
            InterfaceLaw::rcc(
                0.3,
                None,
                Some(Orthotropy {
                    axis: [1.0, 0.0, 0.0],
                    mu2: 0.6,
                }),
            ),
        ];
        let rho = 1e3;
        // (r, x) of a stick, a slide and a separating point.
        let cases: [(V3, V3); 3] = [
            ([0.1, -0.05, 1.0], [0.0, 0.0, 0.0]),
            ([0.5, 0.3, 1.0], [-2e-4, -1e-4, 1e-5]),
            ([0.01, 0.0, 0.05], [1e-5, 0.0, 2e-4]),
        ];
        let mut checked = 0;
        for law in &laws {
            for &(r, x) in &cases {
                let lin = |r: V3, x: V3| linearise_point(law, bonded, 1e-3, 1e-6, rho, r, x);
                let l = lin(r, x);
                let (a, b) = fd_jacobians(|r, x| lin(r, x).phi, r, x, 1e-7, 1e-10);
                // The trial point stays on one side of every kink within the steps.
                let scale_a = l.a.norm().max(1.0);
                let scale_b = l.b.norm().max(rho);
                assert!(
                    (a - l.a).norm() <= 1e-6 * scale_a,
                    "{law:?} at {r:?}, {x:?}: A {} vs {}",
                    l.a,
                    a
                );
                assert!(
                    (b - l.b).norm() <= 1e-6 * scale_b,
                    "{law:?} at {r:?}, {x:?}: B {} vs {}",
                    l.b,
                    b
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 9);
    }

    /// The mixed solve on (K, H) finds the solution of the reduced problem on W = H K⁻¹ Hᵀ,
    /// q = x₀ (forces to 1e-8 of their size, both solved to 1e-12), and its δu is K⁻¹Hᵀr:
    /// the same problem, without forming W. With an out-of-balance force in the displacement
    /// part, the same holds for the shifted start.
    #[test]
    fn mixed_solve_matches_the_reduced_problem() {
        for seed in 1..5u64 {
            let mut rng = Lcg(seed);
            let (n, m) = (12, 3);
            let k = random_spd(&mut rng, n, 1.0);
            let kmat = nalgebra::DMatrix::from_row_slice(n, n, &k);
            let mut col_ptr = vec![0];
            let (mut row_idx, mut values) = (Vec::new(), Vec::new());
            for j in 0..n {
                for i in 0..=j {
                    row_idx.push(i);
                    values.push(kmat[(i, j)]);
                }
                col_ptr.push(row_idx.len());
            }
            // Each point reads the three unknowns of its own node and, with weight −½, those
            // of the next node (a master face).
            let h: Vec<Vec<(usize, V3)>> = (0..m)
                .map(|p| {
                    let mut terms = Vec::new();
                    for (node, w) in [(p, 1.0), (p + 1, -0.5)] {
                        for c in 0..3 {
                            let mut coef = [0.0; 3];
                            coef[c] = w;
                            terms.push((3 * node + c, coef));
                        }
                    }
                    terms
                })
                .collect();
            let mut hmat = nalgebra::DMatrix::zeros(3 * m, n);
            for (p, terms) in h.iter().enumerate() {
                for &(i, c) in terms {
                    for a in 0..3 {
                        hmat[(3 * p + a, i)] += c[a];
                    }
                }
            }
            let kinv = kmat.clone().try_inverse().expect("SPD");
            let w = &hmat * &kinv * hmat.transpose();
            let mut rnd = || rng.next_centered();
            let x0: Vec<V3> = (0..m).map(|_| [rnd(), rnd(), rnd() - 0.4]).collect();
            let mu = vec![0.3; m];
            let wd = BlockSparseDelassus::from_dense(m, w.as_slice());
            // nalgebra is column-major and W symmetric: the slice is W row-major too.
            let (reference, _) = semismooth_newton(&wd, &x0, &mu, &vec![[0.0; 3]; m], 1e-12, 100);
            assert!(reference.converged);
            let law = InterfaceLaw::coulomb(0.3);
            let rho: Vec<f64> = (0..m).map(|p| 1.0 / w[(3 * p + 2, 3 * p + 2)]).collect();
            let op = MixedOperator {
                col_ptr: &col_ptr,
                row_idx: &row_idx,
                values: &values,
                h: &h,
            };
            let bond = BondState {
                beta: 0.0,
                ut: Vec2::zeros(),
                damage: 0.0,
            }
            .encode();
            let lin = |p: usize, r: V3, x: V3| linearise_point(&law, bond, 1.0, 1.0, rho[p], r, x);
            let force: f64 = reference
                .r
                .iter()
                .flatten()
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt();
            let (mut pattern, mut eta_rel) = (None, ETA_START);
            let phi = |pts: &[PointSolution]| {
                let defects = pts.iter().zip(&rho).map(|(pt, &rho)| {
                    crate::contact::law::natural_map_defect(&law, rho, pt.r_dry, pt.x)
                });
                defects
                    .flat_map(|d| [d[0], d[1], d[2]])
                    .map(|v| v * v)
                    .sum::<f64>()
                    .sqrt()
            };
            let r0 = vec![[0.0; 3]; m];
            // Once as it is, once with an out-of-balance force m in the displacement part,
            // started from x₀ − H K⁻¹m: the same linear model, so the same solution, with
            // δu = K⁻¹(Hᵀr + m).
            let m_force = nalgebra::DVector::from_fn(n, |_, _| rng.next_centered());
            for momentum in [nalgebra::DVector::zeros(n), m_force] {
                let shift = &hmat * &kinv * &momentum;
                let start: Vec<V3> = (0..m)
                    .map(|p| std::array::from_fn(|c| x0[p][c] - shift[3 * p + c]))
                    .collect();
                let mut dir = LuDirection {
                    op: &op,
                    pattern: &mut pattern,
                    momentum: momentum.as_slice(),
                };
                let tol = 1e-12 * force;
                let sol = solve_mixed(
                    &mut dir,
                    lin,
                    phi,
                    &rho,
                    &r0,
                    &start,
                    tol,
                    100,
                    STEPPER_SCHEDULE,
                    &mut eta_rel,
                )
                .expect("analysis");
                assert!(sol.converged, "seed {seed}: residual {}", sol.residual);
                for (a, b) in sol.r.iter().zip(&reference.r) {
                    for c in 0..3 {
                        assert!(
                            (a[c] - b[c]).abs() <= 1e-8 * force,
                            "seed {seed}: {a:?} vs {b:?}"
                        );
                    }
                }
                let r = nalgebra::DVector::from_iterator(3 * m, sol.r.iter().flatten().copied());
                let du = &kinv * (hmat.transpose() * r + &momentum);
                let du_norm = du.norm();
                for (a, b) in sol.du.iter().zip(du.iter()) {
                    assert!(
                        (a - b).abs() <= 1e-8 * du_norm,
                        "seed {seed}: δu {a} vs {b}"
                    );
                }
            }
            // Not a trivial case: some point carries a force.
            assert!(force > 0.0, "seed {seed}");
        }
    }
}
