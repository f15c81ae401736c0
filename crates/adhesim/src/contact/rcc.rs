//! The RCC interface law as the stepper and the outputs see it (docs/model.md §5): its history
//! at a slave node (intensity of adhesion β, bond stretch u_t, dissipated adhesive energy D)
//! with its named fields, and the [`Interface`] implementation that reads the history at the
//! start of a step and writes it when the step is committed. Dry Coulomb friction is this law
//! without adhesion ([`InterfaceLaw::coulomb`]): β stays 0 and D keeps what it had.
//!
//! The same implementation gives the point solvers the law's adhesive force, its tangent and
//! warm start (evaluated by [`super::law`]: β update, fatigue) and its checks of a pair's
//! parameters (the adhesive stiffness against the mesh).

use super::history::{FieldKind, HistoryField, LawHistory, NodeHistory, Slot};
use super::law::{
    accumulated_damage, adhesive_response, clamp01, rcc_adhesion_at, AdhEval, AdhesiveResponse,
    BondState, FrozenSprings, Interface, InterfaceLaw, PairScales, PointSolution,
};
use crate::warnings::{cohesive_zone_length, CN_STIFFNESS_RATIO};
use crate::{Vec2, Vec3};

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

impl Interface for InterfaceLaw {
    type History = RccHistory;

    fn bond_traction(&self) -> f64 {
        self.adhesion.map_or(0.0, |a| a.peak_traction())
    }

    fn is_adhesive(&self) -> bool {
        self.adhesion.is_some()
    }

    fn adhesion_at(&self, start: &BondState, dt: f64, area: f64, x: Vec3) -> AdhEval {
        match &self.adhesion {
            Some(a) => rcc_adhesion_at(*start, dt, area, a, x),
            None => AdhEval::default(),
        }
    }

    fn warnings(&self, pair: &PairScales, out: &mut Vec<String>) {
        let (Some(a), Some(area)) = (&self.adhesion, pair.mean_area) else {
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
    fn frozen_springs(&self, start: &BondState, area: f64) -> Option<FrozenSprings> {
        let a = self.adhesion.as_ref()?;
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
        start: &BondState,
        dt: f64,
        area: f64,
        x: Vec3,
    ) -> Option<AdhesiveResponse> {
        self.adhesion
            .as_ref()
            .map(|a| adhesive_response(a, *start, dt, area, x))
    }

    fn point_history(&self, node: &NodeHistory, frame: &[[f64; 3]; 3]) -> BondState {
        let h = RccHistory::decode(node);
        let ut = Vec3::from(h.ut);
        BondState {
            beta: h.beta,
            ut: Vec2::new(ut.dot(&Vec3::from(frame[0])), ut.dot(&Vec3::from(frame[1]))),
            damage: h.damage,
        }
    }

    fn commit(&self, start: &BondState, sol: &PointSolution, frame: &[[f64; 3]; 3]) -> NodeHistory {
        let damage = match &self.adhesion {
            Some(a) => accumulated_damage(start.damage, start.beta, sol.beta, a),
            None => start.damage,
        };
        // The same sums as a frame's rotation of (u_t1, u_t2, 0), to the bit.
        let ut = std::array::from_fn(|k| {
            sol.ut[0] * frame[0][k] + sol.ut[1] * frame[1][k] + 0.0 * frame[2][k]
        });
        RccHistory {
            beta: sol.beta,
            ut,
            damage,
        }
        .encode()
    }

    fn release(&self, node: &NodeHistory) -> NodeHistory {
        let h = RccHistory::decode(node);
        let damage = match &self.adhesion {
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
