//! Global assembly over all bodies: one node numbering (bodies one after another), the
//! sparsity pattern built once, element colouring so that the scatter runs in parallel
//! without locks, and the constant mass matrix.

use crate::anp::{
    add_volume_hessian, has_volumetric_split, IsochoricPart, NodalPatches, PatchState,
};
use crate::element::ElementResponse;
use crate::element::{
    consistent_mass, element_response_with_history, gauss_point_c, hex8_geometry, tet4_geometry,
    DegenerateElement, GaussPoint,
};
use crate::fbar::{fbar_element_response_with_history, fbar_gauss_point_c, Formulation};
use crate::linalg::BlockPattern;
use crate::material::Hyperelastic;
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::sync::Arc;

/// Elements of one kind (N nodes, G Gauss points) with their reference data.
pub struct ElementBlock<const N: usize, const G: usize> {
    /// Global node indices.
    pub nodes: Vec<[usize; N]>,
    /// Reference Gauss-point data.
    pub gauss: Vec<[GaussPoint<N>; G]>,
    /// Index of the owning body.
    pub body: Vec<usize>,
    /// True for F-bar hexahedra and averaged-nodal-pressure tetrahedra ([`crate::anp`]),
    /// false for the standard fully integrated elements.
    pub fbar: Vec<bool>,
    /// Committed internal variables of viscoelastic elements, all Gauss points one after the
    /// other (empty for elastic elements).
    pub history: Vec<Vec<f64>>,
    /// For local pair (a, b): rank of min(node a, node b) among the upper neighbours of
    /// max(node a, node b) in the pattern.
    ranks: Vec<[[u32; N]; N]>,
    /// Element indices grouped so that no two elements of a group share a node.
    colours: Vec<Vec<usize>>,
}

impl<const N: usize, const G: usize> ElementBlock<N, G> {
    fn empty() -> Self {
        ElementBlock {
            nodes: vec![],
            gauss: vec![],
            body: vec![],
            fbar: vec![],
            history: vec![],
            ranks: vec![],
            colours: vec![],
        }
    }
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
    /// True when there are no elements of this kind.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
}

/// An element whose reference geometry is degenerate or inverted.
#[derive(Debug, Clone)]
pub struct BadElement {
    /// Body index.
    pub body: usize,
    /// Cell index within the body's mesh (hexes first, then tets).
    pub cell: usize,
    /// The offending reference Jacobian determinant.
    pub det: f64,
}

/// The discretised bodies: what is needed to assemble forces and tangents.
pub struct Discretisation {
    /// First global node index of each body.
    pub node_offset: Vec<usize>,
    /// Total number of nodes.
    pub num_nodes: usize,
    /// Reference coordinates of all nodes [m].
    pub reference: Vec<[f64; 3]>,
    /// Material of each body.
    pub materials: Vec<Arc<dyn Hyperelastic>>,
    /// Hexahedra.
    pub hexes: ElementBlock<8, 8>,
    /// Tetrahedra.
    pub tets: ElementBlock<4, 1>,
    /// Nodal patches of the averaged-nodal-pressure tetrahedra (`None`: there are none).
    pub patches: Option<NodalPatches>,
    /// Upper-triangle block pattern of every system matrix.
    pub pattern: BlockPattern,
    /// Size of the step being solved [s], for the viscoelastic materials.
    pub step_dt: f64,
}

/// Adds the volumetric part of element `e` to the response of its isochoric part (the
/// averaged-nodal-pressure tetrahedra).
type VolumetricPart<'a, const N: usize> = dyn Fn(usize, &mut ElementResponse<N>) + Sync + 'a;

/// Assembled internal force, tangent values (pattern order), energy and min J.
pub struct Assembled {
    /// Internal force vector [N], 3 per node.
    pub force: Vec<f64>,
    /// Tangent stiffness values in pattern order [N/m] (empty if not requested).
    pub tangent: Vec<f64>,
    /// Total strain energy [J].
    pub energy: f64,
    /// Smallest det F over all Gauss points.
    pub min_j: f64,
}

struct SyncPtr(*mut f64);
unsafe impl Sync for SyncPtr {}
unsafe impl Send for SyncPtr {}
impl SyncPtr {
    /// # Safety
    /// No two threads may write the same index concurrently.
    #[inline]
    unsafe fn add(&self, i: usize, v: f64) {
        *self.0.add(i) += v;
    }
}

fn colour_elements<const N: usize>(nodes: &[[usize; N]], num_nodes: usize) -> Vec<Vec<usize>> {
    // Greedy colouring: an element takes the first colour none of its nodes has seen.
    let mut node_colours: Vec<u64> = vec![0; num_nodes];
    let mut colours: Vec<Vec<usize>> = Vec::new();
    let mut overflow: Vec<usize> = Vec::new();
    for (e, en) in nodes.iter().enumerate() {
        let used = en.iter().fold(0u64, |m, &n| m | node_colours[n]);
        let c = (!used).trailing_zeros() as usize;
        if c >= 64 {
            overflow.push(e);
            continue;
        }
        if c >= colours.len() {
            colours.resize(c + 1, Vec::new());
        }
        colours[c].push(e);
        for &n in en {
            node_colours[n] |= 1 << c;
        }
    }
    // Pathological meshes with more than 64 colours: one element per group.
    colours.extend(overflow.into_iter().map(|e| vec![e]));
    colours
}

fn fill_ranks<const N: usize, const G: usize>(
    block: &mut ElementBlock<N, G>,
    pattern: &BlockPattern,
) {
    block.ranks = block
        .nodes
        .iter()
        .map(|en| {
            let mut r = [[0u32; N]; N];
            for a in 0..N {
                for b in 0..N {
                    let (lo, hi) = if en[a] <= en[b] {
                        (en[a], en[b])
                    } else {
                        (en[b], en[a])
                    };
                    r[a][b] = pattern
                        .rank(lo, hi)
                        .expect("pattern holds every element pair")
                        as u32;
                }
            }
            r
        })
        .collect();
    block.colours = colour_elements(&block.nodes, pattern.num_nodes);
}

/// Zeroed internal variables for an element of `points` Gauss points (empty if elastic).
fn history_for(material: &dyn Hyperelastic, points: usize) -> Vec<f64> {
    material
        .viscoelastic()
        .map_or(Vec::new(), |ve| vec![0.0; points * ve.history_len()])
}

fn commit_block<const N: usize, const G: usize>(
    block: &mut ElementBlock<N, G>,
    materials: &[Arc<dyn Hyperelastic>],
    u: &[f64],
    dt: f64,
) {
    let (nodes, gauss, body, fbar) = (&block.nodes, &block.gauss, &block.body, &block.fbar);
    block
        .history
        .par_iter_mut()
        .enumerate()
        .filter(|(_, h)| !h.is_empty())
        .for_each(|(e, h)| {
            let Some(ve) = materials[body[e]].viscoelastic() else {
                return;
            };
            let ue: [[f64; 3]; N] =
                std::array::from_fn(|a| std::array::from_fn(|i| u[3 * nodes[e][a] + i]));
            let cs = if fbar[e] {
                fbar_gauss_point_c(&gauss[e], &ue)
            } else {
                gauss_point_c(&gauss[e], &ue)
            };
            let len = ve.history_len();
            for (q, c) in cs.iter().enumerate() {
                ve.commit(c, &mut h[q * len..(q + 1) * len], dt);
            }
        });
}

impl Discretisation {
    /// Builds the discretisation of the given bodies (mesh, material). Fails with the list
    /// of degenerate or inverted reference elements.
    pub fn new(bodies: &[(&Mesh, Arc<dyn Hyperelastic>)]) -> Result<Self, Vec<BadElement>> {
        Self::with_formulations(bodies, &[])
    }

    /// As [`Discretisation::new`], with the element formulation of each body's hexahedra
    /// (bodies beyond the end of `formulations` use the standard element).
    pub fn with_formulations(
        bodies: &[(&Mesh, Arc<dyn Hyperelastic>)],
        formulations: &[Formulation],
    ) -> Result<Self, Vec<BadElement>> {
        let mut node_offset = Vec::new();
        let mut reference = Vec::new();
        let mut hexes = ElementBlock::<8, 8>::empty();
        let mut tets = ElementBlock::<4, 1>::empty();
        let mut bad = Vec::new();
        for (bi, (mesh, _)) in bodies.iter().enumerate() {
            let off = reference.len();
            node_offset.push(off);
            reference.extend_from_slice(&mesh.nodes);
            let formulation = formulations.get(bi).copied().unwrap_or_default();
            let fbar = matches!(
                formulation,
                Formulation::FBar | Formulation::AveragedNodalPressure
            );
            let anp = formulation == Formulation::AveragedNodalPressure
                && has_volumetric_split(&*bodies[bi].1);
            for (ci, h) in mesh.hexes.iter().enumerate() {
                let x = h.map(|n| mesh.nodes[n]);
                match hex8_geometry(&x) {
                    Ok(g) => {
                        hexes.nodes.push(h.map(|n| n + off));
                        hexes.gauss.push(g);
                        hexes.body.push(bi);
                        hexes.fbar.push(fbar);
                        hexes.history.push(history_for(&*bodies[bi].1, 8));
                    }
                    Err(DegenerateElement { det }) => bad.push(BadElement {
                        body: bi,
                        cell: ci,
                        det,
                    }),
                }
            }
            for (ci, t) in mesh.tets.iter().enumerate() {
                let x = t.map(|n| mesh.nodes[n]);
                match tet4_geometry(&x) {
                    Ok(g) => {
                        tets.nodes.push(t.map(|n| n + off));
                        tets.gauss.push(g);
                        tets.body.push(bi);
                        tets.fbar.push(anp);
                        tets.history.push(history_for(&*bodies[bi].1, 1));
                    }
                    Err(DegenerateElement { det }) => bad.push(BadElement {
                        body: bi,
                        cell: mesh.hexes.len() + ci,
                        det,
                    }),
                }
            }
        }
        if !bad.is_empty() {
            return Err(bad);
        }
        let num_nodes = reference.len();
        let mut patches = tets.fbar.iter().any(|&a| a).then(|| {
            let volume: Vec<f64> = tets.gauss.iter().map(|g| g[0].weight).collect();
            let kappa: Vec<f64> = tets
                .body
                .iter()
                .map(|&b| bodies[b].1.bulk_modulus())
                .collect();
            NodalPatches::new(&tets.nodes, &volume, &kappa, tets.fbar.clone(), num_nodes)
        });
        let pattern = BlockPattern::from_cells(
            num_nodes,
            hexes
                .nodes
                .iter()
                .map(|c| &c[..])
                .chain(tets.nodes.iter().map(|c| &c[..]))
                .chain(patches.iter().flat_map(|p| p.cells())),
        );
        fill_ranks(&mut hexes, &pattern);
        fill_ranks(&mut tets, &pattern);
        if let Some(p) = patches.as_mut() {
            p.fill_ranks(&pattern);
        }
        let materials = bodies.iter().map(|(_, m)| m.clone()).collect();
        Ok(Discretisation {
            node_offset,
            num_nodes,
            reference,
            materials,
            hexes,
            tets,
            patches,
            pattern,
            step_dt: 0.0,
        })
    }

    /// Sets the size Δt [s] of the step about to be solved (viscoelastic materials).
    pub fn begin_step(&mut self, dt: f64) {
        self.step_dt = dt;
    }

    /// Advances the internal variables of the viscoelastic elements to the converged
    /// displacement `u` at the end of a step of the size last given to
    /// [`Discretisation::begin_step`].
    pub fn commit_step(&mut self, u: &[f64]) {
        let dt = self.step_dt;
        commit_block(&mut self.hexes, &self.materials, u, dt);
        commit_block(&mut self.tets, &self.materials, u, dt);
    }

    /// All internal variables, elements in order (for checkpoints).
    pub fn history(&self) -> Vec<f64> {
        self.hexes
            .history
            .iter()
            .chain(&self.tets.history)
            .flatten()
            .copied()
            .collect()
    }

    /// Restores internal variables saved by [`Discretisation::history`]. Fails, changing
    /// nothing, when the length does not fit.
    pub fn set_history(&mut self, values: &[f64]) -> Result<(), String> {
        let n: usize = self
            .hexes
            .history
            .iter()
            .chain(&self.tets.history)
            .map(Vec::len)
            .sum();
        if values.len() != n {
            return Err(format!(
                "material history has {} values but the problem has {n}",
                values.len()
            ));
        }
        let mut k = 0;
        for h in self.hexes.history.iter_mut().chain(&mut self.tets.history) {
            let len = h.len();
            h.copy_from_slice(&values[k..k + len]);
            k += len;
        }
        Ok(())
    }

    /// Number of scalar unknowns (3 per node).
    pub fn num_dofs(&self) -> usize {
        3 * self.num_nodes
    }

    /// Internal force, and the tangent when `with_tangent`, at global displacement `u`.
    pub fn assemble(&self, u: &[f64], with_tangent: bool) -> Assembled {
        let mut out = Assembled {
            force: vec![0.0; self.num_dofs()],
            tangent: if with_tangent {
                vec![0.0; self.pattern.nnz()]
            } else {
                Vec::new()
            },
            energy: 0.0,
            min_j: f64::INFINITY,
        };
        let (e1, j1) = self.assemble_block(&self.hexes, u, &mut out, with_tangent, None);
        let (e2, j2) = match &self.patches {
            None => self.assemble_block(&self.tets, u, &mut out, with_tangent, None),
            Some(patches) => {
                let state = patches.state(&self.tets.nodes, &self.tets.gauss, u);
                // The volumetric part of each element: p̄_e ∂v_e/∂u and p̄_e ∂²v_e/∂u².
                let add_pressure = |e: usize, r: &mut ElementResponse<4>| {
                    let Some((v, dv)) = &state.volume[e] else {
                        return;
                    };
                    let p = state.element_pressure[e];
                    for (fa, dva) in r.force.iter_mut().zip(dv) {
                        for (f, d) in fa.iter_mut().zip(dva.iter()) {
                            *f += p * d;
                        }
                    }
                    if let Some(k) = r.tangent.as_mut() {
                        add_volume_hessian(k, dv, *v, p);
                    }
                };
                let (e, j) =
                    self.assemble_block(&self.tets, u, &mut out, with_tangent, Some(&add_pressure));
                if with_tangent {
                    patches.add_patch_tangent(&state, &self.pattern, &mut out.tangent);
                }
                (e + state.energy, j)
            }
        };
        out.energy = e1 + e2;
        out.min_j = j1.min(j2);
        out
    }

    fn assemble_block<const N: usize, const G: usize>(
        &self,
        block: &ElementBlock<N, G>,
        u: &[f64],
        out: &mut Assembled,
        with_tangent: bool,
        volumetric: Option<&VolumetricPart<'_, N>>,
    ) -> (f64, f64) {
        let fptr = SyncPtr(out.force.as_mut_ptr());
        let kptr = SyncPtr(out.tangent.as_mut_ptr());
        let pattern = &self.pattern;
        let mut energy = 0.0;
        let mut min_j = f64::INFINITY;
        for colour in &block.colours {
            let (e, j) = colour
                .par_iter()
                .with_min_len(64)
                .map(|&e| {
                    let en = &block.nodes[e];
                    let ue: [[f64; 3]; N] = std::array::from_fn(|a| {
                        let n = en[a];
                        [u[3 * n], u[3 * n + 1], u[3 * n + 2]]
                    });
                    let mat = &*self.materials[block.body[e]];
                    let hist = (!block.history[e].is_empty())
                        .then(|| (&block.history[e][..], self.step_dt));
                    let r = if let (true, Some(add)) = (block.fbar[e], volumetric) {
                        let iso = IsochoricPart(mat);
                        let mut r = element_response_with_history(
                            &block.gauss[e],
                            &ue,
                            &iso,
                            with_tangent,
                            hist,
                        );
                        add(e, &mut r);
                        r
                    } else if block.fbar[e] {
                        fbar_element_response_with_history(
                            &block.gauss[e],
                            &ue,
                            mat,
                            with_tangent,
                            hist,
                        )
                    } else {
                        element_response_with_history(&block.gauss[e], &ue, mat, with_tangent, hist)
                    };
                    // SAFETY: elements of one colour share no node, so they write disjoint
                    // entries of the force vector and of the tangent values.
                    unsafe {
                        for a in 0..N {
                            for i in 0..3 {
                                fptr.add(3 * en[a] + i, r.force[a][i]);
                            }
                        }
                        if let Some(kt) = &r.tangent {
                            let ranks = &block.ranks[e];
                            for a in 0..N {
                                for b in 0..N {
                                    let (na, nb) = (en[a], en[b]);
                                    if na > nb {
                                        continue;
                                    }
                                    let kab = &kt[a][b];
                                    let rank = ranks[a][b] as usize;
                                    for k in 0..3 {
                                        let base = pattern.col_ptr[3 * nb + k] + 3 * rank;
                                        let imax = if na == nb { k + 1 } else { 3 };
                                        for i in 0..imax {
                                            kptr.add(base + i, kab[(i, k)]);
                                        }
                                    }
                                }
                            }
                        }
                    }
                    (r.energy, r.min_j)
                })
                .reduce(|| (0.0, f64::INFINITY), |a, b| (a.0 + b.0, a.1.min(b.1)));
            energy += e;
            min_j = min_j.min(j);
        }
        (energy, min_j)
    }

    /// The volumetric state of the averaged-nodal-pressure tetrahedra at `u` (`None`: there
    /// are none).
    pub fn patch_state(&self, u: &[f64]) -> Option<PatchState> {
        self.patches
            .as_ref()
            .map(|p| p.state(&self.tets.nodes, &self.tets.gauss, u))
    }

    /// Cauchy stress [Pa] and volume ratio of tetrahedron `e` at `u`. For an
    /// averaged-nodal-pressure tetrahedron (`state` from [`Discretisation::patch_state`]) the
    /// isochoric stress of its F plus its pressure p̄_e, and the mean J̄_e of its nodes' volume
    /// ratios; for the others the element's own stress and J.
    pub fn tet_cauchy_stress(
        &self,
        e: usize,
        u: &[f64],
        state: Option<&PatchState>,
    ) -> (crate::Mat3, f64) {
        let en = &self.tets.nodes[e];
        let ue = en.map(|n| [u[3 * n], u[3 * n + 1], u[3 * n + 2]]);
        let mat = &*self.materials[self.tets.body[e]];
        match (state, &self.patches) {
            (Some(st), Some(p)) if p.active[e] => {
                let (iso, _) = crate::element::element_cauchy_stress(
                    &self.tets.gauss[e],
                    &ue,
                    &IsochoricPart(mat),
                );
                let j = en
                    .iter()
                    .map(|&n| st.nodal_ratio[p.patch_of[n] as usize])
                    .sum::<f64>()
                    / 4.0;
                (iso + crate::Mat3::identity() * st.element_pressure[e], j)
            }
            _ => crate::element::element_cauchy_stress(&self.tets.gauss[e], &ue, mat),
        }
    }

    /// Mass matrix values in pattern order [kg], consistent or row-sum lumped, from the
    /// density [kg/m³] of each body.
    pub fn mass(&self, density: &[f64], lumped: bool) -> Vec<f64> {
        let mut m = vec![0.0; self.pattern.nnz()];
        self.mass_block(&self.hexes, density, lumped, &mut m);
        self.mass_block(&self.tets, density, lumped, &mut m);
        m
    }

    fn mass_block<const N: usize, const G: usize>(
        &self,
        block: &ElementBlock<N, G>,
        density: &[f64],
        lumped: bool,
        m: &mut [f64],
    ) {
        for e in 0..block.len() {
            let me = consistent_mass(&block.gauss[e], density[block.body[e]]);
            let en = &block.nodes[e];
            for a in 0..N {
                for b in 0..N {
                    let (na, nb) = (en[a], en[b]);
                    if lumped {
                        if a == b {
                            continue;
                        }
                        let r = block.ranks[e][a][a] as usize;
                        for k in 0..3 {
                            m[self.pattern.position(r, na, k, k)] += me[a][b];
                        }
                        continue;
                    }
                    if na > nb {
                        continue;
                    }
                    let r = block.ranks[e][a][b] as usize;
                    for k in 0..3 {
                        m[self.pattern.position(r, nb, k, k)] += me[a][b];
                    }
                }
                if lumped {
                    let r = block.ranks[e][a][a] as usize;
                    for k in 0..3 {
                        m[self.pattern.position(r, en[a], k, k)] += me[a][a];
                    }
                }
            }
        }
    }

    /// Reference volume of all elements [m³].
    pub fn volume(&self) -> f64 {
        let v1: f64 = self
            .hexes
            .gauss
            .iter()
            .flat_map(|g| g.iter().map(|p| p.weight))
            .sum();
        let v2: f64 = self
            .tets
            .gauss
            .iter()
            .flat_map(|g| g.iter().map(|p| p.weight))
            .sum();
        v1 + v2
    }
}
