//! The reduced (Delassus) dry contact problem on its own, without a mesh:
//! x = q + W r at every contact point, with the Signorini–Coulomb law in its bi-potential form
//! between r and x (the problem of fclib's local files and of Siconos's `fc3d` solvers).
//!
//! W is stored in 3×3 blocks, one per pair of contact points that interact, rows by point
//! ([`BlockSparseDelassus`]); components are ordered (t1, t2, n) with `r_n > 0` compression and
//! `x_n ≥ 0` apart, as in [`crate::contact::law`]. The nonlinear Gauss–Seidel sweep on this
//! storage is in [`super::gauss_seidel::reduced`], the semismooth Newton method in
//! [`super::semismooth::reduced`]. Both stop on Siconos's relative error ([`error_of`]:
//! [`relative_error`] of [`natural_map_residual`]).

use super::natural_map::{natural_map_residual, relative_error};

type M3 = [[f64; 3]; 3];

/// A symmetric Delassus operator in 3×3 blocks, compressed by block rows.
#[derive(Clone, Debug)]
pub struct BlockSparseDelassus {
    points: usize,
    /// Start of each block row in `cols`/`blocks` (points + 1 entries).
    row_start: Vec<usize>,
    /// Block column of each stored block, increasing within a row.
    cols: Vec<usize>,
    /// The stored blocks, row-major 3×3.
    blocks: Vec<M3>,
    /// Index of the diagonal block of each row (always stored, zero if absent from the input).
    diag: Vec<usize>,
}

impl BlockSparseDelassus {
    /// Builds W for `points` contact points from scalar entries (row, column, value), indices
    /// 3·point + component with components (t1, t2, n). Repeated entries are summed.
    ///
    /// # Panics
    /// If an index is ≥ 3·points.
    pub fn from_entries(
        points: usize,
        entries: impl IntoIterator<Item = (usize, usize, f64)>,
    ) -> Self {
        let m = 3 * points;
        // (block row, block column, 3·a + b, value), the diagonal blocks added so that each
        // point has its own block to solve with.
        let keyed: Vec<(usize, usize, usize, f64)> = entries
            .into_iter()
            .map(|(i, j, v)| {
                assert!(
                    i < m && j < m,
                    "entry ({i}, {j}) outside a {m}×{m} operator"
                );
                (i / 3, j / 3, 3 * (i % 3) + j % 3, v)
            })
            .chain((0..points).map(|p| (p, p, 0, 0.0)))
            .collect();
        // Bucketed by block row (a counting sort), then each row, short, sorted by column.
        let mut bucket = vec![0usize; points + 1];
        for e in &keyed {
            bucket[e.0 + 1] += 1;
        }
        for p in 0..points {
            bucket[p + 1] += bucket[p];
        }
        let mut by_row = vec![(0usize, 0usize, 0.0f64); keyed.len()];
        let mut next = bucket.clone();
        for (bi, bj, ab, v) in keyed {
            by_row[next[bi]] = (bj, ab, v);
            next[bi] += 1;
        }
        let mut row_start = vec![0; points + 1];
        let mut cols = Vec::new();
        let mut blocks: Vec<M3> = Vec::new();
        for p in 0..points {
            let row = &mut by_row[bucket[p]..bucket[p + 1]];
            row.sort_unstable_by_key(|e| e.0);
            let mut last = None;
            for &(bj, ab, v) in row.iter() {
                if last != Some(bj) {
                    cols.push(bj);
                    blocks.push([[0.0; 3]; 3]);
                    row_start[p + 1] += 1;
                    last = Some(bj);
                }
                blocks.last_mut().expect("a block was pushed")[ab / 3][ab % 3] += v;
            }
        }
        for p in 0..points {
            row_start[p + 1] += row_start[p];
        }
        let diag = (0..points)
            .map(|p| {
                (row_start[p]..row_start[p + 1])
                    .find(|&k| cols[k] == p)
                    .expect("diagonal block stored")
            })
            .collect();
        Self {
            points,
            row_start,
            cols,
            blocks,
            diag,
        }
    }

    /// Builds W from a dense row-major 3N × 3N matrix, keeping the nonzero 3×3 blocks.
    ///
    /// # Panics
    /// If `w.len()` is not (3·points)².
    pub fn from_dense(points: usize, w: &[f64]) -> Self {
        let m = 3 * points;
        assert_eq!(w.len(), m * m, "dense W of {points} points");
        Self::from_entries(
            points,
            (0..m)
                .flat_map(|i| (0..m).map(move |j| (i, j)))
                .filter(|&(i, j)| w[i * m + j] != 0.0)
                .map(|(i, j)| (i, j, w[i * m + j])),
        )
    }

    /// Number of contact points N.
    pub fn points(&self) -> usize {
        self.points
    }

    /// Number of stored 3×3 blocks.
    pub fn block_count(&self) -> usize {
        self.blocks.len()
    }

    /// Diagonal block W_pp [m/N].
    pub fn diagonal_block(&self, p: usize) -> M3 {
        self.blocks[self.diag[p]]
    }

    /// The stored blocks of row `p`: (column point, block).
    pub fn row(&self, p: usize) -> impl Iterator<Item = (usize, &M3)> + '_ {
        let range = self.row_start[p]..self.row_start[p + 1];
        self.cols[range.clone()]
            .iter()
            .copied()
            .zip(&self.blocks[range])
    }

    /// W + η I [m/N].
    pub fn with_diagonal_shift(&self, eta: f64) -> Self {
        let mut shifted = self.clone();
        for &k in &shifted.diag {
            for a in 0..3 {
                shifted.blocks[k][a][a] += eta;
            }
        }
        shifted
    }

    /// x = q + W r.
    pub fn apply(&self, r: &[[f64; 3]], q: &[[f64; 3]], x: &mut [[f64; 3]]) {
        for p in 0..self.points {
            x[p] = self.row_times(p, r, q[p], None);
        }
    }

    /// `start` + Σ_j W_pj r_j over the stored blocks of row p, skipping column `skip`.
    pub(crate) fn row_times(
        &self,
        p: usize,
        r: &[[f64; 3]],
        start: [f64; 3],
        skip: Option<usize>,
    ) -> [f64; 3] {
        let mut acc = start;
        for (j, b) in self.row(p) {
            if Some(j) == skip {
                continue;
            }
            let rj = r[j];
            for a in 0..3 {
                acc[a] += b[a][0] * rj[0] + b[a][1] * rj[1] + b[a][2] * rj[2];
            }
        }
        acc
    }
}

/// Solution of a reduced contact problem.
#[derive(Clone, Debug)]
pub struct ReducedSolution {
    /// Contact forces per point, (t1, t2, n).
    pub r: Vec<[f64; 3]>,
    /// Relative displacements x = q + W r per point.
    pub x: Vec<[f64; 3]>,
    /// Iterations: sweeps for Gauss–Seidel, Newton steps (plus fallback sweeps) for Newton.
    pub iterations: usize,
    /// Natural-map residual ‖F‖ (unnormalised, ρ = 1).
    pub residual: f64,
    /// Relative error: `residual` / max(‖q‖, ‖r‖, ‖x‖).
    pub error: f64,
    /// Whether `error` ≤ the requested tolerance.
    pub converged: bool,
}

/// x = q + W r and Siconos's error of (r, x): (residual, relative error).
pub fn error_of(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    r: &[[f64; 3]],
    x: &mut [[f64; 3]],
) -> (f64, f64) {
    w.apply(r, q, x);
    let res = natural_map_residual(r, x, mu);
    (res, relative_error(res, q, r, x))
}

/// Reproducible random problems for the tests of the reduced solvers.
#[cfg(test)]
pub(crate) mod test_support {
    /// A linear congruential generator of numbers in [−½, ½).
    pub(crate) struct Lcg(pub(crate) u64);

    impl Lcg {
        pub(crate) fn next_centered(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// A = B Bᵀ/m + shift·I (m × m, row-major) with B drawn from `rng`: symmetric positive
    /// definite.
    pub(crate) fn random_spd(rng: &mut Lcg, m: usize, shift: f64) -> Vec<f64> {
        let b: Vec<f64> = (0..m * m).map(|_| rng.next_centered()).collect();
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] = (0..m).map(|k| b[i * m + k] * b[j * m + k]).sum::<f64>() / m as f64;
            }
            a[i * m + i] += shift;
        }
        a
    }

    /// A symmetric positive definite W of `points` contact points (3N × 3N, row-major).
    pub(crate) fn sym_pd(points: usize, seed: u64) -> Vec<f64> {
        random_spd(&mut Lcg(seed), 3 * points, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::sym_pd;
    use super::*;

    /// The block storage reproduces the dense product, and repeated entries are summed.
    #[test]
    fn block_storage_matches_dense() {
        let n = 4;
        let w = sym_pd(n, 3);
        let bw = BlockSparseDelassus::from_dense(n, &w);
        assert_eq!(bw.block_count(), n * n);
        let r: Vec<[f64; 3]> = (0..n).map(|p| [p as f64, 1.0 - p as f64, 0.5]).collect();
        let q = vec![[0.1, 0.2, 0.3]; n];
        let mut x = vec![[0.0; 3]; n];
        bw.apply(&r, &q, &mut x);
        for i in 0..3 * n {
            let dense: f64 = q[i / 3][i % 3]
                + (0..3 * n)
                    .map(|j| w[i * 3 * n + j] * r[j / 3][j % 3])
                    .sum::<f64>();
            assert!((x[i / 3][i % 3] - dense).abs() < 1e-13);
        }
        let twice = BlockSparseDelassus::from_entries(1, [(2, 2, 1.5), (2, 2, 0.5), (0, 1, 3.0)]);
        assert_eq!(twice.diagonal_block(0)[2][2], 2.0);
        assert_eq!(twice.diagonal_block(0)[0][1], 3.0);
    }
}
