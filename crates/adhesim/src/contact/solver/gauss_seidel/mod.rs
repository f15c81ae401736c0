//! Gauss-Seidel on the Delassus operator (docs/contact-solver.md): [`delassus`] builds
//! W = H K̄⁻¹ Hᵀ and sweeps the sites, each solved by [`point`]; [`coupling`] completes each
//! Newton correction with the sweep's forces and keeps W between steps.

pub(crate) mod coupling;
pub mod delassus;
pub mod point;

pub use coupling::{CachedDelassus, DelassusCache};
