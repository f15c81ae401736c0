//! F-bar with a volume change linear in the element: the quadratic hexahedron's locking-free
//! form (Q2/P1, a discontinuous pressure linear in each element, as Abaqus's hybrid C3D20H).
//!
//! The element-constant volume change of [`crate::fbar`] (Q2/P0 on a hex20) costs a
//! dilatation that varies linearly across the element no volumetric energy, so a quadratic
//! element bent in its plane is too soft on coarse meshes. Here the volume change at Gauss
//! point g is the value there of the L² projection of J onto the functions linear in the
//! reference coordinates X over the element,
//!
//! θ_g = Σ_k φ_k(X_g) c_k,  c = M⁻¹ Σ_h w_h φ(X_h) J_h,  M = Σ_h w_h φ(X_h) φ(X_h)ᵀ,
//!
//! with φ = (1, (X − X̄)/ℓ) (X̄ the element's centroid, ℓ = V^(1/3)), and F̄_g = α_g F_g,
//! α_g = (θ_g/J_g)^(1/3), as in F-bar. For an uncoupled material (W = W̄(C̄) + U(J)) the
//! element energy Σ_g w_g W(F̄_g) = Σ_g w_g [W̄(C̄_g) + U(θ_g)] is the three-field
//! (Hu-Washizu) element of Simo, Taylor & Pister (*Comput. Methods Appl. Mech. Engrg.* 51
//! (1985) 177) with the volume change and the pressure both linear in the element and
//! condensed: the constraint ∫ q (J − θ) dV = 0 for every linear q is exactly the projection
//! above. The constant function is in the space, so a homogeneous deformation gives θ_g = J
//! and the patch test holds on any mesh; the mean of θ is the element's volume ratio v/V.
//!
//! With P_gh = w_h φ(X_g)ᵀ M⁻¹ φ(X_h), θ_g = Σ_h P_gh J_h; F-bar is P_gh = w_h / V. The force
//! and tangent are those of [`crate::fbar`] with θ, its gradient d_a and the second
//! derivatives of ln θ taken per Gauss point:
//!
//! f_a = Σ_g w_g α_g [P̄ G_a + ⅓ (P̄:F) h_ga],  h_ga = d_ga/θ_g − F_g⁻ᵀ G_a,
//! d_ga = ∂θ_g/∂u_a = Σ_k φ_k(X_g) D_ka,  D_ka = ∂c_k/∂u_a = Σ_h r_hk J_h F_h⁻ᵀ G_a,h,
//!
//! r_hk = w_h (M⁻¹ φ(X_h))_k, and ∂²(ln θ_g)/∂u_a∂u_b = (1/θ_g) Σ_h P_gh J_h (g_ha ⊗ g_hb −
//! g_hb ⊗ g_ha) − d_ga ⊗ d_gb/θ_g². The tangent is the Hessian of the energy, hence symmetric;
//! every node of the element couples to every other one, as in the standard element.

use crate::element::{
    displacement_gradient, material_point, zeroed_tangent, ElementResponse, GaussPoint,
    ViscousHistory,
};
use crate::fbar::b_matrix;
use crate::material::Hyperelastic;
use crate::{Mat3, Vec3};
use nalgebra::{Matrix4, Vector4};

/// Number of functions of the linear space: 1, X, Y, Z.
const K: usize = 4;

/// The linear space of volume changes of one element, from its reference configuration.
#[derive(Clone, Copy, Debug)]
pub struct LinearDilatation<const G: usize> {
    /// φ_k(X_g) [-]: 1 and the coordinates of Gauss point g relative to the element's
    /// centroid, over ℓ = V^(1/3).
    pub phi: [[f64; K]; G],
    /// r_gk = w_g (M⁻¹ φ(X_g))_k [-]: the projection's coefficients are c_k = Σ_g r_gk J_g.
    pub proj: [[f64; K]; G],
}

impl<const G: usize> LinearDilatation<G> {
    /// The space of an element with Gauss data `gps` and reference node coordinates `x`
    /// [m]; `None` when the Gauss points do not span three dimensions (M not positive
    /// definite).
    pub fn new<const N: usize>(gps: &[GaussPoint<N>; G], x: &[[f64; 3]; N]) -> Option<Self> {
        let points: [Vec3; G] = std::array::from_fn(|g| {
            (0..N).fold(Vec3::zeros(), |s, a| s + Vec3::from(x[a]) * gps[g].shape[a])
        });
        let vol: f64 = gps.iter().map(|gp| gp.weight).sum();
        let centre = points
            .iter()
            .zip(gps)
            .fold(Vec3::zeros(), |s, (p, gp)| s + p * gp.weight)
            / vol;
        let len = vol.cbrt();
        let phi: [[f64; K]; G] = std::array::from_fn(|g| {
            let d = (points[g] - centre) / len;
            [1.0, d[0], d[1], d[2]]
        });
        let mut m = Matrix4::zeros();
        for (p, gp) in phi.iter().zip(gps) {
            let p = Vector4::from(*p);
            m += p * p.transpose() * gp.weight;
        }
        let m = m.cholesky()?;
        let proj = std::array::from_fn(|g| {
            let r = m.solve(&Vector4::from(phi[g])) * gps[g].weight;
            [r[0], r[1], r[2], r[3]]
        });
        Some(LinearDilatation { phi, proj })
    }

    /// θ_g [-] at each Gauss point from J_g [-] at each: the L² projection of J.
    pub fn project(&self, j: &[f64; G]) -> [f64; G] {
        let mut c = [0.0; K];
        for (r, jh) in self.proj.iter().zip(j) {
            for k in 0..K {
                c[k] += r[k] * jh;
            }
        }
        self.phi
            .map(|p| p.iter().zip(&c).map(|(pk, ck)| pk * ck).sum())
    }
}

/// Gauss-point kinematics of an element: F, J, F⁻ᵀ G_a and θ per point, and the gradients
/// D_ka = ∂c_k/∂u_a of the projection's coefficients.
struct Kinematics<const N: usize, const G: usize> {
    f: [Mat3; G],
    j: [f64; G],
    g: [[Vec3; N]; G],
    theta: [f64; G],
    dc: [[Vec3; N]; K],
}

impl<const N: usize, const G: usize> Kinematics<N, G> {
    /// The kinematics at displacement `u` [m]; `Err(min(J, θ))` when some J or θ is ≤ 0 or
    /// F singular.
    fn new(
        gps: &[GaussPoint<N>; G],
        lin: &LinearDilatation<G>,
        u: &[[f64; 3]; N],
    ) -> Result<Self, f64> {
        let f: [Mat3; G] =
            std::array::from_fn(|q| Mat3::identity() + displacement_gradient(&gps[q], u));
        let j: [f64; G] = std::array::from_fn(|q| f[q].determinant());
        let min_j = j.iter().copied().fold(f64::INFINITY, f64::min);
        let mut g = [[Vec3::zeros(); N]; G];
        let mut dc = [[Vec3::zeros(); N]; K];
        for q in 0..G {
            let f_inv_t = match f[q].try_inverse() {
                Some(inv) if j[q] > 0.0 => inv.transpose(),
                _ => return Err(min_j),
            };
            for a in 0..N {
                g[q][a] = f_inv_t * Vec3::from(gps[q].grad[a]);
                for k in 0..K {
                    dc[k][a] += g[q][a] * (lin.proj[q][k] * j[q]);
                }
            }
        }
        let theta = lin.project(&j);
        let min_theta = theta.iter().copied().fold(f64::INFINITY, f64::min);
        if !(min_theta > 0.0) {
            return Err(min_j.min(min_theta));
        }
        Ok(Kinematics { f, j, g, theta, dc })
    }

    /// d_qa/θ_q = ∂(ln θ_q)/∂u_a [1/m] at Gauss point q.
    fn dlog_theta(&self, lin: &LinearDilatation<G>, q: usize) -> [Vec3; N] {
        let p = &lin.phi[q];
        std::array::from_fn(|a| {
            (0..K).fold(Vec3::zeros(), |s, k| s + self.dc[k][a] * p[k]) / self.theta[q]
        })
    }
}

/// What one Gauss point's force and tangent are built from.
struct Point<const N: usize> {
    /// Weight w [m³] and α = (θ/J)^(1/3) [-].
    w: f64,
    alpha: f64,
    /// F and F̄ = α F [-], C̄ = F̄ᵀF̄ [-], S(C̄) [Pa], P̄:F [Pa].
    f: Mat3,
    fbar: Mat3,
    cbar: Mat3,
    s: Mat3,
    pf: f64,
    /// G_a [1/m], h_a = ∂(ln θ)/∂u_a − F⁻ᵀG_a [1/m], P̄ G_a [Pa/m].
    grads: [Vec3; N],
    hv: [Vec3; N],
    pg: [Vec3; N],
}

/// Adds Gauss point q's internal force to `force` [N] and, when the material gave `dmat`,
/// its tangent (all but the second derivatives of ln θ) to `kt` [N/m], upper blocks only.
fn add_point<const N: usize>(
    pt: &Point<N>,
    g: &[Vec3; N],
    force: &mut [[f64; 3]; N],
    kt: Option<&mut [[Mat3; N]; N]>,
    dmat: Option<crate::Mat6>,
) {
    let (w, alpha, pf) = (pt.w, pt.alpha, pt.pf);
    for a in 0..N {
        let fa = (pt.pg[a] + pt.hv[a] * (pf / 3.0)) * (w * alpha);
        for i in 0..3 {
            force[a][i] += fa[i];
        }
    }
    let (Some(kt), Some(dmat)) = (kt, dmat) else {
        return;
    };
    let x = crate::fbar::tangent_on(&dmat, &pt.cbar);
    // 𝔸[F] = F̄ (S + ℂ:C̄) / α and m_a = 𝔸[F] G_a (see crate::fbar).
    let af = pt.fbar * (pt.s + x) / alpha;
    let (a2, wa) = (w * alpha * alpha, w * alpha);
    let hh = a2 * af.dot(&pt.f) / 9.0 + wa * pf / 9.0;
    let mv: [Vec3; N] =
        std::array::from_fn(|a| af * pt.grads[a] * (a2 / 3.0) + pt.pg[a] * (wa / 3.0));
    let bs = pt.grads.map(|ga| b_matrix(&pt.fbar, &ga));
    let dbs = bs.map(|b| dmat * b);
    for a in 0..N {
        let sga = pt.s * pt.grads[a];
        let ga = g[a] * (wa * pf / 3.0);
        for b in a..N {
            let mut kab = bs[a].transpose() * dbs[b];
            let geo = sga.dot(&pt.grads[b]);
            for i in 0..3 {
                kab[(i, i)] += geo;
            }
            kt[a][b] += kab * a2
                + mv[a] * pt.hv[b].transpose()
                + pt.hv[a] * (mv[b] + pt.hv[b] * hh).transpose()
                + g[b] * ga.transpose();
        }
    }
}

/// Adds Σ_g c_g ∂²(ln θ_g)/∂u_a∂u_b to the upper blocks of `kt` [N/m], c_g = w_g α_g (P̄:F)_g/3
/// [J] the weight of point g's second derivatives.
fn add_log_theta_hessian<const N: usize, const G: usize>(
    kt: &mut [[Mat3; N]; N],
    lin: &LinearDilatation<G>,
    kin: &Kinematics<N, G>,
    c: &[f64; G],
) {
    // Σ_g (c_g/θ_g) ∂²θ_g = Σ_h λ_h J_h (g_ha ⊗ g_hb − g_hb ⊗ g_ha),
    // λ_h = Σ_k r_hk Σ_g φ_k(X_g) c_g/θ_g.
    let mut s = [0.0; K];
    let mut cm = Matrix4::<f64>::zeros();
    for q in 0..G {
        let p = Vector4::from(lin.phi[q]);
        for k in 0..K {
            s[k] += p[k] * c[q] / kin.theta[q];
        }
        cm += p * p.transpose() * (c[q] / (kin.theta[q] * kin.theta[q]));
    }
    for q in 0..G {
        let lambda: f64 = (0..K).map(|k| lin.proj[q][k] * s[k]).sum::<f64>() * kin.j[q];
        for a in 0..N {
            let ga = kin.g[q][a] * lambda;
            for b in a + 1..N {
                let skew = ga * kin.g[q][b].transpose();
                kt[a][b] += skew - skew.transpose();
            }
        }
    }
    // − Σ_g c_g d_ga ⊗ d_gb / θ_g² = − Σ_kl C_kl D_ka ⊗ D_lb, C_kl = Σ_g c_g φ_k φ_l / θ_g².
    let e: [[Vec3; N]; K] = std::array::from_fn(|k| {
        std::array::from_fn(|b| (0..K).fold(Vec3::zeros(), |v, l| v + kin.dc[l][b] * cm[(k, l)]))
    });
    for a in 0..N {
        for b in a..N {
            for k in 0..K {
                kt[a][b] -= kin.dc[k][a] * e[k][b].transpose();
            }
        }
    }
}

/// The state of Gauss point q: F̄ from F and θ, the material at C̄ (with the point's viscous
/// part), and the energy density W(C̄) [J/m³].
fn point_state<const N: usize, const G: usize>(
    gp: &GaussPoint<N>,
    q: usize,
    kin: &Kinematics<N, G>,
    dlog_theta: &[Vec3; N],
    material: &dyn Hyperelastic,
    viscous: ViscousHistory<'_>,
    with_tangent: bool,
) -> (Point<N>, f64, Option<crate::Mat6>) {
    let f = kin.f[q];
    let alpha = (kin.theta[q] / kin.j[q]).cbrt();
    let fbar = f * alpha;
    let cbar = fbar.transpose() * fbar;
    let (w_point, s, dmat) = material_point(material, &cbar, q, viscous, with_tangent);
    let p = fbar * s;
    let grads: [Vec3; N] = gp.grad.map(Vec3::from);
    let point = Point {
        w: gp.weight,
        alpha,
        f,
        fbar,
        cbar,
        s,
        pf: p.dot(&f),
        grads,
        hv: std::array::from_fn(|a| dlog_theta[a] - kin.g[q][a]),
        pg: grads.map(|ga| p * ga),
    };
    (point, w_point, dmat)
}

/// Internal force [N], (optionally) tangent [N/m], energy [J] and min J of one element with
/// the linear volume change, at displacement `u` [m]; `history` as in
/// [`crate::element::element_response_with_history`]. Small-strain materials get the
/// standard element.
pub fn linear_dilatation_response<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    lin: &LinearDilatation<G>,
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
    with_tangent: bool,
    history: Option<(&[f64], f64)>,
) -> ElementResponse<N> {
    if material.small_strain() {
        return crate::element::element_response_with_history(
            gps,
            u,
            material,
            with_tangent,
            history,
        );
    }
    let viscous = history.zip(material.viscoelastic());
    let mut force = [[0.0; 3]; N];
    let mut tangent = with_tangent.then(zeroed_tangent::<N>);
    let kin = match Kinematics::new(gps, lin, u) {
        Ok(kin) => kin,
        Err(min_j) => {
            let energy = f64::NAN;
            return ElementResponse {
                force,
                tangent,
                energy,
                min_j,
            };
        }
    };
    let mut energy = 0.0;
    let mut c = [0.0; G];
    for (q, gp) in gps.iter().enumerate() {
        let dlog = kin.dlog_theta(lin, q);
        let (pt, w_point, dmat) = point_state(gp, q, &kin, &dlog, material, viscous, with_tangent);
        energy += w_point * pt.w;
        c[q] = pt.w * pt.alpha * pt.pf / 3.0;
        add_point(&pt, &kin.g[q], &mut force, tangent.as_deref_mut(), dmat);
    }
    if let Some(kt) = tangent.as_deref_mut() {
        add_log_theta_hessian(kt, lin, &kin, &c);
        for a in 0..N {
            for b in 0..a {
                kt[a][b] = kt[b][a].transpose();
            }
        }
    }
    let min_j = kin.j.iter().copied().fold(f64::INFINITY, f64::min);
    ElementResponse {
        force,
        tangent,
        energy,
        min_j,
    }
}

/// F̄_g [-] at each Gauss point of an element with the linear volume change at `u` [m].
fn fbar_points<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    lin: &LinearDilatation<G>,
    u: &[[f64; 3]; N],
) -> [Mat3; G] {
    let f: [Mat3; G] =
        std::array::from_fn(|q| Mat3::identity() + displacement_gradient(&gps[q], u));
    let theta = lin.project(&f.map(|f| f.determinant()));
    std::array::from_fn(|q| f[q] * (theta[q] / f[q].determinant()).cbrt())
}

/// C̄ = F̄ᵀF̄ [-] at each Gauss point of an element with the linear volume change.
pub fn linear_dilatation_c<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    lin: &LinearDilatation<G>,
    u: &[[f64; 3]; N],
) -> [Mat3; G] {
    fbar_points(gps, lin, u).map(|fb| fb.transpose() * fb)
}

/// Volume-weighted mean over the Gauss points of the Cauchy stress θ_g⁻¹ F̄ S(F̄ᵀF̄) F̄ᵀ [Pa]
/// of an element with the linear volume change, and its volume ratio v/V [-].
pub fn linear_dilatation_cauchy_stress<const N: usize, const G: usize>(
    gps: &[GaussPoint<N>; G],
    lin: &LinearDilatation<G>,
    u: &[[f64; 3]; N],
    material: &dyn Hyperelastic,
) -> (Mat3, f64) {
    if material.small_strain() {
        return crate::element::element_cauchy_stress(gps, u, material);
    }
    let mut sigma = Mat3::zeros();
    let mut vol = 0.0;
    for (fbar, gp) in fbar_points(gps, lin, u).iter().zip(gps) {
        let theta = fbar.determinant();
        let cauchy = fbar * material.pk2(&(fbar.transpose() * fbar)) * fbar.transpose() / theta;
        sigma += cauchy * gp.weight;
        vol += gp.weight;
    }
    (sigma / vol, crate::fbar::volume_ratio(gps, u))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::{hex20_geometry, HEX20};

    /// A curved, skewed hex20 of size about 2 [m] and its linear space.
    fn curved() -> ([[f64; 3]; 20], [GaussPoint<20>; 27], LinearDilatation<27>) {
        let x: [[f64; 3]; 20] = std::array::from_fn(|a| {
            let c = HEX20.natural_nodes[a];
            let bend = 0.1 * (1.0 - c[0] * c[0]);
            [
                c[0] + 0.2 * c[1],
                c[1] + 0.1 * c[2] + bend,
                c[2] + 0.15 * c[0],
            ]
        });
        let gps = hex20_geometry(&x).unwrap();
        let lin = LinearDilatation::new(&gps, &x).unwrap();
        (x, gps, lin)
    }

    /// X_g [m] at each Gauss point.
    fn points(x: &[[f64; 3]; 20], gps: &[GaussPoint<20>; 27]) -> [Vec3; 27] {
        std::array::from_fn(|g| {
            (0..20).fold(Vec3::zeros(), |s, a| s + Vec3::from(x[a]) * gps[g].shape[a])
        })
    }

    /// A J linear in X is its own projection (to round-off); a quadratic one leaves a
    /// residual J − θ orthogonal to 1, X, Y and Z under the Gauss rule (the definition of the
    /// L² projection), and keeps the element's mean.
    #[test]
    fn projection_keeps_linear_fields_and_is_orthogonal() {
        let (x, gps, lin) = curved();
        let p = points(&x, &gps);
        let linear: [f64; 27] = p.map(|p| 1.0 + 0.1 * p[0] - 0.2 * p[1] + 0.05 * p[2]);
        let theta = lin.project(&linear);
        for (t, j) in theta.iter().zip(&linear) {
            assert!((t - j).abs() < 1e-14, "{t} against {j}");
        }
        let quadratic: [f64; 27] = p.map(|p| 1.0 + 0.3 * p[0] * p[1] - 0.2 * p[2] * p[2]);
        let theta = lin.project(&quadratic);
        let mut worst: f64 = 0.0;
        for f in [
            |_: &Vec3| 1.0,
            |p: &Vec3| p[0],
            |p: &Vec3| p[1],
            |p: &Vec3| p[2],
        ] {
            let r: f64 = (0..27)
                .map(|g| gps[g].weight * (quadratic[g] - theta[g]) * f(&p[g]))
                .sum();
            worst = worst.max(r.abs());
        }
        assert!(worst < 1e-14, "residual moment {worst}");
        assert!(theta
            .iter()
            .zip(&quadratic)
            .any(|(t, j)| (t - j).abs() > 1e-3));
    }
}
