//! A contact pair's discretisation: how its contact sites are found at the start of each
//! step. Every solver, output and checkpoint sees only the sites
//! ([`super::detect::ContactPoint`]: signed node weights, a frame, an area and a constant gap
//! part); a discretisation is one file that implements [`super::detect::Discretisation`]
//! (node-to-surface: `node_to_surface`).

use super::detect::{ContactPair, ContactPoint, Discretisation};
use super::node_to_surface::NodeToSurface;

impl ContactPair {
    /// The pair's discretisation (node-to-surface for every pair today).
    pub fn discretisation(&self) -> &dyn Discretisation {
        &NodeToSurface
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
