//! The step's sparse system matrix K̄ and its factorisation: the element pattern, extended by
//! the couplings that contact adds between slave nodes and the nodes of the master faces they
//! touch, with every Dirichlet condition applied by zeroing the constrained rows and columns.
//!
//! The extension only grows: a coupling, once added, stays, so the symbolic analysis (METIS
//! ordering and elimination tree) is redone only when contact reaches a face pair it has never
//! touched before, not at every step.

use crate::linalg::{BlockPattern, LinalgError, SparseCholesky};
use std::collections::BTreeSet;

/// K̄ in the (possibly extended) pattern, with its factorisation.
pub struct SystemMatrix {
    /// The element pattern (what the assembly fills).
    base: BlockPattern,
    /// The pattern in use: `base` plus `couplings`.
    pattern: BlockPattern,
    /// Position in `pattern` of each value of `base` (None while the two are the same).
    base_to_ext: Option<Vec<usize>>,
    /// Node couplings added by contact, as (smaller, larger) node indices.
    couplings: BTreeSet<(usize, usize)>,
    /// Whether each scalar unknown is prescribed.
    constrained: Vec<bool>,
    /// Off-diagonal positions in a constrained row or column (zeroed).
    zero_positions: Vec<usize>,
    /// Values of K̄ in `pattern` (upper triangle).
    pub values: Vec<f64>,
    chol: SparseCholesky,
    /// Symbolic analyses done since the start (1 for the element pattern).
    pub analyses: usize,
}

impl SystemMatrix {
    /// Analyses the element pattern.
    pub fn new(base: BlockPattern, constrained: Vec<bool>) -> Result<Self, LinalgError> {
        let chol = SparseCholesky::analyse(&base, 0)?;
        let zero_positions = zero_positions(&base, &constrained);
        Ok(SystemMatrix {
            values: vec![0.0; base.nnz()],
            pattern: base.clone(),
            base,
            base_to_ext: None,
            couplings: BTreeSet::new(),
            constrained,
            zero_positions,
            chol,
            analyses: 1,
        })
    }

    /// The pattern in use.
    pub fn pattern(&self) -> &BlockPattern {
        &self.pattern
    }

    /// Makes sure the pattern holds the node couplings `pairs`; re-analyses when it grows.
    pub fn ensure_couplings(&mut self, pairs: &[(usize, usize)]) -> Result<(), LinalgError> {
        let mut grew = false;
        for &(a, b) in pairs {
            let key = (a.min(b), a.max(b));
            if key.0 != key.1 && self.base.rank(key.0, key.1).is_none() {
                grew |= self.couplings.insert(key);
            }
        }
        if !grew {
            return Ok(());
        }
        let all: Vec<(usize, usize)> = self.couplings.iter().copied().collect();
        let (ext, map) = self.base.with_extra_pairs(&all);
        self.chol = SparseCholesky::analyse(&ext, 0)?;
        self.zero_positions = zero_positions(&ext, &self.constrained);
        self.values = vec![0.0; ext.nnz()];
        self.pattern = ext;
        self.base_to_ext = Some(map);
        self.analyses += 1;
        Ok(())
    }

    /// Sets K̄ = Σ cᵢ Aᵢ from matrices in the element pattern (`terms` of (c, values)).
    pub fn set_from_base(&mut self, terms: &[(f64, &[f64])]) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (q, slot) in
            (0..self.base.nnz()).map(|q| (q, self.base_to_ext.as_ref().map_or(q, |map| map[q])))
        {
            self.values[slot] = terms.iter().map(|(c, a)| c * a[q]).sum();
        }
    }

    /// Applies the Dirichlet conditions (zero constrained rows and columns, a positive
    /// diagonal) and factorises.
    pub fn factorise(&mut self) -> Result<(), LinalgError> {
        for &q in &self.zero_positions {
            self.values[q] = 0.0;
        }
        for d in 0..self.constrained.len() {
            if self.constrained[d] {
                let q = self.pattern.diagonal_position(d);
                if !(self.values[q] > 0.0) {
                    self.values[q] = 1.0;
                }
            }
        }
        self.chol.factorise(&self.values)
    }

    /// The factorisation (after [`Self::factorise`]).
    pub fn cholesky(&mut self) -> &mut SparseCholesky {
        &mut self.chol
    }

    /// Solves K̄ x = b in place.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        self.chol.solve_in_place(rhs);
    }
}

/// Off-diagonal positions of `pattern` in a row or column of a constrained unknown.
fn zero_positions(pattern: &BlockPattern, constrained: &[bool]) -> Vec<usize> {
    let mut out = Vec::new();
    for j in 0..pattern.dim() {
        for q in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            let i = pattern.row_idx[q];
            if i != j && (constrained[i] || constrained[j]) {
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
        let mut sys = SystemMatrix::new(base.clone(), constrained).unwrap();
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
        let p = sys.pattern().clone();
        let r = p.rank(1, 2).unwrap();
        sys.values[p.position(r, 2, 0, 0)] -= 1.0;
        for n in [1, 2] {
            let q = p.position(p.rank(n, n).unwrap(), n, 0, 0);
            sys.values[q] += 1.0;
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
}
