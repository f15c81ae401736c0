//! Nonlinear Gauss-Seidel over the contact sites of a Newton iteration (docs/model.md §6):
//! x = x_free + W r with the Delassus operator of [`super::delassus`], each site in turn
//! solved by the local bi-potential/RCC solve of [`super::point`] with the others' current
//! forces.

use super::delassus::Delassus;
use super::point::{default_rho, solve_point, PointProblem};
use crate::contact::detect::ContactPoint;
use crate::contact::history::PointHistory;
use crate::contact::interface::PointSolution;
use crate::contact::law::InterfaceLaw;
use crate::Mat3;

/// Result of the Gauss-Seidel solve.
pub struct ContactSolution {
    /// Per point: the local solution (dry and adhesive forces, x, the law's history at the end
    /// of the step, state).
    pub points: Vec<PointSolution>,
    /// Sweeps done.
    pub sweeps: usize,
    /// Whether the sweeps settled within the tolerance.
    pub converged: bool,
}

/// Nonlinear Gauss-Seidel over contact points: x = x_free + W r, with each point's law.
/// `r_start` warm-starts the total force per point, `dry_start` the dry part.
#[allow(clippy::too_many_arguments)]
pub fn gauss_seidel(
    points: &[ContactPoint],
    laws: &[InterfaceLaw],
    history0: &[PointHistory],
    dt: f64,
    del: &Delassus,
    x_free: &[[f64; 3]],
    r_start: &[[f64; 3]],
    dry_start: &[[f64; 3]],
    tol: f64,
    max_sweeps: usize,
) -> ContactSolution {
    let np = points.len();
    let m = del.m;
    let mut r: Vec<[f64; 3]> = r_start.to_vec();
    let mut sols: Vec<Option<PointSolution>> = vec![None; np];
    let mut dry: Vec<[f64; 3]> = dry_start.to_vec();
    let blocks: Vec<Mat3> = (0..np)
        .map(|p| Mat3::from_fn(|a, c| del.w[(3 * p + a) * m + 3 * p + c]))
        .collect();
    let rhos: Vec<f64> = blocks.iter().map(|b| default_rho(*b)).collect();
    let mut converged = false;
    let mut sweeps = 0;
    while sweeps < max_sweeps {
        sweeps += 1;
        let mut change: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for p in 0..np {
            // x_free of this point with every other point's current force.
            let mut xf = x_free[p];
            for q in 0..np {
                if q == p {
                    continue;
                }
                let rq = r[q];
                if rq == [0.0; 3] {
                    continue;
                }
                for a in 0..3 {
                    let row = &del.w[(3 * p + a) * m + 3 * q..(3 * p + a) * m + 3 * q + 3];
                    xf[a] += row[0] * rq[0] + row[1] * rq[1] + row[2] * rq[2];
                }
            }
            let pp = PointProblem {
                w_aa: blocks[p],
                x_free: xf.into(),
                law: &laws[points[p].pair],
                history0: history0[p],
                dt,
                area: points[p].area,
                rho: rhos[p],
            };
            let sol = solve_point(&pp, dry[p].into(), 1e-12, 200);
            let rn = sol.r();
            for a in 0..3 {
                change = change.max((rn[a] - r[p][a]).abs());
                scale = scale.max(rn[a].abs());
            }
            r[p] = rn.into();
            dry[p] = sol.r_dry.into();
            sols[p] = Some(sol);
        }
        if change <= tol * scale || scale == 0.0 {
            converged = true;
            break;
        }
    }
    ContactSolution {
        points: sols
            .into_iter()
            .map(|s| s.expect("every point solved"))
            .collect(),
        sweeps,
        converged,
    }
}
