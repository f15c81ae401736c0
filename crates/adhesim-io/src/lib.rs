//! Input and output of adhesim, apart from the physics of the `adhesim` crate: a scenario
//! file is parsed and validated into a [`scenario::Scenario`] (the [`adhesim::problem::Problem`]
//! the stepper solves and the [`output::settings::OutputSettings`] the writers read),
//! [`run::run`] advances it with an [`adhesim::time::Stepper`] and hands every committed step
//! to a list of [`output::Observer`]s (VTK frames, history.csv, contact maps), each of which
//! saves its own resume state in the run's [`checkpoint`]; [`sweep`] and [`slurm`] run many
//! scenarios. Data flows one way: nothing in `adhesim` calls into this crate.

pub mod checkpoint;
mod codec;
pub mod outdir;
pub mod output;
pub mod run;
pub mod scenario;
pub mod slurm;
pub mod sweep;
