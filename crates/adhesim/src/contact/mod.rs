//! Frictional contact with recoverable adhesion (docs/model.md §4-§7), in three parts.
//!
//! Kinematics (where the contact sites are, and how they move with the nodes):
//! - [`detect`]: contact pairs, a site's kinematics ([`detect::ContactPoint`]: local frame,
//!   gap, area and its stencil, the signed (node, weight) pairs of H), rigid master shapes,
//!   tributary areas and the [`detect::Discretisation`] trait;
//! - [`discretisation`]: the sites of every pair at the start of a step;
//!   `node_to_surface`: single-pass node-to-surface detection, the first discretisation;
//!   `mortar`: segment-to-segment contact between deformable bodies, the second, on the
//!   plane geometry of [`polygon`] (clipping and quadrature).
//!
//! Laws (what happens at one site):
//! - `cone`: Coulomb's cone and the bi-potential projection; [`anisotropic`]: the elliptic
//!   cone of orthotropic interfaces;
//! - [`interface`]: what a bond law gives the solvers (the [`Interface`] trait);
//!   [`rcc`]: the Raous-Cangémi-Cocou law, its parameters, maths and history;
//!   [`law`]: a pair's law (its cone and its bonds); [`history`]: a law's history at a site,
//!   with named fields; [`registry`]: the laws the program knows, for what is drawn from a
//!   history file alone.
//!
//! Solvers (the contact problem of a Newton iteration): [`solver`], one folder per solver
//! holding its point-wise maths and its coupling to the step's Newton loop.

pub mod anisotropic;
pub(crate) mod cone;
pub mod detect;
pub mod discretisation;
pub mod history;
pub mod interface;
pub mod law;
pub(crate) mod mortar;
pub(crate) mod node_to_surface;
pub mod polygon;
pub mod rcc;
pub mod registry;
pub mod solver;
#[cfg(test)]
mod test_support;

pub use cone::ContactState;
pub use detect::{ContactPair, Master, RigidMotion, RigidShape};
pub use discretisation::PairDiscretisation;
pub use history::{HistoryField, LawHistory, LawPointHistory, PointHistory, SiteHistory};
pub use interface::Interface;
pub use law::InterfaceLaw;
pub use rcc::RccHistory;
pub use rcc::{BondState, RccParams};
