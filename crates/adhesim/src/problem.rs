//! A validated problem: everything the stepper needs, in SI units, with node sets resolved
//! to global node indices. Built from a scenario file by `adhesim_io::scenario`, or directly
//! in code.

use crate::material::Hyperelastic;
use crate::mesh::Mesh;
pub use crate::prescribed::{rotate, Rotation, Table};
use std::sync::Arc;

/// Prescribed displacement of a node set: u(X, t) = T(t) + (R(t) − I)(X − c).
#[derive(Clone, Debug, PartialEq)]
pub struct Dirichlet {
    /// Global node indices.
    pub nodes: Vec<usize>,
    /// Which components (x, y, z) are prescribed.
    pub components: [bool; 3],
    /// Translation per component [m].
    pub translation: [Table; 3],
    /// Optional rigid rotation (applied before the translation).
    pub rotation: Option<Rotation>,
}

impl Dirichlet {
    /// Prescribed displacement [m] at time `t` of a node with reference position `x`.
    pub fn displacement(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let mut u: [f64; 3] = std::array::from_fn(|k| self.translation[k].at(t));
        if let Some(r) = &self.rotation {
            let d: [f64; 3] = std::array::from_fn(|k| x[k] - r.center[k]);
            let rd = rotate(d.into(), r.axis.into(), r.angle.at(t));
            for k in 0..3 {
                u[k] += rd[k] - d[k];
            }
        }
        u
    }
}

/// A force distributed equally over the nodes of a set.
#[derive(Clone, Debug, PartialEq)]
pub struct NodalLoad {
    /// Global node indices.
    pub nodes: Vec<usize>,
    /// Total force on the set per component, as functions of time [N].
    pub total_force: [Table; 3],
}

/// A deformable body.
#[derive(Clone, Debug)]
pub struct Body {
    /// Name used in outputs.
    pub name: String,
    /// Reference mesh.
    pub mesh: Mesh,
    /// Constitutive law.
    pub material: Arc<dyn Hyperelastic>,
    /// Mass density [kg/m³].
    pub density: f64,
    /// Initial velocity [m/s] of every node.
    pub initial_velocity: [f64; 3],
    /// Element kinematics of the body's hexahedra (standard or F-bar).
    pub element: crate::fbar::Formulation,
    /// Plane strain in the x-y plane (docs/model.md §1): the nodes of a line through the
    /// thickness move alike (their out-of-plane displacement is held by a Dirichlet
    /// condition of the problem).
    pub plane_strain: bool,
}

/// Time integration settings (docs/model.md §3).
#[derive(Clone, Debug, PartialEq)]
pub struct TimeSettings {
    /// End time [s].
    pub t_end: f64,
    /// Initial and largest time step [s].
    pub dt: f64,
    /// Smallest time step before the run gives up [s].
    pub dt_min: f64,
    /// θ of the velocity update (eq 63), in (0, 1].
    pub theta: f64,
    /// ξ of the force average, in [0, 1].
    pub xi: f64,
    /// Drop inertia and damping (quasi-static load stepping).
    pub quasi_static: bool,
    /// Relative tolerance on the residual and on the displacement increment.
    pub newton_tol: f64,
    /// Most Newton iterations in one step before it is cut back.
    pub max_newton: usize,
    /// Lump the mass matrix (row sums) instead of the consistent mass.
    pub lumped_mass: bool,
    /// Rayleigh damping A = alpha_m M + beta_k K₀ [1/s], [s].
    pub rayleigh: (f64, f64),
    /// How the contact conditions are solved.
    pub contact_solver: ContactSolver,
    /// Tolerance on the contact residual (natural map of the dry contact forces, relative to
    /// the step's force scale; docs/contact-solver.md).
    pub contact_tol: f64,
    /// Whether Newton factorises K̄ at every iteration or keeps a factorisation while the
    /// iterations converge (docs/scaling.md).
    pub newton: NewtonMethod,
    /// The first iterate of a quasi-static step (dynamic steps start from constant velocity).
    pub predictor: Predictor,
}

/// Where the Newton iterations of a quasi-static step start, before the prescribed
/// displacements at the step's end are imposed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Predictor {
    /// The last converged state u₀.
    #[default]
    Last,
    /// The last step's increment carried on: u₀ + Δt v₀, v₀ being the last step's mean rate
    /// (u₀ − u₋₁)/Δt₋₁ (the first step starts from u₀). It saves Newton iterations where the
    /// load moves steadily and costs some where it stops or turns (docs/scenario.md).
    Secant,
}

/// How the Newton iterations of a step use the factorisation of K̄.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NewtonMethod {
    /// `Preconditioned` for a step whose contact is solved inside the Newton loop (the
    /// augmented-Lagrangian solve), `Full` otherwise ([`NewtonMethod::for_contact`]).
    #[default]
    Auto,
    /// A new factorisation for every Newton correction (and for every direction of the
    /// semismooth contact solve).
    Full,
    /// The Newton loop keeps its factorisation, within and across steps, while the
    /// iterations contract with it ([`crate::time::factor_reuse`]), and factorises again
    /// when they do not; a step that does not converge so is solved again with full Newton.
    /// The semismooth contact solve factorises as under `Full`.
    Modified,
    /// Each Newton correction is solved with the matrix of its own iterate, by GMRES
    /// preconditioned with the factorisation the loop keeps, within and across steps
    /// ([`crate::time::factor_reuse`]); the loop factorises again when GMRES does not reach its
    /// tolerance or needed many iterations. The semismooth contact solve factorises as under
    /// `Full`.
    Preconditioned,
}

impl NewtonMethod {
    /// The method of a step whose contact solver is `solver`: `Auto` resolved, the others
    /// kept. Only the augmented-Lagrangian solve leaves K̄ to the Newton loop alone; the
    /// Gauss-Seidel solve builds W from K̄'s factorisation, which must then be that of the
    /// iterate, and the semismooth solve factorises its own matrices.
    pub fn for_contact(self, solver: ContactSolver) -> NewtonMethod {
        match (self, solver) {
            (NewtonMethod::Auto, ContactSolver::Newton) => NewtonMethod::Preconditioned,
            (NewtonMethod::Auto, _) => NewtonMethod::Full,
            (other, _) => other,
        }
    }
}

/// How the contact conditions are solved in each Newton iteration (docs/contact-solver.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactSolver {
    /// The contact law inside the step's Newton loop, its generalised Jacobian in the sparse
    /// matrix, with augmented-Lagrangian multiplier updates: no Delassus operator.
    Newton,
    /// Semismooth Newton on the contact forces, each direction from the step's sparse
    /// factorisation and GMRES: no Delassus operator.
    Semismooth,
    /// The reduced system on the dense Delassus operator W = H K̄⁻¹ Hᵀ, solved by nonlinear
    /// Gauss-Seidel over contact points (small problems, cross-checks).
    GaussSeidel,
    /// The augmented-Lagrangian solve for a step whose contact candidates are all
    /// frictionless and without adhesion; otherwise Gauss-Seidel for a step with fewer than
    /// [`AUTO_SEMISMOOTH_FROM`] candidates and the semismooth solve from there on.
    #[default]
    Auto,
    /// `Auto` without the augmented-Lagrangian solve: what `Auto` becomes in a run once that
    /// solve has failed on one of its steps.
    AutoWithoutNewton,
}

/// Contact candidates from which [`ContactSolver::Auto`] solves a step without W. Measured
/// (docs/contact-solver.md): Gauss-Seidel with a reused W is about 10 % faster on the
/// README example (at most 47 points in contact, with adhesion), the semismooth solve about 30 %
/// faster on the pad at 100 contact nodes, 17 % on the 4.4 twist (441) and 3 times at 1,024.
/// The switch sits above the first, where W is 3 MB.
pub const AUTO_SEMISMOOTH_FROM: usize = 200;

/// Largest number of contact candidates for which a step whose semismooth solve (chosen by
/// [`ContactSolver::Auto`]) failed is tried again with Gauss-Seidel on W before Δt is cut:
/// W then holds at most (3 × 2,000)² values, 288 MB, built from 6,000 solves with K̄'s
/// factorisation.
pub const AUTO_GAUSS_SEIDEL_RETRY_MAX: usize = 2_000;

impl ContactSolver {
    /// The solver used for a step with `candidates` contact candidates, all frictionless
    /// and without adhesion when `frictionless_dry`. Measured (docs/contact-solver.md): on the
    /// frictionless pad at 10⁴ contact nodes the augmented-Lagrangian solve with the
    /// preconditioned Newton loop takes 0.45 of the semismooth solve's time, and at 100
    /// contact nodes 0.59 of Gauss-Seidel's (0.75 on the tet4 Hertz cap, 74 points). A step
    /// without candidates keeps Gauss-Seidel, which then does nothing, and full Newton.
    pub fn for_step(self, candidates: usize, frictionless_dry: bool) -> ContactSolver {
        match self {
            ContactSolver::Auto if frictionless_dry && candidates > 0 => ContactSolver::Newton,
            ContactSolver::Auto if candidates < AUTO_SEMISMOOTH_FROM => ContactSolver::GaussSeidel,
            ContactSolver::Auto => ContactSolver::Semismooth,
            ContactSolver::AutoWithoutNewton => ContactSolver::Auto.for_step(candidates, false),
            other => other,
        }
    }
}

impl Default for TimeSettings {
    fn default() -> Self {
        TimeSettings {
            t_end: 1.0,
            dt: 0.01,
            dt_min: 1e-8,
            theta: 0.5,
            xi: 0.5,
            quasi_static: false,
            newton_tol: 1e-8,
            max_newton: 25,
            lumped_mass: false,
            rayleigh: (0.0, 0.0),
            contact_solver: ContactSolver::Auto,
            contact_tol: 1e-8,
            newton: NewtonMethod::Full,
            predictor: Predictor::Last,
        }
    }
}

/// Everything the stepper needs: the physics of a run (what it writes is
/// `adhesim_io::output::settings::OutputSettings`).
#[derive(Clone, Debug)]
pub struct Problem {
    /// Name of the run (file stem of outputs).
    pub name: String,
    /// Bodies, in global node order.
    pub bodies: Vec<Body>,
    /// Prescribed displacements.
    pub dirichlet: Vec<Dirichlet>,
    /// Nodal loads.
    pub loads: Vec<NodalLoad>,
    /// Gravity acceleration over time [m/s²].
    pub gravity: crate::gravity::Gravity,
    /// Time integration.
    pub time: TimeSettings,
    /// Contact pairs.
    pub contacts: Vec<crate::contact::ContactPair>,
}

impl Problem {
    /// First global node index of each body.
    pub fn node_offsets(&self) -> Vec<usize> {
        let mut off = Vec::with_capacity(self.bodies.len());
        let mut n = 0;
        for b in &self.bodies {
            off.push(n);
            n += b.mesh.num_nodes();
        }
        off
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_interpolates_and_holds_its_end_values() {
        let tab = Table {
            t: vec![0.0, 1.0, 3.0],
            v: vec![0.0, -1.0, -1.0],
        };
        assert_eq!(tab.at(-1.0), 0.0);
        assert_eq!(tab.at(0.5), -0.5);
        assert_eq!(tab.at(2.0), -1.0);
        assert_eq!(tab.at(10.0), -1.0);
    }

    #[test]
    fn rotation_about_y_turns_x_into_minus_z() {
        let r = rotate(
            crate::Vec3::x(),
            crate::Vec3::y(),
            std::f64::consts::FRAC_PI_2,
        );
        assert!((r[0]).abs() < 1e-15 && (r[2] + 1.0).abs() < 1e-15);
    }

    #[test]
    fn rigid_rotation_keeps_distances_to_the_axis() {
        let d = Dirichlet {
            nodes: vec![],
            components: [true; 3],
            translation: [
                Table::constant(0.0),
                Table::constant(0.0),
                Table::constant(0.0),
            ],
            rotation: Some(Rotation {
                center: [1.0, 0.0, 1.0],
                axis: [0.0, 1.0, 0.0],
                angle: Table::constant(0.7),
            }),
        };
        let x = [2.0, 3.0, 1.5];
        let u = d.displacement(x, 0.0);
        let r0 = ((x[0] - 1.0f64).powi(2) + (x[2] - 1.0f64).powi(2)).sqrt();
        let r1 = ((x[0] + u[0] - 1.0f64).powi(2) + (x[2] + u[2] - 1.0f64).powi(2)).sqrt();
        assert!((r0 - r1).abs() < 1e-14 && u[1].abs() < 1e-15);
    }
}

#[cfg(test)]
mod contact_solver_tests {
    use super::*;

    /// "auto" switches to the solve without W at the threshold; the named solvers are kept.
    #[test]
    fn auto_takes_the_solve_without_w_from_the_threshold_on() {
        let auto = ContactSolver::Auto;
        assert_eq!(auto.for_step(0, false), ContactSolver::GaussSeidel);
        assert_eq!(
            auto.for_step(AUTO_SEMISMOOTH_FROM - 1, false),
            ContactSolver::GaussSeidel
        );
        assert_eq!(
            auto.for_step(AUTO_SEMISMOOTH_FROM, false),
            ContactSolver::Semismooth
        );
        for s in [
            ContactSolver::GaussSeidel,
            ContactSolver::Semismooth,
            ContactSolver::Newton,
        ] {
            assert_eq!(s.for_step(10 * AUTO_SEMISMOOTH_FROM, false), s);
            assert_eq!(s.for_step(1, false), s);
            assert_eq!(s.for_step(10 * AUTO_SEMISMOOTH_FROM, true), s);
        }
    }

    /// Frictionless dry steps with candidates take the augmented-Lagrangian solve at any
    /// size, and the "auto" Newton method keeps its factorisation as a preconditioner there
    /// only.
    #[test]
    fn auto_takes_the_augmented_lagrangian_for_frictionless_dry_steps() {
        let auto = ContactSolver::Auto;
        for candidates in [1, AUTO_SEMISMOOTH_FROM - 1, AUTO_SEMISMOOTH_FROM] {
            assert_eq!(auto.for_step(candidates, true), ContactSolver::Newton);
        }
        assert_eq!(auto.for_step(0, true), ContactSolver::GaussSeidel);
        assert_eq!(
            auto.for_step(AUTO_SEMISMOOTH_FROM - 1, false),
            ContactSolver::GaussSeidel
        );
        let method = NewtonMethod::Auto;
        assert_eq!(
            method.for_contact(ContactSolver::Newton),
            NewtonMethod::Preconditioned
        );
        for s in [ContactSolver::GaussSeidel, ContactSolver::Semismooth] {
            assert_eq!(method.for_contact(s), NewtonMethod::Full);
        }
        for m in [NewtonMethod::Full, NewtonMethod::Modified] {
            assert_eq!(m.for_contact(ContactSolver::Newton), m);
        }
    }
}
