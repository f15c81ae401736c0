//! Frictional contact with recoverable adhesion (docs/model.md §4-§7).
//!
//! - [`law`]: the local law at one contact point (bi-potential projection, RCC β update, the
//!   point solver) — pure functions.
//! - [`detect`]: contact pairs, detection once per step, local frames, gaps and the operator H.
//! - [`solve`]: the reduced contact system inside Newton (Delassus operator W = H K̄⁻¹ Hᵀ,
//!   nonlinear Gauss-Seidel over contact points).

pub mod anisotropic;
pub mod detect;
pub mod law;
pub mod mixed;
pub mod natural_map;
pub mod newton;
pub mod reduced;
pub mod semismooth;
pub mod solve;

pub use detect::{ContactPair, Master, RigidMotion, RigidShape};
pub use law::{BondState, ContactState, InterfaceLaw, RccParams};
