//! Gauss-Seidel on the Delassus operator (docs/contact-solver.md): [`delassus`] builds
//! W = H K̄⁻¹ Hᵀ, [`sweep`] sweeps the sites on it, each solved by [`point`], and `coupling`
//! completes each Newton correction of the step with the sweep's forces and keeps W between
//! steps; [`reduced`] is the same sweep on the reduced problem without a mesh (W in blocks).

pub(crate) mod coupling;
pub mod delassus;
pub mod point;
pub mod reduced;
pub mod sweep;

pub use coupling::{CachedDelassus, DelassusCache};
