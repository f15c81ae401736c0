//! Prescribed functions of time and of position, shared by boundary conditions, loads,
//! gravity and rigid contact surfaces: piecewise-linear tables and rigid rotations.

use crate::Vec3;

/// A piecewise-linear function of time, constant beyond its first and last points.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Strictly increasing times [s].
    pub t: Vec<f64>,
    /// Values at those times (unit of the quantity).
    pub v: Vec<f64>,
}

impl Table {
    /// A constant function.
    pub fn constant(v: f64) -> Self {
        Table {
            t: vec![0.0],
            v: vec![v],
        }
    }

    /// Value at time `t`.
    pub fn at(&self, t: f64) -> f64 {
        let n = self.t.len();
        if n == 0 {
            return 0.0;
        }
        if t <= self.t[0] {
            return self.v[0];
        }
        if t >= self.t[n - 1] {
            return self.v[n - 1];
        }
        let k = self.t.partition_point(|&ti| ti <= t);
        let (t0, t1, v0, v1) = (self.t[k - 1], self.t[k], self.v[k - 1], self.v[k]);
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }
}

/// A prescribed rigid rotation about a fixed axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Rotation {
    /// A point of the axis in the reference configuration [m].
    pub center: [f64; 3],
    /// Unit axis direction.
    pub axis: [f64; 3],
    /// Rotation angle as a function of time [rad] (right-hand rule about `axis`).
    pub angle: Table,
}

/// Rodrigues rotation of vector `v` about unit `axis` by `angle` [rad].
pub fn rotate(v: Vec3, axis: Vec3, angle: f64) -> Vec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(&v) * s + axis * axis.dot(&v) * (1.0 - c)
}
