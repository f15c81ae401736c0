//! Sparse symmetric positive-definite solves over faer: the pattern and the symbolic
//! factorisation are computed once per mesh (with a METIS nested-dissection ordering of the
//! node graph), the numeric factorisation once per Newton iteration, and any number of
//! right-hand sides solved with it.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side, Spec};

/// Errors of the linear-algebra layer.
#[derive(Debug, thiserror::Error)]
pub enum LinalgError {
    /// The matrix is not numerically positive definite (e.g. an element turned inside out, a
    /// body not held against rigid motion in a quasi-static run, or a quasi-static load
    /// increment too large; [`crate::diagnosis`] tells which from the problem).
    #[error("the system matrix is not positive definite")]
    NotPositiveDefinite,
    /// Ordering or symbolic analysis failed.
    #[error("symbolic analysis of the system matrix failed: {0}")]
    Symbolic(String),
}

/// Upper triangle (row ≤ column) of a symmetric sparse matrix whose unknowns come in blocks
/// of three (x, y, z of a node), stored column by column.
#[derive(Clone, Debug)]
pub struct BlockPattern {
    /// Number of nodes; the matrix has 3·num_nodes rows.
    pub num_nodes: usize,
    /// For each node B, the sorted nodes A ≤ B that share a cell with B (B included, last).
    pub upper_neighbours: Vec<Vec<usize>>,
    /// Column pointers of the scalar upper CSC matrix (length 3·num_nodes + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices of the scalar upper CSC matrix.
    pub row_idx: Vec<usize>,
}

impl BlockPattern {
    /// Builds the pattern from the node lists of the cells (any cell type).
    pub fn from_cells<'a>(num_nodes: usize, cells: impl Iterator<Item = &'a [usize]>) -> Self {
        let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); num_nodes];
        for cell in cells {
            for &a in cell {
                for &b in cell {
                    if a <= b {
                        nbrs[b].push(a);
                    }
                }
            }
        }
        for (b, list) in nbrs.iter_mut().enumerate() {
            list.push(b);
            list.sort_unstable();
            list.dedup();
        }
        Self::from_neighbours(num_nodes, nbrs)
    }

    /// The pattern of sorted upper neighbour lists (each node's list ends with itself).
    pub fn from_neighbours(num_nodes: usize, nbrs: Vec<Vec<usize>>) -> Self {
        let n = 3 * num_nodes;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (b, list) in nbrs.iter().enumerate() {
            for k in 0..3 {
                for &a in list {
                    let rows = if a == b { k + 1 } else { 3 };
                    for i in 0..rows {
                        row_idx.push(3 * a + i);
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        BlockPattern {
            num_nodes,
            upper_neighbours: nbrs,
            col_ptr,
            row_idx,
        }
    }

    /// This pattern with the extra node couplings `pairs` (any order, repeats allowed), and
    /// for each stored value of `self` its position in the new pattern.
    pub fn with_extra_pairs(&self, pairs: &[(usize, usize)]) -> (BlockPattern, Vec<usize>) {
        let mut nbrs = self.upper_neighbours.clone();
        for &(a, b) in pairs {
            let (lo, hi) = (a.min(b), a.max(b));
            nbrs[hi].push(lo);
        }
        for list in nbrs.iter_mut() {
            list.sort_unstable();
            list.dedup();
        }
        let ext = BlockPattern::from_neighbours(self.num_nodes, nbrs);
        let mut map = vec![0usize; self.nnz()];
        for b in 0..self.num_nodes {
            for (r, &a) in self.upper_neighbours[b].iter().enumerate() {
                let r_ext = ext
                    .rank(a, b)
                    .expect("the extended pattern holds the original");
                for k in 0..3 {
                    let rows = if a == b { k + 1 } else { 3 };
                    for i in 0..rows {
                        map[self.position(r, b, i, k)] = ext.position(r_ext, b, i, k);
                    }
                }
            }
        }
        (ext, map)
    }

    /// The pattern of Tᵀ A T for the node map T that gives node n the unknowns of node
    /// `rep[n]` (`rep[rep[n]] == rep[n]`): every block (a, b) moves to (rep a, rep b), and a
    /// node with rep[n] ≠ n keeps only its diagonal block (which stays empty). Returns it with,
    /// for each stored value of `self`, its position in the new pattern and its factor: 2 for a
    /// diagonal entry of an off-diagonal block (a, b) with rep a = rep b, which stands for both
    /// A_ab and A_ba there, 1 otherwise.
    pub fn condensed(&self, rep: &[usize]) -> (BlockPattern, Vec<(usize, f64)>) {
        let mut nbrs: Vec<Vec<usize>> = (0..self.num_nodes).map(|b| vec![b]).collect();
        for b in 0..self.num_nodes {
            for &a in &self.upper_neighbours[b] {
                let (ra, rb) = (rep[a], rep[b]);
                nbrs[ra.max(rb)].push(ra.min(rb));
            }
        }
        for list in nbrs.iter_mut() {
            list.sort_unstable();
            list.dedup();
        }
        let out = BlockPattern::from_neighbours(self.num_nodes, nbrs);
        let mut map = vec![(0usize, 0.0); self.nnz()];
        for b in 0..self.num_nodes {
            for (r, &a) in self.upper_neighbours[b].iter().enumerate() {
                for k in 0..3 {
                    let rows = if a == b { k + 1 } else { 3 };
                    for i in 0..rows {
                        let to = out.scalar_position(3 * rep[a] + i, 3 * rep[b] + k);
                        map[self.position(r, b, i, k)] = (to, 1.0);
                    }
                }
                if a != b && rep[a] == rep[b] {
                    for k in 0..3 {
                        map[self.position(r, b, k, k)].1 = 2.0;
                    }
                }
            }
        }
        (out, map)
    }

    /// Index into the value array of scalar entry (i, j) or (j, i), whichever is stored; the
    /// pattern must hold the nodes' block.
    pub fn scalar_position(&self, i: usize, j: usize) -> usize {
        let (i, j) = (i.min(j), i.max(j));
        let rank = self
            .rank(i / 3, j / 3)
            .expect("the pattern holds the block");
        self.position(rank, j / 3, i % 3, j % 3)
    }

    /// Number of stored values.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Dimension of the scalar matrix.
    pub fn dim(&self) -> usize {
        3 * self.num_nodes
    }

    /// Position of node A among the stored upper neighbours of node B (A ≤ B), if any.
    pub fn rank(&self, a: usize, b: usize) -> Option<usize> {
        self.upper_neighbours[b].binary_search(&a).ok()
    }

    /// Index into the value array of entry (3a + i, 3b + k), given `rank = self.rank(a, b)`.
    /// Valid only for a < b, or a == b with i ≤ k.
    #[inline]
    pub fn position(&self, rank: usize, b: usize, i: usize, k: usize) -> usize {
        self.col_ptr[3 * b + k] + 3 * rank + i
    }

    /// Index of the diagonal entry of scalar unknown d.
    #[inline]
    pub fn diagonal_position(&self, d: usize) -> usize {
        self.col_ptr[d + 1] - 1
    }

    /// y += A x for the symmetric matrix whose upper triangle has `values`.
    pub fn symmetric_matvec(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        for j in 0..self.dim() {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[p];
                y[i] += values[p] * x[j];
                if i != j {
                    y[j] += values[p] * x[i];
                }
            }
        }
    }

    /// The scalar upper pattern as faer's symbolic matrix.
    pub fn symbolic(&self) -> SymbolicSparseColMat<usize> {
        let n = self.dim();
        SymbolicSparseColMat::new_checked(n, n, self.col_ptr.clone(), None, self.row_idx.clone())
    }

    /// The node adjacency graph in CSR form without self loops (for METIS).
    fn node_graph(&self) -> (Vec<i32>, Vec<i32>) {
        let mut full: Vec<Vec<usize>> = vec![Vec::new(); self.num_nodes];
        for (b, list) in self.upper_neighbours.iter().enumerate() {
            for &a in list {
                if a != b {
                    full[a].push(b);
                    full[b].push(a);
                }
            }
        }
        let mut xadj = vec![0i32];
        let mut adjncy = Vec::new();
        for list in &mut full {
            list.sort_unstable();
            adjncy.extend(list.iter().map(|&v| v as i32));
            xadj.push(adjncy.len() as i32);
        }
        (xadj, adjncy)
    }
}

/// Held while METIS runs (see [`metis_dof_ordering`]).
static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Fill-reducing ordering of the nodes by METIS nested dissection; returns (forward,
/// inverse) permutations of the scalar unknowns, three per node.
pub fn metis_dof_ordering(pattern: &BlockPattern) -> Result<(Vec<usize>, Vec<usize>), LinalgError> {
    let n = pattern.num_nodes;
    let mut node_perm: Vec<i32> = (0..n as i32).collect();
    if n > 1 {
        let (mut xadj, mut adjncy) = pattern.node_graph();
        if !adjncy.is_empty() {
            let mut nvtxs = n as i32;
            let mut perm = vec![0i32; n];
            let mut iperm = vec![0i32; n];
            // METIS draws from a random-number generator whose state is one global of the
            // C library, seeded at the start of each call: two calls from different threads
            // (concurrent runs of a sweep, tests) interleave their draws and get different
            // orderings, hence different round-off. One call at a time keeps every run's
            // ordering the same.
            let _only_caller = METIS_LOCK.lock().unwrap_or_else(|e| e.into_inner());
            // SAFETY: the arrays have the lengths METIS expects (xadj n+1, adjncy xadj[n],
            // perm and iperm n); null pointers select the default weights and options.
            let status = unsafe {
                metis_sys::METIS_NodeND(
                    &mut nvtxs,
                    xadj.as_mut_ptr(),
                    adjncy.as_mut_ptr(),
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    perm.as_mut_ptr(),
                    iperm.as_mut_ptr(),
                )
            };
            if status != metis_sys::rstatus_et_METIS_OK {
                return Err(LinalgError::Symbolic(format!(
                    "METIS_NodeND returned {status}"
                )));
            }
            node_perm = perm;
        }
    }
    let mut fwd = vec![0usize; 3 * n];
    for (new, &old) in node_perm.iter().enumerate() {
        for k in 0..3 {
            fwd[3 * new + k] = 3 * old as usize + k;
        }
    }
    let mut inv = vec![0usize; 3 * n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    Ok((fwd, inv))
}

/// Something that solves A X = B in place for a column-major block of right-hand sides
/// (`rhs.len()` a multiple of the dimension) with a factorisation it holds.
pub trait LinearSolve {
    /// Overwrites each column of `rhs` with A⁻¹ times it.
    fn solve_in_place(&mut self, rhs: &mut [f64]);
}

impl LinearSolve for SparseCholesky {
    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        SparseCholesky::solve_in_place(self, rhs);
    }
}

/// faer's choice between its simplicial and supernodal Cholesky factorisations, a multiple
/// of its default threshold on the factorisation's flops per nonzero of L (supernodal above
/// 40 × this). Half the default: the README example's one-element-thick slab (9.4k unknowns)
/// falls between the two, and its 1,663 factorisations took 5.2 to 5.7 s supernodal against
/// 10.5 to 11.4 s simplicial; the 4.3 plate (2.4k unknowns) 0.91 s against 1.42 s. Bulky 3D
/// meshes are supernodal either way.
const SUPERNODAL_THRESHOLD: SupernodalThreshold = SupernodalThreshold(0.5);

/// A sparse Cholesky factorisation whose symbolic part is reused across numeric
/// factorisations of matrices with the same pattern.
pub struct SparseCholesky {
    /// Number of unknowns.
    dim: usize,
    /// The pattern factorised (upper triangle): the analysed one, or its reduction.
    pattern: SymbolicSparseColMat<usize>,
    /// The unknowns the factorisation is reduced to when entries are dropped.
    reduction: Option<Reduction>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    /// Threads of the numeric factorisation.
    factorise_par: ParChoice,
    factorised: bool,
}

/// Calls of each mode timed before [`ParChoice`] settles.
const PAR_TRIALS: usize = 3;

/// Sequential or parallel: whichever is faster on this matrix and this machine, measured.
///
/// faer's parallel supernodal factorisation pays off on a bulky 3D block factorised alone
/// (`bench_core --sizes 20,30 --threads 1,2`: 0.81× and 0.69× the sequential time on 2
/// threads) but not always inside a run, where thin bodies have narrow elimination trees and
/// the pool's threads are woken for every call: the 3,136-node pad took 1.24× and the 4.4
/// twist 1.27× their sequential time with 2 threads (docs/running.md, *Threads*). The two
/// modes give bit-identical factors (the test below, and the histories of both runs), so
/// timing the first calls of each, alternating, and keeping the faster for the rest has no
/// effect on the results.
#[derive(Clone, Debug)]
enum ParChoice {
    /// Settled (or only one thread).
    Fixed(Par),
    /// Still timing: seconds of the sequential and of the parallel calls so far.
    Trial {
        threads: usize,
        seq: Vec<f64>,
        par: Vec<f64>,
    },
}

impl ParChoice {
    fn new(threads: usize) -> Self {
        if threads == 1 {
            ParChoice::Fixed(Par::Seq)
        } else {
            ParChoice::Trial {
                threads,
                seq: Vec::new(),
                par: Vec::new(),
            }
        }
    }

    /// The mode of the next call: the settled one, or the one with fewer timings (parallel
    /// first).
    fn next(&self) -> Par {
        match self {
            ParChoice::Fixed(p) => *p,
            ParChoice::Trial { threads, seq, par } => {
                if par.len() <= seq.len() {
                    Par::rayon(*threads)
                } else {
                    Par::Seq
                }
            }
        }
    }

    /// Records that a call in mode `mode` took `seconds`; settles after [`PAR_TRIALS`] of each.
    fn record(&mut self, mode: Par, seconds: f64) {
        if let ParChoice::Trial { threads, seq, par } = self {
            match mode {
                Par::Seq => seq.push(seconds),
                _ => par.push(seconds),
            }
            if seq.len() >= PAR_TRIALS && par.len() >= PAR_TRIALS {
                let faster = if median(seq) <= median(par) {
                    Par::Seq
                } else {
                    Par::rayon(*threads)
                };
                *self = ParChoice::Fixed(faster);
            }
        }
    }
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

impl SparseCholesky {
    /// Symbolic analysis: METIS ordering and elimination structure. `threads` = 0 uses the
    /// rayon pool's size.
    pub fn analyse(pattern: &BlockPattern, threads: usize) -> Result<Self, LinalgError> {
        Self::analyse_without(pattern, threads, &[])
    }

    /// [`Self::analyse`] for matrices whose entries at the positions `dropped` (off-diagonal,
    /// in increasing order, indices into the pattern's values) are zero in every matrix
    /// factorised, e.g. the rows and columns of prescribed unknowns. They are left out of the
    /// ordering and of the factor ([`Reduction`]): a node held in all three directions would
    /// otherwise join its neighbours in the elimination and fill the factor in as a free one
    /// does (the scale benchmark's pad at 1,024 contact nodes, whose top face is held: 4.76
    /// million nonzeros in L with them, 3.24 million without).
    pub fn analyse_without(
        pattern: &BlockPattern,
        threads: usize,
        dropped: &[usize],
    ) -> Result<Self, LinalgError> {
        let dim = pattern.dim();
        let (reduction, sym, (fwd, inv)) = if dropped.is_empty() {
            (None, pattern.symbolic(), metis_dof_ordering(pattern)?)
        } else {
            let (reduction, sym, ordering) = Reduction::new(pattern, dropped)?;
            (Some(reduction), sym, ordering)
        };
        let n = sym.nrows();
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
        let symbolic = factorize_symbolic_cholesky(
            sym.as_ref(),
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SUPERNODAL_THRESHOLD,
                ..Default::default()
            },
        )
        .map_err(|e| LinalgError::Symbolic(format!("{e:?}")))?;
        let threads = if threads == 0 {
            rayon::current_num_threads()
        } else {
            threads
        };
        let par = if threads == 1 {
            Par::Seq
        } else {
            Par::rayon(threads)
        };
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Spec::default()),
            symbolic.solve_in_place_scratch::<f64>(64, Par::Seq),
        ]);
        let mem =
            MemBuffer::try_new(req).map_err(|_| LinalgError::Symbolic("out of memory".into()))?;
        let l_values = vec![0.0; symbolic.len_val()];
        Ok(SparseCholesky {
            dim,
            pattern: sym,
            reduction,
            symbolic,
            l_values,
            mem,
            factorise_par: ParChoice::new(threads),
            factorised: false,
        })
    }

    /// Number of nonzeros of the factor L.
    pub fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Whether the last numeric factorisation succeeded (solves are then possible).
    pub fn is_factorised(&self) -> bool {
        self.factorised
    }

    /// Numeric factorisation of the matrix with the analysed pattern and upper-triangle
    /// `values` (those at the dropped positions are not read).
    pub fn factorise(&mut self, values: &[f64]) -> Result<(), LinalgError> {
        self.factorised = false;
        let values = match &mut self.reduction {
            None => values,
            Some(r) => r.gather(values)?,
        };
        let a = SparseColMatRef::new(self.pattern.as_ref(), values);
        let stack = MemStack::new(&mut self.mem);
        let par = self.factorise_par.next();
        let clock = std::time::Instant::now();
        faer_call(par, || {
            self.symbolic.factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Upper,
                LltRegularization::default(),
                par,
                stack,
                Spec::default(),
            )
        })
        .map_err(|_| LinalgError::NotPositiveDefinite)?;
        self.factorise_par
            .record(par, clock.elapsed().as_secs_f64());
        self.factorised = true;
        Ok(())
    }

    /// Solves A X = B in place for a column-major block of right-hand sides (`rhs.len()` a
    /// multiple of the dimension). Solves at most 64 columns at a time.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(self.factorised, "solve before a successful factorisation");
        if self.dim == 0 {
            return;
        }
        let Some(r) = &mut self.reduction else {
            solve_factorised(&self.symbolic, &self.l_values, &mut self.mem, rhs);
            return;
        };
        // The factorised unknowns gathered, solved, and put back; the others each divided by
        // its diagonal.
        r.compact.clear();
        for col in rhs.chunks_exact_mut(self.dim) {
            r.solve_isolated(col);
            r.compact.extend(r.free.iter().map(|&i| col[i]));
        }
        solve_factorised(
            &self.symbolic,
            &self.l_values,
            &mut self.mem,
            &mut r.compact,
        );
        let parts = r.compact.chunks_exact(r.free.len().max(1));
        for (col, part) in rhs.chunks_exact_mut(self.dim).zip(parts) {
            for (&i, &v) in r.free.iter().zip(part) {
                col[i] = v;
            }
        }
    }

    /// The scalar symbolic pattern factorised (upper triangle; on the reduction's unknowns
    /// when entries are dropped).
    pub fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.pattern.as_ref()
    }
}

/// A permutation of the unknowns as (forward, inverse), forward[new] = old.
type Permutation = (Vec<usize>, Vec<usize>);

/// Solves the factorised matrix (`symbolic`, `l_values`; the reduced one, if any) in place,
/// for a column-major block of right-hand sides `rhs`, with the scratch space `mem`.
fn solve_factorised(
    symbolic: &SymbolicCholesky<usize>,
    l_values: &[f64],
    mem: &mut MemBuffer,
    rhs: &mut [f64],
) {
    let n = symbolic.nrows();
    if n == 0 {
        return;
    }
    let llt = LltRef::new(symbolic, l_values);
    // Solved on one thread, one right-hand side (Newton corrections, GMRES's preconditioner)
    // or many (the columns of W): the triangular solves are short and memory-bound. Waking
    // the pool for each single one cost the 4.4 twist 45 % more contact-solve time
    // (docs/running.md), and with 2 threads the blocks of W's columns took 1.4 to 1.6 times
    // as long as on one (README example and a 484-point pad with Gauss-Seidel). Unlike the
    // factorisation, a parallel solve sums in another order, so the choice is not timed:
    // results must not depend on the machine's load.
    faer_call(Par::Seq, || {
        for chunk in rhs.chunks_mut(64 * n) {
            let k = chunk.len() / n;
            let mat = MatMut::from_column_major_slice_mut(chunk, n, k);
            llt.solve_in_place_with_conj(Conj::No, mat, Par::Seq, MemStack::new(mem));
        }
    });
}

/// The matrix a [`SparseCholesky`] factorises when entries are dropped: the unknowns that
/// keep an off-diagonal entry (`free`), in their order, and the others, each left with its
/// diagonal alone (`isolated`) and solved by a division. Prescribed unknowns and those of
/// tied nodes are such. Kept in the factorisation, each would be a supernode of one column:
/// the README example's factor then had 7,986 supernodes for 9,438 unknowns, and its
/// factorisations took 7.8 s instead of 5.1 s with the full pattern, and 2.6 s reduced.
struct Reduction {
    /// The unknowns factorised, increasing.
    free: Vec<usize>,
    /// Positions in the analysed pattern's values of the entries factorised.
    kept: Vec<usize>,
    /// Their values, gathered for the factorisation.
    kept_values: Vec<f64>,
    /// The other unknowns, with the position of their diagonal in the values.
    isolated: Vec<(usize, usize)>,
    /// Their diagonal at the last factorisation.
    isolated_values: Vec<f64>,
    /// Right-hand sides on the factorised unknowns (reused).
    compact: Vec<f64>,
}

impl Reduction {
    /// The reduction of `pattern` without the entries at the positions `dropped`
    /// (off-diagonal, increasing), with the pattern factorised (upper triangle) and its
    /// ordering (forward, inverse): METIS on the node graph in which two nodes are neighbours
    /// when an entry between them is kept, restricted to the factorised unknowns.
    fn new(
        pattern: &BlockPattern,
        dropped: &[usize],
    ) -> Result<(Self, SymbolicSparseColMat<usize>, Permutation), LinalgError> {
        let dim = pattern.dim();
        let mut coupled = vec![false; dim];
        let mut keep = vec![true; pattern.nnz()];
        for &q in dropped {
            keep[q] = false;
        }
        let mut nbrs: Vec<Vec<usize>> = (0..pattern.num_nodes).map(|b| vec![b]).collect();
        for j in 0..dim {
            for q in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[q];
                if keep[q] && i != j {
                    coupled[i] = true;
                    coupled[j] = true;
                    if i / 3 != j / 3 {
                        nbrs[j / 3].push(i / 3);
                    }
                }
            }
        }
        for list in &mut nbrs {
            list.sort_unstable();
            list.dedup();
        }
        let free: Vec<usize> = (0..dim).filter(|&i| coupled[i]).collect();
        let mut index = vec![usize::MAX; dim];
        for (k, &i) in free.iter().enumerate() {
            index[i] = k;
        }
        let (mut kept, mut col_ptr, mut row_idx) = (Vec::new(), vec![0], Vec::new());
        for &j in &free {
            for q in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[q];
                if keep[q] && coupled[i] {
                    kept.push(q);
                    row_idx.push(index[i]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let isolated: Vec<(usize, usize)> = (0..dim)
            .filter(|&i| !coupled[i])
            .map(|i| (i, pattern.diagonal_position(i)))
            .collect();
        let n = free.len();
        let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let nodes = BlockPattern::from_neighbours(pattern.num_nodes, nbrs);
        let fwd: Vec<usize> = metis_dof_ordering(&nodes)?
            .0
            .into_iter()
            .filter(|&old| coupled[old])
            .map(|old| index[old])
            .collect();
        let mut inv = vec![0; n];
        for (new, &old) in fwd.iter().enumerate() {
            inv[old] = new;
        }
        let reduction = Reduction {
            kept_values: vec![0.0; kept.len()],
            isolated_values: vec![0.0; isolated.len()],
            free,
            kept,
            isolated,
            compact: Vec::new(),
        };
        Ok((reduction, sym, (fwd, inv)))
    }

    /// The values factorised, from those of the analysed pattern; an isolated unknown whose
    /// diagonal is not positive makes the matrix not positive definite.
    fn gather(&mut self, values: &[f64]) -> Result<&[f64], LinalgError> {
        for (v, &(_, q)) in self.isolated_values.iter_mut().zip(&self.isolated) {
            *v = values[q];
            if !(*v > 0.0) {
                return Err(LinalgError::NotPositiveDefinite);
            }
        }
        for (v, &q) in self.kept_values.iter_mut().zip(&self.kept) {
            *v = values[q];
        }
        Ok(&self.kept_values)
    }

    /// Divides the isolated unknowns of one right-hand side `col` by their diagonal.
    fn solve_isolated(&self, col: &mut [f64]) {
        for (&(i, _), d) in self.isolated.iter().zip(&self.isolated_values) {
            col[i] /= d;
        }
    }
}

/// When [`gmres`] stops: at a true residual ‖b − A x‖ ≤ `tol` ‖b‖, or after `max_iter`
/// iterations; it restarts every `restart` iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrylovLimits {
    /// Relative tolerance on the residual [-].
    pub tol: f64,
    /// Iteration limit.
    pub max_iter: usize,
    /// Iterations between restarts.
    pub restart: usize,
}

/// What [`gmres`] reached.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrylovOutcome {
    /// Iterations (applications of the operator and the preconditioner).
    pub iterations: usize,
    /// ‖b − A x‖ / ‖b‖ at the end.
    pub relative_residual: f64,
}

/// Euclidean norm.
pub fn norm(x: &[f64]) -> f64 {
    x.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// Restarted GMRES with right preconditioning for A x = b, from x = 0: `apply(v, out)` sets
/// out = A v, `precondition(v)` overwrites v with M⁻¹ v; it stops as `limits` say. Right
/// preconditioning keeps the residual it monitors that of the original system.
pub fn gmres(
    apply: impl Fn(&[f64], &mut [f64]),
    precondition: impl FnMut(&mut [f64]),
    b: &[f64],
    limits: KrylovLimits,
) -> (Vec<f64>, KrylovOutcome) {
    let krylov = |_: &[f64], z: &[f64], w: &mut [f64]| apply(z, w);
    gmres_core(&apply, krylov, precondition, b, limits)
}

/// [`gmres`] for A = M + E with M the preconditioner's own matrix (M⁻¹ solved exactly, up to
/// its factorisation's round-off): the Krylov vectors A M⁻¹ v are formed as v + E M⁻¹ v, so
/// each iteration costs one solve with M and one product with E (`remainder(z, out)` sets
/// out = E z) and never one with A. `apply` (A itself) is used once per restart cycle, for
/// the true residual that decides convergence, so M's round-off cannot stop it early.
pub fn gmres_with_remainder(
    apply: impl Fn(&[f64], &mut [f64]),
    remainder: impl Fn(&[f64], &mut [f64]),
    precondition: impl FnMut(&mut [f64]),
    b: &[f64],
    limits: KrylovLimits,
) -> (Vec<f64>, KrylovOutcome) {
    let krylov = |v: &[f64], z: &[f64], w: &mut [f64]| {
        remainder(z, w);
        for (wi, vi) in w.iter_mut().zip(v) {
            *wi += vi;
        }
    };
    gmres_core(&apply, krylov, precondition, b, limits)
}

/// Restarted right-preconditioned GMRES: `krylov(v, z, w)` sets w = A z for z = M⁻¹ v.
fn gmres_core(
    apply: &impl Fn(&[f64], &mut [f64]),
    krylov: impl Fn(&[f64], &[f64], &mut [f64]),
    mut precondition: impl FnMut(&mut [f64]),
    b: &[f64],
    limits: KrylovLimits,
) -> (Vec<f64>, KrylovOutcome) {
    let KrylovLimits {
        tol,
        max_iter,
        restart,
    } = limits;
    let n = b.len();
    let dot = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
    let b_norm = dot(b, b).sqrt();
    let mut x = vec![0.0; n];
    let mut outcome = KrylovOutcome {
        iterations: 0,
        relative_residual: 0.0,
    };
    if b_norm == 0.0 {
        return (x, outcome);
    }
    let mut r = b.to_vec();
    let mut ax = vec![0.0; n];
    loop {
        let beta = dot(&r, &r).sqrt();
        outcome.relative_residual = beta / b_norm;
        if beta <= tol * b_norm || outcome.iterations >= max_iter {
            return (x, outcome);
        }
        let m = restart.min(max_iter - outcome.iterations).max(1);
        let mut v: Vec<Vec<f64>> = vec![r.iter().map(|ri| ri / beta).collect()];
        let mut z: Vec<Vec<f64>> = Vec::with_capacity(m);
        let mut h = vec![vec![0.0; m]; m + 1];
        let (mut cs, mut sn) = (vec![0.0; m], vec![0.0; m]);
        let mut g = vec![0.0; m + 1];
        g[0] = beta;
        let mut k = 0;
        while k < m {
            let mut zk = v[k].clone();
            precondition(&mut zk);
            let mut w = vec![0.0; n];
            krylov(&v[k], &zk, &mut w);
            z.push(zk);
            outcome.iterations += 1;
            // Modified Gram-Schmidt.
            for (j, vj) in v.iter().enumerate() {
                h[j][k] = dot(&w, vj);
                for (wi, vi) in w.iter_mut().zip(vj) {
                    *wi -= h[j][k] * vi;
                }
            }
            h[k + 1][k] = dot(&w, &w).sqrt();
            for j in 0..k {
                let t = cs[j] * h[j][k] + sn[j] * h[j + 1][k];
                h[j + 1][k] = -sn[j] * h[j][k] + cs[j] * h[j + 1][k];
                h[j][k] = t;
            }
            let denom = h[k][k].hypot(h[k + 1][k]);
            (cs[k], sn[k]) = if denom == 0.0 {
                (1.0, 0.0)
            } else {
                (h[k][k] / denom, h[k + 1][k] / denom)
            };
            let hk1 = h[k + 1][k];
            h[k][k] = cs[k] * h[k][k] + sn[k] * hk1;
            h[k + 1][k] = 0.0;
            g[k + 1] = -sn[k] * g[k];
            g[k] *= cs[k];
            let breakdown = hk1 == 0.0;
            if !breakdown {
                v.push(w.iter().map(|wi| wi / hk1).collect());
            }
            k += 1;
            if breakdown || g[k].abs() <= tol * b_norm {
                break;
            }
        }
        // y from the triangular system, then x += Z y.
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let s: f64 = (i + 1..k).map(|j| h[i][j] * y[j]).sum();
            y[i] = if h[i][i] == 0.0 {
                0.0
            } else {
                (g[i] - s) / h[i][i]
            };
        }
        for (zj, yj) in z.iter().zip(&y) {
            for (xi, zi) in x.iter_mut().zip(zj) {
                *xi += yj * zi;
            }
        }
        apply(&x, &mut ax);
        for ((ri, bi), ai) in r.iter_mut().zip(b).zip(&ax) {
            *ri = bi - ai;
        }
        if !x.iter().all(|v| v.is_finite()) {
            outcome.relative_residual = f64::INFINITY;
            return (x, outcome);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D chain of nodes, each coupled to its neighbours: a block-tridiagonal matrix,
    /// SPD by strict diagonal dominance (diagonal ≥ 4, off-diagonal row sums ≤ 3.1).
    fn chain_matrix(n: usize) -> (BlockPattern, Vec<f64>) {
        let cells: Vec<[usize; 2]> = (0..n - 1).map(|i| [i, i + 1]).collect();
        let pattern = BlockPattern::from_cells(n, cells.iter().map(|c| &c[..]));
        let mut values = vec![0.0; pattern.nnz()];
        for b in 0..n {
            for &a in &pattern.upper_neighbours[b] {
                let r = pattern.rank(a, b).unwrap();
                for k in 0..3 {
                    for i in 0..3 {
                        if a == b && i > k {
                            continue;
                        }
                        let v = if a == b {
                            if i == k {
                                4.0 + k as f64
                            } else {
                                0.5
                            }
                        } else {
                            -0.3 + 0.05 * (i as f64 - k as f64)
                        };
                        values[pattern.position(r, b, i, k)] = v;
                    }
                }
            }
        }
        (pattern, values)
    }

    #[test]
    fn pattern_positions_are_consistent_with_row_indices() {
        let (p, _) = chain_matrix(5);
        for b in 0..5 {
            for &a in &p.upper_neighbours[b] {
                let r = p.rank(a, b).unwrap();
                for k in 0..3 {
                    for i in 0..3 {
                        if a == b && i > k {
                            continue;
                        }
                        assert_eq!(p.row_idx[p.position(r, b, i, k)], 3 * a + i);
                    }
                }
            }
        }
        for d in 0..15 {
            assert_eq!(p.row_idx[p.diagonal_position(d)], d);
        }
    }

    /// A cube of n³ nodes in hex cells, each node coupled to its 26 neighbours: SPD by strict
    /// diagonal dominance (diagonal 4, off-diagonal row sums ≤ 26·3·0.04 = 3.12).
    fn grid_matrix(n: usize) -> (BlockPattern, Vec<f64>) {
        let id = |i: usize, j: usize, k: usize| (k * n + j) * n + i;
        let mut cells = Vec::new();
        for k in 0..n - 1 {
            for j in 0..n - 1 {
                for i in 0..n - 1 {
                    cells.push(std::array::from_fn::<usize, 8, _>(|c| {
                        id(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))
                    }));
                }
            }
        }
        let pattern = BlockPattern::from_cells(n * n * n, cells.iter().map(|c| &c[..]));
        let mut values = vec![0.0; pattern.nnz()];
        for b in 0..n * n * n {
            for &a in &pattern.upper_neighbours[b] {
                let r = pattern.rank(a, b).unwrap();
                for k in 0..3 {
                    for i in 0..3 {
                        if a == b && i > k {
                            continue;
                        }
                        let off = -0.04 + 0.001 * ((a * 7 + b * 3 + i + k) % 5) as f64;
                        let v = if a == b && i == k { 4.0 } else { off };
                        values[pattern.position(r, b, i, k)] = v;
                    }
                }
            }
        }
        (pattern, values)
    }

    /// The factorisation times its first calls sequential and parallel, alternating, before it
    /// keeps the faster: the factors must be the same to the bit, or the results of a run
    /// would depend on the machine's load.
    #[test]
    fn sequential_and_parallel_factors_are_identical() {
        let (p, values) = grid_matrix(14);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            let mut chol = SparseCholesky::analyse(&p, 2).unwrap();
            let mut factors = Vec::new();
            let mut modes = Vec::new();
            for _ in 0..2 * PAR_TRIALS + 1 {
                modes.push(matches!(chol.factorise_par.next(), Par::Seq));
                chol.factorise(&values).unwrap();
                factors.push(chol.l_values.clone());
            }
            assert!(
                modes[..2 * PAR_TRIALS].iter().any(|&s| s),
                "a sequential trial"
            );
            assert!(
                modes[..2 * PAR_TRIALS].iter().any(|&s| !s),
                "a parallel trial"
            );
            assert!(matches!(chol.factorise_par, ParChoice::Fixed(_)), "settled");
            for (c, f) in factors.iter().enumerate() {
                let same = f
                    .iter()
                    .zip(&factors[0])
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "factor {c} differs from the first");
            }
        });
    }

    /// METIS keeps its random generator in a global: orderings computed on several threads
    /// at once (a sweep's concurrent cases) must still be the one computed alone.
    #[test]
    fn concurrent_orderings_equal_the_ordering_computed_alone() {
        let (p, _) = grid_matrix(9);
        let alone = metis_dof_ordering(&p).unwrap();
        std::thread::scope(|scope| {
            let workers: Vec<_> = (0..4)
                .map(|_| {
                    scope.spawn(|| {
                        (0..25)
                            .map(|_| metis_dof_ordering(&p).unwrap())
                            .all(|o| o == alone)
                    })
                })
                .collect();
            for w in workers {
                assert!(
                    w.join().unwrap(),
                    "an ordering differs from the one computed alone"
                );
            }
        });
    }

    /// A factorisation analysed without the rows and columns of held nodes (a face of a
    /// 6×6×4 grid of hexahedra, every direction held) solves the matrix with those rows and
    /// columns zero and a unit diagonal as the full analysis does (to 1e-12, round-off of a
    /// diagonally dominant matrix), with a smaller factor; with every off-diagonal entry
    /// dropped, it divides by the diagonal.
    #[test]
    fn held_rows_left_out_of_the_analysis_solve_alike() {
        let (nx, ny, nz) = (7, 7, 5);
        let id = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
        let mut cells = Vec::new();
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    let mut c = Vec::new();
                    for (di, dj, dk) in [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)] {
                        c.push(id(i + di, j + dj, k + dk));
                    }
                    for (di, dj, dk) in [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)] {
                        c.push(id(i + di, j + dj, k + dk));
                    }
                    cells.push(c);
                }
            }
        }
        let nodes = nx * ny * nz;
        let p = BlockPattern::from_cells(nodes, cells.iter().map(|c| &c[..]));
        let held = |d: usize| d / 3 < nx * ny;
        let mut values = vec![0.0; p.nnz()];
        let mut dropped = Vec::new();
        for j in 0..p.dim() {
            for q in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[q];
                values[q] = if i == j {
                    100.0 + (j % 5) as f64
                } else if held(i) || held(j) {
                    dropped.push(q);
                    0.0
                } else {
                    -1.0 + 0.1 * ((i + 2 * j) % 7) as f64
                };
            }
        }
        let mut full = SparseCholesky::analyse(&p, 1).unwrap();
        let mut pruned = SparseCholesky::analyse_without(&p, 1, &dropped).unwrap();
        assert!(
            pruned.factor_nnz() < full.factor_nnz(),
            "{} against {}",
            pruned.factor_nnz(),
            full.factor_nnz()
        );
        full.factorise(&values).unwrap();
        // The dropped entries are not read: garbage there changes nothing.
        let mut garbage = values.clone();
        for &q in &dropped {
            garbage[q] = 1e30;
        }
        pruned.factorise(&garbage).unwrap();
        // Three right-hand sides at once.
        let b: Vec<f64> = (0..3 * p.dim())
            .map(|i| ((i * 37) % 11) as f64 - 5.0)
            .collect();
        let (mut x_full, mut x_pruned) = (b.clone(), b);
        full.solve_in_place(&mut x_full);
        pruned.solve_in_place(&mut x_pruned);
        let err = max_difference(&x_full, &x_pruned);
        assert!(err < 1e-12, "max difference {err}");
        // Every row held: the factorisation is a division by the diagonal.
        let row_idx = &p.row_idx;
        let every: Vec<usize> = (0..p.dim())
            .flat_map(|j| (p.col_ptr[j]..p.col_ptr[j + 1]).filter(move |&q| row_idx[q] != j))
            .collect();
        let mut diagonal_only = SparseCholesky::analyse_without(&p, 1, &every).unwrap();
        assert_eq!(diagonal_only.factor_nnz(), 0);
        diagonal_only.factorise(&garbage).unwrap();
        let mut x: Vec<f64> = (0..p.dim()).map(|i| i as f64).collect();
        diagonal_only.solve_in_place(&mut x);
        for (i, v) in x.iter().enumerate() {
            let d = 100.0 + (i % 5) as f64;
            assert!((v - i as f64 / d).abs() <= 1e-15 * (i as f64), "{i}: {v}");
        }
    }

    /// The largest entry-wise difference between `a` and `b`.
    fn max_difference(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn cholesky_solves_many_right_hand_sides_to_round_off() {
        let n = 40;
        let (p, values) = chain_matrix(n);
        let mut chol = SparseCholesky::analyse(&p, 1).unwrap();
        chol.factorise(&values).unwrap();
        let dim = 3 * n;
        let ncols = 70; // more than one 64-column chunk
        let x_true: Vec<f64> = (0..dim * ncols)
            .map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0)
            .collect();
        let mut b = vec![0.0; dim * ncols];
        for c in 0..ncols {
            p.symmetric_matvec(
                &values,
                &x_true[c * dim..(c + 1) * dim],
                &mut b[c * dim..(c + 1) * dim],
            );
        }
        chol.solve_in_place(&mut b);
        let err = max_difference(&b, &x_true);
        assert!(err < 1e-12, "max error {err}");
    }

    #[test]
    fn extra_pairs_keep_every_value_in_place() {
        let (p, values) = chain_matrix(6);
        let (ext, map) = p.with_extra_pairs(&[(5, 0), (2, 4), (0, 5)]);
        assert_eq!(ext.nnz(), p.nnz() + 2 * 9);
        assert!(ext.rank(0, 5).is_some() && ext.rank(2, 4).is_some());
        let mut ext_values = vec![0.0; ext.nnz()];
        for (q, &v) in values.iter().enumerate() {
            assert_eq!(ext.row_idx[map[q]], p.row_idx[q]);
            ext_values[map[q]] = v;
        }
        // Same matrix, so the same product.
        let x: Vec<f64> = (0..18).map(|i| (i as f64 * 0.37).sin()).collect();
        let (mut y0, mut y1) = (vec![0.0; 18], vec![0.0; 18]);
        p.symmetric_matvec(&values, &x, &mut y0);
        ext.symmetric_matvec(&ext_values, &x, &mut y1);
        assert_eq!(y0, y1);
    }

    #[test]
    fn indefinite_matrix_is_reported_not_panicking() {
        let (p, mut values) = chain_matrix(3);
        values[p.diagonal_position(4)] = -10.0;
        let mut chol = SparseCholesky::analyse(&p, 1).unwrap();
        assert!(matches!(
            chol.factorise(&values),
            Err(LinalgError::NotPositiveDefinite)
        ));
    }

    /// GMRES solves an unsymmetric system to its tolerance, with and without a
    /// preconditioner, and a good preconditioner (here the matrix's own symmetric part,
    /// solved exactly) needs fewer iterations than none.
    #[test]
    fn gmres_solves_an_unsymmetric_system() {
        const LIMITS: KrylovLimits = KrylovLimits {
            tol: 1e-12,
            max_iter: 400,
            restart: 30,
        };
        let n = 40;
        let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            a[(i, i)] = 4.0 + (i % 7) as f64;
            if i + 1 < n {
                a[(i, i + 1)] = -1.0;
                a[(i + 1, i)] = -1.0;
                // The unsymmetric part.
                a[(i, i + 1)] += 0.5;
            }
        }
        let b: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64) - 5.0).collect();
        let exact = a
            .clone()
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&b))
            .unwrap();
        let apply = |v: &[f64], out: &mut [f64]| {
            let y = &a * nalgebra::DVector::from_column_slice(v);
            out.copy_from_slice(y.as_slice());
        };
        let (x, plain) = gmres(apply, |_| {}, &b, LIMITS);
        assert!(plain.relative_residual <= 1e-12, "{plain:?}");
        for (xi, ei) in x.iter().zip(exact.iter()) {
            assert!((xi - ei).abs() < 1e-10 * exact.norm(), "{xi} vs {ei}");
        }
        let sym_lu = ((&a + a.transpose()) * 0.5).lu();
        let precondition = |v: &mut [f64]| {
            let y = sym_lu
                .solve(&nalgebra::DVector::from_column_slice(v))
                .unwrap();
            v.copy_from_slice(y.as_slice());
        };
        let (x, pre) = gmres(apply, precondition, &b, LIMITS);
        assert!(pre.relative_residual <= 1e-12, "{pre:?}");
        assert!(pre.iterations < plain.iterations, "{pre:?} vs {plain:?}");
        for (xi, ei) in x.iter().zip(exact.iter()) {
            assert!((xi - ei).abs() < 1e-10 * exact.norm(), "{xi} vs {ei}");
        }
        // The same with the Krylov vectors formed from the remainder E = A − M alone
        // (M the symmetric part): the same solution to the same tolerance, in as many
        // iterations (the Krylov spaces are the same in exact arithmetic).
        let e = (&a - a.transpose()) * 0.5;
        let remainder = |v: &[f64], out: &mut [f64]| {
            let y = &e * nalgebra::DVector::from_column_slice(v);
            out.copy_from_slice(y.as_slice());
        };
        let (x, split) = gmres_with_remainder(apply, remainder, precondition, &b, LIMITS);
        assert!(split.relative_residual <= 1e-12, "{split:?}");
        assert!(
            split.iterations <= pre.iterations + 1,
            "{split:?} vs {pre:?}"
        );
        for (xi, ei) in x.iter().zip(exact.iter()) {
            assert!((xi - ei).abs() < 1e-10 * exact.norm(), "{xi} vs {ei}");
        }
    }
}

/// Runs `call`, a call into faer with parallelism `par`, then clears the upper halves of the
/// vector registers (`vzeroupper`) on this thread and, when `par` ran work on the rayon pool,
/// on every thread of the pool. Every call into faer's factorisations and solves goes
/// through it.
///
/// faer's supernodal kernels run AVX/AVX-512 code (detected at run time) and can return with
/// the registers' upper halves in use. adhesim itself is compiled for baseline x86-64, with
/// SSE instructions, and on processors that track that state every SSE instruction then
/// waits on the upper halves: the element kernels ran twice as slowly after a supernodal
/// factorisation (the README example's assembly took 28 s instead of 13 s) until they were
/// cleared. Without AVX, or on another architecture, clearing does nothing.
pub fn faer_call<T>(par: Par, call: impl FnOnce() -> T) -> T {
    let out = call();
    clear_this_thread();
    if let Par::Rayon(_) = par {
        rayon::broadcast(|_| clear_this_thread());
    }
    out
}

#[inline]
fn clear_this_thread() {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx")]
        unsafe fn zero_upper() {
            std::arch::x86_64::_mm256_zeroupper();
        }
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the processor has AVX (checked above), the only requirement of the
            // instruction.
            unsafe { zero_upper() }
        }
    }
}
