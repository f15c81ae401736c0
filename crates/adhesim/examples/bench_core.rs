//! Performance benchmark of the solver core on Blatz-Ko hex meshes of the unit cube:
//!
//! 1. assembly throughput (element tangent + residual + scatter) on 1 and 2 threads, and a
//!    microbenchmark of one hex8 element response;
//! 2. METIS ordering, faer symbolic analysis and faer numeric Cholesky factorisation of
//!    K̄ = K + M/Δt² on 1 and 2 threads;
//! 3. optionally, the numeric factorisation of the very same matrix by SuiteSparse CHOLMOD
//!    (through the driver in bench/cholmod, run as a server so that faer and CHOLMOD
//!    factorisations alternate), with its own METIS ordering and with the elimination
//!    order used by faer;
//! 4. Newton iterations per step of a dynamic compression of a 20³ block.
//!
//! Every timing is repeated (after one warm-up run, which is kept as a sample when it
//! is long) and reported as a median.
//!
//! Run `cargo run --release --example bench_core -- --help` for the options, or
//! `bench/run.sh` for the complete comparison with CHOLMOD.

use adhesim::assembly::Discretisation;
use adhesim::element::{element_response, hex8_geometry};
use adhesim::linalg::{metis_dof_ordering, BlockPattern, SparseCholesky};
use adhesim::material::{BlatzKo, Hyperelastic};
use adhesim::mesh::generate;
use adhesim::problem::{Body, Dirichlet, Problem, Table, TimeSettings};
use adhesim::time::Stepper;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::SymbolicSparseColMat;
use faer::Side;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::hint::black_box;
use std::io::Write as _;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Small-strain shear modulus of the Blatz-Ko material [Pa].
const SHEAR_MODULUS: f64 = 1e6;
/// Density used for the mass matrix [kg/m³].
const DENSITY: f64 = 1000.0;
/// Time step of K̄ = K + M/Δt² [s].
const MATRIX_DT: f64 = 1e-3;

const USAGE: &str = "\
bench_core: performance benchmark of adhesim's assembly and sparse Cholesky

Options:
  --sizes 20,30,40          cube meshes n³ to measure (default 20,30,40)
  --reps N                  timed repetitions per measurement, after one warm-up (default 5)
  --threads 1,2             thread counts (default 1,2)
  --cholmod PATH            CHOLMOD driver (bench/cholmod/cholmod_bench); omit to skip
  --cholmod-orderings LIST  orderings given to the driver (default metis,given)
  --cholmod-modes LIST      CHOLMOD modes (default supernodal,simplicial)
  --given-max-size N        CHOLMOD with faer's elimination order only up to N³ (default 20)
  --simplicial-max-gflop X  skip CHOLMOD simplicial above this many GFlop (default 2)
  --data-dir DIR            where matrices are exported (default: a temporary directory)
  --keep-data               keep the exported matrices
  --micro-iters N           element calls per microbenchmark repetition (default 20000)
  --dynamic-size N          mesh of the dynamic case (default 20; 0 skips it)
  --dynamic-steps N         steps of the dynamic case (default 20)
  --dense N                 diagnostic: dense N×N Cholesky and product, faer vs the
                            driver's BLAS/LAPACK (default 0 = skipped)
  --faer-relax              diagnostic: faer numeric factorisation (1 thread) with more
                            aggressive supernode amalgamation, for sizes ≤ --relax-max-size
  --relax-max-size N        (default 30)
  --results PATH            also write the report (markdown) to PATH
";

struct Config {
    sizes: Vec<usize>,
    reps: usize,
    threads: Vec<usize>,
    cholmod: Option<PathBuf>,
    cholmod_orderings: String,
    cholmod_modes: String,
    given_max_size: usize,
    simplicial_max_gflop: f64,
    data_dir: PathBuf,
    keep_data: bool,
    micro_iters: usize,
    dynamic_size: usize,
    dynamic_steps: usize,
    dense: usize,
    faer_relax: bool,
    relax_max_size: usize,
    results: Option<PathBuf>,
}

fn parse_list(s: &str) -> Vec<usize> {
    s.split(',')
        .map(|x| {
            x.trim()
                .parse()
                .unwrap_or_else(|_| usage_error(&format!("not a number: {x}")))
        })
        .collect()
}

fn usage_error(msg: &str) -> ! {
    eprintln!("bench_core: {msg}\n\n{USAGE}");
    std::process::exit(2)
}

fn fail(msg: &str) -> ! {
    eprintln!("bench_core: {msg}");
    std::process::exit(1)
}

fn parse_args() -> Config {
    let mut c = Config {
        sizes: vec![20, 30, 40],
        reps: 5,
        threads: vec![1, 2],
        cholmod: None,
        cholmod_orderings: "metis,given".into(),
        cholmod_modes: "supernodal,simplicial".into(),
        given_max_size: 20,
        simplicial_max_gflop: 2.0,
        data_dir: std::env::temp_dir().join("adhesim-bench"),
        keep_data: false,
        micro_iters: 20_000,
        dynamic_size: 20,
        dynamic_steps: 20,
        dense: 0,
        faer_relax: false,
        relax_max_size: 30,
        results: None,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let flag = args[i].as_str();
        if flag == "--help" || flag == "-h" {
            print!("{USAGE}");
            std::process::exit(0);
        }
        if flag == "--keep-data" || flag == "--faer-relax" {
            c.keep_data |= flag == "--keep-data";
            c.faer_relax |= flag == "--faer-relax";
            i += 1;
            continue;
        }
        if !USAGE.contains(&format!("  {flag} ")) {
            usage_error(&format!("unknown option {flag}"));
        }
        let value = args
            .get(i + 1)
            .unwrap_or_else(|| usage_error(&format!("{flag} needs a value")))
            .clone();
        let number = |v: &str| -> usize {
            v.parse()
                .unwrap_or_else(|_| usage_error(&format!("{flag}: not a number: {v}")))
        };
        match flag {
            "--sizes" => c.sizes = parse_list(&value),
            "--reps" => c.reps = number(&value).max(1),
            "--threads" => c.threads = parse_list(&value),
            "--cholmod" => c.cholmod = Some(PathBuf::from(value)),
            "--cholmod-orderings" => c.cholmod_orderings = value,
            "--cholmod-modes" => c.cholmod_modes = value,
            "--given-max-size" => c.given_max_size = number(&value),
            "--simplicial-max-gflop" => {
                c.simplicial_max_gflop = value
                    .parse()
                    .unwrap_or_else(|_| usage_error("--simplicial-max-gflop: not a number"))
            }
            "--data-dir" => c.data_dir = PathBuf::from(value),
            "--micro-iters" => c.micro_iters = number(&value).max(1),
            "--dynamic-size" => c.dynamic_size = number(&value),
            "--dynamic-steps" => c.dynamic_steps = number(&value).max(1),
            "--results" => c.results = Some(PathBuf::from(value)),
            "--dense" => c.dense = number(&value),
            "--relax-max-size" => c.relax_max_size = number(&value),
            _ => usage_error(&format!("unknown option {flag}")),
        }
        i += 2;
    }
    if c.threads.contains(&0) {
        usage_error("thread counts must be at least 1");
    }
    c
}

/// Repeated timings [s] of one measurement.
#[derive(Clone, Debug, Default)]
struct Samples(Vec<f64>);

impl Samples {
    fn sorted(&self) -> Vec<f64> {
        let mut v = self.0.clone();
        v.sort_by(f64::total_cmp);
        v
    }
    fn median(&self) -> f64 {
        let v = self.sorted();
        let n = v.len();
        if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
    fn min(&self) -> f64 {
        self.sorted().first().copied().unwrap_or(f64::NAN)
    }
    fn max(&self) -> f64 {
        self.sorted().last().copied().unwrap_or(f64::NAN)
    }
}

/// A run at least this long [s] needs no separate warm-up: it is kept as the first sample.
const LONG_RUN: f64 = 2.0;

/// One warm-up call, then `reps` timed calls; when the warm-up takes longer than
/// [`LONG_RUN`], it counts as the first of the `reps` samples.
fn time_reps(reps: usize, mut f: impl FnMut()) -> Samples {
    let mut timed = || {
        let t0 = Instant::now();
        f();
        t0.elapsed().as_secs_f64()
    };
    let first = timed();
    let mut samples = Vec::with_capacity(reps);
    if first > LONG_RUN {
        samples.push(first);
    }
    while samples.len() < reps {
        samples.push(timed());
    }
    Samples(samples)
}

fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

/// Smooth displacement field: 5 % stretch along x with lateral contraction, shears of
/// 1–3 %, and a bubble so that no two elements see the same deformation.
fn displacement(x: [f64; 3]) -> [f64; 3] {
    let s = (PI * x[0]).sin() * (PI * x[1]).sin() * (PI * x[2]).sin();
    [
        0.05 * x[0] + 0.03 * x[1] + 0.01 * s,
        -0.0125 * x[1] + 0.02 * x[2] + 0.005 * s,
        0.01 * x[0] - 0.0125 * x[2] - 0.008 * s,
    ]
}

fn material() -> Arc<dyn Hyperelastic> {
    Arc::new(BlatzKo::new(SHEAR_MODULUS))
}

// ---------------------------------------------------------------------------------------
// Measurements
// ---------------------------------------------------------------------------------------

struct AssemblyResult {
    threads: usize,
    with_tangent: Samples,
    force_only: Samples,
    kernels_only: Samples,
}

struct FactorStats {
    supernodal: bool,
    supernodes: usize,
    largest_supernode: usize,
    stored: usize,
    flops: f64,
}

struct NumericResult {
    threads: usize,
    factorise: Samples,
    solve_error: f64,
}

#[derive(Default)]
struct CholmodRun {
    info: BTreeMap<String, String>,
    results: Vec<BTreeMap<String, String>>,
    notes: Vec<String>,
    auto_modes: Vec<BTreeMap<String, String>>,
}

impl CholmodRun {
    fn find(
        &self,
        ordering: &str,
        mode: &str,
        threads: usize,
    ) -> Option<&BTreeMap<String, String>> {
        self.results.iter().find(|r| {
            r.get("ordering").map(String::as_str) == Some(ordering)
                && r.get("mode").map(String::as_str) == Some(mode)
                && r.get("threads").and_then(|t| t.parse().ok()) == Some(threads)
        })
    }
    fn any(&self, ordering: &str, mode: &str) -> Option<&BTreeMap<String, String>> {
        self.results.iter().find(|r| {
            r.get("ordering").map(String::as_str) == Some(ordering)
                && r.get("mode").map(String::as_str) == Some(mode)
        })
    }
}

struct SizeResult {
    n: usize,
    elements: usize,
    dofs: usize,
    nnz: usize,
    min_j: f64,
    assembly: Vec<AssemblyResult>,
    metis: Samples,
    symbolic: Samples,
    analyse: Samples,
    stats: FactorStats,
    numeric: Vec<NumericResult>,
    relax: Vec<RelaxResult>,
    cholmod: Option<CholmodRun>,
}

fn factor_stats(s: &SymbolicCholesky<usize>) -> FactorStats {
    match s.raw() {
        SymbolicCholeskyRaw::Supernodal(sn) => {
            let begin = sn.supernode_begin();
            let end = sn.supernode_end();
            let val_ptr = sn.col_ptr_for_val();
            let mut flops = 0.0;
            let mut largest = 0;
            for k in 0..sn.n_supernodes() {
                let ncols = end[k] - begin[k];
                let nrows = (val_ptr[k + 1] - val_ptr[k]) / ncols;
                largest = largest.max(ncols);
                for j in 0..ncols {
                    let c = (nrows - j) as f64;
                    flops += c * c;
                }
            }
            FactorStats {
                supernodal: true,
                supernodes: sn.n_supernodes(),
                largest_supernode: largest,
                stored: sn.len_val(),
                flops,
            }
        }
        SymbolicCholeskyRaw::Simplicial(sp) => {
            let cp = sp.col_ptr();
            let flops = cp.windows(2).map(|w| ((w[1] - w[0]) as f64).powi(2)).sum();
            FactorStats {
                supernodal: false,
                supernodes: 0,
                largest_supernode: 0,
                stored: sp.len_val(),
                flops,
            }
        }
    }
}

fn symbolic_with(
    sym: &SymbolicSparseColMat<usize>,
    fwd: &[usize],
    inv: &[usize],
) -> SymbolicCholesky<usize> {
    symbolic_relaxed(sym, fwd, inv, None)
}

/// faer's symbolic analysis with the given elimination order and, if given, supernode
/// relaxation thresholds in place of faer's defaults.
fn symbolic_relaxed(
    sym: &SymbolicSparseColMat<usize>,
    fwd: &[usize],
    inv: &[usize],
    relax: Option<&[(usize, f64)]>,
) -> SymbolicCholesky<usize> {
    let n = sym.nrows();
    let perm = PermRef::new_checked(fwd, inv, n);
    let mut params = CholeskySymbolicParams::default();
    if let Some(r) = relax {
        params.supernodal_params =
            faer::sparse::linalg::SymbolicSupernodalParams { relax: Some(r) };
    }
    factorize_symbolic_cholesky(
        sym.as_ref(),
        Side::Upper,
        SymmetricOrdering::Custom(perm),
        params,
    )
    .expect("symbolic factorisation")
}

/// Supernode relaxation variants (columns, tolerated fraction of zeros), faer's default
/// first.
const RELAX_VARIANTS: [(&str, &[(usize, f64)]); 3] = [
    (
        "faer default",
        &[(4, 1.0), (16, 0.8), (48, 0.1), (usize::MAX, 0.05)],
    ),
    (
        "×2 columns",
        &[(8, 1.0), (32, 0.8), (96, 0.1), (usize::MAX, 0.05)],
    ),
    (
        "×4 columns",
        &[(16, 1.0), (64, 0.8), (192, 0.1), (usize::MAX, 0.05)],
    ),
];

struct RelaxResult {
    variant: &'static str,
    stats: FactorStats,
    factorise: Samples,
}

/// faer's numeric factorisation on 1 thread, called directly, for each relaxation variant.
fn bench_relax(
    sym: &SymbolicSparseColMat<usize>,
    fwd: &[usize],
    inv: &[usize],
    values: &[f64],
    reps: usize,
) -> Vec<RelaxResult> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::llt::factor::LltRegularization;
    use faer::sparse::SparseColMatRef;
    RELAX_VARIANTS
        .iter()
        .map(|&(variant, relax)| {
            let symbolic = symbolic_relaxed(sym, fwd, inv, Some(relax));
            let mut l = vec![0.0; symbolic.len_val()];
            let mut mem = MemBuffer::new(
                symbolic.factorize_numeric_llt_scratch::<f64>(faer::Par::Seq, Default::default()),
            );
            let a = SparseColMatRef::new(sym.as_ref(), values);
            let factorise = time_reps(reps, || {
                symbolic
                    .factorize_numeric_llt(
                        &mut l,
                        a,
                        Side::Upper,
                        LltRegularization::default(),
                        faer::Par::Seq,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .expect("SPD");
            });
            RelaxResult {
                variant,
                stats: factor_stats(&symbolic),
                factorise,
            }
        })
        .collect()
}

/// Writes the upper-triangle CSC matrix and an elimination order in the ADHKBAR1 format
/// read by bench/cholmod/cholmod_bench.
fn export_matrix(
    path: &Path,
    p: &BlockPattern,
    values: &[f64],
    perm: &[usize],
) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    w.write_all(b"ADHKBAR1")?;
    for h in [p.dim() as u64, p.nnz() as u64, 1] {
        w.write_all(&h.to_le_bytes())?;
    }
    for &x in p.col_ptr.iter().chain(&p.row_idx) {
        w.write_all(&(x as u64).to_le_bytes())?;
    }
    for &v in values {
        w.write_all(&v.to_le_bytes())?;
    }
    for &x in perm {
        w.write_all(&(x as u64).to_le_bytes())?;
    }
    w.flush()
}

/// Splits `kind key=value key="quoted value" ...` into the kind and its fields.
fn parse_driver_line(line: &str) -> Option<(String, BTreeMap<String, String>)> {
    let mut chars = line.trim().chars().peekable();
    let kind: String = chars.by_ref().take_while(|c| !c.is_whitespace()).collect();
    if kind.is_empty() {
        return None;
    }
    let mut fields = BTreeMap::new();
    loop {
        while chars.peek().is_some_and(|c| c.is_whitespace()) {
            chars.next();
        }
        let key: String = chars.by_ref().take_while(|&c| c != '=').collect();
        if key.is_empty() {
            break;
        }
        let value: String = if chars.peek() == Some(&'"') {
            chars.next();
            chars.by_ref().take_while(|&c| c != '"').collect()
        } else {
            chars.by_ref().take_while(|c| !c.is_whitespace()).collect()
        };
        fields.insert(key.trim().to_string(), value);
    }
    Some((kind, fields))
}

/// Pause before every timed factorisation, so that the BLAS threads of the other process
/// (OpenBLAS workers spin for about 0.1 s after a call) and rayon's workers are asleep.
const PAUSE: Duration = Duration::from_millis(200);

/// The CHOLMOD driver running in `--serve` mode: it has analysed the matrix once per
/// configuration and performs single numeric factorisations on request.
struct Driver {
    child: Child,
    input: ChildStdin,
    output: BufReader<ChildStdout>,
    configs: Vec<BTreeMap<String, String>>,
    blas_threads: bool,
    run: CholmodRun,
}

impl Driver {
    fn start(cfg: &Config, driver: &Path, matrix: &Path, n: usize) -> Driver {
        let orderings: Vec<&str> = cfg
            .cholmod_orderings
            .split(',')
            .filter(|o| *o != "given" || n <= cfg.given_max_size)
            .collect();
        let mut child = Command::new(driver)
            .arg(matrix)
            .arg("--serve")
            .args(["--orderings", &orderings.join(",")])
            .args(["--modes", &cfg.cholmod_modes])
            .args([
                "--simplicial-max-gflop",
                &cfg.simplicial_max_gflop.to_string(),
            ])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| fail(&format!("cannot run {}: {e}", driver.display())));
        let input = child.stdin.take().expect("piped stdin");
        let output = BufReader::new(child.stdout.take().expect("piped stdout"));
        let mut d = Driver {
            child,
            input,
            output,
            configs: Vec::new(),
            blas_threads: false,
            run: CholmodRun::default(),
        };
        loop {
            let line = d.read_line();
            if line.trim() == "ready" {
                break;
            }
            match parse_driver_line(&line) {
                Some((kind, fields)) if kind == "info" => {
                    d.blas_threads = fields.get("blas_threads").map(String::as_str) == Some("1");
                    d.run.info = fields;
                }
                Some((kind, fields)) if kind == "config" => d.configs.push(fields),
                Some((kind, fields)) if kind == "note" && fields.contains_key("auto_mode") => {
                    d.run.auto_modes.push(fields)
                }
                Some(_) => d.run.notes.push(line.trim().to_string()),
                None => {}
            }
        }
        d
    }

    fn read_line(&mut self) -> String {
        let mut line = String::new();
        match self.output.read_line(&mut line) {
            Ok(n) if n > 0 => line,
            _ => fail("the CHOLMOD driver stopped unexpectedly"),
        }
    }

    fn request(&mut self, line: &str) -> BTreeMap<String, String> {
        writeln!(self.input, "{line}")
            .and_then(|_| self.input.flush())
            .unwrap_or_else(|e| fail(&format!("cannot talk to the CHOLMOD driver: {e}")));
        let reply = self.read_line();
        match parse_driver_line(&reply) {
            Some((kind, fields)) if kind != "error" => fields,
            _ => fail(&format!("CHOLMOD driver: {}", reply.trim())),
        }
    }

    /// One timed numeric factorisation of configuration `id` [s].
    fn factorise(&mut self, id: usize, threads: usize) -> f64 {
        let reply = self.request(&format!("factorize {id} {threads}"));
        field(&reply, "s").unwrap_or_else(|| fail("CHOLMOD driver: no time in reply"))
    }

    /// Configurations to time on `threads` threads (simplicial ones on the first thread
    /// count only: they do not use the BLAS).
    fn ids_for(&self, threads: usize, first: bool) -> Vec<usize> {
        if threads > 1 && !self.blas_threads {
            return Vec::new();
        }
        (0..self.configs.len())
            .filter(|&k| {
                first || self.configs[k].get("mode").map(String::as_str) == Some("supernodal")
            })
            .collect()
    }

    fn finish(mut self) -> CholmodRun {
        let _ = writeln!(self.input, "quit");
        drop(self.input);
        let _ = self.child.wait();
        self.run
    }
}

/// The element kernels of a full assembly (gather + element response with tangent) without
/// the scatter into the global arrays; returns the summed energy.
fn kernels_only(disc: &Discretisation, u: &[f64]) -> f64 {
    let hexes = disc.hexes();
    (0..hexes.len())
        .into_par_iter()
        .with_min_len(64)
        .map(|e| {
            let en = &hexes.nodes[e];
            let ue: [[f64; 3]; 8] =
                std::array::from_fn(|a| std::array::from_fn(|k| u[3 * en[a] + k]));
            let mat = &*disc.materials[hexes.body[e]];
            let r = element_response(&hexes.gauss[e], &ue, mat, true);
            black_box(&r.tangent);
            r.energy
        })
        .sum()
}

fn bench_size(cfg: &Config, n: usize) -> SizeResult {
    let progress = |what: &str| eprintln!("[{n}³] {what}");
    let mesh = generate::block([1.0; 3], [n; 3]);
    let disc = Discretisation::new(&[(&mesh, material())]).expect("valid mesh");
    let u: Vec<f64> = disc
        .reference
        .iter()
        .flat_map(|&x| displacement(x))
        .collect();
    let pattern = &disc.pattern;

    progress("assembly");
    let mut assembly = Vec::new();
    let mut reference = None;
    for &t in &cfg.threads {
        let (with_tangent, force_only, kernels, asm) = with_threads(t, || {
            let with_tangent = time_reps(cfg.reps, || {
                black_box(disc.assemble(black_box(&u), true));
            });
            let force_only = time_reps(cfg.reps, || {
                black_box(disc.assemble(black_box(&u), false));
            });
            let kernels = time_reps(cfg.reps, || {
                black_box(kernels_only(&disc, black_box(&u)));
            });
            (with_tangent, force_only, kernels, disc.assemble(&u, true))
        });
        assembly.push(AssemblyResult {
            threads: t,
            with_tangent,
            force_only,
            kernels_only: kernels,
        });
        reference.get_or_insert(asm);
    }
    let asm = reference.expect("at least one thread count");
    let mass = disc.mass(&[DENSITY], false);
    let kbar: Vec<f64> = asm
        .tangent
        .iter()
        .zip(&mass)
        .map(|(k, m)| k + m / (MATRIX_DT * MATRIX_DT))
        .collect();

    progress("METIS ordering and faer symbolic analysis");
    let dim = pattern.dim();
    let metis = time_reps(cfg.reps, || {
        black_box(metis_dof_ordering(pattern).expect("METIS"));
    });
    let sym = pattern.symbolic();
    let (fwd, inv) = metis_dof_ordering(pattern).expect("METIS");
    let symbolic_samples = time_reps(cfg.reps, || {
        black_box(symbolic_with(&sym, &fwd, &inv));
    });
    let symbolic = symbolic_with(&sym, &fwd, &inv);
    let stats = factor_stats(&symbolic);
    let elimination_order: Vec<usize> = match symbolic.perm() {
        Some(p) => p.arrays().0.to_vec(),
        None => fwd.clone(),
    };
    drop(symbolic);
    let analyse = with_threads(1, || {
        time_reps(cfg.reps, || {
            black_box(SparseCholesky::analyse(pattern, 1).expect("analyse"));
        })
    });

    let mut ones_image = vec![0.0; dim];
    pattern.symmetric_matvec(&kbar, &vec![1.0; dim], &mut ones_image);
    let mut driver = cfg.cholmod.as_ref().map(|path| {
        progress("CHOLMOD analysis");
        let file = cfg.data_dir.join(format!("kbar_{n}.bin"));
        export_matrix(&file, pattern, &kbar, &elimination_order)
            .unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", file.display())));
        let d = Driver::start(cfg, path, &file, n);
        if !cfg.keep_data {
            let _ = std::fs::remove_file(&file);
        }
        d
    });

    let mut numeric = Vec::new();
    let mut cholmod_results = Vec::new();
    for (ti, &t) in cfg.threads.iter().enumerate() {
        let ids = driver
            .as_ref()
            .map_or(Vec::new(), |d| d.ids_for(t, ti == 0));
        progress(&format!(
            "numeric factorisation, {t} thread(s): faer{}",
            if ids.is_empty() {
                ""
            } else {
                " and CHOLMOD, alternating"
            }
        ));
        let (result, samples) = with_threads(t, || {
            let mut chol = SparseCholesky::analyse(pattern, t).expect("analyse");
            assert_eq!(chol.factor_nnz(), stats.stored, "same symbolic structure");
            let mut faer_run = || {
                std::thread::sleep(PAUSE);
                let t0 = Instant::now();
                chol.factorise(&kbar).expect("SPD");
                t0.elapsed().as_secs_f64()
            };
            let mut cholmod_run = |id: usize| {
                std::thread::sleep(PAUSE);
                driver.as_mut().expect("driver").factorise(id, t)
            };
            // Warm-up runs, kept as samples when long; then one run of each in turn.
            let keep = |first: f64| {
                if first > LONG_RUN {
                    vec![first]
                } else {
                    Vec::new()
                }
            };
            let mut faer = keep(faer_run());
            let mut cholmod: Vec<Vec<f64>> = ids.iter().map(|&id| keep(cholmod_run(id))).collect();
            while faer.len() < cfg.reps || cholmod.iter().any(|v| v.len() < cfg.reps) {
                if faer.len() < cfg.reps {
                    faer.push(faer_run());
                }
                for (k, &id) in ids.iter().enumerate() {
                    if cholmod[k].len() < cfg.reps {
                        cholmod[k].push(cholmod_run(id));
                    }
                }
            }
            let mut x = ones_image.clone();
            chol.solve_in_place(&mut x);
            let solve_error = x.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
            (
                NumericResult {
                    threads: t,
                    factorise: Samples(faer),
                    solve_error,
                },
                cholmod,
            )
        });
        numeric.push(result);
        if let Some(d) = driver.as_mut() {
            for (&id, v) in ids.iter().zip(samples) {
                let v = Samples(v);
                let check = d.request(&format!("check {id}"));
                let mut r = d.configs[id].clone();
                r.insert("threads".into(), t.to_string());
                r.insert("median_s".into(), format!("{:.6}", v.median()));
                r.insert("min_s".into(), format!("{:.6}", v.min()));
                r.insert("max_s".into(), format!("{:.6}", v.max()));
                r.insert(
                    "max_err".into(),
                    check.get("max_err").cloned().unwrap_or_default(),
                );
                cholmod_results.push(r);
            }
        }
    }
    let cholmod = driver.map(|d| {
        let mut run = d.finish();
        run.results = cholmod_results;
        run
    });

    let relax = if cfg.faer_relax && n <= cfg.relax_max_size {
        progress("faer supernode relaxation variants, 1 thread");
        with_threads(1, || bench_relax(&sym, &fwd, &inv, &kbar, cfg.reps))
    } else {
        Vec::new()
    };

    SizeResult {
        n,
        elements: disc.hexes().len(),
        dofs: dim,
        nnz: pattern.nnz(),
        min_j: asm.min_j,
        assembly,
        metis,
        symbolic: symbolic_samples,
        analyse,
        stats,
        numeric,
        relax,
        cholmod,
    }
}

/// Dense SPD test matrix shared with the CHOLMOD driver: a_ij = ((7i + 13j) mod 17)/17 for
/// i ≠ j (symmetrised through min/max), a_ii = n.
fn dense_spd(n: usize) -> faer::Mat<f64> {
    faer::Mat::from_fn(n, n, |i, j| {
        if i == j {
            n as f64
        } else {
            let (a, b) = (i.min(j), i.max(j));
            ((7 * a + 13 * b) % 17) as f64 / 17.0
        }
    })
}

struct DenseResult {
    threads: usize,
    cholesky: Samples,
    product: Samples,
}

/// faer's dense Cholesky (the kernel of the large supernodes) and matrix product.
fn bench_dense(n: usize, threads: usize, reps: usize) -> DenseResult {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::llt::factor::{
        cholesky_in_place, cholesky_in_place_scratch, LltRegularization,
    };
    let par = if threads == 1 {
        faer::Par::Seq
    } else {
        faer::Par::rayon(threads)
    };
    with_threads(threads, || {
        let a = dense_spd(n);
        let mut work = a.clone();
        let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(n, par, Default::default()));
        let mut cholesky = Vec::new();
        for rep in 0..=reps {
            work.copy_from(&a);
            let t0 = Instant::now();
            cholesky_in_place(
                work.as_mut(),
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .expect("SPD");
            if rep > 0 {
                cholesky.push(t0.elapsed().as_secs_f64());
            }
        }
        let mut c = faer::Mat::<f64>::zeros(n, n);
        let product = time_reps(reps, || {
            faer::linalg::matmul::matmul(
                c.as_mut(),
                faer::Accum::Replace,
                a.as_ref(),
                work.as_ref(),
                1.0,
                par,
            );
            black_box(&c);
        });
        DenseResult {
            threads,
            cholesky: Samples(cholesky),
            product,
        }
    })
}

fn run_driver_dense(cfg: &Config, driver: &Path) -> Vec<BTreeMap<String, String>> {
    let threads: Vec<String> = cfg.threads.iter().map(|t| t.to_string()).collect();
    let output = Command::new(driver)
        .args(["--dense", &cfg.dense.to_string()])
        .args(["--reps", &cfg.reps.to_string()])
        .args(["--threads", &threads.join(",")])
        .output()
        .unwrap_or_else(|e| fail(&format!("cannot run {}: {e}", driver.display())));
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(parse_driver_line)
        .filter(|(kind, _)| kind == "dense")
        .map(|(_, f)| f)
        .collect()
}

struct MicroResult {
    with_tangent: Samples,
    force_only: Samples,
    iters: usize,
}

fn bench_element(cfg: &Config) -> MicroResult {
    let h = 0.05;
    let origin = [0.4, 0.45, 0.5];
    let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
        let xi = adhesim::element::HEX_NODE_XI[a];
        std::array::from_fn(|k| origin[k] + 0.5 * h * (xi[k] + 1.0))
    });
    let gps = hex8_geometry(&x).expect("valid element");
    let ue: [[f64; 3]; 8] = std::array::from_fn(|a| displacement(x[a]));
    let mat = BlatzKo::new(SHEAR_MODULUS);
    let iters = cfg.micro_iters;
    let run = |with_tangent: bool| {
        with_threads(1, || {
            time_reps(cfg.reps, || {
                for _ in 0..iters {
                    let r = element_response(
                        black_box(&gps),
                        black_box(&ue),
                        black_box(&mat as &dyn Hyperelastic),
                        with_tangent,
                    );
                    black_box(r);
                }
            })
        })
    };
    MicroResult {
        with_tangent: run(true),
        force_only: run(false),
        iters,
    }
}

struct DynamicResult {
    n: usize,
    threads: usize,
    iterations: Vec<usize>,
    cutbacks: usize,
    wall: f64,
    t_end: f64,
}

/// A Blatz-Ko block, bottom face fixed, top face pushed down by 10 % of the height at
/// constant speed over `steps` steps (θ = ξ = ½, consistent mass).
fn bench_dynamic(n: usize, steps: usize, threads: usize) -> DynamicResult {
    let mesh = generate::block([1.0; 3], [n; 3]);
    let t_end = 0.2;
    let zero = || {
        [
            Table::constant(0.0),
            Table::constant(0.0),
            Table::constant(0.0),
        ]
    };
    let push = Table {
        t: vec![0.0, t_end],
        v: vec![0.0, -0.1],
    };
    let problem = Problem {
        name: "bench_dynamic".into(),
        bodies: vec![Body {
            name: "block".into(),
            mesh: mesh.clone(),
            material: material(),
            density: DENSITY,
            initial_velocity: [0.0; 3],
            element: Default::default(),
            plane_strain: false,
        }],
        dirichlet: vec![
            Dirichlet {
                nodes: mesh.node_sets["bottom"].clone(),
                components: [true; 3],
                translation: zero(),
                rotation: None,
            },
            Dirichlet {
                nodes: mesh.node_sets["top"].clone(),
                components: [true; 3],
                translation: [Table::constant(0.0), push, Table::constant(0.0)],
                rotation: None,
            },
        ],
        loads: vec![],
        gravity: Default::default(),
        time: TimeSettings {
            t_end,
            dt: t_end / steps as f64,
            theta: 0.5,
            xi: 0.5,
            ..TimeSettings::default()
        },
        contacts: vec![],
    };
    with_threads(threads, || {
        let t0 = Instant::now();
        let mut stepper = Stepper::new(Arc::new(problem)).expect("set-up");
        let mut iterations = Vec::new();
        let mut cutbacks = 0;
        while !stepper.finished() {
            let r = stepper.step().expect("step");
            iterations.push(r.newton_iterations);
            cutbacks += r.cutbacks;
        }
        DynamicResult {
            n,
            threads,
            iterations,
            cutbacks,
            wall: t0.elapsed().as_secs_f64(),
            t_end,
        }
    })
}

// ---------------------------------------------------------------------------------------
// Report
// ---------------------------------------------------------------------------------------

fn field(r: &BTreeMap<String, String>, key: &str) -> Option<f64> {
    r.get(key).and_then(|v| v.parse().ok())
}

fn opt(v: Option<f64>, fmt: impl Fn(f64) -> String) -> String {
    v.map(fmt).unwrap_or_else(|| "—".into())
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

fn report(
    cfg: &Config,
    load: (&str, &str),
    sizes: &[SizeResult],
    micro: &MicroResult,
    dense: &(Vec<DenseResult>, Vec<BTreeMap<String, String>>),
    dynamic: Option<&DynamicResult>,
) -> String {
    let mut s = String::new();
    let cores = std::thread::available_parallelism().map_or(0, |c| c.get());
    let _ = writeln!(s, "# adhesim core benchmark\n");
    let _ = writeln!(
        s,
        "Blatz-Ko (G = {SHEAR_MODULUS:.0e} Pa) hex8 meshes of the unit cube, displacement = 5 % \
         stretch + shear + bubble. {cores} logical CPUs ({}). Medians of {} timed runs after one \
         warm-up (runs longer than {LONG_RUN} s: the first run is kept as a sample instead).",
        cpu_model(),
        cfg.reps
    );
    let _ = writeln!(
        s,
        "Load average (1, 5, 15 min) at the start: {}; at the end: {}.",
        load.0, load.1
    );
    if let Some(info) = sizes
        .iter()
        .find_map(|r| r.cholmod.as_ref().map(|c| &c.info))
    {
        let _ = writeln!(
            s,
            "CHOLMOD {} with {}.",
            info.get("cholmod").map_or("?", String::as_str),
            info.get("blas").map_or("?", String::as_str)
        );
    }

    let _ = writeln!(
        s,
        "\n## 1. Assembly (element tangent + residual + scatter)\n"
    );
    let _ = writeln!(
        s,
        "| mesh | elements | dofs | nnz(K) upper | threads | assemble K+f [ms] | µs/element/core | \
         element kernels only, µs/element/core | f only [ms] | µs/element/core (f only) |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in sizes {
        for a in &r.assembly {
            let per = |t: f64| t * a.threads as f64 / r.elements as f64 * 1e6;
            let _ = writeln!(
                s,
                "| {n}³ | {} | {} | {} | {} | {:.1} | {:.2} | {:.2} | {:.1} | {:.2} |",
                r.elements,
                r.dofs,
                r.nnz,
                a.threads,
                a.with_tangent.median() * 1e3,
                per(a.with_tangent.median()),
                per(a.kernels_only.median()),
                a.force_only.median() * 1e3,
                per(a.force_only.median()),
                n = r.n,
            );
        }
    }
    let _ = writeln!(
        s,
        "\nOne hex8 `element_response` (Blatz-Ko, 8 Gauss points), 1 thread, {} calls per run: \
         **{:.2} µs** with tangent, {:.2} µs force only (target < 10 µs).",
        micro.iters,
        micro.with_tangent.median() / micro.iters as f64 * 1e6,
        micro.force_only.median() / micro.iters as f64 * 1e6
    );

    let _ = writeln!(
        s,
        "\n## 2. Symbolic analysis of K̄ = K + M/Δt² (Δt = {MATRIX_DT:e} s, ρ = {DENSITY} kg/m³)\n"
    );
    let _ = writeln!(
        s,
        "| mesh | dofs | METIS (node graph) [ms] | faer symbolic [ms] | `analyse` total [ms] | \
         supernodes | largest supernode | L entries (faer) | Σc² flops (faer) | CHOLMOD analyse, METIS [ms] | L entries (CHOLMOD METIS) | Σc² flops (CHOLMOD METIS) |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in sizes {
        let cm = r
            .cholmod
            .as_ref()
            .and_then(|c| c.any("metis", "supernodal"));
        let _ = writeln!(
            s,
            "| {}³ | {} | {:.0} | {:.0} | {:.0} | {} | {} | {:.3e} | {:.3e} | {} | {} | {} |",
            r.n,
            r.dofs,
            r.metis.median() * 1e3,
            r.symbolic.median() * 1e3,
            r.analyse.median() * 1e3,
            if r.stats.supernodal {
                r.stats.supernodes.to_string()
            } else {
                "simplicial".into()
            },
            r.stats.largest_supernode,
            r.stats.stored as f64,
            r.stats.flops,
            opt(cm.and_then(|c| field(c, "analyse_s")), |v| format!(
                "{:.0}",
                v * 1e3
            )),
            opt(cm.and_then(|c| field(c, "stored")), |v| format!("{v:.3e}")),
            opt(cm.and_then(|c| field(c, "stored_flops")), |v| format!(
                "{v:.3e}"
            )),
        );
    }

    let _ = writeln!(s, "\n## 3. Numeric factorisation of K̄: faer vs CHOLMOD\n");
    let _ = writeln!(
        s,
        "faer: `SparseCholesky::factorise` (adhesim's METIS node ordering). CHOLMOD (METIS): \
         its own METIS ordering of the scalar graph. CHOLMOD (same order): the elimination \
         order faer uses, given to CHOLMOD. Ratio = faer / CHOLMOD (target ≤ 1.3). The faer and \
         CHOLMOD runs alternate (one of each in turn, {} ms apart) so that both see the same \
         machine load.\n",
        PAUSE.as_millis()
    );
    let _ = writeln!(
        s,
        "| mesh | threads | faer [s] | faer GFlop/s | CHOLMOD METIS, supernodal [s] | faer / CHOLMOD | \
         CHOLMOD same order, supernodal [s] | faer / CHOLMOD (same order) | CHOLMOD METIS, simplicial [s] |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in sizes {
        for num in &r.numeric {
            let t = num.threads;
            let faer = num.factorise.median();
            let c = r.cholmod.as_ref();
            let cm = c
                .and_then(|c| c.find("metis", "supernodal", t))
                .and_then(|x| field(x, "median_s"));
            let cg = c
                .and_then(|c| c.find("given", "supernodal", t))
                .and_then(|x| field(x, "median_s"));
            let cs = c
                .and_then(|c| c.find("metis", "simplicial", t))
                .and_then(|x| field(x, "median_s"));
            let _ = writeln!(
                s,
                "| {}³ | {} | {:.3} | {:.1} | {} | {} | {} | {} | {} |",
                r.n,
                t,
                faer,
                r.stats.flops / faer * 1e-9,
                opt(cm, |v| format!("{v:.3}")),
                opt(cm, |v| format!("**{:.2}**", faer / v)),
                opt(cg, |v| format!("{v:.3}")),
                opt(cg, |v| format!("{:.2}", faer / v)),
                opt(cs, |v| format!("{v:.3}")),
            );
        }
    }

    let auto: Vec<String> = sizes
        .iter()
        .filter_map(|r| {
            let a = r.cholmod.as_ref()?.auto_modes.first()?;
            Some(format!(
                "{}³: {} (flops/nnz(L) = {})",
                r.n,
                a.get("auto_mode").map_or("?", String::as_str),
                a.get("flops_per_lnz").map_or("?", String::as_str)
            ))
        })
        .collect();
    if !auto.is_empty() {
        let _ = writeln!(
            s,
            "\nMode chosen by CHOLMOD's default (CHOLMOD_AUTO, supernodal when flops/nnz(L) ≥ 40) \
             with the METIS ordering: {}. The simplicial factorisation does not use the BLAS and \
             is timed on 1 thread only, and only below the flop limit.",
            auto.join("; ")
        );
    }

    if let Some(d) = dynamic {
        let n_steps = d.iterations.len();
        let total: usize = d.iterations.iter().sum();
        let _ = writeln!(s, "\n## 4. Newton iterations on a dynamic case\n");
        let _ = writeln!(
            s,
            "{n}³ Blatz-Ko block (ρ = {DENSITY} kg/m³), bottom fixed, top pushed down by 10 % over \
             {t_end} s in {n_steps} steps, θ = ξ = ½, Newton tolerance {tol:e}, {th} thread(s).\n",
            n = d.n,
            t_end = d.t_end,
            tol = TimeSettings::default().newton_tol,
            th = d.threads
        );
        let _ = writeln!(s, "| steps | Newton iterations (mean) | (max) | total | cut-backs | wall time [s] | per step [s] |");
        let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|---:|");
        let _ = writeln!(
            s,
            "| {} | {:.2} | {} | {} | {} | {:.2} | {:.3} |",
            n_steps,
            total as f64 / n_steps.max(1) as f64,
            d.iterations.iter().max().copied().unwrap_or(0),
            total,
            d.cutbacks,
            d.wall,
            d.wall / n_steps.max(1) as f64
        );
        let _ = writeln!(s, "\nIterations per step: {:?}", d.iterations);
    }

    if sizes.iter().any(|r| !r.relax.is_empty()) {
        let _ = writeln!(
            s,
            "\n## faer supernode amalgamation (diagnostic, 1 thread, faer called directly)\n"
        );
        let _ = writeln!(
            s,
            "| mesh | relaxation | supernodes | L entries | Σc² flops | numeric [s] | GFlop/s |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|");
        for r in sizes {
            for v in &r.relax {
                let t = v.factorise.median();
                let _ = writeln!(
                    s,
                    "| {}³ | {} | {} | {:.3e} | {:.3e} | {:.3} | {:.1} |",
                    r.n,
                    v.variant,
                    v.stats.supernodes,
                    v.stats.stored as f64,
                    v.stats.flops,
                    t,
                    v.stats.flops / t * 1e-9
                );
            }
        }
    }

    if !dense.0.is_empty() {
        let n = cfg.dense as f64;
        let (chol_flops, prod_flops) = (n * n * n / 3.0, 2.0 * n * n * n);
        let _ = writeln!(
            s,
            "\n## Dense kernels (diagnostic): {0}×{0} Cholesky and product, GFlop/s\n",
            cfg.dense
        );
        let _ = writeln!(
            s,
            "| threads | faer Cholesky | BLAS dpotrf | faer product | BLAS dgemm |"
        );
        let _ = writeln!(s, "|---:|---:|---:|---:|---:|");
        for d in &dense.0 {
            let blas = dense
                .1
                .iter()
                .find(|r| r.get("threads").and_then(|t| t.parse().ok()) == Some(d.threads));
            let rate = |key: &str, flops: f64| {
                opt(blas.and_then(|r| field(r, key)), |t| {
                    format!("{:.1}", flops / t * 1e-9)
                })
            };
            let _ = writeln!(
                s,
                "| {} | {:.1} | {} | {:.1} | {} |",
                d.threads,
                chol_flops / d.cholesky.median() * 1e-9,
                rate("potrf_median_s", chol_flops),
                prod_flops / d.product.median() * 1e-9,
                rate("gemm_median_s", prod_flops),
            );
        }
    }

    let _ = writeln!(s, "\n## Raw samples [s]\n");
    let fmt = |v: &Samples| {
        format!(
            "median {:.4}, min {:.4}, max {:.4}",
            v.median(),
            v.min(),
            v.max()
        )
    };
    for r in sizes {
        let _ = writeln!(s, "- {}³: min det F = {:.4}", r.n, r.min_j);
        for a in &r.assembly {
            let _ = writeln!(
                s,
                "  - assemble K+f, {} thread(s): {}",
                a.threads,
                fmt(&a.with_tangent)
            );
            let _ = writeln!(
                s,
                "  - assemble f, {} thread(s): {}",
                a.threads,
                fmt(&a.force_only)
            );
            let _ = writeln!(
                s,
                "  - element kernels only, {} thread(s): {}",
                a.threads,
                fmt(&a.kernels_only)
            );
        }
        let _ = writeln!(s, "  - METIS: {}", fmt(&r.metis));
        let _ = writeln!(s, "  - faer symbolic: {}", fmt(&r.symbolic));
        let _ = writeln!(s, "  - analyse: {}", fmt(&r.analyse));
        for num in &r.numeric {
            let _ = writeln!(
                s,
                "  - faer factorise, {} thread(s): {}; solve max error {:.1e}",
                num.threads,
                fmt(&num.factorise),
                num.solve_error
            );
        }
        if let Some(c) = &r.cholmod {
            for x in &c.results {
                let g = |k: &str| x.get(k).map_or("?", String::as_str);
                let _ = writeln!(
                    s,
                    "  - CHOLMOD {} {}, {} thread(s): median {}, min {}, max {}; analyse {} s; \
                     lnz {}, supernodes {}, solve max error {}",
                    g("ordering"),
                    g("mode"),
                    g("threads"),
                    g("median_s"),
                    g("min_s"),
                    g("max_s"),
                    g("analyse_s"),
                    g("lnz"),
                    g("nsuper"),
                    g("max_err")
                );
            }
            for note in &c.notes {
                let _ = writeln!(s, "  - CHOLMOD: `{note}`");
            }
        }
    }
    let _ = writeln!(
        s,
        "- element_response with tangent: {} per {} calls",
        fmt(&micro.with_tangent),
        micro.iters
    );
    s
}

fn main() {
    let cfg = parse_args();
    let started = Instant::now();
    let load_start = load_average();
    eprintln!("element microbenchmark");
    let micro = bench_element(&cfg);
    let sizes: Vec<SizeResult> = cfg.sizes.iter().map(|&n| bench_size(&cfg, n)).collect();
    let dynamic = (cfg.dynamic_size > 0).then(|| {
        let threads = cfg.threads.iter().copied().max().unwrap_or(1);
        eprintln!("dynamic case {}³, {} thread(s)", cfg.dynamic_size, threads);
        bench_dynamic(cfg.dynamic_size, cfg.dynamic_steps, threads)
    });
    let dense = if cfg.dense > 0 {
        eprintln!("dense kernels {}×{}", cfg.dense, cfg.dense);
        let faer: Vec<DenseResult> = cfg
            .threads
            .iter()
            .map(|&t| bench_dense(cfg.dense, t, cfg.reps))
            .collect();
        let blas = cfg
            .cholmod
            .as_ref()
            .map(|d| run_driver_dense(&cfg, d))
            .unwrap_or_default();
        (faer, blas)
    } else {
        (Vec::new(), Vec::new())
    };
    let load_end = load_average();
    let text = report(
        &cfg,
        (&load_start, &load_end),
        &sizes,
        &micro,
        &dense,
        dynamic.as_ref(),
    );
    print!("{text}");
    eprintln!(
        "total benchmark time {:.0} s",
        started.elapsed().as_secs_f64()
    );
    if let Some(path) = &cfg.results {
        std::fs::write(path, &text)
            .unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", path.display())));
        eprintln!("report written to {}", path.display());
    }
}
