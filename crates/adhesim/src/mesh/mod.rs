//! Meshes: nodes, cells, named node and face sets. No physics here.
//!
//! Conventions
//! - Hex8 cells use the VTK node order: nodes 0-3 are the face ζ = −1 counter-clockwise seen
//!   from +ζ, nodes 4-7 the face ζ = +1 in the same order (natural coordinates of node 0..7:
//!   (−1,−1,−1), (1,−1,−1), (1,1,−1), (−1,1,−1), (−1,−1,1), (1,−1,1), (1,1,1), (−1,1,1)).
//!   A valid hex has positive Jacobian determinant at all its Gauss points.
//! - Tet4 cells use the VTK order; (x1−x0)·((x2−x0)×(x3−x0)) > 0.
//! - Boundary faces are listed counter-clockwise seen from outside the body, so that the
//!   right-hand-rule normal points out of the body.

use std::collections::BTreeMap;

pub mod generate;
pub mod gmsh;
pub mod quality;

/// A boundary face of a cell: a bilinear quadrilateral or a linear triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Face {
    /// Quadrilateral face of a hex8, nodes counter-clockwise seen from outside.
    Quad([usize; 4]),
    /// Triangular face of a tet4, nodes counter-clockwise seen from outside.
    Tri([usize; 3]),
}

impl Face {
    /// The face's node indices.
    pub fn nodes(&self) -> &[usize] {
        match self {
            Face::Quad(n) => n,
            Face::Tri(n) => n,
        }
    }
}

/// An unstructured mesh of one body.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Reference coordinates of the nodes [m].
    pub nodes: Vec<[f64; 3]>,
    /// Hexahedral cells (VTK order), indices into `nodes`.
    pub hexes: Vec<[usize; 8]>,
    /// Tetrahedral cells (VTK order), indices into `nodes`.
    pub tets: Vec<[usize; 4]>,
    /// Named node sets (sorted, no duplicates).
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named boundary face sets, outward oriented.
    pub face_sets: BTreeMap<String, Vec<Face>>,
}

impl Mesh {
    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of cells (hexes and tets).
    pub fn num_cells(&self) -> usize {
        self.hexes.len() + self.tets.len()
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
        for h in &self.hexes {
            for f in HEX_FACES {
                add(Face::Quad([h[f[0]], h[f[1]], h[f[2]], h[f[3]]]));
            }
        }
        for t in &self.tets {
            for f in TET_FACES {
                add(Face::Tri([t[f[0]], t[f[1]], t[f[2]]]));
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
            tets: self.tets.clone(),
            node_sets: self.node_sets.clone(),
            ..Default::default()
        };
        let perms = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for h in &self.hexes {
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
                out.tets.push(t);
            }
        }
        let boundary: std::collections::HashMap<Vec<usize>, Face> = out
            .cell_faces()
            .into_iter()
            .filter(|(_, (n, _))| *n == 1)
            .map(|(k, (_, f))| (k, f))
            .collect();
        for (name, faces) in &self.face_sets {
            let mut tris = Vec::new();
            for f in faces {
                match f {
                    Face::Tri(_) => tris.push(*f),
                    Face::Quad(q) => {
                        for skip in 0..4 {
                            let mut key: Vec<usize> =
                                (0..4).filter(|&i| i != skip).map(|i| q[i]).collect();
                            key.sort_unstable();
                            if let Some(t) = boundary.get(&key) {
                                tris.push(*t);
                            }
                        }
                    }
                }
            }
            out.face_sets.insert(name.clone(), tris);
        }
        out
    }
}

/// Local node indices of the six faces of a hex8 (VTK order), outward oriented.
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1], // ζ = −1
    [4, 5, 6, 7], // ζ = +1
    [0, 1, 5, 4], // η = −1
    [2, 3, 7, 6], // η = +1
    [0, 4, 7, 3], // ξ = −1
    [1, 2, 6, 5], // ξ = +1
];

/// Local node indices of the four faces of a tet4 (VTK order), outward oriented.
pub const TET_FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
