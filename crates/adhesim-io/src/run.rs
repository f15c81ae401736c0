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
use crate::output::settings::OutputSettings;
use crate::output::{observers, Begin, Observer, SavedObserver, StepView};
use crate::scenario::Scenario;
use adhesim::problem::Problem;
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
    let started = Instant::now();
    // Held until the run returns; the operating system releases it if the process dies.
    let _lock = lock_out_dir(out_dir, control)?;
    let fingerprint = fingerprint(&problem, &output);
    let checkpoint = open_out_dir(out_dir, control, fingerprint)?;
    let problem = Arc::new(problem);
    let stepper = Stepper::new(problem.clone())?;
    let summary = new_summary(&stepper, scenario_file);
    let mut run = ActiveRun {
        out_dir,
        problem,
        output,
        stepper,
        observers: Vec::new(),
        summary,
        fingerprint,
        started,
        wall_before: 0.0,
    };
    match checkpoint {
        Some(c) => run.resume_from(c)?,
        None => run.begin_new()?,
    }
    run.update_summary();
    run.write_summary()?;
    let result = run.advance(progress, control);
    run.finish(result, progress)
}

/// The lock on `out_dir` for the run, none when there is nothing to resume there (reading
/// the checkpoint then says so).
fn lock_out_dir(
    out_dir: &Path,
    control: &RunControl,
) -> Result<Option<crate::outdir::DirLock>, RunError> {
    if control.resume && !out_dir.is_dir() {
        Ok(None)
    } else {
        Ok(Some(crate::outdir::lock(out_dir)?))
    }
}

/// The checkpoint to resume from, checked against the problem's `fingerprint`; for a new run,
/// `out_dir` created and cleared of a previous run (when `control` allows it).
fn open_out_dir(
    out_dir: &Path,
    control: &RunControl,
    fingerprint: u64,
) -> Result<Option<Checkpoint>, RunError> {
    if control.resume {
        let c = Checkpoint::read(out_dir)?;
        c.check_matches(fingerprint, out_dir)?;
        Ok(Some(c))
    } else {
        std::fs::create_dir_all(out_dir).map_err(|source| io_error(out_dir, source))?;
        crate::outdir::prepare_fresh(out_dir, !control.refuse_existing_run)?;
        Ok(None)
    }
}

/// The summary of a run of `stepper`'s problem at its start.
fn new_summary(stepper: &Stepper, scenario_file: Option<&Path>) -> RunSummary {
    let problem = &stepper.problem;
    RunSummary {
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
    }
}

/// An output-folder error as a [`RunError`].
fn io_error(out_dir: &Path, source: std::io::Error) -> RunError {
    RunError::Io {
        dir: out_dir.to_path_buf(),
        source,
    }
}

/// A run under way: its stepper, its observers and the summary they keep up to date.
struct ActiveRun<'a> {
    out_dir: &'a Path,
    problem: Arc<Problem>,
    output: OutputSettings,
    stepper: Stepper,
    observers: Vec<Box<dyn Observer>>,
    summary: RunSummary,
    fingerprint: u64,
    /// When this process started the run.
    started: Instant,
    /// Wall-clock time of the sessions before a resume [s].
    wall_before: f64,
}

impl<'a> ActiveRun<'a> {
    /// A new run: the observers created and handed the state at t = 0.
    fn begin_new(&mut self) -> Result<(), RunError> {
        self.observers = observers(self.out_dir, &self.problem, &self.output, Begin::New)
            .map_err(|source| io_error(self.out_dir, source))?;
        let initial = StepReport {
            internal: 0.0,
            kinetic: self.stepper.kinetic_energy(&self.stepper.state.v),
            ..Default::default()
        };
        self.observe(&initial)
    }

    /// Goes on from the checkpoint `c`: the stepper restored, the summary's counts taken
    /// over, half-written files of the interrupted process removed, the observers resumed.
    fn resume_from(&mut self, c: Checkpoint) -> Result<(), RunError> {
        let out_dir = self.out_dir;
        let at = CheckpointInfo {
            step: c.snapshot.step,
            t: c.snapshot.t,
        };
        self.stepper
            .restore(c.snapshot)
            .map_err(|reason| CheckpointError::Mismatch {
                path: Checkpoint::path(out_dir),
                reason,
            })?;
        let summary = &mut self.summary;
        summary.steps = at.step;
        summary.cutbacks = c.cutbacks;
        summary.newton_iterations = c.newton_iterations;
        summary.resumed_from = Some(at);
        summary.checkpoint = Some(at);
        self.wall_before = c.wall_time;
        for d in [out_dir.to_path_buf(), out_dir.join("vtu")] {
            if d.is_dir() {
                crate::output::atomic::remove_stale_temps(&d)
                    .map_err(|source| io_error(out_dir, source))?;
            }
        }
        let begin = Begin::Resume {
            saved: &c.observers,
            t: at.t,
        };
        self.observers = observers(out_dir, &self.problem, &self.output, begin)
            .map_err(|source| io_error(out_dir, source))?;
        Ok(())
    }

    /// Steps until the end time, a stop request (checkpoint written) or a step that fails
    /// (the outcome says why); an error only when an output or checkpoint cannot be written.
    fn advance(
        &mut self,
        progress: &mut dyn Progress,
        control: &RunControl,
    ) -> Result<(), RunError> {
        while !self.stepper.finished() {
            if control.stop_requested(self.stepper.state.step) {
                self.summary.outcome = Outcome::Interrupted;
                if self.summary.checkpoint.map(|c| c.step) != Some(self.stepper.state.step) {
                    self.save_checkpoint()?;
                }
                return Ok(());
            }
            match self.stepper.step() {
                Ok(report) => self.commit(&report, progress, control.checkpoint_every)?,
                Err(e) => {
                    let message = adhesim::diagnosis::describe_step_failure(&self.problem, &e);
                    progress.message(&message);
                    self.summary.outcome = Outcome::Failed(message);
                    return Ok(());
                }
            }
        }
        self.summary.outcome = Outcome::Finished;
        // A finished run has nothing to resume: its last periodic checkpoint goes.
        match std::fs::remove_file(Checkpoint::path(self.out_dir)) {
            Ok(()) => self.summary.checkpoint = None,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io_error(self.out_dir, e)),
        }
        Ok(())
    }

    /// A committed step: counted, observed, reported, and checkpointed every `every` steps
    /// (0: never) unless it is the last.
    fn commit(
        &mut self,
        report: &StepReport,
        progress: &mut dyn Progress,
        every: usize,
    ) -> Result<(), RunError> {
        self.summary.steps += 1;
        self.summary.cutbacks += report.cutbacks;
        self.summary.newton_iterations += report.newton_iterations;
        self.observe(report)?;
        progress.step(report, self.problem.time.t_end);
        if every > 0 && self.stepper.state.step % every == 0 && !self.stepper.finished() {
            self.save_checkpoint()?;
        }
        Ok(())
    }

    /// Hands the stepper's current state with `report` to every observer.
    fn observe(&mut self, report: &StepReport) -> Result<(), RunError> {
        let view = StepView {
            problem: &self.problem,
            disc: &self.stepper.disc,
            state: &self.stepper.state,
            report,
            contact: &self.stepper.contact,
            reactions: self.stepper.reactions(),
        };
        observe(&mut self.observers, &view).map_err(|source| io_error(self.out_dir, source))
    }

    /// The summary's time reached, frame count and wall time brought up to date.
    fn update_summary(&mut self) {
        self.summary.t_reached = self.stepper.state.t;
        self.summary.frames = self.observers.iter().map(|o| o.frames_written()).sum();
        self.summary.wall_time = self.wall_before + self.started.elapsed().as_secs_f64();
    }

    fn write_summary(&self) -> Result<(), RunError> {
        write_summary(self.out_dir, &self.summary).map_err(|source| io_error(self.out_dir, source))
    }

    /// Writes a checkpoint of the stepper and the observers, then run.json naming it.
    fn save_checkpoint(&mut self) -> Result<(), RunError> {
        self.update_summary();
        let c = Checkpoint {
            version: self.summary.version.clone(),
            fingerprint: self.fingerprint,
            format: crate::checkpoint::FORMAT,
            snapshot: self.stepper.snapshot(),
            observers: self
                .observers
                .iter()
                .map(|o| SavedObserver {
                    key: o.key().to_string(),
                    state: o.resume_state(),
                })
                .collect(),
            cutbacks: self.summary.cutbacks,
            newton_iterations: self.summary.newton_iterations,
            wall_time: self.summary.wall_time,
        };
        c.write(self.out_dir)?;
        self.summary.checkpoint = Some(CheckpointInfo {
            step: self.stepper.state.step,
            t: self.stepper.state.t,
        });
        self.write_summary()
    }

    /// Ends the run after [`ActiveRun::advance`] returned `result`: the figures drawn (unless
    /// it was interrupted or could not write), run.json written with the outcome, and an
    /// output error handed on after run.json says why the run stopped.
    fn finish(
        mut self,
        result: Result<(), RunError>,
        progress: &mut dyn Progress,
    ) -> Result<RunSummary, RunError> {
        if result.is_ok() && self.output.figures && self.summary.outcome != Outcome::Interrupted {
            // Figures are a convenience drawn from the files just written: a failure to draw
            // them is reported, and does not change how the run ended.
            if let Err(e) = draw_figures(self.out_dir) {
                progress.message(&format!("figures not drawn: {e}"));
            }
        }
        self.update_summary();
        if let Err(e) = result {
            // Leave a run.json that says why the run stopped (best effort: the error may well
            // be that nothing can be written).
            self.summary.outcome = Outcome::Failed(e.to_string());
            let _ = self.write_summary();
            return Err(e);
        }
        self.write_summary()?;
        Ok(self.summary)
    }
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
