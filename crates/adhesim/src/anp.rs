//! The averaged-nodal-pressure tetrahedron (Bonet & Burton, *Commun. Numer. Meth. Engng* 14
//! (1998) 437), in variational form with its consistent tangent.
//!
//! A linear tetrahedron with one integration point must keep its own volume when the material
//! is nearly incompressible; a mesh of them has about as many elements as five times its
//! nodes, so the volume constraints outnumber the free displacements and the mesh locks. The
//! element here moves the volume constraint to the nodes: for the uncoupled materials
//! (W = W̄(C̄) + U(J), U(J) = κ/2 (J − 1)²) the energy of a body is
//!
//! Π = Σ_e V_e W̄(C̄_e) + Σ_a V_a U(J_a),  J_a = v_a / V_a,
//!
//! V_a = ¼ Σ_{e∋a} V_e and v_a = ¼ Σ_{e∋a} v_e the reference and current volumes of node a's
//! share of its patch (the elements that hold it), v_e = J_e V_e. A node has about one
//! constraint, and a tetrahedral mesh has a third as many constraints as displacements.
//!
//! The internal force is the gradient of Π:
//!
//! f = Σ_e [f̄_e + p̄_e ∂v_e/∂u],  p̄_e = ¼ Σ_{a∈e} p_a,  p_a = U′(J_a),
//!
//! with f̄_e the force of the isochoric energy alone and ∂v_e/∂u_b = v_e F_e⁻ᵀ G_b: the
//! element's pressure is the mean of its nodes' pressures, which is Bonet and Burton's
//! averaged nodal pressure. The tangent is the Hessian of Π, symmetric:
//!
//! K = Σ_e [K̄_e + p̄_e ∂²v_e/∂u²] + Σ_a (U″(J_a)/V_a) w_a ⊗ w_a,  w_a = ∂v_a/∂u,
//!
//! with ∂²v_e/∂u_b∂u_c = v_e (g_b ⊗ g_c − g_c ⊗ g_b), g_b = F⁻ᵀ G_b. The last term couples
//! every pair of nodes of a patch, i.e. a node with the neighbours of its neighbours: the
//! sparsity pattern holds each patch as one extra "cell". Faces stay linear triangles and the
//! nodes stay the corners, so contact, output and mass are those of the linear tetrahedron.

use crate::element::{displacement_gradient, GaussPoint};
use crate::material::{Hyperelastic, Viscoelastic};
use crate::{Mat3, Mat6, Vec3};

/// Volumetric energy U(J) = κ/2 (J − 1)² [J/m³] of the uncoupled materials.
pub fn volumetric_energy(kappa: f64, j: f64) -> f64 {
    0.5 * kappa * (j - 1.0) * (j - 1.0)
}

/// Pressure p = U′(J) = κ (J − 1) [Pa] (positive in tension).
pub fn volumetric_pressure(kappa: f64, j: f64) -> f64 {
    kappa * (j - 1.0)
}

/// True when the material has a volumetric/isochoric split the element can use (the
/// uncoupled finite-strain materials and viscoelastic materials built on them).
pub fn has_volumetric_split(material: &dyn Hyperelastic) -> bool {
    !material.small_strain()
        && material
            .isochoric_pk2_and_tangent(&Mat3::identity())
            .is_some()
}

/// The isochoric part W̄(C̄(C)) of an uncoupled material, as a material of its own (its
/// bulk modulus is zero). Its viscous part, if any, is the material's: the Prony series acts
/// on the isochoric stress only.
#[derive(Debug)]
pub struct IsochoricPart<'a>(pub &'a dyn Hyperelastic);

impl IsochoricPart<'_> {
    fn split(&self, c: &Mat3) -> (Mat3, Mat6) {
        self.0
            .isochoric_pk2_and_tangent(c)
            .expect("the averaged-nodal-pressure element needs an uncoupled material")
    }
}

impl Hyperelastic for IsochoricPart<'_> {
    fn energy(&self, c: &Mat3) -> f64 {
        let j = c.determinant().sqrt();
        self.0.energy(c) - volumetric_energy(self.0.bulk_modulus(), j)
    }
    fn pk2(&self, c: &Mat3) -> Mat3 {
        self.split(c).0
    }
    fn pk2_and_tangent(&self, c: &Mat3) -> (Mat3, Mat6) {
        self.split(c)
    }
    fn shear_modulus(&self) -> f64 {
        self.0.shear_modulus()
    }
    fn bulk_modulus(&self) -> f64 {
        0.0
    }
    fn isochoric_pk2_and_tangent(&self, c: &Mat3) -> Option<(Mat3, Mat6)> {
        Some(self.split(c))
    }
    fn viscoelastic(&self) -> Option<&Viscoelastic> {
        self.0.viscoelastic()
    }
}

/// Current volume v = J V [m³] of a one-point element and its gradient ∂v/∂u_b = v F⁻ᵀ G_b
/// [m²]; `None` when J ≤ 0.
pub fn volume_and_gradient<const N: usize>(
    gp: &GaussPoint<N>,
    u: &[[f64; 3]; N],
) -> Option<(f64, [Vec3; N])> {
    let f = Mat3::identity() + displacement_gradient(gp, u);
    let j = f.determinant();
    if j.is_nan() || j <= 0.0 {
        return None;
    }
    let f_inv_t = f.try_inverse()?.transpose();
    let v = j * gp.weight;
    Some((
        v,
        std::array::from_fn(|b| f_inv_t * Vec3::from(gp.grad[b]) * v),
    ))
}

/// p̄ ∂²v/∂u_b∂u_c = (p̄/v) (dv_b ⊗ dv_c − dv_c ⊗ dv_b) added to the element tangent blocks
/// `k[b][c]`, from the volume gradient `dv` and the volume `v`.
pub fn add_volume_hessian<const N: usize>(
    k: &mut [[Mat3; N]; N],
    dv: &[Vec3; N],
    v: f64,
    pressure: f64,
) {
    let s = pressure / v;
    for b in 0..N {
        for c in 0..N {
            k[b][c] += (dv[b] * dv[c].transpose() - dv[c] * dv[b].transpose()) * s;
        }
    }
}

/// The nodal patches of the averaged-nodal-pressure tetrahedra of a discretisation.
#[derive(Clone, Debug, Default)]
pub struct NodalPatches {
    /// For each tetrahedron of the discretisation: true when it uses this formulation.
    pub active: Vec<bool>,
    /// Global index of each patch node (a node of at least one active tetrahedron).
    pub nodes: Vec<usize>,
    /// Reference volume V_a of each patch node's share [m³].
    pub ref_volume: Vec<f64>,
    /// Bulk modulus κ of each patch node's material [Pa].
    pub kappa: Vec<f64>,
    /// Patch index of each global node (`u32::MAX`: none).
    pub patch_of: Vec<u32>,
    /// Elements of patch a: `elem[elem_ptr[a]..elem_ptr[a + 1]]`, each the tetrahedron index
    /// and the positions of its four nodes in the patch's node list.
    pub elem_ptr: Vec<usize>,
    /// See `elem_ptr`.
    pub elem: Vec<(usize, [u32; 4])>,
    /// Sorted global nodes of patch a: `patch_nodes[node_ptr[a]..node_ptr[a + 1]]`.
    pub node_ptr: Vec<usize>,
    /// See `node_ptr`.
    pub patch_nodes: Vec<usize>,
    /// Pattern ranks of the node pairs (i ≤ j) of each patch, row by row, starting at
    /// `rank_ptr[a]`.
    pub rank_ptr: Vec<usize>,
    /// See `rank_ptr`.
    pub ranks: Vec<u32>,
}

impl NodalPatches {
    /// Patches of the tetrahedra `tets` (global nodes) flagged in `active`, with reference
    /// volumes `volume` [m³] and the bulk modulus of each element's material `kappa` [Pa].
    pub fn new(
        tets: &[[usize; 4]],
        volume: &[f64],
        kappa: &[f64],
        active: Vec<bool>,
        num_nodes: usize,
    ) -> Self {
        let mut patch_of = vec![u32::MAX; num_nodes];
        let mut nodes = Vec::new();
        let mut ref_volume = Vec::new();
        let mut node_kappa = Vec::new();
        let mut elems: Vec<Vec<usize>> = Vec::new();
        for (e, t) in tets.iter().enumerate() {
            if !active[e] {
                continue;
            }
            for &n in t {
                if patch_of[n] == u32::MAX {
                    patch_of[n] = nodes.len() as u32;
                    nodes.push(n);
                    ref_volume.push(0.0);
                    node_kappa.push(kappa[e]);
                    elems.push(Vec::new());
                }
                let a = patch_of[n] as usize;
                ref_volume[a] += 0.25 * volume[e];
                elems[a].push(e);
            }
        }
        let mut out = NodalPatches {
            active,
            nodes,
            ref_volume,
            kappa: node_kappa,
            patch_of,
            elem_ptr: vec![0],
            node_ptr: vec![0],
            rank_ptr: vec![0],
            ..Default::default()
        };
        for list in &elems {
            let mut pn: Vec<usize> = list.iter().flat_map(|&e| tets[e]).collect();
            pn.sort_unstable();
            pn.dedup();
            for &e in list {
                let pos = tets[e].map(|n| pn.binary_search(&n).expect("patch node") as u32);
                out.elem.push((e, pos));
            }
            out.elem_ptr.push(out.elem.len());
            out.patch_nodes.extend_from_slice(&pn);
            out.node_ptr.push(out.patch_nodes.len());
        }
        out
    }

    /// The node lists of the patches (each couples all its nodes in the sparsity pattern).
    pub fn cells(&self) -> impl Iterator<Item = &[usize]> {
        (0..self.nodes.len()).map(|a| &self.patch_nodes[self.node_ptr[a]..self.node_ptr[a + 1]])
    }

    /// Fills the pattern ranks of every patch's node pairs.
    pub fn fill_ranks(&mut self, pattern: &crate::linalg::BlockPattern) {
        self.ranks.clear();
        self.rank_ptr = vec![0];
        for a in 0..self.nodes.len() {
            let pn = &self.patch_nodes[self.node_ptr[a]..self.node_ptr[a + 1]];
            for i in 0..pn.len() {
                for j in i..pn.len() {
                    let r = pattern
                        .rank(pn[i], pn[j])
                        .expect("the pattern holds every patch pair");
                    self.ranks.push(r as u32);
                }
            }
            self.rank_ptr.push(self.ranks.len());
        }
    }

    /// Volumes and nodal pressures at the displacement `u` of the gauss data `gauss` of all
    /// tetrahedra (global nodes `tets`).
    pub fn state(
        &self,
        tets: &[[usize; 4]],
        gauss: &[[GaussPoint<4>; 1]],
        u: &[f64],
    ) -> PatchState {
        use rayon::prelude::*;
        let vol: Vec<Option<(f64, [Vec3; 4])>> = (0..tets.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|e| {
                if !self.active[e] {
                    return None;
                }
                let ue: [[f64; 3]; 4] = tets[e].map(|n| [u[3 * n], u[3 * n + 1], u[3 * n + 2]]);
                volume_and_gradient(&gauss[e][0], &ue)
            })
            .collect();
        let mut valid = true;
        let mut energy = 0.0;
        let mut ratio = vec![0.0; self.nodes.len()];
        let mut pressure = vec![0.0; self.nodes.len()];
        for a in 0..self.nodes.len() {
            let mut v = 0.0;
            for &(e, _) in &self.elem[self.elem_ptr[a]..self.elem_ptr[a + 1]] {
                match vol[e] {
                    Some((ve, _)) => v += 0.25 * ve,
                    None => valid = false,
                }
            }
            let j = v / self.ref_volume[a];
            ratio[a] = j;
            pressure[a] = volumetric_pressure(self.kappa[a], j);
            energy += self.ref_volume[a] * volumetric_energy(self.kappa[a], j);
        }
        let element_pressure = tets
            .iter()
            .enumerate()
            .map(|(e, t)| {
                if self.active[e] {
                    0.25 * t
                        .iter()
                        .map(|&n| pressure[self.patch_of[n] as usize])
                        .sum::<f64>()
                } else {
                    0.0
                }
            })
            .collect();
        PatchState {
            volume: vol,
            nodal_ratio: ratio,
            element_pressure,
            energy: if valid { energy } else { f64::NAN },
        }
    }

    /// Adds Σ_a (κ_a/V_a) w_a ⊗ w_a to the tangent values (pattern order).
    pub fn add_patch_tangent(
        &self,
        state: &PatchState,
        pattern: &crate::linalg::BlockPattern,
        tangent: &mut [f64],
    ) {
        let mut w: Vec<Vec3> = Vec::new();
        for a in 0..self.nodes.len() {
            let pn = &self.patch_nodes[self.node_ptr[a]..self.node_ptr[a + 1]];
            w.clear();
            w.resize(pn.len(), Vec3::zeros());
            for &(e, pos) in &self.elem[self.elem_ptr[a]..self.elem_ptr[a + 1]] {
                if let Some((_, dv)) = &state.volume[e] {
                    for k in 0..4 {
                        w[pos[k] as usize] += dv[k] * 0.25;
                    }
                }
            }
            let c = self.kappa[a] / self.ref_volume[a];
            let ranks = &self.ranks[self.rank_ptr[a]..self.rank_ptr[a + 1]];
            let mut r = 0;
            for i in 0..pn.len() {
                let wi = w[i] * c;
                for j in i..pn.len() {
                    let rank = ranks[r] as usize;
                    r += 1;
                    let hi = pn[j];
                    for (k, wjk) in w[j].iter().enumerate() {
                        let base = pattern.col_ptr[3 * hi + k] + 3 * rank;
                        let imax = if i == j { k + 1 } else { 3 };
                        for l in 0..imax {
                            tangent[base + l] += wi[l] * wjk;
                        }
                    }
                }
            }
        }
    }
}

/// The volumetric state of the patches at one displacement.
pub struct PatchState {
    /// For each tetrahedron (active ones only): current volume v_e [m³] and ∂v_e/∂u [m²].
    pub volume: Vec<Option<(f64, [Vec3; 4])>>,
    /// Volume ratio J_a of each patch.
    pub nodal_ratio: Vec<f64>,
    /// Element pressure p̄_e [Pa] of each tetrahedron (0 for inactive ones).
    pub element_pressure: Vec<f64>,
    /// Volumetric energy Σ_a V_a U(J_a) [J] (NaN when some element is inverted).
    pub energy: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::tet4_geometry;

    #[test]
    fn volume_gradient_matches_finite_differences() {
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [0.2, 0.9, 0.1],
            [0.1, 0.2, 1.1],
        ];
        let gp = tet4_geometry(&x).unwrap()[0];
        let u = [
            [0.01, -0.02, 0.03],
            [0.1, 0.05, -0.02],
            [-0.03, 0.08, 0.02],
            [0.02, 0.01, 0.12],
        ];
        let (v, dv) = volume_and_gradient(&gp, &u).unwrap();
        let h = 1e-6;
        for b in 0..4 {
            for i in 0..3 {
                let mut up = u;
                let mut um = u;
                up[b][i] += h;
                um[b][i] -= h;
                let fd = (volume_and_gradient(&gp, &up).unwrap().0
                    - volume_and_gradient(&gp, &um).unwrap().0)
                    / (2.0 * h);
                // Central differences of a cubic: error O(h²) relative to v.
                assert!(
                    (fd - dv[b][i]).abs() < 1e-9 * v,
                    "{b} {i}: {fd} {}",
                    dv[b][i]
                );
            }
        }
    }

    #[test]
    fn volume_hessian_matches_finite_differences() {
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.1],
            [0.0, 1.0, 0.0],
            [0.1, 0.0, 1.0],
        ];
        let gp = tet4_geometry(&x).unwrap()[0];
        let u = [
            [0.0, 0.02, 0.0],
            [0.1, -0.05, 0.02],
            [0.03, 0.1, -0.02],
            [-0.02, 0.04, 0.2],
        ];
        let (v, dv) = volume_and_gradient(&gp, &u).unwrap();
        let mut k = [[Mat3::zeros(); 4]; 4];
        add_volume_hessian(&mut k, &dv, v, 1.0);
        let h = 1e-6;
        for c in 0..4 {
            for j in 0..3 {
                let mut up = u;
                let mut um = u;
                up[c][j] += h;
                um[c][j] -= h;
                let gp_ = volume_and_gradient(&gp, &up).unwrap().1;
                let gm = volume_and_gradient(&gp, &um).unwrap().1;
                for b in 0..4 {
                    for i in 0..3 {
                        let fd = (gp_[b][i] - gm[b][i]) / (2.0 * h);
                        assert!(
                            (fd - k[b][c][(i, j)]).abs() < 1e-8,
                            "{fd} {}",
                            k[b][c][(i, j)]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn isochoric_part_has_no_volumetric_stress() {
        let m = crate::material::UncoupledNeoHookean::from_young_poisson(1.0e6, 0.4999);
        let iso = IsochoricPart(&m);
        // Pure dilatation: no isochoric stress and no isochoric energy.
        let c = Mat3::identity() * 1.1f64.powf(2.0 / 3.0);
        assert!(iso.pk2(&c).norm() < 1e-9 * m.shear_modulus());
        // W̄ = W − U: the difference of two values of size U, exact to round-off.
        let u = volumetric_energy(m.bulk_modulus(), 1.1);
        assert!(iso.energy(&c).abs() < 1e-12 * u);
        assert!(has_volumetric_split(&m));
        assert!(!has_volumetric_split(&crate::material::BlatzKo::new(1.0e6)));
    }
}
