//! The native part of adhesim's Python module (`adhesim._native`): thin functions over the
//! library that the Python package (`python/adhesim/`) wraps into its public API.
//!
//! Scenarios cross the boundary as TOML text plus the path that names them in messages and
//! anchors their relative mesh paths; run summaries and scenario documents as JSON text;
//! histories as one little-endian `f64` byte buffer (row-major) that numpy views without a
//! copy per value. Every scenario error is raised as `ScenarioError` with the message that
//! `adhesim check` prints.

use adhesim::time::StepReport;
use adhesim_io::run::{Progress, RunControl};
use adhesim_io::scenario::{LoadOptions, Override};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

create_exception!(
    _native,
    AdhesimError,
    PyException,
    "Base class of the errors raised by adhesim."
);
create_exception!(
    _native,
    ScenarioError,
    AdhesimError,
    "A scenario that cannot be read or is invalid; the message names the file, the key and \
     what would be valid (the message of `adhesim check`)."
);
create_exception!(
    _native,
    RunError,
    AdhesimError,
    "A run that cannot start or cannot write its outputs (output folder in use or holding a \
     previous run, unusable checkpoint, unwritable file)."
);

/// The variant and `KEY=VALUE` overrides as the library takes them.
fn load_options(variant: Option<String>, overrides: &[String]) -> PyResult<LoadOptions> {
    let overrides = overrides
        .iter()
        .map(|o| Override::parse(o).map_err(|e| ScenarioError::new_err(format!("override: {e}"))))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(LoadOptions { variant, overrides })
}

/// Reads and validates scenario text as `adhesim check` does (the scenario, then the
/// elements of its meshes).
fn load(
    text: &str,
    path: &Path,
    variant: Option<String>,
    overrides: &[String],
) -> PyResult<adhesim_io::scenario::Scenario> {
    let options = load_options(variant, overrides)?;
    let scenario = adhesim_io::scenario::parse_with(text, path, &options)
        .map_err(|e| ScenarioError::new_err(e.to_string()))?;
    if let Err(err) = adhesim::time::check_elements(&scenario.problem) {
        return Err(ScenarioError::new_err(format!("{}: {err}", path.display())));
    }
    Ok(scenario)
}

/// The TOML document `text` as JSON text (syntax only: nothing is validated).
#[pyfunction]
fn toml_to_json(text: &str, path: PathBuf) -> PyResult<String> {
    let doc: toml::Table = toml::from_str(text).map_err(|e| {
        ScenarioError::new_err(format!("{}: {}", path.display(), e.to_string().trim_end()))
    })?;
    serde_json::to_string(&doc).map_err(|e| ScenarioError::new_err(e.to_string()))
}

/// A JSON object (a scenario given as a dict) as TOML text.
#[pyfunction]
fn json_to_toml(json: &str) -> PyResult<String> {
    use serde::Deserialize;
    let value: serde_json::Value =
        serde_json::from_str(json).map_err(|e| ScenarioError::new_err(e.to_string()))?;
    let table = toml::Table::deserialize(value).map_err(|e| {
        ScenarioError::new_err(format!(
            "the scenario dict cannot be written as TOML: {e} (values must be numbers, \
             strings, booleans, lists or dicts with string keys; None has no TOML form)"
        ))
    })?;
    toml::to_string(&table).map_err(|e| {
        ScenarioError::new_err(format!("the scenario dict cannot be written as TOML: {e}"))
    })
}

/// Validates a scenario; returns JSON with its name, counts, times, fingerprint and the
/// physical warnings `adhesim check` prints.
#[pyfunction]
#[pyo3(signature = (text, path, variant=None, overrides=Vec::new()))]
fn check(
    text: &str,
    path: PathBuf,
    variant: Option<String>,
    overrides: Vec<String>,
) -> PyResult<String> {
    let scenario = load(text, &path, variant, &overrides)?;
    let problem = &scenario.problem;
    let warnings = adhesim::warnings::physical_warnings(problem);
    let info = serde_json::json!({
        "name": problem.name,
        "bodies": problem.bodies.iter().map(|b| b.name.clone()).collect::<Vec<_>>(),
        "nodes": problem.bodies.iter().map(|b| b.mesh.num_nodes()).sum::<usize>(),
        "cells": problem.bodies.iter().map(|b| b.mesh.num_cells()).sum::<usize>(),
        "t_end": problem.time.t_end,
        "dt": problem.time.dt,
        "fingerprint": format!("{:016x}", adhesim_io::checkpoint::fingerprint(problem, &scenario.output)),
        "warnings": warnings,
    });
    Ok(info.to_string())
}

/// A stop request that any Python thread can set while a run goes on (the run releases
/// the interpreter between steps): the run stops after its current step with a checkpoint.
#[pyclass(module = "adhesim._native")]
#[derive(Clone, Default)]
struct StopRequest {
    flag: Arc<AtomicBool>,
}

#[pymethods]
impl StopRequest {
    #[new]
    fn new() -> Self {
        Self::default()
    }
    /// Asks the run to stop after its current step.
    fn set(&self) {
        self.flag.store(true, Ordering::SeqCst);
    }
    /// Whether a stop was asked for.
    fn is_set(&self) -> bool {
        self.flag.load(Ordering::SeqCst)
    }
}

/// Forwards every committed step to a Python callable; a `False` return value, an
/// exception in it or Ctrl-C asks the run to stop after the step (with a checkpoint). The
/// run itself goes on without the interpreter; each call takes it back.
struct Callback {
    callback: Option<Py<PyAny>>,
    stop: Arc<AtomicBool>,
    /// The exception that stopped the run, raised again once the run has ended cleanly.
    error: Option<PyErr>,
    messages: Vec<String>,
}

impl Progress for Callback {
    fn step(&mut self, r: &StepReport, t_end: f64) {
        if self.error.is_some() {
            return;
        }
        Python::with_gil(|py| {
            if let Err(e) = py.check_signals() {
                self.error = Some(e);
                self.stop.store(true, Ordering::SeqCst);
                return;
            }
            let Some(cb) = &self.callback else { return };
            let result = (|| -> PyResult<bool> {
                let d = PyDict::new(py);
                d.set_item("step", r.step)?;
                d.set_item("t", r.t)?;
                d.set_item("t_end", t_end)?;
                d.set_item("dt", r.dt)?;
                d.set_item("newton_iterations", r.newton_iterations)?;
                d.set_item("cutbacks", r.cutbacks)?;
                d.set_item("residual", r.residual)?;
                d.set_item("kinetic", r.kinetic)?;
                d.set_item("internal", r.internal)?;
                d.set_item("external_work", r.external_work)?;
                d.set_item("contact_points", r.contact_points)?;
                let answer = cb.bind(py).call1((d,))?;
                // Only an explicit False stops: a callback that returns nothing goes on.
                Ok(!answer.is_instance_of::<pyo3::types::PyBool>() || answer.is_truthy()?)
            })();
            match result {
                Ok(true) => {}
                Ok(false) => self.stop.store(true, Ordering::SeqCst),
                Err(e) => {
                    self.error = Some(e);
                    self.stop.store(true, Ordering::SeqCst);
                }
            }
        });
    }
    fn message(&mut self, text: &str) {
        self.messages.push(text.to_string());
    }
}

/// Runs a scenario into `out_dir`; returns the run summary (run.json) as JSON text and the
/// messages of the run (the reason it stopped, figures not drawn).
#[pyfunction]
#[pyo3(signature = (text, path, out_dir, variant=None, overrides=Vec::new(), callback=None,
    checkpoint_every=100, resume=false, overwrite=false, stop_after_steps=None,
    from_file=true, stop=None))]
#[allow(clippy::too_many_arguments)]
fn run<'py>(
    py: Python<'py>,
    text: &str,
    path: PathBuf,
    out_dir: PathBuf,
    variant: Option<String>,
    overrides: Vec<String>,
    callback: Option<Bound<'py, PyAny>>,
    checkpoint_every: usize,
    resume: bool,
    overwrite: bool,
    stop_after_steps: Option<usize>,
    from_file: bool,
    stop: Option<StopRequest>,
) -> PyResult<(String, Vec<String>)> {
    let scenario = load(text, &path, variant, &overrides)?;
    let stop = stop.unwrap_or_default().flag;
    let control = RunControl {
        checkpoint_every,
        resume,
        stop: Some(stop.clone()),
        stop_after_steps,
        refuse_existing_run: !overwrite,
    };
    let mut progress = Callback {
        callback: callback.map(Bound::unbind),
        stop,
        error: None,
        messages: Vec::new(),
    };
    let scenario_file = from_file.then_some(path.as_path());
    let summary = py
        .allow_threads(|| {
            adhesim_io::run::run_with(scenario, scenario_file, &out_dir, &mut progress, &control)
        })
        .map_err(|e| RunError::new_err(format!("{}: {e}", path.display())))?;
    if let Some(e) = progress.error {
        return Err(e);
    }
    let json = serde_json::to_string(&summary).map_err(|e| RunError::new_err(e.to_string()))?;
    Ok((json, progress.messages))
}

/// Reads a history.csv: the column names, the number of rows and the values row after row
/// as little-endian f64 bytes.
#[pyfunction]
fn read_history<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Vec<String>, usize, Bound<'py, PyBytes>)> {
    let (names, rows) = adhesim_io::output::csv::read_history(&path)
        .map_err(|e| pyo3::exceptions::PyOSError::new_err(e.to_string()))?;
    let mut bytes = Vec::with_capacity(rows.len() * names.len() * 8);
    for row in &rows {
        for v in row {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok((names, rows.len(), PyBytes::new(py, &bytes)))
}

/// Runs a parameter study (as `adhesim sweep`): the cartesian product of `axes`
/// (`KEY=V1,V2,...`) on the scenario file, with the variant and the fixed overrides common
/// to every case. Returns the cases' run summaries as JSON text.
#[pyfunction]
#[pyo3(signature = (path, out_dir, axes, variant=None, fixed=Vec::new(), jobs=1,
    checkpoint_every=100, resume=false, overwrite=false))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    path: PathBuf,
    out_dir: PathBuf,
    axes: Vec<String>,
    variant: Option<String>,
    fixed: Vec<String>,
    jobs: usize,
    checkpoint_every: usize,
    resume: bool,
    overwrite: bool,
) -> PyResult<String> {
    use adhesim_io::sweep::{Axis, SweepError, SweepOptions, SweepPlan};
    let axes = axes
        .iter()
        .map(|a| Axis::parse(a))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| ScenarioError::new_err(format!("{}: axis: {e}", path.display())))?;
    let plan = SweepPlan::new(&path, variant, &fixed, &axes)
        .map_err(|e| ScenarioError::new_err(format!("{}: {e}", path.display())))?;
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let jobs = jobs.max(1);
    let options = SweepOptions {
        jobs,
        threads_per_case: (cores / jobs).max(1),
        checkpoint_every,
        resume,
        overwrite,
        stop: None,
    };
    // The cases run on worker threads that never call into Python: the interpreter is
    // free for other threads meanwhile.
    let summary = py
        .allow_threads(|| {
            adhesim_io::sweep::run_sweep(&plan, &options, &out_dir, &adhesim_io::sweep::QuietSweep)
        })
        .map_err(|e| match e {
            SweepError::Scenario { .. } | SweepError::Axes(_) => {
                ScenarioError::new_err(e.to_string())
            }
            other => RunError::new_err(other.to_string()),
        })?;
    let cases: Vec<_> = summary
        .cases
        .iter()
        .zip(&summary.results)
        .map(|(c, r)| {
            serde_json::json!({
                "label": c.label,
                "dir": c.dir_name,
                "run": r.as_ref().ok(),
                "error": r.as_ref().err(),
            })
        })
        .collect();
    Ok(serde_json::json!({
        "cases": cases,
        "interrupted": summary.interrupted,
        "figures": summary.figures,
        "wall_time": summary.wall_time,
    })
    .to_string())
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("AdhesimError", py.get_type::<AdhesimError>())?;
    m.add("ScenarioError", py.get_type::<ScenarioError>())?;
    m.add("RunError", py.get_type::<RunError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<StopRequest>()?;
    m.add_function(wrap_pyfunction!(toml_to_json, m)?)?;
    m.add_function(wrap_pyfunction!(json_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(read_history, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    Ok(())
}
