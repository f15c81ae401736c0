//! The Raous–Cangémi–Cocou interface law (docs/model.md §5): its parameters ([`RccParams`]),
//! its maths at one point (the β update, the adhesive force, the dissipated energy and fatigue)
//! and the law as the stepper and the outputs see it: its history at a slave node (intensity
//! of adhesion β, bond stretch u_t, dissipated adhesive energy D) with its named fields, and
//! the [`Interface`] implementation that reads the history at the start of a step and writes
//! it when the step is committed. At a contact point within a step the same three
//! quantities, in the point's local frame, are its [`BondState`], encoded to the law-agnostic
//! [`PointHistory`] the solvers carry. Dry Coulomb friction is this law without adhesion
//! ([`super::law::InterfaceLaw::coulomb`]): β stays 0 and D keeps what it had.
//!
//! The same implementation gives the point solvers the law's adhesive force, its tangent and
//! warm start, and its checks of a pair's parameters (the adhesive stiffness against the
//! mesh).
//!
//! # Choices
//! - **ε cut-off.** `β < ε` means a broken bond (`β = 0`) unless the bond is *forming*, i.e. the
//!   equilibrium `β∞ = min(1, w/E)` for the current stretch energy `E` is itself `≥ ε`. A plain
//!   `β < ε → 0` would forbid bonding whenever `Δt·w/b < ε`, so bonding would vanish as `Δt → 0`.
//!   The implicit Euler `β₁` is a convex combination of `β₀` and `β∞` (before the clamp at 1), so a
//!   decaying bond below ε always has `β∞ < ε` and is cut exactly as the paper intends.
//! - **Bonds at a distance.** [`beta_update`] follows the RCC law for any gap: from `β₀ = 0` at a
//!   gap `x` a bond forms when `w/(C_n x²) ≥ ε`, i.e. `x ≤ √(w/(ε C_n)) = 100 x_c` for ε = 1e-4
//!   (`x_c = √(w/C_n)`). Its traction there is at most `w²/(C_n x³)`. Candidates beyond the
//!   detection distance are the caller's business: they carry `β = 0` (docs/model.md §5).

use super::history::{
    FieldKind, HistoryField, LawHistory, LawPointHistory, PointHistory, SiteHistory, Slot,
};
use super::interface::{
    AdhEval, AdhesiveResponse, FrozenSprings, Interface, PairScales, PointSolution,
};
use crate::{Mat3, Vec2, Vec3};
use std::sync::{Arc, OnceLock};

/// Warn when C_n·A exceeds this many times E·h (per slave node).
pub const CN_STIFFNESS_RATIO: f64 = 1e4;

/// Length of the adhesive cohesive zone E*/C_n [m]: the plane-strain modulus
/// E* = E/(1 − ν²) [Pa] of the slave body over the adhesive normal stiffness C_n [N/m³].
/// Over a length much shorter than this the body is stiffer than the adhesive layer.
pub fn cohesive_zone_length(young: f64, poisson: f64, cn: f64) -> f64 {
    young / (1.0 - poisson * poisson) / cn
}

/// The history of the RCC law at a slave node, between steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RccHistory {
    /// Intensity of adhesion β ∈ [0, 1] [-].
    pub beta: f64,
    /// Bond stretch u_t in global axes [m].
    pub ut: [f64; 3],
    /// Adhesive energy dissipated at the node so far, D [J/m²]: the interface's memory of
    /// past debonding, which the fatigue law degrades the decohesion energy with (kept when
    /// the node leaves contact).
    pub damage: f64,
}

impl LawHistory for RccHistory {
    const FIELDS: &'static [HistoryField] = &[
        HistoryField {
            name: "beta",
            label: "intensity of adhesion β [-]",
            kind: FieldKind::Scalar,
            slot: Slot::First,
            range: Some((0.0, 1.0)),
        },
        HistoryField {
            name: "ut",
            label: "bond stretch u_t [m]",
            kind: FieldKind::Vector,
            slot: Slot::Motion,
            range: None,
        },
        HistoryField {
            name: "damage",
            label: "dissipated adhesive energy D [J/m²]",
            kind: FieldKind::Scalar,
            slot: Slot::Last,
            range: None,
        },
    ];

    fn encode(&self) -> SiteHistory {
        let mut h = SiteHistory::default();
        h.0[0] = self.beta;
        h.0[1..4].copy_from_slice(&self.ut);
        h.0[4] = self.damage;
        h
    }

    fn decode(h: &SiteHistory) -> Self {
        RccHistory {
            beta: h.0[0],
            ut: [h.0[1], h.0[2], h.0[3]],
            damage: h.0[4],
        }
    }
}

impl From<&SiteHistory> for RccHistory {
    fn from(h: &SiteHistory) -> Self {
        RccHistory::decode(h)
    }
}

/// The RCC bond law with its parameters, or without (`None`): dry contact, whose nodes keep
/// the RCC history (β = 0, no stretch, the damage they had).
#[derive(Clone, Copy)]
pub struct Rcc(pub Option<RccParams>);

impl Rcc {
    /// The law of dry contact, shared: one allocation for the whole program.
    pub fn dry() -> Arc<dyn Interface> {
        static DRY: OnceLock<Arc<dyn Interface>> = OnceLock::new();
        DRY.get_or_init(|| Arc::new(Rcc(None))).clone()
    }
}

/// As the parameters: `None` or `Some(RccParams { .. })`.
impl std::fmt::Debug for Rcc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl Interface for Rcc {
    fn history_fields(&self) -> &'static [HistoryField] {
        RccHistory::FIELDS
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn bond_traction(&self) -> f64 {
        self.0.map_or(0.0, |a| a.peak_traction())
    }

    fn is_adhesive(&self) -> bool {
        self.0.is_some()
    }

    fn adhesion_at(&self, start: &PointHistory, dt: f64, area: f64, x: Vec3) -> AdhEval {
        match &self.0 {
            Some(a) => rcc_adhesion_at(BondState::decode(start), dt, area, a, x),
            None => AdhEval::default(),
        }
    }

    fn warnings(&self, pair: &PairScales, out: &mut Vec<String>) {
        let (Some(a), Some(area)) = (&self.0, pair.mean_area) else {
            return;
        };
        let (e, nu, h) = (pair.young, pair.poisson, pair.edge);
        let zone = cohesive_zone_length(e, nu, a.cn);
        if zone < h {
            out.push(format!(
                "contact {:?}: the cohesive zone E*/C_n = {zone:.3e} m (E* = E/(1 − ν²) = {:.3e} Pa, C_n = {:.3e} N/m³) is shorter than the mean slave edge {h:.3e} m (warning below one edge): the peak adhesive traction falls between nodes and de-bonding jumps from node to node; refine the slave surface to a few elements per {zone:.3e} m or lower C_n",
                pair.name,
                e / (1.0 - nu * nu),
                a.cn
            ));
        }
        let link = a.cn * area;
        let body_stiffness = e * h;
        let ratio = link / body_stiffness;
        if ratio > CN_STIFFNESS_RATIO {
            out.push(format!(
                "contact {:?}: the adhesive normal stiffness per slave node C_n·A = {link:.3e} N/m (C_n = {:.3e} N/m³, mean tributary area {area:.3e} m²) is {ratio:.3e} times (warning above {CN_STIFFNESS_RATIO:.0e}) the body's stiffness per node E·h = {body_stiffness:.3e} N/m (E = {e:.3e} Pa, mean slave edge {h:.3e} m): the contact solve will be ill-conditioned and may need many sweeps or Δt cut-backs; a smaller C_n gives nearly the same response",
                pair.name, a.cn
            ));
        }
    }

    /// Springs A β₀² (C_t, C_t2, C_n) at the undegraded stiffnesses, stretched by u_t0.
    fn frozen_springs(&self, start: &PointHistory, area: f64) -> Option<FrozenSprings> {
        let a = self.0.as_ref()?;
        let start = BondState::decode(start);
        let b0 = clamp01(start.beta);
        let k = area * b0 * b0;
        if k.is_nan() || k <= 0.0 {
            return None;
        }
        Some(FrozenSprings {
            stiffness: Vec3::new(k * a.ct, k * a.ct2, k * a.cn),
            stretch: start.ut,
        })
    }

    fn adhesive_response(
        &self,
        start: &PointHistory,
        dt: f64,
        area: f64,
        x: Vec3,
    ) -> Option<AdhesiveResponse> {
        self.0
            .as_ref()
            .map(|a| adhesive_response(a, BondState::decode(start), dt, area, x))
    }

    fn point_history(&self, node: &SiteHistory, frame: &[[f64; 3]; 3]) -> PointHistory {
        let h = RccHistory::decode(node);
        let ut = Vec3::from(h.ut);
        BondState {
            beta: h.beta,
            ut: Vec2::new(ut.dot(&Vec3::from(frame[0])), ut.dot(&Vec3::from(frame[1]))),
            damage: h.damage,
        }
        .encode()
    }

    /// β₁ and u_t as the step left them, u_t turned to global axes; D accumulated over the
    /// step's β₀ → β₁ (§5.4), or kept from the start without adhesion.
    fn commit(
        &self,
        start: &PointHistory,
        sol: &PointSolution,
        frame: &[[f64; 3]; 3],
    ) -> SiteHistory {
        let (start, end) = (BondState::decode(start), BondState::decode(&sol.history));
        let damage = match &self.0 {
            Some(a) => accumulated_damage(start.damage, start.beta, end.beta, a),
            None => start.damage,
        };
        // The same sums as a frame's rotation of (u_t1, u_t2, 0), to the bit.
        let ut = std::array::from_fn(|k| {
            end.ut[0] * frame[0][k] + end.ut[1] * frame[1][k] + 0.0 * frame[2][k]
        });
        RccHistory {
            beta: end.beta,
            ut,
            damage,
        }
        .encode()
    }

    fn release(&self, node: &SiteHistory) -> SiteHistory {
        let h = RccHistory::decode(node);
        let damage = match &self.0 {
            Some(a) => accumulated_damage(h.damage, h.beta, 0.0, a),
            None => h.damage,
        };
        RccHistory {
            damage,
            ..Default::default()
        }
        .encode()
    }
}

// The RCC law's maths at one point (docs/model.md §5).

/// Default bond cut-off ε of the RCC law: below it a bond is broken.
pub const DEFAULT_BETA_EPS: f64 = 1e-4;

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

pub(super) fn clamp01(v: f64) -> f64 {
    if v > 1.0 {
        1.0
    } else if v > 0.0 {
        v
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::cone::ContactState;
    use crate::contact::test_support::*;

    /// RCC's point history survives its encoding exactly (bit for bit, NaN and −0 included),
    /// and the law-agnostic `bonded` of the encoding is β > 0.
    #[test]
    fn point_history_round_trips_the_bond_state_and_bonded_is_beta_positive() {
        let betas = [
            0.0,
            -0.0,
            1.0,
            0.5,
            1e-300,
            -1e-3,
            f64::MIN_POSITIVE,
            f64::NAN,
            f64::INFINITY,
        ];
        for (i, &beta) in betas.iter().enumerate() {
            let typed = BondState {
                beta,
                ut: Vec2::new(1e-6 * i as f64, -3e-7 / (1.0 + i as f64)),
                damage: [0.0, 12.5, f64::NAN][i % 3],
            };
            let h = typed.encode();
            let back = BondState::decode(&h);
            let bits = |b: &BondState| [b.beta, b.ut[0], b.ut[1], b.damage].map(f64::to_bits);
            assert_eq!(bits(&back), bits(&typed), "β = {beta}");
            assert_eq!(h.bonded(), beta > 0.0, "β = {beta}");
            // The values past RCC's four stay zero.
            assert!(h.0[4..].iter().all(|v| v.to_bits() == 0));
            let sol = PointSolution {
                r_dry: Vec3::zeros(),
                r_adh: Vec3::zeros(),
                x: Vec3::zeros(),
                history: h,
                state: ContactState::Apart,
                iterations: 1,
                converged: true,
            };
            assert_eq!(sol.bonded(), beta > 0.0, "β = {beta}");
        }
    }

    /// A node's history taken to a point's local frame and committed back unchanged (the
    /// point's solution carrying its start history: β kept, so no energy dissipated) is the
    /// node's history again: β and D exactly, u_t (in the tangent plane) to round-off of
    /// the two rotations, 1e-15 of its length.
    #[test]
    fn node_history_through_the_point_frame_and_back() {
        let law = super::super::law::InterfaceLaw::rcc(
            0.3,
            Some(RccParams::new(20.0, 2e9, 2e9, 0.1)),
            None,
        );
        let (c, s) = (0.6_f64, 0.8_f64);
        // Rows t₁, t₂, n: orthonormal, n = t₁ × t₂.
        let frame = [[c, s, 0.0], [0.0, 0.0, 1.0], [s, -c, 0.0]];
        let ut = Vec3::from(frame[0]) * 2e-6 - Vec3::from(frame[1]) * 5e-7;
        let node = RccHistory {
            beta: 0.75,
            ut: ut.into(),
            damage: 3.5,
        }
        .encode();
        let start = law.point_history(&node, &frame);
        let local = BondState::decode(&start);
        assert_eq!((local.beta, local.damage), (0.75, 3.5));
        assert!(start.bonded() && node.bonded());
        let sol = PointSolution {
            r_dry: Vec3::zeros(),
            r_adh: Vec3::zeros(),
            x: Vec3::zeros(),
            history: start,
            state: ContactState::Stick,
            iterations: 1,
            converged: true,
        };
        let back = RccHistory::decode(&law.commit(&start, &sol, &frame));
        assert_eq!((back.beta, back.damage), (0.75, 3.5));
        let err = (Vec3::from(back.ut) - ut).norm();
        assert!(err <= 1e-15 * ut.norm(), "u_t {:?} vs {ut:?}", back.ut);
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
