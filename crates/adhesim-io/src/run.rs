//! The run driver: builds the stepper, advances it to the end time, hands every committed
//! step to the observers and reports progress. A run that cannot go on stops with a clear
//! message; everything already written stays valid.
//!
//! Long runs: [`RunControl`] asks for a checkpoint every N steps, for a stop after the
//! current step (a flag set by a signal handler, or a step count) and for resuming from the
//! checkpoint in the output directory. `run.json` is written when the run starts (status
//! `running`), rewritten at every checkpoint and at the end (`finished`, `interrupted` or
//! `failed` with its message), each time atomically; a run.json that says `running` after
//! the process has gone belongs to a run that was killed.
//!
//! The output folder is locked for the whole run and a folder holding a previous run is
//! only written over on request (see [`crate::outdir`]).

use crate::checkpoint::{fingerprint, Checkpoint, CheckpointError};
use crate::output::plot::PlotError;
use crate::output::{resume_observers, start_observers, Observer, SavedObserver, StepView};
use crate::scenario::Scenario;
use adhesim::time::{SetupError, StepReport, Stepper};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
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
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", tag = "status", content = "message")]
pub enum Outcome {
    /// Reached the end time.
    Finished,
    /// Stopped on an error; every committed output is intact.
    Failed(String),
    /// Stopped on request after a committed step, with a checkpoint to resume from.
    Interrupted,
    /// Still running: only in the run.json written while the run goes on (one left behind
    /// by a process that is gone means the run was killed).
    Running,
}

/// How a run is driven besides its problem: checkpoints, stopping, resuming.
#[derive(Clone, Debug, Default)]
pub struct RunControl {
    /// Write a checkpoint every this many committed steps (0: only when the run is stopped
    /// on request).
    pub checkpoint_every: usize,
    /// Continue from the checkpoint in the output directory instead of starting at t = 0.
    pub resume: bool,
    /// When set (e.g. by a signal handler) the run stops after the current step, writes a
    /// checkpoint and ends with [`Outcome::Interrupted`].
    pub stop: Option<Arc<AtomicBool>>,
    /// Stop the same way once this many steps have been committed (counted from t = 0).
    pub stop_after_steps: Option<usize>,
    /// Refuse to start a new run (not a resumed one) in a folder that holds a previous run
    /// (see [`crate::outdir`]); when false, that run's outputs are removed first.
    pub refuse_existing_run: bool,
}

impl RunControl {
    fn stop_requested(&self, steps: usize) -> bool {
        self.stop.as_ref().is_some_and(|s| s.load(Ordering::SeqCst))
            || self.stop_after_steps.is_some_and(|n| steps >= n)
    }
}

/// Where a checkpoint was taken.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CheckpointInfo {
    /// Committed steps.
    pub step: usize,
    /// Simulated time [s].
    pub t: f64,
}

/// What a run did.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
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
    /// Wall-clock time [s], summed over the sessions of a resumed run (the time spent
    /// after the last checkpoint of an interrupted session is not counted).
    pub wall_time: f64,
    /// The step the run was resumed from, when it was.
    pub resumed_from: Option<CheckpointInfo>,
    /// The last checkpoint written (or resumed from).
    pub checkpoint: Option<CheckpointInfo>,
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
    /// A checkpoint could not be written, read or used.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The output folder is in use by another run, or holds a run that would be lost.
    #[error(transparent)]
    OutDir(#[from] crate::outdir::OutDirError),
}

/// Runs `scenario` (read from the file `scenario_file`, if any), writing outputs to
/// `out_dir`; returns the summary (also written to `out_dir/run.json`). A step that cannot be
/// completed ends the run with [`Outcome::Failed`], not an error.
pub fn run(
    scenario: Scenario,
    scenario_file: Option<&Path>,
    out_dir: &Path,
    progress: &mut dyn Progress,
) -> Result<RunSummary, RunError> {
    run_with(
        scenario,
        scenario_file,
        out_dir,
        progress,
        &RunControl::default(),
    )
}

/// [`run`] with checkpoints, stop requests and resuming as `control` asks.
///
/// Resuming reads `out_dir/checkpoint.bin`, refuses a checkpoint written for another
/// problem, cuts history.csv back to the rows up to the checkpoint, keeps the frames up to it
/// and goes on from there: the outputs end up as those of an uninterrupted run.
pub fn run_with(
    scenario: Scenario,
    scenario_file: Option<&Path>,
    out_dir: &Path,
    progress: &mut dyn Progress,
    control: &RunControl,
) -> Result<RunSummary, RunError> {
    let Scenario { problem, output } = scenario;
    let start = Instant::now();
    let io_err = |source| RunError::Io {
        dir: out_dir.to_path_buf(),
        source,
    };
    // Held until the run returns; the operating system releases it if the process dies.
    let _lock = if control.resume && !out_dir.is_dir() {
        None // nothing to resume: reading the checkpoint below says so
    } else {
        Some(crate::outdir::lock(out_dir)?)
    };
    let fingerprint = fingerprint(&problem, &output);
    let resume_from = if control.resume {
        let c = Checkpoint::read(out_dir)?;
        c.check_matches(fingerprint, out_dir)?;
        Some(c)
    } else {
        std::fs::create_dir_all(out_dir).map_err(io_err)?;
        crate::outdir::prepare_fresh(out_dir, !control.refuse_existing_run)?;
        None
    };
    let problem = Arc::new(problem);
    let mut stepper = Stepper::new(problem.clone())?;
    let mut summary = RunSummary {
        name: problem.name.clone(),
        scenario: scenario_file.map(Path::to_path_buf),
        version: env!("CARGO_PKG_VERSION").to_string(),
        outcome: Outcome::Running,
        t_reached: 0.0,
        t_end: problem.time.t_end,
        steps: 0,
        cutbacks: 0,
        newton_iterations: 0,
        frames: 0,
        nodes: stepper.disc.num_nodes,
        cells: stepper.disc.num_cells(),
        wall_time: 0.0,
        resumed_from: None,
        checkpoint: None,
    };
    let mut wall_before = 0.0;
    let mut observers = match resume_from {
        Some(c) => {
            let at = CheckpointInfo {
                step: c.snapshot.step,
                t: c.snapshot.t,
            };
            stepper
                .restore(c.snapshot)
                .map_err(|reason| CheckpointError::Mismatch {
                    path: Checkpoint::path(out_dir),
                    reason,
                })?;
            summary.steps = at.step;
            summary.cutbacks = c.cutbacks;
            summary.newton_iterations = c.newton_iterations;
            summary.resumed_from = Some(at);
            summary.checkpoint = Some(at);
            wall_before = c.wall_time;
            // Half-written files of the interrupted process.
            for d in [out_dir.to_path_buf(), out_dir.join("vtu")] {
                if d.is_dir() {
                    crate::output::atomic::remove_stale_temps(&d).map_err(io_err)?;
                }
            }
            resume_observers(out_dir, &problem, &output, &c.observers, at.t).map_err(io_err)?
        }
        None => {
            let mut observers = start_observers(out_dir, &problem, &output).map_err(io_err)?;
            let initial = StepReport {
                internal: 0.0,
                kinetic: stepper.kinetic_energy(&stepper.state.v),
                ..Default::default()
            };
            let view = StepView {
                problem: &problem,
                disc: &stepper.disc,
                state: &stepper.state,
                report: &initial,
                contact: &stepper.contact,
                reactions: stepper.reactions(),
            };
            observe(&mut observers, &view).map_err(io_err)?;
            observers
        }
    };
    let update = |summary: &mut RunSummary, stepper: &Stepper, observers: &[Box<dyn Observer>]| {
        summary.t_reached = stepper.state.t;
        summary.frames = observers.iter().map(|o| o.frames_written()).sum();
        summary.wall_time = wall_before + start.elapsed().as_secs_f64();
    };
    update(&mut summary, &stepper, &observers);
    write_summary(out_dir, &summary).map_err(io_err)?;
    let save = |summary: &mut RunSummary,
                stepper: &Stepper,
                observers: &[Box<dyn Observer>]|
     -> Result<(), RunError> {
        update(summary, stepper, observers);
        let c = Checkpoint {
            version: summary.version.clone(),
            fingerprint,
            format: crate::checkpoint::FORMAT,
            snapshot: stepper.snapshot(),
            observers: observers
                .iter()
                .map(|o| SavedObserver {
                    key: o.key().to_string(),
                    state: o.resume_state(),
                })
                .collect(),
            cutbacks: summary.cutbacks,
            newton_iterations: summary.newton_iterations,
            wall_time: summary.wall_time,
        };
        c.write(out_dir)?;
        summary.checkpoint = Some(CheckpointInfo {
            step: stepper.state.step,
            t: stepper.state.t,
        });
        write_summary(out_dir, summary).map_err(|source| RunError::Io {
            dir: out_dir.to_path_buf(),
            source,
        })
    };
    let result = (|| -> Result<(), RunError> {
        while !stepper.finished() {
            if control.stop_requested(stepper.state.step) {
                summary.outcome = Outcome::Interrupted;
                if summary.checkpoint.map(|c| c.step) != Some(stepper.state.step) {
                    save(&mut summary, &stepper, &observers)?;
                }
                return Ok(());
            }
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
                        reactions: stepper.reactions(),
                    };
                    observe(&mut observers, &view).map_err(io_err)?;
                    progress.step(&report, problem.time.t_end);
                    let every = control.checkpoint_every;
                    if every > 0 && stepper.state.step % every == 0 && !stepper.finished() {
                        save(&mut summary, &stepper, &observers)?;
                    }
                }
                Err(e) => {
                    let message = adhesim::diagnosis::describe_step_failure(&problem, &e);
                    progress.message(&message);
                    summary.outcome = Outcome::Failed(message);
                    return Ok(());
                }
            }
        }
        summary.outcome = Outcome::Finished;
        // A finished run has nothing to resume: its last periodic checkpoint goes.
        match std::fs::remove_file(Checkpoint::path(out_dir)) {
            Ok(()) => summary.checkpoint = None,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io_err(e)),
        }
        Ok(())
    })();
    if result.is_ok() && output.figures && summary.outcome != Outcome::Interrupted {
        // Figures are a convenience drawn from the files just written: a failure to draw
        // them is reported, and does not change how the run ended.
        if let Err(e) = draw_figures(out_dir) {
            progress.message(&format!("figures not drawn: {e}"));
        }
    }
    update(&mut summary, &stepper, &observers);
    if let Err(e) = result {
        // Leave a run.json that says why the run stopped (best effort: the error may well be
        // that nothing can be written).
        summary.outcome = Outcome::Failed(e.to_string());
        let _ = write_summary(out_dir, &summary);
        return Err(e);
    }
    write_summary(out_dir, &summary).map_err(io_err)?;
    Ok(summary)
}

/// Hands `view` to every observer, in order.
fn observe(observers: &mut [Box<dyn Observer>], view: &StepView) -> std::io::Result<()> {
    observers.iter_mut().try_for_each(|o| o.observe(view))
}

/// Writes `DIR/run.json` atomically.
fn write_summary(out_dir: &Path, summary: &RunSummary) -> std::io::Result<()> {
    let json = serde_json::to_vec_pretty(summary).expect("summary serialises");
    crate::output::atomic::write_atomic(&out_dir.join("run.json"), &json)
}

/// Draws every figure of a finished (or stopped) run in `dir` into `dir/figures/`: the
/// history figures and the contact maps. Returns the files written.
pub fn draw_figures(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = crate::output::figures::draw_history_figures(dir)?;
    files.extend(crate::output::maps::draw_map_figures(dir)?);
    Ok(files)
}
