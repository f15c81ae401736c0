//! Gravity as a function of time: each component of the acceleration a table over time,
//! so that a quasi-static run can apply it gradually (from zero to its full value over
//! the first increments) instead of at once.
//!
//! Scenario forms (`gravity` at the top level of a scenario):
//! - `gravity = [gx, gy, gz]`: constant [m/s²];
//! - `gravity = { y = [[0.0, 0.0], [1.0, -9.81]] }`: per component, a number or a table
//!   `[[t, g], ...]` (linear between points, constant outside), as for loads; a missing
//!   component is zero.

use crate::prescribed::Table;

/// Gravitational acceleration over time [m/s²], one table per component.
#[derive(Clone, Debug, PartialEq)]
pub struct Gravity {
    /// x, y and z components of the acceleration [m/s²].
    pub components: [Table; 3],
}

impl Default for Gravity {
    /// No gravity.
    fn default() -> Self {
        Gravity::constant([0.0; 3])
    }
}

impl Gravity {
    /// A constant acceleration [m/s²].
    pub fn constant(g: [f64; 3]) -> Self {
        Gravity {
            components: g.map(Table::constant),
        }
    }

    /// The acceleration at time `t` [m/s²].
    pub fn at(&self, t: f64) -> [f64; 3] {
        std::array::from_fn(|k| self.components[k].at(t))
    }

    /// Whether gravity is zero at every time.
    pub fn is_zero(&self) -> bool {
        self.components
            .iter()
            .all(|c| c.v.iter().all(|&v| v == 0.0))
    }

    /// The largest magnitude over the table points [m/s²] (the acceleration is linear
    /// between them, so this is the largest over all times).
    pub fn max_magnitude(&self) -> f64 {
        let mut times: Vec<f64> = self.components.iter().flat_map(|c| c.t.clone()).collect();
        times.push(0.0);
        times
            .iter()
            .map(|&t| {
                let g = self.at(t);
                (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
            })
            .fold(0.0, f64::max)
    }
}

/// The body force of gravity `g` on the nodes: M·ĝ for a unit acceleration along each
/// axis, so that the force at any time is Σ_k g_k(t) · `unit[k]` [N per m/s²].
pub fn unit_forces(num_dofs: usize, mass_matvec: impl Fn(&[f64], &mut [f64])) -> [Vec<f64>; 3] {
    std::array::from_fn(|k| {
        let mut e = vec![0.0; num_dofs];
        for i in (k..num_dofs).step_by(3) {
            e[i] = 1.0;
        }
        let mut f = vec![0.0; num_dofs];
        mass_matvec(&e, &mut f);
        f
    })
}

/// Adds the gravity force at acceleration `g` [m/s²] to `f` [N], from the unit forces of
/// [`unit_forces`].
pub fn add_force(f: &mut [f64], g: [f64; 3], unit: &[Vec<f64>; 3]) {
    for k in 0..3 {
        if g[k] != 0.0 {
            for (fi, ui) in f.iter_mut().zip(&unit[k]) {
                *fi += g[k] * ui;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_and_ramped_values() {
        let c = Gravity::constant([0.0, -9.81, 0.0]);
        assert_eq!(c.at(0.0), [0.0, -9.81, 0.0]);
        assert_eq!(c.at(5.0), [0.0, -9.81, 0.0]);
        assert_eq!(c.max_magnitude(), 9.81);
        let mut r = Gravity::default();
        assert!(r.is_zero());
        r.components[1] = Table {
            t: vec![0.0, 2.0],
            v: vec![0.0, -10.0],
        };
        assert!(!r.is_zero());
        assert_eq!(r.at(0.0), [0.0, 0.0, 0.0]);
        assert_eq!(r.at(0.5), [0.0, -2.5, 0.0]);
        assert_eq!(r.at(3.0), [0.0, -10.0, 0.0]);
        assert_eq!(r.max_magnitude(), 10.0);
    }

    #[test]
    fn unit_forces_sum_to_the_force_of_the_acceleration() {
        // A diagonal "mass matrix" with distinct entries per dof.
        let m: Vec<f64> = (0..9).map(|i| 1.0 + i as f64).collect();
        let matvec = |x: &[f64], y: &mut [f64]| {
            for i in 0..9 {
                y[i] = m[i] * x[i];
            }
        };
        let unit = unit_forces(9, matvec);
        let g = [1.5, -2.0, 0.25];
        let mut f = vec![0.0; 9];
        add_force(&mut f, g, &unit);
        for i in 0..9 {
            assert_eq!(f[i], m[i] * g[i % 3]);
        }
    }
}
