//! The semismooth Newton contact solve without the Delassus operator
//! (docs/contact-solver.md): after each Newton correction of the step, the same reduced
//! contact problem as the Gauss-Seidel solve, x = x(u) + H Δu + W (r − r_prev), is solved by
//! [`crate::contact::mixed::solve_mixed`], whose directions come from sparse LU
//! factorisations of the mixed (displacement, force) matrix instead of W.

use super::coupling::{ContactCoupling, Evaluated, Iterate, StepContact};
use super::PhaseTimes;
use crate::contact::detect::ContactPoint;
use crate::contact::law::PointSolution;
use crate::contact::mixed::{linearise_point, solve_mixed, MixedOperator, MixedWorkspace};
use crate::contact::newton::RHO_FACTOR;
use crate::system::SystemMatrix;
use std::time::Instant;

/// ρ_α of the natural map the Newton iterations work on, as a multiple of the stiffness K̄
/// shows at the point. The solution does not depend on it; it weighs force against
/// displacement in the merit of the line search. The solve stops on the residual the step's
/// convergence test measures ([`StepContact::natural_map`], with the larger ρ of the
/// augmented-Lagrangian solve).
const NATURAL_MAP_RHO: f64 = 1.0;

/// The contact solve stops when the natural map is below this fraction of the step's force scale, or
/// below [`FORCING`] times the out-of-balance force the correction started from, whichever
/// is larger (an inexact Newton method: early iterations of the step need no exact contact
/// solve).
const INNER_TOL: f64 = 1e-10;
const FORCING: f64 = 1e-2;

/// Newton steps after which the contact solve gives up (the step is then cut back).
const MAX_INNER: usize = 100;

/// The semismooth Newton contact solve of one step.
pub struct MixedCoupling<'a> {
    sc: StepContact<'a>,
    /// H of each point on the factorised system's unknowns (see [`point_h`]).
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
    /// `workspace` keeps the LU analysis from step to step.
    pub fn new(sc: StepContact<'a>, r0: Vec<[f64; 3]>, workspace: &'a mut MixedWorkspace) -> Self {
        workspace.start_step();
        let n = sc.constraints.mask().len();
        let contact_force = sc.nodal_force(r0.iter().copied(), n);
        MixedCoupling {
            sc,
            h: Vec::new(),
            workspace,
            r_contact: r0,
            solutions: Vec::new(),
            contact_force,
            contact_residual: 0.0,
            iterations: 0,
        }
    }
}

/// H of point `pt` on the unknowns of the factorised system: node n's unknowns are those of
/// its representative `rep[n]`, and the `fixed` unknowns are left out. Each unknown is listed
/// once, with the coefficients of the point's three local components.
pub fn point_h(pt: &ContactPoint, rep: &[usize], fixed: &[bool]) -> Vec<(usize, [f64; 3])> {
    let mut terms: Vec<(usize, [f64; 3])> = Vec::new();
    let nodes = pt
        .slave_nodes()
        .chain(pt.master.iter().map(|&(m, w)| (m, -w)));
    for (node, w) in nodes {
        for k in 0..3 {
            let i = 3 * rep[node] + k;
            if !fixed[i] {
                terms.push((i, std::array::from_fn(|c| w * pt.frame[c][k])));
            }
        }
    }
    terms.sort_by_key(|t| t.0);
    let mut merged: Vec<(usize, [f64; 3])> = Vec::with_capacity(terms.len());
    for (i, c) in terms {
        match merged.last_mut() {
            Some(last) if last.0 == i => (0..3).for_each(|k| last.1[k] += c[k]),
            _ => merged.push((i, c)),
        }
    }
    merged
}

impl<'a> ContactCoupling<'a> for MixedCoupling<'a> {
    fn step_contact(&mut self) -> &mut StepContact<'a> {
        &mut self.sc
    }

    fn evaluate(&mut self, _: &Iterate, _: &mut [f64], _: &mut PhaseTimes) -> Evaluated {
        Evaluated::Ready
    }

    fn contact_force(&self) -> &[f64] {
        &self.contact_force
    }

    fn contact_residual(&self, _scale: f64) -> f64 {
        self.contact_residual
    }

    fn add_tangent(&self, _: &mut SystemMatrix) {}

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
            self.h = sc.points.iter().map(|p| point_h(p, rep, fixed)).collect();
        }
        // The reduced problem's start: x at the forces r_prev the correction du was solved with.
        let x0: Vec<[f64; 3]> = sc
            .points
            .iter()
            .map(|pt| {
                let (x, h) = (pt.local_x(sc.reference, u), pt.apply_h(du));
                std::array::from_fn(|k| x[k] + h[k])
            })
            .collect();
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
            linearise_point(law, sc.bond0[p], sc.dt, pt.area, rho[p], r, x)
        };
        let solve =
            |system: &SystemMatrix, r0: &[[f64; 3]], x0: &[[f64; 3]], ws: &mut MixedWorkspace| {
                let (pattern, values) = system.factorised_matrix();
                let op = MixedOperator {
                    col_ptr: &pattern.col_ptr,
                    row_idx: &pattern.row_idx,
                    values,
                    h,
                };
                let measure = |pts: &[PointSolution]| sc.natural_map(pts);
                solve_mixed(&op, &law, measure, &rho, r0, x0, tol, MAX_INNER, ws)
            };
        let mut sol = solve(system, &self.r_contact, &x0, &mut *self.workspace)?;
        let mut iterations = sol.iterations;
        let mut shift = None;
        if !sol.converged && self.r_contact.iter().any(|r| *r != [0.0; 3]) {
            // Where a bond's branch ends (snap-off) the solution lies on another branch than
            // the one Newton follows from the last forces: start again from no contact force,
            // x shifted by −W r_prev (one solve with the factorised K̄).
            let mut d0 = sc.nodal_force(self.r_contact.iter().map(|r| r.map(|v| -v)), u.len());
            system.solve_in_place(&mut d0);
            let x0: Vec<[f64; 3]> = sc
                .points
                .iter()
                .zip(&x0)
                .map(|(pt, x)| {
                    let h = pt.apply_h(&d0);
                    std::array::from_fn(|k| x[k] + h[k])
                })
                .collect();
            let zeros = vec![[0.0; 3]; x0.len()];
            let again = solve(system, &zeros, &x0, &mut *self.workspace)?;
            iterations += again.iterations;
            if again.converged {
                (sol, shift) = (again, Some(d0));
            }
        }
        self.iterations += iterations;
        timings.contact_solve += clock.elapsed().as_secs_f64();
        if !sol.converged {
            return Err(format!(
                "the contact solve did not converge in {iterations} semismooth Newton steps \
                 (residual {:.2e} N, Newton iteration {})",
                sol.residual, it.iter
            ));
        }
        if let Some(d0) = shift {
            for (d, c) in du.iter_mut().zip(&d0) {
                *d += c;
            }
        }
        let mut dc = sol.du;
        system.expand_tied(&mut dc);
        for (d, c) in du.iter_mut().zip(&dc) {
            *d += c;
        }
        self.r_contact = sol.r;
        self.contact_force = self.sc.nodal_force(self.r_contact.iter().copied(), u.len());
        self.solutions = sol.points;
        self.contact_residual = self.sc.natural_map(&self.solutions) / scale;
        Ok(())
    }

    fn solutions(&self) -> Vec<PointSolution> {
        self.solutions.clone()
    }

    fn sweeps(&self) -> usize {
        self.iterations
    }
}
