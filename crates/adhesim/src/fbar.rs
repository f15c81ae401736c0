//! F-bar solid elements with the element's mean dilatation, in variational, total-Lagrangian
//! form (the F-bar idea of de Souza Neto, Perić, Dutko & Owen 1996, *Int. J. Solids Struct.*
//! 33:3277, with the volume change of Simo, Taylor & Pister's mean-dilatation Q1/P0 element,
//! *Comput. Methods Appl. Mech. Engrg.* 51 (1985) 177).
//!
//! At every Gauss point the deformation gradient is replaced by
//!
//! F̄ = α F,  α = (θ / J)^(1/3),  J = det F,  θ = v / V = (1/V) Σ_g w_g J_g,
//!
//! θ the element's current-to-reference volume ratio. F̄ keeps the isochoric part of the
//! point's F and takes its volume change from the whole element, so a hex8 no longer has to
//! keep J = 1 at eight points (which locks it for nearly incompressible materials) but only its
//! volume. For the uncoupled materials (W = W̄(C̄) + U(J)) the energy Σ_g w_g W(F̄_g) is exactly
//! the Q1/P0 energy Σ_g w_g W̄(C̄_g) + V U(θ) with the pressure condensed out. Taking θ rather
//! than J at the element centre (the original F-bar) makes the element pass the patch test on
//! distorted meshes.
//!
//! The element energy is Π = Σ_g w_g W(F̄_g) and the internal force its exact gradient,
//!
//! f_a = Σ_g w_g α [P̄ G_a + ⅓ (P̄:F) h_a],  h_a = d_a/θ − F⁻ᵀ G_a,  P̄ = F̄ S(F̄ᵀF̄),
//!
//! with G_a = ∂N_a/∂X at the point and d_a = ∂θ/∂u_a = (1/V) Σ_g w_g J_g F_g⁻ᵀ G_a,g. The
//! tangent is the Hessian of Π, hence symmetric: the system matrices stay symmetric and the
//! sparse Cholesky solver of the stepper applies unchanged (the original spatial form of F-bar
//! has a non-symmetric tangent). Because θ depends on all nodes of the element, every node
//! couples to every other node of the element: the 8×8 node-block pattern of the element is
//! the same as for the standard hex8, so the sparse pattern does not change.
//!
//! With g_a = F⁻ᵀ G_a and ∂α/∂u_a = α/3 h_a, per Gauss point
//!
//! K_ab = w { α² [K̂_ab + ⅓ (m_a ⊗ h_b + h_a ⊗ m_b) + ⅑ (𝔸[F]:F) h_a ⊗ h_b]
//!          + (P̄:F) α [⅑ h_a ⊗ h_b + ⅓ (g_b ⊗ g_a + L_ab)]
//!          + α/3 (h_a ⊗ P̄G_b + P̄G_a ⊗ h_b) },
//!
//! where K̂_ab is the standard material + geometric block evaluated with F̄, 𝔸 = ∂P/∂F at F̄,
//! 𝔸[F] = F̄ (S + ℂ:C̄) / α, m_a = 𝔸[F] G_a, and L_ab = ∂²(ln θ)/∂u_a∂u_b
//! = (1/(θV)) Σ_g w_g J_g (g_a ⊗ g_b − g_b ⊗ g_a) − d_a ⊗ d_b / θ².

use crate::element::{displacement_gradient, material_point, ElementResponse, GaussPoint};
use crate::material::Hyperelastic;
use crate::{Mat3, Mat6, Vec3};
use nalgebra::{SMatrix, Vector6};

/// Which kinematics an element of a body uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Formulation {
    /// Full integration with the displacement-based F (locks when nearly incompressible).
    #[default]
    Standard,
    /// F-bar: the volume change of each Gauss point is the element's mean dilatation (hex8,
    /// tet10), or on a hex20 the linear projection of J over the element
    /// ([`crate::dilatation`]).
    FBar,
    /// Averaged nodal pressure for the tetrahedra (see [`crate::anp`]) and F-bar for the
    /// hexahedra of the body; needs an uncoupled (volumetric/isochoric split) material
    /// (with another material the tetrahedra stay standard; scenarios refuse it).
    AveragedNodalPressure,
}

pub(crate) type Bmat = SMatrix<f64, 6, 3>;

/// The 6×3 block of ∂E/∂u_a (Voigt, engineering shears) at F and G_a = ∂N_a/∂X [1/m].
#[inline]
pub(crate) fn b_matrix(f: &Mat3, g: &Vec3) -> Bmat {
    let mut b = Bmat::zeros();
    for i in 0..3 {
        b[(0, i)] = f[(i, 0)] * g[0];
        b[(1, i)] = f[(i, 1)] * g[1];
        b[(2, i)] = f[(i, 2)] * g[2];
        b[(3, i)] = f[(i, 0)] * g[1] + f[(i, 1)] * g[0];
        b[(4, i)] = f[(i, 1)] * g[2] + f[(i, 2)] * g[1];
        b[(5, i)] = f[(i, 0)] * g[2] + f[(i, 2)] * g[0];
    }
    b
}

/// Gauss-point kinematics of an F-bar element: F, J, F⁻ᵀ G_a per point, the volume ratio θ
/// and its gradient d_a = ∂θ/∂u_a. `None` when some J ≤ 0 or F is singular.
#[allow(clippy::type_complexity)]
fn kinematics<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
) -> (
    [Mat3; G],
    [f64; G],
    Option<([[Vec3; N]; G], f64, [Vec3; N])>,
) {
    let f: [Mat3; G] =
        std::array::from_fn(|q| Mat3::identity() + displacement_gradient(&gps[q], u));
    let j: [f64; G] = std::array::from_fn(|q| f[q].determinant());
    let mut g = [[Vec3::zeros(); N]; G];
    let (mut vol, mut vol0) = (0.0, 0.0);
    let mut d = [Vec3::zeros(); N];
    for q in 0..G {
        let f_inv_t = match f[q].try_inverse() {
            Some(inv) if j[q] > 0.0 => inv.transpose(),
            _ => return (f, j, None),
        };
        let w = gps[q].weight;
        vol += w * j[q];
        vol0 += w;
        for a in 0..N {
            g[q][a] = f_inv_t * Vec3::from(gps[q].grad[a]);
            d[a] += g[q][a] * (w * j[q]);
        }
    }
    for da in &mut d {
        *da /= vol0;
    }
    (f, j, Some((g, vol / vol0, d)))
}

/// The element's volume ratio θ = v/V [-] (the mean J over its Gauss points).
pub fn volume_ratio<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
) -> f64 {
    let (mut v, mut v0) = (0.0, 0.0);
    for gp in gps {
        v += gp.weight * (Mat3::identity() + displacement_gradient(gp, u)).determinant();
        v0 += gp.weight;
    }
    v / v0
}

/// Internal force, (optionally) tangent, energy and min J of one F-bar element.
/// Small-strain materials are not meant for F-bar; they get the standard element.
pub fn fbar_element_response<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
) -> ElementResponse<N> {
    fbar_element_response_with_history(gps, u, material, with_tangent, None)
}

/// As [`fbar_element_response`], for a viscoelastic material (see
/// [`crate::element::element_response_with_history`]); the material is evaluated at C̄.
pub fn fbar_element_response_with_history<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
    history: Option<(&[f64], f64)>,
) -> ElementResponse<N> {
    if material.small_strain() {
        return crate::element::element_response(gps, u, material, with_tangent);
    }
    let viscous = history.zip(material.viscoelastic());
    let mut force = [[0.0; 3]; N];
    let mut tangent = if with_tangent {
        Some(Box::new([[Mat3::zeros(); N]; N]))
    } else {
        None
    };
    let (fs, js, kin) = kinematics(gps, u);
    let min_j = js.iter().copied().fold(f64::INFINITY, f64::min);
    let Some((gs, theta, d)) = kin else {
        return ElementResponse {
            force,
            tangent,
            energy: f64::NAN,
            min_j,
        };
    };
    let dt: [Vec3; N] = std::array::from_fn(|a| d[a] / theta);
    let mut energy = 0.0;
    // Σ_g w α (P̄:F)/3, the weight of L_ab.
    let mut l_weight = 0.0;
    for (q, gp) in gps.iter().enumerate() {
        let (f, j, g) = (fs[q], js[q], &gs[q]);
        let alpha = (theta / j).cbrt();
        let fbar = f * alpha;
        let w = gp.weight;
        let cbar = fbar.transpose() * fbar;
        let (w_point, s, dmat) = material_point(material, &cbar, q, viscous, with_tangent);
        energy += w_point * w;
        let p = fbar * s;
        let pf = p.dot(&f);
        let grads: [Vec3; N] = std::array::from_fn(|a| Vec3::from(gp.grad[a]));
        let hv: [Vec3; N] = std::array::from_fn(|a| dt[a] - g[a]);
        let pg: [Vec3; N] = std::array::from_fn(|a| p * grads[a]);
        for a in 0..N {
            let fa = (pg[a] + hv[a] * (pf / 3.0)) * (w * alpha);
            for i in 0..3 {
                force[a][i] += fa[i];
            }
        }
        let (Some(kt), Some(dmat)) = (tangent.as_mut(), dmat) else {
            continue;
        };
        // 𝔸[F] = F̄ (S + ℂ:C̄) / α.
        let x = tangent_on(&dmat, &cbar);
        let af = fbar * (s + x) / alpha;
        let af_f = af.dot(&f);
        let m: [Vec3; N] = std::array::from_fn(|a| af * grads[a]);
        let bs: [Bmat; N] = std::array::from_fn(|a| b_matrix(&fbar, &grads[a]));
        let dbs: [Bmat; N] = std::array::from_fn(|b| dmat * bs[b]);
        let a2 = w * alpha * alpha;
        let wa = w * alpha;
        l_weight += wa * pf / 3.0;
        let hh = a2 * af_f / 9.0 + wa * pf / 9.0;
        for a in 0..N {
            let sga = s * grads[a];
            let ma = m[a] * (a2 / 3.0) + pg[a] * (wa / 3.0);
            let ga = g[a] * (wa * pf / 3.0);
            for b in a..N {
                let mut kab = bs[a].transpose() * dbs[b];
                let geo = sga.dot(&grads[b]);
                for i in 0..3 {
                    kab[(i, i)] += geo;
                }
                let mb = m[b] * (a2 / 3.0) + pg[b] * (wa / 3.0);
                kab = kab * a2
                    + ma * hv[b].transpose()
                    + hv[a] * (mb + hv[b] * hh).transpose()
                    + g[b] * ga.transpose();
                kt[a][b] += kab;
            }
        }
    }
    if let Some(kt) = tangent.as_mut() {
        // L_ab = (1/(θV)) Σ_g w_g J_g (g_a ⊗ g_b − g_b ⊗ g_a) − d_a ⊗ d_b / θ².
        let vol0: f64 = gps.iter().map(|gp| gp.weight).sum();
        for (q, gp) in gps.iter().enumerate() {
            let c = l_weight * gp.weight * js[q] / (theta * vol0);
            for a in 0..N {
                let ga = gs[q][a] * c;
                for b in a + 1..N {
                    let skew = ga * gs[q][b].transpose();
                    kt[a][b] += skew - skew.transpose();
                }
            }
        }
        for a in 0..N {
            for b in a..N {
                kt[a][b] -= dt[a] * (dt[b] * l_weight).transpose();
            }
        }
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

/// C̄ = F̄ᵀF̄ at each Gauss point of an F-bar element.
pub fn fbar_gauss_point_c<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
) -> [Mat3; G] {
    let theta = volume_ratio(gps, u);
    std::array::from_fn(|q| {
        let f = Mat3::identity() + displacement_gradient(&gps[q], u);
        let fbar = f * (theta / f.determinant()).cbrt();
        fbar.transpose() * fbar
    })
}

/// Volume-weighted Cauchy stress σ̄ = θ⁻¹ F̄ S(F̄ᵀF̄) F̄ᵀ over the Gauss points of an F-bar
/// element [Pa], and its volume ratio θ.
pub fn fbar_cauchy_stress<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
) -> (Mat3, f64) {
    if material.small_strain() {
        return crate::element::element_cauchy_stress(gps, u, material);
    }
    let theta = volume_ratio(gps, u);
    let mut sigma = Mat3::zeros();
    let mut vol = 0.0;
    for gp in gps {
        let f = Mat3::identity() + displacement_gradient(gp, u);
        let fbar = f * (theta / f.determinant()).cbrt();
        let cauchy = fbar * material.pk2(&(fbar.transpose() * fbar)) * fbar.transpose() / theta;
        sigma += cauchy * gp.weight;
        vol += gp.weight;
    }
    (sigma / vol, theta)
}

/// ℂ:C [Pa] for the Voigt tangent `dmat` [Pa] (order xx, yy, zz, xy, yz, xz) and the
/// symmetric `c` [-], written with engineering shears.
pub(crate) fn tangent_on(dmat: &Mat6, c: &Mat3) -> Mat3 {
    let cv = Vector6::new(
        c[(0, 0)],
        c[(1, 1)],
        c[(2, 2)],
        2.0 * c[(0, 1)],
        2.0 * c[(1, 2)],
        2.0 * c[(0, 2)],
    );
    let xv = dmat * cv;
    Mat3::new(
        xv[0], xv[3], xv[5], xv[3], xv[1], xv[4], xv[5], xv[4], xv[2],
    )
}
