//! adhesim: finite-element dynamics of soft bodies in frictional contact with recoverable
//! adhesion (Raous-Cangémi-Cocou interface, bi-potential contact solver, NSCD θ-method).
//!
//! Data flows one way: a scenario file is parsed and validated into a [`problem::Problem`], a
//! [`time::Stepper`] advances it step by step, and [`output::Observer`]s record what was
//! computed. Physics never formats output and output never does physics.
//!
//! Units are SI throughout (m, kg, s, N, Pa).

pub mod anp;
pub mod assembly;
pub mod checkpoint;
pub mod contact;
pub mod diagnosis;
pub mod element;
pub mod fbar;
pub mod gravity;
pub mod linalg;
pub mod material;
pub mod mesh;
pub mod outdir;
pub mod output;
pub mod prescribed;
pub mod problem;
pub mod run;
pub mod scenario;
pub mod slurm;
pub mod sparse_lu;
pub mod sweep;
pub mod system;
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
