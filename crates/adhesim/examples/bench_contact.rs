//! Performance benchmark of the contact part of a step.
//!
//! A Blatz-Ko pad (G = 1 MPa) is pressed on a rigid plane with Coulomb friction (μ = 0.3)
//! and RCC adhesion (w = 20 J/m², C_n = C_t = 2e9 N/m³, b = 0.1 N·s/m). Its top face is
//! driven down while held in x and z; its whole bottom face is the slave set, and every
//! bottom node stays a contact candidate. For each mesh size the time of each phase of a
//! step (assembly, factorisation, Delassus operator, Gauss-Seidel) is recorded over a few
//! steps and repetitions, together with Newton iterations, Gauss-Seidel sweeps and the peak
//! memory of the process.
//!
//! After the timed steps the Delassus operator of the final state is rebuilt once and
//! analysed: how fast its 3×3 blocks decay with the distance between contact nodes (what a
//! cut-off would keep), the error a cut-off makes on the actual contact forces, and the cost
//! of one numeric factorisation and of one single-right-hand-side solve (the unit costs of
//! the alternatives to a dense W).
//!
//! Sizes too large to step within the time limit can be probed instead: the same case is set
//! up and factorised, K̄⁻¹Hᵀ and W are built for a subset of the contact nodes (the cost per
//! node is the same for every node), and Gauss-Seidel sweeps are timed on a dense W of the
//! full size. The per-node cost times the number of contact nodes is the projected Delassus
//! time of one Newton iteration.
//!
//! Each size runs in its own child process, so that peak memory is per size and an
//! out-of-memory kill or a time-out only loses that size.
//!
//! Run `cargo run --release --example bench_contact -- --help` for the options.

use adhesim::contact::detect::ContactPoint;
use adhesim::contact::discretisation::detect;
use adhesim::contact::history::PointHistory;
use adhesim::contact::solver::gauss_seidel::delassus::{delassus, Delassus};
use adhesim::contact::solver::gauss_seidel::sweep::gauss_seidel;
use adhesim::linalg::SparseCholesky;
use adhesim::problem::Problem;
use adhesim::time::{StepReport, Stepper};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Edge of the square pad [m].
const WIDTH: f64 = 0.01;
/// Height of the pad [m].
const HEIGHT: f64 = 0.002;
/// Blatz-Ko shear modulus [Pa].
const SHEAR_MODULUS: f64 = 1e6;
/// Density [kg/m³].
const DENSITY: f64 = 1000.0;
/// Relative block magnitudes at which the decay of W is reported.
const CUTOFFS: [f64; 4] = [1e-2, 1e-3, 1e-4, 1e-6];
/// Marker of the result line a child process prints.
const RESULT_TAG: &str = "BENCH_CONTACT_RESULT ";

const USAGE: &str = "\
bench_contact: time per step of a pad pressed on an adhesive, frictional rigid plane

Options:
  --sizes 9,31,70        elements per edge of the bottom face; (n+1)² contact nodes
                         (default 9,17,31,44,54)
  --probe-sizes 54,70    sizes whose unit costs are probed instead of stepped
                         (default 31,44,54,70; empty to skip)
  --probe-points N       contact nodes of the probed K̄⁻¹Hᵀ subset (default 128)
  --layers N             element layers through the height (default 4)
  --steps N              steps per repetition (default 3)
  --ramp-steps N         steps over which the top moves down (default: --steps)
  --reps N               repetitions per size, each from a fresh stepper (default 3)
  --budget S             start no further repetition of a size after S seconds
                         (default 300; the first always runs)
  --mode M               dynamic (θ = ξ = ½, default) or quasi-static
  --dt S                 time step [s] (default 1e-4)
  --press M              downward displacement of the top face over the ramp [m]
                         (default 2e-5)
  --timeout S            wall-time limit of one size [s] (default 1800)
  --memory-fraction F    skip a size whose estimated peak memory exceeds this fraction
                         of the available memory (default 0.85)
  --no-analysis          skip the analysis of W after the timed steps
  --results PATH         also write the report (markdown) to PATH
  --single N             run one size in this process and print its result line
  --probe N              probe one size in this process and print its result line
";

#[derive(Clone, Debug)]
struct Config {
    sizes: Vec<usize>,
    probe_sizes: Vec<usize>,
    probe_points: usize,
    layers: usize,
    steps: usize,
    ramp_steps: Option<usize>,
    reps: usize,
    budget: f64,
    quasi_static: bool,
    dt: f64,
    press: f64,
    timeout: f64,
    memory_fraction: f64,
    analysis: bool,
    results: Option<PathBuf>,
    single: Option<usize>,
    probe: Option<usize>,
}

fn fail(msg: &str) -> ! {
    eprintln!("bench_contact: {msg}\n\n{USAGE}");
    std::process::exit(2)
}

fn parse_args() -> Config {
    let mut cfg = Config {
        sizes: vec![9, 17, 31, 44, 54],
        probe_sizes: vec![31, 44, 54, 70],
        probe_points: 128,
        layers: 4,
        steps: 3,
        ramp_steps: None,
        reps: 3,
        budget: 300.0,
        quasi_static: false,
        dt: 1e-4,
        press: 2e-5,
        timeout: 1800.0,
        memory_fraction: 0.85,
        analysis: true,
        results: None,
        single: None,
        probe: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        match flag.as_str() {
            "-h" | "--help" => {
                print!("{USAGE}");
                std::process::exit(0);
            }
            "--no-analysis" => {
                cfg.analysis = false;
                continue;
            }
            _ => {}
        }
        let value = args
            .next()
            .unwrap_or_else(|| fail(&format!("{flag} needs a value")));
        let int = |v: &str| -> usize {
            v.trim()
                .parse()
                .unwrap_or_else(|_| fail(&format!("{flag}: not a whole number: {v}")))
        };
        let list = |v: &str| -> Vec<usize> {
            v.split(',')
                .filter(|x| !x.trim().is_empty())
                .map(int)
                .collect()
        };
        let real = |v: &str| -> f64 {
            match v.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 => x,
                _ => fail(&format!("{flag}: not a positive number: {v}")),
            }
        };
        match flag.as_str() {
            "--sizes" => cfg.sizes = list(&value),
            "--probe-sizes" => cfg.probe_sizes = list(&value),
            "--probe-points" => cfg.probe_points = int(&value).max(1),
            "--layers" => cfg.layers = int(&value).max(1),
            "--steps" => cfg.steps = int(&value).max(1),
            "--ramp-steps" => cfg.ramp_steps = Some(int(&value).max(1)),
            "--reps" => cfg.reps = int(&value).max(1),
            "--mode" => {
                cfg.quasi_static = match value.as_str() {
                    "dynamic" => false,
                    "quasi-static" => true,
                    other => fail(&format!("--mode: dynamic or quasi-static, not {other}")),
                }
            }
            "--dt" => cfg.dt = real(&value),
            "--press" => cfg.press = real(&value),
            "--timeout" => cfg.timeout = real(&value),
            "--budget" => cfg.budget = real(&value),
            "--memory-fraction" => cfg.memory_fraction = real(&value),
            "--results" => cfg.results = Some(PathBuf::from(value)),
            "--single" => cfg.single = Some(int(&value)),
            "--probe" => cfg.probe = Some(int(&value)),
            _ => fail(&format!("unknown option {flag}")),
        }
    }
    if cfg.sizes.iter().chain(&cfg.probe_sizes).any(|&n| n == 0) {
        fail("sizes must be at least 1");
    }
    cfg
}

/// The options a child process needs to reproduce the parent's case.
fn child_args(cfg: &Config, kind: Kind, n: usize) -> Vec<String> {
    let mut a = vec![
        match kind {
            Kind::Step => "--single".to_string(),
            Kind::Probe => "--probe".to_string(),
        },
        n.to_string(),
        "--probe-points".into(),
        cfg.probe_points.to_string(),
        "--layers".into(),
        cfg.layers.to_string(),
        "--steps".into(),
        cfg.steps.to_string(),
        "--ramp-steps".into(),
        ramp_steps(cfg).to_string(),
        "--reps".into(),
        cfg.reps.to_string(),
        "--budget".into(),
        format!("{:e}", cfg.budget),
        "--mode".into(),
        mode_name(cfg).into(),
        "--dt".into(),
        format!("{:e}", cfg.dt),
        "--press".into(),
        format!("{:e}", cfg.press),
    ];
    if !cfg.analysis {
        a.push("--no-analysis".into());
    }
    a
}

fn ramp_steps(cfg: &Config) -> usize {
    cfg.ramp_steps.unwrap_or(cfg.steps)
}

fn mode_name(cfg: &Config) -> &'static str {
    if cfg.quasi_static {
        "quasi-static"
    } else {
        "dynamic"
    }
}

/// The benchmark case as a scenario file.
fn scenario(cfg: &Config, n: usize) -> String {
    let ramp_end = ramp_steps(cfg) as f64 * cfg.dt;
    format!(
        r#"
name = "bench_contact"
[time]
t_end = 1.0
dt = {dt:e}
dt_min = {dt_min:e}
theta = 0.5
xi = 0.5
mode = "{mode}"
[[body]]
name = "pad"
mesh = {{ generator = "block", size = [{WIDTH:e}, {HEIGHT:e}, {WIDTH:e}], divisions = [{n}, {layers}, {n}] }}
material = {{ model = "blatz-ko", g = {SHEAR_MODULUS:e} }}
density = {DENSITY:e}
[[boundary]]
body = "pad"
set = "top"
fix = ["x", "z"]
displacement = {{ y = [[0.0, 0.0], [{ramp_end:e}, {press:e}]] }}
[[contact]]
name = "ground"
slave = {{ body = "pad", set = "bottom" }}
master = {{ rigid = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
friction = 0.3
adhesion = {{ w = 20.0, cn = 2e9, ct = 2e9, b = 0.1 }}
detection_distance = 1e-4
"#,
        dt = cfg.dt,
        dt_min = cfg.dt / 64.0,
        mode = mode_name(cfg),
        layers = cfg.layers,
        press = -cfg.press,
    )
}

/// One committed step.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct StepSample {
    rep: usize,
    step: usize,
    newton: usize,
    cutbacks: usize,
    sweeps: usize,
    points: usize,
    assembly: f64,
    factorisation: f64,
    delassus: f64,
    gauss_seidel: f64,
    wall: f64,
}

impl StepSample {
    fn new(rep: usize, r: &StepReport, wall: f64) -> Self {
        StepSample {
            rep,
            step: r.step,
            newton: r.newton_iterations,
            cutbacks: r.cutbacks,
            sweeps: r.contact_sweeps,
            points: r.contact_points,
            assembly: r.timings.assembly,
            factorisation: r.timings.factorisation,
            delassus: r.timings.delassus,
            gauss_seidel: r.timings.contact_solve,
            wall,
        }
    }

    /// Wall time outside the four timed phases (residual, updates, commit).
    fn other(&self) -> f64 {
        self.wall - self.assembly - self.factorisation - self.delassus - self.gauss_seidel
    }

    fn contact_share(&self) -> f64 {
        (self.delassus + self.gauss_seidel) / self.wall
    }
}

/// Decay of the off-diagonal blocks of W at one relative cut-off ε.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Cutoff {
    eps: f64,
    /// Fraction of the off-diagonal blocks with ‖W_pq‖ ≥ ε √(‖W_pp‖ ‖W_qq‖).
    kept_fraction: f64,
    /// Mean number of such blocks per contact node.
    kept_per_node: f64,
    /// Largest distance between two nodes whose block is kept, in element widths.
    radius_elements: f64,
    /// ‖(W − W_ε) r‖ / ‖W r‖ for the contact forces r of the final state.
    force_error: f64,
}

/// The Delassus operator of the final state, rebuilt once outside the stepper.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Analysis {
    /// Numeric factorisation of K̄ [s] (median).
    factorise: f64,
    /// One solve with one right-hand side [s] (median).
    solve_one: f64,
    /// One solve with 64 right-hand sides, per right-hand side [s] (median).
    solve_block: f64,
    /// K̄⁻¹Hᵀ for all contact nodes and W = H K̄⁻¹Hᵀ [s].
    delassus: f64,
    /// The same projected from a subset of the contact nodes, as a probe does [s].
    delassus_projected: f64,
    cutoffs: Vec<Cutoff>,
}

/// Everything measured for one mesh size.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct SizeResult {
    divisions: usize,
    layers: usize,
    dofs: usize,
    contact_nodes: usize,
    factor_nnz: usize,
    threads: usize,
    /// Stepper::new: discretisation, METIS ordering and symbolic analysis [s] (median).
    setup: f64,
    steps: Vec<StepSample>,
    peak_rss: u64,
    analysis: Option<Analysis>,
}

/// Unit costs of a size that is probed rather than stepped.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct ProbeResult {
    divisions: usize,
    layers: usize,
    dofs: usize,
    contact_nodes: usize,
    factor_nnz: usize,
    threads: usize,
    setup: f64,
    /// Numeric factorisation of K̄ at the reference state [s] (median).
    factorise: f64,
    /// One solve with one right-hand side [s] (median).
    solve_one: f64,
    /// One solve with 64 right-hand sides, per right-hand side [s] (median).
    solve_block: f64,
    /// Contact nodes of the subset.
    subset: usize,
    /// K̄⁻¹Hᵀ and W for the subset [s] (median).
    subset_delassus: f64,
    /// subset_delassus × contact_nodes / subset [s].
    delassus_projected: f64,
    /// One Gauss-Seidel sweep over all contact nodes with a dense W [s] (median).
    gs_sweep: f64,
    peak_rss: u64,
}

/// How a child process treats its size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Step,
    Probe,
}

/// What became of one size.
#[derive(Clone, Debug)]
enum Outcome {
    Done(Box<SizeResult>),
    Probed(Box<ProbeResult>),
    Skipped {
        kind: Kind,
        divisions: usize,
        reason: String,
    },
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// A field of /proc/self/status or /proc/meminfo in bytes (the files give kB).
fn proc_kb(file: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(file).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kb: u64 = line[key.len()..]
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

fn peak_rss() -> u64 {
    proc_kb("/proc/self/status", "VmHWM:").unwrap_or(0)
}

fn available_memory() -> Option<u64> {
    proc_kb("/proc/meminfo", "MemAvailable:")
}

/// Mesh dimensions of a size: (DOFs, contact nodes).
fn mesh_counts(cfg: &Config, n: usize) -> (usize, usize) {
    let nodes = (n + 1) * (n + 1) * (cfg.layers + 1);
    (3 * nodes, (n + 1) * (n + 1))
}

/// The dense arrays of one Delassus build: one chunk of K̄⁻¹Hᵀ (DOFs × 64 columns) and W
/// (3N_c × 3N_c) [bytes].
fn dense_bytes(dofs: usize, contact_nodes: usize) -> (u64, u64) {
    let m = 3 * contact_nodes as u64;
    (8 * dofs as u64 * m.min(64), 8 * m * m)
}

fn gb(bytes: u64) -> f64 {
    bytes as f64 / 1e9
}

fn main() {
    let cfg = parse_args();
    if let Some(n) = cfg.single {
        let result = run_size(&cfg, n);
        println!(
            "{RESULT_TAG}{}",
            serde_json::to_string(&result).expect("serialisable result")
        );
        return;
    }
    if let Some(n) = cfg.probe {
        let result = probe_size(&cfg, n);
        println!(
            "{RESULT_TAG}{}",
            serde_json::to_string(&result).expect("serialisable result")
        );
        return;
    }
    let started = Instant::now();
    let mut outcomes = Vec::new();
    let jobs = cfg
        .sizes
        .iter()
        .map(|&n| (Kind::Step, n))
        .chain(cfg.probe_sizes.iter().map(|&n| (Kind::Probe, n)));
    for (kind, n) in jobs {
        let outcome = run_child(&cfg, kind, n);
        match &outcome {
            Outcome::Done(r) => eprintln!(
                "size {n}: {} contact nodes, {} DOFs stepped",
                r.contact_nodes, r.dofs
            ),
            Outcome::Probed(r) => eprintln!(
                "size {n}: {} contact nodes, {} DOFs probed",
                r.contact_nodes, r.dofs
            ),
            Outcome::Skipped { reason, .. } => eprintln!("size {n}: {reason}"),
        }
        outcomes.push(outcome);
    }
    let text = report(&cfg, &outcomes, started.elapsed().as_secs_f64());
    print!("{text}");
    if let Some(path) = &cfg.results {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).ok();
        }
        std::fs::write(path, &text)
            .unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", path.display())));
    }
}

/// Runs one size in a child process, within the memory and time limits.
fn run_child(cfg: &Config, kind: Kind, n: usize) -> Outcome {
    let (dofs, nc) = mesh_counts(cfg, n);
    let (z, w) = dense_bytes(dofs, nc);
    // A probe holds W and K̄⁻¹Hᵀ of the subset only.
    let needed = match kind {
        Kind::Step => z + w,
        Kind::Probe => w + z * cfg.probe_points.min(nc) as u64 / nc.max(1) as u64,
    };
    if let Some(avail) = available_memory() {
        if needed as f64 > cfg.memory_fraction * avail as f64 {
            return Outcome::Skipped {
                kind,
                divisions: n,
                reason: format!(
                    "skipped: K̄⁻¹Hᵀ ({:.1} GB) and W ({:.1} GB) exceed {:.0} % of the {:.1} GB available",
                    gb(z),
                    gb(w),
                    100.0 * cfg.memory_fraction,
                    gb(avail)
                ),
            };
        }
    }
    let exe = std::env::current_exe().unwrap_or_else(|e| fail(&format!("no executable path: {e}")));
    let mut child = Command::new(exe)
        .args(child_args(cfg, kind, n))
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap_or_else(|e| fail(&format!("cannot start a child process: {e}")));
    let mut stdout = child.stdout.take().expect("piped stdout");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        stdout.read_to_string(&mut s).ok();
        s
    });
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if start.elapsed().as_secs_f64() > cfg.timeout => {
                child.kill().ok();
                child.wait().ok();
                break None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(200)),
            Err(e) => fail(&format!("waiting for the child: {e}")),
        }
    };
    let out = reader.join().unwrap_or_default();
    let parsed = BufReader::new(out.as_bytes())
        .lines()
        .map_while(Result::ok)
        .find_map(|l| {
            let json = l.strip_prefix(RESULT_TAG)?;
            match kind {
                Kind::Step => serde_json::from_str::<SizeResult>(json)
                    .ok()
                    .map(|r| Outcome::Done(Box::new(r))),
                Kind::Probe => serde_json::from_str::<ProbeResult>(json)
                    .ok()
                    .map(|r| Outcome::Probed(Box::new(r))),
            }
        });
    match (status, parsed) {
        (_, Some(outcome)) => outcome,
        (None, None) => Outcome::Skipped {
            kind,
            divisions: n,
            reason: format!("did not finish within {:.0} s", cfg.timeout),
        },
        (Some(status), None) => Outcome::Skipped {
            kind,
            divisions: n,
            reason: format!("the child process failed ({status}); out of memory?"),
        },
    }
}

/// Runs the timed steps of one size, then the analysis of W.
fn run_size(cfg: &Config, n: usize) -> SizeResult {
    let text = scenario(cfg, n);
    let problem = adhesim_io::scenario::parse(&text, Path::new("bench_contact.toml"))
        .unwrap_or_else(|e| fail(&format!("scenario: {e}")))
        .problem;
    let problem = Arc::new(problem);
    let mut setups = Vec::new();
    let mut steps = Vec::new();
    let mut last: Option<Stepper> = None;
    let started = Instant::now();
    for rep in 0..cfg.reps {
        if rep > 0 && started.elapsed().as_secs_f64() > cfg.budget {
            break;
        }
        // Free the previous stepper before building the next one.
        drop(last.take());
        let clock = Instant::now();
        let mut stepper =
            Stepper::new(problem.clone()).unwrap_or_else(|e| fail(&format!("setup: {e}")));
        setups.push(clock.elapsed().as_secs_f64());
        for _ in 0..cfg.steps {
            let clock = Instant::now();
            let report = stepper
                .step()
                .unwrap_or_else(|e| fail(&format!("size {n}: {e}")));
            let sample = StepSample::new(rep, &report, clock.elapsed().as_secs_f64());
            eprintln!(
                "  n = {n} rep {rep} step {}: {} Newton, {} sweeps, {:.3} s",
                sample.step, sample.newton, sample.sweeps, sample.wall
            );
            steps.push(sample);
        }
        last = Some(stepper);
    }
    let stepper = last.expect("at least one repetition");
    let mut chol = SparseCholesky::analyse(&stepper.disc.pattern, 0)
        .unwrap_or_else(|e| fail(&format!("analysis: {e}")));
    let analysis = cfg
        .analysis
        .then(|| analyse_delassus(&stepper, &mut chol, n, cfg.probe_points));
    SizeResult {
        divisions: n,
        layers: cfg.layers,
        dofs: stepper.disc.num_dofs(),
        contact_nodes: problem.contacts.iter().map(|c| c.slave_nodes.len()).sum(),
        factor_nnz: chol.factor_nnz(),
        threads: rayon::current_num_threads(),
        setup: median(setups),
        steps,
        peak_rss: peak_rss(),
        analysis,
    }
}

/// Unknowns held by a Dirichlet condition.
fn constrained_dofs(problem: &Problem, dofs: usize) -> Vec<bool> {
    let mut c = vec![false; dofs];
    for d in &problem.dirichlet {
        for &node in &d.nodes {
            for k in 0..3 {
                c[3 * node + k] |= d.components[k];
            }
        }
    }
    c
}

/// K̄ at the stepper's state, with the Dirichlet unknowns decoupled as the stepper does.
fn iteration_matrix(stepper: &Stepper, constrained: &[bool]) -> Vec<f64> {
    let problem = &stepper.problem;
    let ts = &problem.time;
    let dt = stepper.next_dt();
    let (c_stiff, c_mass) = if ts.quasi_static {
        (1.0, 0.0)
    } else {
        (ts.xi, 1.0 / (ts.theta * dt * dt))
    };
    let disc = &stepper.disc;
    let density: Vec<f64> = problem.bodies.iter().map(|b| b.density).collect();
    let mass = disc.mass(&density, ts.lumped_mass);
    let tangent = disc.assemble(&stepper.state.u, true).tangent;
    let p = &disc.pattern;
    let mut kbar: Vec<f64> = tangent
        .iter()
        .zip(&mass)
        .map(|(k, m)| c_stiff * k + c_mass * m)
        .collect();
    for j in 0..p.dim() {
        let column = p.col_ptr[j]..p.col_ptr[j + 1];
        for (k, &i) in kbar[column.clone()].iter_mut().zip(&p.row_idx[column]) {
            if i != j && (constrained[i] || constrained[j]) {
                *k = 0.0;
            }
        }
    }
    kbar
}

fn time_median(reps: usize, mut f: impl FnMut()) -> f64 {
    f();
    median(
        (0..reps)
            .map(|_| {
                let clock = Instant::now();
                f();
                clock.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

/// Contact force of each point at the stepper's committed state, in the point's frame [N].
fn committed_forces(stepper: &Stepper, points: &[ContactPoint]) -> Vec<[f64; 3]> {
    points
        .iter()
        .map(|pt| {
            let f = stepper.contact[pt.pair][pt.local].force;
            std::array::from_fn(|a| (0..3).map(|k| pt.frame[a][k] * f[k]).sum())
        })
        .collect()
}

/// Rebuilds W at the final state and measures its decay and the unit costs of a solve.
fn analyse_delassus(
    stepper: &Stepper,
    chol: &mut SparseCholesky,
    n: usize,
    probe: usize,
) -> Analysis {
    let problem = &stepper.problem;
    let dofs = stepper.disc.num_dofs();
    let constrained = constrained_dofs(problem, dofs);
    let kbar = iteration_matrix(stepper, &constrained);
    let factorise = time_median(3, || {
        chol.factorise(&kbar)
            .unwrap_or_else(|e| fail(&format!("factorisation: {e}")))
    });
    let (solve_one, solve_block) = solve_costs(chol, dofs);
    let points = step_points(stepper);
    let (_, delassus_projected) = subset_delassus(&points, chol, &constrained, probe);
    let clock = Instant::now();
    let del = delassus(&points, chol, &constrained);
    let delassus_time = clock.elapsed().as_secs_f64();
    let forces = committed_forces(stepper, &points);
    let element = WIDTH / n as f64;
    let cutoffs = block_decay(
        &del.w,
        del.m,
        &points,
        &stepper.disc.reference,
        &forces,
        element,
    );
    Analysis {
        factorise,
        solve_one,
        solve_block,
        delassus: delassus_time,
        delassus_projected,
        cutoffs,
    }
}

/// The contact candidates the next step of the stepper would use.
fn step_points(stepper: &Stepper) -> Vec<ContactPoint> {
    let t0 = stepper.state.t;
    detect(
        &stepper.problem.contacts,
        &stepper.disc.reference,
        &stepper.state.u,
        t0,
        t0 + stepper.next_dt(),
    )
}

/// Median time of one solve with one right-hand side, and per right-hand side of one solve
/// with 64 [s], with the current factorisation.
fn solve_costs(chol: &mut SparseCholesky, dofs: usize) -> (f64, f64) {
    let column = |c: usize| -> Vec<f64> {
        (0..dofs)
            .map(|i| (((i + 31 * c) * 7919) % 997) as f64 - 498.0)
            .collect()
    };
    let one = column(0);
    let block: Vec<f64> = (0..64).flat_map(column).collect();
    let solve_one = time_median(5, || {
        let mut x = one.clone();
        chol.solve_in_place(&mut x);
        std::hint::black_box(&x);
    });
    let solve_block = time_median(3, || {
        let mut x = block.clone();
        chol.solve_in_place(&mut x);
        std::hint::black_box(&x);
    }) / 64.0;
    (solve_one, solve_block)
}

/// Builds K̄⁻¹Hᵀ and W for the first `probe` contact points (median of two after a warm-up)
/// and returns the number of points used and the time projected to all the points [s].
fn subset_delassus(
    points: &[ContactPoint],
    chol: &mut SparseCholesky,
    constrained: &[bool],
    probe: usize,
) -> (usize, f64) {
    let k = points.len().min(probe);
    let t = time_median(2, || {
        let del = delassus(&points[..k], chol, constrained);
        std::hint::black_box(&del.w);
    });
    (k, t * points.len() as f64 / k as f64)
}

/// Unit costs of one size without stepping it: factorisation and solves at the reference
/// state, K̄⁻¹Hᵀ and W for a subset of the contact nodes, and Gauss-Seidel sweeps over all
/// contact nodes with a dense W of the full size.
fn probe_size(cfg: &Config, n: usize) -> ProbeResult {
    let text = scenario(cfg, n);
    let problem = adhesim_io::scenario::parse(&text, Path::new("bench_contact.toml"))
        .unwrap_or_else(|e| fail(&format!("scenario: {e}")))
        .problem;
    let problem = Arc::new(problem);
    let clock = Instant::now();
    let stepper = Stepper::new(problem.clone()).unwrap_or_else(|e| fail(&format!("setup: {e}")));
    let setup = clock.elapsed().as_secs_f64();
    let dofs = stepper.disc.num_dofs();
    let constrained = constrained_dofs(&problem, dofs);
    let kbar = iteration_matrix(&stepper, &constrained);
    let mut chol = SparseCholesky::analyse(&stepper.disc.pattern, 0)
        .unwrap_or_else(|e| fail(&format!("analysis: {e}")));
    let factorise = time_median(3, || {
        chol.factorise(&kbar)
            .unwrap_or_else(|e| fail(&format!("factorisation: {e}")))
    });
    let (solve_one, solve_block) = solve_costs(&mut chol, dofs);
    let points = step_points(&stepper);
    eprintln!(
        "  probe n = {n}: {dofs} DOFs, {} contact nodes, factorise {factorise:.3} s",
        points.len()
    );
    let (subset, delassus_projected) =
        subset_delassus(&points, &mut chol, &constrained, cfg.probe_points);
    let subset_delassus = delassus_projected * subset as f64 / points.len() as f64;
    eprintln!("  probe n = {n}: K̄⁻¹Hᵀ and W for {subset} nodes {subset_delassus:.3} s");
    let gs_sweep = probe_sweep(&stepper, &points, &mut chol, &constrained);
    ProbeResult {
        divisions: n,
        layers: cfg.layers,
        dofs,
        contact_nodes: points.len(),
        factor_nnz: chol.factor_nnz(),
        threads: rayon::current_num_threads(),
        setup,
        factorise,
        solve_one,
        solve_block,
        subset,
        subset_delassus,
        delassus_projected,
        gs_sweep,
        peak_rss: peak_rss(),
    }
}

/// Median time of one Gauss-Seidel sweep over all `points` with a dense W of the full size:
/// the diagonal blocks are the true one of the first point (every node of the uniform face
/// sees nearly the same), the couplings zero (a sweep reads every block all the same), and
/// every point is pressed into the plane.
fn probe_sweep(
    stepper: &Stepper,
    points: &[ContactPoint],
    chol: &mut SparseCholesky,
    constrained: &[bool],
) -> f64 {
    let np = points.len();
    let m = 3 * np;
    let one = delassus(&points[..1], chol, constrained);
    let mut w = vec![0.0; m * m];
    for p in 0..np {
        for a in 0..3 {
            for c in 0..3 {
                w[(3 * p + a) * m + 3 * p + c] = one.w[a * 3 + c];
            }
        }
    }
    let del = Delassus { w, m };
    let laws: Vec<_> = stepper
        .problem
        .contacts
        .iter()
        .map(|c| c.law.clone())
        .collect();
    let history0 = vec![PointHistory::default(); np];
    let x_free = vec![[0.0, 0.0, -1e-7]; np];
    let zero = vec![[0.0; 3]; np];
    let dt = stepper.next_dt();
    let mut per_sweep = Vec::new();
    for _ in 0..3 {
        let clock = Instant::now();
        // A negative tolerance never settles: exactly `max_sweeps` sweeps.
        let sol = gauss_seidel(
            points, &laws, &history0, dt, &del, &x_free, &zero, &zero, -1.0, 3,
        );
        per_sweep.push(clock.elapsed().as_secs_f64() / sol.sweeps as f64);
    }
    median(per_sweep)
}

/// Frobenius norm of the 3×3 block (p, q) of a row-major m × m matrix.
fn block_norm(w: &[f64], m: usize, p: usize, q: usize) -> f64 {
    let mut s = 0.0;
    for a in 0..3 {
        for c in 0..3 {
            s += w[(3 * p + a) * m + 3 * q + c].powi(2);
        }
    }
    s.sqrt()
}

/// For each cut-off ε: which off-diagonal blocks of W a cut-off keeps, how far they reach,
/// and the error of the truncated operator applied to the contact forces.
fn block_decay(
    w: &[f64],
    m: usize,
    points: &[ContactPoint],
    reference: &[[f64; 3]],
    forces: &[[f64; 3]],
    element: f64,
) -> Vec<Cutoff> {
    let np = points.len();
    let diag: Vec<f64> = (0..np).map(|p| block_norm(w, m, p, p)).collect();
    let mut exact = vec![0.0; m];
    let mut dropped = vec![vec![0.0; m]; CUTOFFS.len()];
    let mut kept = [0usize; CUTOFFS.len()];
    let mut radius = [0.0f64; CUTOFFS.len()];
    for p in 0..np {
        let xp = reference[points[p].slave];
        for q in 0..np {
            let mut wr = [0.0; 3];
            for (a, v) in wr.iter_mut().enumerate() {
                let row = &w[(3 * p + a) * m + 3 * q..(3 * p + a) * m + 3 * q + 3];
                *v = row[0] * forces[q][0] + row[1] * forces[q][1] + row[2] * forces[q][2];
            }
            for a in 0..3 {
                exact[3 * p + a] += wr[a];
            }
            if q == p {
                continue;
            }
            let rel = block_norm(w, m, p, q) / (diag[p] * diag[q]).sqrt();
            let xq = reference[points[q].slave];
            let dist = (0..3).map(|k| (xp[k] - xq[k]).powi(2)).sum::<f64>().sqrt() / element;
            for (i, &eps) in CUTOFFS.iter().enumerate() {
                if rel >= eps {
                    kept[i] += 1;
                    radius[i] = radius[i].max(dist);
                } else {
                    for a in 0..3 {
                        dropped[i][3 * p + a] += wr[a];
                    }
                }
            }
        }
    }
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let off_diagonal = (np * np.saturating_sub(1)).max(1) as f64;
    CUTOFFS
        .iter()
        .enumerate()
        .map(|(i, &eps)| Cutoff {
            eps,
            kept_fraction: kept[i] as f64 / off_diagonal,
            kept_per_node: kept[i] as f64 / np.max(1) as f64,
            radius_elements: radius[i],
            force_error: norm(&dropped[i]) / norm(&exact),
        })
        .collect()
}

/// Per-size medians used by the report.
struct Summary {
    newton: f64,
    sweeps: f64,
    assembly: f64,
    factorisation: f64,
    delassus: f64,
    gauss_seidel: f64,
    other: f64,
    wall: f64,
    share: f64,
    cutbacks: usize,
    /// Per Newton iteration [s].
    delassus_it: f64,
    gs_it: f64,
    factorisation_it: f64,
    assembly_it: f64,
    /// Per Gauss-Seidel sweep [s].
    gs_sweep: f64,
    /// Gauss-Seidel sweeps per Newton iteration.
    sweeps_it: f64,
}

fn summarise(r: &SizeResult) -> Summary {
    let s = &r.steps;
    let col = |f: &dyn Fn(&StepSample) -> f64| median(s.iter().map(f).collect());
    let per_newton = |f: &dyn Fn(&StepSample) -> f64| {
        median(
            s.iter()
                .filter(|x| x.newton > 0)
                .map(|x| f(x) / x.newton as f64)
                .collect(),
        )
    };
    Summary {
        newton: col(&|x| x.newton as f64),
        sweeps: col(&|x| x.sweeps as f64),
        assembly: col(&|x| x.assembly),
        factorisation: col(&|x| x.factorisation),
        delassus: col(&|x| x.delassus),
        gauss_seidel: col(&|x| x.gauss_seidel),
        other: col(&|x| x.other()),
        wall: col(&|x| x.wall),
        share: col(&|x| x.contact_share()),
        cutbacks: s.iter().map(|x| x.cutbacks).sum(),
        delassus_it: per_newton(&|x| x.delassus),
        gs_it: per_newton(&|x| x.gauss_seidel),
        factorisation_it: per_newton(&|x| x.factorisation),
        // Assembly runs once more than the corrections (the converged residual).
        assembly_it: median(
            s.iter()
                .map(|x| x.assembly / (x.newton + 1) as f64)
                .collect(),
        ),
        gs_sweep: median(
            s.iter()
                .filter(|x| x.sweeps > 0)
                .map(|x| x.gauss_seidel / x.sweeps as f64)
                .collect(),
        ),
        sweeps_it: per_newton(&|x| x.sweeps as f64),
    }
}

/// Least-squares slope of log y against log x.
fn loglog_slope(pts: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = pts
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let k = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / k;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / k;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

fn ms(s: f64) -> String {
    if !s.is_finite() {
        "–".into()
    } else if s >= 10.0 {
        format!("{s:.1} s")
    } else if s >= 1.0 {
        format!("{s:.2} s")
    } else {
        format!("{:.1} ms", s * 1e3)
    }
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

fn report(cfg: &Config, outcomes: &[Outcome], elapsed: f64) -> String {
    let mut o = String::new();
    let done: Vec<&SizeResult> = outcomes
        .iter()
        .filter_map(|x| match x {
            Outcome::Done(r) => Some(r.as_ref()),
            _ => None,
        })
        .collect();
    let probes: Vec<&ProbeResult> = outcomes
        .iter()
        .filter_map(|x| match x {
            Outcome::Probed(r) => Some(r.as_ref()),
            _ => None,
        })
        .collect();
    let sums: Vec<Summary> = done.iter().map(|r| summarise(r)).collect();
    let threads = done
        .first()
        .map(|r| r.threads)
        .or(probes.first().map(|r| r.threads))
        .unwrap_or(0);
    let _ = writeln!(o, "## bench_contact results\n");
    let _ = writeln!(
        o,
        "{} mode, Δt = {:e} s, pad {} × {} × {} m with {} element layers, top pressed {:e} m \
         over {} steps; per size up to {} repetitions of {} steps (none started after {:.0} s); \
         {} thread(s) on {}; load average at the end {}; total {:.0} s.\n",
        if cfg.quasi_static {
            "quasi-static"
        } else {
            "dynamic (θ = ξ = ½)"
        },
        cfg.dt,
        WIDTH,
        HEIGHT,
        WIDTH,
        cfg.layers,
        cfg.press,
        ramp_steps(cfg),
        cfg.reps,
        cfg.steps,
        cfg.budget,
        threads,
        cpu_model(),
        load_average(),
        elapsed
    );
    report_steps(&mut o, cfg, outcomes, &done, &sums);
    report_iterations(&mut o, &done, &sums);
    report_growth(&mut o, &done, &sums);
    report_structure(&mut o, &done);
    if !probes.is_empty() {
        report_probes(&mut o, &probes, &done, &sums);
    }
    report_raw(&mut o, &done);
    o
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

fn report_steps(
    o: &mut String,
    cfg: &Config,
    outcomes: &[Outcome],
    done: &[&SizeResult],
    sums: &[Summary],
) {
    let _ = writeln!(o, "### Median time per step\n");
    let _ = writeln!(
        o,
        "| contact nodes | mesh | DOFs | steps | Newton it. | GS sweeps | assembly | \
         factorisation | Delassus | Gauss-Seidel | other | step | contact share | peak memory |"
    );
    let _ = writeln!(
        o,
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for (r, s) in done.iter().zip(sums) {
        let _ = writeln!(
            o,
            "| {} | {}×{}×{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0} % | {:.2} GB |",
            r.contact_nodes,
            r.divisions,
            r.layers,
            r.divisions,
            r.dofs,
            r.steps.len(),
            s.newton,
            s.sweeps,
            ms(s.assembly),
            ms(s.factorisation),
            ms(s.delassus),
            ms(s.gauss_seidel),
            ms(s.other),
            ms(s.wall),
            100.0 * s.share,
            gb(r.peak_rss)
        );
    }
    for x in outcomes {
        if let Outcome::Skipped {
            kind,
            divisions,
            reason,
        } = x
        {
            let (dofs, nc) = mesh_counts(cfg, *divisions);
            let what = match kind {
                Kind::Step => "stepping",
                Kind::Probe => "probe",
            };
            let _ = writeln!(
                o,
                "| {nc} | {d}×{}×{d} | {dofs} | {what} {reason} |||||||||||",
                cfg.layers,
                d = divisions
            );
        }
    }
    let cut: usize = sums.iter().map(|s| s.cutbacks).sum();
    let _ = writeln!(
        o,
        "\nMedians are taken per column over all steps of all repetitions, so a row need not add \
         up. \"other\" is the step's wall time outside the four phases (residuals, the update \
         Δu += K̄⁻¹Hᵀ r, commit). Contact share = (Delassus + Gauss-Seidel) / step wall time. \
         Cut-backs: {cut}.\n"
    );
}

fn report_iterations(o: &mut String, done: &[&SizeResult], sums: &[Summary]) {
    let _ = writeln!(o, "### Per Newton iteration and per sweep\n");
    let _ = writeln!(
        o,
        "| contact nodes | nnz(L) | assembly | factorisation + solve | Delassus | Gauss-Seidel | \
         GS sweeps | one GS sweep | K̄⁻¹Hᵀ + W (dense) |"
    );
    let _ = writeln!(o, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (r, s) in done.iter().zip(sums) {
        let (z, w) = dense_bytes(r.dofs, r.contact_nodes);
        let _ = writeln!(
            o,
            "| {} | {:.2e} | {} | {} | {} | {} | {:.0} | {} | {:.2} + {:.2} GB |",
            r.contact_nodes,
            r.factor_nnz as f64,
            ms(s.assembly_it),
            ms(s.factorisation_it),
            ms(s.delassus_it),
            ms(s.gs_it),
            s.sweeps_it,
            ms(s.gs_sweep),
            gb(z),
            gb(w)
        );
    }
}

/// (N_c, value) of the stepped sizes.
fn series(done: &[&SizeResult], sums: &[Summary], f: fn(&Summary) -> f64) -> Vec<(f64, f64)> {
    done.iter()
        .zip(sums)
        .map(|(r, s)| (r.contact_nodes as f64, f(s)))
        .collect()
}

const FIT_FROM: f64 = 1000.0;

/// A per-size quantity of the report: its name and how to read it from a summary.
type Quantity = (&'static str, fn(&Summary) -> f64);

fn report_growth(o: &mut String, done: &[&SizeResult], sums: &[Summary]) {
    let _ = writeln!(o, "\n### Growth with the number of contact nodes N_c\n");
    let phases: [Quantity; 6] = [
        ("assembly / iteration", |s| s.assembly_it),
        ("factorisation / iteration", |s| s.factorisation_it),
        ("Delassus / iteration", |s| s.delassus_it),
        ("Gauss-Seidel / iteration", |s| s.gs_it),
        ("GS sweeps / iteration", |s| s.sweeps_it),
        ("one GS sweep", |s| s.gs_sweep),
    ];
    let _ = writeln!(
        o,
        "Least-squares exponent p of t ∝ N_c^p over all stepped sizes, over the sizes with \
         N_c ≥ {FIT_FROM}, and between the two largest:\n"
    );
    let _ = writeln!(
        o,
        "| quantity | p (all) | p (N_c ≥ {FIT_FROM}) | p (two largest) |"
    );
    let _ = writeln!(o, "|---|---:|---:|---:|");
    let fmt = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.2}"));
    for (name, f) in phases {
        let all = series(done, sums, f);
        let large: Vec<(f64, f64)> = all.iter().copied().filter(|p| p.0 >= FIT_FROM).collect();
        let last = &all[all.len().saturating_sub(2)..];
        let _ = writeln!(
            o,
            "| {name} | {} | {} | {} |",
            fmt(loglog_slope(&all)),
            fmt(loglog_slope(&large)),
            fmt(loglog_slope(last))
        );
    }
}

fn report_structure(o: &mut String, done: &[&SizeResult]) {
    let analysed: Vec<(&SizeResult, &Analysis)> = done
        .iter()
        .filter_map(|r| r.analysis.as_ref().map(|a| (*r, a)))
        .collect();
    if analysed.is_empty() {
        return;
    }
    let _ = writeln!(
        o,
        "\n### Unit costs and structure of W at the final state\n"
    );
    let _ = writeln!(
        o,
        "With K̄ of the final state (medians): one numeric factorisation, one solve with one \
         right-hand side, the cost per right-hand side of one solve with 64, and K̄⁻¹Hᵀ + W as \
         built and as projected from a subset of the contact nodes.\n"
    );
    let _ = writeln!(
        o,
        "| contact nodes | factorise | one solve | per RHS in 64 | Delassus | projected |"
    );
    let _ = writeln!(o, "|---:|---:|---:|---:|---:|---:|");
    for (r, a) in &analysed {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} |",
            r.contact_nodes,
            ms(a.factorise),
            ms(a.solve_one),
            ms(a.solve_block),
            ms(a.delassus),
            ms(a.delassus_projected)
        );
    }
    let _ = writeln!(
        o,
        "\nDecay of W: share of the off-diagonal 3×3 blocks with ‖W_pq‖ ≥ ε √(‖W_pp‖ ‖W_qq‖), \
         kept blocks per node, farthest kept block (element widths), and the error \
         ‖(W − W_ε) r‖ / ‖W r‖ of the truncated operator on the committed contact forces r.\n"
    );
    let _ = writeln!(
        o,
        "| contact nodes | ε | kept | per node | radius | error |"
    );
    let _ = writeln!(o, "|---:|---:|---:|---:|---:|---:|");
    for (r, a) in &analysed {
        for (i, c) in a.cutoffs.iter().enumerate() {
            let head = if i == 0 {
                r.contact_nodes.to_string()
            } else {
                String::new()
            };
            let _ = writeln!(
                o,
                "| {head} | {:.0e} | {:.1} % | {:.0} | {:.1} | {:.1e} |",
                c.eps,
                100.0 * c.kept_fraction,
                c.kept_per_node,
                c.radius_elements,
                c.force_error
            );
        }
    }
}

/// y(x) from the least-squares power law through `pts` (the sizes with N_c ≥ FIT_FROM when
/// there are two, else all).
fn power_law_at(pts: &[(f64, f64)], x: f64) -> f64 {
    let large: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 >= FIT_FROM).collect();
    let use_pts = if large.len() >= 2 {
        large
    } else {
        pts.to_vec()
    };
    let Some(p) = loglog_slope(&use_pts) else {
        return f64::NAN;
    };
    let k = use_pts.len() as f64;
    let mx = use_pts.iter().map(|q| q.0.ln()).sum::<f64>() / k;
    let my = use_pts.iter().map(|q| q.1.ln()).sum::<f64>() / k;
    (my + p * (x.ln() - mx)).exp()
}

fn report_probes(o: &mut String, probes: &[&ProbeResult], done: &[&SizeResult], sums: &[Summary]) {
    let _ = writeln!(o, "\n### Probed sizes (unit costs)\n");
    let _ = writeln!(
        o,
        "Factorisation and solves at the reference state; K̄⁻¹Hᵀ + W built for a subset of the \
         contact nodes and projected linearly to all of them (each node costs three solves); one \
         Gauss-Seidel sweep over all nodes with a dense W of the full size.\n"
    );
    let _ = writeln!(
        o,
        "| contact nodes | DOFs | nnz(L) | factorise | one solve | per RHS in 64 | subset | \
         subset time | Delassus / iteration | one GS sweep | K̄⁻¹Hᵀ + W (dense) | probe peak memory |"
    );
    let _ = writeln!(
        o,
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for p in probes {
        let (z, w) = dense_bytes(p.dofs, p.contact_nodes);
        let _ = writeln!(
            o,
            "| {} | {} | {:.2e} | {} | {} | {} | {} | {} | {} | {} | {:.2} + {:.2} GB | {:.2} GB |",
            p.contact_nodes,
            p.dofs,
            p.factor_nnz as f64,
            ms(p.factorise),
            ms(p.solve_one),
            ms(p.solve_block),
            p.subset,
            ms(p.subset_delassus),
            ms(p.delassus_projected),
            ms(p.gs_sweep),
            gb(z),
            gb(w),
            gb(p.peak_rss)
        );
    }
    // The projection needs a power law of the sweeps, so at least two stepped sizes.
    let (Some(big), Some(big_sum)) = (done.last(), sums.last()) else {
        return;
    };
    if done.len() < 2 {
        return;
    }
    let sweeps = series(done, sums, |s| s.sweeps_it);
    let _ = writeln!(o, "\n### Projected time per step at the probed sizes\n");
    let _ = writeln!(
        o,
        "Newton iterations per step as at the largest stepped size ({}); assembly per iteration \
         scaled from it in proportion to the DOFs; factorisation per iteration = factorise + one \
         solve; GS sweeps per iteration from the power law of the stepped sizes. Contact share \
         = (Delassus + GS) / (sum of the four phases).\n",
        big_sum.newton
    );
    let _ = writeln!(
        o,
        "| contact nodes | Newton it. | GS sweeps / it. | assembly | factorisation | Delassus | \
         Gauss-Seidel | step | contact share |"
    );
    let _ = writeln!(o, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for p in probes {
        let newton = big_sum.newton;
        let sweeps_it = power_law_at(&sweeps, p.contact_nodes as f64);
        let assembly = big_sum.assembly_it * p.dofs as f64 / big.dofs as f64 * (newton + 1.0);
        let factorisation = (p.factorise + p.solve_one) * newton;
        let delassus = p.delassus_projected * newton;
        let gs = p.gs_sweep * sweeps_it * newton;
        let step = assembly + factorisation + delassus + gs;
        let _ = writeln!(
            o,
            "| {} | {} | {:.0} | {} | {} | {} | {} | {} | {:.0} % |",
            p.contact_nodes,
            newton,
            sweeps_it,
            ms(assembly),
            ms(factorisation),
            ms(delassus),
            ms(gs),
            ms(step),
            100.0 * (delassus + gs) / step
        );
    }
}

fn report_raw(o: &mut String, done: &[&SizeResult]) {
    let _ = writeln!(o, "\n### Raw steps\n");
    let _ = writeln!(
        o,
        "| contact nodes | rep | step | Newton | cut-backs | sweeps | assembly | factorisation | \
         Delassus | Gauss-Seidel | wall |"
    );
    let _ = writeln!(
        o,
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in done {
        for x in &r.steps {
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                r.contact_nodes,
                x.rep,
                x.step,
                x.newton,
                x.cutbacks,
                x.sweeps,
                ms(x.assembly),
                ms(x.factorisation),
                ms(x.delassus),
                ms(x.gauss_seidel),
                ms(x.wall)
            );
        }
    }
}
