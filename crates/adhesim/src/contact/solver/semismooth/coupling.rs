//! The semismooth Newton contact solve without the Delassus operator
//! (docs/contact-solver.md). Each Newton iteration of the step solves the momentum balance
//! and the contact law together: from the iterate u and the forces r_prev, the linear model
//! K̄ δu = Hᵀ(r − r_prev) + m (m = Hᵀr_prev − G, the out-of-balance force), x = x(u) + H δu,
//! with the law Φ(r, x) = 0, is solved by [`super::mixed::solve_mixed`] without W:
//! each direction of the mixed (displacement, force) system comes from one sparse Cholesky
//! factorisation of K̄ with the points' condensed blocks, and GMRES ([`CondensedDirection`]).
//! The step's matrix is therefore factorised once per direction and never alone. The
//! factorisations are counted in `time_factorisation`, the rest of the solve (the points'
//! linearisations, GMRES, the line search) in `time_contact_solve`.

use super::mixed::{
    add_ht_terms, apply_h_terms, linearise_point, solve_mixed, Direction, LuDirection,
    MixedDirection, MixedOperator, MixedPattern, MixedWorkspace, PointLinearisation,
    STEPPER_SCHEDULE,
};
use crate::contact::detect::ContactPoint;
use crate::contact::interface::PointSolution;
use crate::contact::solver::site_stiffness::{add_contact_tangent, couplings, RHO_FACTOR};
use crate::linalg::{gmres_with_remainder, KrylovLimits};
use crate::system::SystemMatrix;
use crate::time::coupling::{ContactCoupling, Iterate, PhaseTimes, StepContact};
use crate::{rows_of, Mat3};
use std::time::Instant;

/// ρ_α of the natural map the Newton iterations work on, as a multiple of the stiffness K̄
/// shows at the point. The solution does not depend on it; it weighs force against
/// displacement in the merit of the line search. The solve stops on the residual the step's
/// convergence test measures ([`StepContact::natural_map`], with the larger ρ of the
/// augmented-Lagrangian solve).
const NATURAL_MAP_RHO: f64 = 1.0;

/// The contact solve stops when the natural map and the part of the out-of-balance force
/// still to remove are below this fraction of the step's force scale, or below [`FORCING`]
/// times the out-of-balance force the iteration started from, whichever is larger (an inexact
/// Newton method: the step's next iteration, with a new K̄, does better than more directions
/// on the old one). On the pad of the scale benchmark at 3,136 contact nodes, 0.5 took 33 s
/// where 0.1 took 36 s and 10⁻² 55 s.
const INNER_TOL: f64 = 1e-10;
const FORCING: f64 = 0.5;

/// Newton steps after which the contact solve gives up (the step is then cut back).
const MAX_INNER: usize = 100;

/// The semismooth Newton contact solve of one step.
pub struct MixedCoupling<'a> {
    sc: StepContact<'a>,
    /// H of each point on the factorised system's unknowns (see [`ContactPoint::h_terms`]).
    h: Vec<Vec<(usize, [f64; 3])>>,
    workspace: &'a mut MixedWorkspace,
    /// Total contact force of each point at the last solve, local frames [N].
    r_contact: Vec<[f64; 3]>,
    solutions: Vec<PointSolution>,
    contact_force: Vec<f64>,
    contact_residual: f64,
    iterations: usize,
}

impl<'a> MixedCoupling<'a> {
    /// The solve of the step with candidates `sc`, started from the contact forces `r0`
    /// (local frames) [N], e.g. the dry forces committed at the end of the last step.
    /// `workspace` keeps the LU analysis (for directions GMRES cannot find) from step to step.
    pub fn new(
        sc: StepContact<'a>,
        r0: Vec<[f64; 3]>,
        workspace: &'a mut MixedWorkspace,
        system: &mut SystemMatrix,
    ) -> Result<Self, String> {
        if !sc.is_empty() {
            system
                .ensure_couplings(&couplings(&sc.points))
                .map_err(|e| e.to_string())?;
        }
        workspace.start_step();
        let n = sc.constraints.mask().len();
        let contact_force = sc.nodal_force(r0.iter().copied(), n);
        Ok(MixedCoupling {
            sc,
            h: Vec::new(),
            workspace,
            r_contact: r0,
            solutions: Vec::new(),
            contact_force,
            contact_residual: 0.0,
            iterations: 0,
        })
    }
}

/// x_α + H_α v for each point, from the local displacements `x` [m] and a global field `v`.
fn plus_h(points: &[ContactPoint], x: impl Iterator<Item = [f64; 3]>, v: &[f64]) -> Vec<[f64; 3]> {
    points
        .iter()
        .zip(x)
        .map(|(pt, x)| {
            let h = pt.apply_h(v);
            std::array::from_fn(|k| x[k] + h[k])
        })
        .collect()
}

impl<'a> ContactCoupling<'a> for MixedCoupling<'a> {
    fn step_contact(&mut self) -> &mut StepContact<'a> {
        &mut self.sc
    }

    fn contact_force(&self) -> &[f64] {
        &self.contact_force
    }

    fn contact_residual(&self, _scale: f64) -> f64 {
        self.contact_residual
    }

    fn correct(
        &mut self,
        it: &Iterate,
        u: &[f64],
        du: &mut [f64],
        residual_norm: f64,
        scale: f64,
        system: &mut SystemMatrix,
        timings: &mut PhaseTimes,
    ) -> Result<(), String> {
        if self.sc.is_empty() {
            return Ok(());
        }
        let clock = Instant::now();
        let sc = &self.sc;
        if self.h.is_empty() {
            let (rep, fixed) = (system.representatives(), system.fixed());
            self.h = sc.points.iter().map(|p| p.h_terms(rep, fixed)).collect();
        }
        // The start: x at the iterate, the forces r_prev, and the out-of-balance force
        // m = Hᵀr_prev − G that the first direction removes with the contact law's residual.
        let x0: Vec<[f64; 3]> = sc
            .points
            .iter()
            .map(|pt| pt.local_x(sc.reference, u))
            .collect();
        let mut momentum = du.to_vec();
        system.condense(&mut momentum);
        let rho: Vec<f64> = sc
            .rho
            .iter()
            .map(|r| r / RHO_FACTOR * NATURAL_MAP_RHO)
            .collect();
        let tol = (INNER_TOL * scale).max(FORCING * residual_norm);
        let h = &self.h;
        let law = |p: usize, r: [f64; 3], x: [f64; 3]| {
            let pt = &sc.points[p];
            let law = &sc.laws[pt.pair];
            linearise_point(law, sc.history0[p], sc.dt, pt.area, rho[p], r, x)
        };
        let measure = |pts: &[PointSolution]| sc.natural_map(pts);
        // K̄ as the Newton loop set it, restored before each direction's factorisation.
        let base = system.matrix().1.to_vec();
        let mut factorisation = 0.0;
        let mut solve = |system: &mut SystemMatrix, r0: &[[f64; 3]], x0: &[[f64; 3]], m: &[f64]| {
            let mut dir = CondensedDirection {
                system,
                base: &base,
                points: &sc.points,
                h,
                lu: &mut self.workspace.pattern,
                momentum: m,
                factorisation: &mut factorisation,
            };
            let eta = &mut self.workspace.eta_rel;
            let schedule = STEPPER_SCHEDULE;
            solve_mixed(
                &mut dir, &law, measure, &rho, r0, x0, tol, MAX_INNER, schedule, eta,
            )
        };
        let mut sol = solve(system, &self.r_contact, &x0, &momentum)?;
        let mut iterations = sol.iterations;
        let mut shift = None;
        let mut restart_factorisation = 0.0;
        if !sol.converged && self.r_contact.iter().any(|r| *r != [0.0; 3]) {
            // Where a bond's branch ends (snap-off) the solution lies on another branch than
            // the one Newton follows from the last forces: start again from no contact force,
            // x shifted by −W r_prev (one solve with K̄, factorised again).
            let restart_clock = Instant::now();
            system.set_values(&base);
            system.factorise().map_err(|e| e.to_string())?;
            restart_factorisation = restart_clock.elapsed().as_secs_f64();
            let mut d0 = sc.nodal_force(self.r_contact.iter().map(|r| r.map(|v| -v)), u.len());
            for (d, m) in d0.iter_mut().zip(du.iter()) {
                *d += m;
            }
            system.solve_in_place(&mut d0);
            let x0 = plus_h(&sc.points, x0.iter().copied(), &d0);
            let zeros = vec![[0.0; 3]; x0.len()];
            let again = solve(system, &zeros, &x0, &[])?;
            iterations += again.iterations;
            if again.converged {
                (sol, shift) = (again, Some(d0));
            }
        }
        self.iterations += iterations;
        let factorisation = factorisation + restart_factorisation;
        timings.factorisation += factorisation;
        timings.contact_solve += clock.elapsed().as_secs_f64() - factorisation;
        if !sol.converged {
            return Err(format!(
                "the contact solve did not converge in {iterations} semismooth Newton steps \
                 (residual {:.2e} N, Newton iteration {})",
                sol.residual, it.iter
            ));
        }
        let mut dc = sol.du;
        system.expand_tied(&mut dc);
        du.copy_from_slice(&dc);
        if let Some(d0) = shift {
            for (d, c) in du.iter_mut().zip(&d0) {
                *d += c;
            }
        }
        self.r_contact = sol.r;
        self.contact_force = self.sc.nodal_force(self.r_contact.iter().copied(), u.len());
        self.solutions = sol.points;
        // The solve's measure is the step's natural map.
        self.contact_residual = sol.residual / scale;
        Ok(())
    }

    fn solutions(&self) -> Vec<PointSolution> {
        self.solutions.clone()
    }

    fn sweeps(&self) -> usize {
        self.iterations
    }

    fn folds_momentum(&self) -> bool {
        !self.sc.is_empty()
    }
}

/// Smallest regularisation η (relative to the mean 1/ρ) of the condensed directions: a
/// sticking point enters K̄ as a spring of stiffness 1/η, so this bounds the penalty at 10⁸ ρ,
/// which the Cholesky factorisation resolves to about 10⁻⁸; the residual Φ stays exact, so the
/// Newton iterations still converge to the exact solution, at a rate of about this factor.
const ETA_FLOOR: f64 = 1e-8;

/// GMRES: relative tolerance, iteration limit, restart. A direction need not be exact: its
/// δu gives x = x₀ + H δu exactly and d follows from δu point by point, so an inexact δu
/// only leaves part of the momentum balance to the step's next Newton iteration. On the pad
/// of the scale benchmark (5 increments; tolerance: total GMRES iterations, Newton
/// iterations, normal force at the end) at 1,024 contact points: 1e-8: 120, 19,
/// 16.06207078 N; 1e-6: 95, 21, 16.0620708 N; 1e-4: 72, 21, 16.0621153 N; 1e-3: 63, 22,
/// 16.0644615 N. At 10,000 points 1e-8 took 244 iterations and 1e-6 184, with the same force
/// to 10 digits. 1e-6 keeps the force and cuts a quarter of the triangular solves; looser
/// tolerances move the force by more than the step's own tolerance.
const GMRES: KrylovLimits = KrylovLimits {
    tol: 1e-6,
    max_iter: 200,
    restart: 40,
};
/// Largest relative residual of GMRES accepted as a direction.
const GMRES_ACCEPT: f64 = 1e-5;

/// Largest mixed matrix (unknowns plus three per contact point) factorised by LU when GMRES
/// does not converge: a sparse LU with partial pivoting of a 3D mesh fills in much more than
/// the Cholesky factor (about 0.6 GB at 18k rows, over 16 GB at 180k).
const LU_FALLBACK_MAX: usize = 60_000;

/// The direction of the mixed system without its LU: the force part eliminated point by
/// point, d = −Ã⁻¹(Φ + B H δu) with Ã = A + ηB, leaves
///
///   (K̄ + Σ Hᵀ S H) δu = −Σ Hᵀ Ã⁻¹Φ,   S = Ã⁻¹B,
///
/// on the unknowns of K̄. S is symmetric for sticking (I/η), separating and bonded points and
/// not for sliding ones (the friction force follows the normal one). The system is solved by
/// GMRES preconditioned with the Cholesky factorisation of K̄ + Σ Hᵀ S₊ H, S₊ the positive
/// part of S's symmetric part, which the step's sparse Cholesky (METIS ordering, K̄'s pattern
/// extended by the contact couplings) factorises as it does K̄.
struct CondensedDirection<'s> {
    system: &'s mut SystemMatrix,
    base: &'s [f64],
    points: &'s [ContactPoint],
    h: &'s [Vec<(usize, [f64; 3])>],
    /// The LU analysis of the whole mixed matrix, for directions GMRES cannot find.
    lu: &'s mut Option<MixedPattern>,
    /// The out-of-balance force m on the system's unknowns [N] (empty: none).
    momentum: &'s [f64],
    /// Time spent factorising [s], added to.
    factorisation: &'s mut f64,
}

/// The positive part of the symmetric part of `s`.
fn positive_symmetric_part(s: &Mat3) -> Mat3 {
    let eig = ((s + s.transpose()) * 0.5).symmetric_eigen();
    let clipped = eig.eigenvalues.map(|v| v.max(0.0));
    eig.eigenvectors * Mat3::from_diagonal(&clipped) * eig.eigenvectors.transpose()
}

impl MixedDirection for CondensedDirection<'_> {
    fn unknowns(&self) -> usize {
        self.system.pattern().dim()
    }

    fn eta_floor(&self) -> f64 {
        ETA_FLOOR
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
        let m = lin.len();
        let (mut s, mut g, mut positive, mut rest) = (
            Vec::with_capacity(m),
            Vec::with_capacity(m),
            Vec::with_capacity(m),
            Vec::with_capacity(m),
        );
        for l in lin {
            let Some(inv) = (l.a + eta * l.b).try_inverse() else {
                return Ok(None);
            };
            let sa = inv * l.b;
            // The preconditioner's block: S with D = I, symmetric for a dry point (A and
            // B then both functions of P'), its positive symmetric part otherwise.
            let Some(inv_plain) = (l.a + eta * l.b_plain).try_inverse() else {
                return Ok(None);
            };
            let p = positive_symmetric_part(&(inv_plain * l.b_plain));
            positive.push(rows_of(&p));
            // The part of S the preconditioner leaves out.
            rest.push(sa - p);
            g.push(inv * nalgebra::Vector3::from(l.phi));
            s.push(sa);
        }
        let clock = Instant::now();
        self.system.set_values(self.base);
        add_contact_tangent(self.points, &positive, self.system);
        let factorised = self.system.factorise();
        *self.factorisation += clock.elapsed().as_secs_f64();
        if factorised.is_err() {
            return Ok(None);
        }
        let n = self.unknowns();
        let mut rhs = vec![0.0; n];
        for (v, f) in rhs.iter_mut().zip(self.momentum) {
            *v = momentum * f;
        }
        for (h, ga) in self.h.iter().zip(&g) {
            add_ht_terms(h, (-ga).into(), &mut rhs);
        }
        let h = self.h;
        let (pattern, values, factor) = self.system.operator_and_factor();
        // Only the points whose S the preconditioner leaves part of.
        let rest: Vec<_> = h
            .iter()
            .zip(rest)
            .filter(|(_, ra)| ra.iter().any(|&e| e != 0.0))
            .collect();
        let remainder = |v: &[f64], out: &mut [f64]| {
            out.iter_mut().for_each(|o| *o = 0.0);
            for (ha, ra) in &rest {
                let hv = nalgebra::Vector3::from(apply_h_terms(ha, v));
                add_ht_terms(ha, (ra * hv).into(), out);
            }
        };
        let apply = |v: &[f64], out: &mut [f64]| {
            remainder(v, out);
            pattern.symmetric_matvec(values, v, out);
        };
        let precondition = |v: &mut [f64]| factor.solve_in_place(v);
        let (du, outcome) = gmres_with_remainder(apply, remainder, precondition, &rhs, GMRES);
        if !(outcome.relative_residual <= GMRES_ACCEPT) {
            // GMRES stalled (strongly coupled sliding points): the exact direction from the
            // LU of the whole mixed matrix, where it fits in memory.
            if n + 3 * m > LU_FALLBACK_MAX {
                return Ok(None);
            }
            let pattern = self.system.pattern();
            let op = MixedOperator {
                col_ptr: &pattern.col_ptr,
                row_idx: &pattern.row_idx,
                values: self.base,
                h: self.h,
            };
            let mut lu = LuDirection {
                op: &op,
                pattern: &mut *self.lu,
                momentum: self.momentum,
            };
            return lu.direction(lin, eta, momentum);
        }
        let x: Vec<[f64; 3]> = self.h.iter().map(|ha| apply_h_terms(ha, &du)).collect();
        let d = s
            .iter()
            .zip(&g)
            .zip(&x)
            .map(|((sa, ga), &xa)| (-ga - sa * nalgebra::Vector3::from(xa)).into())
            .collect();
        Ok(Some(Direction { du, d, x }))
    }
}
