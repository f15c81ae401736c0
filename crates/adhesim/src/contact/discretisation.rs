//! A contact pair's discretisation: how its contact sites are found at the start of each
//! step. Every solver, output and checkpoint sees only the sites
//! ([`super::detect::ContactPoint`]: signed node weights, a frame, an area and a constant gap
//! part); a discretisation is one file that implements [`super::detect::Discretisation`]
//! (node-to-surface: `node_to_surface`; mortar: `mortar`).

use super::detect::{ContactPair, ContactPoint, Discretisation};
use super::mortar::Mortar;
use super::node_to_surface::NodeToSurface;

/// The discretisations a contact pair can have.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PairDiscretisation {
    /// Each slave node projected on the master surface, with its tributary area.
    #[default]
    NodeToSurface,
    /// Segment-to-segment: the conditions integrated over the slave faces' overlaps with the
    /// master faces (deformable masters only).
    Mortar,
}

impl PairDiscretisation {
    /// The name the input uses for each, in the order of the variants.
    pub const NAMES: [(&'static str, PairDiscretisation); 2] = [
        ("node-to-surface", PairDiscretisation::NodeToSurface),
        ("mortar", PairDiscretisation::Mortar),
    ];
}

impl ContactPair {
    /// The pair's discretisation.
    pub fn discretisation(&self) -> &dyn Discretisation {
        match self.discretisation {
            PairDiscretisation::NodeToSurface => &NodeToSurface,
            PairDiscretisation::Mortar => &Mortar,
        }
    }
}

/// Detects the contact sites of all pairs at the start of a step [t0, t1] from the
/// displacement `u0`, pair by pair through each pair's [`Discretisation`].
pub fn detect(
    pairs: &[ContactPair],
    reference: &[[f64; 3]],
    u0: &[f64],
    t0: f64,
    t1: f64,
) -> Vec<ContactPoint> {
    let mut out = Vec::new();
    for (pi, pair) in pairs.iter().enumerate() {
        out.extend(pair.discretisation().sites(pi, pair, reference, u0, t0, t1));
    }
    out
}
