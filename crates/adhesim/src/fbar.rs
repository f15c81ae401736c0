//! F-bar solid elements (de Souza Neto, Perić, Dutko & Owen 1996, *Int. J. Solids Struct.*
//! 33:3277) in their variational, total-Lagrangian form.
//!
//! At every Gauss point the deformation gradient is replaced by
//!
//! F̄ = α F,  α = (J₀ / J)^(1/3),  J = det F,  J₀ = det F₀,
//!
//! F₀ the deformation gradient at the element centre. F̄ keeps the isochoric part of the
//! point's F and takes its volume change from the centre, so a hex8 no longer has to keep J = 1
//! at eight points (which locks it for nearly incompressible materials) but at one.
//!
//! The element energy is Π = Σ_g w_g W(F̄_g) and the internal force its exact gradient,
//!
//! f_a = Σ_g w_g α [P̄ G_a + ⅓ (P̄:F) (F₀⁻ᵀ G⁰_a − F⁻ᵀ G_a)],  P̄ = F̄ S(F̄ᵀF̄),
//!
//! with G_a = ∂N_a/∂X at the point and G⁰_a at the centre. The tangent is then the Hessian
//! of Π, hence symmetric: the system matrices stay symmetric and the sparse Cholesky solver
//! of the stepper applies unchanged (the original spatial form of F-bar has a non-symmetric
//! tangent). Because F₀ depends on all nodes of the element, every node couples to every
//! other node of the element through the volumetric term: the 8×8 node-block pattern of the
//! element is the same as for the standard hex8, so the sparse pattern does not change.
//!
//! With h_a = F₀⁻ᵀ G⁰_a − F⁻ᵀ G_a, g_a = F⁻ᵀ G_a, g⁰_a = F₀⁻ᵀ G⁰_a and ∂α/∂u_a = α/3 h_a:
//!
//! K_ab = w { α² [K̂_ab + ⅓ (m_a ⊗ h_b + h_a ⊗ m_b) + ⅑ (𝔸[F]:F) h_a ⊗ h_b]
//!          + (P̄:F) α [⅑ h_a ⊗ h_b + ⅓ (g_b ⊗ g_a − g⁰_b ⊗ g⁰_a)]
//!          + α/3 (h_a ⊗ P̄G_b + P̄G_a ⊗ h_b) },
//!
//! where K̂_ab is the standard material + geometric block evaluated with F̄,
//! 𝔸 = ∂P/∂F at F̄, 𝔸[F] = F̄ (S + ℂ:C̄) / α and m_a = 𝔸[F] G_a.

use crate::element::{displacement_gradient, ElementResponse, GaussPoint};
use crate::material::Hyperelastic;
use crate::{Mat3, Vec3};
use nalgebra::{SMatrix, Vector6};

/// Which kinematics an element of a body uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Formulation {
    /// Full integration with the displacement-based F (locks when nearly incompressible).
    #[default]
    Standard,
    /// F-bar: the volume change of each Gauss point is taken from the element centre (hex8).
    FBar,
}

type Bmat = SMatrix<f64, 6, 3>;

#[inline]
fn b_matrix(f: &Mat3, g: &Vec3) -> Bmat {
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

/// F̄ = (J₀/J)^(1/3) F at one Gauss point, from its displacement gradient `h` and the
/// centre's deformation gradient determinant `j0`. Returns (F, F̄, α).
#[inline]
pub fn fbar_gradient(h: &Mat3, j0: f64) -> (Mat3, Mat3, f64) {
    let f = Mat3::identity() + h;
    let alpha = (j0 / f.determinant()).cbrt();
    (f, f * alpha, alpha)
}

/// Internal force, (optionally) tangent, energy and min J of one F-bar element. `centre`
/// holds the shape-function gradients at the element centre (its weight is not used).
/// Small-strain materials are not meant for F-bar; they get the standard element.
pub fn fbar_element_response<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    centre: &GaussPoint<N>,
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
) -> ElementResponse<N> {
    if material.small_strain() {
        return crate::element::element_response(gps, u, material, with_tangent);
    }
    let mut force = [[0.0; 3]; N];
    let mut tangent = if with_tangent {
        Some(Box::new([[Mat3::zeros(); N]; N]))
    } else {
        None
    };
    let f0 = Mat3::identity() + displacement_gradient(centre, u);
    let j0 = f0.determinant();
    let mut energy = 0.0;
    let mut min_j = j0;
    let f0_inv_t = match f0.try_inverse() {
        Some(inv) if j0 > 0.0 => inv.transpose(),
        _ => {
            return ElementResponse {
                force,
                tangent,
                energy: f64::NAN,
                min_j,
            }
        }
    };
    let g0: [Vec3; N] = std::array::from_fn(|a| f0_inv_t * Vec3::from(centre.grad[a]));
    for gp in gps {
        let (f, fbar, alpha) = fbar_gradient(&displacement_gradient(gp, u), j0);
        let j = f.determinant();
        min_j = min_j.min(j);
        let f_inv_t = match f.try_inverse() {
            Some(inv) if j > 0.0 => inv.transpose(),
            _ => {
                energy = f64::NAN;
                continue;
            }
        };
        let w = gp.weight;
        let cbar = fbar.transpose() * fbar;
        energy += material.energy(&cbar) * w;
        let (s, d) = if with_tangent {
            let (s, d) = material.pk2_and_tangent(&cbar);
            (s, Some(d))
        } else {
            (material.pk2(&cbar), None)
        };
        let p = fbar * s;
        let pf = p.dot(&f);
        let grads: [Vec3; N] = std::array::from_fn(|a| Vec3::from(gp.grad[a]));
        let g: [Vec3; N] = std::array::from_fn(|a| f_inv_t * grads[a]);
        let hv: [Vec3; N] = std::array::from_fn(|a| g0[a] - g[a]);
        let pg: [Vec3; N] = std::array::from_fn(|a| p * grads[a]);
        for a in 0..N {
            let fa = (pg[a] + hv[a] * (pf / 3.0)) * (w * alpha);
            for i in 0..3 {
                force[a][i] += fa[i];
            }
        }
        let (Some(kt), Some(d)) = (tangent.as_mut(), d) else {
            continue;
        };
        // 𝔸[F] = F̄ (S + ℂ:C̄) / α, with ℂ:C̄ from the Voigt tangent applied to C̄ written
        // with engineering shears.
        let cv = Vector6::new(
            cbar[(0, 0)],
            cbar[(1, 1)],
            cbar[(2, 2)],
            2.0 * cbar[(0, 1)],
            2.0 * cbar[(1, 2)],
            2.0 * cbar[(0, 2)],
        );
        let xv = d * cv;
        let x = Mat3::new(
            xv[0], xv[3], xv[5], xv[3], xv[1], xv[4], xv[5], xv[4], xv[2],
        );
        let af = fbar * (s + x) / alpha;
        let af_f = af.dot(&f);
        let m: [Vec3; N] = std::array::from_fn(|a| af * grads[a]);
        let bs: [Bmat; N] = std::array::from_fn(|a| b_matrix(&fbar, &grads[a]));
        let dbs: [Bmat; N] = std::array::from_fn(|b| d * bs[b]);
        let a2 = w * alpha * alpha;
        let wa = w * alpha;
        for a in 0..N {
            let sga = s * grads[a];
            for b in a..N {
                let mut kab = bs[a].transpose() * dbs[b];
                let geo = sga.dot(&grads[b]);
                for i in 0..3 {
                    kab[(i, i)] += geo;
                }
                kab = kab * a2
                    + (m[a] * hv[b].transpose() + hv[a] * m[b].transpose()) * (a2 / 3.0)
                    + hv[a] * hv[b].transpose() * (a2 * af_f / 9.0 + wa * pf / 9.0)
                    + (g[b] * g[a].transpose() - g0[b] * g0[a].transpose()) * (wa * pf / 3.0)
                    + (hv[a] * pg[b].transpose() + pg[a] * hv[b].transpose()) * (wa / 3.0);
                kt[a][b] += kab;
            }
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

/// Volume-weighted Cauchy stress σ̄ = J̄⁻¹ F̄ S(F̄ᵀF̄) F̄ᵀ over the Gauss points of an F-bar
/// element [Pa], and the mean J (of the displacement-based F).
pub fn fbar_cauchy_stress<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    centre: &GaussPoint<N>,
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
) -> (Mat3, f64) {
    if material.small_strain() {
        return crate::element::element_cauchy_stress(gps, u, material);
    }
    let j0 = (Mat3::identity() + displacement_gradient(centre, u)).determinant();
    let mut sigma = Mat3::zeros();
    let (mut jsum, mut vol) = (0.0, 0.0);
    for gp in gps {
        let (f, fbar, _) = fbar_gradient(&displacement_gradient(gp, u), j0);
        let cauchy = fbar * material.pk2(&(fbar.transpose() * fbar)) * fbar.transpose() / j0;
        sigma += cauchy * gp.weight;
        jsum += f.determinant() * gp.weight;
        vol += gp.weight;
    }
    (sigma / vol, jsum / vol)
}
