//! The point solver of the nonlinear Gauss–Seidel sweep over contact points: the local problem
//! x = x_free + W_αα (r̄ + r̃) at one point, with the dry force r̄ on Coulomb's cone
//! (`cone.rs`) and the adhesive force r̃ of the pair's bond law ([`crate::contact::interface`]).
//! Pure functions on plain arrays: no mesh, no allocation.
//!
//! [`solve_point`] solves the apart, stick and slide cases directly (the adhesive part
//! implicitly in x) and checks each against the bi-potential fixed point; the bi-potential
//! iteration itself (semi-smooth Newton, fixed-point steps with ρ = 1/λ_max(W)) is the
//! fallback. A plain fixed point diverges once C·A·‖W‖ > 1 if r̃ lags one iteration behind x,
//! and crawls when the compliance is ill-conditioned.

use crate::contact::anisotropic::{scale, scale_matrix, unscale, unscale_matrix};
use crate::contact::cone::{
    bipotential_trial, dry_projection, modified_displacement_jacobian, projection_jacobian,
    ContactState,
};
use crate::contact::history::PointHistory;
use crate::contact::interface::{AdhEval, FrozenSprings, Interface, PointSolution};
use crate::contact::law::InterfaceLaw;
use crate::{Mat3, Vec3};
use std::f64::consts::PI;

/// Largest number of Newton steps of the adhesive sub-problem per evaluation.
const MAX_INNER: usize = 60;

/// Largest number of step lengths tried along a Newton direction of the dry force.
const NEWTON_HALVINGS: usize = 4;

/// Largest number of step halvings in the line search of the slide equations; a Newton
/// direction that needs more is abandoned for the bi-potential iteration.
const SLIDE_HALVINGS: usize = 6;

/// Largest change of the friction direction per Newton step of the slide equations [rad].
const MAX_TURN: f64 = 0.5;

/// Largest number of step halvings in a line search.
const MAX_HALVINGS: usize = 40;

/// ρ [N/m] for the bi-potential iteration at a point with Delassus block `w_aa` [m/N]:
/// 1/λ_max of its symmetric part. The fixed point r̄ ← Proj(r̄ − ρ(x + μ‖x_t‖n)) contracts for
/// 0 < ρ < 2/λ_max; 1/λ_max is safely inside. (1/max W_ii can reach 3/λ_max and diverge.)
/// Falls back to 1/max|W_ii|, then 1, for degenerate blocks.
pub fn default_rho(w_aa: Mat3) -> f64 {
    let w = w_aa;
    let lmax = eig_sym3(&((w + w.transpose()) * 0.5))[2];
    if lmax.is_finite() && lmax > 0.0 {
        return 1.0 / lmax;
    }
    let dmax = w_aa[(0, 0)]
        .abs()
        .max(w_aa[(1, 1)].abs())
        .max(w_aa[(2, 2)].abs());
    if dmax.is_finite() && dmax > 0.0 {
        1.0 / dmax
    } else {
        1.0
    }
}

/// The local problem at contact point α within a Gauss–Seidel sweep:
/// x = x_free + W_αα (r̄ + r̃), with the dry and adhesive laws at the point.
#[derive(Clone, Copy, Debug)]
pub struct PointProblem<'a> {
    /// Delassus diagonal block W_αα [m/N], symmetric positive definite.
    pub w_aa: Mat3,
    /// x with the other points' current forces and this point's force removed [m].
    pub x_free: Vec3,
    /// Interface law of the pair.
    pub law: &'a InterfaceLaw,
    /// The law's history of the point frozen at the start of the step.
    pub history0: PointHistory,
    /// Time step Δt [s].
    pub dt: f64,
    /// Tributary area A [m²].
    pub area: f64,
    /// Bi-potential parameter ρ [N/m], e.g. [`default_rho`].
    pub rho: f64,
}

/// Solves the local problem at one contact point: x = x_free + W_αα (r̄ + r̃) with r̄ obeying
/// Signorini–Coulomb (r̄ = Proj_K(r̄ − ρ(x + μ‖x_t‖n))) and r̃ = r̃(β₁(x), x) the RCC force.
///
/// The three cases are tried in turn, each solved exactly rather than by a ρ-dependent fixed
/// point (whose rate degrades like λ_min/λ_max of the compliance, and with stiff adhesion like
/// 1/(C·A·‖W‖)):
/// 1. apart: r̄ = 0; the adhesive part alone, x = x_free + W r̃(x), is solved implicitly
///    (Newton on the incremental potential with a line search, started from linear springs at
///    β₀, so a bond holds as long as its branch exists and snaps off past it). Valid if x_n ≥ 0.
/// 2. stick: x = 0, so r̃ = r̃(0) is explicit and r̄ = −W⁻¹x_free − r̃(0). Valid if r̄ ∈ K_μ.
/// 3. slide: damped Newton on (r_n, θ, λ) with r̄ = r_n(μ cos θ, μ sin θ, 1) on the cone and
///    slip x_t = −λ(cos θ, sin θ), x_n = 0, started from the friction direction of `r_start` when
///    that lies on the cone (warm start from the previous sweep), else of the stick force.
///
/// A case is accepted only if it passes the bi-potential check: with r = r̄ + r̃ and the force
/// scale s = ρ‖x_free‖ + A·√(max(C_n, C_t)·w), ‖r̄ − Proj_K(r̄ − ρ(x + μ‖x_t‖n))‖ ≤
/// `tol`·(‖r‖ + s). If none does (singular or stalled slide Newton, e.g. a tangential snap of
/// the bond), the bi-potential iteration takes over from `r_start`: semi-smooth Newton steps on
/// that residual, kept when they reduce it, plain fixed-point steps otherwise; it stops when the
/// change of r over an iteration and the residual are both ≤ `tol`·(‖r‖ + s).
///
/// `iterations` counts 1 for the apart test, 1 for the stick test, then the Newton steps of the
/// slide equations and of the fallback. When the law admits several solutions (μ large with
/// strongly coupled W, or softening adhesion), the first in the order apart, stick, slide wins.
/// `rho` is only used by the check and the fallback (a non-positive ρ is replaced by
/// [`default_rho`]); the solution does not depend on it. r̄ lies in K_μ to rounding.
pub fn solve_point(p: &PointProblem, r_start: Vec3, tol: f64, max_iter: usize) -> PointSolution {
    solve_point_impl(p, r_start, tol, max_iter, Method::Cases)
}

/// Everything derived from one value of the dry force r̄.
#[derive(Clone, Copy, Debug)]
struct Eval {
    /// Dry force r̄ at which this was evaluated [N].
    r_dry: Vec3,
    /// Local relative displacement [m].
    x: Vec3,
    /// Adhesive force r̃ [N] with x = x_free + W (r̄ + r̃) exactly; equal to the law's r̃(x) to
    /// the sub-problem's tolerance.
    r_adh: Vec3,
    /// Adhesive state at x.
    adh: AdhEval,
    /// Trial force r* [N].
    r_star: Vec3,
    /// Projection of r* [N].
    proj: Vec3,
    /// Case of the projection.
    case: ContactState,
    /// Fixed-point defect F = r̄ − Proj(r*) [N].
    f: Vec3,
}

/// Per-solve constants.
struct Ctx<'a> {
    p: &'a PointProblem<'a>,
    /// The problem's Delassus block W_αα [m/N].
    w: Mat3,
    /// The problem's x_free [m].
    x_free: Vec3,
    /// Scale of the second tangential axis of the solver's variables (1, or μ₂/μ₁ on an
    /// orthotropic interface); the adhesive law is evaluated in the unscaled ones.
    t2: f64,
    mu: f64,
    /// ρ [N/m] in use (the problem's, or [`default_rho`] when that is not positive).
    rho: f64,
    /// Relative tolerance of the point problem.
    tol: f64,
    /// Force scale s [N] of the convergence criteria.
    scale: f64,
    /// Relative tolerance of the adhesive sub-problem.
    tol_in: f64,
}

/// How [`solve_point_impl`] solves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Method {
    /// Case by case (apart, stick, slide), falling back to the bi-potential iteration.
    Cases,
    /// Bi-potential iteration only; `newton` enables the semi-smooth Newton steps.
    #[cfg_attr(not(test), allow(dead_code))]
    Bipotential { newton: bool },
}

/// [`solve_point`] with a choice of method. An orthotropic law is solved as the isotropic
/// problem of its scaled variables r' = T⁻¹r, x' = Tx ([`crate::contact::anisotropic`]).
fn solve_point_impl(
    p: &PointProblem,
    r_start: Vec3,
    tol: f64,
    max_iter: usize,
    method: Method,
) -> PointSolution {
    let s = p.law.tangent_scale();
    if s == 1.0 {
        return solve_scaled(p, r_start, tol, max_iter, method, 1.0);
    }
    let law = InterfaceLaw {
        anisotropy: None,
        ..p.law.clone()
    };
    let scaled = PointProblem {
        w_aa: scale_matrix(p.w_aa, s),
        x_free: scale(p.x_free, s),
        law: &law,
        ..*p
    };
    let sol = solve_scaled(&scaled, unscale(r_start, s), tol, max_iter, method, s);
    PointSolution {
        r_dry: scale(sol.r_dry, s),
        r_adh: scale(sol.r_adh, s),
        x: unscale(sol.x, s),
        ..sol
    }
}

/// The point problem `p` in variables whose second tangential axis is scaled by `t2`
/// (x' = T x, r' = T⁻¹ r, T = diag(1, t2, 1)); `p.law` is isotropic there.
fn solve_scaled(
    p: &PointProblem,
    r_start: Vec3,
    tol: f64,
    max_iter: usize,
    method: Method,
    t2: f64,
) -> PointSolution {
    let mu = p.law.mu.max(0.0);
    let adh_scale = if p.law.is_adhesive() {
        p.area.abs() * p.law.bond_traction()
    } else {
        0.0
    };
    let rho = if p.rho.is_finite() && p.rho > 0.0 {
        p.rho
    } else {
        default_rho(p.w_aa)
    };
    let w = p.w_aa;
    let x_free = p.x_free;
    let scale = rho * x_free.norm() + adh_scale;
    let tol = if tol.is_finite() && tol > 0.0 {
        tol
    } else {
        1e-10
    };
    let ctx = Ctx {
        p,
        w,
        x_free,
        t2,
        mu,
        rho,
        scale,
        tol,
        tol_in: (1e-3 * tol).max(1e-13),
    };
    let r0 = if r_start.iter().all(|v| v.is_finite()) {
        r_start
    } else {
        Vec3::zeros()
    };
    let mut used = 0;
    let newton = match method {
        Method::Cases => {
            match solve_by_cases(&ctx, r0, max_iter) {
                Ok(sol) => return sol,
                Err(n) => used = n,
            }
            true
        }
        Method::Bipotential { newton } => newton,
    };
    bipotential_iteration(&ctx, r0, max_iter.saturating_sub(used), newton, used)
}

/// Whether `ev` satisfies the law: fixed-point defect ‖F‖ ≤ tol·(‖r‖ + s).
fn is_solution(ctx: &Ctx, ev: &Eval) -> bool {
    ev.f.norm() <= ctx.tol * ((ev.r_dry + ev.r_adh).norm() + ctx.scale)
}

/// Packs an evaluation into a [`PointSolution`].
fn finish(ev: &Eval, state: ContactState, iterations: usize, converged: bool) -> PointSolution {
    PointSolution {
        r_dry: ev.r_dry,
        r_adh: ev.r_adh,
        x: ev.x,
        history: ev.adh.history,
        state,
        iterations,
        converged,
    }
}

/// Solves the three cases in turn and returns the first one that passes [`is_solution`]:
/// apart (r̄ = 0, the adhesive sub-problem alone, valid when x_n ≥ 0), stick (x = 0, so
/// r̄ = −W⁻¹x_free − r̃(0), valid when r̄ ∈ K_μ), slide (Newton's method on the slide equations).
/// `Err` carries the iterations spent.
fn solve_by_cases(ctx: &Ctx, r_start: Vec3, max_iter: usize) -> Result<PointSolution, usize> {
    let p = ctx.p;
    if max_iter == 0 {
        return Err(0);
    }
    // Apart.
    let ev = evaluate(ctx, Vec3::zeros(), frozen_adhesion_guess(ctx, ctx.x_free));
    if ev.x[2] >= 0.0 && is_solution(ctx, &ev) {
        return Ok(finish(&ev, ContactState::Apart, 1, true));
    }
    // Stick.
    let r_adh0 = if p.law.is_adhesive() {
        adhesion_eval(ctx, Vec3::zeros()).force
    } else {
        Vec3::zeros()
    };
    let r_stick = stick_force(&ctx.w, &ctx.x_free).map(|r| r - r_adh0);
    if let Some(rs) = r_stick {
        if rs[2] >= 0.0 && rs[0].hypot(rs[1]) <= ctx.mu * rs[2] {
            let ev = evaluate(ctx, rs, r_adh0);
            if is_solution(ctx, &ev) {
                return Ok(finish(&ev, ContactState::Stick, 2, true));
            }
        }
    }
    // Slide.
    let mut used = 2;
    if max_iter > used {
        let (ev, n) = solve_slide(ctx, r_start, r_stick, r_adh0, max_iter - used);
        used += n;
        if let Some(ev) = ev {
            if is_solution(ctx, &ev) {
                return Ok(finish(&ev, ContactState::Slide, used, true));
            }
        }
    }
    Err(used)
}

/// Slide equations in the unknowns (r_n, θ, λ): r̄ = r_n (μ cos θ, μ sin θ, 1) on the cone,
/// slip x_t = −λ (cos θ, sin θ) opposing the friction force, x_n = 0:
/// R = x_free + W (r̄ + r̃(x)) − x = 0. Returns R [m], ∂R/∂(r_n, θ, λ), r̄ and r̃.
fn slide_residual(ctx: &Ctx, q: Vec3) -> (Vec3, Mat3, Vec3, Vec3) {
    let p = ctx.p;
    let (rn, th, lam) = (q[0], q[1], q[2]);
    let c = [th.cos(), th.sin()];
    let cp = [-c[1], c[0]];
    let mu = ctx.mu;
    let x = Vec3::new(-lam * c[0], -lam * c[1], 0.0);
    let rd = Vec3::new(mu * rn * c[0], mu * rn * c[1], rn);
    let (ra, k) = if p.law.is_adhesive() {
        let ad = adhesion_eval(ctx, x);
        (ad.force, ad.stiff)
    } else {
        (Vec3::zeros(), Mat3::zeros())
    };
    let w = ctx.w;
    let res = ctx.x_free + w * (rd + ra) - x;
    // ∂R/∂x = −(I + W K) on the tangential columns.
    let a = Mat3::identity() + w * k;
    let d_rn = w * Vec3::new(mu * c[0], mu * c[1], 1.0);
    let d_lam = a * Vec3::new(c[0], c[1], 0.0);
    let d_th = w * Vec3::new(mu * rn * cp[0], mu * rn * cp[1], 0.0)
        + a * Vec3::new(lam * cp[0], lam * cp[1], 0.0);
    let jac = Mat3::from_columns(&[d_rn, d_th, d_lam]);
    (res, jac, rd, ra)
}

/// Newton's method with a backtracking line search on ‖R‖ for the slide equations, started from
/// the friction direction of `r_start` when it lies on the cone, else from the projection of the
/// stick force. Returns the evaluation at the converged dry force and the iterations spent.
fn solve_slide(
    ctx: &Ctx,
    r_start: Vec3,
    r_stick: Option<Vec3>,
    r_adh0: Vec3,
    max_iter: usize,
) -> (Option<Eval>, usize) {
    let mu = ctx.mu;
    let on_cone = |r: Vec3| {
        let t = r[0].hypot(r[1]);
        r[2] > 0.0 && t > 0.0 && (t - mu * r[2]).abs() <= 1e-6 * t
    };
    let base = if on_cone(r_start) {
        r_start
    } else {
        match r_stick {
            Some(rs) => {
                let (pr, _) = dry_projection(rs, mu);
                if pr[0].hypot(pr[1]) > 0.0 {
                    pr
                } else {
                    Vec3::new(rs[0], rs[1], pr[2])
                }
            }
            None => r_start,
        }
    };
    let th0 = if base[0].hypot(base[1]) > 0.0 {
        base[1].atan2(base[0])
    } else {
        0.0
    };
    let mut q = Vec3::new(base[2].max(0.0), th0, 0.0);
    let (mut res, mut jac, mut rd, mut ra) = slide_residual(ctx, q);
    // At the first friction direction, (r_n, λ) by least squares on the linearised equations.
    if let Some((dn, dl)) = least_squares_2(&jac, &res) {
        let q1 = Vec3::new(q[0] + dn, q[1], (q[2] + dl).max(0.0));
        let trial = slide_residual(ctx, q1);
        if trial.0.norm() < res.norm() {
            q = q1;
            (res, jac, rd, ra) = trial;
        }
    }
    let mut iterations = 0;
    let mut converged = false;
    while iterations < max_iter {
        iterations += 1;
        let mut d = match solve3(&jac, &-res) {
            Some(d) if d.iter().all(|v| v.is_finite()) => d,
            _ => break,
        };
        if d[1].abs() > MAX_TURN {
            d *= MAX_TURN / d[1].abs();
        }
        let r_old = rd + ra;
        let m0 = res.norm();
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..SLIDE_HALVINGS {
            let qt = q + d * alpha;
            let trial = slide_residual(ctx, qt);
            let m1 = trial.0.norm();
            if m1 <= (1.0 - 1e-4 * alpha) * m0 || m1 == 0.0 {
                q = qt;
                (res, jac, rd, ra) = trial;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            // No further decrease possible: converged if the residual is already negligible.
            converged = ctx.rho * m0 <= ctx.tol * (r_old.norm() + ctx.scale);
            break;
        }
        let r_new = rd + ra;
        let bound = ctx.tol * (r_new.norm() + ctx.scale);
        if (r_new - r_old).norm() <= bound && ctx.rho * res.norm() <= bound {
            converged = true;
            break;
        }
    }
    if !converged {
        return (None, iterations);
    }
    let guess = if ra == Vec3::zeros() { r_adh0 } else { ra };
    (Some(evaluate(ctx, rd, guess)), iterations)
}

/// Least-squares solution (a, b) of a·J[:,0] + b·J[:,2] = −res (the r_n and λ columns of the
/// slide Jacobian).
fn least_squares_2(jac: &Mat3, res: &Vec3) -> Option<(f64, f64)> {
    let c0 = jac.column(0);
    let c2 = jac.column(2);
    let (a11, a12, a22) = (c0.dot(&c0), c0.dot(&c2), c2.dot(&c2));
    let (b1, b2) = (-c0.dot(res), -c2.dot(res));
    let det = a11 * a22 - a12 * a12;
    if !(det.is_finite() && det > 1e-14 * a11 * a22) {
        return None;
    }
    Some(((b1 * a22 - b2 * a12) / det, (a11 * b2 - a12 * b1) / det))
}

/// The bi-potential iteration on the dry force: r̄ ← Proj(r̄ − ρ(x + μ‖x_t‖n)) with x from the
/// implicit adhesive sub-problem, optionally accelerated by semi-smooth Newton steps kept when
/// they reduce ‖F‖. `offset` iterations were already spent.
fn bipotential_iteration(
    ctx: &Ctx,
    r0: Vec3,
    max_iter: usize,
    newton: bool,
    offset: usize,
) -> PointSolution {
    let z0 = frozen_adhesion_guess(ctx, ctx.x_free + ctx.w * r0);
    let mut ev = evaluate(ctx, r0, z0);
    let mut iterations = 0;
    let mut converged = false;
    while iterations < max_iter {
        iterations += 1;
        let r_old = ev.r_dry + ev.r_adh;
        let fn_old = ev.f.norm();
        let mut next = None;
        if newton {
            if let Some(step) = newton_step(ctx, &ev) {
                let mut alpha = 1.0;
                for _ in 0..NEWTON_HALVINGS {
                    let trial = dry_projection(ev.r_dry + step * alpha, ctx.mu).0;
                    let cand = evaluate(ctx, trial, ev.r_adh);
                    if cand.f.norm() < (1.0 - 1e-4 * alpha) * fn_old {
                        next = Some(cand);
                        break;
                    }
                    alpha *= 0.5;
                }
            }
        }
        ev = match next {
            Some(cand) => cand,
            None => evaluate(ctx, ev.proj, ev.r_adh),
        };
        let r_new = ev.r_dry + ev.r_adh;
        let bound = ctx.tol * (r_new.norm() + ctx.scale);
        if (r_new - r_old).norm() <= bound && ev.f.norm() <= bound {
            converged = true;
            break;
        }
    }
    let state = ev.case;
    let fin = evaluate(ctx, ev.proj, ev.r_adh);
    finish(&fin, state, offset + iterations, converged)
}

/// Evaluates x, the adhesive part and the projection at the dry force `r_dry`, solving the
/// adhesive sub-problem from the adhesive-force guess `z_start`.
fn evaluate(ctx: &Ctx, r_dry: Vec3, z_start: Vec3) -> Eval {
    let y = ctx.x_free + ctx.w * r_dry;
    let (x, r_adh, adh) = if ctx.p.law.is_adhesive() {
        solve_adhesion(ctx, y, z_start)
    } else {
        (y, Vec3::zeros(), AdhEval::default())
    };
    let r_star = bipotential_trial(r_dry, x, ctx.mu, ctx.rho);
    let (proj, case) = dry_projection(r_star, ctx.mu);
    Eval {
        r_dry,
        x,
        r_adh,
        adh,
        r_star,
        proj,
        case,
        f: r_dry - proj,
    }
}

/// The adhesive law at x: β₁, u_t, r̃, −∂r̃/∂x and the incremental potential
/// φ = A [½ E β₁² − w β₁ + b/(2Δt) (β₁ − β₀)²] (β₁ minimises the bracket over [0, 1], so
/// ∂φ/∂x = A β₁² ∂E/∂x / 2 = −r̃).
fn adhesion_eval(ctx: &Ctx, x: Vec3) -> AdhEval {
    let (p, s) = (ctx.p, ctx.t2);
    if s == 1.0 {
        return p.law.adhesion_at(&p.history0, p.dt, p.area, x);
    }
    // x is scaled (x' = T x): the law at T⁻¹x', its force as T⁻¹r̃ and stiffness T⁻¹KT⁻¹.
    let mut ev = p.law.adhesion_at(&p.history0, p.dt, p.area, unscale(x, s));
    ev.force = unscale(ev.force, s);
    ev.stiff = unscale_matrix(ev.stiff, s);
    ev
}

/// Adhesive force guess with β frozen at β₀ (linear springs), given y = x_free + W r̄:
/// z = −K₀ (y + e + W z), K₀ = A β₀² diag(C_t, C_t, C_n [y_n > 0]), e = (u_t0, 0).
fn frozen_adhesion_guess(ctx: &Ctx, y: Vec3) -> Vec3 {
    let (p, s) = (ctx.p, ctx.t2);
    if !p.law.is_adhesive() {
        return Vec3::zeros();
    }
    let Some(FrozenSprings {
        stiffness: c,
        stretch: e,
    }) = p.law.frozen_springs(&p.history0, p.area)
    else {
        return Vec3::zeros();
    };
    // In scaled variables the springs are T⁻¹KT⁻¹ and the stretch T e.
    let kd = Vec3::new(c[0], c[1] / (s * s), if y[2] > 0.0 { c[2] } else { 0.0 });
    let rhs = Vec3::new(
        -kd[0] * (y[0] + e[0]),
        -kd[1] * (y[1] + s * e[1]),
        -kd[2] * y[2],
    );
    let m = Mat3::identity() + Mat3::from_diagonal(&kd) * ctx.w;
    match solve3(&m, &rhs) {
        Some(z) if z.iter().all(|v| v.is_finite()) => z,
        _ => Vec3::zeros(),
    }
}

/// Solves z = r̃(y + W z) for the adhesive force z [N] by Newton's method on the potential
/// Π(z) = ½ zᵀW z + φ(y + W z), whose stationary points are the solutions; the line search keeps
/// Π decreasing, so the iteration settles in a local minimum (a stable equilibrium) next to the
/// starting guess and, past a snap-off, slides down to the detached branch.
fn solve_adhesion(ctx: &Ctx, y: Vec3, z_start: Vec3) -> (Vec3, Vec3, AdhEval) {
    let w = ctx.w;
    let mut z = if z_start.iter().all(|v| v.is_finite()) {
        z_start
    } else {
        Vec3::zeros()
    };
    let mut x = y + w * z;
    let mut ad = adhesion_eval(ctx, x);
    for _ in 0..MAX_INNER {
        let res = z - ad.force;
        let size = z.norm() + ad.force.norm() + ctx.scale;
        if res.norm() <= ctx.tol_in * size {
            break;
        }
        let grad = w * res;
        let mut dir = None;
        let m = Mat3::identity() + ad.stiff * w;
        if let Some(d) = solve3(&m, &-res) {
            if grad.dot(&d) <= 0.0 && d.iter().all(|v| v.is_finite()) {
                dir = Some(d);
            }
        }
        let d = match dir {
            Some(d) => d,
            None => shifted_newton_direction(&w, &ad.stiff, &grad).unwrap_or(-res),
        };
        let pi0 = merit(&z, &w, ad.energy);
        let slope = grad.dot(&d);
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let zt = z + d * alpha;
            let xt = y + w * zt;
            let at = adhesion_eval(ctx, xt);
            let pit = merit(&zt, &w, at.energy);
            let slack = 1e-13 * (pi0.abs() + pit.abs());
            if pit <= pi0 + 1e-4 * alpha * slope + slack {
                accepted = Some((zt, xt, at));
                break;
            }
            alpha *= 0.5;
        }
        let (zn, xn, an) = accepted.unwrap_or_else(|| {
            let zt = z + d;
            let xt = y + w * zt;
            (zt, xt, adhesion_eval(ctx, xt))
        });
        let moved = (zn - z).norm();
        z = zn;
        x = xn;
        ad = an;
        if moved <= 1e-15 * (z.norm() + ctx.scale) {
            break;
        }
    }
    (x, z, ad)
}

/// Π(z) = ½ zᵀ W z + φ [J].
fn merit(z: &Vec3, w: &Mat3, energy: f64) -> f64 {
    0.5 * z.dot(&(w * z)) + energy
}

/// Descent direction from the Hessian of Π in z, H = W + W K W, shifted to be positive definite
/// when the interface softens.
fn shifted_newton_direction(w: &Mat3, k: &Mat3, grad: &Vec3) -> Option<Vec3> {
    let h = w + w * (k * w);
    let h = (h + h.transpose()) * 0.5;
    let ev = eig_sym3(&h);
    let big = ev[0].abs().max(ev[2].abs());
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    let shift = (-ev[0]).max(0.0) + 1e-6 * big;
    let hs = h + Mat3::from_diagonal_element(shift);
    solve3(&hs, &-grad).filter(|d| d.iter().all(|v| v.is_finite()))
}

/// Semi-smooth Newton step on F(r̄) = r̄ − Proj(r̄ − ρ g(x(r̄))), g(x) = x + μ‖x_t‖n:
/// ∂F/∂r̄ = I − P′ (I − ρ G W_e), with P′ the Jacobian of the projection in its case,
/// G = ∂g/∂x and W_e = (I + W K)⁻¹ W the compliance seen by r̄ with the adhesive part solved.
fn newton_step(ctx: &Ctx, ev: &Eval) -> Option<Vec3> {
    let m = Mat3::identity() + ctx.w * ev.adh.stiff;
    let we = solve3_mat(&m, &ctx.w)?;
    let gw = modified_displacement_jacobian(ev.x, ctx.mu) * we;
    let a = Mat3::identity() - gw * ctx.rho;
    let pj = projection_jacobian(ev.r_star, ctx.mu, ev.case);
    let jac = Mat3::identity() - pj * a;
    solve3(&jac, &-ev.f).filter(|d| d.iter().all(|v| v.is_finite()))
}

/// The total force r with W r = −x_free (the point stuck: x = 0). Where the compliance W has
/// a local axis along which no force moves the point (a diagonal entry negligible against the
/// largest, e.g. the out-of-plane tangent of a plane-strain model, whose unknowns are held),
/// the force has no component along it (the least-norm solution) provided x_free has none
/// either; the other components solve the remaining rows. None when no such force exists.
fn stick_force(w: &Mat3, x_free: &Vec3) -> Option<Vec3> {
    if let Some(r) = solve3(w, &-x_free) {
        return Some(r);
    }
    let big = w.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    // W is symmetric positive semi-definite: a negligible diagonal entry bounds its whole row
    // and column (|W_ij| ≤ √(W_ii W_jj)).
    let null: [bool; 3] = std::array::from_fn(|i| w[(i, i)].abs() <= 1e-12 * big);
    let free: Vec<usize> = (0..3).filter(|&i| !null[i]).collect();
    if free.len() == 3 || free.is_empty() {
        return None;
    }
    // A direction the force cannot move must already be at rest.
    let scale = x_free.norm();
    if (0..3).any(|i| null[i] && x_free[i].abs() > 1e-9 * scale) {
        return None;
    }
    let mut r = Vec3::zeros();
    match *free.as_slice() {
        [a] => {
            r[a] = -x_free[a] / w[(a, a)];
        }
        [a, b] => {
            let det = w[(a, a)] * w[(b, b)] - w[(a, b)] * w[(b, a)];
            if det.is_nan() || det.abs() <= 1e-14 * big * big {
                return None;
            }
            r[a] = (-x_free[a] * w[(b, b)] + x_free[b] * w[(a, b)]) / det;
            r[b] = (-x_free[b] * w[(a, a)] + x_free[a] * w[(b, a)]) / det;
        }
        _ => return None,
    }
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Solves m x = b by Gaussian elimination with partial pivoting; `None` when m is singular to
/// working precision (a pivot at most 1e-14 times the largest entry of m).
fn solve3(m: &Mat3, b: &Vec3) -> Option<Vec3> {
    let mut a = *m;
    let mut r = *b;
    let big = a.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    for col in 0..3 {
        let mut piv = col;
        for row in col + 1..3 {
            if a[(row, col)].abs() > a[(piv, col)].abs() {
                piv = row;
            }
        }
        let pivot = a[(piv, col)].abs();
        if pivot.is_nan() || pivot <= 1e-14 * big {
            return None;
        }
        if piv != col {
            a.swap_rows(col, piv);
            r.swap_rows(col, piv);
        }
        for row in col + 1..3 {
            let f = a[(row, col)] / a[(col, col)];
            for k in col..3 {
                a[(row, k)] -= f * a[(col, k)];
            }
            r[row] -= f * r[col];
        }
    }
    let mut x = Vec3::zeros();
    for i in (0..3).rev() {
        let mut s = r[i];
        for k in i + 1..3 {
            s -= a[(i, k)] * x[k];
        }
        x[i] = s / a[(i, i)];
    }
    Some(x)
}

/// Solves m X = b column by column.
fn solve3_mat(m: &Mat3, b: &Mat3) -> Option<Mat3> {
    let mut out = Mat3::zeros();
    for j in 0..3 {
        let col = solve3(m, &b.column(j).into_owned())?;
        out.set_column(j, &col);
    }
    Some(out)
}

/// Eigenvalues of a symmetric 3×3 matrix in ascending order (trigonometric closed form).
fn eig_sym3(a: &Mat3) -> Vec3 {
    let p1 = a[(0, 1)] * a[(0, 1)] + a[(0, 2)] * a[(0, 2)] + a[(1, 2)] * a[(1, 2)];
    let q = (a[(0, 0)] + a[(1, 1)] + a[(2, 2)]) / 3.0;
    let d = [a[(0, 0)] - q, a[(1, 1)] - q, a[(2, 2)] - q];
    let p2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    if p.is_nan() || p <= 0.0 {
        return Vec3::repeat(q);
    }
    let b = (a - Mat3::from_diagonal_element(q)) / p;
    let det = b[(0, 0)] * (b[(1, 1)] * b[(2, 2)] - b[(1, 2)] * b[(2, 1)])
        - b[(0, 1)] * (b[(1, 0)] * b[(2, 2)] - b[(1, 2)] * b[(2, 0)])
        + b[(0, 2)] * (b[(1, 0)] * b[(2, 1)] - b[(1, 1)] * b[(2, 0)]);
    let phi = (0.5 * det).clamp(-1.0, 1.0).acos() / 3.0;
    let l_hi = q + 2.0 * p * phi.cos();
    let l_lo = q + 2.0 * p * (phi + 2.0 * PI / 3.0).cos();
    let l_mid = 3.0 * q - l_hi - l_lo;
    Vec3::new(l_lo, l_mid, l_hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::history::{HistoryField, LawPointHistory, SiteHistory};
    use crate::contact::interface::AdhesiveResponse;
    use crate::contact::rcc::{adhesive_force, beta_update, BondState, RccParams};
    use crate::contact::test_support::*;
    use crate::Vec2;
    use std::sync::Arc;

    use crate::mat3_from_rows;

    static DRY: std::sync::LazyLock<InterfaceLaw> =
        std::sync::LazyLock::new(|| InterfaceLaw::coulomb(0.3));

    fn problem<'a>(
        law: &'a InterfaceLaw,
        w: Mat3,
        x_free: Vec3,
        bond0: BondState,
    ) -> PointProblem<'a> {
        PointProblem {
            w_aa: w,
            x_free,
            law,
            history0: bond0.encode(),
            dt: 1e-4,
            area: 1e-6,
            rho: default_rho(w),
        }
    }

    /// A bond law that is not RCC, defined here and nowhere else: a linear spring of
    /// stiffness k per unit area [N/m³] on the normal opening, always bonded, with no
    /// history. Plugged into a pair's law, the point solver uses it as it uses RCC.
    #[derive(Debug)]
    struct NormalSpring {
        k: f64,
    }

    impl Interface for NormalSpring {
        fn history_fields(&self) -> &'static [HistoryField] {
            &[]
        }
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
        fn bond_traction(&self) -> f64 {
            self.k * 1e-3
        }
        fn is_adhesive(&self) -> bool {
            true
        }
        fn adhesion_at(&self, _: &PointHistory, _: f64, area: f64, x: Vec3) -> AdhEval {
            let ka = self.k * area;
            let mut history = PointHistory::default();
            history.0[0] = 1.0;
            AdhEval {
                history,
                force: v3(0.0, 0.0, -ka * x[2]),
                stiff: Mat3::from_diagonal(&v3(0.0, 0.0, ka)),
                energy: 0.5 * ka * x[2] * x[2],
            }
        }
        fn frozen_springs(&self, _: &PointHistory, area: f64) -> Option<FrozenSprings> {
            Some(FrozenSprings {
                stiffness: v3(0.0, 0.0, self.k * area),
                stretch: Vec2::zeros(),
            })
        }
        fn adhesive_response(
            &self,
            start: &PointHistory,
            dt: f64,
            area: f64,
            x: Vec3,
        ) -> Option<AdhesiveResponse> {
            let e = self.adhesion_at(start, dt, area, x);
            Some(AdhesiveResponse {
                history: e.history,
                force: e.force,
                secant_stiffness: e.stiff,
                energy: e.energy,
            })
        }
        fn point_history(&self, _: &SiteHistory, _: &[[f64; 3]; 3]) -> PointHistory {
            PointHistory::default()
        }
        fn commit(&self, _: &PointHistory, _: &PointSolution, _: &[[f64; 3]; 3]) -> SiteHistory {
            SiteHistory::default()
        }
        fn release(&self, _: &SiteHistory) -> SiteHistory {
            SiteHistory::default()
        }
    }

    /// A point pulled open (x_free along +n) against a bond law of its own: the dry force is
    /// zero and the spring's force −kA x_n n gives x_n = x_free,n / (1 + W_nn k A) (W
    /// diagonal), with no tangential force; the solver reaches the new law only through the
    /// pair's `InterfaceLaw`. Tolerance 1e-9 relative: the point solver's own.
    #[test]
    fn a_bond_law_of_its_own_is_solved_through_the_pair_law() {
        let law = InterfaceLaw {
            mu: 0.3,
            bond: Arc::new(NormalSpring { k: 2e12 }),
            anisotropy: None,
        };
        let w = Mat3::from_diagonal(&v3(1e-6, 1e-6, 2e-6));
        let x_free = v3(0.0, 0.0, 1e-5);
        let p = problem(&law, w, x_free, BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Apart);
        assert_eq!(s.r_dry, Vec3::zeros());
        let ka = 2e12 * p.area;
        let xn = 1e-5 / (1.0 + 2e-6 * ka);
        assert!((s.x[2] - xn).abs() <= 1e-9 * xn, "{} vs {xn}", s.x[2]);
        assert!((s.r_adh[2] + ka * xn).abs() <= 1e-9 * ka * xn);
        assert_eq!((s.r_adh[0], s.r_adh[1]), (0.0, 0.0));
        assert!(s.bonded());
        assert_eq!(format!("{law:?}").matches("NormalSpring").count(), 1);
    }

    /// Independent check of a point solution against the laws of docs/model.md §5: x = x_free + W r,
    /// r̄ ∈ K_μ, Signorini complementarity, Coulomb sliding rule, and the RCC part.
    fn check_solution(p: &PointProblem, s: &PointSolution, tol: f64) {
        let r = s.r();
        let (w, x_free) = (p.w_aa, p.x_free);
        let x = x_free + w * r;
        let xs = x_free.norm().max(x.norm()).max(f64::MIN_POSITIVE);
        let parts = xs + (w * s.r_dry).norm() + (w * s.r_adh).norm();
        assert!(
            (x - s.x).norm() <= 1e-12 * parts,
            "x = x_free + W r: {x:?} vs {:?} ({s:?}, {p:?})",
            s.x
        );
        let mu = p.law.mu;
        let fs = r.norm() + p.rho * x_free.norm();
        let rd = s.r_dry;
        assert!(rd[2] >= 0.0, "dry normal force is compressive");
        assert!(rd[0].hypot(rd[1]) <= mu * rd[2] * (1.0 + 1e-12) + 1e-300);
        let xt = x[0].hypot(x[1]);
        match s.state {
            ContactState::Apart => {
                assert_eq!(rd, Vec3::zeros());
                assert!(x[2] >= -tol * xs, "apart means open gap: {}", x[2]);
            }
            ContactState::Stick => {
                assert!(x[2].abs() <= tol * xs, "stick gap {}", x[2]);
                assert!(xt <= tol * xs, "stick slip {xt}");
            }
            ContactState::Slide => {
                assert!(x[2].abs() <= tol * xs, "slide gap {}", x[2]);
                let rt = rd[0].hypot(rd[1]);
                assert!((rt - mu * rd[2]).abs() <= tol * fs, "on the cone");
                if rt > tol * fs && xt > tol * xs {
                    let c = (rd[0] * x[0] + rd[1] * x[1]) / (rt * xt);
                    assert!(c < -1.0 + 1e-6, "friction opposes slip: cos = {c}");
                }
            }
        }
        let adhesion = p
            .law
            .as_any()
            .downcast_ref::<crate::contact::rcc::Rcc>()
            .unwrap()
            .0;
        match &adhesion {
            None => assert_eq!(s.r_adh, Vec3::zeros()),
            Some(a) => {
                let (b0, b1) = (BondState::decode(&p.history0), end(s));
                let ut = Vec2::new(b0.ut[0] + x[0], b0.ut[1] + x[1]);
                let beta = beta_update(b0.beta, p.dt, a, x[2], ut);
                assert!((beta - b1.beta).abs() <= 1e-9, "β {beta} vs {}", b1.beta);
                let ra = adhesive_force(beta, a, x[2], ut, p.area);
                let scale = ra.norm() + p.area * a.peak_traction();
                assert!(
                    (ra - s.r_adh).norm() <= tol * scale,
                    "{ra:?} vs {:?}",
                    s.r_adh
                );
            }
        }
    }

    #[test]
    fn pull_off_through_the_point_solver() {
        // A soft-adhesion point (C_n A W_nn = 2e-3) pulled open quasi-statically (b = 1e-6,
        // Δt = 1 s): the tensile force follows A·C_n x min(1, w/(C_n x²))² at the solved gap and
        // peaks at A·√(C_n w).
        let rcc = RccParams::new(20.0, 2e9, 2e9, 1e-6);
        let law = InterfaceLaw::rcc(0.3, Some(rcc), None);
        let xc = rcc.critical_opening();
        let area = 1e-6;
        let w = diag(1e-6, 1e-6, 1e-6);
        let mut bond = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        };
        let mut peak = 0.0_f64;
        for k in 1..=10_000 {
            let a = 1e-3 * k as f64 * xc;
            let mut p = problem(&law, w, v3(0.0, 0.0, a), bond);
            p.dt = 1.0;
            let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
            assert!(s.converged && s.iterations == 1, "step {k}: {s:?}");
            assert_eq!(s.state, ContactState::Apart);
            let x = s.x[2];
            let b = (rcc.w / (rcc.cn * x * x)).min(1.0);
            let expect = area * rcc.cn * x * b * b;
            let scale = area * rcc.peak_traction();
            assert!((-s.r()[2] - expect).abs() <= 1e-5 * scale, "step {k}");
            peak = peak.max(-s.r()[2]);
            bond = BondState {
                beta: end(&s).beta,
                ut: end(&s).ut,
                damage: 0.0,
            };
        }
        assert!(
            rel(peak, area * (rcc.cn * rcc.w).sqrt()) < 1e-4,
            "peak {peak}"
        );
    }

    #[test]
    fn stiff_adhesion_in_contact_sheared() {
        // C_t A W_tt = C_n A W_nn = 100, bonded (β₀ = 1) with a stretched link, pressed and
        // sheared: stick below the friction limit, slide above; the answer comes in ≤ 8
        // iterations either way.
        let law = InterfaceLaw::rcc(0.4, Some(paper_rcc()), None);
        let w = diag(0.05, 0.05, 0.05);
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::new(2e-5, 0.0),
            damage: 0.0,
        };
        // r̃(0) = (−0.04, 0, 0) N; pressing with 0.2 N gives μ r_n = 0.08 N.
        for (shear, state) in [(0.0, ContactState::Stick), (-5e-3, ContactState::Slide)] {
            let p = problem(&law, w, v3(shear, 0.0, -1e-2), bond);
            let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
            assert!(s.converged);
            assert_eq!(s.state, state, "shear {shear}");
            assert!(s.iterations <= 8, "{} iterations", s.iterations);
            check_solution(&p, &s, 1e-10);
            assert!(rel(s.r()[2], 0.2) < 1e-10);
        }
    }

    // ------------------------------------------------------------------ point solver

    #[test]
    fn default_rho_is_inverse_largest_eigenvalue() {
        let w = mat3_from_rows([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(rel(default_rho(w), 1.0 / 3.0) < 1e-14);
        assert!(rel(default_rho(diag(1e-6, 2e-6, 4e-6)), 2.5e5) < 1e-14);
        assert_eq!(default_rho(Mat3::zeros()), 1.0);
        let mut rng = Rng(3);
        for _ in 0..1000 {
            let hi = 10f64.powf(rng.uniform(-6.9, -3.0));
            let w = rng.spd(1e-7, hi);
            let ev = eig_sym3(&w);
            let hi = w
                .row_iter()
                .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
                .fold(0.0, f64::max);
            assert!(ev[2] <= hi * (1.0 + 1e-12) && ev[0] > 0.0);
            let rho = default_rho(w);
            assert!(rel(rho * ev[2], 1.0) < 1e-12);
        }
    }

    #[test]
    fn pressed_into_rigid_support() {
        let w = diag(1e-6, 1e-6, 2e-6);
        let p = problem(&DRY, w, v3(0.0, 0.0, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Stick);
        assert!(s.x[2].abs() <= 1e-12 * 1e-4, "x_n = {}", s.x[2]);
        assert!(rel(s.r_dry[2], 1e-4 / 2e-6) < 1e-10, "r_n = {}", s.r_dry[2]);
        check_solution(&p, &s, 1e-10);
    }

    #[test]
    fn stick_then_slide() {
        let w = diag(1e-6, 1e-6, 2e-6);
        // Stick: the sticking force 10 N < μ r_n = 15 N.
        let p = problem(&DRY, w, v3(1e-5, 0.0, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Stick);
        assert!(s.x[0].hypot(s.x[1]) <= 1e-12 * 1e-4);
        assert_vec_close(s.r(), v3(-10.0, 0.0, 50.0), 1e-10);
        check_solution(&p, &s, 1e-10);
        // Slide: the sticking force would be 50 N > 15 N.
        let p = problem(&DRY, w, v3(3e-5, 4e-5, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Slide);
        assert_vec_close(s.r(), v3(-9.0, -12.0, 50.0), 1e-10);
        assert_vec_close(s.x, v3(2.1e-5, 2.8e-5, 0.0), 1e-10);
        check_solution(&p, &s, 1e-10);
        // Frictionless: r_t = 0, all of x_free_t becomes slip.
        let law = InterfaceLaw::rcc(0.0, None, None);
        let p = problem(&law, w, v3(3e-5, 4e-5, -1e-4), BondState::default());
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
        assert!(s.converged);
        assert_vec_close(s.r(), v3(0.0, 0.0, 50.0), 1e-12);
        assert_vec_close(s.x, v3(3e-5, 4e-5, 0.0), 1e-10);
    }

    #[test]
    fn apart_without_adhesion_has_no_force() {
        let w = diag(1e-6, 1e-6, 2e-6);
        let p = problem(&DRY, w, v3(1e-5, 0.0, 1e-4), BondState::default());
        let s = solve_point(&p, v3(5.0, 0.0, 30.0), 1e-12, 50);
        assert!(s.converged);
        assert_eq!(s.state, ContactState::Apart);
        assert_eq!(s.r(), Vec3::zeros());
        assert_eq!(s.x, p.x_free);
        assert!(s.iterations <= 2);
    }

    #[test]
    fn bonded_point_opened_slightly_pulls_back() {
        let law = InterfaceLaw::rcc(0.3, Some(paper_rcc()), None);
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        };
        // C_n A = 2e3 N/m; C_n A W_nn = 0.2 (soft) and 100 (stiff adhesion).
        for wnn in [1e-4, 5e-2] {
            let w = diag(1e-4, 1e-4, wnn);
            let p = problem(&law, w, v3(0.0, 0.0, 1e-5), bond);
            let s = solve_point(&p, Vec3::zeros(), 1e-12, 50);
            assert!(s.converged, "W_nn = {wnn}");
            let k = 2e9 * 1e-6;
            let xn = 1e-5 / (1.0 + k * wnn);
            assert_eq!(s.state, ContactState::Apart);
            assert_eq!(end(&s).beta, 1.0);
            assert!(rel(s.x[2], xn) < 1e-10, "x_n {} vs {xn}", s.x[2]);
            assert!(rel(s.r()[2], -k * xn) < 1e-10);
            assert!(s.iterations <= 3, "{} iterations", s.iterations);
            check_solution(&p, &s, 1e-10);
        }
    }

    #[test]
    fn bond_stretch_bookkeeping() {
        let law = InterfaceLaw::rcc(0.3, Some(paper_rcc()), None);
        let w = diag(1e-4, 1e-4, 1e-4);
        // Bonded, pressed and pulled sideways: stretch grows by the slip, bond survives.
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::new(1e-6, 0.0),
            damage: 0.0,
        };
        let p = problem(&law, w, v3(2e-3, 0.0, -1e-3), bond);
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(s.converged);
        assert!(end(&s).beta > 0.0);
        assert_eq!(end(&s).ut, Vec2::new(1e-6 + s.x[0], s.x[1]));
        check_solution(&p, &s, 1e-9);
        // Far apart with a weak bond: broken, stretch reset.
        let bond = BondState {
            beta: 2e-4,
            ut: Vec2::new(1e-6, 0.0),
            damage: 0.0,
        };
        let mut p = problem(&law, w, v3(0.0, 0.0, 3e-2), bond);
        p.dt = 1.0;
        let s = solve_point(&p, Vec3::zeros(), 1e-12, 100);
        assert!(s.converged);
        assert_eq!(end(&s).beta, 0.0);
        assert_eq!(end(&s).ut, Vec2::zeros());
        assert_eq!(s.r(), Vec3::zeros());
    }

    /// A set of point problems over stiffness ratios, loadings and bond states.
    fn sweep_cases(rng: &mut Rng, n: usize, mut f: impl FnMut(&PointProblem, &str)) {
        let area = 1e-6;
        for i in 0..n {
            let ratio = [0.0, 1e-2, 1.0, 100.0, 1e4][i % 5];
            let coupled = (i / 5) % 2 == 1;
            // W with λ_max = W_ref; C_n A W_ref = ratio.
            let wref = if ratio > 0.0 {
                ratio / (2e9 * area)
            } else {
                1e-4
            };
            let w = if coupled {
                rng.spd(wref / 10.0, wref)
            } else {
                diag(
                    wref * rng.uniform(0.3, 1.0),
                    wref * rng.uniform(0.3, 1.0),
                    wref,
                )
            };
            let mu = [0.0, 0.2, 0.4, 0.8, 1.2][(i / 10) % 5];
            let rcc = RccParams::new(20.0, 2e9, 2e9, v3(0.1, 1e-6, 0.0)[(i / 50) % 3]);
            let law = InterfaceLaw::rcc(mu, if ratio > 0.0 { Some(rcc) } else { None }, None);
            let xc = rcc.critical_opening();
            let a = 10f64.powf(rng.uniform(-2.0, 0.7)) * xc * (1.0 + ratio);
            let x_free = v3(
                a * rng.uniform(-1.0, 1.0),
                a * rng.uniform(-1.0, 1.0),
                a * rng.uniform(-1.0, 1.0),
            );
            let bond = BondState {
                beta: [0.0, 1.0, 0.5, 0.01][(i / 3) % 4],
                ut: Vec2::new(xc * rng.uniform(-0.5, 0.5), xc * rng.uniform(-0.5, 0.5)),
                damage: 0.0,
            };
            let p = PointProblem {
                w_aa: w,
                x_free,
                law: &law,
                history0: bond.encode(),
                dt: 1e-4,
                area,
                rho: default_rho(w),
            };
            let label = format!("case {i}: ratio {ratio}, coupled {coupled}, μ {mu}");
            f(&p, &label);
        }
    }

    #[test]
    fn converges_fast_over_stiffness_ratios() {
        // 1500 random problems: C_n A λ_max(W) ∈ {dry, 0.01, 1, 100, 1e4}, diagonal or coupled
        // W (condition number up to 10), μ ∈ {0, 0.2, 0.4, 0.8, 1.2}, b ∈ {0.1, 1e-6, 0},
        // β₀ ∈ {0, 0.01, 0.5, 1}, random stretch and loads from 0.01 to 5 (1 + ratio) x_c.
        let mut rng = Rng(2024);
        let mut stats = [(0usize, 0usize, 0usize); 5];
        let mut states = [0usize; 3];
        sweep_cases(&mut rng, 1500, |p, label| {
            let s = solve_point(p, Vec3::zeros(), 1e-10, 50);
            assert!(s.converged, "{label}: {s:?} {p:?}");
            check_solution(p, &s, 1e-8);
            let k = label_ratio_index(label);
            stats[k].0 = stats[k].0.max(s.iterations);
            stats[k].1 += s.iterations;
            stats[k].2 += 1;
            states[s.state as usize] += 1;
        });
        for (k, (worst, total, n)) in stats.iter().enumerate() {
            let mean = *total as f64 / *n as f64;
            eprintln!("ratio class {k}: worst {worst}, mean {mean:.2} iterations over {n}");
            let (worst_max, mean_max) = if k <= 2 { (10, 4.0) } else { (16, 5.0) };
            assert!(
                *worst <= worst_max && mean <= mean_max,
                "class {k}: {worst} {mean}"
            );
        }
        assert!(states.iter().all(|&n| n > 30), "states {states:?}");
    }

    fn label_ratio_index(label: &str) -> usize {
        let ratio = label
            .split("ratio ")
            .nth(1)
            .and_then(|t| t.split(',').next());
        match ratio {
            Some("0") => 0,
            Some("0.01") => 1,
            Some("1") => 2,
            Some("100") => 3,
            _ => 4,
        }
    }

    #[test]
    fn plain_fixed_point_with_default_rho_converges_for_dry_contact() {
        // The bi-potential fixed point alone (no Newton step) with ρ = 1/λ_max converges and
        // agrees with the case-by-case solver.
        let mut rng = Rng(99);
        let mut worst = 0;
        for i in 0..300 {
            let w = rng.spd(1e-6, 1e-5);
            let law = InterfaceLaw::rcc(v3(0.0, 0.3, 0.8)[i % 3], None, None);
            let x_free = v3(
                rng.uniform(-1e-4, 1e-4),
                rng.uniform(-1e-4, 1e-4),
                rng.uniform(-1e-4, 1e-4),
            );
            let p = problem(&law, w, x_free, BondState::default());
            let fp = solve_point_impl(
                &p,
                Vec3::zeros(),
                1e-10,
                5000,
                Method::Bipotential { newton: false },
            );
            assert!(fp.converged, "case {i}");
            worst = worst.max(fp.iterations);
            let nw = solve_point(&p, Vec3::zeros(), 1e-10, 50);
            assert!(nw.converged);
            assert_eq!(fp.state, nw.state, "case {i}");
            let scale = fp.r().norm() + p.rho * x_free.norm();
            assert!((fp.r() - nw.r()).norm() <= 1e-8 * scale, "case {i}");
        }
        // Condition number 10: the fixed point needs ~κ·ln(1/tol) iterations.
        assert!(worst <= 400, "worst {worst}");
    }

    #[test]
    fn rho_from_max_diagonal_can_diverge() {
        // W = εI + (1 − ε) v vᵀ, v = (1, 1, 1)/√3: λ_max = 1 but W_ii ≈ 1/3, so ρ = 1/max W_ii ≈ 3
        // exceeds 2/λ_max and the sticking iteration r ← r − ρ W r − ρ x_free diverges.
        let eps = 0.05;
        let w = Mat3::from_fn(|i, j| (1.0 - eps) / 3.0 + if i == j { eps } else { 0.0 });
        let law = InterfaceLaw::rcc(1.0, None, None);
        let mut p = problem(&law, w, v3(0.0, 0.0, -1.0), BondState::default());
        let ok = solve_point_impl(
            &p,
            Vec3::zeros(),
            1e-10,
            5000,
            Method::Bipotential { newton: false },
        );
        assert!(ok.converged);
        check_solution(&p, &ok, 1e-8);
        p.rho = 1.0 / w[(0, 0)];
        let bad = solve_point_impl(
            &p,
            Vec3::zeros(),
            1e-10,
            5000,
            Method::Bipotential { newton: false },
        );
        assert!(!bad.converged);
        // The default solver does not depend on ρ for its answer.
        let s = solve_point(&p, Vec3::zeros(), 1e-10, 50);
        assert!(s.converged);
        assert!((s.r() - ok.r()).norm() <= 1e-8 * ok.r().norm());
    }

    #[test]
    fn stiff_snap_off_and_hysteresis() {
        // 1-D pull-off through a compliance with C_n A W_nn = 100, quasi-static (b = 1e-6,
        // Δt = 1 s). The bonded branch x = a/101 holds up to a = 101 x_c, then the point snaps
        // to x ≈ a with β < ε: broken. Coming back, a bond re-forms at a distance (β∞ ≥ ε below
        // 100 x_c) and the point stays on the far branch x + 100 x_c⁴/x³ = a until its turning
        // point a* = (4/3)·300^{1/4} x_c ≈ 5.55 x_c, where it snaps back into the bonded branch.
        let rcc = RccParams::new(20.0, 2e9, 2e9, 1e-6);
        let law = InterfaceLaw::rcc(0.3, Some(rcc), None);
        let xc = rcc.critical_opening();
        let w = diag(0.05, 0.05, 0.05);
        let mut bond = BondState {
            beta: 1.0,
            ut: Vec2::zeros(),
            damage: 0.0,
        };
        let mut r = Vec3::zeros();
        let mut snap_off = None;
        let mut snap_back = None;
        let mut prev_xn = 0.0;
        let steps: Vec<f64> = (0..=300)
            .map(|k| 0.5 * k as f64)
            .chain((0..300).rev().map(|k| 0.5 * k as f64))
            .collect();
        for (k, &af) in steps.iter().enumerate() {
            let mut p = problem(&law, w, v3(0.0, 0.0, af * xc), bond);
            p.dt = 1.0;
            let s = solve_point(&p, r, 1e-12, 50);
            assert!(s.converged, "step {k}");
            check_solution(&p, &s, 1e-9);
            let xn = s.x[2];
            let loading = k <= 300;
            if loading && snap_off.is_none() && xn > 10.0 * xc {
                snap_off = Some(af);
            }
            if !loading && snap_back.is_none() && xn < 2.0 * xc && prev_xn > 2.0 * xc {
                snap_back = Some(af);
            }
            if loading && af < 100.0 {
                assert!(
                    rel(xn, af * xc / 101.0) < 1e-9,
                    "bonded branch at a = {af} x_c"
                );
                assert_eq!(end(&s).beta, 1.0);
            }
            prev_xn = xn;
            bond = BondState {
                beta: end(&s).beta,
                ut: end(&s).ut,
                damage: 0.0,
            };
            r = s.r_dry;
        }
        let off = snap_off.expect("snaps off");
        let back = snap_back.expect("snaps back");
        assert!((101.0..=101.5).contains(&off), "snap-off at a = {off} x_c");
        assert!((5.0..=5.5).contains(&back), "snap-back at a = {back} x_c");
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let rcc = paper_rcc();
        let law = InterfaceLaw::rcc(0.5, Some(rcc), None);
        let bond = BondState {
            beta: 1.0,
            ut: Vec2::new(1e-5, 0.0),
            damage: 0.0,
        };
        let cases: [(Mat3, Vec3, f64, f64); 6] = [
            (Mat3::zeros(), v3(0.0, 0.0, -1e-4), 1e-6, 1e-4),
            (Mat3::zeros(), v3(1e-5, 0.0, 1e-5), 1e-6, 1e-4),
            (diag(1e-4, 1e-4, 1e-4), v3(1e-5, 0.0, 1e-5), 0.0, 1e-4),
            (diag(1e-4, 1e-4, 1e-4), v3(1e-5, 0.0, 1e-5), 1e-6, 0.0),
            (
                diag(1e300, 1.0, 1e-300),
                v3(1e300, -1e300, 1e-300),
                1e300,
                1e300,
            ),
            (diag(1e-4, 1e-4, 1e-4), v3(f64::NAN, 0.0, 1.0), 1e-6, 1e-4),
        ];
        for (w, xf, area, dt) in cases {
            let p = PointProblem {
                w_aa: w,
                x_free: xf,
                law: &law,
                history0: bond.encode(),
                dt,
                area,
                rho: default_rho(w),
            };
            let s = solve_point(&p, v3(1.0, 2.0, 3.0), 1e-10, 30);
            assert!(s.iterations <= 30);
            let _ = solve_point(&p, Vec3::repeat(f64::NAN), 1e-10, 0);
        }
        // W = 0 with an open gap and no adhesion: r = 0 at once.
        let p = PointProblem {
            w_aa: Mat3::zeros(),
            x_free: v3(0.0, 0.0, 1e-3),
            law: &DRY,
            history0: PointHistory::default(),
            dt: 1e-4,
            area: 1e-6,
            rho: 1.0,
        };
        let s = solve_point(&p, Vec3::zeros(), 1e-10, 10);
        assert!(s.converged && s.r() == Vec3::zeros());
    }
}
