//! The RCC interface law as the stepper and the outputs see it (docs/model.md §5): its history
//! at a slave node (intensity of adhesion β, bond stretch u_t, dissipated adhesive energy D)
//! with its named fields, and the [`Interface`] implementation that reads the history at the
//! start of a step and writes it when the step is committed. Dry Coulomb friction is this law
//! without adhesion ([`InterfaceLaw::coulomb`]): β stays 0 and D keeps what it had.
//!
//! The point solvers evaluate the law itself through [`super::law`] (β update, adhesive force
//! and its tangent, fatigue, orthotropy).

use super::history::{FieldKind, HistoryField, LawHistory, NodeHistory, Slot};
use super::law::{
    accumulated_damage, adhesive_response, AdhesiveResponse, BondState, Interface, InterfaceLaw,
    PointSolution,
};

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

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Interface for InterfaceLaw {
    type History = RccHistory;

    fn bond_traction(&self) -> f64 {
        self.adhesion.map_or(0.0, |a| a.peak_traction())
    }

    fn adhesive_response(
        &self,
        start: &BondState,
        dt: f64,
        area: f64,
        x: [f64; 3],
    ) -> Option<AdhesiveResponse> {
        self.adhesion
            .as_ref()
            .map(|a| adhesive_response(a, *start, dt, area, x))
    }

    fn point_history(&self, node: &NodeHistory, frame: &[[f64; 3]; 3]) -> BondState {
        let h = RccHistory::decode(node);
        BondState {
            beta: h.beta,
            ut: [dot(h.ut, frame[0]), dot(h.ut, frame[1])],
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
