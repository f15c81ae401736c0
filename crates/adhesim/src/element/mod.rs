//! Total-Lagrangian solid elements behind one interface.
//!
//! Every element type has two sides:
//! - a row of the type table [`ELEMENT_TYPES`] ([`ElementType`]): its name, node count,
//!   number of Gauss points, faces, VTK cell type and Gmsh element type. Meshes, the Gmsh
//!   reader, VTK output and the discretisation only go through this table, and the
//!   discretisation builds one assembly block per row through [`visit_element_types`], which
//!   hands it each row's Rust type (so this module never names the assembly);
//! - an implementation of the [`Element`] trait (shape functions, Gauss rule, mass), with the
//!   node count `N` and Gauss-point count `G` as const parameters, so that the kernels below
//!   and the assembly loops are compiled for each type (no dynamic dispatch per element or
//!   Gauss point).
//!
//! The types are trilinear hex8 (2×2×2 Gauss, `hex8.rs`), linear tet4 (1 point, `tet4.rs`),
//! quadratic tet10 (4 points, `tet10.rs`), quadratic (serendipity) hex20 (3×3×3 points,
//! `hex20.rs`) and triquadratic (Lagrange) hex27 (3×3×3 points, `hex27.rs`). Their faces are described by face types (`face.rs`).
//! Reference-configuration data (shape-function gradients, weights) are computed once; the
//! kernels turn nodal displacements into internal force, consistent tangent (material +
//! geometric) and strain energy.

pub mod face;
pub(crate) mod hex20;
pub(crate) mod hex27;
pub(crate) mod hex8;
pub(crate) mod tet10;
pub(crate) mod tet4;

pub use face::{FaceType, LocalFace};
pub use hex20::{
    hex20_geometry, hex20_shape, quad8_shape, Hex20, HEX20, HEX20_EDGES, HEX20_NODE_XI, QUAD8,
    QUAD8_NODE_XI,
};
pub use hex27::{
    hex27_geometry, hex27_shape, quad9_shape, Hex27, HEX27, HEX27_NODE_XI, QUAD9, QUAD9_NODE_XI,
};
pub use hex8::{
    hex8_centre, hex8_gauss_points, hex8_geometry, hex8_shape, quad4_shape, Hex8, HEX8,
    HEX_NODE_XI, QUAD4,
};
pub use tet10::{
    tet10_geometry, tet10_shape, tri6_shape, Tet10, TET10, TET10_EDGES, TRI6, TRI6_NODE_XI,
};
pub use tet4::{tet4_geometry, tet4_shape, Tet4, TET4, TRI3};

use crate::material::Hyperelastic;
use crate::{Mat3, Vec3};

/// The table of element types: each entry is an element's Rust type with its node and
/// Gauss-point counts, and its [`ElementType`] row. It defines [`ELEMENT_TYPES`] and
/// [`visit_element_types`] from the one list, so the two cannot disagree.
macro_rules! element_types {
    ($($element:ty, $nodes:literal, $points:literal, $row:expr;)*) => {
        /// The element types adhesim knows, in the order cell blocks are kept in meshes,
        /// element blocks in the discretisation and cells in the output. A new element type
        /// is one file in this module (its [`Element`] implementation and its
        /// [`ElementType`] row) and one entry in the table that defines this list.
        pub static ELEMENT_TYPES: &[&ElementType] = &[$(&$row),*];

        /// Calls `visitor` with the Rust type of each element type, in the order of
        /// [`ELEMENT_TYPES`]: how code compiled for each type (the assembly's blocks) is
        /// built without this module naming it.
        pub fn visit_element_types(visitor: &mut impl ElementTypeVisitor) {
            $(visitor.visit::<$element, $nodes, $points>();)*
        }
    };
}

element_types! {
    Hex8, 8, 8, HEX8;
    Tet4, 4, 1, TET4;
    Tet10, 10, 4, TET10;
    Hex20, 20, 27, HEX20;
    Hex27, 27, 27, HEX27;
}

/// What is done with each element type's Rust type ([`visit_element_types`]).
pub trait ElementTypeVisitor {
    /// Called once per element type `E`, with `N` nodes and `G` Gauss points.
    fn visit<E: Element<N, G>, const N: usize, const G: usize>(&mut self);
}

/// One row of the element-type table.
pub struct ElementType {
    /// Name (as in messages and Gmsh's element list), e.g. `"hex8"`.
    pub name: &'static str,
    /// Number of nodes of one cell.
    pub nodes: usize,
    /// Natural coordinates ξ of the nodes.
    pub natural_nodes: &'static [[f64; 3]],
    /// Number of Gauss points of the element's rule.
    pub gauss_points: usize,
    /// The Gauss rule: natural coordinates and weight (natural volume) of each point, as
    /// [`Element::gauss_rule`] gives them.
    pub gauss_rule: fn() -> Vec<([f64; 3], f64)>,
    /// Shape functions N_a and natural derivatives ∂N_a/∂ξ at ξ, as [`Element::shape`]
    /// gives them.
    pub shape: fn(xi: [f64; 3]) -> ShapeValues,
    /// Each face: its face type and local node indices (its corners counter-clockwise seen
    /// from outside the cell, then its mid-side nodes): boundary extraction and face sets use
    /// them.
    pub faces: &'static [LocalFace],
    /// Corners for the scaled-Jacobian quality measure ([`crate::mesh::quality`]): each the
    /// corner node and its three neighbours along the natural axes, ordered so that the edge
    /// vectors form a right-handed frame in a valid cell.
    pub corner_frames: &'static [[usize; 4]],
    /// True when a cell with node coordinates `x` [m] is inverted somewhere the corner frames
    /// do not see (for the hex8: a Jacobian determinant ≤ 0 at a Gauss point).
    pub inverted_inside: fn(x: &[[f64; 3]]) -> bool,
    /// VTK cell type number.
    pub vtk_type: u8,
    /// Gmsh element type number (MSH 4.1).
    pub gmsh_type: i32,
    /// For each node of the cell, its position in Gmsh's node list of the element.
    pub gmsh_nodes: &'static [usize],
}

/// The type's name: the `Debug` form of meshes (and so the checkpoint fingerprint of a
/// problem) must not depend on where the type's functions sit in memory.
impl std::fmt::Debug for ElementType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

impl PartialEq for ElementType {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for ElementType {}

impl std::hash::Hash for ElementType {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name.hash(state);
    }
}

impl ElementType {
    /// Position of this type in [`ELEMENT_TYPES`].
    pub fn index(&self) -> usize {
        ELEMENT_TYPES
            .iter()
            .position(|t| *t == self)
            .expect("every element type is in the table")
    }

    /// The type of Gmsh element type number `gmsh_type`, if adhesim has it.
    pub fn from_gmsh(gmsh_type: i32) -> Option<&'static ElementType> {
        ELEMENT_TYPES
            .iter()
            .copied()
            .find(|t| t.gmsh_type == gmsh_type)
    }

    /// Whether the type is of second order (its faces have mid-side nodes).
    pub fn is_quadratic(&self) -> bool {
        self.faces.iter().any(|f| f.face_type.is_quadratic)
    }

    /// The type called `name`, if adhesim has it.
    pub fn from_name(name: &str) -> Option<&'static ElementType> {
        ELEMENT_TYPES.iter().copied().find(|t| t.name == name)
    }
}

/// The volumetric treatment an element type offers for nearly incompressible bodies (the
/// body's [`crate::fbar::Formulation`] switches it on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stabilisation {
    /// None: the element always uses the standard kinematics.
    None,
    /// F-bar with the element's mean dilatation ([`crate::fbar`]), for the formulations
    /// `FBar` and `AveragedNodalPressure`.
    FBar,
    /// F-bar with a volume change linear in the element ([`crate::dilatation`], Q2/P1), for
    /// the formulations `FBar` and `AveragedNodalPressure`.
    LinearDilatation,
    /// Averaged nodal pressure ([`crate::anp`], built on the tet4 block only), for the formulation
    /// `AveragedNodalPressure` with a material that has a volumetric/isochoric split.
    NodalPressure,
}

/// An element type at compile time: `N` nodes, `G` Gauss points. Assembly is generic over
/// it, so each type gets its own compiled kernels.
pub trait Element<const N: usize, const G: usize>: Send + Sync + 'static {
    /// The type's row in [`ELEMENT_TYPES`].
    const TYPE: &'static ElementType;
    /// What the locking-free formulations do to this element.
    const STABILISATION: Stabilisation;

    /// Shape functions N_a and their natural derivatives ∂N_a/∂ξ at natural point ξ.
    fn shape(xi: [f64; 3]) -> ([f64; N], [[f64; 3]; N]);

    /// Gauss points (natural coordinates) and weights (natural volume).
    fn gauss_rule() -> [([f64; 3], f64); G];

    /// Gauss-point data of an element with reference coordinates `x` [m].
    fn geometry(x: &[[f64; 3]; N]) -> Result<[GaussPoint<N>; G], DegenerateElement> {
        let mut out = [GaussPoint {
            shape: [0.0; N],
            grad: [[0.0; 3]; N],
            weight: 0.0,
        }; G];
        for (o, (p, w)) in out.iter_mut().zip(Self::gauss_rule()) {
            let (n, dn) = Self::shape(p);
            *o = gauss_point(x, n, dn, w)?;
        }
        Ok(out)
    }

    /// Consistent mass coefficients m_ab = ∫ ρ N_a N_b dV₀ [kg] from the Gauss data and the
    /// density [kg/m³]; by default the element's own quadrature.
    fn mass(gps: &[GaussPoint<N>; G], density: f64) -> [[f64; N]; N] {
        quadrature_mass(gps, density)
    }

    /// How `time.mass = "lumped"` makes this element's mass diagonal: by default the row
    /// sums of the consistent mass.
    const LUMPING: Lumping = Lumping::RowSum;
}

/// How an element's consistent mass is made diagonal (`time.mass = "lumped"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lumping {
    /// m_a = Σ_b m_ab: the row sums. Positive for the linear elements (hex8, tet4), whose
    /// shape functions are non-negative; negative at the corners of the quadratic ones.
    RowSum,
    /// m_a = m_aa · Σ_bc m_bc / Σ_c m_cc: the consistent mass's diagonal scaled so that the
    /// element keeps its total mass (Hinton, Rock and Zienkiewicz, Earthquake Engng. Struct.
    /// Dyn. 4 (1976) 245). Every m_a is positive, since every m_aa = ∫ ρ N_a² dV₀ is.
    DiagonalScaling,
}

/// The diagonal-scaling lumped mass of a consistent element mass `m` [kg] ([`Lumping`]):
/// its diagonal times the total Σ_ab m_ab over the trace Σ_a m_aa.
pub fn diagonal_scaling_lumped<const N: usize>(m: &[[f64; N]; N]) -> [f64; N] {
    let total: f64 = m.iter().flatten().sum();
    let trace: f64 = (0..N).map(|a| m[a][a]).sum();
    std::array::from_fn(|a| m[a][a] * (total / trace))
}

/// Shape functions N_a and their natural derivatives ∂N_a/∂ξ at one point, one entry per
/// node.
pub type ShapeValues = (Vec<f64>, Vec<[f64; 3]>);

/// [`Element::gauss_rule`] of `E` as a list, for its [`ElementType`] row.
pub fn gauss_rule_of<E: Element<N, G>, const N: usize, const G: usize>() -> Vec<([f64; 3], f64)> {
    E::gauss_rule().to_vec()
}

/// [`Element::shape`] of `E` at ξ as lists, for its [`ElementType`] row.
pub fn shape_of<E: Element<N, G>, const N: usize, const G: usize>(xi: [f64; 3]) -> ShapeValues {
    let (n, dn) = E::shape(xi);
    (n.to_vec(), dn.to_vec())
}

/// m_ab = Σ_g ρ N_a N_b w_g [kg] over the Gauss points `gps`, density ρ [kg/m³].
pub fn quadrature_mass<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    density: f64,
) -> [[f64; N]; N] {
    let mut m = [[0.0; N]; N];
    for gp in gps {
        for a in 0..N {
            for b in 0..N {
                m[a][b] += density * gp.shape[a] * gp.shape[b] * gp.weight;
            }
        }
    }
    m
}

/// Reference-configuration data at one Gauss point of an element with N nodes.
#[derive(Clone, Copy, Debug)]
pub struct GaussPoint<const N: usize> {
    /// Shape functions N_a.
    pub shape: [f64; N],
    /// Reference gradients ∂N_a/∂X [1/m].
    pub grad: [[f64; 3]; N],
    /// Quadrature weight times reference Jacobian determinant [m³].
    pub weight: f64,
}

/// Error when a reference element is degenerate or inverted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DegenerateElement {
    /// Smallest reference Jacobian determinant found [m³ per unit natural volume].
    pub det: f64,
}

pub(crate) fn gauss_point<const N: usize>(
    x: &[[f64; 3]; N],
    shape: [f64; N],
    dn: [[f64; 3]; N],
    w: f64,
) -> Result<GaussPoint<N>, DegenerateElement> {
    let mut j = Mat3::zeros();
    for a in 0..N {
        for i in 0..3 {
            for k in 0..3 {
                j[(i, k)] += x[a][i] * dn[a][k];
            }
        }
    }
    let det = j.determinant();
    if !(det > 0.0) {
        return Err(DegenerateElement { det });
    }
    let jinv_t = j
        .try_inverse()
        .ok_or(DegenerateElement { det })?
        .transpose();
    let mut grad = [[0.0; 3]; N];
    for a in 0..N {
        let g = jinv_t * Vec3::from(dn[a]);
        grad[a] = [g[0], g[1], g[2]];
    }
    Ok(GaussPoint {
        shape,
        grad,
        weight: w * det,
    })
}

/// What the element kernel computes at a given displacement.
pub struct ElementResponse<const N: usize> {
    /// Internal nodal forces [N].
    pub force: [[f64; 3]; N],
    /// Tangent blocks K[a][b] = ∂f_a/∂u_b [N/m] (only when requested).
    pub tangent: Option<Box<[[Mat3; N]; N]>>,
    /// Strain energy [J].
    pub energy: f64,
    /// Smallest J = det F over the Gauss points.
    pub min_j: f64,
}

/// A 3×3×3×3 tensor, `t[i][k][J][L]`.
type Tensor4 = [[[[f64; 3]; 3]; 3]; 3];

/// Voigt index of the symmetric pair (I, J) (order 11, 22, 33, 12, 23, 13).
const VOIGT: [[usize; 3]; 3] = [[0, 3, 5], [3, 1, 4], [5, 4, 2]];

/// w A of one Gauss point, stored as `a[i][k][J][L]` [Pa·m³]: the first elasticity tensor
/// A_iJkL = ∂P_iJ/∂F_kL = F_iI F_kK D_IJKL + δ_ik S_JL of the material tangent D [Pa]
/// (Voigt, on engineering shear strains), the stress S [Pa] and the deformation gradient
/// `f`, times the point's weight `w` [m³]. `geometric = false` leaves out δ_ik S_JL (the
/// small-strain element, whose `f` is the identity).
#[inline]
fn weighted_first_elasticity(
    f: &Mat3,
    s: &Mat3,
    d: &crate::Mat6,
    geometric: bool,
    w: f64,
) -> Tensor4 {
    let fa: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| f[(i, j)]));
    let dd: [[f64; 6]; 6] = std::array::from_fn(|i| std::array::from_fn(|j| d[(i, j)]));
    // y[i][J][K][L] = Σ_I F_iI D_IJKL
    let mut y: Tensor4 = [[[[0.0; 3]; 3]; 3]; 3];
    for (yi, fi) in y.iter_mut().zip(&fa) {
        for (jj, yij) in yi.iter_mut().enumerate() {
            for (kk, yijk) in yij.iter_mut().enumerate() {
                for (ll, x) in yijk.iter_mut().enumerate() {
                    let v = VOIGT[kk][ll];
                    *x = fi[0] * dd[VOIGT[0][jj]][v]
                        + fi[1] * dd[VOIGT[1][jj]][v]
                        + fi[2] * dd[VOIGT[2][jj]][v];
                }
            }
        }
    }
    let mut a: Tensor4 = [[[[0.0; 3]; 3]; 3]; 3];
    for (i, ai) in a.iter_mut().enumerate() {
        for (k, aik) in ai.iter_mut().enumerate() {
            let fk = &fa[k];
            for (jj, aikj) in aik.iter_mut().enumerate() {
                let yij = &y[i][jj];
                for (ll, x) in aikj.iter_mut().enumerate() {
                    let mut t = yij[0][ll] * fk[0] + yij[1][ll] * fk[1] + yij[2][ll] * fk[2];
                    if geometric && i == k {
                        t += s[(jj, ll)];
                    }
                    *x = w * t;
                }
            }
        }
    }
    a
}

/// Adds the stiffness of one Gauss point, K_ab,ik += Σ_JL ∇N_aJ (wA)_iJkL ∇N_bL [N/m], to
/// the blocks b ≥ a of `kt`, from the reference gradients `grads` [1/m] and `wa` of
/// [`weighted_first_elasticity`]: material and geometric stiffness in one contraction,
/// 27 products per block against the 54 of B_aᵀ (D B_b) and the geometric term apart.
#[inline]
fn add_point_stiffness<const N: usize>(
    kt: &mut [[Mat3; N]; N],
    grads: &[[f64; 3]; N],
    wa: &Tensor4,
) {
    for (a, ga) in grads.iter().enumerate() {
        // t[ik][L] = Σ_J ∇N_aJ (wA)_iJkL
        let t: [[f64; 3]; 9] = std::array::from_fn(|ik| {
            let aik = &wa[ik / 3][ik % 3];
            std::array::from_fn(|ll| ga[0] * aik[0][ll] + ga[1] * aik[1][ll] + ga[2] * aik[2][ll])
        });
        for (kab, gb) in kt[a][a..].iter_mut().zip(&grads[a..]) {
            let kab = kab.as_mut_slice();
            for (ik, tik) in t.iter().enumerate() {
                // Column-major 3×3: entry (i, k) at 3k + i.
                kab[3 * (ik % 3) + ik / 3] += tik[0] * gb[0] + tik[1] * gb[1] + tik[2] * gb[2];
            }
        }
    }
}

/// Displacement gradient H = ∂u/∂X at a Gauss point.
#[inline]
pub fn displacement_gradient<const N: usize>(gp: &GaussPoint<N>, u: &[[f64; 3]; N]) -> Mat3 {
    let mut h = Mat3::zeros();
    for a in 0..N {
        for i in 0..3 {
            for k in 0..3 {
                h[(i, k)] += u[a][i] * gp.grad[a][k];
            }
        }
    }
    h
}

/// The committed internal variables of an element's Gauss points and the step size Δt [s],
/// with the viscoelastic model they belong to.
pub(crate) type ViscousHistory<'a> = Option<((&'a [f64], f64), &'a crate::material::Viscoelastic)>;

/// The material at one Gauss point `q` of an element, shared by all element kernels: the
/// energy W(C) [J/m³], the stress S [Pa] and, when `with_tangent`, the tangent D [Pa], with
/// the viscous part of that point when `viscous` holds the element's history.
#[inline]
pub(crate) fn material_point(
    material: &dyn Hyperelastic,
    c: &Mat3,
    q: usize,
    viscous: ViscousHistory<'_>,
    with_tangent: bool,
) -> (f64, Mat3, Option<crate::Mat6>) {
    let (mut s, mut d) = if with_tangent {
        let (s, d) = material.pk2_and_tangent(c);
        (s, Some(d))
    } else {
        (material.pk2(c), None)
    };
    if let Some(((hist, dt), ve)) = viscous {
        let len = ve.history_len();
        ve.add_viscous(c, &hist[q * len..(q + 1) * len], dt, &mut s, d.as_mut());
    }
    (material.energy(c), s, d)
}

/// A zero element tangent allocated in place: `Box::new` of the array would build it on the
/// stack and copy its N² 3×3 blocks to the heap at every element evaluation.
pub(crate) fn zeroed_tangent<const N: usize>() -> Box<[[Mat3; N]; N]> {
    // SAFETY: a Mat3 is nine f64 stored inline, and the all-zero bit pattern is 0.0.
    unsafe { Box::<[[Mat3; N]; N]>::new_zeroed().assume_init() }
}

/// Internal force, (optionally) tangent, energy and min J of one element.
///
/// Finite-strain materials use F = I + H, C = FᵀF; a small-strain material gets
/// C = I + H + Hᵀ (i.e. E = ε), B at F = I and no geometric stiffness.
pub fn element_response<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
) -> ElementResponse<N> {
    element_response_with_history(gps, u, material, with_tangent, None)
}

/// As [`element_response`], for a viscoelastic material: `history` holds the committed
/// internal variables of the element's Gauss points one after the other and the step size
/// Δt [s] (`None`: elastic response).
pub fn element_response_with_history<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
    history: Option<(&[f64], f64)>,
) -> ElementResponse<N> {
    let viscous = history.zip(material.viscoelastic());
    let small = material.small_strain();
    let mut force = [[0.0; 3]; N];
    let mut tangent = if with_tangent {
        Some(zeroed_tangent::<N>())
    } else {
        None
    };
    let mut energy = 0.0;
    let mut min_j = f64::INFINITY;
    for (q, gp) in gps.iter().enumerate() {
        let h = displacement_gradient(gp, u);
        let f = Mat3::identity() + h;
        let j = f.determinant();
        min_j = min_j.min(j);
        let (fb, c) = if small {
            (Mat3::identity(), Mat3::identity() + h + h.transpose())
        } else {
            (f, f.transpose() * f)
        };
        if !small && !(j > 0.0) {
            energy = f64::NAN;
            continue;
        }
        let (w_point, s, d) = material_point(material, &c, q, viscous, with_tangent);
        energy += w_point * gp.weight;
        let w = gp.weight;
        // f_a = w P ∇N_a, P = F S the first Piola-Kirchhoff stress.
        let p = fb * s;
        for (fa, g) in force.iter_mut().zip(&gp.grad) {
            for (i, x) in fa.iter_mut().enumerate() {
                *x += w * (p[(i, 0)] * g[0] + p[(i, 1)] * g[1] + p[(i, 2)] * g[2]);
            }
        }
        if let (Some(kt), Some(d)) = (tangent.as_mut(), d) {
            let wa = weighted_first_elasticity(&fb, &s, &d, !small, w);
            add_point_stiffness(kt, &gp.grad, &wa);
        }
    }
    if let Some(kt) = tangent.as_mut() {
        for a in 0..N {
            for b in 0..a {
                kt[a][b] = kt[b][a].transpose();
            }
        }
    }
    ElementResponse {
        force,
        tangent,
        energy,
        min_j,
    }
}

/// C = FᵀF at each Gauss point (finite strain).
pub fn gauss_point_c<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
) -> [Mat3; G] {
    std::array::from_fn(|q| {
        let f = Mat3::identity() + displacement_gradient(&gps[q], u);
        f.transpose() * f
    })
}

/// Cauchy stress σ = J⁻¹ F S Fᵀ averaged over the Gauss points (volume-weighted) [Pa], and
/// the mean J. Small-strain materials report σ = S(ε).
pub fn element_cauchy_stress<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
) -> (Mat3, f64) {
    let mut sigma = Mat3::zeros();
    let mut jsum = 0.0;
    let mut vol = 0.0;
    for gp in gps {
        let h = displacement_gradient(gp, u);
        let f = Mat3::identity() + h;
        let j = f.determinant();
        let cauchy = if material.small_strain() {
            material.pk2(&(Mat3::identity() + h + h.transpose()))
        } else {
            f * material.pk2(&(f.transpose() * f)) * f.transpose() / j
        };
        sigma += cauchy * gp.weight;
        jsum += j * gp.weight;
        vol += gp.weight;
    }
    (sigma / vol, jsum / vol)
}

/// Von Mises equivalent stress of a Cauchy stress [Pa].
pub fn von_mises(s: &Mat3) -> f64 {
    let d = [
        s[(0, 0)] - s[(1, 1)],
        s[(1, 1)] - s[(2, 2)],
        s[(2, 2)] - s[(0, 0)],
    ];
    let sh = s[(0, 1)].powi(2) + s[(1, 2)].powi(2) + s[(0, 2)].powi(2);
    (0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 3.0 * sh).sqrt()
}

#[cfg(test)]
mod table_tests {
    //! Checks every row of the element-type table against its own definition, so that a new
    //! type is checked as soon as it is in the table.
    use super::*;

    fn sub(a: [f64; 3], b: [f64; 3]) -> Vec3 {
        Vec3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2])
    }

    /// Shape functions interpolate the nodes (N_a(ξ_b) = δ_ab) and form a partition of unity
    /// with derivatives summing to zero at the Gauss points; the weights add up to the
    /// natural volume (the reference cell's volume by the divergence theorem over its faces).
    /// Exact in exact arithmetic; 1e-14 allows for round-off of sums of a few terms of order 1.
    #[test]
    fn shape_functions_and_gauss_rule_are_consistent() {
        for t in ELEMENT_TYPES {
            assert_eq!(t.natural_nodes.len(), t.nodes, "{}", t.name);
            for (b, xb) in t.natural_nodes.iter().enumerate() {
                let (n, dn) = (t.shape)(*xb);
                assert_eq!((n.len(), dn.len()), (t.nodes, t.nodes), "{}", t.name);
                for (a, na) in n.iter().enumerate() {
                    let delta = if a == b { 1.0 } else { 0.0 };
                    assert!(
                        (na - delta).abs() < 1e-14,
                        "{}: N_{a}(ξ_{b}) = {na}",
                        t.name
                    );
                }
            }
            let rule = (t.gauss_rule)();
            assert_eq!(rule.len(), t.gauss_points, "{}", t.name);
            for (xi, _) in &rule {
                let (n, dn) = (t.shape)(*xi);
                assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14, "{}", t.name);
                for k in 0..3 {
                    assert!(
                        dn.iter().map(|d| d[k]).sum::<f64>().abs() < 1e-14,
                        "{}",
                        t.name
                    );
                }
            }
            // Volume of the natural cell from its faces: V = (1/3) Σ_f ∫ x·n dA, each face
            // split into triangles fanning from its first node (planar faces).
            let x = t.natural_nodes;
            let mut volume = 0.0;
            for f in t.faces {
                let f = f.corners();
                for k in 1..f.len() - 1 {
                    let (p, q, r) = (x[f[0]], x[f[k]], x[f[k + 1]]);
                    volume += Vec3::from(p).dot(&sub(q, p).cross(&sub(r, p))) / 6.0;
                }
            }
            let weights: f64 = rule.iter().map(|(_, w)| w).sum();
            assert!(
                (weights - volume).abs() < 1e-14,
                "{}: Σw = {weights}, V = {volume}",
                t.name
            );
        }
    }

    /// Each face is listed counter-clockwise seen from outside (its normal points away from
    /// the natural cell's centroid), every boundary of the reference cell is covered once
    /// (each edge of the faces is shared by exactly two faces, in opposite directions), and
    /// the reference cell passes the quality checks.
    #[test]
    fn faces_are_outward_and_close_the_cell() {
        for t in ELEMENT_TYPES {
            let x = t.natural_nodes;
            let c = x
                .iter()
                .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
            let c = c.map(|v| v / t.nodes as f64);
            let mut edges = std::collections::HashMap::new();
            for f in t.faces {
                let f = f.corners();
                let normal = sub(x[f[1]], x[f[0]]).cross(&sub(x[f[2]], x[f[0]]));
                assert!(normal.dot(&sub(x[f[0]], c)) > 0.0, "{}: face {f:?}", t.name);
                for k in 0..f.len() {
                    *edges.entry((f[k], f[(k + 1) % f.len()])).or_insert(0) += 1;
                }
            }
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "{}: edge {a}-{b} twice in one direction", t.name);
                assert_eq!(edges.get(&(b, a)), Some(&1), "{}: edge {a}-{b}", t.name);
            }
            assert!(!(t.inverted_inside)(x), "{}", t.name);
            for fr in t.corner_frames {
                let det = sub(x[fr[1]], x[fr[0]])
                    .dot(&sub(x[fr[2]], x[fr[0]]).cross(&sub(x[fr[3]], x[fr[0]])));
                assert!(det > 0.0, "{}: corner frame {fr:?}", t.name);
            }
        }
    }

    /// The table's name, node and Gmsh lookups find each row, and the visit of the types
    /// goes through the rows in order, each with its own type and counts.
    #[test]
    fn lookups_and_visits_match_the_rows() {
        for (i, t) in ELEMENT_TYPES.iter().enumerate() {
            assert_eq!(t.index(), i);
            assert_eq!(ElementType::from_name(t.name), Some(*t));
            assert_eq!(ElementType::from_gmsh(t.gmsh_type), Some(*t));
        }
        struct Rows(Vec<(&'static ElementType, usize, usize)>);
        impl ElementTypeVisitor for Rows {
            fn visit<E: Element<N, G>, const N: usize, const G: usize>(&mut self) {
                self.0.push((E::TYPE, N, G));
            }
        }
        let mut rows = Rows(Vec::new());
        visit_element_types(&mut rows);
        let expected: Vec<_> = ELEMENT_TYPES
            .iter()
            .map(|t| (*t, t.nodes, t.gauss_points))
            .collect();
        assert_eq!(rows.0, expected);
    }
}
