//! Meshes: nodes, cell blocks, named node and face sets. No physics here.
//!
//! The cells are kept in blocks, one per element type of [`crate::element::ELEMENT_TYPES`]
//! in the table's order (hex8, tet4, tet10, hex20), each a flat connectivity list. A cell's index in
//! the mesh counts through the blocks in that order.
//!
//! Conventions
//! - Hex8 cells use the VTK node order: nodes 0-3 are the face ζ = −1 counter-clockwise seen
//!   from +ζ, nodes 4-7 the face ζ = +1 in the same order (natural coordinates of node 0..7:
//!   (−1,−1,−1), (1,−1,−1), (1,1,−1), (−1,1,−1), (−1,−1,1), (1,−1,1), (1,1,1), (−1,1,1)).
//!   A valid hex has positive Jacobian determinant at all its Gauss points.
//! - Tet4 cells use the VTK order; (x1−x0)·((x2−x0)×(x3−x0)) > 0.
//! - Tet10 and hex20 cells use the VTK orders: the corners as for tet4 and hex8, then the
//!   mid-edge nodes ([`crate::element::TET10_EDGES`], [`crate::element::HEX20_EDGES`]).
//! - Boundary faces are listed counter-clockwise seen from outside the body, so that the
//!   right-hand-rule normal points out of the body. A face is its face type (one of
//!   [`crate::element::face`], named by the element type it bounds) and its nodes.

use std::collections::BTreeMap;

use crate::element::face::MAX_FACE_NODES;
use crate::element::{
    ElementType, FaceType, LocalFace, HEX20, HEX20_EDGES, HEX27, HEX8, QUAD4, QUAD8, QUAD9, TET10,
    TET10_EDGES, TET4, TRI3, TRI6,
};

pub mod generate;
pub mod gmsh;
pub mod quality;

/// A boundary face of a cell: its face type (which comes from the cell's element type) and
/// its node indices in that type's order (corners counter-clockwise seen from outside, then
/// mid-side nodes).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Face {
    /// The face's type.
    face_type: &'static FaceType,
    /// Node indices; the first `face_type.nodes` are the face's, the rest 0.
    nodes: [usize; MAX_FACE_NODES],
}

/// `Quad([0, 1, 2, 3])`: the face type's `debug_name` and the nodes, the form the checkpoint
/// fingerprint of a problem hashes.
impl std::fmt::Debug for Face {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple(self.face_type.debug_name)
            .field(&self.nodes())
            .finish()
    }
}

impl Face {
    /// The face of type `face_type` with nodes `nodes` (as many as the type has).
    pub fn new(face_type: &'static FaceType, nodes: &[usize]) -> Face {
        assert_eq!(
            nodes.len(),
            face_type.nodes,
            "a {} face has {} nodes",
            face_type.name,
            face_type.nodes
        );
        let mut all = [0; MAX_FACE_NODES];
        all[..nodes.len()].copy_from_slice(nodes);
        Face {
            face_type,
            nodes: all,
        }
    }

    /// A bilinear quadrilateral (a hex8 face), nodes counter-clockwise seen from outside.
    pub fn quad(nodes: [usize; 4]) -> Face {
        Face::new(&QUAD4, &nodes)
    }

    /// A linear triangle (a tet4 face), nodes counter-clockwise seen from outside.
    pub fn tri(nodes: [usize; 3]) -> Face {
        Face::new(&TRI3, &nodes)
    }

    /// The face `local` of `cell` (global node indices).
    pub fn of_cell(cell: &[usize], local: &LocalFace) -> Face {
        let mut nodes = [0; MAX_FACE_NODES];
        for (n, &a) in nodes.iter_mut().zip(local.nodes) {
            *n = cell[a];
        }
        Face {
            face_type: local.face_type,
            nodes,
        }
    }

    /// The face's type.
    pub fn face_type(&self) -> &'static FaceType {
        self.face_type
    }

    /// The face's node indices.
    pub fn nodes(&self) -> &[usize] {
        &self.nodes[..self.face_type.nodes]
    }

    /// The same face with each node index `n` replaced by `map(n)`.
    pub fn map_nodes(&self, map: impl Fn(usize) -> usize) -> Face {
        let mut nodes = [0; MAX_FACE_NODES];
        for (n, &m) in nodes.iter_mut().zip(self.nodes()) {
            *n = map(m);
        }
        Face {
            face_type: self.face_type,
            nodes,
        }
    }

    /// The face's corner nodes, counter-clockwise seen from outside.
    pub fn corners(&self) -> &[usize] {
        &self.nodes[..self.face_type.corners]
    }

    /// The flat pieces the face is drawn and integrated on ([`FaceType::flat_pieces`]):
    /// itself when it is linear. Entries are positions in [`Face::nodes`].
    pub fn flat_pieces(&self) -> &'static [&'static [usize]] {
        self.face_type.flat_pieces
    }

    /// Whether the face is of second order (has mid-side nodes).
    pub fn is_quadratic(&self) -> bool {
        self.face_type.is_quadratic
    }
}

/// Cells of one element type: `element.nodes` node indices per cell, cell after cell.
#[derive(Clone, Debug, PartialEq)]
pub struct CellBlock {
    /// The element type of every cell of the block.
    pub element: &'static ElementType,
    /// Node indices (into the mesh's nodes), cell after cell.
    pub connectivity: Vec<usize>,
}

impl CellBlock {
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.connectivity.len() / self.element.nodes
    }

    /// True when the block holds no cell.
    pub fn is_empty(&self) -> bool {
        self.connectivity.is_empty()
    }

    /// The node indices of each cell.
    pub fn cells(&self) -> std::slice::ChunksExact<'_, usize> {
        self.connectivity.chunks_exact(self.element.nodes)
    }

    /// The node indices of cell `c` of the block.
    pub fn cell(&self, c: usize) -> &[usize] {
        let n = self.element.nodes;
        &self.connectivity[n * c..n * (c + 1)]
    }

    /// The cells as fixed-size arrays; `N` must be the type's node count.
    pub fn as_arrays<const N: usize>(&self) -> &[[usize; N]] {
        assert_eq!(
            N, self.element.nodes,
            "{} cells have {} nodes",
            self.element.name, self.element.nodes
        );
        self.connectivity.as_chunks::<N>().0
    }

    /// The cells as mutable fixed-size arrays; `N` must be the type's node count.
    pub fn as_arrays_mut<const N: usize>(&mut self) -> &mut [[usize; N]] {
        assert_eq!(
            N, self.element.nodes,
            "{} cells have {} nodes",
            self.element.name, self.element.nodes
        );
        self.connectivity.as_chunks_mut::<N>().0
    }
}

/// An unstructured mesh of one body.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Reference coordinates of the nodes [m].
    pub nodes: Vec<[f64; 3]>,
    /// The cells, one block per element type in the order of
    /// [`crate::element::ELEMENT_TYPES`] (no empty blocks); node indices into `nodes`.
    pub blocks: Vec<CellBlock>,
    /// Named node sets (sorted, no duplicates).
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named boundary face sets, outward oriented.
    pub face_sets: BTreeMap<String, Vec<Face>>,
}

impl Mesh {
    /// The block of `element` cells, if the mesh has any.
    pub fn block(&self, element: &ElementType) -> Option<&CellBlock> {
        self.blocks.iter().find(|b| b.element == element)
    }

    /// The connectivity of the `element` block, created (in table order) when missing, for
    /// adding cells: `element.nodes` indices per cell.
    pub fn connectivity_mut(&mut self, element: &'static ElementType) -> &mut Vec<usize> {
        let i = match self.blocks.iter().position(|b| b.element == element) {
            Some(i) => i,
            None => {
                let at = self
                    .blocks
                    .iter()
                    .position(|b| b.element.index() > element.index())
                    .unwrap_or(self.blocks.len());
                self.blocks.insert(
                    at,
                    CellBlock {
                        element,
                        connectivity: Vec::new(),
                    },
                );
                at
            }
        };
        &mut self.blocks[i].connectivity
    }

    /// Adds cells of type `element` (each `element.nodes` node indices).
    pub fn add_cells<const N: usize>(
        &mut self,
        element: &'static ElementType,
        cells: impl IntoIterator<Item = [usize; N]>,
    ) {
        assert_eq!(
            N, element.nodes,
            "{} cells have {} nodes",
            element.name, element.nodes
        );
        let mut cells = cells.into_iter().peekable();
        if cells.peek().is_some() {
            self.connectivity_mut(element).extend(cells.flatten());
        }
    }

    /// The cells of type `element` as fixed-size arrays (empty if there are none); `N` must
    /// be the type's node count.
    pub fn cells_of<const N: usize>(&self, element: &ElementType) -> &[[usize; N]] {
        self.block(element).map_or(&[], |b| b.as_arrays())
    }

    /// The hex8 cells.
    pub fn hexes(&self) -> &[[usize; 8]] {
        self.cells_of(&HEX8)
    }

    /// The tet4 cells.
    pub fn tets(&self) -> &[[usize; 4]] {
        self.cells_of(&TET4)
    }

    /// The hex8 cells, mutable.
    pub fn hexes_mut(&mut self) -> &mut [[usize; 8]] {
        match self.blocks.iter_mut().find(|b| *b.element == HEX8) {
            Some(b) => b.as_arrays_mut(),
            None => &mut [],
        }
    }

    /// Every cell in mesh order (block after block): its element type and node indices.
    pub fn cells(&self) -> impl Iterator<Item = (&'static ElementType, &[usize])> + '_ {
        self.blocks
            .iter()
            .flat_map(|b| b.cells().map(move |c| (b.element, c)))
    }

    /// Cell `c` in mesh order: its element type and node indices.
    pub fn cell(&self, mut c: usize) -> (&'static ElementType, &[usize]) {
        for b in &self.blocks {
            if c < b.len() {
                return (b.element, b.cell(c));
            }
            c -= b.len();
        }
        panic!("cell index beyond the mesh's {} cells", self.num_cells())
    }
}

impl Mesh {
    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of cells (all blocks).
    pub fn num_cells(&self) -> usize {
        self.blocks.iter().map(CellBlock::len).sum()
    }

    /// Adds (or replaces) a node set; the indices are sorted and de-duplicated.
    pub fn set_nodes(&mut self, name: &str, mut ids: Vec<usize>) {
        ids.sort_unstable();
        ids.dedup();
        self.node_sets.insert(name.to_string(), ids);
    }

    /// Adds (or replaces) a face set and the node set of the same name holding its nodes.
    pub fn set_faces(&mut self, name: &str, faces: Vec<Face>) {
        let ids: Vec<usize> = faces
            .iter()
            .flat_map(|f| f.nodes().iter().copied())
            .collect();
        self.set_nodes(name, ids);
        self.face_sets.insert(name.to_string(), faces);
    }

    /// Moves every node by `offset` [m].
    pub fn translate(&mut self, offset: [f64; 3]) {
        for p in &mut self.nodes {
            for k in 0..3 {
                p[k] += offset[k];
            }
        }
    }

    /// Every face of every cell, keyed by its sorted node indices, with the number of cells
    /// that have it (1 on the boundary, 2 inside) and its outward orientation seen from the
    /// first of them.
    pub fn cell_faces(&self) -> std::collections::HashMap<Vec<usize>, (usize, Face)> {
        let mut count: std::collections::HashMap<Vec<usize>, (usize, Face)> =
            std::collections::HashMap::new();
        let mut add = |f: Face| {
            let mut key = f.nodes().to_vec();
            key.sort_unstable();
            count.entry(key).and_modify(|e| e.0 += 1).or_insert((1, f));
        };
        for (element, cell) in self.cells() {
            for f in element.faces {
                add(Face::of_cell(cell, f));
            }
        }
        count
    }

    /// Node indices of every cell face that belongs to exactly one cell (the boundary),
    /// outward oriented.
    pub fn boundary_faces(&self) -> Vec<Face> {
        let count = self.cell_faces();
        let mut faces: Vec<Face> = count
            .into_values()
            .filter(|e| e.0 == 1)
            .map(|e| e.1)
            .collect();
        faces.sort_by(|a, b| a.nodes().cmp(b.nodes()));
        faces
    }
}

impl Mesh {
    /// The same body with second-order cells: a node at the middle of every edge (shared by
    /// the cells around it), each tet4 becoming a straight-sided tet10 and each hex8 a
    /// straight-sided hex20; face sets become six-node triangles and eight-node
    /// quadrilaterals, and node sets take the mid-side nodes of edges whose ends are both in
    /// the set. (For tet10 from a hexahedral mesh, split it first:
    /// [`Mesh::split_hexes_into_tets`].)
    ///
    /// # Panics
    /// The mesh already holds second-order cells.
    pub fn with_mid_side_nodes(&self) -> Mesh {
        let mut out = Mesh {
            nodes: self.nodes.clone(),
            ..Default::default()
        };
        let mut mid: std::collections::HashMap<(usize, usize), usize> =
            std::collections::HashMap::new();
        let mut mid_of = |a: usize, b: usize, nodes: &mut Vec<[f64; 3]>| -> usize {
            let k = (a.min(b), a.max(b));
            *mid.entry(k).or_insert_with(|| {
                let (p, q) = (nodes[a], nodes[b]);
                nodes.push(std::array::from_fn(|i| 0.5 * (p[i] + q[i])));
                nodes.len() - 1
            })
        };
        for block in &self.blocks {
            let (quadratic, edges) = second_order_of(block.element);
            let mut cells =
                Vec::with_capacity(block.connectivity.len() + block.len() * edges.len());
            for t in block.cells() {
                cells.extend_from_slice(t);
                for [i, j] in edges {
                    let m = mid_of(t[*i], t[*j], &mut out.nodes);
                    cells.push(m);
                }
            }
            out.connectivity_mut(quadratic).extend(cells);
        }
        for (name, ids) in &self.node_sets {
            let inside: std::collections::HashSet<usize> = ids.iter().copied().collect();
            let mut with_mids = ids.clone();
            with_mids.extend(
                mid.iter()
                    .filter(|((a, b), _)| inside.contains(a) && inside.contains(b))
                    .map(|(_, &m)| m),
            );
            out.set_nodes(name, with_mids);
        }
        for (name, faces) in &self.face_sets {
            let quadratic = faces
                .iter()
                .map(|f| {
                    let n = f.corners();
                    let m = |a: usize, b: usize| mid[&(n[a].min(n[b]), n[a].max(n[b]))];
                    let mut with_mids = n.to_vec();
                    with_mids.extend((0..n.len()).map(|k| m(k, (k + 1) % n.len())));
                    let face_type = if n.len() == 3 { &TRI6 } else { &QUAD8 };
                    Face::new(face_type, &with_mids)
                })
                .collect();
            out.face_sets.insert(name.clone(), quadratic);
        }
        out
    }
}

impl Mesh {
    /// The same body with each hex20 cell made a hex27: a node at the centre of every face
    /// (shared by the two cells on it) and one at the centre of each cell, placed where the
    /// hex20's own interpolation puts those points (on a straight-sided cell, the mean of the
    /// face's or the cell's corners), so the geometry does not change. Face sets of eight-node
    /// quadrilaterals become nine-node ones; node sets take the face centres of faces whose
    /// corners are all in the set. Other cells are kept.
    pub fn with_face_and_centre_nodes(&self) -> Mesh {
        let mut out = Mesh {
            nodes: self.nodes.clone(),
            ..Default::default()
        };
        // Face centres by the face's sorted corners; the quad8 interpolation at (0, 0):
        // −¼ Σ corners + ½ Σ mid-side nodes.
        let mut centre: std::collections::HashMap<Vec<usize>, usize> =
            std::collections::HashMap::new();
        let mut centre_of = |f: &[usize], nodes: &mut Vec<[f64; 3]>| -> usize {
            let mut key = f[..4].to_vec();
            key.sort_unstable();
            *centre.entry(key).or_insert_with(|| {
                let x: [f64; 3] = std::array::from_fn(|k| {
                    f[..4].iter().map(|&n| -0.25 * nodes[n][k]).sum::<f64>()
                        + f[4..8].iter().map(|&n| 0.5 * nodes[n][k]).sum::<f64>()
                });
                nodes.push(x);
                nodes.len() - 1
            })
        };
        for block in &self.blocks {
            if *block.element != HEX20 {
                out.connectivity_mut(block.element)
                    .extend_from_slice(&block.connectivity);
                continue;
            }
            let mut cells = Vec::with_capacity(block.len() * 27);
            for c in block.cells() {
                cells.extend_from_slice(c);
                // Face centres in the hex27's order: ξ = −1, +1, η = −1, +1, ζ = −1, +1.
                for face in [4, 5, 2, 3, 0, 1] {
                    let local = HEX27.faces[face].nodes;
                    let f: Vec<usize> = local[..8].iter().map(|&a| c[a]).collect();
                    let m = centre_of(&f, &mut out.nodes);
                    cells.push(m);
                }
                // The cell's centre: the hex20 interpolation at 0, −¼ Σ corners + ¼ Σ mids.
                let x: [f64; 3] = std::array::from_fn(|k| {
                    c[..8].iter().map(|&n| -0.25 * out.nodes[n][k]).sum::<f64>()
                        + c[8..20]
                            .iter()
                            .map(|&n| 0.25 * out.nodes[n][k])
                            .sum::<f64>()
                });
                out.nodes.push(x);
                cells.push(out.nodes.len() - 1);
            }
            out.connectivity_mut(&HEX27).extend(cells);
        }
        for (name, ids) in &self.node_sets {
            let inside: std::collections::HashSet<usize> = ids.iter().copied().collect();
            let mut with_centres = ids.clone();
            with_centres.extend(
                centre
                    .iter()
                    .filter(|(corners, _)| corners.iter().all(|c| inside.contains(c)))
                    .map(|(_, &m)| m),
            );
            out.set_nodes(name, with_centres);
        }
        for (name, faces) in &self.face_sets {
            let faces = faces
                .iter()
                .map(|f| {
                    if *f.face_type() != QUAD8 {
                        return *f;
                    }
                    let mut key = f.corners().to_vec();
                    key.sort_unstable();
                    let mut nodes = f.nodes().to_vec();
                    nodes.push(centre[&key]);
                    Face::new(&QUAD9, &nodes)
                })
                .collect();
            out.face_sets.insert(name.clone(), faces);
        }
        out
    }
}

/// The second-order type of the first-order `element` (tet10 of tet4, hex20 of hex8) and the
/// corner pairs of its mid-edge nodes, in its node order.
fn second_order_of(element: &ElementType) -> (&'static ElementType, &'static [[usize; 2]]) {
    if *element == TET4 {
        (&TET10, &TET10_EDGES)
    } else if *element == HEX8 {
        (&HEX20, &HEX20_EDGES)
    } else {
        panic!("{} cells have mid-side nodes already", element.name)
    }
}

/// Hex8 node (VTK order) at each corner of the unit cube, indexed by x + 2y + 4z.
const HEX_CORNER: [usize; 8] = [0, 1, 3, 2, 4, 5, 7, 6];

impl Mesh {
    /// The same body with each hexahedron split into six tetrahedra around its diagonal from
    /// node 0 to node 6 (one tetrahedron per ordering of the three natural axes). Each quad
    /// face is then cut along its diagonal from the corner of lowest to the corner of highest
    /// natural coordinates, so neighbouring hexahedra whose natural axes point the same way
    /// (the structured meshes of [`generate`]) stay conforming. Tetrahedra are kept, node and
    /// face sets carried over (each quad of a face set becomes its two triangles).
    pub fn split_hexes_into_tets(&self) -> Mesh {
        let mut out = Mesh {
            nodes: self.nodes.clone(),
            node_sets: self.node_sets.clone(),
            ..Default::default()
        };
        out.add_cells(&TET4, self.tets().iter().copied());
        let perms = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let mut split = Vec::new();
        for h in self.hexes() {
            for p in perms {
                let c1 = 1 << p[0];
                let c2 = c1 | (1 << p[1]);
                let mut t = [h[HEX_CORNER[0]], h[HEX_CORNER[c1]], h[HEX_CORNER[c2]], h[6]];
                let x = t.map(|n| self.nodes[n]);
                let d = |a: usize| std::array::from_fn::<f64, 3, _>(|k| x[a][k] - x[0][k]);
                let (a, b, c) = (d(1), d(2), d(3));
                let vol = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]);
                if vol < 0.0 {
                    t.swap(1, 2);
                }
                split.push(t);
            }
        }
        out.add_cells(&TET4, split);
        let boundary: std::collections::HashMap<Vec<usize>, Face> = out
            .cell_faces()
            .into_iter()
            .filter(|(_, (n, _))| *n == 1)
            .map(|(k, (_, f))| (k, f))
            .collect();
        for (name, faces) in &self.face_sets {
            let mut tris = Vec::new();
            for f in faces {
                if *f.face_type() != QUAD4 {
                    tris.push(*f);
                    continue;
                }
                let q = f.nodes();
                for skip in 0..4 {
                    let mut key: Vec<usize> = (0..4).filter(|&i| i != skip).map(|i| q[i]).collect();
                    key.sort_unstable();
                    if let Some(t) = boundary.get(&key) {
                        tris.push(*t);
                    }
                }
            }
            out.face_sets.insert(name.clone(), tris);
        }
        out
    }
}
