//! What a step attempt produces: its result for the stepper to commit and the wall time of
//! its phases.

use crate::contact::detect::ContactPoint;
use crate::contact::history::PointHistory;
use crate::contact::interface::PointSolution;

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

/// What a successful attempt at a step hands back to the stepper to commit.
pub(super) struct Attempt {
    pub(super) u: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) f_ext1: Vec<f64>,
    pub(super) f_int1: Vec<f64>,
    pub(super) iterations: usize,
    pub(super) residual: f64,
    pub(super) internal: f64,
    pub(super) work: f64,
    pub(super) points: Vec<ContactPoint>,
    /// The law's history of each candidate frozen at the start of the step (local frames).
    pub(super) history0: Vec<PointHistory>,
    pub(super) solutions: Vec<PointSolution>,
    pub(super) sweeps: usize,
    pub(super) contact_residual: f64,
    pub(super) delassus_builds: usize,
    /// Numeric factorisations of the system matrix in the attempt.
    pub(super) factorisations: usize,
    pub(super) timings: PhaseTimes,
    pub(super) reactions: Vec<f64>,
}
