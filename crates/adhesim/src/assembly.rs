//! Global assembly over all bodies: one node numbering (bodies one after another), the
//! sparsity pattern built once, element colouring so that the scatter runs in parallel
//! without locks, and the constant mass matrix.
//!
//! The elements are kept in one [`ElementBlock`] per element type (all bodies together, in
//! the order of [`crate::element::ELEMENT_TYPES`]). A block is generic over its
//! [`Element`] type, so its loops over elements and Gauss points are compiled for that type;
//! the discretisation holds the blocks as [`Block`] trait objects and dispatches once per
//! block. The averaged-nodal-pressure formulation is assembled on the tet4 block, whose
//! nodal patches couple its elements ([`crate::anp`]).

use crate::anp::{
    add_volume_hessian, has_volumetric_split, IsochoricPart, NodalPatches, PatchState,
};
use crate::dilatation::{
    linear_dilatation_c, linear_dilatation_cauchy_stress, linear_dilatation_response,
    LinearDilatation,
};
use crate::element::{
    diagonal_scaling_lumped, element_cauchy_stress, element_response_with_history, gauss_point_c,
    visit_element_types, DegenerateElement, Element, ElementResponse, ElementType,
    ElementTypeVisitor, GaussPoint, Lumping, Stabilisation, Tet4,
};
use crate::fbar::{
    fbar_cauchy_stress, fbar_element_response_with_history, fbar_gauss_point_c, Formulation,
};
use crate::linalg::BlockPattern;
use crate::material::Hyperelastic;
use crate::mesh::Mesh;
use crate::Mat3;
use rayon::prelude::*;
use std::any::Any;
use std::marker::PhantomData;
use std::sync::Arc;

/// Elements of one type `E` (N nodes, G Gauss points) with their reference data.
pub struct ElementBlock<E, const N: usize, const G: usize> {
    /// Global node indices.
    pub nodes: Vec<[usize; N]>,
    /// Reference Gauss-point data.
    pub gauss: Vec<[GaussPoint<N>; G]>,
    /// Index of the owning body.
    pub body: Vec<usize>,
    /// True for the elements with the type's volumetric treatment switched on
    /// ([`Element::STABILISATION`]: F-bar hexahedra, averaged-nodal-pressure tetrahedra),
    /// false for the standard fully integrated elements.
    pub fbar: Vec<bool>,
    /// The linear volume-change space of each element when the type's treatment is
    /// [`Stabilisation::LinearDilatation`] (empty for the other types).
    pub dilatation: Vec<LinearDilatation<G>>,
    /// Committed internal variables of viscoelastic elements, all Gauss points one after the
    /// other (empty for elastic elements).
    pub history: Vec<Vec<f64>>,
    /// For local pair (a, b): rank of min(node a, node b) among the upper neighbours of
    /// max(node a, node b) in the pattern.
    ranks: Vec<[[u32; N]; N]>,
    /// Element indices grouped so that no two elements of a group share a node.
    colours: Vec<Vec<usize>>,
    element: PhantomData<fn() -> E>,
}

/// The empty blocks of the element types, one per type in the order of
/// [`crate::element::ELEMENT_TYPES`].
struct EmptyBlocks(Vec<Box<dyn Block>>);

impl ElementTypeVisitor for EmptyBlocks {
    fn visit<E: Element<N, G>, const N: usize, const G: usize>(&mut self) {
        self.0.push(Box::new(ElementBlock::<E, N, G>::empty()));
    }
}

/// An empty block of each element type, in the order of [`crate::element::ELEMENT_TYPES`].
fn empty_blocks() -> Vec<Box<dyn Block>> {
    let mut blocks = EmptyBlocks(Vec::new());
    visit_element_types(&mut blocks);
    blocks.0
}

impl<E: Element<N, G>, const N: usize, const G: usize> ElementBlock<E, N, G> {
    fn empty() -> Self {
        ElementBlock {
            nodes: vec![],
            gauss: vec![],
            body: vec![],
            fbar: vec![],
            dilatation: vec![],
            history: vec![],
            ranks: vec![],
            colours: vec![],
            element: PhantomData,
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

impl<E, const N: usize, const G: usize> ElementBlock<E, N, G> {
    /// The linear volume-change space of element `e` when it uses it.
    fn linear_dilatation(&self, e: usize) -> Option<&LinearDilatation<G>> {
        self.dilatation.get(e).filter(|_| self.fbar[e])
    }
}

/// An element whose reference geometry is degenerate or inverted.
#[derive(Debug, Clone)]
pub struct BadElement {
    /// Body index.
    pub body: usize,
    /// Cell index within the body's mesh (mesh order: block after block).
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
    /// The elements, one block per element type in the order of
    /// [`crate::element::ELEMENT_TYPES`] (possibly empty).
    pub blocks: Vec<Box<dyn Block>>,
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

/// An element block seen without its element type: what the discretisation does with each
/// block. Each call runs over all elements of the block in code compiled for its type.
pub trait Block: Send + Sync + Any {
    /// The element type of the block's elements.
    fn element_type(&self) -> &'static ElementType;
    /// Number of elements.
    fn len(&self) -> usize;
    /// True when the block holds no element.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Index of the body owning element `e`.
    fn body(&self, e: usize) -> usize;
    /// Global node indices of element `e`.
    fn element_nodes(&self, e: usize) -> &[usize];
    /// True when element `e` uses the type's volumetric treatment.
    fn stabilised(&self, e: usize) -> bool;
    /// Adds an element of body `body` with global nodes `nodes`, reference coordinates `x`
    /// [m], the body's formulation and material. Fails, adding nothing, when the reference
    /// element is degenerate or inverted.
    fn push(
        &mut self,
        nodes: &[usize],
        x: &[[f64; 3]],
        body: usize,
        formulation: Formulation,
        material: &dyn Hyperelastic,
    ) -> Result<(), DegenerateElement>;
    /// Pattern ranks of the element node pairs and the colouring of the elements.
    fn fill_ranks(&mut self, pattern: &BlockPattern);
    /// Adds the internal force, and the tangent when `with_tangent`, of the block's elements
    /// at displacement `u` to `out`; returns their strain energy [J] and smallest det F.
    fn assemble(
        &self,
        disc: &Discretisation,
        u: &[f64],
        out: &mut Assembled,
        with_tangent: bool,
    ) -> (f64, f64);
    /// Advances the internal variables of the viscoelastic elements to the converged
    /// displacement `u` at the end of a step of size `dt` [s].
    fn commit(&mut self, materials: &[Arc<dyn Hyperelastic>], u: &[f64], dt: f64);
    /// Committed internal variables of each element.
    fn history(&self) -> &[Vec<f64>];
    /// Committed internal variables of each element, mutable.
    fn history_mut(&mut self) -> &mut [Vec<f64>];
    /// Adds the mass matrix values [kg] of the block's elements (density [kg/m³] of each
    /// body, consistent or row-sum lumped) to `m` (pattern order).
    fn add_mass(&self, pattern: &BlockPattern, density: &[f64], lumped: bool, m: &mut [f64]);
    /// Reference volume of the block's elements [m³].
    fn volume(&self) -> f64;
    /// Cauchy stress [Pa] averaged over element `e` and its mean volume ratio at `u`, with
    /// the element's own kinematics (standard or F-bar).
    fn cauchy_stress(&self, e: usize, u: &[f64], material: &dyn Hyperelastic) -> (Mat3, f64);
    /// The block as [`Any`], to reach a block of a known type.
    fn as_any(&self) -> &dyn Any;
}

impl<E: Element<N, G>, const N: usize, const G: usize> Block for ElementBlock<E, N, G> {
    fn element_type(&self) -> &'static ElementType {
        E::TYPE
    }

    fn len(&self) -> usize {
        self.nodes.len()
    }

    fn body(&self, e: usize) -> usize {
        self.body[e]
    }

    fn element_nodes(&self, e: usize) -> &[usize] {
        &self.nodes[e]
    }

    fn stabilised(&self, e: usize) -> bool {
        self.fbar[e]
    }

    fn push(
        &mut self,
        nodes: &[usize],
        x: &[[f64; 3]],
        body: usize,
        formulation: Formulation,
        material: &dyn Hyperelastic,
    ) -> Result<(), DegenerateElement> {
        let nodes: [usize; N] = nodes.try_into().expect("node count of the element type");
        let x: &[[f64; 3]; N] = x.try_into().expect("node count of the element type");
        let gauss = E::geometry(x)?;
        let stabilised = match E::STABILISATION {
            Stabilisation::None => false,
            Stabilisation::FBar | Stabilisation::LinearDilatation => matches!(
                formulation,
                Formulation::FBar | Formulation::AveragedNodalPressure
            ),
            Stabilisation::NodalPressure => {
                formulation == Formulation::AveragedNodalPressure && has_volumetric_split(material)
            }
        };
        if E::STABILISATION == Stabilisation::LinearDilatation {
            // The Gauss points of a valid element span its volume; the det reported otherwise
            // is the element's smallest Gauss weight.
            let lin = LinearDilatation::new(&gauss, x).ok_or(DegenerateElement {
                det: gauss.iter().map(|g| g.weight).fold(f64::INFINITY, f64::min),
            })?;
            self.dilatation.push(lin);
        }
        self.nodes.push(nodes);
        self.gauss.push(gauss);
        self.body.push(body);
        self.fbar.push(stabilised);
        self.history.push(history_for(material, G));
        Ok(())
    }

    fn fill_ranks(&mut self, pattern: &BlockPattern) {
        fill_ranks(self, pattern);
    }

    fn assemble(
        &self,
        disc: &Discretisation,
        u: &[f64],
        out: &mut Assembled,
        with_tangent: bool,
    ) -> (f64, f64) {
        disc.assemble_block(self, u, out, with_tangent, None)
    }

    fn commit(&mut self, materials: &[Arc<dyn Hyperelastic>], u: &[f64], dt: f64) {
        commit_block(self, materials, u, dt);
    }

    fn history(&self) -> &[Vec<f64>] {
        &self.history
    }

    fn history_mut(&mut self) -> &mut [Vec<f64>] {
        &mut self.history
    }

    fn add_mass(&self, pattern: &BlockPattern, density: &[f64], lumped: bool, m: &mut [f64]) {
        mass_block(self, pattern, density, lumped, m);
    }

    fn volume(&self) -> f64 {
        self.gauss
            .iter()
            .flat_map(|g| g.iter().map(|p| p.weight))
            .sum()
    }

    fn cauchy_stress(&self, e: usize, u: &[f64], material: &dyn Hyperelastic) -> (Mat3, f64) {
        let ue = self.nodes[e].map(|n| [u[3 * n], u[3 * n + 1], u[3 * n + 2]]);
        if let Some(lin) = self.linear_dilatation(e) {
            linear_dilatation_cauchy_stress(&self.gauss[e], lin, &ue, material)
        } else if self.fbar[e] {
            fbar_cauchy_stress(&self.gauss[e], &ue, material)
        } else {
            element_cauchy_stress(&self.gauss[e], &ue, material)
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

fn fill_ranks<E, const N: usize, const G: usize>(
    block: &mut ElementBlock<E, N, G>,
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

fn commit_block<E, const N: usize, const G: usize>(
    block: &mut ElementBlock<E, N, G>,
    materials: &[Arc<dyn Hyperelastic>],
    u: &[f64],
    dt: f64,
) {
    let (nodes, gauss, body, fbar) = (&block.nodes, &block.gauss, &block.body, &block.fbar);
    let block_linear = |e: usize| block.dilatation.get(e).filter(|_| fbar[e]);
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
            let cs = if let Some(lin) = block_linear(e) {
                linear_dilatation_c(&gauss[e], lin, &ue)
            } else if fbar[e] {
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

fn mass_block<E: Element<N, G>, const N: usize, const G: usize>(
    block: &ElementBlock<E, N, G>,
    pattern: &BlockPattern,
    density: &[f64],
    lumped: bool,
    m: &mut [f64],
) {
    for e in 0..block.len() {
        let me = E::mass(&block.gauss[e], density[block.body[e]]);
        let en = &block.nodes[e];
        if lumped && E::LUMPING == Lumping::DiagonalScaling {
            for (a, ma) in diagonal_scaling_lumped(&me).into_iter().enumerate() {
                let r = block.ranks[e][a][a] as usize;
                for k in 0..3 {
                    m[pattern.position(r, en[a], k, k)] += ma;
                }
            }
            continue;
        }
        for a in 0..N {
            for b in 0..N {
                let (na, nb) = (en[a], en[b]);
                if lumped {
                    if a == b {
                        continue;
                    }
                    let r = block.ranks[e][a][a] as usize;
                    for k in 0..3 {
                        m[pattern.position(r, na, k, k)] += me[a][b];
                    }
                    continue;
                }
                if na > nb {
                    continue;
                }
                let r = block.ranks[e][a][b] as usize;
                for k in 0..3 {
                    m[pattern.position(r, nb, k, k)] += me[a][b];
                }
            }
            if lumped {
                let r = block.ranks[e][a][a] as usize;
                for k in 0..3 {
                    m[pattern.position(r, en[a], k, k)] += me[a][a];
                }
            }
        }
    }
}

/// The tet4 block, on which the averaged-nodal-pressure formulation works.
type Tet4Block = ElementBlock<Tet4, 4, 1>;

impl Discretisation {
    /// Builds the discretisation of the given bodies (mesh, material). Fails with the list
    /// of degenerate or inverted reference elements.
    pub fn new(bodies: &[(&Mesh, Arc<dyn Hyperelastic>)]) -> Result<Self, Vec<BadElement>> {
        Self::with_formulations(bodies, &[])
    }

    /// As [`Discretisation::new`], with the element formulation of each body
    /// (bodies beyond the end of `formulations` use the standard element).
    pub fn with_formulations(
        bodies: &[(&Mesh, Arc<dyn Hyperelastic>)],
        formulations: &[Formulation],
    ) -> Result<Self, Vec<BadElement>> {
        let mut node_offset = Vec::new();
        let mut reference = Vec::new();
        let mut blocks = empty_blocks();
        let mut bad = Vec::new();
        for (bi, (mesh, material)) in bodies.iter().enumerate() {
            let off = reference.len();
            node_offset.push(off);
            reference.extend_from_slice(&mesh.nodes);
            let formulation = formulations.get(bi).copied().unwrap_or_default();
            let mut ci = 0;
            for cells in &mesh.blocks {
                let block = &mut blocks[cells.element.index()];
                let mut global = Vec::with_capacity(cells.element.nodes);
                let mut x = Vec::with_capacity(cells.element.nodes);
                for cell in cells.cells() {
                    global.clear();
                    global.extend(cell.iter().map(|&n| n + off));
                    x.clear();
                    x.extend(cell.iter().map(|&n| mesh.nodes[n]));
                    if let Err(DegenerateElement { det }) =
                        block.push(&global, &x, bi, formulation, &**material)
                    {
                        bad.push(BadElement {
                            body: bi,
                            cell: ci,
                            det,
                        });
                    }
                    ci += 1;
                }
            }
        }
        if !bad.is_empty() {
            return Err(bad);
        }
        let num_nodes = reference.len();
        let tets = blocks
            .iter()
            .find_map(|b| b.as_any().downcast_ref::<Tet4Block>());
        let mut patches = tets.filter(|t| t.fbar.iter().any(|&a| a)).map(|tets| {
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
            blocks
                .iter()
                .flat_map(|b| (0..b.len()).map(|e| b.element_nodes(e)))
                .chain(patches.iter().flat_map(|p| p.cells())),
        );
        for b in &mut blocks {
            b.fill_ranks(&pattern);
        }
        if let Some(p) = patches.as_mut() {
            p.fill_ranks(&pattern);
        }
        let materials = bodies.iter().map(|(_, m)| m.clone()).collect();
        Ok(Discretisation {
            node_offset,
            num_nodes,
            reference,
            materials,
            blocks,
            patches,
            pattern,
            step_dt: 0.0,
        })
    }

    /// The block of element type `E` (every type of the table has one, possibly empty).
    pub fn block<E: Element<N, G>, const N: usize, const G: usize>(
        &self,
    ) -> &ElementBlock<E, N, G> {
        self.blocks
            .iter()
            .find_map(|b| b.as_any().downcast_ref())
            .expect("every element type has a block")
    }

    /// The hex8 block.
    pub fn hexes(&self) -> &ElementBlock<crate::element::Hex8, 8, 8> {
        self.block()
    }

    /// The tet4 block.
    pub fn tets(&self) -> &Tet4Block {
        self.block()
    }

    /// Number of elements of all blocks.
    pub fn num_cells(&self) -> usize {
        self.blocks.iter().map(|b| b.len()).sum()
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
        for b in &mut self.blocks {
            b.commit(&self.materials, u, dt);
        }
    }

    /// All internal variables, elements in order (for checkpoints).
    pub fn history(&self) -> Vec<f64> {
        self.blocks
            .iter()
            .flat_map(|b| b.history())
            .flatten()
            .copied()
            .collect()
    }

    /// Restores internal variables saved by [`Discretisation::history`]. Fails, changing
    /// nothing, when the length does not fit.
    pub fn set_history(&mut self, values: &[f64]) -> Result<(), String> {
        let n: usize = self
            .blocks
            .iter()
            .flat_map(|b| b.history())
            .map(Vec::len)
            .sum();
        if values.len() != n {
            return Err(format!(
                "material history has {} values but the problem has {n}",
                values.len()
            ));
        }
        let mut k = 0;
        for h in self.blocks.iter_mut().flat_map(|b| b.history_mut()) {
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
        self.assemble_reusing(u, with_tangent, Vec::new())
    }

    /// As [`Self::assemble`], writing the tangent into `tangent_buffer` (any length; it is
    /// resized and zeroed). A Newton loop hands back the previous iteration's tangent so
    /// that the largest array of an assembly is not allocated afresh each time: a new one
    /// is mapped zero pages, each page's first write a fault (at 10⁴ contact nodes of the
    /// scale pad a quarter of the run's time went to them).
    pub fn assemble_reusing(
        &self,
        u: &[f64],
        with_tangent: bool,
        mut tangent_buffer: Vec<f64>,
    ) -> Assembled {
        tangent_buffer.clear();
        if with_tangent {
            tangent_buffer.resize(self.pattern.nnz(), 0.0);
        }
        let mut out = Assembled {
            force: vec![0.0; self.num_dofs()],
            tangent: tangent_buffer,
            energy: 0.0,
            min_j: f64::INFINITY,
        };
        for block in &self.blocks {
            let nodal_pressure = self
                .patches
                .as_ref()
                .zip(block.as_any().downcast_ref::<Tet4Block>());
            let (e, j) = match nodal_pressure {
                Some((patches, tets)) => {
                    self.assemble_nodal_pressure(tets, patches, u, &mut out, with_tangent)
                }
                None => block.assemble(self, u, &mut out, with_tangent),
            };
            out.energy += e;
            out.min_j = out.min_j.min(j);
        }
        out
    }

    /// The tet4 block with its averaged-nodal-pressure elements: their isochoric response
    /// plus the volumetric part of their nodal patches.
    fn assemble_nodal_pressure(
        &self,
        tets: &Tet4Block,
        patches: &NodalPatches,
        u: &[f64],
        out: &mut Assembled,
        with_tangent: bool,
    ) -> (f64, f64) {
        let state = patches.state(&tets.nodes, &tets.gauss, u);
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
        let (e, j) = self.assemble_block(tets, u, out, with_tangent, Some(&add_pressure));
        if with_tangent {
            patches.add_patch_tangent(&state, &self.pattern, &mut out.tangent);
        }
        (e + state.energy, j)
    }

    fn assemble_block<E, const N: usize, const G: usize>(
        &self,
        block: &ElementBlock<E, N, G>,
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
                    } else if let Some(lin) = block.linear_dilatation(e) {
                        linear_dilatation_response(
                            &block.gauss[e],
                            lin,
                            &ue,
                            mat,
                            with_tangent,
                            hist,
                        )
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
        self.patches.as_ref().map(|p| {
            let tets = self.tets();
            p.state(&tets.nodes, &tets.gauss, u)
        })
    }

    /// Cauchy stress [Pa] and volume ratio of element `e` of block `block` at `u`: for the
    /// averaged-nodal-pressure tetrahedra as [`Discretisation::tet_cauchy_stress`], for the
    /// others with the element's own kinematics.
    pub fn cell_cauchy_stress(
        &self,
        block: usize,
        e: usize,
        u: &[f64],
        state: Option<&PatchState>,
    ) -> (Mat3, f64) {
        let b = &self.blocks[block];
        if b.as_any().is::<Tet4Block>() {
            return self.tet_cauchy_stress(e, u, state);
        }
        b.cauchy_stress(e, u, &*self.materials[b.body(e)])
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
    ) -> (Mat3, f64) {
        let tets = self.tets();
        let en = &tets.nodes[e];
        let ue = en.map(|n| [u[3 * n], u[3 * n + 1], u[3 * n + 2]]);
        let mat = &*self.materials[tets.body[e]];
        match (state, &self.patches) {
            (Some(st), Some(p)) if p.active[e] => {
                let (iso, _) = element_cauchy_stress(&tets.gauss[e], &ue, &IsochoricPart(mat));
                let j = en
                    .iter()
                    .map(|&n| st.nodal_ratio[p.patch_of[n] as usize])
                    .sum::<f64>()
                    / 4.0;
                (iso + Mat3::identity() * st.element_pressure[e], j)
            }
            _ => element_cauchy_stress(&tets.gauss[e], &ue, mat),
        }
    }

    /// Mass matrix values in pattern order [kg], consistent or lumped (each element type's
    /// [`Lumping`]: row sums on hex8 and tet4, the scaled diagonal on tet10 and hex20), from
    /// the density [kg/m³] of each body.
    pub fn mass(&self, density: &[f64], lumped: bool) -> Vec<f64> {
        let mut m = vec![0.0; self.pattern.nnz()];
        for b in &self.blocks {
            b.add_mass(&self.pattern, density, lumped, &mut m);
        }
        m
    }

    /// Reference volume of all elements [m³].
    pub fn volume(&self) -> f64 {
        self.blocks.iter().map(|b| b.volume()).sum()
    }
}
