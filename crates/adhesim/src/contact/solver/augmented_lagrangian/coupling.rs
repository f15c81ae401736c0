//! The Newton contact solve (docs/contact-solver.md): the Alart–Curnier augmented
//! Lagrangian of each point with its multipliers held over a Newton step, the law's
//! stiffness in K̄, a line search on the step's potential, and the multiplier update once
//! the equilibrium with the current multipliers is reached.

use super::point::{self, augmented_point, AugmentedPoint};
use crate::contact::cone::ContactState;
use crate::contact::interface::PointSolution;
use crate::contact::solver::site_stiffness::{add_contact_tangent, couplings};
use crate::rows_of;
use crate::system::SystemMatrix;
use crate::time::coupling::{ContactCoupling, Evaluated, Iterate, PhaseTimes, StepContact};
use std::time::Instant;

/// Newton iterations after which a step that changes the contact cases is line-searched too.
const CYCLING_ITERATIONS: usize = 0;

/// Shortest step length the line search tries before it takes the step anyway.
const MIN_STEP_LENGTH: f64 = 1.0 / 64.0;

/// A Newton step under line search: from `u0` along `du`, at step length `alpha`, against the
/// potential `energy0` at `u0` and its slope along `du`.
struct LineSearch {
    cases: Vec<ContactState>,
    u0: Vec<f64>,
    du: Vec<f64>,
    alpha: f64,
    energy0: f64,
    slope: f64,
    merit0: f64,
}

/// The Newton contact solve of one step.
pub struct NewtonCoupling<'a> {
    sc: StepContact<'a>,
    /// Multipliers (dry forces in local frames) [N], warm-started from the committed ones.
    lambda: Vec<[f64; 3]>,
    /// The law at the iterate.
    evals: Vec<AugmentedPoint>,
    contact_force: Vec<f64>,
    line_search: Option<LineSearch>,
    /// The step's potential with contact at the iterate [J].
    energy: f64,
    natural_map: f64,
    updates: usize,
}

impl<'a> NewtonCoupling<'a> {
    /// The solve of the step with candidates `sc` and initial multipliers `lambda`; the system
    /// matrix's pattern is extended with the candidates' couplings.
    pub fn new(
        sc: StepContact<'a>,
        lambda: Vec<[f64; 3]>,
        system: &mut SystemMatrix,
    ) -> Result<Self, String> {
        if !sc.is_empty() {
            system
                .ensure_couplings(&couplings(&sc.points))
                .map_err(|e| e.to_string())?;
        }
        let n = sc.constraints.mask().len();
        Ok(NewtonCoupling {
            sc,
            lambda,
            evals: Vec::new(),
            contact_force: vec![0.0; n],
            line_search: None,
            energy: 0.0,
            natural_map: 0.0,
            updates: 0,
        })
    }

    /// The contact law of every point at displacement `u` with the current multipliers, and
    /// the contact force Hᵀr on the free unknowns.
    fn law_at(&self, u: &[f64]) -> (Vec<AugmentedPoint>, Vec<f64>) {
        let sc = &self.sc;
        let evals: Vec<AugmentedPoint> = sc
            .points
            .iter()
            .enumerate()
            .map(|(p, pt)| {
                let x = pt.local_x(sc.reference, u);
                let law = &sc.laws[pt.pair];
                augmented_point(
                    law,
                    sc.history0[p],
                    sc.dt,
                    pt.area,
                    sc.rho[p],
                    self.lambda[p].into(),
                    x.into(),
                )
            })
            .collect();
        let force = sc.nodal_force(evals.iter().map(|e| e.solution.r().into()), u.len());
        (evals, force)
    }

    fn total_energy(&self, potential: f64) -> f64 {
        potential + self.evals.iter().map(|e| e.energy).sum::<f64>()
    }
}

impl<'a> ContactCoupling<'a> for NewtonCoupling<'a> {
    fn step_contact(&mut self) -> &mut StepContact<'a> {
        &mut self.sc
    }

    fn evaluate(&mut self, it: &Iterate, u: &mut [f64], timings: &mut PhaseTimes) -> Evaluated {
        if self.sc.is_empty() {
            return Evaluated::Ready;
        }
        let clock = Instant::now();
        (self.evals, self.contact_force) = self.law_at(u);
        let merit = self.sc.constraints.free_distance(it.g, &self.contact_force);
        let total = self.total_energy(it.potential);
        // Line search on that step: with the multipliers fixed, the Newton step solves for a
        // stationary point of Π(u) + Σ φ_α(x_α(u)), and its matrix is positive definite, so
        // the step is a descent direction. A step that does not lower that potential by the
        // Armijo factor is halved (a full step can overshoot where points open or close, and
        // then cycle).
        if let Some(ls) = &mut self.line_search {
            let same_cases = self
                .evals
                .iter()
                .zip(&ls.cases)
                .all(|(e, c)| e.solution.state == *c);
            // Near the solution the potential's decrease drowns in its round-off: a step that
            // reduces ‖G − Hᵀr‖ is accepted as well.
            let descent = total <= ls.energy0 + 1e-4 * ls.alpha * ls.slope
                || merit <= (1.0 - 1e-4 * ls.alpha) * ls.merit0;
            if (same_cases || it.iter > CYCLING_ITERATIONS)
                && !descent
                && ls.alpha > MIN_STEP_LENGTH
            {
                ls.alpha *= 0.5;
                for ((ui, u0), du) in u.iter_mut().zip(&ls.u0).zip(&ls.du) {
                    *ui = u0 + ls.alpha * du;
                }
                timings.contact_solve += clock.elapsed().as_secs_f64();
                return Evaluated::Backtracked;
            }
        }
        self.line_search = None;
        self.energy = total;
        let contact_defect = point::defect_norm(&self.evals);
        // Multiplier update λ ← P_K(λ − ρ x̂(u)) once the equilibrium with the current
        // multipliers is reached to a tenth of the change the update would make.
        if it.iter > 1 && merit <= 0.1 * contact_defect {
            for (l, e) in self.lambda.iter_mut().zip(&self.evals) {
                *l = e.solution.r_dry.into();
            }
            self.updates += 1;
            (self.evals, self.contact_force) = self.law_at(u);
            self.energy = self.total_energy(it.potential);
        }
        self.natural_map = self.sc.natural_map(&self.solutions());
        timings.contact_solve += clock.elapsed().as_secs_f64();
        Evaluated::Ready
    }

    fn contact_force(&self) -> &[f64] {
        &self.contact_force
    }

    fn contact_residual(&self, scale: f64) -> f64 {
        self.natural_map / scale
    }

    fn add_tangent(&self, system: &mut SystemMatrix) {
        if self.sc.is_empty() {
            return;
        }
        let stiffness: Vec<_> = self.evals.iter().map(|e| rows_of(&e.stiffness)).collect();
        add_contact_tangent(&self.sc.points, &stiffness, system);
    }

    fn tangent_key(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        // The point (its site and the nodes of its stencil) and its case.
        for (pt, e) in self.sc.points.iter().zip(&self.evals) {
            (pt.pair, pt.local, e.solution.state as u8).hash(&mut h);
            pt.stencil().for_each(|(n, _)| n.hash(&mut h));
        }
        h.finish()
    }

    fn correct(
        &mut self,
        it: &Iterate,
        u: &[f64],
        du: &mut [f64],
        residual_norm: f64,
        _scale: f64,
        _system: &mut SystemMatrix,
        _timings: &mut PhaseTimes,
    ) -> Result<(), String> {
        if self.sc.is_empty() {
            return Ok(());
        }
        let fixed = self.sc.constraints.mask();
        self.line_search = Some(LineSearch {
            cases: self.evals.iter().map(|e| e.solution.state).collect(),
            slope: (0..u.len())
                .filter(|&i| !fixed[i])
                .map(|i| (it.g[i] - self.contact_force[i]) * du[i])
                .sum(),
            u0: u.to_vec(),
            du: du.to_vec(),
            alpha: 1.0,
            energy0: self.energy,
            merit0: residual_norm,
        });
        Ok(())
    }

    fn solutions(&self) -> Vec<PointSolution> {
        self.evals.iter().map(|e| e.solution).collect()
    }

    fn sweeps(&self) -> usize {
        self.updates
    }
}
