//! Mesh quality checks: scaled Jacobians, inverted cells, face-set orientation.
//!
//! Cells are indexed in mesh order (block after block: hexes first, then tets). What is
//! measured for each element type comes from its row of the element-type table
//! ([`crate::element::ElementType::corner_frames`] and
//! [`crate::element::ElementType::inverted_inside`]).

use super::{Face, Mesh};
use crate::Vec3;
use std::collections::HashMap;

/// Minimum scaled Jacobian of every cell (mesh order), dimensionless.
///
/// The minimum over the corners of the type's corner frames of det[e₁, e₂, e₃], the unit edge
/// vectors leaving the corner along the natural axes (right-handed in a valid cell). Hex:
/// the 8 corners; tet: node 0 with the edges x₁ − x₀, x₂ − x₀, x₃ − x₀. The value is 1 for a
/// cube (and for a tet with a right-angled corner at node 0, 1/√2 for a regular tet), ≤ 0
/// for an inverted or degenerate cell (a zero-length edge gives 0).
pub fn cell_min_jacobian_ratio(mesh: &Mesh) -> Vec<f64> {
    mesh.cells()
        .map(|(element, c)| {
            element
                .corner_frames
                .iter()
                .map(|f| corner_ratio(&mesh.nodes, c[f[0]], [c[f[1]], c[f[2]], c[f[3]]]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// Indices of the inverted or degenerate cells (mesh order): cells whose scaled Jacobian
/// ratio is ≤ 0 or that the type's own test finds inverted inside (hexes: a Jacobian
/// determinant ≤ 0 at one of the 2 × 2 × 2 Gauss points, ±1/√3).
pub fn inverted_cells(mesh: &Mesh) -> Vec<usize> {
    let ratios = cell_min_jacobian_ratio(mesh);
    mesh.cells()
        .enumerate()
        .filter(|&(c, (element, cell))| {
            ratios[c] <= 0.0 || ratios[c].is_nan() || {
                let x: Vec<[f64; 3]> = cell.iter().map(|&i| mesh.nodes[i]).collect();
                (element.inverted_inside)(&x)
            }
        })
        .map(|(c, _)| c)
        .collect()
}

/// Checks that every face of every face set is a boundary face of the mesh (a face of exactly
/// one cell), listed with the same orientation as that cell's outward face, and that its
/// normal points away from the cell's centroid.
///
/// # Errors
/// A message naming the first offending face set and face.
pub fn check_faces_outward(mesh: &Mesh) -> Result<(), String> {
    let owners = face_owners(mesh);
    for (name, faces) in &mesh.face_sets {
        for face in faces {
            check_face(mesh, &owners, face).map_err(|e| format!("face set '{name}': {e}"))?;
        }
    }
    Ok(())
}

/// Scaled Jacobian of the frame of unit edge vectors from node `corner` to `ends`.
fn corner_ratio(nodes: &[[f64; 3]], corner: usize, ends: [usize; 3]) -> f64 {
    let o = Vec3::from(nodes[corner]);
    let mut e = [Vec3::zeros(); 3];
    for (k, &end) in ends.iter().enumerate() {
        let d = Vec3::from(nodes[end]) - o;
        let len = d.norm();
        if len == 0.0 || !len.is_finite() {
            return 0.0;
        }
        e[k] = d / len;
    }
    e[0].dot(&e[1].cross(&e[2]))
}

/// Volume of hex `cell` by 2 × 2 × 2 Gauss quadrature [m³].
#[cfg(test)]
pub(crate) fn hex_volume(mesh: &Mesh, cell: usize) -> f64 {
    crate::element::hex8::hex8_gauss_dets(&mesh.hexes()[cell].map(|i| mesh.nodes[i]))
        .iter()
        .sum()
}

/// Every cell face keyed by its sorted node list: the owning cells and their outward faces.
fn face_owners(mesh: &Mesh) -> HashMap<Vec<usize>, Vec<(usize, Face)>> {
    let mut owners: HashMap<Vec<usize>, Vec<(usize, Face)>> = HashMap::new();
    let mut add = |cell: usize, face: Face| {
        let mut key = face.nodes().to_vec();
        key.sort_unstable();
        owners.entry(key).or_default().push((cell, face));
    };
    for (c, (element, cell)) in mesh.cells().enumerate() {
        for f in element.faces {
            add(c, Face::of_cell(cell, f));
        }
    }
    owners
}

fn check_face(
    mesh: &Mesh,
    owners: &HashMap<Vec<usize>, Vec<(usize, Face)>>,
    face: &Face,
) -> Result<(), String> {
    let nodes = face.nodes();
    if let Some(&bad) = nodes.iter().find(|&&i| i >= mesh.nodes.len()) {
        return Err(format!("face {face:?} refers to missing node {bad}"));
    }
    let mut key = nodes.to_vec();
    key.sort_unstable();
    let (cell, outward) = match owners.get(&key).map(Vec::as_slice) {
        None | Some([]) => return Err(format!("face {face:?} is not a face of any cell")),
        Some([one]) => *one,
        Some(many) => {
            return Err(format!(
                "face {face:?} is an interior face shared by {} cells",
                many.len()
            ))
        }
    };
    if !same_cycle(face, &outward) {
        return Err(format!(
            "face {face:?} is oriented into cell {cell} (outward order {:?})",
            outward.nodes()
        ));
    }
    let corners = face.corners();
    let normal = newell_normal(&mesh.nodes, corners);
    let away = centroid(&mesh.nodes, corners) - cell_centroid(mesh, cell);
    if normal.dot(&away) <= 0.0 {
        let normal = [normal[0], normal[1], normal[2]];
        return Err(format!(
            "face {face:?} has normal {normal:?} pointing into cell {cell}"
        ));
    }
    Ok(())
}

/// True if `b` lists the same face as `a` with the same orientation: the same cyclic
/// sequence of corners, for a quadratic face the mid-side nodes turned with them, and a
/// centre node (quad9) in its place.
fn same_cycle(face_a: &Face, face_b: &Face) -> bool {
    let (a, b) = (face_a.nodes(), face_b.nodes());
    if face_a.face_type() != face_b.face_type() {
        return false;
    }
    let n = face_a.corners().len();
    let mids = (a.len() - n).min(n);
    (0..n).any(|shift| {
        (0..n).all(|k| a[k] == b[(k + shift) % n])
            && (0..mids).all(|k| a[n + k] == b[n + (k + shift) % n])
            && (n + mids..a.len()).all(|k| a[k] == b[k])
    })
}

/// Newell's area-weighted normal of a polygon (right-hand rule over the node order).
fn newell_normal(nodes: &[[f64; 3]], poly: &[usize]) -> Vec3 {
    let mut n = Vec3::zeros();
    for k in 0..poly.len() {
        let p = nodes[poly[k]];
        let q = nodes[poly[(k + 1) % poly.len()]];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    n
}

fn centroid(nodes: &[[f64; 3]], ids: &[usize]) -> Vec3 {
    ids.iter().map(|&i| Vec3::from(nodes[i])).sum::<Vec3>() / ids.len() as f64
}

fn cell_centroid(mesh: &Mesh, cell: usize) -> Vec3 {
    centroid(&mesh.nodes, mesh.cell(cell).1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::{HEX8, TET4};

    const CUBE: [[f64; 3]; 8] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];

    fn one_hex(nodes: [[f64; 3]; 8]) -> Mesh {
        let mut m = Mesh {
            nodes: nodes.to_vec(),
            ..Mesh::default()
        };
        m.add_cells(&HEX8, [[0, 1, 2, 3, 4, 5, 6, 7]]);
        m
    }

    fn all_faces(mesh: &Mesh) -> Vec<Face> {
        let h = mesh.hexes()[0];
        HEX8.faces.iter().map(|f| Face::of_cell(&h, f)).collect()
    }

    #[test]
    fn cube_has_ratio_one_and_unit_volume() {
        let m = one_hex(CUBE.map(|p| p.map(|x| 0.002 * x)));
        assert!((cell_min_jacobian_ratio(&m)[0] - 1.0).abs() < 1e-14);
        assert!((hex_volume(&m, 0) - 8e-9).abs() < 1e-22);
        assert!(inverted_cells(&m).is_empty());
    }

    #[test]
    fn sheared_hex_ratio_is_the_sine_of_its_angle() {
        let s = 0.5;
        let m = one_hex(CUBE.map(|p| [p[0] + s * p[1], p[1], p[2]]));
        let expected = 1.0 / (1.0 + s * s).sqrt();
        assert!((cell_min_jacobian_ratio(&m)[0] - expected).abs() < 1e-14);
        assert!((hex_volume(&m, 0) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn frustum_volume_is_exact() {
        // Square frustum of height 1 with sides 1 (bottom) and 2 (top): det J is quadratic in
        // ζ, so the one-point rule would be wrong; 2 × 2 × 2 Gauss is exact: 7/3.
        let m = one_hex(CUBE.map(|p| [p[0] * (1.0 + p[2]), p[1] * (1.0 + p[2]), p[2]]));
        assert!((hex_volume(&m, 0) - 7.0 / 3.0).abs() < 1e-14);
    }

    #[test]
    fn detects_swapped_nodes() {
        let mut m = one_hex(CUBE);
        m.hexes_mut()[0].swap(1, 3);
        assert!(cell_min_jacobian_ratio(&m)[0] < 0.0);
        assert_eq!(inverted_cells(&m), vec![0]);
        let mut m = one_hex(CUBE);
        m.hexes_mut()[0].swap(2, 6);
        assert_eq!(inverted_cells(&m), vec![0]);
    }

    #[test]
    fn detects_flattened_hex() {
        let m = one_hex(CUBE.map(|p| [p[0], p[1], 0.0]));
        assert_eq!(cell_min_jacobian_ratio(&m)[0], 0.0);
        assert_eq!(inverted_cells(&m), vec![0]);
        // Top face collapsed onto one edge: zero-length edges.
        let mut nodes = CUBE;
        nodes[6] = nodes[5];
        nodes[7] = nodes[4];
        assert_eq!(inverted_cells(&one_hex(nodes)), vec![0]);
    }

    #[test]
    fn detects_corner_pushed_through_the_hex() {
        // Pushing one corner through the opposite face inverts the hex near that corner.
        let mut nodes = CUBE;
        nodes[6] = [0.2, 0.2, 0.2];
        let m = one_hex(nodes);
        assert_eq!(inverted_cells(&m), vec![0]);
    }

    #[test]
    fn tets_follow_hexes_and_use_node_zero() {
        let mut m = one_hex(CUBE);
        let base = m.nodes.len();
        m.nodes.extend([
            [3.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [3.0, 0.0, 1.0],
        ]);
        m.add_cells(
            &TET4,
            [
                [base, base + 1, base + 2, base + 3],
                [base, base + 2, base + 1, base + 3],
            ],
        );
        let r = cell_min_jacobian_ratio(&m);
        assert_eq!(r.len(), 3);
        assert!((r[1] - 1.0).abs() < 1e-14);
        assert!((r[2] + 1.0).abs() < 1e-14);
        assert_eq!(inverted_cells(&m), vec![2]);
    }

    #[test]
    fn outward_faces_pass() {
        let mut m = one_hex(CUBE);
        let faces = all_faces(&m);
        m.set_faces("all", faces);
        assert_eq!(check_faces_outward(&m), Ok(()));
    }

    #[test]
    fn reversed_face_is_reported_with_its_set() {
        let mut m = one_hex(CUBE);
        let mut faces = all_faces(&m);
        let q = faces[2].nodes();
        faces[2] = Face::quad([q[0], q[3], q[2], q[1]]);
        m.set_faces("sides", faces);
        let err = check_faces_outward(&m).unwrap_err();
        assert!(
            err.contains("'sides'") && err.contains("oriented into"),
            "{err}"
        );
    }

    #[test]
    fn interior_and_foreign_faces_are_reported() {
        let mut nodes = CUBE.to_vec();
        nodes.extend(CUBE[4..].iter().map(|p| [p[0], p[1], 2.0]));
        let mut m = Mesh {
            nodes,
            ..Mesh::default()
        };
        m.add_cells(
            &HEX8,
            [[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11]],
        );
        m.set_faces("middle", vec![Face::quad([4, 5, 6, 7])]);
        let err = check_faces_outward(&m).unwrap_err();
        assert!(
            err.contains("'middle'") && err.contains("interior"),
            "{err}"
        );
        m.face_sets.clear();
        m.set_faces("diagonal", vec![Face::quad([0, 1, 6, 7])]);
        let err = check_faces_outward(&m).unwrap_err();
        assert!(
            err.contains("'diagonal'") && err.contains("not a face"),
            "{err}"
        );
    }
}
