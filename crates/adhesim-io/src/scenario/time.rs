//! The `[time]` table: the time span and step, the integrator, Newton's iteration (its
//! tolerance, limit and use of the factorisation), damping and the contact solver.

use super::{Ctx, FileTime, ScenarioError};
use adhesim::problem::{ContactSolver, NewtonMethod, Predictor, TimeSettings};

/// The validated `[time]` table; keys left out take [`TimeSettings::default`]'s values.
pub(super) fn validate_time(t: &FileTime, ctx: &Ctx) -> Result<TimeSettings, ScenarioError> {
    let d = TimeSettings::default();
    let (t_end, dt, dt_min) = time_steps(t, &d, ctx)?;
    let (theta, xi) = integrator(t, &d, ctx)?;
    let quasi_static = quasi_static(t, ctx)?;
    let lumped_mass = lumped_mass(t, ctx)?;
    let (newton_tol, max_newton) = newton(t, &d, ctx)?;
    let newton = newton_method(t, ctx)?;
    let predictor = predictor(t, ctx)?;
    let rayleigh = rayleigh(t, ctx)?;
    let (contact_solver, contact_tol) = contact_solver(t, &d, ctx)?;
    Ok(TimeSettings {
        t_end,
        dt,
        dt_min,
        theta,
        xi,
        quasi_static,
        newton_tol,
        max_newton,
        lumped_mass,
        rayleigh,
        contact_solver,
        contact_tol,
        newton,
        predictor,
    })
}

/// The end time, the time step and the smallest step [s] (`dt_min` defaults to a small
/// fraction of `dt`).
fn time_steps(t: &FileTime, d: &TimeSettings, ctx: &Ctx) -> Result<(f64, f64, f64), ScenarioError> {
    let t_end = ctx.positive("time.t_end", t.t_end)?;
    let dt = ctx.positive("time.dt", t.dt)?;
    if dt > t_end {
        return Err(ctx.err(format!(
            "`time.dt` ({dt} s) must not exceed `time.t_end` ({t_end} s)"
        )));
    }
    let dt_min = ctx.positive(
        "time.dt_min",
        t.dt_min.unwrap_or((dt * 1e-6).min(d.dt_min.max(dt * 1e-9))),
    )?;
    if dt_min > dt {
        return Err(ctx.err(format!(
            "`time.dt_min` ({dt_min}) must not exceed `time.dt` ({dt})"
        )));
    }
    Ok((t_end, dt, dt_min))
}

/// The integrator's θ (in (0, 1]) and ξ (in [0, 1]).
fn integrator(t: &FileTime, d: &TimeSettings, ctx: &Ctx) -> Result<(f64, f64), ScenarioError> {
    let theta = t.theta.unwrap_or(d.theta);
    if !(theta > 0.0 && theta <= 1.0) {
        return Err(ctx.err(format!(
            "`time.theta` must be in (0, 1] (½ = trapezoidal, 1 = backward Euler), got {theta}"
        )));
    }
    let xi = t.xi.unwrap_or(d.xi);
    if !(0.0..=1.0).contains(&xi) {
        return Err(ctx.err(format!("`time.xi` must be in [0, 1], got {xi}")));
    }
    Ok((theta, xi))
}

/// Whether `time.mode` asks for a quasi-static run (no inertia).
fn quasi_static(t: &FileTime, ctx: &Ctx) -> Result<bool, ScenarioError> {
    match t.mode.as_deref() {
        None | Some("dynamic") => Ok(false),
        Some("quasi-static") => Ok(true),
        Some(m) => Err(ctx.err(format!(
            "`time.mode` = {m:?}; valid values are \"dynamic\" and \"quasi-static\""
        ))),
    }
}

/// Whether `time.mass` asks for a lumped mass matrix.
fn lumped_mass(t: &FileTime, ctx: &Ctx) -> Result<bool, ScenarioError> {
    match t.mass.as_deref() {
        None | Some("consistent") => Ok(false),
        Some("lumped") => Ok(true),
        Some(m) => Err(ctx.err(format!(
            "`time.mass` = {m:?}; valid values are \"consistent\" and \"lumped\""
        ))),
    }
}

/// Newton's relative tolerance and its largest number of iterations per step.
fn newton(t: &FileTime, d: &TimeSettings, ctx: &Ctx) -> Result<(f64, usize), ScenarioError> {
    let newton_tol = t.newton_tol.unwrap_or(d.newton_tol);
    if !(newton_tol > 0.0 && newton_tol < 1.0) {
        return Err(ctx.err(format!(
            "`time.newton_tol` must be in (0, 1), got {newton_tol}"
        )));
    }
    let max_newton = ctx.count(
        "time.max_newton",
        t.max_newton.unwrap_or(d.max_newton),
        1000,
    )?;
    Ok((newton_tol, max_newton))
}

/// Whether `time.newton` asks for a new factorisation at every iteration (`"full"`), keeps
/// one while the iterations converge (`"modified"`), keeps one as the preconditioner of an
/// iterative solve of each correction (`"preconditioned"`), or leaves the choice to the
/// step's contact solver (`"auto"`, the default: preconditioned with the augmented-Lagrangian
/// solve, full otherwise).
fn newton_method(t: &FileTime, ctx: &Ctx) -> Result<NewtonMethod, ScenarioError> {
    match t.newton.as_deref() {
        None | Some("auto") => Ok(NewtonMethod::Auto),
        Some("full") => Ok(NewtonMethod::Full),
        Some("modified") => Ok(NewtonMethod::Modified),
        Some("preconditioned") => Ok(NewtonMethod::Preconditioned),
        Some(m) => Err(ctx.err(format!(
            "`time.newton` = {m:?}; valid values are \"auto\", \"full\", \"modified\" and \"preconditioned\""
        ))),
    }
}

/// Where a quasi-static step's Newton iterations start: the last converged state (`"last"`,
/// the default) or the last increment carried on (`"secant"`).
fn predictor(t: &FileTime, ctx: &Ctx) -> Result<Predictor, ScenarioError> {
    match t.predictor.as_deref() {
        None | Some("last") => Ok(Predictor::Last),
        Some("secant") => Ok(Predictor::Secant),
        Some(m) => Err(ctx.err(format!(
            "`time.predictor` = {m:?}; valid values are \"last\" and \"secant\""
        ))),
    }
}

/// Rayleigh damping's mass factor α [1/s] and stiffness factor β [s], 0 when left out.
fn rayleigh(t: &FileTime, ctx: &Ctx) -> Result<(f64, f64), ScenarioError> {
    let alpha = t.rayleigh_alpha.unwrap_or(0.0);
    let beta = t.rayleigh_beta.unwrap_or(0.0);
    for (k, v) in [("time.rayleigh_alpha", alpha), ("time.rayleigh_beta", beta)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(ctx.err(format!("`{k}` must be ≥ 0, got {v}")));
        }
    }
    Ok((alpha, beta))
}

/// The contact solver and its relative tolerance.
fn contact_solver(
    t: &FileTime,
    d: &TimeSettings,
    ctx: &Ctx,
) -> Result<(ContactSolver, f64), ScenarioError> {
    let contact_solver = match t.contact_solver.as_deref() {
        None => d.contact_solver,
        Some("newton") => ContactSolver::Newton,
        Some("gauss-seidel") => ContactSolver::GaussSeidel,
        Some("semismooth") => ContactSolver::Semismooth,
        Some("auto") => ContactSolver::Auto,
        Some(m) => {
            return Err(ctx.err(format!(
                "`time.contact_solver` = {m:?}; valid values are \"auto\", \"semismooth\", \"gauss-seidel\" and \"newton\""
            )))
        }
    };
    let contact_tol = t.contact_tol.unwrap_or(d.contact_tol);
    if !(contact_tol > 0.0 && contact_tol < 1.0) {
        return Err(ctx.err(format!(
            "`time.contact_tol` must be in (0, 1), got {contact_tol}"
        )));
    }
    Ok((contact_solver, contact_tol))
}
