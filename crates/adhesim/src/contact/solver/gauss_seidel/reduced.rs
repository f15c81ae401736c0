//! Nonlinear Gauss–Seidel on the reduced problem x = q + W r without a mesh, W in 3×3 blocks
//! ([`BlockSparseDelassus`]): the sweep of [`super::sweep`] on that storage, point by point
//! with [`solve_point`], stopping on Siconos's relative error ([`error_of`]).

use super::point::{default_rho, solve_point, PointProblem};
use crate::contact::history::PointHistory;
use crate::contact::law::InterfaceLaw;
use crate::contact::solver::reduced::{error_of, BlockSparseDelassus, ReducedSolution};
use crate::mat3_from_rows;

/// ρ per point for the bi-potential maps: 1/λ_max of the diagonal block ([`default_rho`]).
pub fn point_rhos(w: &BlockSparseDelassus) -> Vec<f64> {
    (0..w.points())
        .map(|p| default_rho(mat3_from_rows(w.diagonal_block(p))))
        .collect()
}

/// One nonlinear Gauss–Seidel sweep in place: each point in turn solves its dry law exactly
/// ([`solve_point`]) with the others' current forces. `rho` as from [`point_rhos`].
pub fn gauss_seidel_sweep(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    rho: &[f64],
    r: &mut [[f64; 3]],
) {
    let laws: Vec<InterfaceLaw> = mu.iter().map(|&m| InterfaceLaw::coulomb(m)).collect();
    for p in 0..w.points() {
        let x_free = w.row_times(p, r, q[p], Some(p));
        let law = &laws[p];
        let problem = PointProblem {
            w_aa: mat3_from_rows(w.diagonal_block(p)),
            x_free: x_free.into(),
            law,
            history0: PointHistory::default(),
            dt: 1.0,
            area: 1.0,
            rho: rho[p],
        };
        r[p] = solve_point(&problem, r[p].into(), 1e-12, 200).r_dry.into();
    }
}

/// Nonlinear Gauss–Seidel on block-sparse W from `r_start` until Siconos's relative error is
/// ≤ `tol` (checked after every sweep) or `max_sweeps` sweeps.
///
/// # Panics
/// If `q`, `mu` or `r_start` do not have one entry per point.
pub fn gauss_seidel_blocks(
    w: &BlockSparseDelassus,
    q: &[[f64; 3]],
    mu: &[f64],
    r_start: &[[f64; 3]],
    tol: f64,
    max_sweeps: usize,
) -> ReducedSolution {
    let n = w.points();
    assert!(q.len() == n && mu.len() == n && r_start.len() == n);
    let rho = point_rhos(w);
    let mut r = r_start.to_vec();
    let mut x = vec![[0.0; 3]; n];
    let (mut residual, mut error) = error_of(w, q, mu, &r, &mut x);
    let mut sweeps = 0;
    while error > tol && sweeps < max_sweeps {
        gauss_seidel_sweep(w, q, mu, &rho, &mut r);
        sweeps += 1;
        (residual, error) = error_of(w, q, mu, &r, &mut x);
    }
    ReducedSolution {
        r,
        x,
        iterations: sweeps,
        residual,
        error,
        converged: error <= tol,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::solver::reduced::test_support::sym_pd;

    /// One point pressed with a free gap of −d and no tangential load: r_n = d/W_nn exactly.
    #[test]
    fn single_point_normal_closed_form() {
        let w = BlockSparseDelassus::from_entries(1, [(0, 0, 2.0), (1, 1, 2.0), (2, 2, 4.0)]);
        let q = [[0.0, 0.0, -0.2]];
        let sol = gauss_seidel_blocks(&w, &q, &[0.3], &[[0.0; 3]], 1e-12, 10);
        assert!(sol.converged);
        assert!((sol.r[0][2] - 0.05).abs() < 1e-14);
    }

    /// Coupled points: Gauss–Seidel reaches the tolerance and the natural map vanishes.
    #[test]
    fn coupled_points_converge() {
        let n = 5;
        let w = BlockSparseDelassus::from_dense(n, &sym_pd(n, 11));
        let q: Vec<[f64; 3]> = (0..n)
            .map(|p| {
                [
                    0.3 - 0.1 * p as f64,
                    0.2,
                    if p % 2 == 0 { -1.0 } else { 0.4 },
                ]
            })
            .collect();
        let mu = vec![0.5; n];
        let sol = gauss_seidel_blocks(&w, &q, &mu, &vec![[0.0; 3]; n], 1e-10, 2000);
        assert!(sol.converged, "error {}", sol.error);
        assert!(sol.r.iter().any(|r| r[2] > 0.0));
    }
}
