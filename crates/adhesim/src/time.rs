//! One NSCD θ-method step (docs/model.md §3) with its Newton loop and Δt cut-back.
//!
//! Over [t, t+Δt] with known u₀, v₀ and unknown u₁:
//!   v₁ = (u₁ − u₀)/(θΔt) − (1−θ)/θ · v₀
//!   G(u₁) = M (u₁ − u₀ − Δt v₀)/(θΔt²) − (1−ξ)(F_ext⁰ − F_int(u₀) − A v₀)
//!           − ξ (F_ext¹ − F_int(u₁) − A v₁) − R₁
//!   K̄ = ξ K + ξ/(θΔt) A + M/(θΔt²)
//! The quasi-static mode drops M and A: G = F_int(u₁) − F_ext¹ − R₁, K̄ = K.

mod attempt;
mod constraints;
pub(crate) mod coupling;
pub mod factor_reuse;
mod integrator;
mod newton_loop;

pub use attempt::PhaseTimes;
pub use constraints::{thickness_ties, Constraints};

use crate::assembly::{BadElement, Discretisation};
use crate::contact::cone::ContactState;
use crate::contact::detect::{align_frames, ContactPoint};
use crate::contact::discretisation::detect;
use crate::contact::history::PointHistory;
use crate::contact::history::SiteHistory;
use crate::contact::interface::{Interface, PointSolution};
use crate::contact::solver::augmented_lagrangian::coupling::NewtonCoupling;
use crate::contact::solver::gauss_seidel::coupling::DelassusCoupling;
pub use crate::contact::solver::gauss_seidel::{CachedDelassus, DelassusCache};
use crate::contact::solver::semismooth::coupling::MixedCoupling;
use crate::contact::solver::semismooth::mixed::MixedWorkspace;
use crate::linalg::LinalgError;
use crate::problem::{
    ContactSolver, NewtonMethod, Predictor, Problem, AUTO_GAUSS_SEIDEL_RETRY_MAX,
};
use crate::system::SystemMatrix;
use attempt::Attempt;
use coupling::{Candidates, ContactCoupling, StepContact};
use integrator::{Inertia, Scheme, ThetaStep, Workspace};
use newton_loop::{Flow, NewtonLoop};
use std::sync::Arc;
use std::time::Instant;

/// Why a run could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// Degenerate or inverted elements in the reference meshes.
    #[error("{} degenerate or inverted element(s) in the reference mesh: {}", .0.len(), describe_bad(.0))]
    BadElements(Vec<BadElement>),
    /// The linear-algebra setup failed.
    #[error(transparent)]
    Linalg(#[from] LinalgError),
}

/// Checks the reference meshes of `problem` for degenerate or inverted elements (what
/// [`Stepper::new`] would refuse), without building the system matrix.
pub fn check_elements(problem: &Problem) -> Result<(), SetupError> {
    discretise(problem).map(|_| ())
}

/// The elements of every body of `problem`, each body with its element formulation.
fn discretise(problem: &Problem) -> Result<Discretisation, SetupError> {
    let bodies: Vec<_> = problem
        .bodies
        .iter()
        .map(|b| (&b.mesh, b.material.clone()))
        .collect();
    let formulations: Vec<_> = problem.bodies.iter().map(|b| b.element).collect();
    Discretisation::with_formulations(&bodies, &formulations).map_err(SetupError::BadElements)
}

fn describe_bad(bad: &[BadElement]) -> String {
    let mut s: Vec<String> = bad
        .iter()
        .take(10)
        .map(|b| format!("body {} cell {} (det J = {:.3e})", b.body, b.cell, b.det))
        .collect();
    if bad.len() > 10 {
        s.push(format!("and {} more", bad.len() - 10));
    }
    s.join(", ")
}

/// Why a step could not be completed even at the smallest time step.
#[derive(Debug, Clone, thiserror::Error)]
#[error("the step from t = {t:.6e} s could not be completed: Δt fell below its minimum {dt_min:.3e} s; last failure: {reason}")]
pub struct StepError {
    /// Time at the start of the failed step [s].
    pub t: f64,
    /// The smallest allowed step [s].
    pub dt_min: f64,
    /// What went wrong at the smallest step tried.
    pub reason: String,
}

/// The contact candidates, contact solver and Newton method of an attempt at a step.
#[derive(Clone, Copy, Debug, Default)]
struct AttemptKind {
    candidates: usize,
    solver: ContactSolver,
    method: NewtonMethod,
}

/// An attempt at a step that failed: why, and what it was (for the fall-backs).
struct FailedAttempt {
    reason: String,
    kind: AttemptKind,
}

/// What one committed step did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Step number (1-based).
    pub step: usize,
    /// Time at the end of the step [s].
    pub t: f64,
    /// Step size used [s].
    pub dt: f64,
    /// Newton iterations of the successful attempt.
    pub newton_iterations: usize,
    /// Attempts discarded (Δt halved) before this step succeeded.
    pub cutbacks: usize,
    /// Why the last discarded attempt failed (None without cut-backs).
    pub last_cutback: Option<String>,
    /// Final relative residual.
    pub residual: f64,
    /// Kinetic energy ½ vᵀMv [J].
    pub kinetic: f64,
    /// Strain energy [J].
    pub internal: f64,
    /// Work done on the bodies since t = 0 by loads, gravity, supports and contact [J].
    pub external_work: f64,
    /// Contact iterations, summed over the Newton iterations: Gauss-Seidel sweeps over the
    /// contact points, or multiplier updates of the Newton contact solve.
    pub contact_sweeps: usize,
    /// Contact residual of the committed solution: the natural map of the dry contact forces
    /// relative to the step's force scale (0 without contact points; docs/contact-solver.md).
    pub contact_residual: f64,
    /// Contact candidates of the step.
    pub contact_points: usize,
    /// Delassus operators built in the step (0 when the last one could be reused).
    pub delassus_builds: usize,
    /// Numeric factorisations of the step's matrix in the successful attempt (K̄, or, in the
    /// semismooth contact solve, K̄ with the points' condensed blocks).
    pub factorisations: usize,
    /// Wall time of the successful attempt, by phase [s].
    pub timings: PhaseTimes,
}

/// The contact state of one contact site of a pair (a slave node, for node-to-surface
/// contact), committed at the end of every step: what every interface law has (forces, gap,
/// slip, state, frame) and the law's own history. A pair's sites are numbered by its
/// discretisation, in the order of [`crate::contact::ContactPair::slave_nodes`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SiteContact {
    /// The interface law's history at the site, in the order of its named fields
    /// ([`crate::contact::Interface::history_fields`]); e.g. β, u_t and D of the RCC law
    /// ([`crate::contact::RccHistory`]). Kept when the site leaves contact, as the law says
    /// ([`crate::contact::Interface::release`]).
    pub history: SiteHistory,
    /// Dry force r̄ in the local frame (t₁, t₂, n) [N].
    pub r_dry: [f64; 3],
    /// Adhesive force r̃ in the local frame [N].
    pub r_adh: [f64; 3],
    /// Total contact force on the site in global axes [N].
    pub force: [f64; 3],
    /// Gap at the end of the step x_n [m] (NaN when the site is not a candidate).
    pub gap: f64,
    /// Slip increment over the step (t₁, t₂) [m].
    pub slip: [f64; 2],
    /// 0 not a candidate, 1 apart, 2 stick, 3 slide.
    pub state: i32,
    /// Tangent axes T₁, T₂ of the local frame (global components).
    pub tangent_axes: [[f64; 3]; 2],
}

impl SiteContact {
    /// How many numbers [`SiteContact::to_values`] gives (the state code and the law's
    /// history aside).
    pub const VALUES: usize = 18;

    /// Every real-valued field but the history, in a fixed order: r̄ (3), r̃ (3), force (3),
    /// gap, slip (2), tangent axes (2 × 3). With [`SiteContact::state`] and
    /// [`SiteContact::history`] this is the whole site (the checkpoint format).
    pub fn to_values(&self) -> [f64; Self::VALUES] {
        let mut v = [0.0; Self::VALUES];
        let parts: [&[f64]; 6] = [
            &self.r_dry,
            &self.r_adh,
            &self.force,
            &[self.gap],
            &self.slip,
            self.tangent_axes.as_flattened(),
        ];
        for (slot, x) in v.iter_mut().zip(parts.into_iter().flatten()) {
            *slot = *x;
        }
        v
    }

    /// The site whose [`SiteContact::to_values`] are `v`, with state code `state` and
    /// history `history`.
    pub fn from_values(v: &[f64; Self::VALUES], state: i32, history: SiteHistory) -> Self {
        let a3 = |k: usize| [v[k], v[k + 1], v[k + 2]];
        SiteContact {
            history,
            r_dry: a3(0),
            r_adh: a3(3),
            force: a3(6),
            gap: v[9],
            slip: [v[10], v[11]],
            state,
            tangent_axes: [a3(12), a3(15)],
        }
    }
}

/// The state of the bodies.
#[derive(Clone, Debug)]
pub struct State {
    /// Time [s].
    pub t: f64,
    /// Nodal displacements [m], 3 per node.
    pub u: Vec<f64>,
    /// Nodal velocities [m/s], 3 per node.
    pub v: Vec<f64>,
    /// Number of committed steps.
    pub step: usize,
}

/// Everything a [`Stepper`] carries from one step to the next: restoring it into a fresh
/// stepper of the same problem continues the run exactly as if it had not stopped.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Time [s].
    pub t: f64,
    /// Number of committed steps.
    pub step: usize,
    /// Nodal displacements [m].
    pub u: Vec<f64>,
    /// Nodal velocities [m/s].
    pub v: Vec<f64>,
    /// Step size the next step will try before clipping to the end time [s].
    pub dt: f64,
    /// Steps since the last cut-back (Δt doubles back after two).
    pub good_steps_since_cut: usize,
    /// Loads and gravity at the start of the next step [N].
    pub f_ext0: Vec<f64>,
    /// Internal force at the start of the next step [N].
    pub f_int0: Vec<f64>,
    /// Work done on the bodies since t = 0 [J].
    pub external_work: f64,
    /// Strain energy of the committed state [J].
    pub last_internal: f64,
    /// Committed contact state per pair and contact site.
    pub contact: Vec<Vec<SiteContact>>,
    /// Internal variables of the viscoelastic materials (see
    /// [`Discretisation::history`]).
    pub material_history: Vec<f64>,
    /// The Delassus operator the Gauss-Seidel contact solve keeps for reuse: the next step's
    /// iterates depend on it.
    pub delassus: DelassusCache,
}

/// Advances a [`Problem`] in time.
pub struct Stepper {
    /// The problem being solved.
    pub problem: Arc<Problem>,
    /// Its discretisation.
    pub disc: Discretisation,
    /// Committed state.
    pub state: State,
    inertia: Inertia,
    /// Gravity force per unit acceleration along x, y, z [N/(m/s²)].
    gravity_force: [Vec<f64>; 3],
    system: SystemMatrix,
    constraints: Constraints,
    dt: f64,
    good_steps_since_cut: usize,
    f_ext0: Vec<f64>,
    f_int0: Vec<f64>,
    external_work: f64,
    last_internal: f64,
    /// Committed contact state per pair and contact site.
    pub contact: Vec<Vec<SiteContact>>,
    /// Diagonal of the bounding box of the reference nodes [m].
    model_size: f64,
    /// The last Delassus operator, kept for reuse by the Gauss-Seidel contact solve.
    delassus_cache: DelassusCache,
    /// The semismooth solve's LU analysis, kept while the mixed matrix's pattern stays.
    mixed_workspace: MixedWorkspace,
    /// The run's contact solver: the scenario's, until a step on which `auto` chose the
    /// augmented-Lagrangian solve fails; then `AutoWithoutNewton` for the rest of the run.
    contact_solver: ContactSolver,
    /// Nodal reaction forces of the last committed step [N] (see [`Stepper::reactions`]).
    reactions: Vec<f64>,
    /// Buffers of the Newton loop.
    workspace: Workspace,
}

impl Stepper {
    /// Discretises the problem and analyses the system matrix.
    pub fn new(problem: Arc<Problem>) -> Result<Self, SetupError> {
        let disc = discretise(&problem)?;
        let density: Vec<f64> = problem.bodies.iter().map(|b| b.density).collect();
        let mass = disc.mass(&density, problem.time.lumped_mass);
        let n = disc.num_dofs();
        let (am, bk) = problem.time.rayleigh;
        let damping = if am != 0.0 || bk != 0.0 {
            let k0 = disc.assemble(&vec![0.0; n], true).tangent;
            Some(mass.iter().zip(&k0).map(|(m, k)| am * m + bk * k).collect())
        } else {
            None
        };
        let gravity_force =
            crate::gravity::unit_forces(n, |x, y| disc.pattern.symmetric_matvec(&mass, x, y));
        let constraints = Constraints::new(&problem.dirichlet, n);
        let ties = constraints::thickness_ties(&problem, constraints.mask());
        let system = SystemMatrix::new(disc.pattern.clone(), constraints.mask().to_vec(), ties)?;
        let mut v0 = vec![0.0; n];
        let offsets = problem.node_offsets();
        for (b, off) in problem.bodies.iter().zip(offsets) {
            for i in 0..b.mesh.num_nodes() {
                v0[3 * (off + i)..3 * (off + i) + 3].copy_from_slice(&b.initial_velocity);
            }
        }
        let state = State {
            t: 0.0,
            u: vec![0.0; n],
            v: v0,
            step: 0,
        };
        let mut s = Stepper {
            dt: problem.time.dt,
            contact_solver: problem.time.contact_solver,
            problem,
            disc,
            state,
            inertia: Inertia { mass, damping },
            gravity_force,
            system,
            constraints,
            good_steps_since_cut: 0,
            f_ext0: vec![0.0; n],
            f_int0: vec![0.0; n],
            external_work: 0.0,
            last_internal: 0.0,
            contact: Vec::new(),
            model_size: 0.0,
            delassus_cache: None,
            mixed_workspace: MixedWorkspace::default(),
            reactions: vec![0.0; n],
            workspace: Workspace::default(),
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &s.disc.reference {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        s.model_size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        s.contact = s
            .problem
            .contacts
            .iter()
            .map(|c| {
                vec![
                    SiteContact {
                        gap: f64::NAN,
                        ..Default::default()
                    };
                    c.slave_nodes.len()
                ]
            })
            .collect();
        s.constraints.impose(&s.disc.reference, 0.0, &mut s.state.u);
        s.f_ext0 = s.external_force(0.0);
        let a = s.disc.assemble(&s.state.u, false);
        s.f_int0 = a.force;
        s.last_internal = a.energy;
        Ok(s)
    }

    /// Loads and gravity at time `t` [N].
    fn external_force(&self, t: f64) -> Vec<f64> {
        let mut f = vec![0.0; self.state.u.len()];
        crate::gravity::add_force(&mut f, self.problem.gravity.at(t), &self.gravity_force);
        for load in &self.problem.loads {
            let share = 1.0 / load.nodes.len().max(1) as f64;
            for k in 0..3 {
                let fk = load.total_force[k].at(t) * share;
                for &node in &load.nodes {
                    f[3 * node + k] += fk;
                }
            }
        }
        f
    }

    /// The state carried from one step to the next (for checkpoints).
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            t: self.state.t,
            step: self.state.step,
            u: self.state.u.clone(),
            v: self.state.v.clone(),
            dt: self.dt,
            good_steps_since_cut: self.good_steps_since_cut,
            f_ext0: self.f_ext0.clone(),
            f_int0: self.f_int0.clone(),
            external_work: self.external_work,
            last_internal: self.last_internal,
            contact: self.contact.clone(),
            material_history: self.disc.history(),
            delassus: self.delassus_cache.clone(),
        }
    }

    /// Continues from `snap`, taken from a stepper of the same problem. Fails, changing
    /// nothing, when its sizes do not fit this problem.
    pub fn restore(&mut self, snap: Snapshot) -> Result<(), String> {
        let n = self.disc.num_dofs();
        for (what, len) in [
            ("u", snap.u.len()),
            ("v", snap.v.len()),
            ("f_ext0", snap.f_ext0.len()),
            ("f_int0", snap.f_int0.len()),
        ] {
            if len != n {
                return Err(format!(
                    "{what} has {len} values but the problem has {n} degrees of freedom"
                ));
            }
        }
        let sizes: Vec<usize> = self.contact.iter().map(Vec::len).collect();
        let got: Vec<usize> = snap.contact.iter().map(Vec::len).collect();
        if sizes != got {
            return Err(format!(
                "contact state has {got:?} slave nodes per pair but the problem has {sizes:?}"
            ));
        }
        if snap.dt.is_nan() || snap.dt <= 0.0 || !snap.t.is_finite() {
            return Err(format!("invalid time {} or step size {}", snap.t, snap.dt));
        }
        self.disc.set_history(&snap.material_history)?;
        self.state = State {
            t: snap.t,
            u: snap.u,
            v: snap.v,
            step: snap.step,
        };
        self.dt = snap.dt;
        self.good_steps_since_cut = snap.good_steps_since_cut;
        self.f_ext0 = snap.f_ext0;
        self.f_int0 = snap.f_int0;
        self.external_work = snap.external_work;
        self.last_internal = snap.last_internal;
        self.contact = snap.contact;
        self.delassus_cache = snap.delassus;
        Ok(())
    }

    /// Nodal reaction forces [N] of the last committed step, 3 per node: the force the
    /// prescribed displacements exert on the bodies at each constrained degree of freedom,
    /// zero on free ones (and everywhere before the first step).
    pub fn reactions(&self) -> &[f64] {
        &self.reactions
    }

    /// True when the end time has been reached.
    pub fn finished(&self) -> bool {
        self.state.t >= self.problem.time.t_end * (1.0 - 1e-12)
    }

    /// The step size the next step will try [s].
    pub fn next_dt(&self) -> f64 {
        self.dt.min(self.problem.time.t_end - self.state.t)
    }

    /// Kinetic energy ½ vᵀMv of a velocity field [J].
    pub fn kinetic_energy(&self, v: &[f64]) -> f64 {
        let mut mv = vec![0.0; v.len()];
        self.disc
            .pattern
            .symmetric_matvec(&self.inertia.mass, v, &mut mv);
        0.5 * v.iter().zip(&mv).map(|(a, b)| a * b).sum::<f64>()
    }

    /// Advances one step, halving Δt on failure down to dt_min.
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        let ts = self.problem.time.clone();
        let mut cutbacks = 0;
        let mut last_cutback = None;
        loop {
            let remaining = ts.t_end - self.state.t;
            let mut dt = self.dt.min(remaining);
            // Avoid a sliver of a last step.
            if remaining - dt < 1e-3 * dt {
                dt = remaining;
            }
            match self.attempt_with_fallback(dt) {
                Ok(a) => {
                    self.commit_contact(&a.points, &a.solutions, &a.history0);
                    self.reactions = a.reactions;
                    let (contact_sweeps, contact_points, timings, contact_residual) =
                        (a.sweeps, a.points.len(), a.timings, a.contact_residual);
                    self.commit(a.u, a.v, dt);
                    self.external_work += a.work;
                    self.last_internal = a.internal;
                    if cutbacks > 0 {
                        self.good_steps_since_cut = 0;
                    } else {
                        self.good_steps_since_cut += 1;
                        if self.good_steps_since_cut >= 2 && self.dt < ts.dt {
                            self.dt = (self.dt * 2.0).min(ts.dt);
                            self.good_steps_since_cut = 0;
                        }
                    }
                    self.f_ext0 = a.f_ext1;
                    self.f_int0 = a.f_int1;
                    let kinetic = if ts.quasi_static {
                        0.0
                    } else {
                        self.kinetic_energy(&self.state.v)
                    };
                    return Ok(StepReport {
                        step: self.state.step,
                        t: self.state.t,
                        dt,
                        newton_iterations: a.iterations,
                        cutbacks,
                        last_cutback,
                        residual: a.residual,
                        kinetic,
                        internal: a.internal,
                        external_work: self.external_work,
                        contact_sweeps,
                        contact_residual,
                        contact_points,
                        delassus_builds: a.delassus_builds,
                        factorisations: a.factorisations,
                        timings,
                    });
                }
                Err(reason) => {
                    if dt * 0.5 < ts.dt_min {
                        return Err(StepError {
                            t: self.state.t,
                            dt_min: ts.dt_min,
                            reason,
                        });
                    }
                    self.dt = dt * 0.5;
                    cutbacks += 1;
                    last_cutback = Some(reason);
                }
            }
        }
    }

    fn commit_contact(
        &mut self,
        points: &[ContactPoint],
        sols: &[PointSolution],
        history0: &[PointHistory],
    ) {
        // Nodes that are not candidates of this step keep what their law says.
        for (nodes, pair) in self.contact.iter_mut().zip(&self.problem.contacts) {
            for n in nodes.iter_mut() {
                *n = SiteContact {
                    gap: f64::NAN,
                    history: pair.law.release(&n.history),
                    ..Default::default()
                };
            }
        }
        for ((pt, sol), h0) in points.iter().zip(sols).zip(history0) {
            let f = &pt.frame;
            let r: [f64; 3] = sol.r().into();
            let global = |v: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|k| v[0] * f[0][k] + v[1] * f[1][k] + v[2] * f[2][k])
            };
            // Each slave node of the point carries its share of the forces.
            let share = pt.node_share();
            let part = |v: [f64; 3]| v.map(|c| share * c);
            let node = SiteContact {
                history: self.problem.contacts[pt.pair].law.commit(h0, sol, f),
                r_dry: part(sol.r_dry.into()),
                r_adh: part(sol.r_adh.into()),
                force: part(global(r)),
                gap: sol.x[2],
                slip: [sol.x[0], sol.x[1]],
                state: match sol.state {
                    ContactState::Apart => 1,
                    ContactState::Stick => 2,
                    ContactState::Slide => 3,
                },
                tangent_axes: [f[0], f[1]],
            };
            for local in pt.locals() {
                self.contact[pt.pair][local] = node;
            }
        }
    }

    /// Committed history of each contact point, frozen for the step, in its local frame.
    fn histories_at_start(&self, points: &[ContactPoint]) -> Vec<PointHistory> {
        points
            .iter()
            .map(|pt| {
                let c = &self.contact[pt.pair][pt.local];
                self.problem.contacts[pt.pair]
                    .law
                    .point_history(&c.history, &pt.frame)
            })
            .collect()
    }

    fn commit(&mut self, u: Vec<f64>, v: Vec<f64>, dt: f64) {
        self.disc.commit_step(&u);
        self.state.u = u;
        self.state.v = v;
        self.state.t += dt;
        if (self.problem.time.t_end - self.state.t).abs() < 1e-12 * self.problem.time.t_end {
            self.state.t = self.problem.time.t_end;
        }
        self.state.step += 1;
    }

    /// Committed dry force of each contact point, in its local frame: the warm start of the
    /// Newton contact solve's multipliers.
    fn multipliers_at_start(&self, points: &[ContactPoint]) -> Vec<[f64; 3]> {
        points
            .iter()
            .map(|pt| {
                let c = &self.contact[pt.pair][pt.local];
                if c.state == 0 {
                    return [0.0; 3];
                }
                let [t1, t2] = c.tangent_axes;
                let n = crate::Vec3::from(t1).cross(&crate::Vec3::from(t2));
                // The node holds its share of the point's force.
                let r = c.r_dry.map(|v| v / pt.node_share());
                let g: [f64; 3] =
                    std::array::from_fn(|k| r[0] * t1[k] + r[1] * t2[k] + r[2] * n[k]);
                pt.frame
                    .map(|axis| axis[0] * g[0] + axis[1] * g[1] + axis[2] * g[2])
            })
            .collect()
    }

    /// [`Self::attempt_with_solver_fallbacks`] from the scenario's predictor; when a
    /// quasi-static step fails from the secant start, the same step is tried again from the
    /// last state before the caller cuts Δt back, so that the secant start never fails a
    /// step the last state solves (a load path with a kink, a ramp that stops, makes the
    /// carried-on increment overshoot).
    fn attempt_with_fallback(&mut self, dt: f64) -> Result<Attempt, String> {
        let (quasi_static, predictor) =
            (self.problem.time.quasi_static, self.problem.time.predictor);
        let reason = match self.attempt_with_solver_fallbacks(dt, predictor) {
            Err(reason) if quasi_static && predictor == Predictor::Secant => reason,
            done => return done,
        };
        self.attempt_with_solver_fallbacks(dt, Predictor::Last)
            .map_err(|e| format!("{reason}; again from the last state: {e}"))
    }

    /// [`Self::attempt`] from `predictor` with the scenario's Newton method; when a
    /// modified-Newton attempt fails, the same step is tried again with full Newton (a new
    /// factorisation at every iteration) before the caller cuts Δt back, so that keeping
    /// factorisations never fails a step full Newton solves.
    fn attempt_with_solver_fallbacks(
        &mut self,
        dt: f64,
        predictor: Predictor,
    ) -> Result<Attempt, String> {
        let (method, solver) = (self.problem.time.newton, self.contact_solver);
        let mut result = self.attempt(dt, method, solver, predictor);
        if matches!(&result, Err(f) if f.kind.method != NewtonMethod::Full) {
            result = self.attempt(dt, NewtonMethod::Full, solver, predictor);
        }
        let (reason, last) = match result {
            Ok(attempt) => return Ok(attempt),
            Err(failed) => (failed.reason, failed.kind),
        };
        if !matches!(
            solver,
            ContactSolver::Auto | ContactSolver::AutoWithoutNewton
        ) {
            return Err(reason);
        }
        match last.solver {
            // The augmented-Lagrangian solve `auto` chose failed: this step and the rest of
            // the run with the semismooth solve (and Gauss-Seidel below its threshold).
            ContactSolver::Newton => {
                self.contact_solver = ContactSolver::AutoWithoutNewton;
                self.attempt_with_solver_fallbacks(dt, predictor)
                    .map_err(|again| {
                        format!("{reason}; again without the augmented Lagrangian: {again}")
                    })
            }
            // A failed semismooth solve on few enough candidates for W: the same step with
            // Gauss-Seidel on W before Δt is cut.
            ContactSolver::Semismooth if last.candidates <= AUTO_GAUSS_SEIDEL_RETRY_MAX => self
                .attempt(
                    dt,
                    NewtonMethod::Full,
                    ContactSolver::GaussSeidel,
                    predictor,
                )
                .map_err(|again| {
                    format!("{reason}; again with Gauss-Seidel on W: {}", again.reason)
                }),
            _ => Err(reason),
        }
    }

    /// One Newton solve over [t, t+dt] under `method`, a quasi-static step started from
    /// `predictor`; on failure the reason and what the attempt was ([`Self::solve_attempt`]).
    fn attempt(
        &mut self,
        dt: f64,
        method: NewtonMethod,
        contact_solver: ContactSolver,
        predictor: Predictor,
    ) -> Result<Attempt, FailedAttempt> {
        let mut kind = AttemptKind::default();
        self.solve_attempt(dt, method, contact_solver, predictor, &mut kind)
            .map_err(|reason| FailedAttempt { reason, kind })
    }

    /// The Newton solve of [`Self::attempt`], which sets `kind` once the step's contact
    /// solver and Newton method are known; Err with the reason on failure. The stages follow
    /// docs/model.md §3: detect the contact candidates, predict, then iterate (assemble,
    /// evaluate the contact law, check, factorise and solve, solve the contact problem,
    /// update) until the iterate converges.
    fn solve_attempt(
        &mut self,
        dt: f64,
        method: NewtonMethod,
        contact_solver: ContactSolver,
        predictor: Predictor,
        kind: &mut AttemptKind,
    ) -> Result<Attempt, String> {
        self.disc.begin_step(dt);
        let (settings, t1) = (&self.problem.time, self.state.t + dt);
        let f_ext1 = self.external_force(t1);
        let clock = Instant::now();
        let candidates = self.detect_contact(t1, contact_solver);
        let solver = candidates.solver;
        let method = method.for_contact(solver);
        *kind = AttemptKind {
            candidates: candidates.points.len(),
            solver,
            method,
        };
        let laws = self
            .problem
            .contacts
            .iter()
            .map(|c| c.law.clone())
            .collect();
        let reference = &self.disc.reference;
        let (contact, lambda) =
            StepContact::new(candidates, laws, dt, reference, &self.constraints);
        let system = &mut self.system;
        let coupling: Box<dyn ContactCoupling<'_> + '_> = match (solver, lambda) {
            (ContactSolver::Semismooth, Some(r0)) => {
                let ws = &mut self.mixed_workspace;
                Box::new(MixedCoupling::new(contact, r0, ws, system)?)
            }
            (_, Some(lambda)) => Box::new(NewtonCoupling::new(contact, lambda, system)?),
            (_, None) => Box::new(DelassusCoupling::new(contact, &mut self.delassus_cache)),
        };
        let detect_time = clock.elapsed().as_secs_f64();
        let step = ThetaStep::new(
            &Scheme {
                predictor,
                ..Scheme::of(settings)
            },
            dt,
            (&self.state.u, &self.state.v),
            (&self.f_ext0, &self.f_int0),
            f_ext1,
            &self.inertia,
            &self.disc.pattern,
        );
        let ws = &mut self.workspace;
        let (disc, constraints) = (&self.disc, &self.constraints);
        let mut newton = NewtonLoop::new(
            step,
            coupling,
            system,
            disc,
            constraints,
            ws,
            settings,
            self.model_size,
            method,
        );
        newton.timings.delassus += detect_time;
        let mut u = newton.predict(t1);
        for iter in 1..=settings.max_newton {
            if let Flow::Converged(attempt) = newton.iterate(iter, &mut u)? {
                return Ok(*attempt);
            }
        }
        Err(newton.failure())
    }

    /// Stage *detect*: the contact candidates over [t, t1] with their laws' histories frozen
    /// at the start of the step, the force their bonds can carry, ‖(A_α √(C w))_α‖ [N] (the
    /// force scale of an interface that holds, or snaps into, contact without load), and, for
    /// the Newton contact solve, the multipliers it starts from.
    fn detect_contact(&self, t1: f64, contact_solver: ContactSolver) -> Candidates {
        let mut points = if self.problem.contacts.is_empty() {
            Vec::new()
        } else {
            detect(
                &self.problem.contacts,
                &self.disc.reference,
                &self.state.u,
                self.state.t,
                t1,
            )
        };
        align_frames(&mut points, &self.problem.contacts);
        let bond_strength = points
            .iter()
            .map(|pt| {
                let law = &self.problem.contacts[pt.pair].law;
                (pt.area * law.bond_traction()).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        let frictionless_dry = points.iter().all(|pt| {
            let law = &self.problem.contacts[pt.pair].law;
            law.is_frictionless() && !law.is_adhesive()
        });
        let solver = contact_solver.for_step(points.len(), frictionless_dry);
        Candidates {
            multipliers: (solver != ContactSolver::GaussSeidel)
                .then(|| self.multipliers_at_start(&points)),
            solver,
            history0: self.histories_at_start(&points),
            points,
            bond_strength,
        }
    }
}
