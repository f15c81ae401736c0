//! The Gauss-Seidel contact solve on the Delassus operator (docs/contact-solver.md): after
//! each Newton correction, the reduced contact system x = x(u) + H Δu + W (r − r_prev) is
//! solved point by point and the correction completed by K̄⁻¹Hᵀ(r − r_prev). W is kept
//! between steps and reused while it is still accurate.

use super::delassus::{delassus, Delassus};
use super::sweep::gauss_seidel;
use crate::contact::detect::ContactPoint;
use crate::contact::interface::PointSolution;
use crate::linalg::norm;
use crate::system::SystemMatrix;
use crate::time::coupling::{ContactCoupling, Iterate, PhaseTimes, StepContact};
use std::time::Instant;

/// A Newton correction larger than this fraction of the previous one means the contact
/// coupling is converging slowly: W is rebuilt with the current factorisation.
const DELASSUS_REUSE_RATIO: f64 = 0.5;

/// Relative change of probed columns of W above which the cached W is rebuilt. A W that far
/// off still contracts the Newton iterations by about this factor each; a twisting 3D block
/// (paper example 4.4) changes W by 9e-4 a step through its rotation alone, so a tighter
/// bound rebuilds W at every step.
const DELASSUS_STALE_TOL: f64 = 1e-2;

/// Gauss-Seidel tolerance on the change of the contact forces over a sweep, relative.
const SWEEP_TOL: f64 = 1e-10;

/// Sweeps after which the contact solve gives up (the step is then cut back).
const MAX_SWEEPS: usize = 5000;

/// The last Delassus operator, kept between steps (and in checkpoints, so that a resumed
/// run reuses it exactly as the uninterrupted run would).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CachedDelassus {
    /// What it was built for besides the frames and K̄ (see [`delassus_key`]).
    pub key: Vec<u64>,
    /// The local frame of each point (rows T₁, T₂, N) W is expressed in.
    pub frames: Vec<[[f64; 3]; 3]>,
    /// W in those frames.
    pub w: Delassus,
}

/// The Delassus operator kept for reuse, if any.
pub type DelassusCache = Option<CachedDelassus>;

/// The Gauss-Seidel contact solve of one step.
pub struct DelassusCoupling<'a> {
    sc: StepContact<'a>,
    cache: &'a mut DelassusCache,
    key: Vec<u64>,
    /// Whether this step has built or checked the W in use.
    checked: bool,
    builds: usize,
    prev_du_norm: Option<f64>,
    /// Total and dry contact forces of the last solve, local frames [N].
    r_contact: Vec<[f64; 3]>,
    r_dry: Vec<[f64; 3]>,
    solutions: Vec<PointSolution>,
    contact_force: Vec<f64>,
    contact_residual: f64,
    sweeps: usize,
}

impl<'a> DelassusCoupling<'a> {
    /// The solve of the step with candidates `sc`, reusing W from `cache` where it fits.
    pub fn new(sc: StepContact<'a>, cache: &'a mut DelassusCache) -> Self {
        let m = sc.points.len();
        let n = sc.constraints.mask().len();
        DelassusCoupling {
            key: delassus_key(&sc.points, sc.dt),
            sc,
            cache,
            checked: false,
            builds: 0,
            prev_du_norm: None,
            r_contact: vec![[0.0; 3]; m],
            r_dry: vec![[0.0; 3]; m],
            solutions: Vec::new(),
            contact_force: vec![0.0; n],
            contact_residual: 0.0,
            sweeps: 0,
        }
    }

    /// A W that fits this step and the current factorisation: the cached one when it was
    /// built for the same points and Δt and (on a first use in the step, or when the Newton
    /// corrections shrink slowly) three probed columns agree with the current K̄; else a new
    /// one.
    fn operator(&mut self, du: &[f64], system: &mut SystemMatrix) {
        let du_norm = norm(du);
        let slow = self
            .prev_du_norm
            .is_some_and(|p| du_norm > DELASSUS_REUSE_RATIO * p);
        self.prev_du_norm = Some(du_norm);
        let mut reusable = matches!(&*self.cache, Some(c) if c.key == self.key);
        if reusable {
            // Same points: turn W to this step's frames (exact while K̄ and the master
            // weights are unchanged); the probe below judges what else changed.
            let cached = self.cache.as_mut().expect("matched above");
            let frames = frames_of(&self.sc.points);
            if cached.frames != frames {
                cached.w.rotate_frames(&cached.frames, &frames);
                cached.frames = frames;
            }
        }
        // Slow convergence comes from the nonsmooth contact laws as often as from a stale W:
        // probe the columns of the point carrying the largest force (the first point while
        // r_contact is still zero) and rebuild only when they differ from the cached ones.
        if reusable && (slow || !self.checked) {
            self.checked = true;
            let probe = self
                .r_contact
                .iter()
                .enumerate()
                .max_by(|a, b| norm(a.1).total_cmp(&norm(b.1)))
                .map(|(p, _)| p)
                .unwrap_or(0);
            let cached = &self.cache.as_ref().expect("checked").w;
            let mask = self.sc.constraints.mask();
            reusable =
                cached.probed_change(&self.sc.points, probe, system, mask) <= DELASSUS_STALE_TOL;
        }
        if !reusable {
            let mask = self.sc.constraints.mask();
            let del = delassus(&self.sc.points, system, mask);
            *self.cache = Some(CachedDelassus {
                key: self.key.clone(),
                frames: frames_of(&self.sc.points),
                w: del,
            });
            self.builds += 1;
            self.checked = true;
        }
    }
}

impl<'a> ContactCoupling<'a> for DelassusCoupling<'a> {
    fn step_contact(&mut self) -> &mut StepContact<'a> {
        &mut self.sc
    }

    fn contact_force(&self) -> &[f64] {
        &self.contact_force
    }

    fn contact_residual(&self, _scale: f64) -> f64 {
        self.contact_residual
    }

    fn correct(
        &mut self,
        it: &Iterate,
        u: &[f64],
        du: &mut [f64],
        _residual_norm: f64,
        scale: f64,
        system: &mut SystemMatrix,
        timings: &mut PhaseTimes,
    ) -> Result<(), String> {
        if self.sc.is_empty() {
            return Ok(());
        }
        let clock = Instant::now();
        self.operator(du, system);
        let del = &self.cache.as_ref().expect("built above").w;
        let m = del.m;
        // Reduced contact system: x = x(u) + H Δu_free + W (r − r_prev).
        let x_free: Vec<[f64; 3]> = self
            .sc
            .points
            .iter()
            .enumerate()
            .map(|(p, pt)| {
                let x = pt.local_x(self.sc.reference, u);
                let h = pt.apply_h(du);
                let mut xf = [x[0] + h[0], x[1] + h[1], x[2] + h[2]];
                for (a, xa) in xf.iter_mut().enumerate() {
                    let row = &del.w[(3 * p + a) * m..(3 * p + a + 1) * m];
                    for (q, rq) in self.r_contact.iter().enumerate() {
                        *xa -= row[3 * q] * rq[0] + row[3 * q + 1] * rq[1] + row[3 * q + 2] * rq[2];
                    }
                }
                xf
            })
            .collect();
        timings.delassus += clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        let sc = &self.sc;
        let sol = gauss_seidel(
            &sc.points,
            &sc.laws,
            &sc.history0,
            sc.dt,
            del,
            &x_free,
            &self.r_contact,
            &self.r_dry,
            SWEEP_TOL,
            MAX_SWEEPS,
        );
        self.sweeps += sol.sweeps;
        timings.contact_solve += clock.elapsed().as_secs_f64();
        if !sol.converged {
            *self.cache = None;
            return Err(format!(
                "the contact solve did not settle in {} Gauss-Seidel sweeps (Newton iteration {})",
                sol.sweeps, it.iter
            ));
        }
        let clock = Instant::now();
        for (p, ps) in sol.points.iter().enumerate() {
            self.r_contact[p] = ps.r().into();
            self.r_dry[p] = ps.r_dry.into();
        }
        let new_force = self.sc.nodal_force(self.r_contact.iter().copied(), u.len());
        let mut dc: Vec<f64> = (0..u.len())
            .map(|i| new_force[i] - self.contact_force[i])
            .collect();
        system.solve_in_place(&mut dc);
        for i in 0..u.len() {
            du[i] += dc[i];
        }
        self.contact_force = new_force;
        self.solutions = sol.points;
        self.contact_residual = self.sc.natural_map(&self.solutions) / scale;
        timings.delassus += clock.elapsed().as_secs_f64();
        Ok(())
    }

    fn solutions(&self) -> Vec<PointSolution> {
        self.solutions.clone()
    }

    fn sweeps(&self) -> usize {
        self.sweeps
    }

    fn delassus_builds(&self) -> usize {
        self.builds
    }

    fn abandon(&mut self) {
        *self.cache = None;
    }
}

/// The local frame of each point, the frames W is expressed in.
fn frames_of(points: &[ContactPoint]) -> Vec<[[f64; 3]; 3]> {
    points.iter().map(|p| p.frame).collect()
}

/// What a cached W must share with this step to be reused: the contact points (pair, slave
/// nodes, master nodes) and Δt (K̄ = ξK + M/(θΔt²) + ...), compared bit for bit. The frames
/// are turned exactly ([`Delassus::rotate_frames`]); changes of K̄ and of the master weights
/// are left to the probe.
fn delassus_key(points: &[ContactPoint], dt: f64) -> Vec<u64> {
    let mut key = Vec::with_capacity(points.len() * 6 + 1);
    key.push(dt.to_bits());
    for p in points {
        key.push(p.pair as u64);
        key.push(p.slave_nodes().count() as u64);
        key.extend(p.slave_nodes().map(|(s, _)| s as u64));
        key.push(p.master.len() as u64);
        key.extend(p.master.iter().map(|&(m, _)| m as u64));
    }
    key
}
