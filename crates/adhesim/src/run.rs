//! The run driver: builds the stepper, advances it to the end time, hands every committed
//! step to the observers and reports progress. A run that cannot go on stops with a clear
//! message; everything already written stays valid.

use crate::output::maps::MapObserver;
use crate::output::plot::PlotError;
use crate::output::{FrameWriter, HistoryObserver, Observer, StepView};
use crate::problem::Problem;
use crate::time::{SetupError, StepReport, Stepper};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Receives progress (the CLI draws a bar or prints lines).
pub trait Progress {
    /// After every committed step.
    fn step(&mut self, report: &StepReport, t_end: f64);
    /// A message for the user (warnings, the reason a run stopped).
    fn message(&mut self, text: &str);
}

/// A progress sink that ignores everything (for tests and library use).
pub struct Silent;
impl Progress for Silent {
    fn step(&mut self, _: &StepReport, _: f64) {}
    fn message(&mut self, _: &str) {}
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "status", content = "message")]
pub enum Outcome {
    /// Reached the end time.
    Finished,
    /// Stopped on an error; every committed output is intact.
    Failed(String),
}

/// What a run did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunSummary {
    /// Run name.
    pub name: String,
    /// Scenario file, when there is one.
    pub scenario: Option<PathBuf>,
    /// adhesim version.
    pub version: String,
    /// How it ended.
    pub outcome: Outcome,
    /// Simulated time reached [s].
    pub t_reached: f64,
    /// End time asked for [s].
    pub t_end: f64,
    /// Committed steps.
    pub steps: usize,
    /// Discarded attempts (Δt halved).
    pub cutbacks: usize,
    /// Total Newton iterations.
    pub newton_iterations: usize,
    /// VTU frames written.
    pub frames: usize,
    /// Nodes and cells of the discretisation.
    pub nodes: usize,
    /// Cells of the discretisation.
    pub cells: usize,
    /// Wall-clock time [s].
    pub wall_time: f64,
}

/// Errors that prevent a run from starting or from writing its outputs.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Could not set up the discretisation.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// An output file could not be written.
    #[error("cannot write output in {dir}: {source}")]
    Io {
        /// The output directory.
        dir: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// Runs `problem`, writing outputs to `out_dir`; returns the summary (also written to
/// `out_dir/run.json`). A step that cannot be completed ends the run with
/// [`Outcome::Failed`], not an error.
pub fn run(
    problem: Problem,
    scenario: Option<&Path>,
    out_dir: &Path,
    progress: &mut dyn Progress,
) -> Result<RunSummary, RunError> {
    let start = Instant::now();
    let io_err = |source| RunError::Io {
        dir: out_dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(out_dir).map_err(io_err)?;
    let problem = Arc::new(problem);
    let mut stepper = Stepper::new(problem.clone())?;
    let mut frames =
        FrameWriter::new(out_dir, &problem.name, problem.output.frame_interval).map_err(io_err)?;
    let mut history =
        HistoryObserver::new(&out_dir.join("history.csv"), &problem).map_err(io_err)?;
    let mut maps = MapObserver::new(out_dir, &problem.output.maps).map_err(io_err)?;
    let mut summary = RunSummary {
        name: problem.name.clone(),
        scenario: scenario.map(Path::to_path_buf),
        version: env!("CARGO_PKG_VERSION").to_string(),
        outcome: Outcome::Finished,
        t_reached: 0.0,
        t_end: problem.time.t_end,
        steps: 0,
        cutbacks: 0,
        newton_iterations: 0,
        frames: 0,
        nodes: stepper.disc.num_nodes,
        cells: stepper.disc.hexes.len() + stepper.disc.tets.len(),
        wall_time: 0.0,
    };
    let initial = StepReport {
        internal: 0.0,
        kinetic: stepper.kinetic_energy(&stepper.state.v),
        ..Default::default()
    };
    {
        let view = StepView {
            problem: &problem,
            disc: &stepper.disc,
            state: &stepper.state,
            report: &initial,
            contact: &stepper.contact,
        };
        frames.observe(&view).map_err(io_err)?;
        history.observe(&view).map_err(io_err)?;
        maps.observe(&view).map_err(io_err)?;
    }
    while !stepper.finished() {
        match stepper.step() {
            Ok(report) => {
                summary.steps += 1;
                summary.cutbacks += report.cutbacks;
                summary.newton_iterations += report.newton_iterations;
                let view = StepView {
                    problem: &problem,
                    disc: &stepper.disc,
                    state: &stepper.state,
                    report: &report,
                    contact: &stepper.contact,
                };
                frames.observe(&view).map_err(io_err)?;
                history.observe(&view).map_err(io_err)?;
                maps.observe(&view).map_err(io_err)?;
                progress.step(&report, problem.time.t_end);
            }
            Err(e) => {
                progress.message(&e.to_string());
                summary.outcome = Outcome::Failed(e.to_string());
                break;
            }
        }
    }
    if problem.output.figures {
        // Figures are a convenience drawn from the files just written: a failure to draw
        // them is reported, and does not change how the run ended.
        if let Err(e) = draw_figures(out_dir) {
            progress.message(&format!("figures not drawn: {e}"));
        }
    }
    summary.t_reached = stepper.state.t;
    summary.frames = frames.frames();
    summary.wall_time = start.elapsed().as_secs_f64();
    let json = serde_json::to_vec_pretty(&summary).expect("summary serialises");
    crate::output::atomic::write_atomic(&out_dir.join("run.json"), &json).map_err(io_err)?;
    Ok(summary)
}

/// Draws every figure of a finished (or stopped) run in `dir` into `dir/figures/`: the
/// history figures and the contact maps. Returns the files written.
pub fn draw_figures(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = crate::output::figures::draw_history_figures(dir)?;
    files.extend(crate::output::maps::draw_map_figures(dir)?);
    Ok(files)
}
