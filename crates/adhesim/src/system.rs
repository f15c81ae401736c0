//! The step's sparse system matrix K̄ and its factorisation: the element pattern, extended by
//! the couplings that contact adds between slave nodes and the nodes of the master faces they
//! touch, with every Dirichlet condition applied by zeroing the constrained rows and columns.
//!
//! The extension only grows: a coupling, once added, stays, so the symbolic analysis (METIS
//! ordering and elimination tree) is redone only when contact reaches a face pair it has never
//! touched before, not at every step.
//!
//! Nodes may be tied: node n then has the unknowns of its representative `rep[n]` (the nodes
//! of a line through a plane-strain slab, docs/model.md §1). The matrix factorised is Tᵀ K̄ T
//! for that map T, in which a tied node keeps only a unit diagonal; solving adds a tied node's
//! right-hand side to its representative's and copies the solution back.

use crate::linalg::{
    gmres, BlockPattern, KrylovLimits, KrylovOutcome, LinalgError, LinearSolve, SparseCholesky,
};
use std::collections::BTreeSet;

/// K̄ in the (possibly extended) pattern, with its factorisation.
pub struct SystemMatrix {
    /// Representative of each node (itself unless tied).
    rep: Vec<usize>,
    /// The tied nodes with their representatives.
    tied_nodes: Vec<(usize, usize)>,
    /// The element pattern with the ties applied.
    tied: BlockPattern,
    /// The pattern in use: `tied` plus `couplings`.
    pattern: BlockPattern,
    /// Position in `tied` and factor of each value of the element pattern (what the
    /// assembly fills).
    base_to_tied: Vec<(usize, f64)>,
    /// Position in `pattern` of each value of `tied` (None while the two are the same).
    tied_to_ext: Option<Vec<usize>>,
    /// Node couplings added by contact, as (smaller, larger) representative nodes.
    couplings: BTreeSet<(usize, usize)>,
    /// Whether each scalar unknown has a zero row and column with a positive diagonal in the
    /// factorised matrix: prescribed unknowns and those of tied nodes.
    fixed: Vec<bool>,
    /// Off-diagonal positions in a fixed row or column (zeroed).
    zero_positions: Vec<usize>,
    /// Values of K̄ in `pattern` (upper triangle).
    values: Vec<f64>,
    chol: SparseCholesky,
    /// Symbolic analyses done since the start (1 for the element pattern).
    pub analyses: usize,
    /// Numeric factorisations done since the start.
    pub factorisations: usize,
    /// What the factorisation in use was made from, as its maker describes it (see
    /// [`Self::factorise_keyed`]); None when unknown or when there is none.
    factor_key: Option<u64>,
}

impl SystemMatrix {
    /// Analyses the element pattern with the prescribed unknowns `constrained` and the node
    /// representatives `rep` (`rep[n] == n` for a node that is not tied; a tied node and its
    /// representative must have the same prescribed components).
    pub fn new(
        base: BlockPattern,
        constrained: Vec<bool>,
        rep: Vec<usize>,
    ) -> Result<Self, LinalgError> {
        let (tied, base_to_tied) = base.condensed(&rep);
        let fixed: Vec<bool> = constrained
            .iter()
            .enumerate()
            .map(|(d, &c)| c || rep[d / 3] != d / 3)
            .collect();
        let zero_positions = zero_positions(&tied, &fixed);
        let chol = SparseCholesky::analyse_without(&tied, 0, &zero_positions)?;
        let tied_nodes = (0..rep.len())
            .filter(|&t| rep[t] != t)
            .map(|t| (t, rep[t]))
            .collect();
        Ok(SystemMatrix {
            tied_nodes,
            values: vec![0.0; tied.nnz()],
            pattern: tied.clone(),
            rep,
            tied,
            base_to_tied,
            tied_to_ext: None,
            couplings: BTreeSet::new(),
            fixed,
            zero_positions,
            chol,
            analyses: 1,
            factorisations: 0,
            factor_key: None,
        })
    }

    /// Makes sure the pattern holds the node couplings `pairs`; re-analyses when it grows.
    pub fn ensure_couplings(&mut self, pairs: &[(usize, usize)]) -> Result<(), LinalgError> {
        let mut grew = false;
        for &(a, b) in pairs {
            let (a, b) = (self.rep[a], self.rep[b]);
            let key = (a.min(b), a.max(b));
            if key.0 != key.1 && self.tied.rank(key.0, key.1).is_none() {
                grew |= self.couplings.insert(key);
            }
        }
        if !grew {
            return Ok(());
        }
        let all: Vec<(usize, usize)> = self.couplings.iter().copied().collect();
        let (ext, map) = self.tied.with_extra_pairs(&all);
        self.zero_positions = zero_positions(&ext, &self.fixed);
        self.chol = SparseCholesky::analyse_without(&ext, 0, &self.zero_positions)?;
        self.values = vec![0.0; ext.nnz()];
        self.pattern = ext;
        self.tied_to_ext = Some(map);
        self.analyses += 1;
        self.factor_key = None;
        Ok(())
    }

    /// Sets K̄ = Σ cᵢ Aᵢ from matrices in the element pattern (`terms` of (c, values)).
    pub fn set_from_base(&mut self, terms: &[(f64, &[f64])]) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let ext = self.tied_to_ext.as_deref();
        for (q, &(slot, factor)) in self.base_to_tied.iter().enumerate() {
            let slot = ext.map_or(slot, |map| map[slot]);
            let v: f64 = terms.iter().map(|(c, a)| c * a[q]).sum();
            self.values[slot] += factor * v;
        }
    }

    /// Adds the block K_ab [N/m] coupling the unknowns of nodes a and b (and, for a ≠ b, its
    /// transpose K_ba); for a = b the block must be symmetric. The pattern must hold the
    /// coupling (see [`Self::ensure_couplings`]).
    pub fn add_block(&mut self, a: usize, b: usize, block: &[[f64; 3]; 3]) {
        let (ra, rb) = (self.rep[a], self.rep[b]);
        let p = &self.pattern;
        let mut add = |i: usize, j: usize, v: f64| self.values[p.scalar_position(i, j)] += v;
        if ra == rb {
            // K_aa, or K_ab + K_ba on the representative's diagonal block.
            for i in 0..3 {
                for k in i..3 {
                    let v = if a == b {
                        block[i][k]
                    } else {
                        block[i][k] + block[k][i]
                    };
                    add(3 * ra + i, 3 * ra + k, v);
                }
            }
        } else {
            for i in 0..3 {
                for k in 0..3 {
                    add(3 * ra + i, 3 * rb + k, block[i][k]);
                }
            }
        }
    }

    /// Applies the Dirichlet conditions and the ties (zero fixed rows and columns, a positive
    /// diagonal) and factorises.
    pub fn factorise(&mut self) -> Result<(), LinalgError> {
        self.apply_conditions();
        self.factor_key = None;
        self.factorisations += 1;
        self.chol.factorise(&self.values)
    }

    /// [`Self::factorise`], recording `key` (a hash of what the caller built the matrix
    /// from, e.g. the step size and the contact cases) so that a later caller can tell
    /// whether the factor still fits ([`Self::factor_key`]).
    pub fn factorise_keyed(&mut self, key: u64) -> Result<(), LinalgError> {
        self.factorise()?;
        self.factor_key = Some(key);
        Ok(())
    }

    /// The key the factorisation in use was made with by [`Self::factorise_keyed`]; None
    /// when there is no factorisation, or it was made otherwise.
    pub fn factor_key(&self) -> Option<u64> {
        self.factor_key.filter(|_| self.chol.is_factorised())
    }

    /// Applies the Dirichlet conditions and the ties to the values, as [`Self::factorise`]
    /// does before it factorises.
    pub fn apply_conditions(&mut self) {
        for &q in &self.zero_positions {
            self.values[q] = 0.0;
        }
        for d in 0..self.fixed.len() {
            if self.fixed[d] {
                let q = self.pattern.diagonal_position(d);
                if !(self.values[q] > 0.0) {
                    self.values[q] = 1.0;
                }
            }
        }
    }

    /// Moves a right-hand side `rhs` (all unknowns) onto the factorised system's unknowns:
    /// a tied node's part is added to its representative's (as [`Self::solve_in_place`]
    /// does), and the fixed unknowns' parts are set to zero.
    pub fn condense(&self, rhs: &mut [f64]) {
        for &(t, r) in &self.tied_nodes {
            for k in 0..3 {
                rhs[3 * r + k] += rhs[3 * t + k];
                rhs[3 * t + k] = 0.0;
            }
        }
        for (v, &fixed) in rhs.iter_mut().zip(&self.fixed) {
            if fixed {
                *v = 0.0;
            }
        }
    }

    /// The matrix: its pattern (upper triangle) and values, those last factorised or last
    /// given the Dirichlet conditions and the ties by [`Self::apply_conditions`].
    pub fn matrix(&self) -> (&BlockPattern, &[f64]) {
        (&self.pattern, &self.values)
    }

    /// The representative node of each node.
    pub fn representatives(&self) -> &[usize] {
        &self.rep
    }

    /// Whether each scalar unknown has a zero row and column with a positive diagonal in the
    /// factorised matrix (prescribed, or of a tied node).
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }

    /// Replaces the matrix's values by `values` (e.g. those of [`Self::matrix`]
    /// kept from an earlier factorisation); factorise again before solving.
    pub fn set_values(&mut self, values: &[f64]) {
        self.values.copy_from_slice(values);
    }

    /// The pattern in use (upper triangle).
    pub fn pattern(&self) -> &BlockPattern {
        &self.pattern
    }

    /// The factorised matrix for products (pattern, upper-triangle values) and its
    /// factorisation for solves, borrowed apart so that an iterative solve preconditioned by
    /// the factorisation can use both. Both act on the matrix as factorised, ties included
    /// (vectors on the representatives' unknowns, zero on the tied nodes' own).
    pub fn operator_and_factor(&mut self) -> (&BlockPattern, &[f64], &mut SparseCholesky) {
        (&self.pattern, &self.values, &mut self.chol)
    }

    /// Copies the unknowns of each representative to the nodes tied to it.
    pub fn expand_tied(&self, v: &mut [f64]) {
        for &(t, r) in &self.tied_nodes {
            for k in 0..3 {
                v[3 * t + k] = v[3 * r + k];
            }
        }
    }

    /// Solves K̄ x = b in place, for one or more right-hand sides (column-major).
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let (n, tied) = (self.fixed.len(), &self.tied_nodes);
        if n == 0 {
            return;
        }
        for col in rhs.chunks_exact_mut(n) {
            for &(t, r) in tied {
                for k in 0..3 {
                    col[3 * r + k] += col[3 * t + k];
                    col[3 * t + k] = 0.0;
                }
            }
        }
        self.chol.solve_in_place(rhs);
        for col in rhs.chunks_exact_mut(n) {
            for &(t, r) in tied {
                for k in 0..3 {
                    col[3 * t + k] = col[3 * r + k];
                }
            }
        }
    }
}

impl SystemMatrix {
    /// Solves K̄ x = b in place by GMRES on the matrix as its values now are (the Dirichlet
    /// conditions and ties applied, [`Self::apply_conditions`]), preconditioned by the
    /// factorisation in use, which may be of earlier values (docs/scaling.md). `rhs` holds b
    /// on all unknowns, as for [`Self::solve_in_place`]; on return it holds GMRES's x, with
    /// the tied nodes' unknowns copied from their representatives'. Needs a factorisation.
    pub fn solve_preconditioned(&mut self, rhs: &mut [f64], limits: KrylovLimits) -> KrylovOutcome {
        for &(t, r) in &self.tied_nodes {
            for k in 0..3 {
                rhs[3 * r + k] += rhs[3 * t + k];
                rhs[3 * t + k] = 0.0;
            }
        }
        let (pattern, values, factor) = (&self.pattern, &self.values, &mut self.chol);
        let apply = |v: &[f64], out: &mut [f64]| {
            out.iter_mut().for_each(|o| *o = 0.0);
            pattern.symmetric_matvec(values, v, out);
        };
        let (x, outcome) = gmres(apply, |v| factor.solve_in_place(v), rhs, limits);
        rhs.copy_from_slice(&x);
        self.expand_tied(rhs);
        outcome
    }
}

impl LinearSolve for SystemMatrix {
    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        SystemMatrix::solve_in_place(self, rhs);
    }
}

/// Off-diagonal positions of `pattern` in a fixed row or column.
fn zero_positions(pattern: &BlockPattern, fixed: &[bool]) -> Vec<usize> {
    let mut out = Vec::new();
    for j in 0..pattern.dim() {
        for q in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            let i = pattern.row_idx[q];
            if i != j && (fixed[i] || fixed[j]) {
                out.push(q);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coupled_system_solves_like_the_dense_matrix() {
        // Two separate 2-node bars (nodes 0-1 and 2-3) coupled by a contact spring 1-2.
        let cells = [[0usize, 1], [2, 3]];
        let base = BlockPattern::from_cells(4, cells.iter().map(|c| &c[..]));
        let mut constrained = vec![false; 12];
        constrained[0..3].iter_mut().for_each(|c| *c = true); // node 0 fixed
        let mut sys = SystemMatrix::new(base.clone(), constrained, (0..4).collect()).unwrap();
        let mut k = vec![0.0; base.nnz()];
        for c in cells {
            for &b in &c {
                for &a in &c {
                    if a > b {
                        continue;
                    }
                    let r = base.rank(a, b).unwrap();
                    for kk in 0..3 {
                        let rows = if a == b { kk + 1 } else { 3 };
                        for i in 0..rows {
                            if i == kk {
                                k[base.position(r, b, i, kk)] = if a == b { 2.0 } else { -1.0 };
                            }
                        }
                    }
                }
            }
        }
        sys.ensure_couplings(&[(2, 1)]).unwrap();
        assert_eq!(sys.analyses, 2);
        sys.ensure_couplings(&[(1, 2)]).unwrap();
        assert_eq!(sys.analyses, 2, "a known coupling does not re-analyse");
        sys.set_from_base(&[(1.0, &k)]);
        // Contact spring of stiffness 1 along x between nodes 1 and 2.
        let x_spring = |k: f64| [[k, 0.0, 0.0], [0.0; 3], [0.0; 3]];
        sys.add_block(1, 2, &x_spring(-1.0));
        for n in [1, 2] {
            sys.add_block(n, n, &x_spring(1.0));
        }
        sys.factorise().unwrap();
        // Pull node 3 along x by 1: springs 0-1, 1-2, 2-3 in series (k = 2, 1, 2 at the free
        // end the diagonal 2 of the last node includes the spring to nothing: k33 = 2).
        let mut b = vec![0.0; 12];
        b[9] = 1.0;
        sys.solve_in_place(&mut b);
        // Dense check: x-unknowns of nodes 1, 2, 3 with matrix [[3, -1, 0], [-1, 3, -1],
        // [0, -1, 2]] and right-hand side (0, 0, 1).
        let det = 3.0 * (3.0 * 2.0 - 1.0) - (-1.0) * (-1.0 * 2.0);
        let x3 = (3.0 * 3.0 - 1.0) / det;
        assert!((b[9] - x3).abs() < 1e-14, "{} vs {x3}", b[9]);
        assert_eq!(b[0], 0.0);
    }

    /// Nodes 2 and 3 tied to nodes 0 and 1, z held everywhere (a plane-strain slab of one
    /// element): the solve equals the dense solve of Tᵀ K T y = Tᵀ b with x = T y, to
    /// round-off, with an element matrix and a contact block between tied nodes added.
    #[test]
    fn tied_nodes_solve_the_condensed_system() {
        let cell = [0usize, 1, 2, 3];
        let base = BlockPattern::from_cells(4, std::iter::once(&cell[..]));
        let constrained: Vec<bool> = (0..12).map(|d| d % 3 == 2).collect();
        let mut sys =
            SystemMatrix::new(base.clone(), constrained.clone(), vec![0, 1, 0, 1]).unwrap();
        // A dense SPD K = AᵀA + 12 I with a fixed uneven A, stored in the element pattern.
        let a: Vec<f64> = (0..144)
            .map(|k| ((k * 29 % 13) as f64 - 6.0) * 0.1)
            .collect();
        let mut k = vec![vec![0.0; 12]; 12];
        for (i, row) in k.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..12).map(|r| a[r * 12 + i] * a[r * 12 + j]).sum::<f64>()
                    + if i == j { 12.0 } else { 0.0 };
            }
        }
        let mut values = vec![0.0; base.nnz()];
        for bn in 0..4 {
            for an in 0..=bn {
                let r = base.rank(an, bn).unwrap();
                for kk in 0..3 {
                    let rows = if an == bn { kk + 1 } else { 3 };
                    for i in 0..rows {
                        values[base.position(r, bn, i, kk)] = k[3 * an + i][3 * bn + kk];
                    }
                }
            }
        }
        sys.set_from_base(&[(1.0, &values)]);
        // A contact block between node 0 and its tied twin 2, and one between 1 and 2.
        let c02 = [[2.0, 0.5, 0.0], [0.25, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let c12 = [[-1.0, 0.0, 0.0], [0.0, -0.5, 0.0], [0.0, 0.0, 0.0]];
        sys.add_block(0, 2, &c02);
        sys.add_block(1, 2, &c12);
        for (an, bn, c) in [(0, 2, c02), (1, 2, c12)] {
            for i in 0..3 {
                for j in 0..3 {
                    k[3 * an + i][3 * bn + j] += c[i][j];
                    k[3 * bn + j][3 * an + i] += c[i][j];
                }
            }
        }
        sys.factorise().unwrap();
        let b: Vec<f64> = (0..12)
            .map(|d| if d % 3 == 2 { 0.0 } else { 1.0 + d as f64 })
            .collect();
        let mut x = b.clone();
        sys.solve_in_place(&mut x);
        // Dense reference over the free unknowns (x, y of nodes 0 and 1): T maps (node 0,
        // node 1) to all four nodes.
        let free = [0usize, 1, 3, 4];
        let t = |d: usize| d % 6; // the representative unknown of unknown d
        let mut kc = nalgebra::DMatrix::<f64>::zeros(4, 4);
        let mut bc = nalgebra::DVector::<f64>::zeros(4);
        for i in (0..12).filter(|d| d % 3 != 2) {
            let ri = free.iter().position(|&f| f == t(i)).unwrap();
            bc[ri] += b[i];
            for j in (0..12).filter(|d| d % 3 != 2) {
                let rj = free.iter().position(|&f| f == t(j)).unwrap();
                kc[(ri, rj)] += k[i][j];
            }
        }
        let y = kc.lu().solve(&bc).expect("regular");
        for d in 0..12 {
            let expected = if d % 3 == 2 {
                0.0
            } else {
                y[free.iter().position(|&f| f == t(d)).unwrap()]
            };
            assert!(
                (x[d] - expected).abs() <= 1e-12 * expected.abs().max(1e-3),
                "unknown {d}: {} against {expected}",
                x[d]
            );
        }
    }
}
