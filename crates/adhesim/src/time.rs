//! One NSCD θ-method step (model.md §3) with its Newton loop and Δt cut-back.
//!
//! Over [t, t+Δt] with known u₀, v₀ and unknown u₁:
//!   v₁ = (u₁ − u₀)/(θΔt) − (1−θ)/θ · v₀
//!   G(u₁) = M (u₁ − u₀ − Δt v₀)/(θΔt²) − (1−ξ)(F_ext⁰ − F_int(u₀) − A v₀)
//!           − ξ (F_ext¹ − F_int(u₁) − A v₁) − R₁
//!   K̄ = ξ K + ξ/(θΔt) A + M/(θΔt²)
//! The quasi-static mode drops M and A: G = F_int(u₁) − F_ext¹ − R₁, K̄ = K.

use crate::assembly::{BadElement, Discretisation};
use crate::contact::detect::{detect, ContactPoint};
use crate::contact::law::{BondState, ContactState, PointSolution};
use crate::contact::newton::{self, augmented_point, bipotential_projection, AugmentedPoint};
use crate::contact::solve::{delassus, gauss_seidel, Delassus};
use crate::linalg::LinalgError;
use crate::problem::{ContactSolver, Problem};
use crate::system::SystemMatrix;
use std::sync::Arc;

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
    /// Wall time of the successful attempt, by phase [s].
    pub timings: PhaseTimes,
}

/// Wall time spent in each phase of a step [s].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    /// Element loops: internal force and tangent.
    pub assembly: f64,
    /// Numeric factorisation of K̄ and the free solve.
    pub factorisation: f64,
    /// Contact detection, the Delassus operator W = H K̄⁻¹ Hᵀ (Gauss-Seidel solver) or the
    /// analysis of the contact couplings' pattern (Newton solver).
    pub delassus: f64,
    /// Gauss-Seidel over contact points, or the contact law and its tangent (Newton solver).
    pub contact_solve: f64,
}

/// The contact state of one slave node, committed at the end of every step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeContact {
    /// Intensity of adhesion β ∈ [0, 1].
    pub beta: f64,
    /// Bond stretch u_t in global axes [m].
    pub ut: [f64; 3],
    /// Dry force r̄ in the local frame (t₁, t₂, n) [N].
    pub r_dry: [f64; 3],
    /// Adhesive force r̃ in the local frame [N].
    pub r_adh: [f64; 3],
    /// Total contact force on the slave node in global axes [N].
    pub force: [f64; 3],
    /// Gap at the end of the step x_n [m] (NaN when the node is not a candidate).
    pub gap: f64,
    /// Slip increment over the step (t₁, t₂) [m].
    pub slip: [f64; 2],
    /// 0 not a candidate, 1 apart, 2 stick, 3 slide.
    pub state: i32,
    /// Tangent axes T₁, T₂ of the local frame (global components).
    pub tangent_axes: [[f64; 3]; 2],
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
    /// Committed contact state per pair and slave node.
    pub contact: Vec<Vec<NodeContact>>,
    /// Internal variables of the viscoelastic materials (see
    /// [`Discretisation::history`]).
    pub material_history: Vec<f64>,
}

/// Advances a [`Problem`] in time.
pub struct Stepper {
    /// The problem being solved.
    pub problem: Arc<Problem>,
    /// Its discretisation.
    pub disc: Discretisation,
    /// Committed state.
    pub state: State,
    mass: Vec<f64>,
    damping: Option<Vec<f64>>,
    /// Gravity force per unit acceleration along x, y, z [N/(m/s²)].
    gravity_force: [Vec<f64>; 3],
    system: SystemMatrix,
    constrained: Vec<bool>,
    dt: f64,
    good_steps_since_cut: usize,
    f_ext0: Vec<f64>,
    f_int0: Vec<f64>,
    external_work: f64,
    last_internal: f64,
    /// Committed contact state per pair and slave node.
    pub contact: Vec<Vec<NodeContact>>,
    /// Diagonal of the bounding box of the reference nodes [m].
    model_size: f64,
    /// The last Delassus operator and what it was built for (see [`delassus_key`]).
    delassus_cache: Option<(Vec<u64>, Delassus)>,
    /// Nodal reaction forces of the last committed step [N] (see [`Stepper::reactions`]).
    reactions: Vec<f64>,
}

struct Attempt {
    u: Vec<f64>,
    v: Vec<f64>,
    f_ext1: Vec<f64>,
    f_int1: Vec<f64>,
    iterations: usize,
    residual: f64,
    internal: f64,
    work: f64,
    points: Vec<ContactPoint>,
    solutions: Vec<PointSolution>,
    sweeps: usize,
    contact_residual: f64,
    delassus_builds: usize,
    timings: PhaseTimes,
    reactions: Vec<f64>,
}

impl Stepper {
    /// Discretises the problem and analyses the system matrix.
    pub fn new(problem: Arc<Problem>) -> Result<Self, SetupError> {
        let bodies: Vec<_> = problem
            .bodies
            .iter()
            .map(|b| (&b.mesh, b.material.clone()))
            .collect();
        let formulations: Vec<_> = problem.bodies.iter().map(|b| b.element).collect();
        let disc = Discretisation::with_formulations(&bodies, &formulations)
            .map_err(SetupError::BadElements)?;
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
        let mut constrained = vec![false; n];
        for d in &problem.dirichlet {
            for &node in &d.nodes {
                for k in 0..3 {
                    if d.components[k] {
                        constrained[3 * node + k] = true;
                    }
                }
            }
        }
        let system = SystemMatrix::new(disc.pattern.clone(), constrained.clone())?;
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
            problem,
            disc,
            state,
            mass,
            damping,
            gravity_force,
            system,
            constrained,
            good_steps_since_cut: 0,
            f_ext0: vec![0.0; n],
            f_int0: vec![0.0; n],
            external_work: 0.0,
            last_internal: 0.0,
            contact: Vec::new(),
            model_size: 0.0,
            delassus_cache: None,
            reactions: vec![0.0; n],
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
                    NodeContact {
                        gap: f64::NAN,
                        ..Default::default()
                    };
                    c.slave_nodes.len()
                ]
            })
            .collect();
        s.apply_dirichlet_to_state();
        s.f_ext0 = s.external_force(0.0);
        let a = s.disc.assemble(&s.state.u, false);
        s.f_int0 = a.force;
        s.last_internal = a.energy;
        Ok(s)
    }

    fn apply_dirichlet_to_state(&mut self) {
        let u = &mut self.state.u;
        for d in &self.problem.dirichlet {
            for &node in &d.nodes {
                let x = self.disc.reference[node];
                let ud = d.displacement(x, 0.0);
                for k in 0..3 {
                    if d.components[k] {
                        u[3 * node + k] = ud[k];
                    }
                }
            }
        }
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
        if !(snap.dt > 0.0) || !snap.t.is_finite() {
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
        self.disc.pattern.symmetric_matvec(&self.mass, v, &mut mv);
        0.5 * v.iter().zip(&mv).map(|(a, b)| a * b).sum::<f64>()
    }

    /// Advances one step, halving Δt on failure down to dt_min.
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        let ts = self.problem.time.clone();
        let mut cutbacks = 0;
        loop {
            let remaining = ts.t_end - self.state.t;
            let mut dt = self.dt.min(remaining);
            // Avoid a sliver of a last step.
            if remaining - dt < 1e-3 * dt {
                dt = remaining;
            }
            match self.attempt(dt) {
                Ok(a) => {
                    self.commit_contact(&a.points, &a.solutions);
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
                        residual: a.residual,
                        kinetic,
                        internal: a.internal,
                        external_work: self.external_work,
                        contact_sweeps,
                        contact_residual,
                        contact_points,
                        delassus_builds: a.delassus_builds,
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
                }
            }
        }
    }

    fn commit_contact(&mut self, points: &[ContactPoint], sols: &[PointSolution]) {
        for nodes in &mut self.contact {
            for n in nodes.iter_mut() {
                *n = NodeContact {
                    gap: f64::NAN,
                    ..Default::default()
                };
            }
        }
        for (pt, sol) in points.iter().zip(sols) {
            let f = &pt.frame;
            let r = sol.r();
            let global = |v: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|k| v[0] * f[0][k] + v[1] * f[1][k] + v[2] * f[2][k])
            };
            self.contact[pt.pair][pt.local] = NodeContact {
                beta: sol.beta,
                ut: global([sol.ut[0], sol.ut[1], 0.0]),
                r_dry: sol.r_dry,
                r_adh: sol.r_adh,
                force: global(r),
                gap: sol.x[2],
                slip: [sol.x[0], sol.x[1]],
                state: match sol.state {
                    ContactState::Apart => 1,
                    ContactState::Stick => 2,
                    ContactState::Slide => 3,
                },
                tangent_axes: [f[0], f[1]],
            };
        }
    }

    /// Committed bond state of each contact point, in its local frame.
    fn bonds_at_start(&self, points: &[ContactPoint]) -> Vec<BondState> {
        points
            .iter()
            .map(|pt| {
                let c = &self.contact[pt.pair][pt.local];
                let f = &pt.frame;
                let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                BondState {
                    beta: c.beta,
                    ut: [dot(c.ut, f[0]), dot(c.ut, f[1])],
                }
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

    /// Drops the Delassus operator kept for reuse (the next contact solve builds its own).
    pub fn forget_delassus(&mut self) {
        self.delassus_cache = None;
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
                let n = crate::contact::detect::cross(t1, t2);
                let g: [f64; 3] = std::array::from_fn(|k| {
                    c.r_dry[0] * t1[k] + c.r_dry[1] * t2[k] + c.r_dry[2] * n[k]
                });
                pt.frame
                    .map(|axis| axis[0] * g[0] + axis[1] * g[1] + axis[2] * g[2])
            })
            .collect()
    }

    /// One Newton solve over [t, t+dt]; Err with the reason on failure.
    fn attempt(&mut self, dt: f64) -> Result<Attempt, String> {
        self.disc.begin_step(dt);
        let ts = self.problem.time.clone();
        let (theta, xi, qs) = (ts.theta, ts.xi, ts.quasi_static);
        let newton_contact = ts.contact_solver == ContactSolver::Newton;
        let t1 = self.state.t + dt;
        let n = self.disc.num_dofs();
        let f_ext1 = self.external_force(t1);
        let mut timings = PhaseTimes::default();
        let clock = std::time::Instant::now();
        let points = if self.problem.contacts.is_empty() {
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
        let bond0 = self.bonds_at_start(&points);
        // Force the adhesive bonds of the candidates can carry, ‖(A_α √(C w))_α‖ [N]: the force
        // scale of an interface that holds (or snaps into) contact without load.
        let bond_strength = points
            .iter()
            .map(|pt| {
                let law = &self.problem.contacts[pt.pair].law;
                law.adhesion
                    .map_or(0.0, |a| (pt.area * a.peak_traction()).powi(2))
            })
            .sum::<f64>()
            .sqrt();
        let laws: Vec<_> = self.problem.contacts.iter().map(|c| c.law).collect();
        let mut r_contact: Vec<[f64; 3]> = vec![[0.0; 3]; points.len()];
        let mut r_dry: Vec<[f64; 3]> = vec![[0.0; 3]; points.len()];
        let mut solutions: Vec<PointSolution> = Vec::new();
        let mut sweeps = 0;
        let mut contact_force = vec![0.0; n];
        // Newton contact solve: multipliers (warm-started from the committed dry forces),
        // augmentation parameters (set at the first iteration) and the law at the iterate.
        let mut lambda = self.multipliers_at_start(&points);
        let mut rho: Vec<f64> = Vec::new();
        let mut evals: Vec<AugmentedPoint> = Vec::new();
        let mut contact_residual = 0.0;
        if newton_contact && !points.is_empty() {
            self.system
                .ensure_couplings(&newton::couplings(&points))
                .map_err(|e| e.to_string())?;
        }
        timings.delassus += clock.elapsed().as_secs_f64();
        let u0 = &self.state.u;
        let v0 = &self.state.v;
        // Predictor: constant velocity for dynamics, last state for quasi-static.
        let mut u: Vec<f64> = if qs {
            u0.clone()
        } else {
            (0..n).map(|i| u0[i] + dt * v0[i]).collect()
        };
        for d in &self.problem.dirichlet {
            for &node in &d.nodes {
                let ud = d.displacement(self.disc.reference[node], t1);
                for k in 0..3 {
                    if d.components[k] {
                        u[3 * node + k] = ud[k];
                    }
                }
            }
        }
        // Terms fixed over the step: (1−ξ)(F_ext⁰ − F_int⁰ − A v₀).
        let mut fixed = vec![0.0; n];
        if !qs {
            let mut av0 = vec![0.0; n];
            if let Some(a) = &self.damping {
                self.disc.pattern.symmetric_matvec(a, v0, &mut av0);
            }
            for i in 0..n {
                fixed[i] = (1.0 - xi) * (self.f_ext0[i] - self.f_int0[i] - av0[i]);
            }
        }
        let c_mass = if qs { 0.0 } else { 1.0 / (theta * dt * dt) };
        let c_damp = if qs { 0.0 } else { xi / (theta * dt) };
        let c_stiff = if qs { 1.0 } else { xi };
        let mut g = vec![0.0; n];
        let mut tmp = vec![0.0; n];
        let mut last_correction_negligible = false;
        let mut last_rel = f64::NAN;
        let mut line_search: Option<LineSearch> = None;
        let mut contact_energy = 0.0;
        let mut prev_du_norm: Option<f64> = None;
        let mut delassus_builds = 0usize;
        // Whether this attempt has built or checked the Delassus operator in use.
        let mut delassus_checked = false;
        let delassus_key = if newton_contact {
            Vec::new()
        } else {
            delassus_key(&points, dt)
        };
        for iter in 1..=ts.max_newton {
            let clock = std::time::Instant::now();
            let asm = self.disc.assemble(&u, true);
            timings.assembly += clock.elapsed().as_secs_f64();
            if !(asm.min_j > 0.0) || !asm.energy.is_finite() {
                return Err(format!(
                    "an element inverted (min det F = {:.3e}) at Newton iteration {iter}",
                    asm.min_j
                ));
            }
            let v1: Vec<f64> = (0..n)
                .map(|i| (u[i] - u0[i]) / (theta * dt) - (1.0 - theta) / theta * v0[i])
                .collect();
            // Residual.
            for i in 0..n {
                g[i] = c_stiff * (asm.force[i] - f_ext1[i]) - fixed[i];
            }
            let mut scale = norm(&asm.force).max(norm(&f_ext1)).max(norm(&fixed));
            // The step's potential Π(u), whose gradient is g (for the line search): strain
            // energy, loads, and the inertia and damping terms of the θ-method.
            let mut potential = c_stiff * asm.energy
                - (0..n)
                    .map(|i| (c_stiff * f_ext1[i] + fixed[i]) * u[i])
                    .sum::<f64>();
            if !qs {
                tmp.iter_mut().for_each(|x| *x = 0.0);
                let acc: Vec<f64> = (0..n)
                    .map(|i| (u[i] - u0[i] - dt * v0[i]) * c_mass)
                    .collect();
                self.disc
                    .pattern
                    .symmetric_matvec(&self.mass, &acc, &mut tmp);
                scale = scale.max(norm(&tmp));
                for i in 0..n {
                    g[i] += tmp[i];
                    potential += 0.5 * (u[i] - u0[i] - dt * v0[i]) * tmp[i];
                }
                if let Some(a) = &self.damping {
                    tmp.iter_mut().for_each(|x| *x = 0.0);
                    self.disc.pattern.symmetric_matvec(a, &v1, &mut tmp);
                    for i in 0..n {
                        g[i] += xi * tmp[i];
                    }
                    // ξ A v₁ is the gradient of ξ[(u − u₀)ᵀA(u − u₀)/(2θΔt) − (1−θ)/θ v₀ᵀA(u − u₀)].
                    let half: Vec<f64> = (0..n)
                        .map(|i| {
                            0.5 * (u[i] - u0[i]) / (theta * dt) - (1.0 - theta) / theta * v0[i]
                        })
                        .collect();
                    tmp.iter_mut().for_each(|x| *x = 0.0);
                    self.disc.pattern.symmetric_matvec(a, &half, &mut tmp);
                    potential += xi * (0..n).map(|i| (u[i] - u0[i]) * tmp[i]).sum::<f64>();
                }
            }
            let mut natural_map = 0.0;
            if iter == 1 && !points.is_empty() {
                rho = self.augmentation(&points, &asm.tangent, c_stiff, c_mass, c_damp);
            }
            if newton_contact && !points.is_empty() {
                let clock = std::time::Instant::now();
                // The contact law at u with the multipliers of the last Newton step.
                (evals, contact_force) =
                    self.contact_law_at(&points, &laws, &bond0, dt, &rho, &lambda, &u);
                let merit = norm_free(&g, &contact_force, &self.constrained);
                let total: f64 = potential + evals.iter().map(|e| e.energy).sum::<f64>();
                // Line search on that step: with the multipliers fixed, the Newton step
                // solves for a stationary point of Π(u) + Σ φ_α(x_α(u)), and its matrix is
                // positive definite, so the step is a descent direction. A step that does not
                // lower that potential by the Armijo factor is halved (a full step can
                // overshoot where points open or close, and then cycle).
                if let Some(ls) = &mut line_search {
                    let same_cases = evals
                        .iter()
                        .zip(&ls.cases)
                        .all(|(e, c)| e.solution.state == *c);
                    // Near the solution the potential's decrease drowns in its round-off:
                    // a step that reduces ‖G − Hᵀr‖ is accepted as well.
                    let descent = total <= ls.energy0 + 1e-4 * ls.alpha * ls.slope
                        || merit <= (1.0 - 1e-4 * ls.alpha) * ls.merit0;
                    if (same_cases || iter > CYCLING_ITERATIONS)
                        && !descent
                        && ls.alpha > MIN_STEP_LENGTH
                    {
                        ls.alpha *= 0.5;
                        for i in 0..n {
                            u[i] = ls.u0[i] + ls.alpha * ls.du[i];
                        }
                        timings.contact_solve += clock.elapsed().as_secs_f64();
                        continue;
                    }
                }
                line_search = None;
                contact_energy = total;
                let contact_defect = newton::defect_norm(&evals);
                // Multiplier update λ ← P_K(λ − ρ x̂(u)) once the equilibrium with the current
                // multipliers is reached to a tenth of the change the update would make.
                if iter > 1 && merit <= 0.1 * contact_defect {
                    for (l, e) in lambda.iter_mut().zip(&evals) {
                        *l = e.solution.r_dry;
                    }
                    sweeps += 1;
                    (evals, contact_force) =
                        self.contact_law_at(&points, &laws, &bond0, dt, &rho, &lambda, &u);
                    contact_energy = potential + evals.iter().map(|e| e.energy).sum::<f64>();
                }
                let solved: Vec<PointSolution> = evals.iter().map(|e| e.solution).collect();
                natural_map = natural_map_residual(&laws, &points, &rho, &solved);
                timings.contact_solve += clock.elapsed().as_secs_f64();
            }
            // g is G(u) without contact (what the Newton correction solves against); the
            // convergence check uses G(u) − Hᵀr.
            let mut g_check: Vec<f64> = (0..n).map(|i| g[i] - contact_force[i]).collect();
            let reactions: Vec<f64> = (0..n)
                .map(|i| if self.constrained[i] { g_check[i] } else { 0.0 })
                .collect();
            for i in 0..n {
                if self.constrained[i] {
                    g[i] = 0.0;
                    g_check[i] = 0.0;
                }
            }
            scale = scale.max(norm(&contact_force)).max(bond_strength);
            let gnorm = norm(&g_check);
            if !gnorm.is_finite() {
                return Err(format!(
                    "the residual is not finite at Newton iteration {iter}"
                ));
            }
            // Force scale of the current iterate (internal, external, inertial forces and
            // support reactions), so that a large out-of-balance force of an early iterate
            // does not make later residuals look small.
            let scale = scale.max(norm(&reactions)).max(f64::MIN_POSITIVE);
            let rel = gnorm / scale;
            last_rel = rel;
            if newton_contact {
                contact_residual = natural_map / scale;
            }
            // Converged when the residual is small against the forces, or when the last
            // correction was negligible against the step's displacement increment (the
            // residual can sit at its round-off floor when every force is small, e.g. a
            // vibrating body passing through its rest position), and the contact forces
            // satisfy the contact law. With contact candidates, the contact problem must have
            // been solved at least once.
            let contact_solved =
                points.is_empty() || (iter > 1 && contact_residual <= ts.contact_tol);
            if contact_solved
                && (rel <= ts.newton_tol || gnorm == 0.0 || last_correction_negligible)
            {
                let du: Vec<f64> = (0..n).map(|i| u[i] - u0[i]).collect();
                let mut work = 0.0;
                for i in 0..n {
                    let f_applied = if qs {
                        f_ext1[i]
                    } else {
                        (1.0 - xi) * self.f_ext0[i] + xi * f_ext1[i]
                    };
                    work += du[i] * (f_applied + reactions[i] + contact_force[i]);
                }
                if newton_contact {
                    solutions = evals.iter().map(|e| e.solution).collect();
                }
                return Ok(Attempt {
                    v: if qs {
                        du.iter().map(|d| d / dt).collect()
                    } else {
                        v1
                    },
                    u,
                    f_ext1,
                    f_int1: asm.force,
                    iterations: iter - 1,
                    residual: rel,
                    internal: asm.energy,
                    work,
                    points,
                    solutions,
                    sweeps,
                    contact_residual,
                    delassus_builds,
                    timings,
                    reactions,
                });
            }
            if iter == ts.max_newton {
                break;
            }
            let clock = std::time::Instant::now();
            // K̄ = c_stiff K + c_damp A + c_mass M (+ the contact law's stiffness).
            let mut terms: Vec<(f64, &[f64])> = vec![(c_stiff, &asm.tangent), (c_mass, &self.mass)];
            if let Some(a) = &self.damping {
                terms.push((c_damp, a));
            }
            self.system.set_from_base(&terms);
            if newton_contact && !points.is_empty() {
                let stiffness: Vec<_> = evals.iter().map(|e| e.stiffness).collect();
                let pattern = self.system.pattern().clone();
                newton::add_contact_tangent(&points, &stiffness, &pattern, &mut self.system.values);
            }
            self.system
                .factorise()
                .map_err(|e| format!("{e} (Newton iteration {iter})"))?;
            // Newton correction against the residual with the current contact forces Hᵀr.
            // Gauss-Seidel: the contact solve then corrects it by K̄⁻¹Hᵀ(r − r_prev). At a
            // converged iterate r = r_prev and G(u) = Hᵀr whatever W was used, so W may be
            // reused from an earlier iteration or step (it then only slows the convergence).
            let mut du: Vec<f64> = (0..n).map(|i| contact_force[i] - g[i]).collect();
            self.system.solve_in_place(&mut du);
            timings.factorisation += clock.elapsed().as_secs_f64();
            if !newton_contact && !points.is_empty() {
                let clock = std::time::Instant::now();
                let du_norm = norm(&du);
                let slow = prev_du_norm.is_some_and(|p| du_norm > DELASSUS_REUSE_RATIO * p);
                prev_du_norm = Some(du_norm);
                let mut reusable =
                    matches!(&self.delassus_cache, Some((k, _)) if *k == delassus_key);
                // A W from an earlier step, or a slow convergence, is checked before reuse.
                // Slow convergence comes from the nonsmooth contact laws as often as from a
                // stale W: probe three columns of the current W (at the point carrying the
                // largest force; the first point while r_contact is still zero) and rebuild
                // only when they differ from the cached ones.
                if reusable && (slow || !delassus_checked) {
                    delassus_checked = true;
                    let probe = r_contact
                        .iter()
                        .enumerate()
                        .max_by(|a, b| norm(a.1).total_cmp(&norm(b.1)))
                        .map(|(p, _)| p)
                        .unwrap_or(0);
                    let cached = &self.delassus_cache.as_ref().expect("checked").1;
                    reusable = cached.probed_change(
                        &points,
                        probe,
                        self.system.cholesky(),
                        &self.constrained,
                    ) <= DELASSUS_STALE_TOL;
                }
                if !reusable {
                    let del = delassus(&points, self.system.cholesky(), &self.constrained);
                    self.delassus_cache = Some((delassus_key.clone(), del));
                    delassus_builds += 1;
                    delassus_checked = true;
                }
                let del = &self.delassus_cache.as_ref().expect("built above").1;
                let m = del.m;
                // Reduced contact system: x = x(u) + H Δu_free + W (r − r_prev).
                let x_free: Vec<[f64; 3]> = points
                    .iter()
                    .enumerate()
                    .map(|(p, pt)| {
                        let x = pt.local_x(&self.disc.reference, &u);
                        let h = pt.apply_h(&du);
                        let mut xf = [x[0] + h[0], x[1] + h[1], x[2] + h[2]];
                        for (a, xa) in xf.iter_mut().enumerate() {
                            let row = &del.w[(3 * p + a) * m..(3 * p + a + 1) * m];
                            for (q, rq) in r_contact.iter().enumerate() {
                                *xa -= row[3 * q] * rq[0]
                                    + row[3 * q + 1] * rq[1]
                                    + row[3 * q + 2] * rq[2];
                            }
                        }
                        xf
                    })
                    .collect();
                timings.delassus += clock.elapsed().as_secs_f64();
                let clock = std::time::Instant::now();
                let sol = gauss_seidel(
                    &points, &laws, &bond0, dt, del, &x_free, &r_contact, &r_dry, 1e-10, 5000,
                );
                sweeps += sol.sweeps;
                timings.contact_solve += clock.elapsed().as_secs_f64();
                if !sol.converged {
                    self.delassus_cache = None;
                    return Err(format!("the contact solve did not settle in {} Gauss-Seidel sweeps (Newton iteration {iter})", sol.sweeps));
                }
                let clock = std::time::Instant::now();
                let mut new_force = vec![0.0; n];
                for (p, ps) in sol.points.iter().enumerate() {
                    let r = ps.r();
                    r_contact[p] = r;
                    r_dry[p] = ps.r_dry;
                    points[p].add_ht(r, &mut new_force);
                }
                for i in 0..n {
                    if self.constrained[i] {
                        new_force[i] = 0.0;
                    }
                }
                let mut dc: Vec<f64> = (0..n).map(|i| new_force[i] - contact_force[i]).collect();
                self.system.solve_in_place(&mut dc);
                for i in 0..n {
                    du[i] += dc[i];
                }
                contact_force = new_force;
                solutions = sol.points;
                contact_residual = natural_map_residual(&laws, &points, &rho, &solutions) / scale;
                timings.delassus += clock.elapsed().as_secs_f64();
            }
            if newton_contact && !points.is_empty() {
                line_search = Some(LineSearch {
                    cases: evals.iter().map(|e| e.solution.state).collect(),
                    slope: (0..n)
                        .filter(|&i| !self.constrained[i])
                        .map(|i| (g[i] - contact_force[i]) * du[i])
                        .sum(),
                    u0: u.clone(),
                    du: du.clone(),
                    alpha: 1.0,
                    energy0: contact_energy,
                    merit0: gnorm,
                });
            }
            for i in 0..n {
                u[i] += du[i];
            }
            let increment = (0..n).map(|i| (u[i] - u0[i]).powi(2)).sum::<f64>().sqrt();
            // The floor (1e-6 of the model size) covers steps in which nothing moves.
            last_correction_negligible =
                norm(&du) <= ts.newton_tol * increment.max(1e-6 * self.model_size);
        }
        self.delassus_cache = None;
        Err(format!(
            "Newton did not converge in {} iterations (residual {:.2e}, contact residual {:.2e})",
            ts.max_newton, last_rel, contact_residual
        ))
    }

    /// The contact law of every point at displacement `u` with multipliers `lambda`, and the
    /// contact force Hᵀr on the free unknowns.
    #[allow(clippy::too_many_arguments)]
    fn contact_law_at(
        &self,
        points: &[ContactPoint],
        laws: &[crate::contact::InterfaceLaw],
        bond0: &[BondState],
        dt: f64,
        rho: &[f64],
        lambda: &[[f64; 3]],
        u: &[f64],
    ) -> (Vec<AugmentedPoint>, Vec<f64>) {
        let evals: Vec<AugmentedPoint> = points
            .iter()
            .enumerate()
            .map(|(p, pt)| {
                let x = pt.local_x(&self.disc.reference, u);
                augmented_point(&laws[pt.pair], bond0[p], dt, pt.area, rho[p], lambda[p], x)
            })
            .collect();
        let mut force = vec![0.0; u.len()];
        for (pt, ev) in points.iter().zip(&evals) {
            pt.add_ht(ev.solution.r(), &mut force);
        }
        for (f, &fixed) in force.iter_mut().zip(&self.constrained) {
            if fixed {
                *f = 0.0;
            }
        }
        (evals, force)
    }

    /// Augmentation parameter ρ_α [N/m] of each point: [`newton::RHO_FACTOR`] times the
    /// stiffness K̄ = c_stiff K + c_mass M + c_damp A shows there.
    fn augmentation(
        &self,
        points: &[ContactPoint],
        tangent: &[f64],
        c_stiff: f64,
        c_mass: f64,
        c_damp: f64,
    ) -> Vec<f64> {
        let pattern = &self.disc.pattern;
        let diagonal: Vec<f64> = (0..pattern.dim())
            .map(|d| {
                let q = pattern.diagonal_position(d);
                let a = self.damping.as_ref().map_or(0.0, |a| a[q]);
                c_stiff * tangent[q] + c_mass * self.mass[q] + c_damp * a
            })
            .collect();
        points
            .iter()
            .map(|pt| {
                newton::point_stiffness(pt, &diagonal, &self.constrained)
                    .map_or(1.0, |k| newton::RHO_FACTOR * k)
            })
            .collect()
    }
}

/// Natural-map residual ‖(r̄_α − P_K(r̄_α − ρ_α x̂_α))_α‖ [N] of the bi-potential condition,
/// at each solution's own x, with the ρ_α of the Newton solver: the same measure for both
/// solvers.
fn natural_map_residual(
    laws: &[crate::contact::InterfaceLaw],
    points: &[ContactPoint],
    rho: &[f64],
    solutions: &[PointSolution],
) -> f64 {
    points
        .iter()
        .zip(rho)
        .zip(solutions)
        .map(|((pt, &rho), sol)| {
            let p = bipotential_projection(laws[pt.pair].mu, rho, sol.r_dry, sol.x);
            (0..3).map(|k| (sol.r_dry[k] - p[k]).powi(2)).sum::<f64>()
        })
        .sum::<f64>()
        .sqrt()
}

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

/// Newton iterations after which a step that changes the contact cases is line-searched too.
const CYCLING_ITERATIONS: usize = 0;

/// Shortest step length the line search tries before it takes the step anyway.
const MIN_STEP_LENGTH: f64 = 1.0 / 64.0;

/// ‖g − f‖ over the free unknowns.
fn norm_free(g: &[f64], f: &[f64], constrained: &[bool]) -> f64 {
    g.iter()
        .zip(f)
        .zip(constrained)
        .filter(|(_, &c)| !c)
        .map(|((a, b), _)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt()
}

/// A Newton correction larger than this fraction of the previous one means the contact
/// coupling is converging slowly: W is rebuilt with the current factorisation.
const DELASSUS_REUSE_RATIO: f64 = 0.5;

/// Relative change of probed columns of W above which the cached W is rebuilt.
const DELASSUS_STALE_TOL: f64 = 1e-4;

/// What W depends on besides K̄: the contact points (pair, node, frame, master weights) and
/// Δt (K̄ = ξK + M/(θΔt²) + ...). Compared bit for bit.
fn delassus_key(points: &[ContactPoint], dt: f64) -> Vec<u64> {
    let mut key = Vec::with_capacity(points.len() * 12 + 1);
    key.push(dt.to_bits());
    for p in points {
        key.push(p.pair as u64);
        key.push(p.slave as u64);
        for row in &p.frame {
            key.extend(row.iter().map(|x| x.to_bits()));
        }
        for &(m, w) in &p.master {
            key.push(m as u64);
            key.push(w.to_bits());
        }
    }
    key
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|a| a * a).sum::<f64>().sqrt()
}
