//! The local interface law at one contact point (docs/model.md §5–§6): dry Signorini–Coulomb contact
//! through the bi-potential projection, Raous–Cangémi–Cocou (RCC) recoverable adhesion, and the
//! point solver used inside the nonlinear Gauss–Seidel sweep over contact points.
//!
//! Everything here is a pure function on plain arrays: no mesh, no allocation.
//!
//! # Conventions
//! - Local frame components are ordered (t1, t2, n).
//! - `r` is the force on the slave node [N]; `r_n > 0` is compression. `r = r̄ + r̃` (dry part plus
//!   adhesive part).
//! - `x = (x_t1, x_t2, x_n)` [m]: `x_n` is the gap at the end of the step (≥ 0 apart), `x_t` the
//!   slip increment over the step.
//! - Interface parameters are per unit area; nodal forces are traction × tributary area `A` [m²].
//!
//! # Choices documented here
//! - **ε cut-off.** `β < ε` means a broken bond (`β = 0`) unless the bond is *forming*, i.e. the
//!   equilibrium `β∞ = min(1, w/E)` for the current stretch energy `E` is itself `≥ ε`. A plain
//!   `β < ε → 0` would forbid bonding whenever `Δt·w/b < ε`, so bonding would vanish as `Δt → 0`.
//!   The implicit Euler `β₁` is a convex combination of `β₀` and `β∞` (before the clamp at 1), so a
//!   decaying bond below ε always has `β∞ < ε` and is cut exactly as the paper intends.
//! - **Bonds at a distance.** [`beta_update`] follows the RCC law for any gap: from `β₀ = 0` at a
//!   gap `x` a bond forms when `w/(C_n x²) ≥ ε`, i.e. `x ≤ √(w/(ε C_n)) = 100 x_c` for ε = 1e-4
//!   (`x_c = √(w/C_n)`). Its traction there is at most `w²/(C_n x³)`. Candidates beyond the
//!   detection distance are the caller's business: they carry `β = 0` (docs/model.md §5).
//! - **Point solver.** [`solve_point`] solves the apart, stick and slide cases directly (the
//!   adhesive part implicitly in x) and checks each against the bi-potential fixed point; the
//!   bi-potential iteration itself (semi-smooth Newton, fixed-point steps with ρ = 1/λ_max(W))
//!   is the fallback. A plain fixed point diverges once C·A·‖W‖ > 1 if r̃ lags one iteration
//!   behind x, and crawls when the compliance is ill-conditioned.
//! - **Sign of the sliding projection.** The paper's eq 32 prints `+ μ n`; with `r_n > 0` as
//!   compression that leaves the cone, so `− μ n` is used, as docs/model.md says.

pub use super::anisotropic::Orthotropy;
use super::anisotropic::{scale, scale_matrix, unscale, unscale_matrix};
use super::history::{HistoryField, LawHistory, LawPointHistory, NodeHistory, PointHistory};
use crate::{Mat3, Vec2, Vec3};
use std::f64::consts::PI;
use std::sync::Arc;

/// Default bond cut-off ε of the RCC law: below it a bond is broken.
pub const DEFAULT_BETA_EPS: f64 = 1e-4;

/// Largest number of Newton steps of the adhesive sub-problem per evaluation.
const MAX_INNER: usize = 60;
/// Largest number of step lengths tried along a Newton direction of the dry force.
const NEWTON_HALVINGS: usize = 4;
/// Largest number of step halvings in the line search of the slide equations; a Newton
/// direction that needs more is abandoned for the bi-potential iteration.
const SLIDE_HALVINGS: usize = 6;
/// Largest change of the friction direction per Newton step of the slide equations [rad].
const MAX_TURN: f64 = 0.5;
/// Largest number of step halvings in a line search.
const MAX_HALVINGS: usize = 40;

/// RCC adhesion parameters of a contact pair, per unit area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RccParams {
    /// Decohesion energy w [J/m²].
    pub w: f64,
    /// Normal adhesive stiffness C_n [N/m³].
    pub cn: f64,
    /// Tangential adhesive stiffness C_t [N/m³] (along the local axis t₁).
    pub ct: f64,
    /// Tangential adhesive stiffness along t₂, C_t2 [N/m³]: equal to `ct` except on an
    /// orthotropic interface, whose t₁, t₂ follow the master's material axes
    /// ([`super::anisotropic`]).
    pub ct2: f64,
    /// Interface viscosity b [N·s/m = J·s/m²]; `b = 0` is the rate-independent limit.
    pub b: f64,
    /// Cut-off ε of the intensity of adhesion β [-] (default [`DEFAULT_BETA_EPS`]).
    pub eps: f64,
    /// Fatigue energy D_f [J/m²] of the interface: the decohesion energy degrades as
    /// w(D) = w·exp(−D/D_f) with the adhesive energy D dissipated at the point so far
    /// ([`accumulated_damage`]). `f64::INFINITY` (the default) is the RCC law without fatigue.
    pub fatigue_energy: f64,
}

impl RccParams {
    /// Parameters with the default cut-off ε = [`DEFAULT_BETA_EPS`].
    pub fn new(w: f64, cn: f64, ct: f64, b: f64) -> Self {
        Self {
            w,
            cn,
            ct,
            ct2: ct,
            b,
            eps: DEFAULT_BETA_EPS,
            fatigue_energy: f64::INFINITY,
        }
    }

    /// The parameters at a point that has dissipated `damage` = D [J/m²]: the decohesion
    /// energy w·exp(−D/D_f), everything else unchanged.
    pub fn degraded(&self, damage: f64) -> RccParams {
        let mut p = *self;
        if self.fatigue_energy.is_finite() && damage > 0.0 {
            p.w = self.w * (-damage / self.fatigue_energy).exp();
        }
        p
    }

    /// Critical opening x_c = √(w/C_n) [m] where the quasi-static normal traction peaks.
    pub fn critical_opening(&self) -> f64 {
        if self.cn > 0.0 {
            (self.w.max(0.0) / self.cn).sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// Largest quasi-static adhesive traction √(max(C_n, C_t)·w) [Pa].
    pub fn peak_traction(&self) -> f64 {
        (self.cn.max(self.ct).max(self.ct2).max(0.0) * self.w.max(0.0)).sqrt()
    }
}

/// Interface law of a contact pair: its friction cone (μ, and the material axes of an
/// orthotropic interface) and the law of its bonds, which also keeps the history at each
/// slave node ([`Interface`]).
#[derive(Clone)]
pub struct InterfaceLaw {
    /// Coulomb friction coefficient μ ≥ 0 [-] (negative values are treated as 0); μ₁, along
    /// the first material axis, on an orthotropic interface.
    pub mu: f64,
    /// The bond law: RCC adhesion ([`super::rcc::Rcc`], without parameters for dry contact)
    /// or any other implementation of [`Interface`].
    pub bond: Arc<dyn Interface>,
    /// Material axes and μ₂ of an orthotropic interface (elliptic friction cone), or `None`
    /// for an isotropic one ([`super::anisotropic`]).
    pub anisotropy: Option<Orthotropy>,
}

/// The form the checkpoint fingerprint hashes: the bond law's under the name `adhesion`
/// (`None` or `Some(RccParams { .. })` for RCC), as when RCC was the only law, so that a
/// scenario's fingerprint does not change with this layout.
impl std::fmt::Debug for InterfaceLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InterfaceLaw")
            .field("mu", &self.mu)
            .field("adhesion", &self.bond)
            .field("anisotropy", &self.anisotropy)
            .finish()
    }
}

impl InterfaceLaw {
    /// Dry isotropic Coulomb friction with coefficient `mu` [-]: no adhesion, no anisotropy.
    pub fn coulomb(mu: f64) -> Self {
        Self::rcc(mu, None, None)
    }

    /// Coulomb friction `mu` [-] with RCC adhesion `adhesion` (None: dry) and the orthotropy
    /// `anisotropy` (None: isotropic).
    pub fn rcc(mu: f64, adhesion: Option<RccParams>, anisotropy: Option<Orthotropy>) -> Self {
        let bond: Arc<dyn Interface> = match adhesion {
            Some(_) => Arc::new(super::rcc::Rcc(adhesion)),
            None => super::rcc::Rcc::dry(),
        };
        InterfaceLaw {
            mu,
            bond,
            anisotropy,
        }
    }

    /// The scale s = μ₂/μ₁ of the second tangential axis that maps the law's cone on the
    /// circular cone of μ₁ ([`super::anisotropic`]): 1 for an isotropic law (and for μ₁ = μ₂).
    pub fn tangent_scale(&self) -> f64 {
        match &self.anisotropy {
            Some(o) if o.mu2 != self.mu && self.mu > 0.0 && o.mu2 > 0.0 => o.mu2 / self.mu,
            _ => 1.0,
        }
    }
}

/// What the stepper and the contact solves need from an interface law besides its friction
/// cone (μ, [`InterfaceLaw::tangent_scale`]): its history at a slave node ([`LawHistory`],
/// named fields for the outputs and the checkpoints), the frozen history the point solvers
/// take at the start of a step ([`PointHistory`], in the point's local frame), the adhesive
/// response at that history with the point history it leads to, the node history to commit
/// from a point's solution, and the force scale of its bonds.
///
/// A point history is plain numbers that only the law reads (through its typed view, e.g.
/// [`BondState`] for RCC); the solvers pass it from [`Interface::point_history`] to the
/// adhesive evaluations and from those, in the point's solution, to [`Interface::commit`].
///
/// Every point solver reaches the adhesive part only through this trait: the
/// Gauss-Seidel point solver ([`solve_point`], implicit in x) through
/// [`Interface::is_adhesive`], [`Interface::adhesion_at`], [`Interface::frozen_springs`] and
/// [`Interface::bond_traction`], the fclib Newton and the mixed solve through
/// [`Interface::adhesive_response`].
///
/// A contact pair holds its bond law as a trait object ([`InterfaceLaw::bond`]), and
/// [`InterfaceLaw`] implements the trait by handing each call to it: a new law is a type that
/// implements it in a file of its own, with its history registered in
/// [`REGISTERED_HISTORIES`]. The RCC law ([`super::rcc::Rcc`], with dry Coulomb friction as its
/// case without adhesion) implements it in `rcc.rs`. Its `Debug` form is part of the
/// checkpoint fingerprint of a problem, so it must show every parameter.
pub trait Interface: std::fmt::Debug + Send + Sync {
    /// The named fields of the law's history at a slave node (its [`LawHistory::FIELDS`]).
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
    /// Gauss-Seidel point solver ([`solve_point`]) solves with it.
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
    fn point_history(&self, node: &NodeHistory, frame: &[[f64; 3]; 3]) -> PointHistory;

    /// The node history to commit for a point that started the step with `start` and whose
    /// solution is `sol` (with the point history the step led to, [`PointSolution::history`]),
    /// in the local frame `frame`.
    fn commit(
        &self,
        start: &PointHistory,
        sol: &PointSolution,
        frame: &[[f64; 3]; 3],
    ) -> NodeHistory;

    /// The history of a node that is no longer a contact candidate, from its last one.
    fn release(&self, node: &NodeHistory) -> NodeHistory;
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

/// A contact pair's law is its bond law's, whatever that is.
impl Interface for InterfaceLaw {
    fn history_fields(&self) -> &'static [HistoryField] {
        self.bond.history_fields()
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self.bond.as_any()
    }

    fn bond_traction(&self) -> f64 {
        self.bond.bond_traction()
    }

    fn is_adhesive(&self) -> bool {
        self.bond.is_adhesive()
    }

    fn adhesion_at(&self, start: &PointHistory, dt: f64, area: f64, x: Vec3) -> AdhEval {
        self.bond.adhesion_at(start, dt, area, x)
    }

    fn frozen_springs(&self, start: &PointHistory, area: f64) -> Option<FrozenSprings> {
        self.bond.frozen_springs(start, area)
    }

    fn warnings(&self, pair: &PairScales, out: &mut Vec<String>) {
        self.bond.warnings(pair, out)
    }

    fn adhesive_response(
        &self,
        start: &PointHistory,
        dt: f64,
        area: f64,
        x: Vec3,
    ) -> Option<AdhesiveResponse> {
        self.bond.adhesive_response(start, dt, area, x)
    }

    fn point_history(&self, node: &NodeHistory, frame: &[[f64; 3]; 3]) -> PointHistory {
        self.bond.point_history(node, frame)
    }

    fn commit(
        &self,
        start: &PointHistory,
        sol: &PointSolution,
        frame: &[[f64; 3]; 3],
    ) -> NodeHistory {
        self.bond.commit(start, sol, frame)
    }

    fn release(&self, node: &NodeHistory) -> NodeHistory {
        self.bond.release(node)
    }
}

/// The history fields of every registered interface law.
pub const REGISTERED_HISTORIES: &[&[HistoryField]] = &[super::rcc::RccHistory::FIELDS];

/// The defect r̄ − P_K(r̄ − ρ x̂) [N] of the law's bi-potential condition at a dry force `r_dry`
/// [N] and local relative displacement `x` [m], with `rho` [N/m]: zero exactly at a solution.
/// For an orthotropic law it is evaluated in the scaled variables and mapped back by T.
pub fn natural_map_defect(law: &InterfaceLaw, rho: f64, r_dry: Vec3, x: Vec3) -> Vec3 {
    let s = law.tangent_scale();
    let (r, y) = if s == 1.0 {
        (r_dry, x)
    } else {
        (unscale(r_dry, s), scale(x, s))
    };
    let p = dry_projection(bipotential_trial(r, y, law.mu, rho), law.mu).0;
    let d = r - p;
    if s == 1.0 {
        d
    } else {
        scale(d, s)
    }
}

/// Which case of the bi-potential projection the dry part fell into. Whether the point is
/// bonded is reported separately ([`PointSolution::bonded`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactState {
    /// Separating: r̄ = 0 (the gap is open).
    Apart,
    /// Sticking: r̄ inside the Coulomb cone, no slip.
    Stick,
    /// Sliding: r̄ on the boundary of the cone, opposing the slip.
    Slide,
}

/// The RCC law's history at a contact point, in the point's local frame: its typed view of a
/// [`PointHistory`], frozen at the start of a step or led to by it. The RCC functions of
/// this module take and give it; the law's [`Interface`] implementation (`rcc.rs`) encodes
/// it at the trait's boundary.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BondState {
    /// Intensity of adhesion β ∈ [0, 1] [-].
    pub beta: f64,
    /// Accumulated stretch of the adhesive links in the (t1, t2) plane [m].
    pub ut: Vec2,
    /// Adhesive energy dissipated at the point so far, D [J/m²] ([`accumulated_damage`]).
    pub damage: f64,
}

impl LawPointHistory for BondState {
    /// (β, u_t1, u_t2, D).
    fn encode(&self) -> PointHistory {
        let mut h = PointHistory::default();
        h.0[0] = self.beta;
        h.0[1] = self.ut[0];
        h.0[2] = self.ut[1];
        h.0[3] = self.damage;
        h
    }

    fn decode(h: &PointHistory) -> Self {
        BondState {
            beta: h.0[0],
            ut: Vec2::new(h.0[1], h.0[2]),
            damage: h.0[3],
        }
    }
}

impl From<&PointHistory> for BondState {
    fn from(h: &PointHistory) -> Self {
        BondState::decode(h)
    }
}

/// The adhesive energy dissipated at a point, D [J/m²], after a step in which β went from
/// `beta0` to `beta1`, from its value `damage0` before the step.
///
/// Breaking bonds releases the current decohesion energy w(D) per unit of β lost, so
/// dD = −w(D) dβ while β decreases (re-forming bonds dissipate nothing). With the fatigue law
/// w(D) = w₀·exp(−D/D_f) of [`RccParams::degraded`] this integrates exactly over any decrease
/// Δβ: exp(D₁/D_f) = exp(D₀/D_f) + w₀ Δβ / D_f, so the result does not depend on how the
/// decrease is split into steps. Without fatigue (D_f = ∞) it is D₀ + w₀ Δβ.
///
/// Closed form for a point fully bonded and fully broken k times: D_k = D_f ln(1 + k w₀/D_f),
/// hence w(D_k) = w₀ / (1 + k w₀/D_f) and the quasi-static pull-off traction of cycle k + 1 is
/// √(C_n w₀ / (1 + k w₀/D_f)).
pub fn accumulated_damage(damage0: f64, beta0: f64, beta1: f64, p: &RccParams) -> f64 {
    let lost = (clamp01(beta0) - clamp01(beta1)).max(0.0);
    let w0 = p.w.max(0.0);
    if lost == 0.0 || w0 == 0.0 {
        return damage0;
    }
    let df = p.fatigue_energy;
    if !df.is_finite() {
        return damage0 + w0 * lost;
    }
    // D₁ = D₀ + D_f ln(1 + w₀ Δβ exp(−D₀/D_f) / D_f), in a form exact for small increments.
    damage0 + df * (w0 * lost * (-damage0 / df).exp() / df).ln_1p()
}

/// Projection of `r_star` [N] onto the Coulomb cone K_μ = {r_n ≥ 0, ‖r_t‖ ≤ μ r_n}
/// (docs/model.md §5), with the case it fell into.
///
/// - separating, `μ‖r*_t‖ < −r*_n`: `r = 0`;
/// - sticking, `‖r*_t‖ ≤ μ r*_n`: `r = r*`;
/// - sliding otherwise: `r_n = (r*_n + μ‖r*_t‖)/(1 + μ²)`, `r_t = μ r_n r*_t/‖r*_t‖`.
///
/// `μ = 0` is frictionless contact: `r_t = 0`, `r_n = max(r*_n, 0)`.
pub fn dry_projection(r_star: Vec3, mu: f64) -> (Vec3, ContactState) {
    let mu = mu.max(0.0);
    let st = r_star[0].hypot(r_star[1]);
    let sn = r_star[2];
    if mu * st < -sn {
        return (Vec3::zeros(), ContactState::Apart);
    }
    if st <= mu * sn {
        return (r_star, ContactState::Stick);
    }
    // Sliding: here st > μ s_n and μ st ≥ −s_n, which together give st > 0.
    let rn = ((sn + mu * st) / (1.0 + mu * mu)).max(0.0);
    if st > 0.0 {
        let k = mu * rn / st;
        (
            Vec3::new(k * r_star[0], k * r_star[1], rn),
            ContactState::Slide,
        )
    } else {
        (Vec3::new(0.0, 0.0, rn), ContactState::Slide)
    }
}

/// Bi-potential trial force r* = r̄ − ρ (x + μ‖x_t‖ n) [N] (docs/model.md §5, paper eq 30), from the
/// dry force `r_dry` [N], the local relative displacement `x` [m] and ρ [N/m].
pub fn bipotential_trial(r_dry: Vec3, x: Vec3, mu: f64, rho: f64) -> Vec3 {
    let mu = mu.max(0.0);
    let xt = x[0].hypot(x[1]);
    r_dry - rho * Vec3::new(x[0], x[1], x[2] + mu * xt)
}

/// D = ∂x̂/∂x of the modified relative displacement x̂ = x + μ‖x_t‖n at `x` [m] with the
/// friction coefficient `mu` ≥ 0: I + μ n (x_t/‖x_t‖, 0)ᵀ, the second term dropped at x_t = 0.
pub fn modified_displacement_jacobian(x: Vec3, mu: f64) -> Mat3 {
    let mut d = Mat3::identity();
    let xt = x[0].hypot(x[1]);
    if xt > 0.0 && mu > 0.0 {
        d[(2, 0)] = mu * x[0] / xt;
        d[(2, 1)] = mu * x[1] / xt;
    }
    d
}

/// Intensity of adhesion at the end of a step of `dt` [s] from `beta0`, by implicit Euler of
/// b β̇ = w − (C_n x_n⁺² + C_t‖u_t‖²) β held in [0, 1]:
/// β₁ = min(1, (b β₀ + Δt w)/(b + Δt E)), with the stretch energy E = C_n x_n⁺² + C_t‖u_t‖²
/// [J/m²].
///
/// - `xn` [m] is the gap (only its positive part stretches the links), `ut` [m] the accumulated
///   bond stretch including this step's slip.
/// - `b = 0` (or negative): rate-independent β₁ = min(1, w/E), 1 when E = 0 and w > 0.
/// - `dt ≤ 0` with `b > 0`: no time elapses, β₁ = β₀.
/// - Cut-off: β₁ < ε gives 0 unless the bond is forming (β∞ = min(1, w/E) ≥ ε); see the module
///   documentation. With β₀ = 0 at a gap x the bond forms only if w/(C_n x²) ≥ ε.
pub fn beta_update(beta0: f64, dt: f64, p: &RccParams, xn: f64, ut: Vec2) -> f64 {
    beta_step(beta0, dt, p, stretch_energy(p, xn, ut)).0
}

/// Adhesive force r̃ = (−C_t u_t1 β² A, −C_t2 u_t2 β² A, −C_n x_n⁺ β² A) [N] for the intensity of
/// adhesion `beta`, gap `xn` [m], bond stretch `ut` [m] and tributary area `area` [m²].
pub fn adhesive_force(beta: f64, p: &RccParams, xn: f64, ut: Vec2, area: f64) -> Vec3 {
    let k = beta * beta * area;
    Vec3::new(
        -p.ct * ut[0] * k,
        -p.ct2 * ut[1] * k,
        -p.cn * xn.max(0.0) * k,
    )
}

/// ρ [N/m] for the bi-potential iteration at a point with Delassus block `w_aa` [m/N]:
/// 1/λ_max of its symmetric part. The fixed point r̄ ← Proj(r̄ − ρ(x + μ‖x_t‖n)) contracts for
/// 0 < ρ < 2/λ_max; 1/λ_max is safely inside. (1/max W_ii can reach 3/λ_max and diverge.)
/// Falls back to 1/max|W_ii|, then 1, for degenerate blocks.
pub fn default_rho(w_aa: Mat3) -> f64 {
    let w = w_aa;
    let lmax = eig_sym3(&((w + w.transpose()) * 0.5))[2];
    if lmax.is_finite() && lmax > 0.0 {
        return 1.0 / lmax;
    }
    let dmax = w_aa[(0, 0)]
        .abs()
        .max(w_aa[(1, 1)].abs())
        .max(w_aa[(2, 2)].abs());
    if dmax.is_finite() && dmax > 0.0 {
        1.0 / dmax
    } else {
        1.0
    }
}

/// The local problem at contact point α within a Gauss–Seidel sweep:
/// x = x_free + W_αα (r̄ + r̃), with the dry and adhesive laws at the point.
#[derive(Clone, Copy, Debug)]
pub struct PointProblem<'a> {
    /// Delassus diagonal block W_αα [m/N], symmetric positive definite.
    pub w_aa: Mat3,
    /// x with the other points' current forces and this point's force removed [m].
    pub x_free: Vec3,
    /// Interface law of the pair.
    pub law: &'a InterfaceLaw,
    /// The law's history of the point frozen at the start of the step.
    pub history0: PointHistory,
    /// Time step Δt [s].
    pub dt: f64,
    /// Tributary area A [m²].
    pub area: f64,
    /// Bi-potential parameter ρ [N/m], e.g. [`default_rho`].
    pub rho: f64,
}

/// Solution of a [`PointProblem`].
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
    /// Iterations spent, counted as in [`solve_point`].
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

/// Solves the local problem at one contact point: x = x_free + W_αα (r̄ + r̃) with r̄ obeying
/// Signorini–Coulomb (r̄ = Proj_K(r̄ − ρ(x + μ‖x_t‖n))) and r̃ = r̃(β₁(x), x) the RCC force.
///
/// The three cases are tried in turn, each solved exactly rather than by a ρ-dependent fixed
/// point (whose rate degrades like λ_min/λ_max of the compliance, and with stiff adhesion like
/// 1/(C·A·‖W‖)):
/// 1. apart: r̄ = 0; the adhesive part alone, x = x_free + W r̃(x), is solved implicitly
///    (Newton on the incremental potential with a line search, started from linear springs at
///    β₀, so a bond holds as long as its branch exists and snaps off past it). Valid if x_n ≥ 0.
/// 2. stick: x = 0, so r̃ = r̃(0) is explicit and r̄ = −W⁻¹x_free − r̃(0). Valid if r̄ ∈ K_μ.
/// 3. slide: damped Newton on (r_n, θ, λ) with r̄ = r_n(μ cos θ, μ sin θ, 1) on the cone and
///    slip x_t = −λ(cos θ, sin θ), x_n = 0, started from the friction direction of `r_start` when
///    that lies on the cone (warm start from the previous sweep), else of the stick force.
///
/// A case is accepted only if it passes the bi-potential check: with r = r̄ + r̃ and the force
/// scale s = ρ‖x_free‖ + A·√(max(C_n, C_t)·w), ‖r̄ − Proj_K(r̄ − ρ(x + μ‖x_t‖n))‖ ≤
/// `tol`·(‖r‖ + s). If none does (singular or stalled slide Newton, e.g. a tangential snap of
/// the bond), the bi-potential iteration takes over from `r_start`: semi-smooth Newton steps on
/// that residual, kept when they reduce it, plain fixed-point steps otherwise; it stops when the
/// change of r over an iteration and the residual are both ≤ `tol`·(‖r‖ + s).
///
/// `iterations` counts 1 for the apart test, 1 for the stick test, then the Newton steps of the
/// slide equations and of the fallback. When the law admits several solutions (μ large with
/// strongly coupled W, or softening adhesion), the first in the order apart, stick, slide wins.
/// `rho` is only used by the check and the fallback (a non-positive ρ is replaced by
/// [`default_rho`]); the solution does not depend on it. r̄ lies in K_μ to rounding.
pub fn solve_point(p: &PointProblem, r_start: Vec3, tol: f64, max_iter: usize) -> PointSolution {
    solve_point_impl(p, r_start, tol, max_iter, Method::Cases)
}

/// Everything derived from one value of the dry force r̄.
#[derive(Clone, Copy, Debug)]
struct Eval {
    /// Dry force r̄ at which this was evaluated [N].
    r_dry: Vec3,
    /// Local relative displacement [m].
    x: Vec3,
    /// Adhesive force r̃ [N] with x = x_free + W (r̄ + r̃) exactly; equal to the law's r̃(x) to
    /// the sub-problem's tolerance.
    r_adh: Vec3,
    /// Adhesive state at x.
    adh: AdhEval,
    /// Trial force r* [N].
    r_star: Vec3,
    /// Projection of r* [N].
    proj: Vec3,
    /// Case of the projection.
    case: ContactState,
    /// Fixed-point defect F = r̄ − Proj(r*) [N].
    f: Vec3,
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

/// Per-solve constants.
struct Ctx<'a> {
    p: &'a PointProblem<'a>,
    /// The problem's Delassus block W_αα [m/N].
    w: Mat3,
    /// The problem's x_free [m].
    x_free: Vec3,
    /// Scale of the second tangential axis of the solver's variables (1, or μ₂/μ₁ on an
    /// orthotropic interface); the adhesive law is evaluated in the unscaled ones.
    t2: f64,
    mu: f64,
    /// ρ [N/m] in use (the problem's, or [`default_rho`] when that is not positive).
    rho: f64,
    /// Relative tolerance of the point problem.
    tol: f64,
    /// Force scale s [N] of the convergence criteria.
    scale: f64,
    /// Relative tolerance of the adhesive sub-problem.
    tol_in: f64,
}

/// How [`solve_point_impl`] solves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Method {
    /// Case by case (apart, stick, slide), falling back to the bi-potential iteration.
    Cases,
    /// Bi-potential iteration only; `newton` enables the semi-smooth Newton steps.
    #[cfg_attr(not(test), allow(dead_code))]
    Bipotential { newton: bool },
}

/// [`solve_point`] with a choice of method. An orthotropic law is solved as the isotropic
/// problem of its scaled variables r' = T⁻¹r, x' = Tx ([`super::anisotropic`]).
fn solve_point_impl(
    p: &PointProblem,
    r_start: Vec3,
    tol: f64,
    max_iter: usize,
    method: Method,
) -> PointSolution {
    let s = p.law.tangent_scale();
    if s == 1.0 {
        return solve_scaled(p, r_start, tol, max_iter, method, 1.0);
    }
    let law = InterfaceLaw {
        anisotropy: None,
        ..p.law.clone()
    };
    let scaled = PointProblem {
        w_aa: scale_matrix(p.w_aa, s),
        x_free: scale(p.x_free, s),
        law: &law,
        ..*p
    };
    let sol = solve_scaled(&scaled, unscale(r_start, s), tol, max_iter, method, s);
    PointSolution {
        r_dry: scale(sol.r_dry, s),
        r_adh: scale(sol.r_adh, s),
        x: unscale(sol.x, s),
        ..sol
    }
}

/// The point problem `p` in variables whose second tangential axis is scaled by `t2`
/// (x' = T x, r' = T⁻¹ r, T = diag(1, t2, 1)); `p.law` is isotropic there.
fn solve_scaled(
    p: &PointProblem,
    r_start: Vec3,
    tol: f64,
    max_iter: usize,
    method: Method,
    t2: f64,
) -> PointSolution {
    let mu = p.law.mu.max(0.0);
    let adh_scale = if p.law.is_adhesive() {
        p.area.abs() * p.law.bond_traction()
    } else {
        0.0
    };
    let rho = if p.rho.is_finite() && p.rho > 0.0 {
        p.rho
    } else {
        default_rho(p.w_aa)
    };
    let w = p.w_aa;
    let x_free = p.x_free;
    let scale = rho * x_free.norm() + adh_scale;
    let tol = if tol.is_finite() && tol > 0.0 {
        tol
    } else {
        1e-10
    };
    let ctx = Ctx {
        p,
        w,
        x_free,
        t2,
        mu,
        rho,
        scale,
        tol,
        tol_in: (1e-3 * tol).max(1e-13),
    };
    let r0 = if r_start.iter().all(|v| v.is_finite()) {
        r_start
    } else {
        Vec3::zeros()
    };
    let mut used = 0;
    let newton = match method {
        Method::Cases => {
            match solve_by_cases(&ctx, r0, max_iter) {
                Ok(sol) => return sol,
                Err(n) => used = n,
            }
            true
        }
        Method::Bipotential { newton } => newton,
    };
    bipotential_iteration(&ctx, r0, max_iter.saturating_sub(used), newton, used)
}

/// Whether `ev` satisfies the law: fixed-point defect ‖F‖ ≤ tol·(‖r‖ + s).
fn is_solution(ctx: &Ctx, ev: &Eval) -> bool {
    ev.f.norm() <= ctx.tol * ((ev.r_dry + ev.r_adh).norm() + ctx.scale)
}

/// Packs an evaluation into a [`PointSolution`].
fn finish(ev: &Eval, state: ContactState, iterations: usize, converged: bool) -> PointSolution {
    PointSolution {
        r_dry: ev.r_dry,
        r_adh: ev.r_adh,
        x: ev.x,
        history: ev.adh.history,
        state,
        iterations,
        converged,
    }
}

/// Solves the three cases in turn and returns the first one that passes [`is_solution`]:
/// apart (r̄ = 0, the adhesive sub-problem alone, valid when x_n ≥ 0), stick (x = 0, so
/// r̄ = −W⁻¹x_free − r̃(0), valid when r̄ ∈ K_μ), slide (Newton's method on the slide equations).
/// `Err` carries the iterations spent.
fn solve_by_cases(ctx: &Ctx, r_start: Vec3, max_iter: usize) -> Result<PointSolution, usize> {
    let p = ctx.p;
    if max_iter == 0 {
        return Err(0);
    }
    // Apart.
    let ev = evaluate(ctx, Vec3::zeros(), frozen_adhesion_guess(ctx, ctx.x_free));
    if ev.x[2] >= 0.0 && is_solution(ctx, &ev) {
        return Ok(finish(&ev, ContactState::Apart, 1, true));
    }
    // Stick.
    let r_adh0 = if p.law.is_adhesive() {
        adhesion_eval(ctx, Vec3::zeros()).force
    } else {
        Vec3::zeros()
    };
    let r_stick = stick_force(&ctx.w, &ctx.x_free).map(|r| r - r_adh0);
    if let Some(rs) = r_stick {
        if rs[2] >= 0.0 && rs[0].hypot(rs[1]) <= ctx.mu * rs[2] {
            let ev = evaluate(ctx, rs, r_adh0);
            if is_solution(ctx, &ev) {
                return Ok(finish(&ev, ContactState::Stick, 2, true));
            }
        }
    }
    // Slide.
    let mut used = 2;
    if max_iter > used {
        let (ev, n) = solve_slide(ctx, r_start, r_stick, r_adh0, max_iter - used);
        used += n;
        if let Some(ev) = ev {
            if is_solution(ctx, &ev) {
                return Ok(finish(&ev, ContactState::Slide, used, true));
            }
        }
    }
    Err(used)
}

/// Slide equations in the unknowns (r_n, θ, λ): r̄ = r_n (μ cos θ, μ sin θ, 1) on the cone,
/// slip x_t = −λ (cos θ, sin θ) opposing the friction force, x_n = 0:
/// R = x_free + W (r̄ + r̃(x)) − x = 0. Returns R [m], ∂R/∂(r_n, θ, λ), r̄ and r̃.
fn slide_residual(ctx: &Ctx, q: Vec3) -> (Vec3, Mat3, Vec3, Vec3) {
    let p = ctx.p;
    let (rn, th, lam) = (q[0], q[1], q[2]);
    let c = [th.cos(), th.sin()];
    let cp = [-c[1], c[0]];
    let mu = ctx.mu;
    let x = Vec3::new(-lam * c[0], -lam * c[1], 0.0);
    let rd = Vec3::new(mu * rn * c[0], mu * rn * c[1], rn);
    let (ra, k) = if p.law.is_adhesive() {
        let ad = adhesion_eval(ctx, x);
        (ad.force, ad.stiff)
    } else {
        (Vec3::zeros(), Mat3::zeros())
    };
    let w = ctx.w;
    let res = ctx.x_free + w * (rd + ra) - x;
    // ∂R/∂x = −(I + W K) on the tangential columns.
    let a = Mat3::identity() + w * k;
    let d_rn = w * Vec3::new(mu * c[0], mu * c[1], 1.0);
    let d_lam = a * Vec3::new(c[0], c[1], 0.0);
    let d_th = w * Vec3::new(mu * rn * cp[0], mu * rn * cp[1], 0.0)
        + a * Vec3::new(lam * cp[0], lam * cp[1], 0.0);
    let jac = Mat3::from_columns(&[d_rn, d_th, d_lam]);
    (res, jac, rd, ra)
}

/// Newton's method with a backtracking line search on ‖R‖ for the slide equations, started from
/// the friction direction of `r_start` when it lies on the cone, else from the projection of the
/// stick force. Returns the evaluation at the converged dry force and the iterations spent.
fn solve_slide(
    ctx: &Ctx,
    r_start: Vec3,
    r_stick: Option<Vec3>,
    r_adh0: Vec3,
    max_iter: usize,
) -> (Option<Eval>, usize) {
    let mu = ctx.mu;
    let on_cone = |r: Vec3| {
        let t = r[0].hypot(r[1]);
        r[2] > 0.0 && t > 0.0 && (t - mu * r[2]).abs() <= 1e-6 * t
    };
    let base = if on_cone(r_start) {
        r_start
    } else {
        match r_stick {
            Some(rs) => {
                let (pr, _) = dry_projection(rs, mu);
                if pr[0].hypot(pr[1]) > 0.0 {
                    pr
                } else {
                    Vec3::new(rs[0], rs[1], pr[2])
                }
            }
            None => r_start,
        }
    };
    let th0 = if base[0].hypot(base[1]) > 0.0 {
        base[1].atan2(base[0])
    } else {
        0.0
    };
    let mut q = Vec3::new(base[2].max(0.0), th0, 0.0);
    let (mut res, mut jac, mut rd, mut ra) = slide_residual(ctx, q);
    // At the first friction direction, (r_n, λ) by least squares on the linearised equations.
    if let Some((dn, dl)) = least_squares_2(&jac, &res) {
        let q1 = Vec3::new(q[0] + dn, q[1], (q[2] + dl).max(0.0));
        let trial = slide_residual(ctx, q1);
        if trial.0.norm() < res.norm() {
            q = q1;
            (res, jac, rd, ra) = trial;
        }
    }
    let mut iterations = 0;
    let mut converged = false;
    while iterations < max_iter {
        iterations += 1;
        let mut d = match solve3(&jac, &-res) {
            Some(d) if d.iter().all(|v| v.is_finite()) => d,
            _ => break,
        };
        if d[1].abs() > MAX_TURN {
            d *= MAX_TURN / d[1].abs();
        }
        let r_old = rd + ra;
        let m0 = res.norm();
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..SLIDE_HALVINGS {
            let qt = q + d * alpha;
            let trial = slide_residual(ctx, qt);
            let m1 = trial.0.norm();
            if m1 <= (1.0 - 1e-4 * alpha) * m0 || m1 == 0.0 {
                q = qt;
                (res, jac, rd, ra) = trial;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            // No further decrease possible: converged if the residual is already negligible.
            converged = ctx.rho * m0 <= ctx.tol * (r_old.norm() + ctx.scale);
            break;
        }
        let r_new = rd + ra;
        let bound = ctx.tol * (r_new.norm() + ctx.scale);
        if (r_new - r_old).norm() <= bound && ctx.rho * res.norm() <= bound {
            converged = true;
            break;
        }
    }
    if !converged {
        return (None, iterations);
    }
    let guess = if ra == Vec3::zeros() { r_adh0 } else { ra };
    (Some(evaluate(ctx, rd, guess)), iterations)
}

/// Least-squares solution (a, b) of a·J[:,0] + b·J[:,2] = −res (the r_n and λ columns of the
/// slide Jacobian).
fn least_squares_2(jac: &Mat3, res: &Vec3) -> Option<(f64, f64)> {
    let c0 = jac.column(0);
    let c2 = jac.column(2);
    let (a11, a12, a22) = (c0.dot(&c0), c0.dot(&c2), c2.dot(&c2));
    let (b1, b2) = (-c0.dot(res), -c2.dot(res));
    let det = a11 * a22 - a12 * a12;
    if !(det.is_finite() && det > 1e-14 * a11 * a22) {
        return None;
    }
    Some(((b1 * a22 - b2 * a12) / det, (a11 * b2 - a12 * b1) / det))
}

/// The bi-potential iteration on the dry force: r̄ ← Proj(r̄ − ρ(x + μ‖x_t‖n)) with x from the
/// implicit adhesive sub-problem, optionally accelerated by semi-smooth Newton steps kept when
/// they reduce ‖F‖. `offset` iterations were already spent.
fn bipotential_iteration(
    ctx: &Ctx,
    r0: Vec3,
    max_iter: usize,
    newton: bool,
    offset: usize,
) -> PointSolution {
    let z0 = frozen_adhesion_guess(ctx, ctx.x_free + ctx.w * r0);
    let mut ev = evaluate(ctx, r0, z0);
    let mut iterations = 0;
    let mut converged = false;
    while iterations < max_iter {
        iterations += 1;
        let r_old = ev.r_dry + ev.r_adh;
        let fn_old = ev.f.norm();
        let mut next = None;
        if newton {
            if let Some(step) = newton_step(ctx, &ev) {
                let mut alpha = 1.0;
                for _ in 0..NEWTON_HALVINGS {
                    let trial = dry_projection(ev.r_dry + step * alpha, ctx.mu).0;
                    let cand = evaluate(ctx, trial, ev.r_adh);
                    if cand.f.norm() < (1.0 - 1e-4 * alpha) * fn_old {
                        next = Some(cand);
                        break;
                    }
                    alpha *= 0.5;
                }
            }
        }
        ev = match next {
            Some(cand) => cand,
            None => evaluate(ctx, ev.proj, ev.r_adh),
        };
        let r_new = ev.r_dry + ev.r_adh;
        let bound = ctx.tol * (r_new.norm() + ctx.scale);
        if (r_new - r_old).norm() <= bound && ev.f.norm() <= bound {
            converged = true;
            break;
        }
    }
    let state = ev.case;
    let fin = evaluate(ctx, ev.proj, ev.r_adh);
    finish(&fin, state, offset + iterations, converged)
}

/// Evaluates x, the adhesive part and the projection at the dry force `r_dry`, solving the
/// adhesive sub-problem from the adhesive-force guess `z_start`.
fn evaluate(ctx: &Ctx, r_dry: Vec3, z_start: Vec3) -> Eval {
    let y = ctx.x_free + ctx.w * r_dry;
    let (x, r_adh, adh) = if ctx.p.law.is_adhesive() {
        solve_adhesion(ctx, y, z_start)
    } else {
        (y, Vec3::zeros(), AdhEval::default())
    };
    let r_star = bipotential_trial(r_dry, x, ctx.mu, ctx.rho);
    let (proj, case) = dry_projection(r_star, ctx.mu);
    Eval {
        r_dry,
        x,
        r_adh,
        adh,
        r_star,
        proj,
        case,
        f: r_dry - proj,
    }
}

/// Stretch energy density E = C_n x_n⁺² + C_t ‖u_t‖² [N/m].
fn stretch_energy(p: &RccParams, xn: f64, ut: Vec2) -> f64 {
    let xp = xn.max(0.0);
    let tangential = if p.ct2 == p.ct {
        p.ct * (ut[0] * ut[0] + ut[1] * ut[1])
    } else {
        p.ct * ut[0] * ut[0] + p.ct2 * ut[1] * ut[1]
    };
    p.cn * xp * xp + tangential
}

/// β₁ and c = −(∂β₁/∂E)/β₁ [m/N] (0 where β₁ is clamped, cut or frozen).
fn beta_step(beta0: f64, dt: f64, p: &RccParams, e: f64) -> (f64, f64) {
    let beta0 = clamp01(beta0);
    let w = p.w.max(0.0);
    let target = if e > 0.0 {
        (w / e).min(1.0)
    } else if w > 0.0 {
        1.0
    } else {
        beta0
    };
    let (raw, c) = if p.b > 0.0 {
        if dt > 0.0 {
            let den = p.b + dt * e;
            ((p.b * beta0 + dt * w) / den, dt / den)
        } else {
            (beta0, 0.0)
        }
    } else if e > 0.0 {
        (w / e, 1.0 / e)
    } else {
        (target, 0.0)
    };
    if raw >= 1.0 {
        return (1.0, 0.0);
    }
    let beta = clamp01(raw);
    if beta < p.eps && target < p.eps {
        (0.0, 0.0)
    } else {
        (beta, c)
    }
}

/// The adhesive law at x: β₁, u_t, r̃, −∂r̃/∂x and the incremental potential
/// φ = A [½ E β₁² − w β₁ + b/(2Δt) (β₁ − β₀)²] (β₁ minimises the bracket over [0, 1], so
/// ∂φ/∂x = A β₁² ∂E/∂x / 2 = −r̃).
fn adhesion_eval(ctx: &Ctx, x: Vec3) -> AdhEval {
    let (p, s) = (ctx.p, ctx.t2);
    if s == 1.0 {
        return p.law.adhesion_at(&p.history0, p.dt, p.area, x);
    }
    // x is scaled (x' = T x): the law at T⁻¹x', its force as T⁻¹r̃ and stiffness T⁻¹KT⁻¹.
    let mut ev = p.law.adhesion_at(&p.history0, p.dt, p.area, unscale(x, s));
    ev.force = unscale(ev.force, s);
    ev.stiff = unscale_matrix(ev.stiff, s);
    ev
}

/// The RCC law `a` at `x` from the committed bond state, Δt [s] and tributary area [m²]
/// (its [`Interface::adhesion_at`]).
pub(super) fn rcc_adhesion_at(
    bond0: BondState,
    dt: f64,
    area: f64,
    a: &RccParams,
    x: Vec3,
) -> AdhEval {
    rcc_step(bond0, dt, area, a, x).1
}

/// The RCC law `a` at `x` from the committed bond state `bond0`, Δt [s] and tributary area
/// [m²]: the bond state the step leads to (β₁; the stretch u_t0 + x_t while bonded, else 0;
/// D as at the start: the energy dissipated by β₀ → β₁ is added once, when the step is
/// committed, not at every evaluation of the point solvers) and the evaluation, whose
/// history is that state.
fn rcc_step(bond0: BondState, dt: f64, area: f64, a: &RccParams, x: Vec3) -> (BondState, AdhEval) {
    let a = &a.degraded(bond0.damage);
    let ut = bond0.ut + x.xy();
    let e = stretch_energy(a, x[2], ut);
    let (beta, c) = beta_step(bond0.beta, dt, a, e);
    let force = adhesive_force(beta, a, x[2], ut, area);
    let xp = x[2].max(0.0);
    let mut energy = 0.5 * e * beta * beta - a.w.max(0.0) * beta;
    if a.b > 0.0 && dt > 0.0 {
        let d = beta - clamp01(bond0.beta);
        energy += 0.5 * a.b / dt * d * d;
    }
    energy *= area;
    let stiff = if beta > 0.0 {
        let k = area * beta * beta;
        let v = [a.ct * ut[0], a.ct2 * ut[1], a.cn * xp];
        let dn = if x[2] > 0.0 { a.cn } else { 0.0 };
        let diag = [a.ct, a.ct2, dn];
        Mat3::from_fn(|i, j| {
            let d = if i == j { diag[i] } else { 0.0 };
            k * (d - 4.0 * c * v[i] * v[j])
        })
    } else {
        Mat3::zeros()
    };
    let end = BondState {
        beta,
        ut: if beta > 0.0 { ut } else { Vec2::zeros() },
        damage: bond0.damage,
    };
    let ev = AdhEval {
        history: end.encode(),
        force,
        stiff,
        energy,
    };
    (end, ev)
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

/// [`AdhesiveResponse`] of the RCC law `a` at `x` [m], for a point whose committed bond state
/// is `bond0`.
pub fn adhesive_response(
    a: &RccParams,
    bond0: BondState,
    dt: f64,
    area: f64,
    x: Vec3,
) -> AdhesiveResponse {
    let (end, ev) = rcc_step(bond0, dt, area, a, x);
    let k = area * end.beta * end.beta;
    let secant_stiffness = if end.beta > 0.0 {
        let kn = if x[2] > 0.0 { k * a.cn } else { 0.0 };
        Mat3::from_diagonal(&Vec3::new(k * a.ct, k * a.ct2, kn))
    } else {
        Mat3::zeros()
    };
    AdhesiveResponse {
        history: ev.history,
        force: ev.force,
        secant_stiffness,
        energy: ev.energy,
    }
}

/// Adhesive force guess with β frozen at β₀ (linear springs), given y = x_free + W r̄:
/// z = −K₀ (y + e + W z), K₀ = A β₀² diag(C_t, C_t, C_n [y_n > 0]), e = (u_t0, 0).
fn frozen_adhesion_guess(ctx: &Ctx, y: Vec3) -> Vec3 {
    let (p, s) = (ctx.p, ctx.t2);
    if !p.law.is_adhesive() {
        return Vec3::zeros();
    }
    let Some(FrozenSprings {
        stiffness: c,
        stretch: e,
    }) = p.law.frozen_springs(&p.history0, p.area)
    else {
        return Vec3::zeros();
    };
    // In scaled variables the springs are T⁻¹KT⁻¹ and the stretch T e.
    let kd = Vec3::new(c[0], c[1] / (s * s), if y[2] > 0.0 { c[2] } else { 0.0 });
    let rhs = Vec3::new(
        -kd[0] * (y[0] + e[0]),
        -kd[1] * (y[1] + s * e[1]),
        -kd[2] * y[2],
    );
    let m = Mat3::identity() + Mat3::from_diagonal(&kd) * ctx.w;
    match solve3(&m, &rhs) {
        Some(z) if z.iter().all(|v| v.is_finite()) => z,
        _ => Vec3::zeros(),
    }
}

/// Solves z = r̃(y + W z) for the adhesive force z [N] by Newton's method on the potential
/// Π(z) = ½ zᵀW z + φ(y + W z), whose stationary points are the solutions; the line search keeps
/// Π decreasing, so the iteration settles in a local minimum (a stable equilibrium) next to the
/// starting guess and, past a snap-off, slides down to the detached branch.
fn solve_adhesion(ctx: &Ctx, y: Vec3, z_start: Vec3) -> (Vec3, Vec3, AdhEval) {
    let w = ctx.w;
    let mut z = if z_start.iter().all(|v| v.is_finite()) {
        z_start
    } else {
        Vec3::zeros()
    };
    let mut x = y + w * z;
    let mut ad = adhesion_eval(ctx, x);
    for _ in 0..MAX_INNER {
        let res = z - ad.force;
        let size = z.norm() + ad.force.norm() + ctx.scale;
        if res.norm() <= ctx.tol_in * size {
            break;
        }
        let grad = w * res;
        let mut dir = None;
        let m = Mat3::identity() + ad.stiff * w;
        if let Some(d) = solve3(&m, &-res) {
            if grad.dot(&d) <= 0.0 && d.iter().all(|v| v.is_finite()) {
                dir = Some(d);
            }
        }
        let d = match dir {
            Some(d) => d,
            None => shifted_newton_direction(&w, &ad.stiff, &grad).unwrap_or(-res),
        };
        let pi0 = merit(&z, &w, ad.energy);
        let slope = grad.dot(&d);
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let zt = z + d * alpha;
            let xt = y + w * zt;
            let at = adhesion_eval(ctx, xt);
            let pit = merit(&zt, &w, at.energy);
            let slack = 1e-13 * (pi0.abs() + pit.abs());
            if pit <= pi0 + 1e-4 * alpha * slope + slack {
                accepted = Some((zt, xt, at));
                break;
            }
            alpha *= 0.5;
        }
        let (zn, xn, an) = accepted.unwrap_or_else(|| {
            let zt = z + d;
            let xt = y + w * zt;
            (zt, xt, adhesion_eval(ctx, xt))
        });
        let moved = (zn - z).norm();
        z = zn;
        x = xn;
        ad = an;
        if moved <= 1e-15 * (z.norm() + ctx.scale) {
            break;
        }
    }
    (x, z, ad)
}

/// Π(z) = ½ zᵀ W z + φ [J].
fn merit(z: &Vec3, w: &Mat3, energy: f64) -> f64 {
    0.5 * z.dot(&(w * z)) + energy
}

/// Descent direction from the Hessian of Π in z, H = W + W K W, shifted to be positive definite
/// when the interface softens.
fn shifted_newton_direction(w: &Mat3, k: &Mat3, grad: &Vec3) -> Option<Vec3> {
    let h = w + w * (k * w);
    let h = (h + h.transpose()) * 0.5;
    let ev = eig_sym3(&h);
    let big = ev[0].abs().max(ev[2].abs());
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    let shift = (-ev[0]).max(0.0) + 1e-6 * big;
    let hs = h + Mat3::from_diagonal_element(shift);
    solve3(&hs, &-grad).filter(|d| d.iter().all(|v| v.is_finite()))
}

/// Semi-smooth Newton step on F(r̄) = r̄ − Proj(r̄ − ρ g(x(r̄))), g(x) = x + μ‖x_t‖n:
/// ∂F/∂r̄ = I − P′ (I − ρ G W_e), with P′ the Jacobian of the projection in its case,
/// G = ∂g/∂x and W_e = (I + W K)⁻¹ W the compliance seen by r̄ with the adhesive part solved.
fn newton_step(ctx: &Ctx, ev: &Eval) -> Option<Vec3> {
    let m = Mat3::identity() + ctx.w * ev.adh.stiff;
    let we = solve3_mat(&m, &ctx.w)?;
    let gw = modified_displacement_jacobian(ev.x, ctx.mu) * we;
    let a = Mat3::identity() - gw * ctx.rho;
    let pj = projection_jacobian(ev.r_star, ctx.mu, ev.case);
    let jac = Mat3::identity() - pj * a;
    solve3(&jac, &-ev.f).filter(|d| d.iter().all(|v| v.is_finite()))
}

/// Jacobian of [`dry_projection`] at `r_star` in the given case (symmetric, eigenvalues in
/// [0, 1]).
pub fn projection_jacobian(r_star: Vec3, mu: f64, case: ContactState) -> Mat3 {
    match case {
        ContactState::Apart => Mat3::zeros(),
        ContactState::Stick => Mat3::identity(),
        ContactState::Slide => {
            let s = r_star[0].hypot(r_star[1]);
            let q = 1.0 + mu * mu;
            if s.is_nan() || s <= 0.0 {
                let mut j = Mat3::zeros();
                j[(2, 2)] = 1.0 / q;
                return j;
            }
            let t = [r_star[0] / s, r_star[1] / s];
            let rn = ((r_star[2] + mu * s) / q).max(0.0);
            let mut j = Mat3::zeros();
            for a in 0..2 {
                for b in 0..2 {
                    let delta = if a == b { 1.0 } else { 0.0 };
                    j[(a, b)] = mu * mu * t[a] * t[b] / q + mu * rn / s * (delta - t[a] * t[b]);
                }
                j[(a, 2)] = mu * t[a] / q;
                j[(2, a)] = mu * t[a] / q;
            }
            j[(2, 2)] = 1.0 / q;
            j
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Small dense helpers.

pub(super) fn clamp01(v: f64) -> f64 {
    if v > 1.0 {
        1.0
    } else if v > 0.0 {
        v
    } else {
        0.0
    }
}

/// The total force r with W r = −x_free (the point stuck: x = 0). Where the compliance W has
/// a local axis along which no force moves the point (a diagonal entry negligible against the
/// largest, e.g. the out-of-plane tangent of a plane-strain model, whose unknowns are held),
/// the force has no component along it (the least-norm solution) provided x_free has none
/// either; the other components solve the remaining rows. None when no such force exists.
fn stick_force(w: &Mat3, x_free: &Vec3) -> Option<Vec3> {
    if let Some(r) = solve3(w, &-x_free) {
        return Some(r);
    }
    let big = w.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    // W is symmetric positive semi-definite: a negligible diagonal entry bounds its whole row
    // and column (|W_ij| ≤ √(W_ii W_jj)).
    let null: [bool; 3] = std::array::from_fn(|i| w[(i, i)].abs() <= 1e-12 * big);
    let free: Vec<usize> = (0..3).filter(|&i| !null[i]).collect();
    if free.len() == 3 || free.is_empty() {
        return None;
    }
    // A direction the force cannot move must already be at rest.
    let scale = x_free.norm();
    if (0..3).any(|i| null[i] && x_free[i].abs() > 1e-9 * scale) {
        return None;
    }
    let mut r = Vec3::zeros();
    match *free.as_slice() {
        [a] => {
            r[a] = -x_free[a] / w[(a, a)];
        }
        [a, b] => {
            let det = w[(a, a)] * w[(b, b)] - w[(a, b)] * w[(b, a)];
            if det.is_nan() || det.abs() <= 1e-14 * big * big {
                return None;
            }
            r[a] = (-x_free[a] * w[(b, b)] + x_free[b] * w[(a, b)]) / det;
            r[b] = (-x_free[b] * w[(a, a)] + x_free[a] * w[(b, a)]) / det;
        }
        _ => return None,
    }
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Solves m x = b by Gaussian elimination with partial pivoting; `None` when m is singular to
/// working precision (a pivot at most 1e-14 times the largest entry of m).
fn solve3(m: &Mat3, b: &Vec3) -> Option<Vec3> {
    let mut a = *m;
    let mut r = *b;
    let big = a.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    for col in 0..3 {
        let mut piv = col;
        for row in col + 1..3 {
            if a[(row, col)].abs() > a[(piv, col)].abs() {
                piv = row;
            }
        }
        let pivot = a[(piv, col)].abs();
        if pivot.is_nan() || pivot <= 1e-14 * big {
            return None;
        }
        if piv != col {
            a.swap_rows(col, piv);
            r.swap_rows(col, piv);
        }
        for row in col + 1..3 {
            let f = a[(row, col)] / a[(col, col)];
            for k in col..3 {
                a[(row, k)] -= f * a[(col, k)];
            }
            r[row] -= f * r[col];
        }
    }
    let mut x = Vec3::zeros();
    for i in (0..3).rev() {
        let mut s = r[i];
        for k in i + 1..3 {
            s -= a[(i, k)] * x[k];
        }
        x[i] = s / a[(i, i)];
    }
    Some(x)
}

/// Solves m X = b column by column.
fn solve3_mat(m: &Mat3, b: &Mat3) -> Option<Mat3> {
    let mut out = Mat3::zeros();
    for j in 0..3 {
        let col = solve3(m, &b.column(j).into_owned())?;
        out.set_column(j, &col);
    }
    Some(out)
}

/// Eigenvalues of a symmetric 3×3 matrix in ascending order (trigonometric closed form).
fn eig_sym3(a: &Mat3) -> Vec3 {
    let p1 = a[(0, 1)] * a[(0, 1)] + a[(0, 2)] * a[(0, 2)] + a[(1, 2)] * a[(1, 2)];
    let q = (a[(0, 0)] + a[(1, 1)] + a[(2, 2)]) / 3.0;
    let d = [a[(0, 0)] - q, a[(1, 1)] - q, a[(2, 2)] - q];
    let p2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    if p.is_nan() || p <= 0.0 {
        return Vec3::repeat(q);
    }
    let b = (a - Mat3::from_diagonal_element(q)) / p;
    let det = b[(0, 0)] * (b[(1, 1)] * b[(2, 2)] - b[(1, 2)] * b[(2, 1)])
        - b[(0, 1)] * (b[(1, 0)] * b[(2, 2)] - b[(1, 2)] * b[(2, 0)])
        + b[(0, 2)] * (b[(1, 0)] * b[(2, 1)] - b[(1, 1)] * b[(2, 0)]);
    let phi = (0.5 * det).clamp(-1.0, 1.0).acos() / 3.0;
    let l_hi = q + 2.0 * p * phi.cos();
    let l_lo = q + 2.0 * p * (phi + 2.0 * PI / 3.0).cos();
    let l_mid = 3.0 * q - l_hi - l_lo;
    Vec3::new(l_lo, l_mid, l_hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::mat3_from_rows;

    /// The RCC history a point's solution leads to.
    fn end(s: &PointSolution) -> BondState {
        BondState::decode(&s.history)
    }

    /// A local vector from its components.
    fn v3(a: f64, b: f64, c: f64) -> Vec3 {
        Vec3::new(a, b, c)
    }

    /// Deterministic generator for randomised tests (splitmix64).
    struct Rng(u64);

    impl Rng {
        fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }

        fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
            let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            lo + (hi - lo) * u
        }

        /// Random symmetric positive definite matrix with eigenvalues in [lo, hi].
        fn spd(&mut self, lo: f64, hi: f64) -> Mat3 {
            let mut q = [Vec3::zeros(); 3];
            for row in q.iter_mut() {
                for v in row.iter_mut() {
                    *v = self.uniform(-1.0, 1.0);
                }
            }
            // Gram-Schmidt on the rows.
            for i in 0..3 {
                for k in 0..i {
                    let d = q[i].dot(&q[k]);
                    q[i] -= q[k] * d;
                }
                let n = q[i].norm();
                q[i] /= n;
            }
            let l = [lo, self.uniform(lo, hi), hi];
            Mat3::from_fn(|i, j| (0..3).map(|k| q[k][i] * l[k] * q[k][j]).sum())
        }
    }

    fn diag(a: f64, b: f64, c: f64) -> Mat3 {
        Mat3::from_diagonal(&v3(a, b, c))
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
    }

    fn assert_vec_close(a: Vec3, b: Vec3, tol: f64) {
        let s = a.norm().max(b.norm()).max(f64::MIN_POSITIVE);
        assert!((a - b).norm() <= tol * s, "{a:?} vs {b:?} (tol {tol})");
    }

    static DRY: std::sync::LazyLock<InterfaceLaw> =
        std::sync::LazyLock::new(|| InterfaceLaw::coulomb(0.3));

    /// Paper-like interface: w = 20 J/m², C_n = C_t = 2e9 N/m³ (x_c = 0.1 mm), b = 0.1 N·s/m.
    fn paper_rcc() -> RccParams {
        RccParams::new(20.0, 2e9, 2e9, 0.1)
    }

    fn problem<'a>(
        law: &'a InterfaceLaw,
        w: Mat3,
        x_free: Vec3,
        bond0: BondState,
    ) -> PointProblem<'a> {
        PointProblem {
            w_aa: w,
            x_free,
            law,
            history0: bond0.encode(),
            dt: 1e-4,
            area: 1e-6,
            rho: default_rho(w),
        }
    }

    /// A bond law that is not RCC, defined here and nowhere else: a linear spring of
    /// stiffness k per unit area [N/m³] on the normal opening, always bonded, with no
    /// history. Plugged into a pair's law, the point solver uses it as it uses RCC.
    #[derive(Debug)]
    struct NormalSpring {
        k: f64,
    }

    impl Interface for NormalSpring {
        fn history_fields(&self) -> &'static [HistoryField] {
            &[]
        }
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
        fn bond_traction(&self) -> f64 {
            self.k * 1e-3
        }
        fn is_adhesive(&self) -> bool {
            true
        }
        fn adhesion_at(&self, _: &PointHistory, _: f64, area: f64, x: Vec3) -> AdhEval {
            let ka = self.k * area;
            let mut history = PointHistory::default();
            history.0[0] = 1.0;
            AdhEval {
                history,
                force: v3(0.0, 0.0, -ka * x[2]),
                stiff: Mat3::from_diagonal(&v3(0.0, 0.0, ka)),
                energy: 0.5 * ka * x[2] * x[2],
            }
        }
        fn frozen_springs(&self, _: &PointHistory, area: f64) -> Option<FrozenSprings> {
            Some(FrozenSprings {
                stiffness: v3(0.0, 0.0, self.k * area),
                stretch: Vec2::zeros(),
            })
        }
        fn adhesive_response(
            &self,
            start: &PointHistory,
            dt: f64,
            area: f64,
            x: Vec3,
        ) -> Option<AdhesiveResponse> {
            let e = self.adhesion_at(start, dt, area, x);
            Some(AdhesiveResponse {
                history: e.history,
                force: e.force,
                secant_stiffness: e.stiff,
                energy: e.energy,
            })
        }
        fn point_history(&self, _: &NodeHistory, _: &[[f64; 3]; 3]) -> PointHistory {
            PointHistory::default()
        }
        fn commit(&self, _: &PointHistory, _: &PointSolution, _: &[[f64; 3]; 3]) -> NodeHistory {
            NodeHistory::default()
        }
        fn release(&self, _: &NodeHistory) -> NodeHistory {
            NodeHistory::default()
        }
    }

    /// A point pulled open (x_free along +n) against a bond law of its own: the dry force is
    /// zero and the spring's force −kA x_n n gives x_n = x_free,n / (1 + W_nn k A) (W
    /// diagonal), with no tangential force; the solver reaches the new law only through the
    /// pair's `InterfaceLaw`. Tolerance 1e-9 relative: the point solver's own.
    #[test]
    fn a_bond_law_of_its_own_is_solved_through_the_pair_law() {
        let law = InterfaceLaw {
            mu: 0.3,
            bond: Arc::new(NormalSpring { k: 2e12 }),
            anisotropy: None,
        };
        let w = Mat3::from_diagonal(&v3(1e-6, 1e-6, 2e-6));
        let x_free = v3(0.0, 0.0, 1e-5);
        let p = problem(&law, w, x_free, BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Apart);
        assert_eq!(s.r_dry, Vec3::zeros());
        let ka = 2e12 * p.area;
        let xn = 1e-5 / (1.0 + 2e-6 * ka);
        assert!((s.x[2] - xn).abs() <= 1e-9 * xn, "{} vs {xn}", s.x[2]);
        assert!((s.r_adh[2] + ka * xn).abs() <= 1e-9 * ka * xn);
        assert_eq!((s.r_adh[0], s.r_adh[1]), (0.0, 0.0));
        assert!(s.bonded());
        assert_eq!(format!("{law:?}").matches("NormalSpring").count(), 1);
    }

    /// Independent check of a point solution against the laws of docs/model.md §5: x = x_free + W r,
    /// r̄ ∈ K_μ, Signorini complementarity, Coulomb sliding rule, and the RCC part.
    fn check_solution(p: &PointProblem, s: &PointSolution, tol: f64) {
        let r = s.r();
        let (w, x_free) = (p.w_aa, p.x_free);
        let x = x_free + w * r;
        let xs = x_free.norm().max(x.norm()).max(f64::MIN_POSITIVE);
        let parts = xs + (w * s.r_dry).norm() + (w * s.r_adh).norm();
        assert!(
            (x - s.x).norm() <= 1e-12 * parts,
            "x = x_free + W r: {x:?} vs {:?} ({s:?}, {p:?})",
            s.x
        );
        let mu = p.law.mu;
        let fs = r.norm() + p.rho * x_free.norm();
        let rd = s.r_dry;
        assert!(rd[2] >= 0.0, "dry normal force is compressive");
        assert!(rd[0].hypot(rd[1]) <= mu * rd[2] * (1.0 + 1e-12) + 1e-300);
        let xt = x[0].hypot(x[1]);
        match s.state {
            ContactState::Apart => {
                assert_eq!(rd, Vec3::zeros());
                assert!(x[2] >= -tol * xs, "apart means open gap: {}", x[2]);
            }
            ContactState::Stick => {
                assert!(x[2].abs() <= tol * xs, "stick gap {}", x[2]);
                assert!(xt <= tol * xs, "stick slip {xt}");
            }
            ContactState::Slide => {
                assert!(x[2].abs() <= tol * xs, "slide gap {}", x[2]);
                let rt = rd[0].hypot(rd[1]);
                assert!((rt - mu * rd[2]).abs() <= tol * fs, "on the cone");
                if rt > tol * fs && xt > tol * xs {
                    let c = (rd[0] * x[0] + rd[1] * x[1]) / (rt * xt);
                    assert!(c < -1.0 + 1e-6, "friction opposes slip: cos = {c}");
                }
            }
        }
        let adhesion = p
            .law
            .as_any()
            .downcast_ref::<super::super::rcc::Rcc>()
            .unwrap()
            .0;
        match &adhesion {
            None => assert_eq!(s.r_adh, Vec3::zeros()),
            Some(a) => {
                let (b0, b1) = (BondState::decode(&p.history0), end(s));
                let ut = Vec2::new(b0.ut[0] + x[0], b0.ut[1] + x[1]);
                let beta = beta_update(b0.beta, p.dt, a, x[2], ut);
                assert!((beta - b1.beta).abs() <= 1e-9, "β {beta} vs {}", b1.beta);
                let ra = adhesive_force(beta, a, x[2], ut, p.area);
                let scale = ra.norm() + p.area * a.peak_traction();
                assert!(
                    (ra - s.r_adh).norm() <= tol * scale,
                    "{ra:?} vs {:?}",
                    s.r_adh
                );
            }
        }
    }

    // ------------------------------------------------------------------ projection

    #[test]
    fn projection_cases_match_hand_values() {
        // Separating: μ‖r*_t‖ = 0.05 < 1 = −r*_n.
        let (r, c) = dry_projection(v3(0.1, 0.0, -1.0), 0.5);
        assert_eq!((r, c), (Vec3::zeros(), ContactState::Apart));
        // Sticking: ‖r*_t‖ = 0.5 ≤ 1 = μ r*_n.
        let (r, c) = dry_projection(v3(0.3, 0.4, 2.0), 0.5);
        assert_eq!((r, c), (v3(0.3, 0.4, 2.0), ContactState::Stick));
        // Sliding (docs/model.md §5.1): μ = 1, r* = (2, 0, 0) → r_n = 1, r_t = (1, 0).
        let (r, c) = dry_projection(v3(2.0, 0.0, 0.0), 1.0);
        assert_eq!(c, ContactState::Slide);
        assert_vec_close(r, v3(1.0, 0.0, 1.0), 1e-15);
        // Sliding: μ = 0.5, r* = (3, 4, 1): r_n = (1 + 2.5)/1.25 = 2.8, r_t = 1.4 (0.6, 0.8).
        let (r, c) = dry_projection(v3(3.0, 4.0, 1.0), 0.5);
        assert_eq!(c, ContactState::Slide);
        assert_vec_close(r, v3(0.84, 1.12, 2.8), 1e-15);
        // Sliding from below the apex plane: μ = 2, r* = (3, 0, −1): r_n = (−1 + 6)/5 = 1.
        let (r, c) = dry_projection(v3(3.0, 0.0, -1.0), 2.0);
        assert_eq!(c, ContactState::Slide);
        assert_vec_close(r, v3(2.0, 0.0, 1.0), 1e-15);
    }

    #[test]
    fn projection_frictionless() {
        let (r, c) = dry_projection(v3(1.0, -2.0, 3.0), 0.0);
        assert_eq!((r, c), (v3(0.0, 0.0, 3.0), ContactState::Slide));
        let (r, c) = dry_projection(v3(1.0, -2.0, -3.0), 0.0);
        assert_eq!((r, c), (Vec3::zeros(), ContactState::Apart));
        let (r, c) = dry_projection(v3(0.0, 0.0, 3.0), 0.0);
        assert_eq!((r, c), (v3(0.0, 0.0, 3.0), ContactState::Stick));
        // Negative μ is treated as 0.
        assert_eq!(dry_projection(v3(1.0, 0.0, 1.0), -0.5).0, v3(0.0, 0.0, 1.0));
    }

    #[test]
    fn sliding_projection_is_orthogonal_closed_form() {
        // r* − r = (‖r*_t‖ − μ r*_n)/(1 + μ²) (t̂, −μ): normal to the cone's generator (μ t̂, 1)
        // through r, and r itself lies on that generator.
        let mu = 0.7;
        let rs = v3(1.5, -2.0, 0.4);
        let (r, c) = dry_projection(rs, mu);
        assert_eq!(c, ContactState::Slide);
        let st = rs[0].hypot(rs[1]);
        let t = [rs[0] / st, rs[1] / st];
        let k = (st - mu * rs[2]) / (1.0 + mu * mu);
        let y = rs - r;
        assert_vec_close(y, v3(k * t[0], k * t[1], -k * mu), 1e-14);
        let gen = v3(mu * t[0], mu * t[1], 1.0);
        assert!(y.dot(&gen).abs() <= 1e-14 * rs.norm());
        let rn = r[2];
        assert_vec_close(r, rn * gen, 1e-14);
    }

    #[test]
    fn paper_plus_sign_would_leave_the_cone() {
        // Eq 32 as printed: r = r* − (‖r*_t‖ − μ r*_n)/(1 + μ²) (t̂ + μ n).
        let (mu, rs) = (1.0, v3(2.0, 0.0, 0.0));
        let k = (2.0 - mu * 0.0) / (1.0 + mu * mu);
        let printed = [rs[0] - k, rs[1], rs[2] - k * mu];
        assert!(printed[2] < 0.0, "printed sign gives r_n = {}", printed[2]);
        let (ours, _) = dry_projection(rs, mu);
        assert!(ours[2] > 0.0 && (ours[0].hypot(ours[1]) - mu * ours[2]).abs() < 1e-15);
    }

    #[test]
    fn projection_random_properties() {
        let mut rng = Rng(7);
        let mut hits = [0usize; 3];
        for i in 0..20_000 {
            let mu = if i % 10 == 0 {
                0.0
            } else {
                rng.uniform(0.0, 1.5)
            };
            let mag = 10f64.powf(rng.uniform(-6.0, 6.0));
            let rs = v3(
                mag * rng.uniform(-1.0, 1.0),
                mag * rng.uniform(-1.0, 1.0),
                mag * rng.uniform(-1.0, 1.0),
            );
            let (r, c) = dry_projection(rs, mu);
            hits[c as usize] += 1;
            let s = rs.norm();
            let tol = 1e-12 * s;
            // In the cone.
            assert!(r[2] >= 0.0);
            assert!(r[0].hypot(r[1]) <= mu * r[2] + tol, "{rs:?} μ={mu}");
            // Idempotent.
            let (rr, cc) = dry_projection(r, mu);
            assert!((rr - r).norm() <= tol, "idempotence {rs:?} μ={mu}");
            if r.norm() > 0.0 {
                assert_ne!(cc, ContactState::Apart);
            }
            // Moreau: y = r* − r lies in the polar cone {μ‖y_t‖ ≤ −y_n} and y ⊥ r.
            let y = rs - r;
            assert!(mu * y[0].hypot(y[1]) + y[2] <= tol, "polar {rs:?} μ={mu}");
            assert!(
                y.dot(&r).abs() <= 1e-12 * s * s,
                "orthogonality {rs:?} μ={mu}"
            );
            // Nearest point: no random point of the cone is closer.
            let d = y.norm();
            for _ in 0..4 {
                let kn = mag * rng.uniform(0.0, 2.0);
                let ang = rng.uniform(0.0, 2.0 * PI);
                let kt = mu * kn * rng.uniform(0.0, 1.0);
                let k = v3(kt * ang.cos(), kt * ang.sin(), kn);
                assert!((rs - k).norm() >= d - tol);
            }
        }
        assert!(hits.iter().all(|&h| h > 1000), "all cases hit: {hits:?}");
    }

    #[test]
    fn bipotential_trial_by_hand() {
        // r* = r̄ − ρ (x + μ‖x_t‖ n): ‖x_t‖ = 5e-3, μ‖x_t‖ = 2.5e-3.
        let r = bipotential_trial(v3(1.0, 2.0, 3.0), v3(3e-3, -4e-3, 1e-3), 0.5, 100.0);
        assert_vec_close(r, v3(0.7, 2.4, 3.0 - 0.35), 1e-15);
    }

    // ------------------------------------------------------------------ β and adhesive force

    #[test]
    fn bonding_in_closed_contact_is_linear_in_time() {
        let p = paper_rcc();
        let dt = 1.5e-4; // Δt w/b = 0.03
        let mut beta = 0.0;
        for k in 1..=50 {
            beta = beta_update(beta, dt, &p, 0.0, Vec2::zeros());
            let expect = (k as f64 * dt * p.w / p.b).min(1.0);
            assert!(
                (beta - expect).abs() <= 1e-13,
                "step {k}: {beta} vs {expect}"
            );
        }
        assert_eq!(beta, 1.0);
        // A negative gap stretches nothing.
        assert!((beta_update(0.0, dt, &p, -1e-3, Vec2::zeros()) - 0.03).abs() <= 1e-15);
    }

    #[test]
    fn bonding_survives_steps_below_the_cut_off() {
        // Δt w/b = 1e-6 < ε: each step's β is below ε but the bond is forming (β∞ = 1).
        let p = paper_rcc();
        let dt = 5e-9;
        let mut beta = 0.0;
        for _ in 0..1000 {
            beta = beta_update(beta, dt, &p, 0.0, Vec2::zeros());
        }
        assert!((beta - 1e-3).abs() <= 1e-12, "{beta}");
    }

    #[test]
    fn held_opening_converges_at_first_order() {
        let p = paper_rcc();
        let x = 2.0 * p.critical_opening();
        let binf = p.w / (p.cn * x * x);
        assert!((binf - 0.25).abs() < 1e-12);
        let tau = p.b / (p.cn * x * x);
        let t_end = 2.0 * tau;
        let exact = binf + (1.0 - binf) * (-t_end / tau).exp();
        let err = |n: usize| {
            let dt = t_end / n as f64;
            let mut b = 1.0;
            for _ in 0..n {
                b = beta_update(b, dt, &p, x, Vec2::zeros());
            }
            (b - exact).abs()
        };
        let e = v3(err(40), err(80), err(160));
        let o1 = (e[0] / e[1]).log2();
        let o2 = (e[1] / e[2]).log2();
        assert!(
            (0.9..=1.1).contains(&o1) && (0.9..=1.1).contains(&o2),
            "{o1} {o2}"
        );
        assert!(e[2] < 2e-3, "error {}", e[2]);
        // Long hold: the equilibrium β∞ is reached.
        let mut b = 1.0;
        for _ in 0..200 {
            b = beta_update(b, tau, &p, x, Vec2::zeros());
        }
        assert!(rel(b, binf) < 1e-12);
        // The same with a tangential stretch: E = C_t ‖u_t‖² only.
        let mut b = 1.0;
        for _ in 0..200 {
            b = beta_update(b, tau, &p, 0.0, Vec2::new(0.6 * x, 0.8 * x));
        }
        assert!(rel(b, binf) < 1e-12);
    }

    #[test]
    fn rate_independent_limit() {
        let mut p = paper_rcc();
        p.b = 0.0;
        let xc = p.critical_opening();
        for f in [0.0, 0.5, 1.0, 1.5, 3.0, 20.0, 99.0] {
            let x = f * xc;
            let expect = if x > 0.0 {
                (p.w / (p.cn * x * x)).min(1.0)
            } else {
                1.0
            };
            for dt in [1e-3, 0.0] {
                let b = beta_update(0.3, dt, &p, x, Vec2::zeros());
                assert!(rel(b, expect) < 1e-14, "x = {f} x_c: {b} vs {expect}");
            }
        }
        let b = beta_update(0.0, 1.0, &p, xc, Vec2::new(xc, 0.0));
        assert!(rel(b, 0.5) < 1e-14);
    }

    #[test]
    fn cut_off() {
        let p = paper_rcc();
        let xc = p.critical_opening();
        // A decaying bond that falls below ε is broken.
        let x = 200.0 * xc; // β∞ = 2.5e-5 < ε
        assert_eq!(beta_update(2e-4, 1.0, &p, x, Vec2::zeros()), 0.0);
        // Still above ε: kept.
        let b = beta_update(2e-4, 1e-9, &p, x, Vec2::zeros());
        assert!(b > 1e-4 && b < 2e-4);
        // β₀ = 0 far away: no bond.
        assert_eq!(beta_update(0.0, 1e-3, &p, x, Vec2::zeros()), 0.0);
        // β₀ = 0 within √(w/(ε C_n)) = 100 x_c: the bond forms, per the law.
        let x = 50.0 * xc; // β∞ = 4e-4
        let dt = 1e-7;
        let b = beta_update(0.0, dt, &p, x, Vec2::zeros());
        let expect = dt * p.w / (p.b + dt * p.cn * x * x);
        assert!(b < p.eps && rel(b, expect) < 1e-14, "{b} vs {expect}");
        let dt = 1e-3;
        // Rate-independent: β = β∞ cut at ε.
        let mut q = p;
        q.b = 0.0;
        assert_eq!(beta_update(0.0, dt, &q, 200.0 * xc, Vec2::zeros()), 0.0);
        assert!(rel(beta_update(0.0, dt, &q, x, Vec2::zeros()), 4e-4) < 1e-12);
        // A larger ε cuts more.
        q.eps = 1e-3;
        assert_eq!(beta_update(0.0, dt, &q, x, Vec2::zeros()), 0.0);
    }

    #[test]
    fn beta_stays_in_unit_interval() {
        // β₁ ∈ Vec2::new(0, 1), lies between β₀ and β∞ = min(1, w/E), and is below ε only while forming.
        let mut rng = Rng(11);
        for _ in 0..10_000 {
            let p = RccParams {
                fatigue_energy: f64::INFINITY,
                w: rng.uniform(0.0, 50.0),
                cn: 10f64.powf(rng.uniform(6.0, 12.0)),
                ct: 10f64.powf(rng.uniform(6.0, 12.0)),
                ct2: f64::NAN,
                b: if rng.uniform(0.0, 1.0) < 0.2 {
                    0.0
                } else {
                    10f64.powf(rng.uniform(-6.0, 1.0))
                },
                eps: DEFAULT_BETA_EPS,
            };
            let p = RccParams { ct2: p.ct, ..p };
            let beta0 = rng.uniform(0.0, 1.0);
            let xn = rng.uniform(-1e-3, 1e-3);
            let ut = Vec2::new(rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3));
            let b = beta_update(beta0, 10f64.powf(rng.uniform(-8.0, 0.0)), &p, xn, ut);
            assert!((0.0..=1.0).contains(&b), "{b}");
            let e = stretch_energy(&p, xn, ut);
            let binf = if e > 0.0 { (p.w / e).min(1.0) } else { 1.0 };
            if b > 0.0 {
                let (lo, hi) = (beta0.min(binf), beta0.max(binf));
                assert!(
                    b >= lo * (1.0 - 1e-12) && b <= hi * (1.0 + 1e-12),
                    "{b} {beta0} {binf}"
                );
                assert!(b >= p.eps || binf >= p.eps, "{b} below ε and not forming");
            } else {
                assert!(
                    binf < p.eps || p.w == 0.0 || b == beta0,
                    "{b} {beta0} {binf}"
                );
            }
        }
        // Out-of-range β₀ is clamped.
        let p = paper_rcc();
        assert_eq!(beta_update(1.5, 0.0, &p, 0.0, Vec2::zeros()), 1.0);
        assert_eq!(beta_update(-0.5, 0.0, &p, 0.0, Vec2::zeros()), 0.0);
    }

    #[test]
    fn adhesive_force_signs_and_values() {
        let p = paper_rcc();
        let r = adhesive_force(0.5, &p, 1e-5, Vec2::new(2e-5, -1e-5), 1e-6);
        // β² A = 2.5e-7: C_n x β² A = 2e9 · 1e-5 · 2.5e-7 = 5e-3 N.
        assert_vec_close(r, v3(-1e-2, 5e-3, -5e-3), 1e-14);
        // Closed gap: no normal adhesive force, tangential one still there.
        let r = adhesive_force(1.0, &p, -1e-5, Vec2::new(1e-5, 0.0), 1e-6);
        assert_eq!(r[2], 0.0);
        assert!(r[0] < 0.0);
        assert_eq!(
            adhesive_force(0.0, &p, 1e-5, Vec2::new(1e-5, 1e-5), 1e-6),
            Vec3::zeros()
        );
    }

    #[test]
    fn quasi_static_pull_off() {
        // b = 1e-6 N·s/m, opening at 0.1 mm/s: b/(Δt E) ≤ 5e-5 beyond x_c, effectively b → 0.
        let p = RccParams::new(20.0, 2e9, 2e9, 1e-6);
        let xc = p.critical_opening();
        let v = 1e-4;
        let (mut x, mut beta) = (0.0_f64, 1.0);
        let (mut work, mut t_prev) = (0.0, 0.0);
        let (mut peak, mut x_peak) = (0.0_f64, 0.0);
        let mut max_dev = 0.0_f64;
        while x < 300.0 * xc {
            // Uniform steps of x_c/1000 up to 3 x_c, then 0.1 % geometric growth.
            let dx = if x < 3.0 * xc { 1e-3 * xc } else { 1e-3 * x };
            x += dx;
            beta = beta_update(beta, dx / v, &p, x, Vec2::zeros());
            let t = -adhesive_force(beta, &p, x, Vec2::zeros(), 1.0)[2];
            let b_qs = (p.w / (p.cn * x * x)).min(1.0);
            let t_qs = p.cn * x * b_qs * b_qs;
            if b_qs >= p.eps {
                max_dev = max_dev.max((t - t_qs).abs() / p.peak_traction());
            }
            work += 0.5 * (t + t_prev) * dx;
            t_prev = t;
            if t > peak {
                peak = t;
                x_peak = x;
            }
        }
        assert!(max_dev < 1e-5, "traction deviates by {max_dev} of the peak");
        assert!(rel(peak, (p.cn * p.w).sqrt()) < 1e-9, "peak {peak}");
        assert!(
            (x_peak - xc).abs() <= 1e-3 * xc,
            "peak at {} x_c",
            x_peak / xc
        );
        // Work of separation: w, less the tail beyond the cut-off (β∞ = ε at x = x_c/√ε), which
        // carries ∫ w²/(C_n x³) dx = w ε/2.
        assert!(rel(work, p.w) < 1e-4, "work {work} vs w = {}", p.w);
        assert!(rel(work, p.w * (1.0 - 0.5 * p.eps)) < 1e-5, "work {work}");
        assert_eq!(beta, 0.0, "the bond is broken at 300 x_c");
    }

    #[test]
    fn pull_off_through_the_point_solver() {
        // A soft-adhesion point (C_n A W_nn = 2e-3) pulled open quasi-statically (b = 1e-6,
        // Δt = 1 s): the tensile force follows A·C_n x min(1, w/(C_n x²))² at the solved gap and
        // peaks at A·√(C_n w).
        let rcc = RccParams::new(20.0, 2e9, 2e9, 1e-6);
        let law = InterfaceLaw::rcc(0.3, Some(rcc), None);
        let xc = rcc.critical_opening();
        let area = 1e-6;
        let w = diag(1e-6, 1e-6, 1e-6);
        let mut bond = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        };
        let mut peak = 0.0_f64;
        for k in 1..=10_000 {
            let a = 1e-3 * k as f64 * xc;
            let mut p = problem(&law, w, v3(0.0, 0.0, a), bond);
            p.dt = 1.0;
            let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
            assert!(s.converged && s.iterations == 1, "step {k}: {s:?}");
            assert_eq!(s.state, ContactState::Apart);
            let x = s.x[2];
            let b = (rcc.w / (rcc.cn * x * x)).min(1.0);
            let expect = area * rcc.cn * x * b * b;
            let scale = area * rcc.peak_traction();
            assert!((-s.r()[2] - expect).abs() <= 1e-5 * scale, "step {k}");
            peak = peak.max(-s.r()[2]);
            bond = BondState {
                beta: end(&s).beta,
                ut: end(&s).ut,
                damage: 0.0,
            };
        }
        assert!(
            rel(peak, area * (rcc.cn * rcc.w).sqrt()) < 1e-4,
            "peak {peak}"
        );
    }

    #[test]
    fn stiff_adhesion_in_contact_sheared() {
        // C_t A W_tt = C_n A W_nn = 100, bonded (β₀ = 1) with a stretched link, pressed and
        // sheared: stick below the friction limit, slide above; the answer comes in ≤ 8
        // iterations either way.
        let law = InterfaceLaw::rcc(0.4, Some(paper_rcc()), None);
        let w = diag(0.05, 0.05, 0.05);
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::new(2e-5, 0.0),
            damage: 0.0,
        };
        // r̃(0) = (−0.04, 0, 0) N; pressing with 0.2 N gives μ r_n = 0.08 N.
        for (shear, state) in [(0.0, ContactState::Stick), (-5e-3, ContactState::Slide)] {
            let p = problem(&law, w, v3(shear, 0.0, -1e-2), bond);
            let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
            assert!(s.converged);
            assert_eq!(s.state, state, "shear {shear}");
            assert!(s.iterations <= 8, "{} iterations", s.iterations);
            check_solution(&p, &s, 1e-10);
            assert!(rel(s.r()[2], 0.2) < 1e-10);
        }
    }

    // ------------------------------------------------------------------ point solver

    #[test]
    fn default_rho_is_inverse_largest_eigenvalue() {
        let w = mat3_from_rows([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(rel(default_rho(w), 1.0 / 3.0) < 1e-14);
        assert!(rel(default_rho(diag(1e-6, 2e-6, 4e-6)), 2.5e5) < 1e-14);
        assert_eq!(default_rho(Mat3::zeros()), 1.0);
        let mut rng = Rng(3);
        for _ in 0..1000 {
            let hi = 10f64.powf(rng.uniform(-6.9, -3.0));
            let w = rng.spd(1e-7, hi);
            let ev = eig_sym3(&w);
            let hi = w
                .row_iter()
                .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
                .fold(0.0, f64::max);
            assert!(ev[2] <= hi * (1.0 + 1e-12) && ev[0] > 0.0);
            let rho = default_rho(w);
            assert!(rel(rho * ev[2], 1.0) < 1e-12);
        }
    }

    #[test]
    fn pressed_into_rigid_support() {
        let w = diag(1e-6, 1e-6, 2e-6);
        let p = problem(&DRY, w, v3(0.0, 0.0, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Stick);
        assert!(s.x[2].abs() <= 1e-12 * 1e-4, "x_n = {}", s.x[2]);
        assert!(rel(s.r_dry[2], 1e-4 / 2e-6) < 1e-10, "r_n = {}", s.r_dry[2]);
        check_solution(&p, &s, 1e-10);
    }

    #[test]
    fn stick_then_slide() {
        let w = diag(1e-6, 1e-6, 2e-6);
        // Stick: the sticking force 10 N < μ r_n = 15 N.
        let p = problem(&DRY, w, v3(1e-5, 0.0, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Stick);
        assert!(s.x[0].hypot(s.x[1]) <= 1e-12 * 1e-4);
        assert_vec_close(s.r(), v3(-10.0, 0.0, 50.0), 1e-10);
        check_solution(&p, &s, 1e-10);
        // Slide: the sticking force would be 50 N > 15 N.
        let p = problem(&DRY, w, v3(3e-5, 4e-5, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Slide);
        assert_vec_close(s.r(), v3(-9.0, -12.0, 50.0), 1e-10);
        assert_vec_close(s.x, v3(2.1e-5, 2.8e-5, 0.0), 1e-10);
        check_solution(&p, &s, 1e-10);
        // Frictionless: r_t = 0, all of x_free_t becomes slip.
        let law = InterfaceLaw::rcc(0.0, None, None);
        let p = problem(&law, w, v3(3e-5, 4e-5, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_vec_close(s.r(), v3(0.0, 0.0, 50.0), 1e-12);
        assert_vec_close(s.x, v3(3e-5, 4e-5, 0.0), 1e-10);
    }

    #[test]
    fn apart_without_adhesion_has_no_force() {
        let w = diag(1e-6, 1e-6, 2e-6);
        let p = problem(&DRY, w, v3(1e-5, 0.0, 1e-4), BondState::default());
        let s = solve_point(&p, v3(5.0, 0.0, 30.0), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Apart);
        assert_eq!(s.r(), Vec3::zeros());
        assert_eq!(s.x, p.x_free);
        assert!(s.iterations <= 2);
    }

    #[test]
    fn bonded_point_opened_slightly_pulls_back() {
        let law = InterfaceLaw::rcc(0.3, Some(paper_rcc()), None);
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        };
        // C_n A = 2e3 N/m; C_n A W_nn = 0.2 (soft) and 100 (stiff adhesion).
        for wnn in [1e-4, 5e-2] {
            let w = diag(1e-4, 1e-4, wnn);
            let p = problem(&law, w, v3(0.0, 0.0, 1e-5), bond);
            let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
            assert!(s.converged, "W_nn = {wnn}");
            let k = 2e9 * 1e-6;
            let xn = 1e-5 / (1.0 + k * wnn);
            assert_eq!(s.state, ContactState::Apart);
            assert_eq!(end(&s).beta, 1.0);
            assert!(rel(s.x[2], xn) < 1e-10, "x_n {} vs {xn}", s.x[2]);
            assert!(rel(s.r()[2], -k * xn) < 1e-10);
            assert!(s.iterations <= 3, "{} iterations", s.iterations);
            check_solution(&p, &s, 1e-10);
        }
    }

    #[test]
    fn bond_stretch_bookkeeping() {
        let law = InterfaceLaw::rcc(0.3, Some(paper_rcc()), None);
        let w = diag(1e-4, 1e-4, 1e-4);
        // Bonded, pressed and pulled sideways: stretch grows by the slip, bond survives.
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::new(1e-6, 0.0),
            damage: 0.0,
        };
        let p = problem(&law, w, v3(2e-3, 0.0, -1e-3), bond);
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(s.converged);
        assert!(end(&s).beta > 0.0);
        assert_eq!(end(&s).ut, Vec2::new(1e-6 + s.x[0], s.x[1]));
        check_solution(&p, &s, 1e-9);
        // Far apart with a weak bond: broken, stretch reset.
        let bond = BondState {
            beta: 2e-4,
            ut: Vec2::new(1e-6, 0.0),
            damage: 0.0,
        };
        let mut p = problem(&law, w, v3(0.0, 0.0, 3e-2), bond);
        p.dt = 1.0;
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(s.converged);
        assert_eq!(end(&s).beta, 0.0);
        assert_eq!(end(&s).ut, Vec2::zeros());
        assert_eq!(s.r(), Vec3::zeros());
    }

    /// A set of point problems over stiffness ratios, loadings and bond states.
    fn sweep_cases(rng: &mut Rng, n: usize, mut f: impl FnMut(&PointProblem, &str)) {
        let area = 1e-6;
        for i in 0..n {
            let ratio = [0.0, 1e-2, 1.0, 100.0, 1e4][i % 5];
            let coupled = (i / 5) % 2 == 1;
            // W with λ_max = W_ref; C_n A W_ref = ratio.
            let wref = if ratio > 0.0 {
                ratio / (2e9 * area)
            } else {
                1e-4
            };
            let w = if coupled {
                rng.spd(wref / 10.0, wref)
            } else {
                diag(
                    wref * rng.uniform(0.3, 1.0),
                    wref * rng.uniform(0.3, 1.0),
                    wref,
                )
            };
            let mu = [0.0, 0.2, 0.4, 0.8, 1.2][(i / 10) % 5];
            let rcc = RccParams::new(20.0, 2e9, 2e9, v3(0.1, 1e-6, 0.0)[(i / 50) % 3]);
            let law = InterfaceLaw::rcc(mu, if ratio > 0.0 { Some(rcc) } else { None }, None);
            let xc = rcc.critical_opening();
            let a = 10f64.powf(rng.uniform(-2.0, 0.7)) * xc * (1.0 + ratio);
            let x_free = v3(
                a * rng.uniform(-1.0, 1.0),
                a * rng.uniform(-1.0, 1.0),
                a * rng.uniform(-1.0, 1.0),
            );
            let bond = BondState {
                beta: [0.0, 1.0, 0.5, 0.01][(i / 3) % 4],
                ut: Vec2::new(xc * rng.uniform(-0.5, 0.5), xc * rng.uniform(-0.5, 0.5)),
                damage: 0.0,
            };
            let p = PointProblem {
                w_aa: w,
                x_free,
                law: &law,
                history0: bond.encode(),
                dt: 1e-4,
                area,
                rho: default_rho(w),
            };
            let label = format!("case {i}: ratio {ratio}, coupled {coupled}, μ {mu}");
            f(&p, &label);
        }
    }

    #[test]
    fn converges_fast_over_stiffness_ratios() {
        // 1500 random problems: C_n A λ_max(W) ∈ {dry, 0.01, 1, 100, 1e4}, diagonal or coupled
        // W (condition number up to 10), μ ∈ {0, 0.2, 0.4, 0.8, 1.2}, b ∈ {0.1, 1e-6, 0},
        // β₀ ∈ {0, 0.01, 0.5, 1}, random stretch and loads from 0.01 to 5 (1 + ratio) x_c.
        let mut rng = Rng(2024);
        let mut stats = [(0usize, 0usize, 0usize); 5];
        let mut states = [0usize; 3];
        sweep_cases(&mut rng, 1500, |p, label| {
            let s = solve_point(p, Vec3::zeros(), 1e-10, 50);
            assert!(s.converged, "{label}: {s:?} {p:?}");
            check_solution(p, &s, 1e-8);
            let k = label_ratio_index(label);
            stats[k].0 = stats[k].0.max(s.iterations);
            stats[k].1 += s.iterations;
            stats[k].2 += 1;
            states[s.state as usize] += 1;
        });
        for (k, (worst, total, n)) in stats.iter().enumerate() {
            let mean = *total as f64 / *n as f64;
            eprintln!("ratio class {k}: worst {worst}, mean {mean:.2} iterations over {n}");
            let (worst_max, mean_max) = if k <= 2 { (10, 4.0) } else { (16, 5.0) };
            assert!(
                *worst <= worst_max && mean <= mean_max,
                "class {k}: {worst} {mean}"
            );
        }
        assert!(states.iter().all(|&n| n > 30), "states {states:?}");
    }

    fn label_ratio_index(label: &str) -> usize {
        let ratio = label
            .split("ratio ")
            .nth(1)
            .and_then(|t| t.split(',').next());
        match ratio {
            Some("0") => 0,
            Some("0.01") => 1,
            Some("1") => 2,
            Some("100") => 3,
            _ => 4,
        }
    }

    #[test]
    fn plain_fixed_point_with_default_rho_converges_for_dry_contact() {
        // The bi-potential fixed point alone (no Newton step) with ρ = 1/λ_max converges and
        // agrees with the case-by-case solver.
        let mut rng = Rng(99);
        let mut worst = 0;
        for i in 0..300 {
            let w = rng.spd(1e-6, 1e-5);
            let law = InterfaceLaw::rcc(v3(0.0, 0.3, 0.8)[i % 3], None, None);
            let x_free = v3(
                rng.uniform(-1e-4, 1e-4),
                rng.uniform(-1e-4, 1e-4),
                rng.uniform(-1e-4, 1e-4),
            );
            let p = problem(&law, w, x_free, BondState::default());
            let fp = solve_point_impl(
                &p,
                Vec3::zeros(),
                1e-10,
                5000,
                Method::Bipotential { newton: false },
            );
            assert!(fp.converged, "case {i}");
            worst = worst.max(fp.iterations);
            let nw = solve_point(&p, Vec3::zeros(), 1e-10, 50);
            assert!(nw.converged);
            assert_eq!(fp.state, nw.state, "case {i}");
            let scale = fp.r().norm() + p.rho * x_free.norm();
            assert!((fp.r() - nw.r()).norm() <= 1e-8 * scale, "case {i}");
        }
        // Condition number 10: the fixed point needs ~κ·ln(1/tol) iterations.
        assert!(worst <= 400, "worst {worst}");
    }

    #[test]
    fn rho_from_max_diagonal_can_diverge() {
        // W = εI + (1 − ε) v vᵀ, v = (1, 1, 1)/√3: λ_max = 1 but W_ii ≈ 1/3, so ρ = 1/max W_ii ≈ 3
        // exceeds 2/λ_max and the sticking iteration r ← r − ρ W r − ρ x_free diverges.
        let eps = 0.05;
        let w = Mat3::from_fn(|i, j| (1.0 - eps) / 3.0 + if i == j { eps } else { 0.0 });
        let law = InterfaceLaw::rcc(1.0, None, None);
        let mut p = problem(&law, w, v3(0.0, 0.0, -1.0), BondState::default());
        let ok = solve_point_impl(
            &p,
            Vec3::zeros(),
            1e-10,
            5000,
            Method::Bipotential { newton: false },
        );
        assert!(ok.converged);
        check_solution(&p, &ok, 1e-8);
        p.rho = 1.0 / w[(0, 0)];
        let bad = solve_point_impl(
            &p,
            Vec3::zeros(),
            1e-10,
            5000,
            Method::Bipotential { newton: false },
        );
        assert!(!bad.converged);
        // The default solver does not depend on ρ for its answer.
        let s = solve_point(&p, Vec3::zeros(), 1e-10, 50);
        assert!(s.converged);
        assert!((s.r() - ok.r()).norm() <= 1e-8 * ok.r().norm());
    }

    #[test]
    fn stiff_snap_off_and_hysteresis() {
        // 1-D pull-off through a compliance with C_n A W_nn = 100, quasi-static (b = 1e-6,
        // Δt = 1 s). The bonded branch x = a/101 holds up to a = 101 x_c, then the point snaps
        // to x ≈ a with β < ε: broken. Coming back, a bond re-forms at a distance (β∞ ≥ ε below
        // 100 x_c) and the point stays on the far branch x + 100 x_c⁴/x³ = a until its turning
        // point a* = (4/3)·300^{1/4} x_c ≈ 5.55 x_c, where it snaps back into the bonded branch.
        let rcc = RccParams::new(20.0, 2e9, 2e9, 1e-6);
        let law = InterfaceLaw::rcc(0.3, Some(rcc), None);
        let xc = rcc.critical_opening();
        let w = diag(0.05, 0.05, 0.05);
        let mut bond = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        };
        let mut r = Vec3::zeros();
        let mut snap_off = None;
        let mut snap_back = None;
        let mut prev_xn = 0.0;
        let steps: Vec<f64> = (0..=300)
            .map(|k| 0.5 * k as f64)
            .chain((0..300).rev().map(|k| 0.5 * k as f64))
            .collect();
        for (k, &af) in steps.iter().enumerate() {
            let mut p = problem(&law, w, v3(0.0, 0.0, af * xc), bond);
            p.dt = 1.0;
            let s = solve_point(&p, r, 1e-12, 50);
            assert!(s.converged, "step {k}");
            check_solution(&p, &s, 1e-9);
            let xn = s.x[2];
            let loading = k <= 300;
            if loading && snap_off.is_none() && xn > 10.0 * xc {
                snap_off = Some(af);
            }
            if !loading && snap_back.is_none() && xn < 2.0 * xc && prev_xn > 2.0 * xc {
                snap_back = Some(af);
            }
            if loading && af < 100.0 {
                assert!(
                    rel(xn, af * xc / 101.0) < 1e-9,
                    "bonded branch at a = {af} x_c"
                );
                assert_eq!(end(&s).beta, 1.0);
            }
            prev_xn = xn;
            bond = BondState {
                beta: end(&s).beta,
                ut: end(&s).ut,
                damage: 0.0,
            };
            r = s.r_dry;
        }
        let off = snap_off.expect("snaps off");
        let back = snap_back.expect("snaps back");
        assert!((101.0..=101.5).contains(&off), "snap-off at a = {off} x_c");
        assert!((5.0..=5.5).contains(&back), "snap-back at a = {back} x_c");
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let rcc = paper_rcc();
        let law = InterfaceLaw::rcc(0.5, Some(rcc), None);
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::new(1e-5, 0.0),
            damage: 0.0,
        };
        let cases: [(Mat3, Vec3, f64, f64); 6] = [
            (Mat3::zeros(), v3(0.0, 0.0, -1e-4), 1e-6, 1e-4),
            (Mat3::zeros(), v3(1e-5, 0.0, 1e-5), 1e-6, 1e-4),
            (diag(1e-4, 1e-4, 1e-4), v3(1e-5, 0.0, 1e-5), 0.0, 1e-4),
            (diag(1e-4, 1e-4, 1e-4), v3(1e-5, 0.0, 1e-5), 1e-6, 0.0),
            (
                diag(1e300, 1.0, 1e-300),
                v3(1e300, -1e300, 1e-300),
                1e300,
                1e300,
            ),
            (diag(1e-4, 1e-4, 1e-4), v3(f64::NAN, 0.0, 1.0), 1e-6, 1e-4),
        ];
        for (w, xf, area, dt) in cases {
            let p = PointProblem {
                w_aa: w,
                x_free: xf,
                law: &law,
                history0: bond.encode(),
                dt,
                area,
                rho: default_rho(w),
            };
            let s = solve_point(&p, v3(1.0, 2.0, 3.0), 1e-10, 30);
            assert!(s.iterations <= 30);
            let _ = solve_point(&p, Vec3::repeat(f64::NAN), 1e-10, 0);
        }
        // W = 0 with an open gap and no adhesion: r = 0 at once.
        let p = PointProblem {
            w_aa: Mat3::zeros(),
            x_free: v3(0.0, 0.0, 1e-3),
            law: &DRY,
            history0: PointHistory::default(),
            dt: 1e-4,
            area: 1e-6,
            rho: 1.0,
        };
        let s = solve_point(&p, Vec3::zeros(), 1e-10, 10);
        assert!(s.converged && s.r() == Vec3::zeros());
    }

    /// Without fatigue, D counts w per unit of β lost and nothing for β gained.
    #[test]
    fn damage_without_fatigue_is_w_times_the_beta_lost() {
        let p = paper_rcc();
        assert_eq!(accumulated_damage(3.0, 0.8, 0.3, &p), 3.0 + 20.0 * 0.5);
        assert_eq!(accumulated_damage(3.0, 0.3, 0.8, &p), 3.0);
        assert_eq!(p.degraded(1e6), p);
    }

    /// The fatigue update integrates dD = −w(D) dβ exactly: the damage after a full break does
    /// not depend on how the decrease of β is split into steps, and after k full breaks it is
    /// D_f ln(1 + k w₀/D_f).
    #[test]
    fn fatigue_damage_is_path_independent_and_matches_its_closed_form() {
        let mut p = paper_rcc();
        p.fatigue_energy = 50.0;
        let (w0, df) = (p.w, p.fatigue_energy);
        let mut d_one = 0.0;
        let mut d_many = 0.0;
        for k in 1..=5 {
            d_one = accumulated_damage(d_one, 1.0, 0.0, &p);
            // 1000 uneven steps from β = 1 to 0.
            let mut beta = 1.0;
            for i in 0..1000 {
                let next = if i == 999 {
                    0.0
                } else {
                    beta * (1.0 - 0.004 * (1.0 + (i % 7) as f64 / 7.0))
                };
                d_many = accumulated_damage(d_many, beta, next, &p);
                beta = next;
            }
            let closed = df * (1.0 + k as f64 * w0 / df).ln();
            assert!(
                (d_one - closed).abs() < 1e-12 * closed,
                "k = {k}: {d_one} vs {closed}"
            );
            assert!(
                (d_many - closed).abs() < 1e-12 * closed,
                "k = {k}: {d_many} vs {closed}"
            );
            let w_k = p.degraded(d_one).w;
            let expect = w0 / (1.0 + k as f64 * w0 / df);
            assert!(
                (w_k - expect).abs() < 1e-12 * expect,
                "k = {k}: w {w_k} vs {expect}"
            );
        }
    }

    /// The adhesive force of a damaged bond peaks at the degraded traction √(C_n w(D)) A:
    /// a rate-independent bond (b = 0) pulled open from β = 1.
    #[test]
    fn damaged_bond_peaks_at_the_degraded_traction() {
        let mut p = RccParams::new(20.0, 2e9, 2e9, 0.0);
        p.fatigue_energy = 40.0;
        let area = 1e-6;
        for k in 0..4 {
            let damage = p.fatigue_energy * (1.0 + k as f64 * p.w / p.fatigue_energy).ln();
            let bond = BondState {
                beta: 1.0,
                ut: Vec2::zeros(),
                damage,
            };
            let xc = p.degraded(damage).critical_opening();
            // The force rises linearly to its kink at x_c and falls as x⁻³ beyond: sample on a
            // grid through x_c.
            let peak = (1..=3000)
                .map(|i| {
                    let x = v3(0.0, 0.0, xc * i as f64 / 1000.0);
                    -adhesive_response(&p, bond, 1e-3, area, x).force[2]
                })
                .fold(0.0, f64::max);
            let expect = area * (p.cn * p.w / (1.0 + k as f64 * p.w / p.fatigue_energy)).sqrt();
            // The sampled maximum of a smooth peak: 4000 samples over 3 x_c put it within
            // (3/4000)² of the true maximum.
            assert!(
                (peak - expect).abs() < 1e-6 * expect,
                "k = {k}: {peak} vs {expect}"
            );
        }
    }
}
