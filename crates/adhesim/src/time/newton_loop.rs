//! One attempt at a step: the Newton loop over the stages of docs/model.md §3, on borrowed
//! parts of the stepper (so that the stepper keeps only what lives between steps).

use super::attempt::{Attempt, PhaseTimes};
use super::constraints::Constraints;
use super::coupling::{ContactCoupling, Evaluated, Iterate};
use super::factor_reuse::{
    keep_as_preconditioner, keep_for_correction, matrix_key, KRYLOV_CORRECTION, KRYLOV_REFRESH,
};
use super::integrator::{norm, ThetaStep, Workspace};
use crate::assembly::{Assembled, Discretisation};
use crate::problem::{NewtonMethod, TimeSettings};
use crate::system::SystemMatrix;
use std::time::Instant;

/// What an iteration leads to.
pub enum Flow {
    /// The iterate converged: the step's result.
    Converged(Box<Attempt>),
    /// Another iteration is needed.
    Continue,
}

/// The Newton loop of one attempt.
pub struct NewtonLoop<'a> {
    /// The θ-method step.
    pub step: ThetaStep<'a>,
    /// The contact stage.
    pub coupling: Box<dyn ContactCoupling<'a> + 'a>,
    /// K̄ and its factorisation.
    pub system: &'a mut SystemMatrix,
    /// Elements and their assembly.
    pub disc: &'a Discretisation,
    /// Prescribed displacements.
    pub constraints: &'a Constraints,
    /// Buffers reused by the iterations.
    pub ws: &'a mut Workspace,
    /// Time-stepping settings (tolerances, iteration limit).
    pub settings: &'a TimeSettings,
    /// Diagonal of the model's bounding box [m] (floor of the negligible correction).
    pub model_size: f64,
    /// Wall time by phase.
    pub timings: PhaseTimes,
    /// Whether each correction gets a new factorisation or may keep the last one.
    method: NewtonMethod,
    /// ‖G − Hᵀr‖ of the last corrected iterate [N] (the contraction test of a kept factor).
    last_norm: Option<f64>,
    /// Whether the next preconditioned correction factorises K̄ afresh (the last one needed
    /// many GMRES iterations).
    refresh: bool,
    /// K̄'s factorisations when the attempt started.
    factorisations0: usize,
    negligible: bool,
    last_relative: f64,
    contact_residual: f64,
}

impl<'a> NewtonLoop<'a> {
    /// The loop over `step` with the contact stage `coupling`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        step: ThetaStep<'a>,
        coupling: Box<dyn ContactCoupling<'a> + 'a>,
        system: &'a mut SystemMatrix,
        disc: &'a Discretisation,
        constraints: &'a Constraints,
        ws: &'a mut Workspace,
        settings: &'a TimeSettings,
        model_size: f64,
        method: NewtonMethod,
    ) -> Self {
        NewtonLoop {
            factorisations0: system.factorisations,
            step,
            coupling,
            system,
            disc,
            constraints,
            ws,
            settings,
            model_size,
            timings: PhaseTimes::default(),
            method,
            last_norm: None,
            refresh: false,
            negligible: false,
            last_relative: f64::NAN,
            contact_residual: 0.0,
        }
    }

    /// Stage *predict*: the first iterate, with the prescribed displacements at `t1` [s].
    pub fn predict(&mut self, t1: f64) -> Vec<f64> {
        let mut u = self.step.predict(self.ws);
        self.constraints.impose(&self.disc.reference, t1, &mut u);
        u
    }

    /// Newton iteration `iter` (1-based) from the iterate `u`: assemble, evaluate the contact
    /// law, check convergence, factorise K̄ and solve the correction, solve the contact
    /// problem, update `u`.
    pub fn iterate(&mut self, iter: usize, u: &mut [f64]) -> Result<Flow, String> {
        let buffer = std::mem::take(&mut self.ws.tangent);
        let mut asm = assemble(self.disc, u, iter, buffer, &mut self.timings)?;
        let flow = self.iterate_assembled(iter, u, &mut asm);
        self.ws.tangent = std::mem::take(&mut asm.tangent);
        flow
    }

    /// The rest of Newton iteration `iter` once `asm` holds the iterate's force and tangent.
    fn iterate_assembled(
        &mut self,
        iter: usize,
        u: &mut [f64],
        asm: &mut Assembled,
    ) -> Result<Flow, String> {
        let balance = self.step.balance(u, &asm.force, asm.energy, self.ws);
        if iter == 1 {
            let step = &self.step;
            let diagonal = || step.matrix_diagonal(&asm.tangent);
            self.coupling.step_contact().set_augmentation(diagonal);
        }
        let it = Iterate::new(iter, &self.ws.g, balance.potential);
        if let Evaluated::Backtracked = self.coupling.evaluate(&it, u, &mut self.timings) {
            return Ok(Flow::Continue);
        }
        let scale = balance
            .scale
            .max(self.coupling.step_contact().bond_strength);
        let force = self.coupling.contact_force();
        let check = check_balance(&mut self.ws.g, force, self.constraints, scale, iter)?;
        self.last_relative = check.relative;
        self.contact_residual = self.coupling.contact_residual(check.scale);
        let contact_solved = self.coupling.step_contact().is_empty()
            || (iter > 1 && self.contact_residual <= self.settings.contact_tol);
        if contact_solved && check.converged(self.settings.newton_tol, self.negligible) {
            return Ok(Flow::Converged(Box::new(self.finish(u, asm, check))));
        }
        if iter == self.settings.max_newton {
            return Ok(Flow::Continue);
        }
        let mut du = if self.coupling.folds_momentum() {
            self.out_of_balance(&asm.tangent)
        } else {
            self.newton_correction(&asm.tangent, iter, check.norm)?
        };
        let it = Iterate::new(iter, &self.ws.g, balance.potential);
        let (norm_g, scale) = (check.norm, check.scale);
        let timings = &mut self.timings;
        let system = &mut *self.system;
        self.coupling
            .correct(&it, u, &mut du, norm_g, scale, system, timings)?;
        for (ui, di) in u.iter_mut().zip(&du) {
            *ui += di;
        }
        // The floor (1e-6 of the model size) covers steps in which nothing moves.
        let floor = 1e-6 * self.model_size;
        self.negligible = norm(&du) <= self.settings.newton_tol * self.step.increment(u).max(floor);
        Ok(Flow::Continue)
    }

    /// Why the loop gave up after its last iteration (the caller cuts Δt back).
    pub fn failure(mut self) -> String {
        self.coupling.abandon();
        format!(
            "Newton did not converge in {} iterations (residual {:.2e}, contact residual {:.2e})",
            self.settings.max_newton, self.last_relative, self.contact_residual
        )
    }

    /// Stage *factorise and solve*: K̄ = c_stiff K + c_damp A + c_mass M (+ the contact law's
    /// stiffness) and the correction against the residual with the current contact forces
    /// Hᵀr. The Gauss-Seidel solve then adds K̄⁻¹Hᵀ(r − r_prev): at a converged iterate
    /// r = r_prev and G(u) = Hᵀr whatever W was used, so W may be reused from an earlier
    /// iteration or step (it then only slows the convergence). Under modified Newton the
    /// factorisation of an earlier iteration or step is kept while the out-of-balance force,
    /// `norm` [N] here, contracts ([`keep_for_correction`]): the same argument holds for K̄.
    fn newton_correction(
        &mut self,
        tangent: &[f64],
        iter: usize,
        norm: f64,
    ) -> Result<Vec<f64>, String> {
        let clock = Instant::now();
        let key = matrix_key(self.step.dt, self.coupling.tangent_key());
        let (factor, last) = (self.system.factor_key(), self.last_norm);
        let force = self.coupling.contact_force();
        let mut du: Vec<f64> = force.iter().zip(&self.ws.g).map(|(r, g)| r - g).collect();
        if self.method == NewtonMethod::Preconditioned {
            self.preconditioned_correction(tangent, key, iter, &mut du)?;
        } else {
            if !keep_for_correction(self.method, factor, key, last, norm) {
                self.system.set_from_base(&self.step.matrix_terms(tangent));
                self.coupling.add_tangent(self.system);
                self.system
                    .factorise_keyed(key)
                    .map_err(|e| format!("{e} (Newton iteration {iter})"))?;
            }
            self.system.solve_in_place(&mut du);
        }
        self.last_norm = Some(norm);
        self.timings.factorisation += clock.elapsed().as_secs_f64();
        Ok(du)
    }

    /// The correction `du` (given as its right-hand side Hᵀr − G) solved with K̄ of this
    /// iterate by GMRES preconditioned with the kept factorisation ([`keep_as_preconditioner`]);
    /// K̄ is factorised again, under `key`, when there is none or GMRES does not reach
    /// [`KRYLOV_CORRECTION`]'s tolerance, and flagged for a new factorisation at the next
    /// correction when it needed more than [`KRYLOV_REFRESH`] iterations.
    fn preconditioned_correction(
        &mut self,
        tangent: &[f64],
        key: u64,
        iter: usize,
        du: &mut [f64],
    ) -> Result<(), String> {
        self.system.set_from_base(&self.step.matrix_terms(tangent));
        self.coupling.add_tangent(self.system);
        self.system.apply_conditions();
        if keep_as_preconditioner(self.system.factor_key(), self.refresh) {
            let rhs = du.to_vec();
            let outcome = self.system.solve_preconditioned(du, KRYLOV_CORRECTION);
            if outcome.relative_residual <= KRYLOV_CORRECTION.tol {
                self.refresh = outcome.iterations > KRYLOV_REFRESH;
                return Ok(());
            }
            du.copy_from_slice(&rhs);
        }
        self.system
            .factorise_keyed(key)
            .map_err(|e| format!("{e} (Newton iteration {iter})"))?;
        self.refresh = false;
        self.system.solve_in_place(du);
        Ok(())
    }

    /// K̄'s values, with the conditions applied but not factorised, and the out-of-balance
    /// force Hᵀr − G, for a coupling that solves both together.
    fn out_of_balance(&mut self, tangent: &[f64]) -> Vec<f64> {
        self.system.set_from_base(&self.step.matrix_terms(tangent));
        self.coupling.add_tangent(self.system);
        self.system.apply_conditions();
        let force = self.coupling.contact_force();
        force.iter().zip(&self.ws.g).map(|(r, g)| r - g).collect()
    }

    /// Stage *commit* (what the step hands back): the converged iterate `u` with its end
    /// velocity, work, forces and contact solution.
    fn finish(&mut self, u: &[f64], asm: &mut Assembled, check: Check) -> Attempt {
        let (points, history0) = self.coupling.step_contact().take_candidates();
        let force = self.coupling.contact_force();
        Attempt {
            work: self.step.work(u, &check.reactions, force),
            v: self.step.end_velocity(u, &self.ws.v1),
            f_ext1: self.step.f_ext1.clone(),
            u: u.to_vec(),
            f_int1: std::mem::take(&mut asm.force),
            iterations: check.iter - 1,
            residual: check.relative,
            internal: asm.energy,
            solutions: self.coupling.solutions(),
            sweeps: self.coupling.sweeps(),
            contact_residual: self.contact_residual,
            delassus_builds: self.coupling.delassus_builds(),
            factorisations: self.system.factorisations - self.factorisations0,
            timings: self.timings,
            reactions: check.reactions,
            points,
            history0,
        }
    }
}

/// Stage *assemble*: internal force, strain energy and tangent at `u`; an inverted element
/// fails the attempt.
fn assemble(
    disc: &Discretisation,
    u: &[f64],
    iter: usize,
    tangent_buffer: Vec<f64>,
    timings: &mut PhaseTimes,
) -> Result<Assembled, String> {
    let clock = Instant::now();
    let asm = disc.assemble_reusing(u, true, tangent_buffer);
    timings.assembly += clock.elapsed().as_secs_f64();
    if asm.min_j.is_nan() || asm.min_j <= 0.0 || !asm.energy.is_finite() {
        return Err(format!(
            "an element inverted (min det F = {:.3e}) at Newton iteration {iter}",
            asm.min_j
        ));
    }
    Ok(asm)
}

/// The out-of-balance force G − Hᵀr of an iterate, measured.
struct Check {
    /// Newton iteration (1-based).
    iter: usize,
    /// ‖G − Hᵀr‖ on the free unknowns [N].
    norm: f64,
    /// The force scale it is measured against [N].
    scale: f64,
    /// norm / scale.
    relative: f64,
    /// Support reactions [N] (zero on free unknowns).
    reactions: Vec<f64>,
}

impl Check {
    /// Converged when the residual is small against the forces, or when the last correction
    /// was `negligible` against the step's displacement increment (the residual can sit at
    /// its round-off floor when every force is small, e.g. a vibrating body passing through
    /// its rest position).
    fn converged(&self, tol: f64, negligible: bool) -> bool {
        self.relative <= tol || self.norm == 0.0 || negligible
    }
}

/// Stage *check*: G − Hᵀr against the iterate's force scale (internal, external, inertial,
/// contact forces and support reactions, so that a large out-of-balance force of an early
/// iterate does not make later residuals look small). Zeroes `g` on the prescribed unknowns.
fn check_balance(
    g: &mut [f64],
    contact_force: &[f64],
    constraints: &Constraints,
    scale: f64,
    iter: usize,
) -> Result<Check, String> {
    let mut out_of_balance: Vec<f64> = g.iter().zip(contact_force).map(|(a, b)| a - b).collect();
    let reactions = constraints.reactions(&out_of_balance);
    constraints.zero_fixed(g);
    constraints.zero_fixed(&mut out_of_balance);
    let scale = scale.max(norm(contact_force));
    let residual = norm(&out_of_balance);
    if !residual.is_finite() {
        return Err(format!(
            "the residual is not finite at Newton iteration {iter}"
        ));
    }
    let scale = scale.max(norm(&reactions)).max(f64::MIN_POSITIVE);
    Ok(Check {
        iter,
        norm: residual,
        scale,
        relative: residual / scale,
        reactions,
    })
}
