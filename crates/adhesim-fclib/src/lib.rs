//! fclib frictional contact problems for adhesim's contact solvers.
//!
//! fclib (the format of the Siconos project's contact test data) stores discrete 3D frictional
//! contact problems in HDF5:
//! - local: u = W r + q, r ∈ K_μ, û = u + μ‖u_T‖N ∈ K*_μ (group `/fclib_local`);
//! - global: M v = H r + f, u = Hᵀ v + w, same cone conditions (group `/fclib_global`);
//! - optionally a stored solution (`/solution`) and initial guesses (`/guesses`).
//!
//! Contact components there are ordered (N, T1, T2), the normal first; adhesim orders them
//! (t1, t2, n). Both take r_N ≥ 0 as compression and u_N ≥ 0 as separation, so converting is a
//! permutation of the components of every contact ([`to_adhesim`], [`from_adhesim`]), done at
//! the boundary by [`ReducedProblem::from_local`] and [`ReducedProblem::condense`].
//!
//! [`read`] needs the HDF5 C library; this crate is kept out of the main library and command
//! for that reason.

use std::path::{Path, PathBuf};

use adhesim::contact::solver::reduced::{BlockSparseDelassus, ReducedSolution};
use nalgebra::DMatrix;

/// A failure to read an fclib file: the file, the dataset and what went wrong.
#[derive(Debug, thiserror::Error)]
pub enum FclibError {
    /// The HDF5 library failed on a dataset or group.
    #[error("{file}: {what}: {source}")]
    Hdf5 {
        file: PathBuf,
        what: String,
        source: hdf5_metno::Error,
    },
    /// The content is not a valid fclib problem.
    #[error("{file}: {what}")]
    Invalid { file: PathBuf, what: String },
}

/// How a sparse matrix was stored in the file (fclib's `nz` field).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// `nz = -1`: compressed columns (`p` has n + 1 column starts, `i` the row indices).
    CompressedColumns,
    /// `nz = -2`: compressed rows (`p` has m + 1 row starts, `i` the column indices).
    CompressedRows,
    /// `nz ≥ 0`: `nz` triplets (`i` rows, `p` columns), repeated entries summed.
    Triplets,
}

/// A sparse matrix read from a file, as (row, column, value) entries.
#[derive(Clone, Debug)]
pub struct SparseMatrix {
    pub rows: usize,
    pub cols: usize,
    /// The storage kind found in the file.
    pub storage: Storage,
    /// Entries in file order; repeated (row, column) pairs are to be summed.
    pub entries: Vec<(usize, usize, f64)>,
}

impl SparseMatrix {
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.entries.len()
    }

    /// The matrix as a dense nalgebra matrix (repeated entries summed).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(self.rows, self.cols);
        for &(i, j, v) in &self.entries {
            a[(i, j)] += v;
        }
        a
    }

    /// Whether every entry lies on the diagonal.
    pub fn is_diagonal(&self) -> bool {
        self.entries.iter().all(|&(i, j, _)| i == j)
    }
}

/// A local problem u = W r + q in fclib's (N, T1, T2) order.
#[derive(Clone, Debug)]
pub struct LocalProblem {
    pub w: SparseMatrix,
    pub q: Vec<f64>,
    pub mu: Vec<f64>,
}

/// A global problem M v = H r + f, u = Hᵀ v + w in fclib's (N, T1, T2) order.
#[derive(Clone, Debug)]
pub struct GlobalProblem {
    pub m: SparseMatrix,
    pub h: SparseMatrix,
    pub f: Vec<f64>,
    pub w: Vec<f64>,
    pub mu: Vec<f64>,
}

/// Either kind of problem.
#[derive(Clone, Debug)]
pub enum Problem {
    Local(LocalProblem),
    Global(GlobalProblem),
}

/// A solution or an initial guess, in fclib's order (`v` for global problems only).
#[derive(Clone, Debug, Default)]
pub struct Guess {
    pub r: Vec<f64>,
    pub u: Vec<f64>,
    pub v: Option<Vec<f64>>,
}

/// Everything read from one fclib file.
#[derive(Clone, Debug)]
pub struct FclibFile {
    pub path: PathBuf,
    pub problem: Problem,
    /// `/info/title` of the problem group, when present and readable.
    pub title: Option<String>,
    /// `/solution`, when present.
    pub solution: Option<Guess>,
    /// `/guesses/1..=number_of_guesses`.
    pub guesses: Vec<Guess>,
}

impl FclibFile {
    /// Number of contacts.
    pub fn contacts(&self) -> usize {
        match &self.problem {
            Problem::Local(p) => p.mu.len(),
            Problem::Global(p) => p.mu.len(),
        }
    }

    /// The global problem, if the file holds one.
    pub fn global(&self) -> Option<&GlobalProblem> {
        match &self.problem {
            Problem::Global(p) => Some(p),
            Problem::Local(_) => None,
        }
    }
}

struct Reader<'a> {
    path: &'a Path,
    file: hdf5_metno::File,
}

impl Reader<'_> {
    fn err(&self, what: impl Into<String>, source: hdf5_metno::Error) -> FclibError {
        FclibError::Hdf5 {
            file: self.path.to_path_buf(),
            what: what.into(),
            source,
        }
    }

    fn invalid(&self, what: impl Into<String>) -> FclibError {
        FclibError::Invalid {
            file: self.path.to_path_buf(),
            what: what.into(),
        }
    }

    fn exists(&self, name: &str) -> bool {
        self.file.link_exists(name)
    }

    fn f64s(&self, name: &str) -> Result<Vec<f64>, FclibError> {
        self.file
            .dataset(name)
            .and_then(|d| d.read_raw::<f64>())
            .map_err(|e| self.err(format!("dataset {name}"), e))
    }

    fn i64s(&self, name: &str) -> Result<Vec<i64>, FclibError> {
        self.file
            .dataset(name)
            .and_then(|d| d.read_raw::<i64>())
            .map_err(|e| self.err(format!("dataset {name}"), e))
    }

    fn int(&self, name: &str) -> Result<i64, FclibError> {
        let v = self.i64s(name)?;
        match v.as_slice() {
            [x] => Ok(*x),
            _ => Err(self.invalid(format!(
                "dataset {name} holds {} values; one integer expected",
                v.len()
            ))),
        }
    }

    fn index(&self, name: &str, v: i64, bound: usize) -> Result<usize, FclibError> {
        usize::try_from(v)
            .ok()
            .filter(|&k| k < bound)
            .ok_or_else(|| self.invalid(format!("{name}: index {v} outside 0..{bound}")))
    }

    fn sparse(&self, group: &str) -> Result<SparseMatrix, FclibError> {
        let dim = |key: &str| -> Result<usize, FclibError> {
            let v = self.int(&format!("{group}/{key}"))?;
            usize::try_from(v)
                .map_err(|_| self.invalid(format!("{group}/{key} = {v}; a size ≥ 0 expected")))
        };
        let (rows, cols) = (dim("m")?, dim("n")?);
        let nz = self.int(&format!("{group}/nz"))?;
        let p = self.i64s(&format!("{group}/p"))?;
        let i = self.i64s(&format!("{group}/i"))?;
        let x = self.f64s(&format!("{group}/x"))?;
        let mut entries = Vec::new();
        let storage = match nz {
            -1 | -2 => {
                let (outer, inner, storage) = if nz == -1 {
                    (cols, rows, Storage::CompressedColumns)
                } else {
                    (rows, cols, Storage::CompressedRows)
                };
                if p.len() < outer + 1 {
                    return Err(self.invalid(format!(
                        "{group}/p has {} entries; {} expected for compressed storage",
                        p.len(),
                        outer + 1
                    )));
                }
                let total = p[outer];
                if total < 0 || total as usize > i.len().min(x.len()) {
                    return Err(self.invalid(format!(
                        "{group}: {total} entries announced, i has {}, x has {}",
                        i.len(),
                        x.len()
                    )));
                }
                for k in 0..outer {
                    let (a, b) = (p[k], p[k + 1]);
                    if a < 0 || b < a || b > total {
                        return Err(self.invalid(format!("{group}/p is not increasing at {k}")));
                    }
                    for e in a as usize..b as usize {
                        let other = self.index(&format!("{group}/i"), i[e], inner)?;
                        let (r, c) = if nz == -1 { (other, k) } else { (k, other) };
                        entries.push((r, c, x[e]));
                    }
                }
                storage
            }
            nz if nz >= 0 => {
                let nz = nz as usize;
                if p.len() < nz || i.len() < nz || x.len() < nz {
                    return Err(self.invalid(format!(
                        "{group}: nz = {nz} triplets, but p, i, x have {}, {}, {} values",
                        p.len(),
                        i.len(),
                        x.len()
                    )));
                }
                for e in 0..nz {
                    let r = self.index(&format!("{group}/i"), i[e], rows)?;
                    let c = self.index(&format!("{group}/p"), p[e], cols)?;
                    entries.push((r, c, x[e]));
                }
                Storage::Triplets
            }
            other => {
                return Err(self.invalid(format!(
                    "{group}/nz = {other}; -1 (columns), -2 (rows) or a triplet count expected"
                )))
            }
        };
        Ok(SparseMatrix {
            rows,
            cols,
            storage,
            entries,
        })
    }

    fn guess(&self, group: &str) -> Result<Guess, FclibError> {
        let v_name = format!("{group}/v");
        Ok(Guess {
            r: self.f64s(&format!("{group}/r"))?,
            u: self.f64s(&format!("{group}/u"))?,
            v: if self.exists(&v_name) {
                Some(self.f64s(&v_name)?)
            } else {
                None
            },
        })
    }

    fn title(&self, group: &str) -> Option<String> {
        let ds = self.file.dataset(&format!("{group}/info/title")).ok()?;
        let s = ds
            .read_scalar::<hdf5_metno::types::FixedAscii<1024>>()
            .ok()?;
        Some(s.as_str().trim_end_matches('\0').to_string())
    }

    fn check_len(&self, name: &str, v: &[f64], len: usize) -> Result<(), FclibError> {
        if v.len() == len {
            Ok(())
        } else {
            Err(self.invalid(format!("{name} has {} values; {len} expected", v.len())))
        }
    }
}

/// Reads an fclib file: the local or global problem, its title, the stored solution and the
/// guesses. Sizes are checked against each other (3 components per contact).
pub fn read(path: impl AsRef<Path>) -> Result<FclibFile, FclibError> {
    let path = path.as_ref();
    let file = hdf5_metno::File::open(path).map_err(|e| FclibError::Hdf5 {
        file: path.to_path_buf(),
        what: "opening the file".into(),
        source: e,
    })?;
    let rd = Reader { path, file };
    let (problem, group) = if rd.exists("fclib_local") {
        let g = "fclib_local";
        let w = rd.sparse(&format!("{g}/W"))?;
        let q = rd.f64s(&format!("{g}/vectors/q"))?;
        let mu = rd.f64s(&format!("{g}/vectors/mu"))?;
        let m = 3 * mu.len();
        if w.rows != m || w.cols != m {
            return Err(rd.invalid(format!(
                "W is {}×{}; {m}×{m} expected for {} contacts",
                w.rows,
                w.cols,
                mu.len()
            )));
        }
        rd.check_len("fclib_local/vectors/q", &q, m)?;
        (Problem::Local(LocalProblem { w, q, mu }), g)
    } else if rd.exists("fclib_global") {
        let g = "fclib_global";
        let m = rd.sparse(&format!("{g}/M"))?;
        let h = rd.sparse(&format!("{g}/H"))?;
        let f = rd.f64s(&format!("{g}/vectors/f"))?;
        let w = rd.f64s(&format!("{g}/vectors/w"))?;
        let mu = rd.f64s(&format!("{g}/vectors/mu"))?;
        let nc3 = 3 * mu.len();
        if m.rows != m.cols || h.rows != m.rows || h.cols != nc3 {
            return Err(rd.invalid(format!(
                "M is {}×{} and H {}×{}; M square and H {}×{nc3} expected",
                m.rows, m.cols, h.rows, h.cols, m.rows
            )));
        }
        rd.check_len("fclib_global/vectors/f", &f, m.rows)?;
        rd.check_len("fclib_global/vectors/w", &w, nc3)?;
        (Problem::Global(GlobalProblem { m, h, f, w, mu }), g)
    } else {
        return Err(rd.invalid("neither /fclib_local nor /fclib_global is present"));
    };
    let solution = if rd.exists("solution") {
        Some(rd.guess("solution")?)
    } else {
        None
    };
    let mut guesses = Vec::new();
    if rd.exists("guesses") {
        let count = rd.int("guesses/number_of_guesses")?;
        for k in 1..=count.max(0) {
            guesses.push(rd.guess(&format!("guesses/{k}"))?);
        }
    }
    Ok(FclibFile {
        path: path.to_path_buf(),
        title: rd.title(group),
        problem,
        solution,
        guesses,
    })
}

/// adhesim component (t1, t2, n) of fclib component (N, T1, T2): N → n, T1 → t1, T2 → t2.
pub fn to_adhesim(fclib_component: usize) -> usize {
    (fclib_component + 2) % 3
}

/// fclib component (N, T1, T2) of adhesim component (t1, t2, n).
pub fn from_adhesim(adhesim_component: usize) -> usize {
    (adhesim_component + 1) % 3
}

/// Index in adhesim's order of entry `k` = 3·contact + component of an fclib vector.
pub fn index_to_adhesim(k: usize) -> usize {
    3 * (k / 3) + to_adhesim(k % 3)
}

/// A contact-ordered vector of fclib (N, T1, T2) triples as adhesim (t1, t2, n) triples.
pub fn triples_to_adhesim(v: &[f64]) -> Vec<[f64; 3]> {
    v.chunks_exact(3)
        .map(|c| std::array::from_fn(|a| c[from_adhesim(a)]))
        .collect()
}

/// adhesim (t1, t2, n) triples as an fclib (N, T1, T2) vector.
pub fn triples_to_fclib(v: &[[f64; 3]]) -> Vec<f64> {
    v.iter()
        .flat_map(|t| (0..3).map(move |c| t[to_adhesim(c)]))
        .collect()
}

/// A local problem x = q + W r in adhesim's order, ready for its solvers.
#[derive(Clone, Debug)]
pub struct ReducedProblem {
    pub w: BlockSparseDelassus,
    pub q: Vec<[f64; 3]>,
    pub mu: Vec<f64>,
}

impl ReducedProblem {
    /// The local problem of a file, components permuted to (t1, t2, n).
    pub fn from_local(p: &LocalProblem) -> Self {
        let w = BlockSparseDelassus::from_entries(
            p.mu.len(),
            p.w.entries
                .iter()
                .map(|&(i, j, v)| (index_to_adhesim(i), index_to_adhesim(j), v)),
        );
        Self {
            w,
            q: triples_to_adhesim(&p.q),
            mu: p.mu.clone(),
        }
    }

    /// The global problem condensed on the contacts as Siconos does:
    /// W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w.
    ///
    /// M is split into its diagonal blocks, the connected components of its pattern (one per
    /// rigid body, one per degree of freedom of a diagonal M, one for a deformable body), each
    /// factorised dense by Cholesky; then W = Σ_b H_bᵀ M_b⁻¹ H_b over the blocks b, H_b the rows
    /// of H in block b restricted to the contacts that touch it. The cost is that of the blocks
    /// and of the contact pairs that share a block, never of an n × n or n × 3n_c dense matrix.
    /// A file may store M's two triangles or one: an off-diagonal entry whose mirror is absent
    /// is mirrored. Exact zeros of W (contacts on bodies that do not interact) are not stored.
    /// Fails, naming the block's first row, if a block of M is not positive definite.
    pub fn condense(p: &GlobalProblem) -> Result<Self, String> {
        let n = p.m.rows;
        let nc3 = p.h.cols;
        let blocks = diagonal_blocks(&p.m);
        let mut h_rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &(i, j, v) in &p.h.entries {
            h_rows[i].push((j, v));
        }
        let perm = index_to_adhesim;
        let mut q = p.w.clone();
        let mut entries: Vec<(usize, usize, f64)> = Vec::new();
        // Column of H → its position among the block's columns (usize::MAX: not in the block).
        let mut slot = vec![usize::MAX; nc3];
        for block in &blocks {
            let rows = &block.rows;
            if let (&[i], Some(DenseCholesky::Scalar(d))) = (rows.as_slice(), &block.chol) {
                // A 1 × 1 block (a diagonal M): h_i h_iᵀ / d and h_i f_i / d, no dense algebra.
                for &(a, ha) in &h_rows[i] {
                    q[a] += ha * p.f[i] / d;
                    for &(b, hb) in &h_rows[i] {
                        let v = ha * hb / d;
                        if v != 0.0 {
                            entries.push((perm(a), perm(b), v));
                        }
                    }
                }
                continue;
            }
            let mut cols: Vec<usize> = Vec::new();
            for &i in rows {
                for &(j, _) in &h_rows[i] {
                    if slot[j] == usize::MAX {
                        slot[j] = cols.len();
                        cols.push(j);
                    }
                }
            }
            // [H_b | f_b], solved in place by M_b⁻¹.
            let k = cols.len();
            let mut hb = DMatrix::<f64>::zeros(rows.len(), k + 1);
            for (a, &i) in rows.iter().enumerate() {
                for &(j, v) in &h_rows[i] {
                    hb[(a, slot[j])] += v;
                }
                hb[(a, k)] = p.f[i];
            }
            let z = block
                .chol
                .as_ref()
                .ok_or_else(|| {
                    format!(
                        "M is not positive definite: its diagonal block of {} row(s) from row {} \
                         has no Cholesky factor",
                        rows.len(),
                        rows[0]
                    )
                })?
                .solve(&hb);
            let g = hb.columns(0, k).transpose() * &z;
            for a in 0..k {
                q[cols[a]] += g[(a, k)];
                for b in 0..k {
                    let v = 0.5 * (g[(a, b)] + g[(b, a)]);
                    if v != 0.0 {
                        entries.push((perm(cols[a]), perm(cols[b]), v));
                    }
                }
            }
            for &j in &cols {
                slot[j] = usize::MAX;
            }
        }
        let w = BlockSparseDelassus::from_entries(p.mu.len(), entries);
        Ok(Self {
            w,
            q: triples_to_adhesim(&q),
            mu: p.mu.clone(),
        })
    }

    /// The problem of a file, condensed if global.
    pub fn of_file(file: &FclibFile) -> Result<Self, String> {
        match &file.problem {
            Problem::Local(p) => Ok(Self::from_local(p)),
            Problem::Global(p) => Self::condense(p),
        }
    }

    /// W as a dense row-major matrix in adhesim's order.
    pub fn dense_w(&self) -> Vec<f64> {
        let n = self.w.points();
        let m = 3 * n;
        let mut w = vec![0.0; m * m];
        for p in 0..n {
            for (j, b) in self.w.row(p) {
                for a in 0..3 {
                    for c in 0..3 {
                        w[(3 * p + a) * m + 3 * j + c] = b[a][c];
                    }
                }
            }
        }
        w
    }
}

/// A diagonal block of M: its rows (a connected component of M's pattern, in increasing
/// order) and the Cholesky factor of the block (none if it is not positive definite).
struct DiagonalBlock {
    rows: Vec<usize>,
    chol: Option<DenseCholesky>,
}

/// Cholesky factor of a small dense symmetric positive definite matrix (1 × 1 blocks, the
/// rows of a diagonal M, skip nalgebra's general path).
enum DenseCholesky {
    Scalar(f64),
    Dense(nalgebra::Cholesky<f64, nalgebra::Dyn>),
}

impl DenseCholesky {
    fn new(a: DMatrix<f64>) -> Option<Self> {
        if a.nrows() == 1 {
            let d = a[(0, 0)];
            return (d > 0.0 && d.is_finite()).then_some(Self::Scalar(d));
        }
        a.cholesky().map(Self::Dense)
    }

    fn solve(&self, b: &DMatrix<f64>) -> DMatrix<f64> {
        match self {
            Self::Scalar(d) => b / *d,
            Self::Dense(c) => c.solve(b),
        }
    }
}

/// M split into its diagonal blocks (the connected components of its pattern), each
/// symmetrised and factorised.
fn diagonal_blocks(m: &SparseMatrix) -> Vec<DiagonalBlock> {
    let n = m.rows;
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for &(i, j, v) in &m.entries {
        if v != 0.0 {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut block_of = vec![usize::MAX; n];
    let mut local = vec![0usize; n];
    let mut rows: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        if block_of[r] == usize::MAX {
            block_of[r] = rows.len();
            rows.push(Vec::new());
        }
        let b = block_of[r];
        block_of[i] = b;
        local[i] = rows[b].len();
        rows[b].push(i);
    }
    let mut dense: Vec<DMatrix<f64>> = rows
        .iter()
        .map(|r| DMatrix::zeros(r.len(), r.len()))
        .collect();
    for &(i, j, v) in &m.entries {
        dense[block_of[i]][(local[i], local[j])] += v;
    }
    rows.into_iter()
        .zip(dense)
        .map(|(rows, mut a)| {
            let k = a.nrows();
            for x in 0..k {
                for y in 0..x {
                    let (lower, upper) = (a[(x, y)], a[(y, x)]);
                    let v = if lower == 0.0 {
                        upper
                    } else if upper == 0.0 {
                        lower
                    } else {
                        0.5 * (lower + upper)
                    };
                    a[(x, y)] = v;
                    a[(y, x)] = v;
                }
            }
            DiagonalBlock {
                rows,
                chol: DenseCholesky::new(a),
            }
        })
        .collect()
}

/// Solves a global problem without condensing it: the semismooth Newton method of
/// `adhesim::contact::solver::semismooth::mixed` on the mixed system in (v, r), with M in place
/// of K̄ and fclib's H (each contact reads u = H_αᵀ v + w_α). W = Hᵀ M⁻¹ H is never formed; each Newton step
/// factorises the sparse mixed matrix (unknowns plus three rows per contact) by LU, and one more
/// sparse LU of M gives the start q = Hᵀ M⁻¹ f + w. ρ_α = 3/λ_max of Σ_i h_i h_iᵀ/M_ii (W_αα
/// exactly when M is diagonal). Stops on Siconos's error ≤ `tol` or after `max_iter` steps.
/// The solution is in adhesim's (t1, t2, n) order, with x the relative velocities
/// u = Hᵀ v + w and `iterations` the Newton steps (each one sparse LU factorisation).
pub fn solve_global(
    p: &GlobalProblem,
    tol: f64,
    max_iter: usize,
) -> Result<ReducedSolution, String> {
    use adhesim::contact::history::PointHistory;
    use adhesim::contact::interface::PointSolution;
    use adhesim::contact::law::InterfaceLaw;
    use adhesim::contact::solver::natural_map::{natural_map_residual, relative_error};
    use adhesim::contact::solver::semismooth::mixed::{
        linearise_point, solve_mixed, LuDirection, MixedOperator, RELATIVE_SCHEDULE,
    };
    use std::collections::BTreeMap;

    let n = p.m.rows;
    let nc = p.mu.len();
    // M's upper triangle, from whichever triangle(s) the file stores.
    let mut full: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for &(i, j, v) in &p.m.entries {
        *full.entry((i, j)).or_insert(0.0) += v;
    }
    let mut upper: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for (&(i, j), &v) in &full {
        let (a, b) = (i.min(j), i.max(j));
        let mirrored = full.contains_key(&(j, i)) && i != j;
        *upper.entry((b, a)).or_insert(0.0) += if mirrored { 0.5 * v } else { v };
    }
    // Compressed columns of the upper triangle (keys are (column, row), sorted).
    let mut col_ptr = vec![0usize; n + 1];
    let mut row_idx = Vec::with_capacity(upper.len());
    let mut values = Vec::with_capacity(upper.len());
    for (&(j, i), &v) in &upper {
        col_ptr[j + 1] += 1;
        row_idx.push(i);
        values.push(v);
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    // H per contact in adhesim's component order.
    let mut h: Vec<BTreeMap<usize, [f64; 3]>> = vec![BTreeMap::new(); nc];
    for &(i, col, v) in &p.h.entries {
        let (c, k) = (col / 3, to_adhesim(col % 3));
        h[c].entry(i).or_insert([0.0; 3])[k] += v;
    }
    let h: Vec<Vec<(usize, [f64; 3])>> = h.into_iter().map(|m| m.into_iter().collect()).collect();
    // q = Hᵀ M⁻¹ f + w by a sparse LU of M (its full pattern, natural column order).
    let mut m_cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for (&(j, i), &v) in &upper {
        m_cols[j].push((i, v));
        if i != j {
            m_cols[i].push((j, v));
        }
    }
    let mut mp = vec![0usize];
    let (mut mi, mut mv) = (Vec::new(), Vec::new());
    for col in &mut m_cols {
        col.sort_by_key(|e| e.0);
        mi.extend(col.iter().map(|e| e.0));
        mv.extend(col.iter().map(|e| e.1));
        mp.push(mi.len());
    }
    let ident: Vec<usize> = (0..n).collect();
    let mut lu = adhesim::sparse_lu::OrderedLu::analyse(mp, mi, ident.clone(), ident)
        .map_err(|e| format!("M: {e}"))?;
    lu.factorise(&mv).map_err(|e| format!("M: {e}"))?;
    let mut v0 = p.f.clone();
    lu.solve_in_place(&mut v0);
    let w = triples_to_adhesim(&p.w);
    let q: Vec<[f64; 3]> = (0..nc)
        .map(|c| {
            let mut u = w[c];
            for &(i, coef) in &h[c] {
                for k in 0..3 {
                    u[k] += coef[k] * v0[i];
                }
            }
            u
        })
        .collect();
    // ρ from the diagonal of M.
    let diag: Vec<f64> = (0..n)
        .map(|j| upper.get(&(j, j)).copied().unwrap_or(0.0))
        .collect();
    let rho: Vec<f64> = h
        .iter()
        .map(|terms| {
            let mut wd = nalgebra::Matrix3::<f64>::zeros();
            for &(i, c) in terms {
                if diag[i] > 0.0 {
                    let c = nalgebra::Vector3::from(c);
                    wd += c * c.transpose() / diag[i];
                }
            }
            let lmax = wd.symmetric_eigenvalues().max();
            if lmax > 0.0 {
                3.0 / lmax
            } else {
                1.0
            }
        })
        .collect();
    let laws: Vec<InterfaceLaw> = p.mu.iter().map(|&mu| InterfaceLaw::coulomb(mu)).collect();
    let law = |c: usize, r: [f64; 3], x: [f64; 3]| {
        linearise_point(&laws[c], PointHistory::default(), 1.0, 1.0, rho[c], r, x)
    };
    let error = |pts: &[PointSolution]| {
        let r: Vec<[f64; 3]> = pts.iter().map(|s| s.r_dry.into()).collect();
        let x: Vec<[f64; 3]> = pts.iter().map(|s| s.x.into()).collect();
        relative_error(natural_map_residual(&r, &x, &p.mu), &q, &r, &x)
    };
    let op = MixedOperator {
        col_ptr: &col_ptr,
        row_idx: &row_idx,
        values: &values,
        h: &h,
    };
    let mut pattern = None;
    let mut dir = LuDirection {
        op: &op,
        pattern: &mut pattern,
        momentum: &[],
    };
    let mut eta_rel = 1e-2;
    let r0 = vec![[0.0; 3]; nc];
    let sol = solve_mixed(
        &mut dir,
        law,
        error,
        &rho,
        &r0,
        &q,
        tol,
        max_iter,
        RELATIVE_SCHEDULE,
        &mut eta_rel,
    )?;
    let x: Vec<[f64; 3]> = sol.points.iter().map(|s| s.x.into()).collect();
    Ok(ReducedSolution {
        residual: natural_map_residual(&sol.r, &x, &p.mu),
        r: sol.r,
        x,
        iterations: sol.iterations,
        error: sol.residual,
        converged: sol.converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn component_permutation_round_trips() {
        assert_eq!(to_adhesim(0), 2); // N → n
        assert_eq!(to_adhesim(1), 0); // T1 → t1
        assert_eq!(to_adhesim(2), 1); // T2 → t2
        for c in 0..3 {
            assert_eq!(from_adhesim(to_adhesim(c)), c);
        }
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let t = triples_to_adhesim(&v);
        assert_eq!(t, vec![[2.0, 3.0, 1.0], [5.0, 6.0, 4.0]]);
        assert_eq!(triples_to_fclib(&t), v.to_vec());
    }
}
