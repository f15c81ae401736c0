//! The θ-method over one step (docs/model.md, time integration): the predictor, the
//! out-of-balance force G(u₁) without contact, the step's potential whose gradient it is, the
//! coefficients of K̄, the end velocity and the work done over the step.

pub use crate::linalg::norm;
use crate::linalg::BlockPattern;
use crate::problem::Predictor;

/// Mass and damping matrices, stored on the discretisation's block pattern.
pub struct Inertia {
    /// Mass matrix M [kg] (consistent or lumped), values on the pattern.
    pub mass: Vec<f64>,
    /// Rayleigh damping A = α M + β K₀ [N·s/m], when the problem has any.
    pub damping: Option<Vec<f64>>,
}

/// Buffers the Newton loop reuses from one iteration to the next.
#[derive(Default)]
pub struct Workspace {
    /// G(u) without contact on the free unknowns [N].
    pub g: Vec<f64>,
    /// End-of-step velocity of the iterate [m/s].
    pub v1: Vec<f64>,
    tmp: Vec<f64>,
    acc: Vec<f64>,
    /// The last assembled tangent's values, kept for the next assembly to write into.
    pub tangent: Vec<f64>,
}

impl Workspace {
    fn resize(&mut self, n: usize) {
        for b in [&mut self.g, &mut self.v1, &mut self.tmp, &mut self.acc] {
            b.clear();
            b.resize(n, 0.0);
        }
    }
}

/// One θ-method step from a committed state (u₀, v₀) over Δt.
pub struct ThetaStep<'a> {
    /// Step size Δt [s].
    pub dt: f64,
    theta: f64,
    xi: f64,
    quasi_static: bool,
    predictor: Predictor,
    /// Coefficient of K in K̄ (ξ, or 1 when quasi-static).
    pub c_stiff: f64,
    /// Coefficient of M in K̄, 1/(θΔt²) (0 when quasi-static) [1/s²].
    pub c_mass: f64,
    /// Coefficient of A in K̄, ξ/(θΔt) (0 when quasi-static) [1/s].
    pub c_damp: f64,
    u0: &'a [f64],
    v0: &'a [f64],
    f_ext0: &'a [f64],
    /// Loads and gravity at the end of the step [N].
    pub f_ext1: Vec<f64>,
    /// The terms fixed over the step, (1−ξ)(F_ext⁰ − F_int⁰ − A v₀) [N].
    fixed: Vec<f64>,
    inertia: &'a Inertia,
    pattern: &'a BlockPattern,
}

/// G(u) and what the line search and the convergence test need of it.
pub struct Balance {
    /// The step's potential Π(u) [J], whose gradient is G(u) (without contact).
    pub potential: f64,
    /// Force scale of the iterate: internal, external and inertial forces [N].
    pub scale: f64,
}

/// The time-integration settings a step needs.
pub struct Scheme {
    /// θ of the velocity update.
    pub theta: f64,
    /// ξ of the force average.
    pub xi: f64,
    /// Quasi-static: no inertia or damping.
    pub quasi_static: bool,
    /// The first iterate of a quasi-static step.
    pub predictor: Predictor,
}

impl Scheme {
    /// The settings of a problem's time stepping.
    pub fn of(settings: &crate::problem::TimeSettings) -> Self {
        Scheme {
            theta: settings.theta,
            xi: settings.xi,
            quasi_static: settings.quasi_static,
            predictor: settings.predictor,
        }
    }
}

impl<'a> ThetaStep<'a> {
    /// The step from `(u0, v0)`, with loads `f_ext0` and internal force `f_int0` at its start
    /// and `f_ext1` at its end [N].
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scheme: &Scheme,
        dt: f64,
        (u0, v0): (&'a [f64], &'a [f64]),
        (f_ext0, f_int0): (&'a [f64], &[f64]),
        f_ext1: Vec<f64>,
        inertia: &'a Inertia,
        pattern: &'a BlockPattern,
    ) -> Self {
        let (theta, xi, qs) = (scheme.theta, scheme.xi, scheme.quasi_static);
        let n = u0.len();
        let mut fixed = vec![0.0; n];
        if !qs {
            let mut av0 = vec![0.0; n];
            if let Some(a) = &inertia.damping {
                pattern.symmetric_matvec(a, v0, &mut av0);
            }
            for i in 0..n {
                fixed[i] = (1.0 - xi) * (f_ext0[i] - f_int0[i] - av0[i]);
            }
        }
        ThetaStep {
            dt,
            theta,
            xi,
            quasi_static: qs,
            predictor: scheme.predictor,
            c_stiff: if qs { 1.0 } else { xi },
            c_mass: if qs { 0.0 } else { 1.0 / (theta * dt * dt) },
            c_damp: if qs { 0.0 } else { xi / (theta * dt) },
            u0,
            v0,
            f_ext0,
            f_ext1,
            fixed,
            inertia,
            pattern,
        }
    }

    /// The first iterate: constant velocity for dynamics; when quasi-static, the last step's
    /// increment carried on ([`Predictor::Secant`]: v₀ is then the last step's mean rate, see
    /// [`ThetaStep::end_velocity`]) or the last state ([`Predictor::Last`]). The prescribed
    /// components are still to be imposed. Sizes the workspace for the step.
    pub fn predict(&self, ws: &mut Workspace) -> Vec<f64> {
        ws.resize(self.u0.len());
        if self.quasi_static && self.predictor == Predictor::Last {
            self.u0.to_vec()
        } else {
            (0..self.u0.len())
                .map(|i| self.u0[i] + self.dt * self.v0[i])
                .collect()
        }
    }

    /// G(u) without contact into `ws.g` and `ws.v1`, given the internal force `f_int` and
    /// strain energy `energy` [J] at `u`:
    ///   G = M (u − u₀ − Δt v₀)/(θΔt²) + ξ (F_int − F_ext¹ + A v₁) − (1−ξ)(F_ext⁰ − F_int⁰ − A v₀).
    pub fn balance(&self, u: &[f64], f_int: &[f64], energy: f64, ws: &mut Workspace) -> Balance {
        let n = u.len();
        let (theta, dt, xi) = (self.theta, self.dt, self.xi);
        let (u0, v0) = (self.u0, self.v0);
        for i in 0..n {
            ws.v1[i] = (u[i] - u0[i]) / (theta * dt) - (1.0 - theta) / theta * v0[i];
        }
        let g = &mut ws.g;
        for i in 0..n {
            g[i] = self.c_stiff * (f_int[i] - self.f_ext1[i]) - self.fixed[i];
        }
        let mut scale = norm(f_int).max(norm(&self.f_ext1)).max(norm(&self.fixed));
        // Strain energy, loads, and the inertia and damping terms of the θ-method.
        let mut potential = self.c_stiff * energy
            - (0..n)
                .map(|i| (self.c_stiff * self.f_ext1[i] + self.fixed[i]) * u[i])
                .sum::<f64>();
        if !self.quasi_static {
            let tmp = &mut ws.tmp;
            tmp.iter_mut().for_each(|x| *x = 0.0);
            for i in 0..n {
                ws.acc[i] = (u[i] - u0[i] - dt * v0[i]) * self.c_mass;
            }
            self.pattern
                .symmetric_matvec(&self.inertia.mass, &ws.acc, tmp);
            scale = scale.max(norm(tmp));
            for i in 0..n {
                g[i] += tmp[i];
                potential += 0.5 * (u[i] - u0[i] - dt * v0[i]) * tmp[i];
            }
            if let Some(a) = &self.inertia.damping {
                tmp.iter_mut().for_each(|x| *x = 0.0);
                self.pattern.symmetric_matvec(a, &ws.v1, tmp);
                for i in 0..n {
                    g[i] += xi * tmp[i];
                }
                // ξ A v₁ is the gradient of ξ[(u − u₀)ᵀA(u − u₀)/(2θΔt) − (1−θ)/θ v₀ᵀA(u − u₀)].
                for i in 0..n {
                    ws.acc[i] = 0.5 * (u[i] - u0[i]) / (theta * dt) - (1.0 - theta) / theta * v0[i];
                }
                tmp.iter_mut().for_each(|x| *x = 0.0);
                self.pattern.symmetric_matvec(a, &ws.acc, tmp);
                potential += xi * (0..n).map(|i| (u[i] - u0[i]) * tmp[i]).sum::<f64>();
            }
        }
        Balance { potential, scale }
    }

    /// The terms of K̄ = c_stiff K + c_mass M + c_damp A, given the tangent K at the iterate.
    pub fn matrix_terms<'b>(&'b self, tangent: &'b [f64]) -> Vec<(f64, &'b [f64])> {
        let mut terms: Vec<(f64, &[f64])> =
            vec![(self.c_stiff, tangent), (self.c_mass, &self.inertia.mass)];
        if let Some(a) = &self.inertia.damping {
            terms.push((self.c_damp, a));
        }
        terms
    }

    /// The diagonal of K̄ at the iterate whose tangent is `tangent`.
    pub fn matrix_diagonal(&self, tangent: &[f64]) -> Vec<f64> {
        let pattern = self.pattern;
        (0..pattern.dim())
            .map(|d| {
                let q = pattern.diagonal_position(d);
                let a = self.inertia.damping.as_ref().map_or(0.0, |a| a[q]);
                self.c_stiff * tangent[q] + self.c_mass * self.inertia.mass[q] + self.c_damp * a
            })
            .collect()
    }

    /// The committed end velocity of the converged iterate `u` (`v1` is its θ-method
    /// velocity; quasi-static runs report the mean velocity over the step) [m/s].
    pub fn end_velocity(&self, u: &[f64], v1: &[f64]) -> Vec<f64> {
        if self.quasi_static {
            (0..u.len())
                .map(|i| (u[i] - self.u0[i]) / self.dt)
                .collect()
        } else {
            v1.to_vec()
        }
    }

    /// Work done on the bodies over the step [J] by the loads, the supports' `reactions` and
    /// the contact forces `contact_force` [N], at the converged iterate `u`.
    pub fn work(&self, u: &[f64], reactions: &[f64], contact_force: &[f64]) -> f64 {
        let mut work = 0.0;
        for i in 0..u.len() {
            let du = u[i] - self.u0[i];
            let f_applied = if self.quasi_static {
                self.f_ext1[i]
            } else {
                (1.0 - self.xi) * self.f_ext0[i] + self.xi * self.f_ext1[i]
            };
            work += du * (f_applied + reactions[i] + contact_force[i]);
        }
        work
    }

    /// ‖u − u₀‖: the step's displacement increment [m].
    pub fn increment(&self, u: &[f64]) -> f64 {
        (0..u.len())
            .map(|i| (u[i] - self.u0[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}
