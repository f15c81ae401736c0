//! Frictional contact with recoverable adhesion (docs/model.md §4-§7).
//!
//! - [`law`]: the local law at one contact point (bi-potential projection, RCC β update, the
//!   point solver) — pure functions.
//! - [`history`]: a law's history at a slave node, its named fields and values; [`rcc`]: the
//!   RCC law's history and its [`interface::Interface`] implementation.
//! - [`detect`]: contact pairs, detection once per step, local frames, gaps and the operator H.
//! - [`solve`]: the reduced contact system inside Newton (Delassus operator W = H K̄⁻¹ Hᵀ,
//!   nonlinear Gauss-Seidel over contact points).

pub mod anisotropic;
pub mod cone;
pub mod detect;
pub mod discretisation;
pub mod history;
pub mod interface;
pub mod law;
pub mod mixed;
pub mod natural_map;
pub mod newton;
pub mod node_to_surface;
pub mod point;
pub mod rcc;
pub mod reduced;
pub mod registry;
pub mod semismooth;
pub mod solve;
#[cfg(test)]
mod test_support;

pub use cone::ContactState;
pub use detect::{ContactPair, Master, RigidMotion, RigidShape};
pub use history::{HistoryField, LawHistory, LawPointHistory, NodeHistory, PointHistory};
pub use interface::Interface;
pub use law::InterfaceLaw;
pub use rcc::RccHistory;
pub use rcc::{BondState, RccParams};
