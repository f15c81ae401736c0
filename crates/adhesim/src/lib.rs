//! adhesim: finite-element dynamics of soft bodies in frictional contact with recoverable
//! adhesion (Raous-Cangémi-Cocou interface, bi-potential contact solver, NSCD θ-method).
//!
//! Data flows one way: a [`problem::Problem`] (read from a scenario file by the `adhesim-io`
//! crate, or built in code) is advanced step by step by a [`time::Stepper`], whose committed
//! states the `adhesim-io` crate's observers record. This crate is the physics (meshes,
//! elements, materials, contact, time stepping): it parses no scenario and writes no output.
//!
//! Units are SI throughout (m, kg, s, N, Pa).
//!
//! The public modules are what a program built on the crate uses: the problem
//! ([`problem`], [`mesh`], [`material`], [`gravity`], the element formulations [`element`],
//! [`fbar`], [`dilatation`], [`anp`]), its stepper and what it reports ([`time`], [`assembly`],
//! [`diagnosis`], [`warnings`]), contact ([`contact`], whose reduced solvers the fclib
//! benchmarks drive on their own) and the sparse solves the benchmarks time ([`linalg`],
//! [`sparse_lu`]). The step's system matrix, the prescribed functions of time, the element
//! kernels and the node-to-surface detection are internal.

pub mod anp;
pub mod assembly;
pub mod contact;
pub mod diagnosis;
pub mod dilatation;
pub mod element;
pub mod fbar;
pub mod gravity;
pub mod linalg;
pub mod material;
pub mod mesh;
pub(crate) mod prescribed;
pub mod problem;
pub mod sparse_lu;
pub(crate) mod system;
pub mod time;
pub mod warnings;

/// 3×3 matrix of f64 (deformation gradients, stresses).
pub type Mat3 = nalgebra::Matrix3<f64>;
/// 3-vector of f64 (positions, displacements, forces).
pub type Vec3 = nalgebra::Vector3<f64>;
/// 2-vector of f64 (tangential components in a contact frame).
pub type Vec2 = nalgebra::Vector2<f64>;
/// A row-major 3×3 array (rows t₁, t₂, n of a contact frame, a point's W block) as a
/// [`Mat3`]; nalgebra's own `From` reads such an array as columns.
pub fn mat3_from_rows(a: [[f64; 3]; 3]) -> Mat3 {
    Mat3::from_fn(|i, j| a[i][j])
}

/// A [`Mat3`] as a row-major 3×3 array, the inverse of [`mat3_from_rows`].
pub fn rows_of(m: &Mat3) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

/// 6×6 matrix of f64 (material tangents in Voigt notation).
pub type Mat6 = nalgebra::Matrix6<f64>;
