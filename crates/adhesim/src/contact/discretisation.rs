//! A contact pair's discretisation: how its contact sites are found at the start of each
//! step. Every solver, output and checkpoint sees only the sites
//! ([`super::detect::ContactPoint`]: signed node weights, a frame, an area and a constant gap
//! part); a discretisation is one file that implements [`Discretisation`]
//! (node-to-surface: [`super::node_to_surface`]).

use super::detect::{ContactPair, ContactPoint};
use super::node_to_surface::NodeToSurface;

/// How a contact pair is discretised: the contact sites it has at the start of a step. A
/// discretisation is one file (node-to-surface: [`super::node_to_surface`]).
pub trait Discretisation: std::fmt::Debug + Send + Sync {
    /// Its name in scenario files and messages.
    fn name(&self) -> &'static str;

    /// The candidate sites of pair `pair_index` (`pair`) at the start of a step [t0, t1] [s]
    /// from the reference coordinates [m] and the displacement `u0` [m].
    fn sites(
        &self,
        pair_index: usize,
        pair: &ContactPair,
        reference: &[[f64; 3]],
        u0: &[f64],
        t0: f64,
        t1: f64,
    ) -> Vec<ContactPoint>;
}

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
