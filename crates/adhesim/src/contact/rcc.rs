//! The RCC interface law as the stepper and the outputs see it (docs/model.md §5): its history
//! at a slave node (intensity of adhesion β, bond stretch u_t, dissipated adhesive energy D)
//! with its named fields, and the [`Interface`] implementation that reads the history at the
//! start of a step and writes it when the step is committed. At a contact point within a step
//! the same three quantities, in the point's local frame, are its [`BondState`], encoded to
//! the law-agnostic [`PointHistory`] the solvers carry. Dry Coulomb friction is this law
//! without adhesion ([`InterfaceLaw::coulomb`]): β stays 0 and D keeps what it had.
//!
//! The same implementation gives the point solvers the law's adhesive force, its tangent and
//! warm start (evaluated by [`super::law`]: β update, fatigue) and its checks of a pair's
//! parameters (the adhesive stiffness against the mesh).

use super::history::{
    FieldKind, HistoryField, LawHistory, LawPointHistory, NodeHistory, PointHistory, Slot,
};
use super::law::{
    accumulated_damage, adhesive_response, clamp01, rcc_adhesion_at, AdhEval, AdhesiveResponse,
    BondState, FrozenSprings, Interface, PairScales, PointSolution, RccParams,
};
use crate::{Vec2, Vec3};
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

    fn encode(&self) -> NodeHistory {
        let mut h = NodeHistory::default();
        h.0[0] = self.beta;
        h.0[1..4].copy_from_slice(&self.ut);
        h.0[4] = self.damage;
        h
    }

    fn decode(h: &NodeHistory) -> Self {
        RccHistory {
            beta: h.0[0],
            ut: [h.0[1], h.0[2], h.0[3]],
            damage: h.0[4],
        }
    }
}

impl From<&NodeHistory> for RccHistory {
    fn from(h: &NodeHistory) -> Self {
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

    fn point_history(&self, node: &NodeHistory, frame: &[[f64; 3]; 3]) -> PointHistory {
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
    ) -> NodeHistory {
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

    fn release(&self, node: &NodeHistory) -> NodeHistory {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::law::{ContactState, RccParams};

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
}
