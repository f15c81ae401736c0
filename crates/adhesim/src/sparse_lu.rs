//! A sparse LU factorisation with partial pivoting and a column ordering given by the caller
//! (e.g. METIS nested dissection of a structurally symmetric matrix), whose symbolic analysis
//! is reused across numeric factorisations of matrices with the same pattern.
//!
//! faer's high-level sparse LU always orders the columns by COLAMD; on the mixed
//! (displacement, force) matrices of the contact solve, which are structurally symmetric
//! finite-element matrices, nested dissection gives much less fill.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::supernodal::{
    factorize_supernodal_numeric_lu, factorize_supernodal_numeric_lu_scratch,
    factorize_supernodal_symbolic_lu, factorize_supernodal_symbolic_lu_scratch, SupernodalLu,
    SymbolicSupernodalLu,
};
use faer::sparse::linalg::qr::{
    col_etree, col_etree_scratch, column_counts_aat_scratch, column_counts_ata, postorder,
    postorder_scratch,
};
use faer::sparse::linalg::SymbolicSupernodalParams;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Spec};

use crate::linalg::{faer_call, LinalgError};

/// The LU factors of a square sparse matrix with a fixed pattern and column ordering.
pub struct OrderedLu {
    pattern: SymbolicSparseColMat<usize>,
    transposed: SymbolicSparseColMat<usize>,
    /// Position in the transposed values of each value of the matrix.
    to_transposed: Vec<usize>,
    col_fwd: Vec<usize>,
    col_inv: Vec<usize>,
    row_fwd: Vec<usize>,
    row_inv: Vec<usize>,
    symbolic: SymbolicSupernodalLu<usize>,
    lu: SupernodalLu<usize, f64>,
    mem: MemBuffer,
    transposed_values: Vec<f64>,
    factorised: bool,
}

impl OrderedLu {
    /// Symbolic analysis of the square matrix with compressed columns (`col_ptr`, `row_idx`,
    /// rows sorted within each column) under the column ordering (`col_fwd`, `col_inv`).
    pub fn analyse(
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        col_fwd: Vec<usize>,
        col_inv: Vec<usize>,
    ) -> Result<Self, LinalgError> {
        let n = col_ptr.len() - 1;
        let fail = |e: &dyn std::fmt::Debug| LinalgError::Symbolic(format!("{e:?}"));
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let (transposed, to_transposed) = transpose(&pattern);
        let perm = PermRef::new_checked(&col_fwd, &col_inv, n);
        let req = StackReq::any_of(&[
            col_etree_scratch::<usize>(n, n),
            postorder_scratch::<usize>(n),
            column_counts_aat_scratch::<usize>(n, n),
            factorize_supernodal_symbolic_lu_scratch::<usize>(n, n),
        ]);
        let mut mem = MemBuffer::try_new(req).map_err(|e| fail(&e))?;
        let mut etree = vec![0usize; n];
        let mut post = vec![0usize; n];
        let mut col_counts = vec![0usize; n];
        let mut min_row = vec![0usize; n];
        let stack = MemStack::new(&mut mem);
        let tree = col_etree(pattern.as_ref(), Some(perm), &mut etree, stack);
        let stack = MemStack::new(&mut mem);
        postorder(&mut post, tree, stack);
        let stack = MemStack::new(&mut mem);
        column_counts_ata(
            &mut col_counts,
            &mut min_row,
            transposed.as_ref(),
            Some(perm),
            tree,
            &post,
            stack,
        );
        let stack = MemStack::new(&mut mem);
        let symbolic = factorize_supernodal_symbolic_lu(
            pattern.as_ref(),
            Some(perm),
            &min_row,
            tree,
            &col_counts,
            stack,
            SymbolicSupernodalParams::default(),
        )
        .map_err(|e| fail(&e))?;
        let req = factorize_supernodal_numeric_lu_scratch::<usize, f64>(&symbolic, Spec::default());
        let req = StackReq::any_of(&[
            req,
            faer::sparse::linalg::lu::supernodal::solve_in_place_scratch::<usize, f64>(
                n,
                1,
                Par::Seq,
            ),
            StackReq::new::<f64>(n),
        ]);
        let nnz = to_transposed.len();
        Ok(OrderedLu {
            pattern,
            transposed,
            to_transposed,
            col_fwd,
            col_inv,
            row_fwd: vec![0; n],
            row_inv: vec![0; n],
            symbolic,
            lu: SupernodalLu::new(),
            mem: MemBuffer::try_new(req).map_err(|e| fail(&e))?,
            transposed_values: vec![0.0; nnz],
            factorised: false,
        })
    }

    /// Numeric factorisation of the matrix with the analysed pattern and `values`.
    pub fn factorise(&mut self, values: &[f64]) -> Result<(), LinalgError> {
        self.factorised = false;
        for (v, &t) in values.iter().zip(&self.to_transposed) {
            self.transposed_values[t] = *v;
        }
        let a = SparseColMatRef::new(self.pattern.as_ref(), values);
        let at = SparseColMatRef::new(self.transposed.as_ref(), &self.transposed_values);
        let perm = PermRef::new_checked(&self.col_fwd, &self.col_inv, self.col_fwd.len());
        let stack = MemStack::new(&mut self.mem);
        let par = Par::rayon(0);
        faer_call(par, || {
            factorize_supernodal_numeric_lu(
                &mut self.row_fwd,
                &mut self.row_inv,
                &mut self.lu,
                a,
                at,
                perm,
                &self.symbolic,
                par,
                stack,
                Spec::default(),
            )
        })
        .map_err(|_| LinalgError::NotPositiveDefinite)?;
        self.factorised = true;
        Ok(())
    }

    /// Solves A x = b in place.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(self.factorised, "solve before a successful factorisation");
        let n = rhs.len();
        let rows = PermRef::new_checked(&self.row_fwd, &self.row_inv, n);
        let cols = PermRef::new_checked(&self.col_fwd, &self.col_inv, n);
        let stack = MemStack::new(&mut self.mem);
        faer_call(Par::Seq, || {
            self.lu.solve_in_place_with_conj(
                rows,
                cols,
                Conj::No,
                MatMut::from_column_major_slice_mut(rhs, n, 1),
                Par::Seq,
                stack,
            )
        });
    }
}

/// The pattern of Aᵀ and the position in it of each entry of A.
fn transpose(a: &SymbolicSparseColMat<usize>) -> (SymbolicSparseColMat<usize>, Vec<usize>) {
    let n = a.nrows();
    let (cp, ri) = (a.col_ptr(), a.row_idx());
    let mut count = vec![0usize; n + 1];
    for &i in ri {
        count[i + 1] += 1;
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let col_ptr = count.clone();
    let mut next = count;
    let mut row_idx = vec![0usize; ri.len()];
    let mut pos = vec![0usize; ri.len()];
    for j in 0..n {
        for q in cp[j]..cp[j + 1] {
            let i = ri[q];
            row_idx[next[i]] = j;
            pos[q] = next[i];
            next[i] += 1;
        }
    }
    (
        SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
        pos,
    )
}
