//! `adhesim`: command-line front end. Parses arguments, shows progress, maps outcomes to
//! exit codes (0 success, 1 the run stopped early, 2 invalid input or unwritable output,
//! 130 interrupted by Ctrl-C or SIGTERM with a checkpoint to resume from).

use adhesim::time::StepReport;
use adhesim_io::run::{Outcome, Progress, RunSummary};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Finite-element dynamics of soft bodies in frictional contact with recoverable adhesion.
///
/// A scenario file (TOML, SI units) describes bodies, materials, prescribed motions and time
/// stepping; see docs/scenario.md. Outputs: ParaView frames (<name>.pvd + vtu/), history.csv
/// (one row per step) and run.json (what ran and how it ended).
#[derive(Parser)]
#[command(name = "adhesim", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
#[allow(clippy::large_enum_variant)] // parsed once; boxing would only obscure the fields
enum Command {
    /// Run a scenario and write its outputs.
    ///
    /// Long runs: a checkpoint (DIR/checkpoint.bin) is written every --checkpoint-every
    /// steps; Ctrl-C or SIGTERM stops the run after the current step and writes one (a second
    /// Ctrl-C stops at once); `adhesim run FILE --resume DIR` continues from it and gives the
    /// outputs of an uninterrupted run. DIR/run.json says `running`, `finished`,
    /// `interrupted` or `failed`.
    ///
    /// A run locks its output directory (DIR/run.lock): a second run into it is refused
    /// with the first one's process id. A directory that holds a previous run is refused
    /// unless --resume or --overwrite is given.
    ///
    /// Exit codes: 0 the run reached its end time, 1 it stopped early (Δt fell below its
    /// minimum; everything computed until then is kept), 2 the scenario is invalid, the
    /// outputs cannot be written or the checkpoint cannot be resumed, 130 interrupted by
    /// Ctrl-C or SIGTERM (resume with --resume).
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Output directory [default: out/<scenario name>, or DIR with --resume].
        #[arg(long, conflicts_with = "resume")]
        out: Option<PathBuf>,
        /// Write a checkpoint every N committed steps (0: only on Ctrl-C/SIGTERM).
        #[arg(long, value_name = "N", default_value_t = 100)]
        checkpoint_every: usize,
        /// Continue the interrupted run whose outputs are in DIR from its last checkpoint
        /// (the scenario must be unchanged).
        #[arg(long, value_name = "DIR")]
        resume: Option<PathBuf>,
        /// Replace the run whose outputs are in the output directory (finished, interrupted
        /// or killed); without it such a directory is refused, so that no run is lost.
        #[arg(long, conflicts_with = "resume")]
        overwrite: bool,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
        /// Apply the scenario's [variants.NAME] table first (e.g. `coarse`).
        #[arg(long, value_name = "NAME")]
        variant: Option<String>,
        /// Override one key: a dotted path into the scenario (`time.dt=1e-4`,
        /// `contact.indentor.adhesion.cn=5e9`, `body.wheel.material.g=1e7`) or a parameter name
        /// (`v_descent=0.2`). Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
    /// Run a parameter study: the cartesian product of the values given with --set, one case
    /// per worker at a time, each in its own sub-folder of the output directory; then one
    /// comparison figure per tracked quantity (one curve per case) in DIR/figures/ and a
    /// summary table DIR/sweep.csv. DIR/sweep.json holds the plan.
    ///
    /// Example: adhesim sweep scenarios/paper/plate-on-cylinder.toml
    ///   --set v_descent=1.0,0.8,0.6,0.4,0.2 --set contact.plate.friction=0,0.2,0.4,0.6,0.8
    ///
    /// Ctrl-C stops every running case after its step with a checkpoint; the same command
    /// with --resume keeps the finished cases, resumes the interrupted ones and runs the rest.
    ///
    /// On a Slurm cluster: --slurm writes the plan and a job-array script
    /// (DIR/slurm/sweep.sbatch, one array task per case) instead of running, --submit also
    /// submits it; `adhesim sweep submit DIR` (re)submits the unfinished cases and
    /// `adhesim sweep collect DIR` assembles sweep.csv and the figures from whatever cases
    /// have finished.
    ///
    /// Exit codes: 0 every case finished, 1 some case stopped early, 2 invalid input or an
    /// output directory that holds another sweep, 130 interrupted by Ctrl-C or SIGTERM.
    #[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
    Sweep {
        #[command(subcommand)]
        action: Option<SweepAction>,
        /// Scenario file (TOML).
        #[arg(required = true)]
        scenario: Option<PathBuf>,
        /// A swept key and its values, comma-separated: KEY=V1,V2,... Repeatable; the cases
        /// are the cartesian product.
        #[arg(long = "set", value_name = "KEY=V1,V2,...", required = true)]
        axes: Vec<String>,
        /// Fixed overrides common to every case (KEY=VALUE). Repeatable.
        #[arg(long = "fix", value_name = "KEY=VALUE")]
        fixed: Vec<String>,
        /// Apply the scenario's [variants.NAME] table to every case.
        #[arg(long, value_name = "NAME")]
        variant: Option<String>,
        /// Cases run at the same time [default: the number of cores].
        #[arg(long, short)]
        jobs: Option<usize>,
        /// Output directory [default: out/<scenario name>-sweep].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Each case writes a checkpoint every N committed steps (0: only when stopped).
        #[arg(long, value_name = "N", default_value_t = 100)]
        checkpoint_every: usize,
        /// Continue the sweep in the output directory (same scenario, --variant, --fix and
        /// --set): finished cases are kept, interrupted ones resume from their checkpoints.
        #[arg(long, conflicts_with = "overwrite")]
        resume: bool,
        /// Replace a sweep already in the output directory.
        #[arg(long)]
        overwrite: bool,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
        #[command(flatten)]
        slurm: SlurmArgs,
    },
    /// Draw figures (PNG) from a finished run's history.csv into DIR/figures/: one per
    /// tracked quantity (displacements, β, contact and adhesive forces) with one curve per
    /// tracked node, and one per contact-pair total.
    Plot {
        /// Output directory of a run (holds history.csv).
        dir: PathBuf,
    },
    /// Validate a scenario without running it: parse, check every value, build the meshes
    /// and check them for inverted elements. Exit code 0 when valid, 2 otherwise.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Apply the scenario's [variants.NAME] table first.
        #[arg(long, value_name = "NAME")]
        variant: Option<String>,
        /// Override one key (KEY=VALUE). Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
}

/// What `adhesim sweep` does besides running a study.
#[derive(Subcommand)]
enum SweepAction {
    /// Assemble DIR/sweep.csv and the comparison figures from whatever cases of the sweep in
    /// DIR have run, and list the cases that are missing, still running (or killed),
    /// interrupted or failed. Exit code 0 when every case finished, 1 otherwise.
    Collect {
        /// Sweep directory (holds sweep.json).
        dir: PathBuf,
        /// Print nothing but errors and the cases that have not finished.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Submit the sweep's job-array script (written by --slurm) with sbatch: by default
    /// every case that has not finished (a stopped case resumes from its checkpoint).
    Submit {
        /// Sweep directory (holds sweep.json and slurm/sweep.sbatch).
        dir: PathBuf,
        /// Only these case numbers (comma-separated, e.g. 2,5).
        #[arg(long, value_name = "N,N,...", value_delimiter = ',')]
        cases: Vec<usize>,
    },
}

/// The job-array settings of `adhesim sweep --slurm`.
#[derive(clap::Args)]
struct SlurmArgs {
    /// Write the plan and a Slurm job-array script (DIR/slurm/sweep.sbatch) instead of
    /// running the cases here.
    #[arg(long)]
    slurm: bool,
    /// Submit the script with sbatch (with --slurm).
    #[arg(long, requires = "slurm")]
    submit: bool,
    /// #SBATCH --partition.
    #[arg(long, requires = "slurm")]
    partition: Option<String>,
    /// #SBATCH --time: the limit of each case (e.g. 12:00:00).
    #[arg(long, requires = "slurm")]
    time: Option<String>,
    /// #SBATCH --mem: the memory of each case (e.g. 8G).
    #[arg(long, requires = "slurm")]
    mem: Option<String>,
    /// #SBATCH --cpus-per-task: the cores (threads) of each case.
    #[arg(long, default_value_t = 1)]
    cpus_per_task: usize,
    /// #SBATCH --account.
    #[arg(long, requires = "slurm")]
    account: Option<String>,
    /// Any other sbatch option, one #SBATCH line each (e.g. --sbatch=--qos=long).
    /// Repeatable.
    #[arg(
        long = "sbatch",
        value_name = "OPTION",
        requires = "slurm",
        allow_hyphen_values = true
    )]
    sbatch: Vec<String>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run {
            scenario,
            out,
            checkpoint_every,
            resume,
            overwrite,
            quiet,
            variant,
            overrides,
        } => match load_options(variant, &overrides) {
            Ok(opts) => run(
                &scenario,
                &opts,
                out,
                checkpoint_every,
                resume,
                overwrite,
                quiet,
            ),
            Err(e) => fail_input(e),
        },
        Command::Check {
            scenario,
            variant,
            overrides,
        } => match load_options(variant, &overrides) {
            Ok(opts) => check(&scenario, &opts),
            Err(e) => fail_input(e),
        },
        Command::Sweep {
            action: Some(SweepAction::Collect { dir, quiet }),
            ..
        } => collect(&dir, quiet),
        Command::Sweep {
            action: Some(SweepAction::Submit { dir, cases }),
            ..
        } => submit(&dir, &cases),
        Command::Sweep {
            action: None,
            scenario,
            axes,
            fixed,
            variant,
            jobs,
            out,
            checkpoint_every,
            resume,
            overwrite,
            quiet,
            slurm,
        } => {
            let Some(scenario) = scenario else {
                return fail_input("adhesim sweep needs a scenario file");
            };
            let request = SweepRequest {
                axes,
                fixed,
                variant,
                jobs,
                out,
                checkpoint_every,
                resume,
                overwrite,
                quiet,
                slurm,
            };
            sweep(&scenario, request)
        }
        Command::Plot { dir } => match adhesim_io::run::draw_figures(&dir) {
            Ok(files) => {
                for f in files {
                    println!("{}", f.display());
                }
                ExitCode::SUCCESS
            }
            Err(e) => fail_input(e),
        },
    }
}

fn fail_input(msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(2)
}

/// Load options from the command line's --variant and --set.
fn load_options(
    variant: Option<String>,
    overrides: &[String],
) -> Result<adhesim_io::scenario::LoadOptions, String> {
    let overrides = overrides
        .iter()
        .map(|o| adhesim_io::scenario::Override::parse(o).map_err(|e| format!("--set: {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(adhesim_io::scenario::LoadOptions { variant, overrides })
}

fn check(path: &Path, opts: &adhesim_io::scenario::LoadOptions) -> ExitCode {
    let scenario = match adhesim_io::scenario::load_with(path, opts) {
        Ok(p) => p,
        Err(e) => return fail_input(e),
    };
    let problem = &scenario.problem;
    if let Err(err) = adhesim::time::check_elements(problem) {
        return fail_input(format!("{}: {err}", path.display()));
    }
    for w in adhesim::warnings::physical_warnings(problem) {
        eprintln!("warning: {w}");
    }
    let nodes: usize = problem.bodies.iter().map(|b| b.mesh.num_nodes()).sum();
    let cells: usize = problem.bodies.iter().map(|b| b.mesh.num_cells()).sum();
    println!(
        "{}: valid — {} bod{}, {nodes} nodes, {cells} cells, t_end = {} s, dt = {} s",
        path.display(),
        problem.bodies.len(),
        if problem.bodies.len() == 1 {
            "y"
        } else {
            "ies"
        },
        problem.time.t_end,
        problem.time.dt
    );
    ExitCode::SUCCESS
}

fn run(
    path: &Path,
    opts: &adhesim_io::scenario::LoadOptions,
    out: Option<PathBuf>,
    checkpoint_every: usize,
    resume: Option<PathBuf>,
    overwrite: bool,
    quiet: bool,
) -> ExitCode {
    let scenario = match adhesim_io::scenario::load_with(path, opts) {
        Ok(p) => p,
        Err(e) => return fail_input(e),
    };
    let out = resume
        .clone()
        .or(out)
        .unwrap_or_else(|| default_out_dir(&scenario.problem.name, opts.variant.as_deref()));
    let control = adhesim_io::run::RunControl {
        checkpoint_every,
        resume: resume.is_some(),
        stop: Some(stop_on_signals()),
        stop_after_steps: None,
        refuse_existing_run: !overwrite,
    };
    let mut progress = progress_sink(quiet);
    if !quiet {
        let verb = if resume.is_some() {
            "resuming"
        } else {
            "running"
        };
        eprintln!("{verb} {} → {}", path.display(), out.display());
        for w in adhesim::warnings::physical_warnings(&scenario.problem) {
            progress.message(&format!("warning: {w}"));
        }
    }
    let summary =
        match adhesim_io::run::run_with(scenario, Some(path), &out, progress.as_mut(), &control) {
            Ok(s) => s,
            Err(e) => return fail_input(format!("{}: {e}", path.display())),
        };
    drop(progress);
    report_run(&summary, path, &out, quiet)
}

/// `out/<name>` or, for a variant, `out/<name>-<variant>`.
fn default_out_dir(name: &str, variant: Option<&str>) -> PathBuf {
    let name = match variant {
        Some(v) => format!("{name}-{v}"),
        None => name.to_string(),
    };
    PathBuf::from("out").join(name)
}

/// Nothing when `quiet`, a bar on a terminal, plain lines in a log or a pipe.
fn progress_sink(quiet: bool) -> Box<dyn Progress> {
    if quiet {
        Box::new(adhesim_io::run::Silent)
    } else if std::io::stderr().is_terminal() {
        Box::new(Bar::new())
    } else {
        Box::new(Lines::new())
    }
}

/// Says how the run of `path` into `out` ended; its exit code (0 finished, 1 stopped early,
/// 130 interrupted).
fn report_run(summary: &RunSummary, path: &Path, out: &Path, quiet: bool) -> ExitCode {
    match &summary.outcome {
        Outcome::Finished => {
            if !quiet {
                eprintln!(
                    "done: {} steps ({} cut-backs, {} Newton iterations) in {:.1} s; {} frames in {}",
                    summary.steps,
                    summary.cutbacks,
                    summary.newton_iterations,
                    summary.wall_time,
                    summary.frames,
                    out.display()
                );
            }
            ExitCode::SUCCESS
        }
        Outcome::Failed(msg) => {
            eprintln!(
                "error: the run stopped at t = {:.6e} s of {} s: {msg}\nEvery output written until then is intact in {}.",
                summary.t_reached,
                summary.t_end,
                out.display()
            );
            ExitCode::from(1)
        }
        Outcome::Interrupted | Outcome::Running => {
            eprintln!(
                "interrupted at t = {:.6e} s of {} s (step {}); checkpoint written.\nContinue with: adhesim run {} --resume {}",
                summary.t_reached,
                summary.t_end,
                summary.steps,
                path.display(),
                out.display()
            );
            ExitCode::from(130)
        }
    }
}

/// A flag set by the first Ctrl-C (SIGINT) or SIGTERM: the run stops after the current step
/// and writes a checkpoint. A second signal ends the process at once (exit code 130); every
/// output file is still complete, since each is written atomically or row by row.
fn stop_on_signals() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let installed = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping after the current step (press Ctrl-C again to stop at once)");
    });
    if let Err(e) = installed {
        eprintln!("warning: cannot catch Ctrl-C ({e}); an interrupted run resumes from its last periodic checkpoint");
    }
    stop
}

/// A progress bar for terminals.
struct Bar {
    bar: ProgressBar,
}

impl Bar {
    fn new() -> Self {
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:30} {percent:>3}% {msg} [{elapsed_precise}, ETA {eta}]",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Bar { bar }
    }
}

impl Progress for Bar {
    fn step(&mut self, r: &StepReport, t_end: f64) {
        self.bar.set_position((1000.0 * r.t / t_end).round() as u64);
        self.bar.set_message(format!(
            "step {} t = {:.4e} s Δt = {:.2e} s Newton {}{}",
            r.step,
            r.t,
            r.dt,
            r.newton_iterations,
            if r.cutbacks > 0 {
                format!(" ({} cut-backs)", r.cutbacks)
            } else {
                String::new()
            }
        ));
    }
    fn message(&mut self, text: &str) {
        self.bar.println(text);
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// Plain progress lines (at most one every two seconds) for logs and pipes.
struct Lines {
    start: Instant,
    last: Instant,
    /// The reason of the latest cut-back since the last line printed.
    cutback: Option<String>,
}

impl Lines {
    fn new() -> Self {
        let now = Instant::now();
        Lines {
            start: now,
            last: now - Duration::from_secs(10),
            cutback: None,
        }
    }
}

impl Progress for Lines {
    fn step(&mut self, r: &StepReport, t_end: f64) {
        let done = r.t >= t_end * (1.0 - 1e-12);
        if let Some(reason) = &r.last_cutback {
            self.cutback = Some(format!("t = {:.4e} s: {reason}", r.t - r.dt));
        }
        if self.last.elapsed() < Duration::from_secs(2) && !done {
            return;
        }
        if let Some(reason) = self.cutback.take() {
            eprintln!("  Δt cut back in the step from {reason}");
        }
        self.last = Instant::now();
        let frac = (r.t / t_end).clamp(0.0, 1.0);
        let elapsed = self.start.elapsed().as_secs_f64();
        let eta = if frac > 0.0 {
            elapsed * (1.0 - frac) / frac
        } else {
            0.0
        };
        eprintln!(
            "step {:>6}  t = {:.4e} s ({:5.1}%)  Δt = {:.2e} s  Newton {:>2}  cut-backs {}  ETA {:.0} s",
            r.step,
            r.t,
            100.0 * frac,
            r.dt,
            r.newton_iterations,
            r.cutbacks,
            eta
        );
    }
    fn message(&mut self, text: &str) {
        eprintln!("{text}");
    }
}

/// Sweep progress as plain lines.
struct SweepLines {
    quiet: bool,
    start: Instant,
}

impl adhesim_io::sweep::SweepProgress for SweepLines {
    fn started(&self, case: &adhesim_io::sweep::Case, total: usize) {
        if !self.quiet {
            eprintln!(
                "[{:>6.1} s] case {}/{total} started: {}",
                self.start.elapsed().as_secs_f64(),
                case.index + 1,
                case.label
            );
        }
    }
    fn finished(
        &self,
        case: &adhesim_io::sweep::Case,
        total: usize,
        result: &Result<adhesim_io::run::RunSummary, String>,
    ) {
        let what = match result {
            Ok(s) => match &s.outcome {
                Outcome::Finished => format!(
                    "finished: {} steps, {} cut-backs, {:.1} s",
                    s.steps, s.cutbacks, s.wall_time
                ),
                Outcome::Failed(m) => format!("stopped at t = {:.4e} s: {m}", s.t_reached),
                Outcome::Interrupted | Outcome::Running => {
                    format!("interrupted at t = {:.4e} s", s.t_reached)
                }
            },
            Err(m) => format!("could not run: {m}"),
        };
        if !self.quiet || !matches!(result, Ok(s) if s.outcome == Outcome::Finished) {
            eprintln!(
                "[{:>6.1} s] case {}/{total} ({}) {what}",
                self.start.elapsed().as_secs_f64(),
                case.index + 1,
                case.label
            );
        }
    }
}

/// `adhesim sweep FILE …` as given on the command line.
struct SweepRequest {
    axes: Vec<String>,
    fixed: Vec<String>,
    variant: Option<String>,
    jobs: Option<usize>,
    out: Option<PathBuf>,
    checkpoint_every: usize,
    resume: bool,
    overwrite: bool,
    quiet: bool,
    slurm: SlurmArgs,
}

fn sweep(path: &Path, r: SweepRequest) -> ExitCode {
    let (plan, out) = match sweep_plan(path, &r) {
        Ok(planned) => planned,
        Err(code) => return code,
    };
    let n_cases = plan.cases.len();
    if r.slurm.slurm {
        return slurm_sweep(
            &plan,
            &out,
            r.checkpoint_every,
            r.resume,
            r.overwrite,
            r.slurm,
        );
    }
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let jobs = r.jobs.unwrap_or(cores).max(1);
    let options = adhesim_io::sweep::SweepOptions {
        jobs,
        threads_per_case: (cores / jobs).max(1),
        checkpoint_every: r.checkpoint_every,
        resume: r.resume,
        overwrite: r.overwrite,
        stop: Some(stop_on_signals()),
    };
    if !r.quiet {
        eprintln!(
            "sweep of {} → {}: {n_cases} cases, {} at a time{}",
            path.display(),
            out.display(),
            jobs.min(n_cases.max(1)),
            if r.resume { " (resumed)" } else { "" }
        );
    }
    let progress = SweepLines {
        quiet: r.quiet,
        start: Instant::now(),
    };
    match adhesim_io::sweep::run_sweep(&plan, &options, &out, &progress) {
        Ok(summary) => report_sweep(&summary, &out, r.quiet),
        Err(e) => fail_input(format!("{}: {e}", path.display())),
    }
}

/// The cases of the sweep `r` of `path` and its output folder (`--out`, or
/// `out/<name>-sweep`); the exit code of an invalid request.
fn sweep_plan(
    path: &Path,
    r: &SweepRequest,
) -> Result<(adhesim_io::sweep::SweepPlan, PathBuf), ExitCode> {
    if let Err(e) = load_options(None, &r.fixed) {
        return Err(fail_input(e.replace("--set", "--fix")));
    }
    let axes = r
        .axes
        .iter()
        .map(|a| adhesim_io::sweep::Axis::parse(a))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| fail_input(format!("--set: {e}")))?;
    let plan = adhesim_io::sweep::SweepPlan::new(path, r.variant.clone(), &r.fixed, &axes)
        .map_err(|e| fail_input(format!("{}: {e}", path.display())))?;
    // The name of the default folder; every case is validated in full later.
    let base = load_options(r.variant.clone(), &r.fixed)
        .map_err(|e| fail_input(e.replace("--set", "--fix")))?;
    let scenario = adhesim_io::scenario::load_with(path, &base).map_err(fail_input)?;
    let out = r
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-sweep", scenario.problem.name)));
    Ok((plan, out))
}

/// Says how the sweep into `out` ended; its exit code (0 every case finished, 1 some stopped
/// early, 130 interrupted).
fn report_sweep(summary: &adhesim_io::sweep::SweepSummary, out: &Path, quiet: bool) -> ExitCode {
    let failed = summary
        .results
        .iter()
        .filter(|r| !matches!(r, Ok(s) if s.outcome == Outcome::Finished))
        .count();
    if summary.interrupted {
        eprintln!(
            "sweep interrupted; every running case wrote a checkpoint.\nContinue with the same command and --resume (--out {})",
            out.display()
        );
        return ExitCode::from(130);
    }
    if !quiet {
        let kept = if summary.kept > 0 {
            format!(", {} kept from before", summary.kept)
        } else {
            String::new()
        };
        eprintln!(
            "done: {} cases ({failed} stopped early{kept}) in {:.1} s; summary {}, {} comparison figures in {}",
            summary.cases.len(),
            summary.wall_time,
            out.join("sweep.csv").display(),
            summary.figures.len(),
            out.join("figures").display()
        );
    }
    if failed > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// `adhesim sweep … --slurm`: validates every case, writes the plan and the job-array
/// script, and submits it with --submit.
fn slurm_sweep(
    plan: &adhesim_io::sweep::SweepPlan,
    out: &Path,
    checkpoint_every: usize,
    resume: bool,
    overwrite: bool,
    args: SlurmArgs,
) -> ExitCode {
    let file = plan.scenario.display().to_string();
    if let Err(e) = plan.load_cases() {
        return fail_input(format!("{file}: {e}"));
    }
    if let Err(e) = adhesim_io::sweep::check_folder(plan, out, resume, overwrite) {
        return fail_input(e);
    }
    let (dir, exe) = match (std::path::absolute(out), std::env::current_exe()) {
        (Ok(d), Ok(e)) => (d, e),
        (Err(e), _) | (_, Err(e)) => return fail_input(format!("{}: {e}", out.display())),
    };
    let options = adhesim_io::slurm::SlurmOptions {
        partition: args.partition,
        time: args.time,
        mem: args.mem,
        cpus_per_task: args.cpus_per_task,
        account: args.account,
        extra: args.sbatch,
        checkpoint_every,
    };
    if let Err(e) = plan.write(&dir) {
        return fail_input(e);
    }
    let script = match adhesim_io::slurm::write_script(plan, &dir, &exe, &options) {
        Ok(s) => s,
        Err(e) => return fail_input(e),
    };
    eprintln!(
        "{} cases: plan {}, job-array script {}",
        plan.cases.len(),
        dir.join(adhesim_io::sweep::PLAN_FILE).display(),
        script.display()
    );
    if !args.submit {
        eprintln!(
            "submit with: adhesim sweep submit {}\nthen: adhesim sweep collect {}",
            dir.display(),
            dir.display()
        );
        return ExitCode::SUCCESS;
    }
    submit(&dir, &[])
}

/// `adhesim sweep submit DIR`: submits the given cases, or every unfinished one.
fn submit(dir: &Path, cases: &[usize]) -> ExitCode {
    let plan = match adhesim_io::sweep::SweepPlan::read(dir) {
        Ok(p) => p,
        Err(e) => return fail_input(e),
    };
    let numbers: Vec<usize> = if cases.is_empty() {
        plan.cases
            .iter()
            .filter(|c| {
                !matches!(adhesim_io::sweep::read_run(&dir.join(&c.dir)),
                    Some(s) if s.outcome == Outcome::Finished)
            })
            .map(|c| c.number)
            .collect()
    } else {
        if let Some(bad) = cases.iter().find(|&&n| n == 0 || n > plan.cases.len()) {
            return fail_input(format!(
                "--cases: {bad} is not a case of the sweep in {} (1 to {})",
                dir.display(),
                plan.cases.len()
            ));
        }
        cases.to_vec()
    };
    if numbers.is_empty() {
        eprintln!(
            "every case of {} has finished; nothing to submit",
            dir.display()
        );
        return ExitCode::SUCCESS;
    }
    match adhesim_io::slurm::submit(dir, &numbers) {
        Ok(id) => {
            eprintln!(
                "submitted job {id}: cases {} (logs in {})",
                adhesim_io::slurm::array_spec(&numbers),
                dir.join("slurm").display()
            );
            println!("{id}");
            ExitCode::SUCCESS
        }
        Err(e) => fail_input(e),
    }
}

/// `adhesim sweep collect DIR`.
fn collect(dir: &Path, quiet: bool) -> ExitCode {
    let collected = match adhesim_io::sweep::collect(dir) {
        Ok(c) => c,
        Err(e) => return fail_input(e),
    };
    let mut unfinished = 0;
    for (case, result) in collected.plan.cases.iter().zip(&collected.results) {
        let case_dir = dir.join(&case.dir);
        let what = match result {
            Ok(s) => match &s.outcome {
                Outcome::Finished => None,
                Outcome::Failed(m) => Some(format!("failed at t = {:.4e} s: {m}", s.t_reached)),
                Outcome::Interrupted => Some(format!(
                    "interrupted at t = {:.4e} s (resubmit to resume it)",
                    s.t_reached
                )),
                Outcome::Running if adhesim_io::outdir::is_locked(&case_dir) => {
                    Some(format!("running, at t = {:.4e} s", s.t_reached))
                }
                Outcome::Running => Some(format!(
                    "killed at t = {:.4e} s or later (no process holds its lock; resubmit to resume it)",
                    s.t_reached
                )),
            },
            Err(m) => Some(m.clone()),
        };
        if let Some(what) = what {
            unfinished += 1;
            eprintln!("case {} ({}): {what}", case.number, case.label);
        }
    }
    if !quiet {
        eprintln!(
            "{} of {} cases finished; summary {}, {} comparison figures in {}",
            collected.plan.cases.len() - unfinished,
            collected.plan.cases.len(),
            dir.join("sweep.csv").display(),
            collected.figures.len(),
            dir.join("figures").display()
        );
    }
    if unfinished > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
