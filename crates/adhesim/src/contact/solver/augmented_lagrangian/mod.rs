//! The augmented-Lagrangian contact solve (docs/contact-solver.md): [`point`] gives each site's
//! forces, stiffness and energy with its multiplier held; `coupling` puts them into the step's
//! Newton loop, line-searches it and updates the multipliers.

pub(crate) mod coupling;
pub mod point;
