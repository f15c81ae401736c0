//! Parameter studies: the cartesian product of overridden values of a scenario, run in
//! parallel (one case per worker), each case in its own sub-folder, then compared.
//!
//! Outputs in the sweep folder:
//! - `caseNN_<label>/`: a complete run of each case (history, frames, figures, run.json);
//! - `sweep.csv`: one row per case: its values, how it ended, its cost, and for every tracked
//!   quantity (`<track>.<field>`, `<pair>.<field>`) the maximum, minimum and final value;
//! - `figures/<column>.png`: one figure per tracked quantity, one curve per case;
//! - `sweep.json`: the plan (scenario, variant, fixed overrides, axes, cases), written
//!   before any case runs, from which a sweep is resumed, submitted to Slurm
//!   ([`crate::slurm`]) or collected ([`collect`]) from whatever cases have run.
//! - `figures/peak_<column>_vs_<key>.png`: the peak of a tracked quantity (its value of
//!   largest magnitude over the run: peak β, peak pull-off force) against each numeric swept
//!   key, one curve per combination of the other keys' values.

use crate::output::csv::read_history;
use crate::output::plot::{draw_line_plot, LinePlot, PlotError, Series};
use crate::run::{Outcome, RunSummary, Silent};
use crate::scenario::{LoadOptions, Override, ScenarioError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// One swept key and its values.
#[derive(Clone, Debug)]
pub struct Axis {
    /// Dotted key (see [`crate::scenario::prepare`]).
    pub key: String,
    /// Values in the order given.
    pub values: Vec<toml::Value>,
    /// The values as written (for labels and folder names).
    pub texts: Vec<String>,
}

impl Axis {
    /// Parses `key=v1,v2,...` (commas inside brackets belong to a value).
    pub fn parse(text: &str) -> Result<Axis, String> {
        let (key, values) = text.split_once('=').ok_or_else(|| {
            format!(
                "`{text}` is not of the form key=v1,v2,... (e.g. contact.top.friction=0,0.2,0.4)"
            )
        })?;
        let key = key.trim();
        if key.is_empty() {
            return Err(format!("`{text}` has an empty key"));
        }
        let texts = crate::scenario::prepare::split_values(values);
        if texts.iter().any(|v| v.is_empty()) {
            return Err(format!("`{text}` has an empty value"));
        }
        let values = texts
            .iter()
            .map(|v| crate::scenario::prepare::parse_value(v))
            .collect();
        Ok(Axis {
            key: key.to_string(),
            values,
            texts,
        })
    }

    /// Short name for labels: the last part of the key.
    fn short(&self) -> &str {
        self.key.rsplit('.').next().unwrap_or(&self.key)
    }
}

/// One case of a sweep.
#[derive(Clone, Debug)]
pub struct Case {
    /// Position in the sweep (0-based).
    pub index: usize,
    /// Legend label, e.g. `friction=0.2, v=1`.
    pub label: String,
    /// Sub-folder name.
    pub dir_name: String,
    /// The overrides that make this case (after the common ones).
    pub overrides: Vec<Override>,
    /// The values as written, one per axis.
    pub texts: Vec<String>,
}

/// The cartesian product of the axes, the first axis varying slowest.
pub fn cases(axes: &[Axis]) -> Vec<Case> {
    let total: usize = axes.iter().map(|a| a.values.len()).product();
    let width = total.to_string().len().max(2);
    (0..total)
        .map(|index| {
            let mut rest = index;
            let mut picks = vec![0; axes.len()];
            for (k, a) in axes.iter().enumerate().rev() {
                picks[k] = rest % a.values.len();
                rest /= a.values.len();
            }
            let parts: Vec<String> = axes
                .iter()
                .zip(&picks)
                .map(|(a, &p)| format!("{}={}", a.short(), a.texts[p]))
                .collect();
            let label = parts.join(", ");
            let slug: String = parts
                .join("_")
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || "-._=".contains(c) {
                        c
                    } else {
                        '-'
                    }
                })
                .collect();
            Case {
                index,
                label,
                dir_name: format!("case{:0width$}_{slug}", index + 1),
                overrides: axes
                    .iter()
                    .zip(&picks)
                    .map(|(a, &p)| Override {
                        key: a.key.clone(),
                        value: a.values[p].clone(),
                    })
                    .collect(),
                texts: axes
                    .iter()
                    .zip(&picks)
                    .map(|(a, &p)| a.texts[p].clone())
                    .collect(),
            }
        })
        .collect()
}

/// A sweep as written to `DIR/sweep.json` before any case runs: enough to run, resume,
/// submit or collect it later, from this machine or a cluster's nodes.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SweepPlan {
    /// adhesim version that wrote the plan.
    pub version: String,
    /// Scenario file (absolute path).
    pub scenario: PathBuf,
    /// Variant applied to every case.
    pub variant: Option<String>,
    /// Overrides common to every case, `KEY=VALUE` as given.
    pub fixed: Vec<String>,
    /// Swept keys and their values as given.
    pub axes: Vec<PlannedAxis>,
    /// The cases, in order.
    pub cases: Vec<PlannedCase>,
}

/// One swept key of a [`SweepPlan`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlannedAxis {
    /// Dotted key.
    pub key: String,
    /// Values as written.
    pub values: Vec<String>,
}

/// One case of a [`SweepPlan`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlannedCase {
    /// Case number (1-based; the Slurm array index).
    pub number: usize,
    /// Legend label.
    pub label: String,
    /// Sub-folder of the sweep folder.
    pub dir: String,
    /// The case's own overrides, `KEY=VALUE` (after the fixed ones).
    pub set: Vec<String>,
}

/// File name of the plan in a sweep folder.
pub const PLAN_FILE: &str = "sweep.json";

impl SweepPlan {
    /// The plan of the cartesian product of `axes` on `scenario` (made absolute), with the
    /// variant and the fixed overrides (`KEY=VALUE`) common to every case.
    pub fn new(
        scenario: &Path,
        variant: Option<String>,
        fixed: &[String],
        axes: &[Axis],
    ) -> Result<SweepPlan, SweepError> {
        if axes.is_empty() {
            return Err(SweepError::Axes(
                "a sweep needs at least one --set key=v1,v2,...".into(),
            ));
        }
        for a in axes {
            if a.values.is_empty() {
                return Err(SweepError::Axes(format!("`{}` has no values", a.key)));
            }
            if axes.iter().filter(|b| b.key == a.key).count() > 1 {
                return Err(SweepError::Axes(format!("`{}` is swept twice", a.key)));
            }
        }
        for f in fixed {
            Override::parse(f).map_err(|e| SweepError::Axes(format!("--fix: {e}")))?;
        }
        let scenario = std::path::absolute(scenario).map_err(|source| SweepError::Io {
            path: scenario.to_path_buf(),
            source,
        })?;
        Ok(SweepPlan {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scenario,
            variant,
            fixed: fixed.to_vec(),
            axes: axes
                .iter()
                .map(|a| PlannedAxis {
                    key: a.key.clone(),
                    values: a.texts.clone(),
                })
                .collect(),
            cases: cases(axes)
                .into_iter()
                .map(|c| PlannedCase {
                    number: c.index + 1,
                    set: axes
                        .iter()
                        .zip(&c.texts)
                        .map(|(a, t)| format!("{}={t}", a.key))
                        .collect(),
                    label: c.label,
                    dir: c.dir_name,
                })
                .collect(),
        })
    }

    /// The axes, parsed back from the plan.
    pub fn parsed_axes(&self) -> Vec<Axis> {
        self.axes
            .iter()
            .map(|a| Axis {
                key: a.key.clone(),
                values: a
                    .values
                    .iter()
                    .map(|v| crate::scenario::prepare::parse_value(v))
                    .collect(),
                texts: a.values.clone(),
            })
            .collect()
    }

    /// The cases, parsed back from the plan.
    pub fn parsed_cases(&self) -> Vec<Case> {
        cases(&self.parsed_axes())
    }

    /// The arguments of `adhesim run` that give case `c` (after the scenario file):
    /// `--variant V` and one `--set KEY=VALUE` per fixed and per swept value.
    pub fn run_args(&self, c: &PlannedCase) -> Vec<String> {
        let mut args = Vec::new();
        if let Some(v) = &self.variant {
            args.push("--variant".to_string());
            args.push(v.clone());
        }
        for s in self.fixed.iter().chain(&c.set) {
            args.push("--set".to_string());
            args.push(s.clone());
        }
        args
    }

    /// How each case is loaded: the variant, then the fixed overrides, then its own.
    fn load_options(&self, c: &PlannedCase) -> LoadOptions {
        LoadOptions {
            variant: self.variant.clone(),
            overrides: self
                .fixed
                .iter()
                .chain(&c.set)
                .filter_map(|s| Override::parse(s).ok())
                .collect(),
        }
    }

    /// Loads every case's scenario; the first invalid case stops it.
    pub fn load_cases(&self) -> Result<Vec<crate::scenario::Scenario>, SweepError> {
        self.cases
            .iter()
            .map(|c| {
                crate::scenario::load_with(&self.scenario, &self.load_options(c)).map_err(
                    |source| SweepError::Scenario {
                        label: c.label.clone(),
                        source,
                    },
                )
            })
            .collect()
    }

    /// Whether `other` describes the same study (the version that wrote it aside).
    pub fn same_study(&self, other: &SweepPlan) -> bool {
        self.scenario == other.scenario
            && self.variant == other.variant
            && self.fixed == other.fixed
            && self.axes == other.axes
    }

    /// Writes `dir/sweep.json` atomically, creating `dir`.
    pub fn write(&self, dir: &Path) -> Result<(), SweepError> {
        std::fs::create_dir_all(dir).map_err(|source| SweepError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let path = dir.join(PLAN_FILE);
        let json = serde_json::to_vec_pretty(self).expect("plan serialises");
        crate::output::atomic::write_atomic(&path, &json)
            .map_err(|source| SweepError::Io { path, source })
    }

    /// Reads `dir/sweep.json`.
    pub fn read(dir: &Path) -> Result<SweepPlan, SweepError> {
        let path = dir.join(PLAN_FILE);
        let bytes = std::fs::read(&path).map_err(|source| SweepError::Read {
            path: path.clone(),
            source,
        })?;
        serde_json::from_slice(&bytes).map_err(|e| SweepError::Plan {
            path,
            reason: e.to_string(),
        })
    }
}

/// How a sweep is run.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Cases run at the same time.
    pub jobs: usize,
    /// Threads of each case's own pool (element loops, factorisation).
    pub threads_per_case: usize,
    /// Each case writes a checkpoint every this many steps (0: only when stopped).
    pub checkpoint_every: usize,
    /// Continue the sweep in the output folder: finished (and failed) cases are kept,
    /// interrupted or killed ones resume from their checkpoints, the others start.
    pub resume: bool,
    /// Replace a previous sweep in the output folder (each case's outputs are removed before
    /// it runs).
    pub overwrite: bool,
    /// When set (by a signal handler), running cases stop after their current step with a
    /// checkpoint and no further case starts.
    pub stop: Option<Arc<AtomicBool>>,
}

/// Receives sweep progress (the CLI prints lines).
pub trait SweepProgress: Sync {
    /// A case starts (or resumes).
    fn started(&self, case: &Case, total: usize);
    /// A case ended (or could not run: `Err`).
    fn finished(&self, case: &Case, total: usize, result: &Result<RunSummary, String>);
}

/// Progress that is not shown.
pub struct QuietSweep;
impl SweepProgress for QuietSweep {
    fn started(&self, _: &Case, _: usize) {}
    fn finished(&self, _: &Case, _: usize, _: &Result<RunSummary, String>) {}
}

/// Errors that prevent a sweep from running.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// A case's scenario is invalid (checked for every case before any runs).
    #[error("case {label}: {source}")]
    Scenario {
        /// The case.
        label: String,
        /// What is wrong.
        source: ScenarioError,
    },
    /// No axis or an axis without values.
    #[error("{0}")]
    Axes(String),
    /// An output could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A sweep folder's plan cannot be read.
    #[error("cannot read {path} (is this a sweep folder? `adhesim sweep` writes it): {source}")]
    Read {
        /// The plan file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A sweep plan (sweep.json) cannot be read.
    #[error("{path} is not a sweep plan written by adhesim: {reason}")]
    Plan {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The output folder holds another sweep, or none to resume.
    #[error("{0}")]
    Folder(String),
    /// A comparison figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// What a sweep did.
#[derive(Debug)]
pub struct SweepSummary {
    /// The cases, in order.
    pub cases: Vec<Case>,
    /// Each case's run summary, or why it has none.
    pub results: Vec<Result<RunSummary, String>>,
    /// Cases kept from a previous session of a resumed sweep.
    pub kept: usize,
    /// Whether a stop request ended the sweep early.
    pub interrupted: bool,
    /// Comparison figures written.
    pub figures: Vec<PathBuf>,
    /// Wall time of the whole sweep [s].
    pub wall_time: f64,
}

/// Checks whether `plan` may be written to `out_dir`, given a sweep already there: a new
/// sweep needs an empty folder (or `overwrite`), a resumed one the same study.
pub fn check_folder(
    plan: &SweepPlan,
    out_dir: &Path,
    resume: bool,
    overwrite: bool,
) -> Result<(), SweepError> {
    let exists = out_dir.join(PLAN_FILE).exists();
    match (exists, resume) {
        (false, true) => Err(SweepError::Folder(format!(
            "{} holds no sweep to resume (no {PLAN_FILE}); start it without --resume",
            out_dir.display()
        ))),
        (true, true) => {
            let old = SweepPlan::read(out_dir)?;
            if old.same_study(plan) {
                Ok(())
            } else {
                Err(SweepError::Folder(format!(
                    "{} holds another sweep ({} with {}); resume it with the same scenario, \
                     --variant, --fix and --set, or start this one with another --out",
                    out_dir.display(),
                    old.scenario.display(),
                    old.axes
                        .iter()
                        .map(|a| format!("{}={}", a.key, a.values.join(",")))
                        .collect::<Vec<_>>()
                        .join(" ")
                )))
            }
        }
        (true, false) if !overwrite => Err(SweepError::Folder(format!(
            "{} holds a sweep already; continue it with --resume, or replace it with --overwrite",
            out_dir.display()
        ))),
        _ => Ok(()),
    }
}

/// Runs every case of `plan` into `out_dir`, `options.jobs` at a time, after writing the
/// plan there. Every case is validated first, so that a bad value stops the sweep before
/// anything runs. The table and figures are then assembled as by [`collect`].
pub fn run_sweep(
    plan: &SweepPlan,
    options: &SweepOptions,
    out_dir: &Path,
    progress: &dyn SweepProgress,
) -> Result<SweepSummary, SweepError> {
    let start = std::time::Instant::now();
    // Each case is loaded once: here, so that a bad value stops the sweep before anything
    // runs, and the worker that runs it takes it from its slot.
    let loaded: Vec<Mutex<Option<crate::scenario::Scenario>>> = plan
        .load_cases()?
        .into_iter()
        .map(|p| Mutex::new(Some(p)))
        .collect();
    // One sweep at a time in a folder (each case also locks its own).
    let _lock = crate::outdir::lock(out_dir).map_err(|e| SweepError::Folder(e.to_string()))?;
    check_folder(plan, out_dir, options.resume, options.overwrite)?;
    plan.write(out_dir)?;
    let cases = plan.parsed_cases();
    let results: Mutex<Vec<Option<Result<RunSummary, String>>>> =
        Mutex::new(vec![None; cases.len()]);
    let kept = AtomicUsize::new(0);
    let next = AtomicUsize::new(0);
    let jobs = options.jobs.clamp(1, cases.len().max(1));
    let total = cases.len();
    let stopped = || {
        options
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::SeqCst))
    };
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(case) = cases.get(i) else { break };
                if stopped() {
                    break;
                }
                let dir = out_dir.join(&case.dir_name);
                if options.resume {
                    if let Some(done) = read_run(&dir)
                        .filter(|s| matches!(s.outcome, Outcome::Finished | Outcome::Failed(_)))
                    {
                        kept.fetch_add(1, Ordering::SeqCst);
                        progress.finished(case, total, &Ok(done.clone()));
                        if let Ok(mut r) = results.lock() {
                            r[i] = Some(Ok(done));
                        }
                        continue;
                    }
                }
                progress.started(case, total);
                let scenario = loaded[i].lock().ok().and_then(|mut p| p.take());
                let result = match scenario {
                    Some(scenario) => run_case(&plan.scenario, &dir, scenario, options),
                    None => Err("the case's scenario is not available".into()),
                };
                progress.finished(case, total, &result);
                if let Ok(mut r) = results.lock() {
                    r[i] = Some(result);
                }
            });
        }
    });
    let results = results.into_inner().unwrap_or_default();
    let collected = assemble(out_dir, plan, &cases, &results)?;
    Ok(SweepSummary {
        cases,
        results: collected.results,
        kept: kept.into_inner(),
        interrupted: stopped(),
        figures: collected.figures,
        wall_time: start.elapsed().as_secs_f64(),
    })
}

/// Runs one case into `dir`: resumed from its checkpoint when the sweep is resumed and
/// there is one, otherwise from the start.
fn run_case(
    scenario_file: &Path,
    dir: &Path,
    scenario: crate::scenario::Scenario,
    options: &SweepOptions,
) -> Result<RunSummary, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads_per_case.max(1))
        .build()
        .map_err(|e| format!("cannot start the case's threads: {e}"))?;
    let resume = options.resume && crate::checkpoint::Checkpoint::path(dir).exists();
    let control = crate::run::RunControl {
        checkpoint_every: options.checkpoint_every,
        resume,
        stop: options.stop.clone(),
        stop_after_steps: None,
        // A resumed sweep restarts a case that has no checkpoint (never started, or killed
        // before its first one); a new sweep only writes over a case with --overwrite.
        refuse_existing_run: !(options.resume || options.overwrite),
    };
    pool.install(|| crate::run::run_with(scenario, Some(scenario_file), dir, &mut Silent, &control))
        .map_err(|e| e.to_string())
}

/// The run summary in `dir/run.json`, if there is a readable one.
pub fn read_run(dir: &Path) -> Option<RunSummary> {
    serde_json::from_slice(&std::fs::read(dir.join("run.json")).ok()?).ok()
}

/// What [`collect`] found.
#[derive(Debug)]
pub struct Collected {
    /// The plan.
    pub plan: SweepPlan,
    /// Each case's run summary (from its run.json), or why it has none.
    pub results: Vec<Result<RunSummary, String>>,
    /// Comparison figures written.
    pub figures: Vec<PathBuf>,
}

/// Assembles `sweep.csv` and the comparison figures of the sweep in `out_dir` (its
/// `sweep.json` names the cases) from whatever cases have run so far: each case's row comes
/// from its run.json and history.csv, as they are on disk. Cases without a run.json are
/// listed as `not run`.
pub fn collect(out_dir: &Path) -> Result<Collected, SweepError> {
    let plan = SweepPlan::read(out_dir)?;
    let cases = plan.parsed_cases();
    if cases.len() != plan.cases.len()
        || cases
            .iter()
            .zip(&plan.cases)
            .any(|(c, p)| c.dir_name != p.dir)
    {
        return Err(SweepError::Plan {
            path: out_dir.join(PLAN_FILE),
            reason: "its cases do not match its axes".into(),
        });
    }
    let none = vec![None; cases.len()];
    assemble(out_dir, &plan, &cases, &none)
}

/// Reads every case's outcome from disk (falling back to `known`, the in-memory result of
/// a case that could not write a run.json), writes sweep.csv and the figures.
fn assemble(
    out_dir: &Path,
    plan: &SweepPlan,
    cases: &[Case],
    known: &[Option<Result<RunSummary, String>>],
) -> Result<Collected, SweepError> {
    let results: Vec<Result<RunSummary, String>> = cases
        .iter()
        .zip(known)
        .map(|(c, k)| {
            let dir = out_dir.join(&c.dir_name);
            match (read_run(&dir), k) {
                (Some(s), _) => Ok(s),
                (None, Some(Err(m))) => Err(format!("could not run: {m}")),
                (None, _) if dir.join("run.json").exists() => Err("run.json cannot be read".into()),
                (None, _) => Err("not run".into()),
            }
        })
        .collect();
    let histories: Vec<Option<History>> = cases
        .iter()
        .map(|c| read_history(out_dir.join(&c.dir_name).join("history.csv")).ok())
        .collect();
    let axes = plan.parsed_axes();
    write_summary(out_dir, &axes, cases, &results, &histories)?;
    let mut figures = draw_comparison(out_dir, cases, &histories)?;
    figures.extend(draw_peak_figures(out_dir, &axes, cases, &histories)?);
    Ok(Collected {
        plan: plan.clone(),
        results,
        figures,
    })
}

/// Quotes a CSV field when it holds a comma or a quote.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A run's history: column names and rows.
pub type History = (Vec<String>, Vec<Vec<f64>>);

/// The columns of the histories that satisfy `keep`: their union over the cases, in
/// first-seen order. Tracked quantities (a track's or a pair's fields) hold a dot.
fn columns_where(histories: &[Option<History>], keep: impl Fn(&str) -> bool) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for (cols, _) in histories.iter().flatten() {
        for c in cols {
            if keep(c) && !out.contains(c) {
                out.push(c.clone());
            }
        }
    }
    out
}

fn write_summary(
    out_dir: &Path,
    axes: &[Axis],
    cases: &[Case],
    results: &[Result<RunSummary, String>],
    histories: &[Option<History>],
) -> Result<(), SweepError> {
    let tracked = columns_where(histories, |c| c.contains('.'));
    let mut header = vec!["case".to_string(), "dir".to_string()];
    header.extend(axes.iter().map(|a| a.key.clone()));
    header.extend(
        [
            "status",
            "t_reached",
            "steps",
            "cutbacks",
            "newton_iterations",
            "wall_time",
        ]
        .map(String::from),
    );
    for c in &tracked {
        for s in ["max", "min", "final"] {
            header.push(format!("{c}.{s}"));
        }
    }
    let mut text = header
        .iter()
        .map(|h| csv_field(h))
        .collect::<Vec<_>>()
        .join(",");
    text.push('\n');
    for ((case, result), history) in cases.iter().zip(results).zip(histories) {
        let mut row = vec![(case.index + 1).to_string(), csv_field(&case.dir_name)];
        row.extend(case.texts.iter().map(|t| csv_field(t)));
        match result {
            Ok(s) => {
                row.push(match &s.outcome {
                    Outcome::Finished => "finished".to_string(),
                    Outcome::Failed(m) => csv_field(&format!("failed: {m}")),
                    Outcome::Interrupted => "interrupted".to_string(),
                    Outcome::Running => "running".to_string(),
                });
                row.push(format!("{:e}", s.t_reached));
                row.push(s.steps.to_string());
                row.push(s.cutbacks.to_string());
                row.push(s.newton_iterations.to_string());
                row.push(format!("{:.3}", s.wall_time));
            }
            Err(m) => {
                row.push(csv_field(m));
                row.extend(std::iter::repeat_n(String::new(), 5));
            }
        }
        for c in &tracked {
            let stats = history.as_ref().and_then(|(cols, rows)| {
                let k = cols.iter().position(|x| x == c)?;
                let v: Vec<f64> = rows
                    .iter()
                    .map(|r| r[k])
                    .filter(|x| x.is_finite())
                    .collect();
                let last = rows.last().map(|r| r[k])?;
                Some([
                    v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    v.iter().copied().fold(f64::INFINITY, f64::min),
                    last,
                ])
            });
            match stats {
                Some(s) => row.extend(s.iter().map(|x| format!("{x:e}"))),
                None => row.extend(std::iter::repeat_n(String::new(), 3)),
            }
        }
        text.push_str(&row.join(","));
        text.push('\n');
    }
    let path = out_dir.join("sweep.csv");
    crate::output::atomic::write_atomic(&path, text.as_bytes())
        .map_err(|source| SweepError::Io { path, source })
}

/// One figure per tracked quantity with one curve per case, from the cases' histories.
pub fn draw_comparison(
    out_dir: &Path,
    cases: &[Case],
    histories: &[Option<History>],
) -> Result<Vec<PathBuf>, SweepError> {
    let tracked = columns_where(histories, |c| {
        c.rsplit_once('.')
            .is_some_and(|(_, f)| crate::output::figures::field_label(f).is_some())
    });
    let fig_dir = out_dir.join("figures");
    std::fs::create_dir_all(&fig_dir).map_err(|source| SweepError::Io {
        path: fig_dir.clone(),
        source,
    })?;
    let mut written = Vec::new();
    for column in &tracked {
        let mut series = Vec::new();
        for (case, h) in cases.iter().zip(histories) {
            let Some((cols, rows)) = h else { continue };
            let (Some(t), Some(k)) = (
                cols.iter().position(|c| c == "t"),
                cols.iter().position(|c| c == column),
            ) else {
                continue;
            };
            series.push(Series {
                label: case.label.clone(),
                x: rows.iter().map(|r| r[t]).collect(),
                y: rows.iter().map(|r| r[k]).collect(),
            });
        }
        let field = column.rsplit_once('.').map(|(_, f)| f).unwrap_or(column);
        let owner = column.rsplit_once('.').map(|(o, _)| o).unwrap_or("");
        let y_label = crate::output::figures::field_label(field).unwrap_or(field);
        let plot = LinePlot {
            title: format!(
                "{} at {owner}: one curve per case",
                y_label.split(" [").next().unwrap_or(field)
            ),
            x_label: "time t [s]".into(),
            y_label: y_label.into(),
            series,
        };
        let file = fig_dir.join(format!("{column}.png"));
        draw_line_plot(&file, &plot)?;
        written.push(file);
    }
    Ok(written)
}

/// Unit of a swept key, from its last part, for legends and axes ("" when unknown).
fn key_unit(key: &str) -> &'static str {
    match key.rsplit('.').next().unwrap_or(key) {
        "friction" | "mu" | "poisson" | "theta" | "xi" => "-",
        "w" => "J/m²",
        "cn" | "ct" => "N/m³",
        "b" => "N·s/m",
        "g" | "young" => "Pa",
        "density" => "kg/m³",
        "dt" | "t_end" => "s",
        "omega" | "angular_velocity" => "rad/s",
        _ => "",
    }
}

fn with_unit(text: &str, key: &str) -> String {
    match key_unit(key) {
        "" => text.to_string(),
        u => format!("{text} {u}"),
    }
}

/// The value of largest magnitude of a history column (its sign kept), over finite values.
fn peak(rows: &[Vec<f64>], k: usize) -> Option<f64> {
    rows.iter().map(|r| r[k]).filter(|x| x.is_finite()).fold(
        None,
        |best: Option<f64>, x| match best {
            Some(b) if b.abs() >= x.abs() => Some(b),
            _ => Some(x),
        },
    )
}

/// Curves of the peak of `column` against the numeric values of axis `along`, one per
/// combination of the other axes' values (cases with a missing history or a non-numeric
/// value left out). Labels hold the other keys' values with their units.
fn peak_series(
    axes: &[Axis],
    cases: &[Case],
    histories: &[Option<History>],
    column: &str,
    along: usize,
) -> Vec<Series> {
    let mut series: Vec<Series> = Vec::new();
    for (case, h) in cases.iter().zip(histories) {
        let Some((cols, rows)) = h else { continue };
        let Some(k) = cols.iter().position(|c| c == column) else {
            continue;
        };
        let (Ok(x), Some(y)) = (case.texts[along].parse::<f64>(), peak(rows, k)) else {
            continue;
        };
        let label: Vec<String> = axes
            .iter()
            .zip(&case.texts)
            .enumerate()
            .filter(|(j, _)| *j != along)
            .map(|(_, (a, t))| with_unit(&format!("{}={t}", a.short()), &a.key))
            .collect();
        let label = if label.is_empty() {
            column.to_string()
        } else {
            label.join(", ")
        };
        match series.iter_mut().find(|s| s.label == label) {
            Some(s) => {
                s.x.push(x);
                s.y.push(y);
            }
            None => series.push(Series {
                label,
                x: vec![x],
                y: vec![y],
            }),
        }
    }
    for s in &mut series {
        let mut pts: Vec<(f64, f64)> = s.x.iter().copied().zip(s.y.iter().copied()).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        (s.x, s.y) = pts.into_iter().unzip();
    }
    series
}

/// The peak figures (see the module documentation).
fn draw_peak_figures(
    out_dir: &Path,
    axes: &[Axis],
    cases: &[Case],
    histories: &[Option<History>],
) -> Result<Vec<PathBuf>, SweepError> {
    let tracked = columns_where(histories, |c| {
        c.rsplit_once('.')
            .is_some_and(|(_, f)| crate::output::figures::field_label(f).is_some())
    });
    let mut written = Vec::new();
    for (along, axis) in axes.iter().enumerate() {
        let numeric = axis.texts.iter().all(|t| t.parse::<f64>().is_ok());
        if !numeric || axis.texts.len() < 2 {
            continue;
        }
        for column in &tracked {
            let series = peak_series(axes, cases, histories, column, along);
            if series.is_empty() {
                continue;
            }
            let field = column.rsplit_once('.').map(|(_, f)| f).unwrap_or(column);
            let y_label = crate::output::figures::field_label(field).unwrap_or(field);
            let plot = LinePlot {
                title: format!("peak of {column} against {}", axis.short()),
                x_label: match key_unit(&axis.key) {
                    "" => axis.key.clone(),
                    u => format!("{} [{u}]", axis.key),
                },
                y_label: format!("peak {y_label}"),
                series,
            };
            let file = out_dir
                .join("figures")
                .join(format!("peak_{column}_vs_{}.png", axis.short()));
            draw_line_plot(&file, &plot)?;
            written.push(file);
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two axes (μ × w), a history per case whose column `p.fy` has a known peak: the curves
    /// against μ are one per w, sorted by μ, with the peak of largest magnitude (sign kept).
    #[test]
    fn peak_series_group_by_the_other_keys_with_units() {
        let axes = vec![
            Axis::parse("parameters.mu=0.4,0.2").unwrap(),
            Axis::parse("parameters.w=100,0").unwrap(),
        ];
        let cases = cases(&axes);
        let histories: Vec<Option<History>> = cases
            .iter()
            .map(|c| {
                let mu: f64 = c.texts[0].parse().unwrap();
                let w: f64 = c.texts[1].parse().unwrap();
                // Pull-off: the force dips to −(w + 10 μ) before coming back.
                let rows = vec![vec![0.0, 1.0], vec![1.0, -(w + 10.0 * mu)], vec![2.0, 0.5]];
                Some((vec!["t".to_string(), "p.fy".to_string()], rows))
            })
            .collect();
        let s = peak_series(&axes, &cases, &histories, "p.fy", 0);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].label, "w=100 J/m²");
        assert_eq!(s[0].x, [0.2, 0.4]);
        assert_eq!(s[0].y, [-102.0, -104.0]);
        assert_eq!(s[1].label, "w=0 J/m²");
        assert_eq!(s[1].y, [-2.0, -4.0]);
    }

    #[test]
    fn cases_are_the_cartesian_product_first_axis_slowest() {
        let axes = vec![
            Axis::parse("contact.top.friction=0,0.2").unwrap(),
            Axis::parse("v=1.0,0.8,0.6").unwrap(),
        ];
        let c = cases(&axes);
        assert_eq!(c.len(), 6);
        assert_eq!(c[0].label, "friction=0, v=1.0");
        assert_eq!(c[1].label, "friction=0, v=0.8");
        assert_eq!(c[3].label, "friction=0.2, v=1.0");
        assert_eq!(c[5].dir_name, "case06_friction=0.2_v=0.6");
        assert_eq!(c[4].overrides[1].value, toml::Value::Float(0.8));
    }

    #[test]
    fn a_plan_survives_its_json_and_gives_each_case_its_run_arguments() {
        let axes = vec![
            Axis::parse("contact.top.friction=0,0.2").unwrap(),
            Axis::parse("v=1.0,0.8,0.6").unwrap(),
        ];
        let plan = SweepPlan::new(
            Path::new("/s/x.toml"),
            None,
            &["time.dt=1e-4".to_string()],
            &axes,
        )
        .unwrap();
        assert_eq!(plan.cases.len(), 6);
        assert_eq!(plan.cases[4].number, 5);
        assert_eq!(plan.cases[4].dir, "case05_friction=0.2_v=0.8");
        assert_eq!(
            plan.run_args(&plan.cases[4]),
            [
                "--set",
                "time.dt=1e-4",
                "--set",
                "contact.top.friction=0.2",
                "--set",
                "v=0.8"
            ]
        );
        let back: SweepPlan = serde_json::from_slice(&serde_json::to_vec(&plan).unwrap()).unwrap();
        assert_eq!(back, plan);
        assert_eq!(
            back.parsed_cases()
                .iter()
                .map(|c| c.dir_name.clone())
                .collect::<Vec<_>>(),
            plan.cases.iter().map(|c| c.dir.clone()).collect::<Vec<_>>()
        );
        let other = SweepPlan::new(Path::new("/s/x.toml"), None, &[], &axes).unwrap();
        assert!(!plan.same_study(&other), "the fixed overrides differ");
    }

    #[test]
    fn axis_values_keep_arrays_whole() {
        let a = Axis::parse("body.0.mesh.divisions=[4,2,1],[8,4,1]").unwrap();
        assert_eq!(a.values.len(), 2);
        assert!(Axis::parse("novalue").is_err());
        assert!(Axis::parse("k=1,,2").is_err());
    }
}
