//! The contact stage of a step: the candidates found at its start, and the trait
//! ([`ContactCoupling`]) behind which the Newton loop calls the three ways of solving the
//! contact conditions, each implemented with its solver in [`crate::contact::solver`]:
//! Gauss-Seidel on the Delassus operator, the W-free semismooth solve on the mixed system and
//! the augmented-Lagrangian Newton solve. docs/contact-solver.md describes all three.

pub(crate) use super::attempt::PhaseTimes;
use super::constraints::Constraints;
use crate::contact::detect::ContactPoint;
use crate::contact::history::PointHistory;
use crate::contact::interface::PointSolution;
use crate::contact::law::natural_map_defect;
use crate::contact::solver::site_stiffness::{point_stiffness, RHO_FACTOR};
use crate::contact::InterfaceLaw;
use crate::system::SystemMatrix;

/// The contact candidates of one step and what every solver needs of them.
pub struct StepContact<'a> {
    /// Candidates found at the start of the step.
    pub points: Vec<ContactPoint>,
    /// Interface law of each contact pair.
    pub laws: Vec<InterfaceLaw>,
    /// The law's history of each candidate frozen at the start of the step, in its local
    /// frame.
    pub history0: Vec<PointHistory>,
    /// Force the adhesive bonds of the candidates can carry, ‖(A_α √(C w))_α‖ [N]: the force
    /// scale of an interface that holds (or snaps into) contact without load.
    pub bond_strength: f64,
    /// Augmentation parameter ρ_α of each candidate [N/m], set at the first iteration.
    pub rho: Vec<f64>,
    /// Step size [s].
    pub dt: f64,
    /// Reference positions of the nodes [m].
    pub reference: &'a [[f64; 3]],
    /// The prescribed unknowns, on which no contact force acts.
    pub constraints: &'a Constraints,
}

/// The candidates of a step as detected, before the solve takes them up.
pub struct Candidates {
    /// Candidates found at the start of the step.
    pub points: Vec<ContactPoint>,
    /// The law's history of each frozen at the start of the step, in its local frame.
    pub history0: Vec<PointHistory>,
    /// Force their bonds can carry [N] (see [`StepContact::bond_strength`]).
    pub bond_strength: f64,
    /// The solver of the step.
    pub solver: crate::problem::ContactSolver,
    /// Forces (multipliers) the solves without W start from (None: the Gauss-Seidel solve).
    pub multipliers: Option<Vec<[f64; 3]>>,
}

impl<'a> StepContact<'a> {
    /// The step's contact data from its `candidates`, the pairs' `laws`, the step size `dt`
    /// [s], the nodes' `reference` positions [m] and the `constraints`.
    pub fn new(
        candidates: Candidates,
        laws: Vec<InterfaceLaw>,
        dt: f64,
        reference: &'a [[f64; 3]],
        constraints: &'a Constraints,
    ) -> (Self, Option<Vec<[f64; 3]>>) {
        let contact = StepContact {
            points: candidates.points,
            laws,
            history0: candidates.history0,
            bond_strength: candidates.bond_strength,
            rho: Vec::new(),
            dt,
            reference,
            constraints,
        };
        (contact, candidates.multipliers)
    }
}

impl StepContact<'_> {
    /// The candidates and their history at the start of the step, handed back at its end.
    pub fn take_candidates(&mut self) -> (Vec<ContactPoint>, Vec<PointHistory>) {
        (
            std::mem::take(&mut self.points),
            std::mem::take(&mut self.history0),
        )
    }

    /// True when the step has no contact candidate.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Sets ρ_α to [`RHO_FACTOR`] times the stiffness K̄ shows at each point, from
    /// K̄'s diagonal (computed only when there are candidates).
    pub fn set_augmentation(&mut self, diagonal: impl FnOnce() -> Vec<f64>) {
        if self.is_empty() {
            return;
        }
        let diagonal = diagonal();
        self.rho = self
            .points
            .iter()
            .map(|pt| {
                point_stiffness(pt, &diagonal, self.constraints.mask())
                    .map_or(1.0, |k| RHO_FACTOR * k)
            })
            .collect();
    }

    /// Natural-map residual ‖(r̄_α − P_K(r̄_α − ρ_α x̂_α))_α‖ [N] of the bi-potential
    /// condition, at each solution's own x, with the ρ_α of the Newton solver: the same
    /// measure for both solvers.
    pub fn natural_map(&self, solutions: &[PointSolution]) -> f64 {
        self.points
            .iter()
            .zip(&self.rho)
            .zip(solutions)
            .map(|((pt, &rho), sol)| {
                let d = natural_map_defect(&self.laws[pt.pair], rho, sol.r_dry, sol.x);
                d.iter().map(|v| v * v).sum::<f64>()
            })
            .sum::<f64>()
            .sqrt()
    }

    /// Hᵀr on the free unknowns for the forces `forces` of the points (local frames) [N].
    pub fn nodal_force(&self, forces: impl Iterator<Item = [f64; 3]>, n: usize) -> Vec<f64> {
        let mut f = vec![0.0; n];
        for (pt, r) in self.points.iter().zip(forces) {
            pt.add_ht(r, &mut f);
        }
        self.constraints.zero_fixed(&mut f);
        f
    }
}

/// What the contact stage asks of the Newton loop after evaluating an iterate.
pub enum Evaluated {
    /// The iterate is ready for the convergence check.
    Ready,
    /// The iterate was replaced by a shorter step along the last correction: assemble again.
    Backtracked,
}

/// The iterate's data the contact stage reads.
pub struct Iterate<'a> {
    /// Newton iteration (1-based).
    pub iter: usize,
    /// G(u) without contact [N].
    pub g: &'a [f64],
    /// The step's potential without contact [J].
    pub potential: f64,
}

impl<'a> Iterate<'a> {
    /// The iterate of Newton iteration `iter` with out-of-balance force `g` and potential
    /// `potential`.
    pub fn new(iter: usize, g: &'a [f64], potential: f64) -> Self {
        Iterate { iter, g, potential }
    }
}

/// A way of solving the contact conditions inside the step's Newton loop.
pub trait ContactCoupling<'a> {
    /// The candidates and shared data of the step.
    fn step_contact(&mut self) -> &mut StepContact<'a>;
    /// Evaluates the contact forces at the iterate `u` (before the convergence check); may
    /// replace `u` by a shorter step. The solves that find the forces in [`Self::correct`]
    /// have nothing to do here.
    fn evaluate(&mut self, _it: &Iterate, _u: &mut [f64], _timings: &mut PhaseTimes) -> Evaluated {
        Evaluated::Ready
    }
    /// The contact forces Hᵀr on the free unknowns at the iterate [N].
    fn contact_force(&self) -> &[f64];
    /// The contact residual of the iterate relative to the force scale `scale` [N].
    fn contact_residual(&self, scale: f64) -> f64;
    /// Adds the contact conditions' stiffness to K̄ (before its factorisation); nothing for
    /// the solves that keep K̄ as it is.
    fn add_tangent(&self, _system: &mut SystemMatrix) {}
    /// What the stiffness [`Self::add_tangent`] adds depends on besides the points' geometry
    /// (e.g. their contact cases), hashed: a kept factorisation of K̄ is only reused for the
    /// same key (`time.newton = "modified"`). 0 for the solves that add none.
    fn tangent_key(&self) -> u64 {
        0
    }
    /// Completes the Newton correction `du` solved from K̄ du = Hᵀr − G; for a coupling that
    /// [folds the momentum](Self::folds_momentum) in, `du` holds Hᵀr − G itself, K̄'s values
    /// are set but not factorised, and `correct` replaces `du` by the whole correction.
    #[allow(clippy::too_many_arguments)]
    fn correct(
        &mut self,
        it: &Iterate,
        u: &[f64],
        du: &mut [f64],
        residual_norm: f64,
        scale: f64,
        system: &mut SystemMatrix,
        timings: &mut PhaseTimes,
    ) -> Result<(), String>;
    /// Whether the coupling solves the momentum balance together with the contact law in
    /// [`Self::correct`] (one factorisation of the coupled system per Newton iteration),
    /// instead of completing a correction solved with K̄ alone.
    fn folds_momentum(&self) -> bool {
        false
    }
    /// Per-point solutions at the iterate.
    fn solutions(&self) -> Vec<PointSolution>;
    /// Contact iterations so far (Gauss-Seidel sweeps or multiplier updates).
    fn sweeps(&self) -> usize;
    /// Delassus operators built so far in the step.
    fn delassus_builds(&self) -> usize {
        0
    }
    /// The step failed: drop whatever must not be reused.
    fn abandon(&mut self) {}
}
