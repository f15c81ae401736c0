//! What the contact solvers need of a bond law: the [`Interface`] trait that every law
//! implements (RCC in `rcc.rs`, a pair's [`super::law::InterfaceLaw`] by handing each call to
//! its bond law), the adhesive evaluations it returns ([`AdhEval`], [`AdhesiveResponse`],
//! [`FrozenSprings`]), what its checks of a pair see ([`PairScales`]) and the solution at a
//! point that its commit reads ([`PointSolution`]). Forces are in the point's local frame
//! (t₁, t₂, n) [N], relative displacements x [m]; interface parameters are per unit area and
//! a point's forces are traction × tributary area.

use super::cone::ContactState;
use super::history::{HistoryField, PointHistory, SiteHistory};
use crate::{Mat3, Vec2, Vec3};

/// What the stepper and the contact solves need from an interface law besides its friction
/// cone (μ, [`super::law::InterfaceLaw::tangent_scale`]): its history at a slave node ([`super::history::LawHistory`],
/// named fields for the outputs and the checkpoints), the frozen history the point solvers
/// take at the start of a step ([`PointHistory`], in the point's local frame), the adhesive
/// response at that history with the point history it leads to, the node history to commit
/// from a point's solution, and the force scale of its bonds.
///
/// A point history is plain numbers that only the law reads (through its typed view, e.g.
/// [`super::rcc::BondState`] for RCC); the solvers pass it from [`Interface::point_history`] to the
/// adhesive evaluations and from those, in the point's solution, to [`Interface::commit`].
///
/// Every point solver reaches the adhesive part only through this trait: the
/// Gauss-Seidel point solver ([`super::point::solve_point`], implicit in x) through
/// [`Interface::is_adhesive`], [`Interface::adhesion_at`], [`Interface::frozen_springs`] and
/// [`Interface::bond_traction`], the fclib Newton and the mixed solve through
/// [`Interface::adhesive_response`].
///
/// A contact pair holds its bond law as a trait object ([`super::law::InterfaceLaw::bond`]), and
/// [`super::law::InterfaceLaw`] implements the trait by handing each call to it: a new law is a type that
/// implements it in a file of its own, with its history registered in
/// [`super::registry::REGISTERED_HISTORIES`]. The RCC law ([`super::rcc::Rcc`], with dry Coulomb friction as its
/// case without adhesion) implements it in `rcc.rs`. Its `Debug` form is part of the
/// checkpoint fingerprint of a problem, so it must show every parameter.
pub trait Interface: std::fmt::Debug + Send + Sync {
    /// The named fields of the law's history at a slave node (its [`super::history::LawHistory::FIELDS`]).
    fn history_fields(&self) -> &'static [HistoryField];

    /// The law as [`std::any::Any`], to reach the parameters of a law of a known type.
    fn as_any(&self) -> &dyn std::any::Any;

    /// Largest quasi-static traction of the law's bonds [Pa] (0 without adhesion): times a
    /// point's area, the force its bond can carry.
    fn bond_traction(&self) -> f64;

    /// Whether the law has an adhesive part; without one the point solvers skip the adhesive
    /// sub-problem and r̃ = 0.
    fn is_adhesive(&self) -> bool;

    /// The adhesive law at the local relative displacement `x` [m] (unscaled axes) of a point
    /// whose history is frozen at `start`, over a step of `dt` [s], with tributary area `area`
    /// [m²]: the force r̃, its tangent −∂r̃/∂x, the incremental potential and the point
    /// history the step leads to. Only called when [`Interface::is_adhesive`]; the
    /// Gauss-Seidel point solver ([`super::point::solve_point`]) solves with it.
    fn adhesion_at(&self, start: &PointHistory, dt: f64, area: f64, x: Vec3) -> AdhEval;

    /// Warm start of the point solver's adhesive sub-problem at a point whose history is frozen
    /// at `start`, with tributary area `area` [m²]: the linear springs that approximate its
    /// bond, or None when it has none to start from. Only called when
    /// [`Interface::is_adhesive`].
    fn frozen_springs(&self, start: &PointHistory, area: f64) -> Option<FrozenSprings>;

    /// Warnings of the law about a contact pair's parameters (e.g. an adhesive stiffness the
    /// mesh cannot resolve), appended to `out`; none by default.
    fn warnings(&self, _pair: &PairScales, _out: &mut Vec<String>) {}

    /// The adhesive response at the local relative displacement `x` [m] of a point whose
    /// history is frozen at `start`, over a step of `dt` [s], with tributary area `area` [m²]
    /// (the force r̃, its secant stiffness, the incremental potential and the point history
    /// it leads to); None for a law without adhesion. The fclib Newton and the mixed solve
    /// linearise the law with it.
    fn adhesive_response(
        &self,
        start: &PointHistory,
        dt: f64,
        area: f64,
        x: Vec3,
    ) -> Option<AdhesiveResponse>;

    /// The frozen history at the start of a step of a point whose node history is `node`,
    /// in the point's local frame `frame` (rows t₁, t₂, n in global components).
    fn point_history(&self, node: &SiteHistory, frame: &[[f64; 3]; 3]) -> PointHistory;

    /// The node history to commit for a point that started the step with `start` and whose
    /// solution is `sol` (with the point history the step led to, [`PointSolution::history`]),
    /// in the local frame `frame`.
    fn commit(
        &self,
        start: &PointHistory,
        sol: &PointSolution,
        frame: &[[f64; 3]; 3],
    ) -> SiteHistory;

    /// The history of a node that is no longer a contact candidate, from its last one.
    fn release(&self, node: &SiteHistory) -> SiteHistory;
}

/// Linear springs r̃ ≈ −K (x + e) approximating a point's bond at its frozen history, the warm
/// start of the Gauss-Seidel point solver's adhesive sub-problem
/// ([`Interface::frozen_springs`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrozenSprings {
    /// Diagonal of K along t₁, t₂ and n [N/m]; the normal spring acts in tension only.
    pub stiffness: Vec3,
    /// Stretch e of the tangential springs at x = 0, along t₁ and t₂ [m].
    pub stretch: Vec2,
}

/// What a law's own checks of a contact pair see ([`Interface::warnings`]).
#[derive(Clone, Copy, Debug)]
pub struct PairScales<'a> {
    /// Name of the contact pair.
    pub name: &'a str,
    /// Mean tributary area of the slave nodes with a positive one [m²], None if there is none.
    pub mean_area: Option<f64>,
    /// Young's modulus E of the slave body at small strain [Pa].
    pub young: f64,
    /// Poisson's ratio ν of the slave body at small strain [-].
    pub poisson: f64,
    /// Mean slave edge h [m].
    pub edge: f64,
}

/// Solution of a [`super::point::PointProblem`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointSolution {
    /// Dry part r̄ [N], in the Coulomb cone.
    pub r_dry: Vec3,
    /// Adhesive part r̃ [N].
    pub r_adh: Vec3,
    /// Local relative displacement x = x_free + W_αα (r̄ + r̃) [m].
    pub x: Vec3,
    /// The law's history of the point at the end of the step, as its adhesive evaluation
    /// wrote it (zero for a law without adhesion): what [`Interface::commit`] reads.
    pub history: PointHistory,
    /// Case of the solution: apart (r̄ = 0, x_n ≥ 0), stick (x = 0) or slide (r̄ on the cone,
    /// opposing the slip, x_n = 0). Whether the point is bonded is [`PointSolution::bonded`].
    pub state: ContactState,
    /// Iterations spent, counted as in [`super::point::solve_point`].
    pub iterations: usize,
    /// Whether the convergence criterion was met within `max_iter`.
    pub converged: bool,
}

impl PointSolution {
    /// Total contact force r = r̄ + r̃ [N].
    pub fn r(&self) -> Vec3 {
        self.r_dry + self.r_adh
    }

    /// Whether an adhesive bond is present at the end of the step (the bond intensity of
    /// [`PointSolution::history`] is positive).
    pub fn bonded(&self) -> bool {
        self.history.bonded()
    }
}

/// An adhesive law evaluated at one x ([`Interface::adhesion_at`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct AdhEval {
    /// The point history the step leads to at this x (for RCC: β₁, the bond stretch
    /// u_t0 + x_t while bonded, else 0, and D as at the start, which the commit accumulates).
    pub history: PointHistory,
    /// Adhesive force r̃ [N].
    pub force: Vec3,
    /// −∂r̃/∂x [N/m] (symmetric).
    pub stiff: Mat3,
    /// Incremental interface potential φ(x) [J], with ∂φ/∂x = −r̃.
    pub energy: f64,
}

/// The adhesive response of a law at a local relative displacement x [m] (docs/model.md §5),
/// for a point whose history is frozen at the start of a step, over a step of `dt` [s], with
/// tributary area `area` [m²] ([`Interface::adhesive_response`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdhesiveResponse {
    /// The point history the step leads to at this x (for RCC: β₁, the bond stretch to
    /// commit, u_t0 + x_t while bonded and else 0, and D as at the start).
    pub history: PointHistory,
    /// Adhesive force r̃ [N] in the local frame.
    pub force: Vec3,
    /// −∂r̃/∂x with β₁ held fixed [N/m]: A β₁² diag(C_t, C_t, C_n [x_n > 0]), symmetric
    /// positive semi-definite (the softening part from ∂β₁/∂x is left out).
    pub secant_stiffness: Mat3,
    /// Incremental potential of the bond φ [J], with ∂φ/∂x = −r̃.
    pub energy: f64,
}
