//! The contact problem of a Newton iteration, one folder per solver, each with the maths of
//! its contact sites and its coupling to the step's Newton loop (the
//! `time::coupling::ContactCoupling` trait, which the Newton loop calls; docs/contact-solver.md
//! describes the three):
//! - [`gauss_seidel`]: the Delassus operator W = H K̄⁻¹ Hᵀ and nonlinear Gauss-Seidel over
//!   sites, each site solved by its point solver;
//! - [`augmented_lagrangian`]: the augmented-Lagrangian contact terms inside the step's own
//!   Newton loop (`time.contact_solver = "newton"`);
//! - [`semismooth`]: the W-free semismooth solve on the mixed system (the default above 200
//!   candidate sites).
//!
//! Shared by them: [`site_stiffness`], the stiffness K̄ shows at a site (which sets ρ_α) and
//! what the solves that put the contact conditions into K̄ add to it; [`reduced`], the reduced
//! dry problem x = q + W r without a mesh, as the fclib benchmarks pose it (Gauss-Seidel and
//! semismooth Newton solve it), and [`natural_map`], its error measure.

pub mod augmented_lagrangian;
pub mod gauss_seidel;
pub mod natural_map;
pub mod reduced;
pub mod semismooth;
pub mod site_stiffness;
