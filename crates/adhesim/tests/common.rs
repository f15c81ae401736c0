//! Helpers shared by the verification tests.
#![allow(dead_code)]

use adhesim::material::Hyperelastic;
use adhesim::mesh::Mesh;
use adhesim::problem::{Body, Dirichlet, OutputSettings, Problem, Table, TimeSettings};
use std::sync::Arc;

/// Deterministic pseudo-random numbers in [−1, 1) (xorshift), so tests are repeatable.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

pub fn zero3() -> [Table; 3] {
    [
        Table::constant(0.0),
        Table::constant(0.0),
        Table::constant(0.0),
    ]
}

/// Fixes the given components of a node set at zero.
pub fn fixed(nodes: Vec<usize>, components: [bool; 3]) -> Dirichlet {
    Dirichlet {
        nodes,
        components,
        translation: zero3(),
        rotation: None,
    }
}

/// A one-body problem with no boundary conditions yet.
pub fn one_body(
    mesh: Mesh,
    material: Arc<dyn Hyperelastic>,
    density: f64,
    time: TimeSettings,
) -> Problem {
    Problem {
        name: "test".into(),
        bodies: vec![Body {
            name: "body".into(),
            mesh,
            material,
            density,
            initial_velocity: [0.0; 3],
            element: Default::default(),
        }],
        dirichlet: vec![],
        loads: vec![],
        gravity: Default::default(),
        time,
        contacts: vec![],
        tracks: vec![],
        output: OutputSettings {
            frame_interval: 0.0,
            ..Default::default()
        },
    }
}

pub fn quasi_static(t_end: f64, dt: f64) -> TimeSettings {
    TimeSettings {
        t_end,
        dt,
        quasi_static: true,
        newton_tol: 1e-12,
        ..TimeSettings::default()
    }
}
