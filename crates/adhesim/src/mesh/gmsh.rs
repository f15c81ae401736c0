//! Gmsh MSH 4.1 import, ASCII and binary (little-endian, 8-byte `size_t`).
//!
//! Reading is in two stages:
//! 1. [`read`] / [`parse`] turn the file into an [`MshFile`]: nodes, linear cells and faces,
//!    point and line elements, physical groups. Every error names the file and the line
//!    (ASCII) or byte offset (binary) and says what was expected there.
//! 2. [`MshFile::body`] selects the volume elements of one body (all of them, or those of
//!    some physical volumes), keeps only the nodes they use (renumbered in file order) and
//!    turns physical groups into named sets:
//!    - a physical volume gives a node set and a cell set (cells of that volume);
//!    - a physical surface gives a face set (its triangles and quadrangles that are boundary
//!      faces of the body, re-oriented outward from their cell) and a node set of the same
//!      name holding the nodes of all its faces within the body;
//!    - a physical curve or point gives a node set.
//!
//!    Groups without a name are called `physical_<tag>`.
//!
//! Element types: the volume types of the element-type table
//! ([`crate::element::ELEMENT_TYPES`], found by their Gmsh type number: hex8 (Gmsh type 5),
//! tet4 (4), tet10 (11), hex20 (17) and hex27 (12)) become cells, their nodes taken in the
//! order of the row's `gmsh_nodes` (Gmsh's order is adhesim's (VTK) order for hex8 and tet4;
//! it differs in the mid-edge nodes of tet10, hex20 and hex27 and the face nodes of hex27);
//! quad4 (3), tri3 (2), tri6 (9), quad8 (16) and quad9 (10) are faces; points (15) and lines (1, 8, 26, 27, 28) only feed node sets. Other volume or
//! surface elements are rejected, and so is a file mixing first- and second-order volumes.

use super::{Face, Mesh};
use crate::element::{ElementType, FaceType, ELEMENT_TYPES};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt;
use std::path::{Path, PathBuf};

/// Where in the file an error was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// Line number (1-based) in an ASCII part of the file.
    Line(usize),
    /// Byte offset (0-based) in a binary part of the file.
    Byte(usize),
}

/// A Gmsh file that could not be read or used. The message says what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct GmshError {
    /// The MSH file.
    pub file: PathBuf,
    /// Where the problem is, when it is at one place in the file.
    pub location: Option<Location>,
    /// What is wrong and what would be valid.
    pub message: String,
}

impl fmt::Display for GmshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.location {
            Some(Location::Line(l)) => write!(f, "{}:{l}: {}", self.file.display(), self.message),
            Some(Location::Byte(b)) => {
                write!(f, "{} (byte {b}): {}", self.file.display(), self.message)
            }
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for GmshError {}

/// Dimension and tag of a physical group.
pub type PhysicalKey = (i32, i32);

/// One surface element of the file: its Gmsh tag, the geometric surface holding it and its
/// nodes (indices into [`MshFile::nodes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceElement {
    /// Gmsh element tag.
    pub tag: u64,
    /// Tag of the geometric surface that holds it.
    pub entity: i32,
    /// Node indices into [`MshFile::nodes`], in the face type's order.
    pub nodes: Vec<usize>,
}

/// The volume elements of one type in file order: Gmsh tag, entity and nodes of each.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeElements {
    /// The element type.
    pub element: &'static ElementType,
    /// Gmsh tag of each element.
    pub tags: Vec<u64>,
    /// Tag of the geometric volume holding each element.
    pub entities: Vec<i32>,
    /// Node indices into [`MshFile::nodes`], `element.nodes` per element.
    pub nodes: Vec<usize>,
}

impl VolumeElements {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.tags.len()
    }

    /// True when there is no element.
    pub fn is_empty(&self) -> bool {
        self.tags.is_empty()
    }

    /// Node indices of element `i`.
    pub fn element_nodes(&self, i: usize) -> &[usize] {
        let n = self.element.nodes;
        &self.nodes[n * i..n * (i + 1)]
    }
}

impl MshFile {
    /// The volume elements of type `element` (`None`: the file has none).
    pub fn volume_elements(&self, element: &ElementType) -> Option<&VolumeElements> {
        self.volumes.iter().find(|v| v.element == element)
    }

    fn volume_block_mut(&mut self, element: &'static ElementType) -> &mut VolumeElements {
        let i = match self.volumes.iter().position(|v| v.element == element) {
            Some(i) => i,
            None => {
                let at = self
                    .volumes
                    .iter()
                    .position(|v| v.element.index() > element.index())
                    .unwrap_or(self.volumes.len());
                self.volumes.insert(
                    at,
                    VolumeElements {
                        element,
                        tags: Vec::new(),
                        entities: Vec::new(),
                        nodes: Vec::new(),
                    },
                );
                at
            }
        };
        &mut self.volumes[i]
    }
}

/// The surface elements of one face type in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceElements {
    /// The face type.
    pub face_type: &'static FaceType,
    /// The elements, in file order.
    pub elements: Vec<SurfaceElement>,
}

impl MshFile {
    /// The block of surface elements of `face_type`, created (in face-type order) when
    /// missing.
    fn surface_block_mut(&mut self, face_type: &'static FaceType) -> &mut SurfaceElements {
        let order = |t: &FaceType| FaceType::all().iter().position(|f| *f == t);
        let i = match self.surfaces.iter().position(|b| b.face_type == face_type) {
            Some(i) => i,
            None => {
                let at = self
                    .surfaces
                    .iter()
                    .position(|b| order(b.face_type) > order(face_type))
                    .unwrap_or(self.surfaces.len());
                self.surfaces.insert(
                    at,
                    SurfaceElements {
                        face_type,
                        elements: Vec::new(),
                    },
                );
                at
            }
        };
        &mut self.surfaces[i]
    }
}

/// The content of an MSH 4.1 file that adhesim uses.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MshFile {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// Node coordinates in file order.
    pub nodes: Vec<[f64; 3]>,
    /// Gmsh tag of each node.
    pub node_tags: Vec<u64>,
    /// Volume elements, one block per element type in the order of
    /// [`crate::element::ELEMENT_TYPES`] (no empty blocks).
    pub volumes: Vec<VolumeElements>,
    /// Surface elements of the face types adhesim has ([`FaceType::all`]), one block per
    /// face type in that order (no empty blocks), nodes in Gmsh's order, which is the face
    /// type's.
    pub surfaces: Vec<SurfaceElements>,
    /// Point (dimension 0) and line (dimension 1) elements: dimension, entity, nodes.
    pub low_dim: Vec<(i32, i32, Vec<usize>)>,
    /// Physical group names by (dimension, tag); unnamed groups are `physical_<tag>`.
    pub physical_names: BTreeMap<PhysicalKey, String>,
    /// Physical tags of each geometric entity, keyed by (dimension, entity tag).
    pub entity_physicals: HashMap<(i32, i32), Vec<i32>>,
}

/// A body taken from an MSH file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GmshBody {
    /// The mesh with its named node and face sets.
    pub mesh: Mesh,
    /// Gmsh tag of each cell (mesh order: block after block, as in [`super::quality`]).
    pub cell_tags: Vec<u64>,
    /// Gmsh tag of each node.
    pub node_tags: Vec<u64>,
    /// Cells of each physical volume (indices as in `cell_tags`).
    pub cell_sets: BTreeMap<String, Vec<usize>>,
}

/// Reads an MSH 4.1 file (ASCII or binary).
///
/// # Errors
/// The file cannot be read or is not a valid MSH 4.1 mesh of first-order elements.
pub fn read(path: &Path) -> Result<MshFile, GmshError> {
    let bytes = std::fs::read(path).map_err(|e| GmshError {
        file: path.to_path_buf(),
        location: None,
        message: format!("cannot read the mesh file: {e}"),
    })?;
    parse(&bytes, path)
}

/// Parses the bytes of an MSH 4.1 file; `path` names the file in errors.
///
/// # Errors
/// The bytes are not a valid MSH 4.1 mesh of first-order elements.
pub fn parse(bytes: &[u8], path: &Path) -> Result<MshFile, GmshError> {
    let mut p = Parser {
        b: bytes,
        pos: 0,
        binary: false,
        path,
    };
    let mut msh = MshFile {
        path: path.to_path_buf(),
        ..MshFile::default()
    };
    let mut seen_format = false;
    let mut seen_nodes = false;
    let mut seen_elements = false;
    let mut node_index = NodeIndex::default();
    loop {
        p.skip_ws();
        if p.pos >= p.b.len() {
            break;
        }
        let at = p.pos;
        let header = p.ascii_token()?;
        // Binary data starts right after the header line's newline.
        if p.b.get(p.pos) == Some(&b'\r') {
            p.pos += 1;
        }
        if p.b.get(p.pos) == Some(&b'\n') {
            p.pos += 1;
        }
        let Some(section) = header.strip_prefix('$') else {
            return Err(p.err_at(
                at,
                format!(
                    "expected a section header such as $Nodes, found {:?}",
                    short(&header)
                ),
            ));
        };
        if !seen_format && section != "MeshFormat" {
            return Err(p.err_at(
                at,
                format!(
                    "expected $MeshFormat at the start of an MSH file, found {:?}",
                    short(&header)
                ),
            ));
        }
        match section {
            "MeshFormat" => {
                if seen_format {
                    return Err(p.err_at(at, "a second $MeshFormat section"));
                }
                p.mesh_format()?;
                seen_format = true;
            }
            "PhysicalNames" => p.physical_names(&mut msh)?,
            "Entities" => p.entities(&mut msh)?,
            "PartitionedEntities" => {
                return Err(p.err_at(
                    at,
                    "partitioned meshes are not supported: save the mesh without partitions",
                ))
            }
            "Nodes" => {
                if seen_nodes {
                    return Err(p.err_at(at, "a second $Nodes section"));
                }
                node_index = p.nodes(&mut msh)?;
                seen_nodes = true;
            }
            "Elements" => {
                if !seen_nodes {
                    return Err(p.err_at(at, "expected $Nodes before $Elements"));
                }
                if seen_elements {
                    return Err(p.err_at(at, "a second $Elements section"));
                }
                p.elements(&mut msh, &node_index)?;
                seen_elements = true;
            }
            _ if section.starts_with("End") => {
                return Err(p.err_at(at, format!("{header} without its opening section")));
            }
            _ => p.skip_section(section, at)?,
        }
    }
    if !seen_format {
        return Err(p.err_at(0, "empty file: expected $MeshFormat"));
    }
    if !seen_nodes || msh.nodes.is_empty() {
        return Err(p.err_here("the file holds no nodes (no $Nodes section or an empty one)"));
    }
    if !seen_elements {
        return Err(p.err_here("the file holds no $Elements section"));
    }
    if msh.volumes.iter().all(VolumeElements::is_empty) {
        return Err(p.err_here(format!(
            "the file holds no volume elements ({}): mesh the volumes in 3D (gmsh -3)",
            volume_type_names(" or ")
        )));
    }
    let found: Vec<&str> = msh.volumes.iter().map(|v| v.element.name).collect();
    let quadratic = msh
        .volumes
        .iter()
        .filter(|v| v.element.is_quadratic())
        .count();
    if quadratic > 0 && quadratic < msh.volumes.len() {
        return Err(p.err_here(format!(
            "the file mixes first- and second-order volume elements ({}): their faces cannot match; mesh the whole body at one order (Mesh.ElementOrder)",
            found.join(" and ")
        )));
    }
    // Name every physical group used by an entity.
    for phys in msh
        .entity_physicals
        .iter()
        .flat_map(|((d, _), ps)| ps.iter().map(|&t| (*d, t)))
    {
        msh.physical_names
            .entry(phys)
            .or_insert_with(|| format!("physical_{}", phys.1));
    }
    Ok(msh)
}

/// Gmsh element types adhesim knows the node count of: (type, name, nodes, dimension).
const GMSH_ELEMENT_TYPES: &[(i32, &str, usize, i32)] = &[
    (1, "line2", 2, 1),
    (2, "tri3", 3, 2),
    (3, "quad4", 4, 2),
    (4, "tet4", 4, 3),
    (5, "hex8", 8, 3),
    (6, "prism6", 6, 3),
    (7, "pyramid5", 5, 3),
    (8, "line3", 3, 1),
    (9, "tri6", 6, 2),
    (10, "quad9", 9, 2),
    (11, "tet10", 10, 3),
    (12, "hex27", 27, 3),
    (13, "prism18", 18, 3),
    (14, "pyramid14", 14, 3),
    (15, "point", 1, 0),
    (16, "quad8", 8, 2),
    (17, "hex20", 20, 3),
    (18, "prism15", 15, 3),
    (19, "pyramid13", 13, 3),
    (20, "tri9", 9, 2),
    (21, "tri10", 10, 2),
    (22, "tri12", 12, 2),
    (23, "tri15", 15, 2),
    (26, "line4", 4, 1),
    (27, "line5", 5, 1),
    (28, "line6", 6, 1),
    (29, "tet20", 20, 3),
    (30, "tet35", 35, 3),
    (36, "quad16", 16, 2),
    (37, "quad25", 25, 2),
    (92, "hex64", 64, 3),
    (93, "hex125", 125, 3),
];

/// The names of the volume element types adhesim reads, joined by `sep`.
fn volume_type_names(sep: &str) -> String {
    ELEMENT_TYPES
        .iter()
        .map(|t| t.name)
        .collect::<Vec<_>>()
        .join(sep)
}

/// The names of the face types adhesim reads, the last two joined by `last` (with their Gmsh
/// type numbers when `numbers`).
fn face_type_names(last: &str, numbers: bool) -> String {
    let names: Vec<String> = FaceType::all()
        .iter()
        .map(|t| match numbers {
            true => format!("{} ({})", t.name, t.gmsh_type),
            false => t.name.to_string(),
        })
        .collect();
    match names.split_last() {
        Some((end, rest)) if !rest.is_empty() => format!("{}{last}{end}", rest.join(", ")),
        _ => names.join(""),
    }
}

fn element_type(t: i32) -> Option<(&'static str, usize, i32)> {
    GMSH_ELEMENT_TYPES
        .iter()
        .find(|e| e.0 == t)
        .map(|e| (e.1, e.2, e.3))
}

/// Node tag → index into the file's node list: a dense table when the tags are compact,
/// a hash map otherwise.
#[derive(Default)]
struct NodeIndex {
    min: u64,
    dense: Vec<usize>,
    sparse: HashMap<u64, usize>,
}

impl NodeIndex {
    fn build(tags: &[u64]) -> Self {
        let min = tags.iter().copied().min().unwrap_or(0);
        let max = tags.iter().copied().max().unwrap_or(0);
        let span = max - min;
        if span < 4 * tags.len() as u64 + 1024 {
            let mut dense = vec![usize::MAX; span as usize + 1];
            for (i, &t) in tags.iter().enumerate() {
                dense[(t - min) as usize] = i;
            }
            NodeIndex {
                min,
                dense,
                sparse: HashMap::new(),
            }
        } else {
            NodeIndex {
                min,
                dense: Vec::new(),
                sparse: tags.iter().enumerate().map(|(i, &t)| (t, i)).collect(),
            }
        }
    }

    fn get(&self, tag: u64) -> Option<usize> {
        if self.dense.is_empty() {
            self.sparse.get(&tag).copied()
        } else {
            let k = tag.checked_sub(self.min)?;
            self.dense
                .get(usize::try_from(k).ok()?)
                .copied()
                .filter(|&i| i != usize::MAX)
        }
    }
}

fn short(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

struct Parser<'a> {
    b: &'a [u8],
    pos: usize,
    binary: bool,
    path: &'a Path,
}

impl Parser<'_> {
    // ---- errors ---------------------------------------------------------------------

    /// An error at byte `at`, reported as a line in ASCII parts and as a byte offset in
    /// the binary data blocks.
    fn err_at(&self, at: usize, message: impl Into<String>) -> GmshError {
        let at = at.min(self.b.len());
        let location = if self.binary {
            Location::Byte(at)
        } else {
            Location::Line(1 + self.b[..at].iter().filter(|&&c| c == b'\n').count())
        };
        GmshError {
            file: self.path.to_path_buf(),
            location: Some(location),
            message: message.into(),
        }
    }

    /// Position of the next value (after blank space in ASCII), for error locations.
    fn mark(&mut self) -> usize {
        if !self.binary {
            self.skip_ws();
        }
        self.pos
    }

    fn err_here(&self, message: impl Into<String>) -> GmshError {
        self.err_at(self.pos, message)
    }

    // ---- ASCII tokens -------------------------------------------------------------------

    fn skip_ws(&mut self) {
        while self.pos < self.b.len() && self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// The next whitespace-delimited token, as text.
    fn ascii_token(&mut self) -> Result<String, GmshError> {
        self.skip_ws();
        let start = self.pos;
        while self.pos < self.b.len() && !self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.err_at(start, "unexpected end of file (truncated?)"));
        }
        Ok(String::from_utf8_lossy(&self.b[start..self.pos]).into_owned())
    }

    fn ascii_number<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, GmshError> {
        self.skip_ws();
        let at = self.mark();
        let tok = self.ascii_token().map_err(|e| GmshError {
            message: format!("unexpected end of file while reading {what} (truncated?)"),
            ..e
        })?;
        tok.parse()
            .map_err(|_| self.err_at(at, format!("expected {what}, found {:?}", short(&tok))))
    }

    /// Expects the token `$End<section>`.
    fn expect_end(&mut self, section: &str) -> Result<(), GmshError> {
        self.skip_ws();
        let at = self.mark();
        let want = format!("$End{section}");
        match self.ascii_token() {
            Ok(t) if t == want => Ok(()),
            Ok(t) => Err(self.err_at(
                at,
                format!(
                    "expected {want}, found {:?} (wrong count in the section?)",
                    short(&t)
                ),
            )),
            Err(_) => Err(self.err_at(at, format!("unexpected end of file: expected {want}"))),
        }
    }

    fn skip_section(&mut self, section: &str, at: usize) -> Result<(), GmshError> {
        let end = format!("$End{section}");
        let found = self.b[self.pos..]
            .windows(end.len())
            .position(|w| w == end.as_bytes());
        match found {
            Some(k) => {
                self.pos += k + end.len();
                Ok(())
            }
            None => Err(self.err_at(at, format!("section ${section} has no {end}"))),
        }
    }

    // ---- values (ASCII or binary) -----------------------------------------------------

    fn take(&mut self, n: usize, what: &str) -> Result<&[u8], GmshError> {
        if self.b.len() - self.pos < n {
            return Err(self.err_at(
                self.pos,
                format!("unexpected end of file while reading {what} (truncated?)"),
            ));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn int(&mut self, what: &str) -> Result<i32, GmshError> {
        if self.binary {
            let s = self.take(4, what)?;
            Ok(i32::from_le_bytes(s.try_into().expect("4 bytes")))
        } else {
            self.ascii_number(what)
        }
    }

    fn size(&mut self, what: &str) -> Result<u64, GmshError> {
        if self.binary {
            let s = self.take(8, what)?;
            Ok(u64::from_le_bytes(s.try_into().expect("8 bytes")))
        } else {
            self.ascii_number(what)
        }
    }

    fn double(&mut self, what: &str) -> Result<f64, GmshError> {
        if self.binary {
            let s = self.take(8, what)?;
            Ok(f64::from_le_bytes(s.try_into().expect("8 bytes")))
        } else {
            self.ascii_number(what)
        }
    }

    /// A count read as `size_t`, checked against what the rest of the file can hold
    /// (at least `min_bytes` per item), so that a corrupt count fails cleanly.
    fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize, GmshError> {
        let at = self.mark();
        let n = self.size(what)?;
        let room = (self.b.len() - self.pos) / min_bytes.max(1);
        match usize::try_from(n) {
            Ok(n) if n <= room => Ok(n),
            _ => Err(self.err_at(at,
                format!("{what} = {n} is more than the rest of the file can hold (bad count or truncated file)"),
            )),
        }
    }

    /// Bytes a value takes at least: the binary size, or 2 (a digit and a separator).
    fn min_bytes(&self, binary: usize) -> usize {
        if self.binary {
            binary
        } else {
            2
        }
    }

    // ---- sections -------------------------------------------------------------------

    fn mesh_format(&mut self) -> Result<(), GmshError> {
        self.skip_ws();
        let at = self.mark();
        let version = self.ascii_token()?;
        if version != "4.1" {
            return Err(self.err_at(
                at,
                format!(
                    "MSH version {} is not supported: save the mesh as version 4.1 \
                     (Mesh.MshFileVersion = 4.1, or `gmsh -format msh41`)",
                    short(&version)
                ),
            ));
        }
        let file_type: i32 = self.ascii_number("the file type (0 = ASCII, 1 = binary)")?;
        let at_size = self.mark();
        let data_size: i32 = self.ascii_number("the data size")?;
        match file_type {
            0 => {}
            1 => {
                if data_size != 8 {
                    return Err(self.err_at(
                        at_size,
                        format!("binary MSH with data size {data_size} is not supported: only 8-byte size_t (64-bit Gmsh) is"),
                    ));
                }
                // The rest of the header line, then the integer 1 in the writer's byte order.
                while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
                    self.pos += 1;
                }
                self.pos = (self.pos + 1).min(self.b.len());
                let at_one = self.pos;
                self.binary = true;
                let one = self.take(4, "the endianness check (binary integer 1)")?;
                let one: [u8; 4] = one.try_into().expect("4 bytes");
                if i32::from_le_bytes(one) != 1 {
                    let message = if i32::from_be_bytes(one) == 1 {
                        "big-endian binary MSH is not supported: save the mesh as ASCII or on a little-endian machine".to_string()
                    } else {
                        format!("expected the binary integer 1 after the format line, found bytes {one:?}")
                    };
                    return Err(self.err_at(at_one, message));
                }
                self.binary = true;
            }
            t => {
                return Err(self.err_at(
                    at,
                    format!("file type {t} is not valid: expected 0 (ASCII) or 1 (binary)"),
                ))
            }
        }
        self.expect_end("MeshFormat")
    }

    fn physical_names(&mut self, msh: &mut MshFile) -> Result<(), GmshError> {
        // Always ASCII, also in binary files.
        let n: usize = self.ascii_number("the number of physical names")?;
        for _ in 0..n {
            let dim: i32 = self.ascii_number("a physical group dimension")?;
            let tag: i32 = self.ascii_number("a physical group tag")?;
            self.skip_ws();
            let at = self.mark();
            if self.b.get(self.pos) != Some(&b'"') {
                return Err(self.err_at(at, "expected a quoted physical group name"));
            }
            let close = self.b[at + 1..]
                .iter()
                .position(|&c| c == b'"' || c == b'\n')
                .filter(|&k| self.b[at + 1 + k] == b'"')
                .ok_or_else(|| self.err_at(at, "the physical group name has no closing quote"))?;
            let name = String::from_utf8_lossy(&self.b[at + 1..at + 1 + close]).into_owned();
            self.pos = at + close + 2;
            if !(0..=3).contains(&dim) {
                return Err(self.err_at(
                    at,
                    format!("physical group dimension {dim}: expected 0 to 3"),
                ));
            }
            msh.physical_names.insert((dim, tag), name);
        }
        self.expect_end("PhysicalNames")
    }

    fn entities(&mut self, msh: &mut MshFile) -> Result<(), GmshError> {
        let (int, size, dbl) = (self.min_bytes(4), self.min_bytes(8), self.min_bytes(8));
        let mut counts = [0usize; 4];
        for (d, c) in counts.iter_mut().enumerate() {
            *c = self.count(
                &format!(
                    "the number of {} entities",
                    ["point", "curve", "surface", "volume"][d]
                ),
                int + 3 * dbl + size,
            )?;
        }
        for (d, &n) in counts.iter().enumerate() {
            for _ in 0..n {
                let tag = self.int("an entity tag")?;
                let coords = if d == 0 { 3 } else { 6 };
                for _ in 0..coords {
                    self.double("an entity bounding-box coordinate")?;
                }
                let np = self.count("the number of physical tags", int)?;
                let mut phys = Vec::with_capacity(np);
                for _ in 0..np {
                    phys.push(self.int("a physical tag")?);
                }
                if d > 0 {
                    let nb = self.count("the number of bounding entities", int)?;
                    for _ in 0..nb {
                        self.int("a bounding entity tag")?;
                    }
                }
                if !phys.is_empty() {
                    msh.entity_physicals.insert((d as i32, tag), phys);
                }
            }
        }
        self.expect_end("Entities")
    }

    fn nodes(&mut self, msh: &mut MshFile) -> Result<NodeIndex, GmshError> {
        let (int, size, dbl) = (self.min_bytes(4), self.min_bytes(8), self.min_bytes(8));
        let blocks = self.count("the number of node blocks", 3 * int + size)?;
        let at_total = self.mark();
        let total = self.count("the number of nodes", size + 3 * dbl)?;
        self.size("the smallest node tag")?;
        self.size("the largest node tag")?;
        msh.nodes.reserve(total);
        msh.node_tags.reserve(total);
        for _ in 0..blocks {
            let dim = self.int("the entity dimension of a node block")?;
            self.int("the entity tag of a node block")?;
            let at_param = self.mark();
            let parametric = self.int("the parametric flag (0 or 1)")?;
            if !(0..=3).contains(&dim) {
                return Err(self.err_at(
                    at_param,
                    format!("node block of dimension {dim}: expected 0 to 3"),
                ));
            }
            let extra = match parametric {
                0 => 0,
                1 => dim as usize,
                p => {
                    return Err(
                        self.err_at(at_param, format!("parametric flag {p}: expected 0 or 1"))
                    )
                }
            };
            let n = self.count("the number of nodes in the block", size + 3 * dbl)?;
            if msh.nodes.len() + n > total {
                return Err(self.err_at(
                    at_total,
                    format!("the node blocks hold more nodes than the {total} announced"),
                ));
            }
            for _ in 0..n {
                msh.node_tags.push(self.size("a node tag")?);
            }
            for _ in 0..n {
                let at = self.mark();
                let mut x = [0.0; 3];
                for c in &mut x {
                    *c = self.double("a node coordinate")?;
                }
                for _ in 0..extra {
                    self.double("a parametric node coordinate")?;
                }
                if x.iter().any(|c| !c.is_finite()) {
                    return Err(self.err_at(
                        at,
                        format!("node coordinates {x:?}: expected finite numbers"),
                    ));
                }
                msh.nodes.push(x);
            }
        }
        if msh.nodes.len() != total {
            return Err(self.err_at(
                at_total,
                format!(
                    "$Nodes announces {total} nodes but its blocks hold {}",
                    msh.nodes.len()
                ),
            ));
        }
        let index = NodeIndex::build(&msh.node_tags);
        if msh.node_tags.contains(&0) {
            return Err(self.err_at(at_total, "node tag 0: Gmsh tags start at 1"));
        }
        {
            let mut seen = BTreeSet::new();
            if let Some(t) = msh.node_tags.iter().find(|&&t| !seen.insert(t)) {
                return Err(self.err_at(at_total, format!("node tag {t} is given twice")));
            }
        }
        self.skip_ws();
        self.expect_end("Nodes")?;
        Ok(index)
    }

    fn elements(&mut self, msh: &mut MshFile, index: &NodeIndex) -> Result<(), GmshError> {
        let (int, size) = (self.min_bytes(4), self.min_bytes(8));
        let blocks = self.count("the number of element blocks", 3 * int + size)?;
        let at_total = self.mark();
        let total = self.count("the number of elements", 2 * size)?;
        self.size("the smallest element tag")?;
        self.size("the largest element tag")?;
        let mut read = 0usize;
        for _ in 0..blocks {
            let dim = self.int("the entity dimension of an element block")?;
            let entity = self.int("the entity tag of an element block")?;
            let at_type = self.mark();
            let etype = self.int("the element type")?;
            let Some((name, nn, edim)) = element_type(etype) else {
                let volumes: Vec<String> = ELEMENT_TYPES
                    .iter()
                    .enumerate()
                    .map(|(i, t)| {
                        if i == 0 {
                            format!("{} (Gmsh type {})", t.name, t.gmsh_type)
                        } else {
                            format!("{} ({})", t.name, t.gmsh_type)
                        }
                    })
                    .collect();
                return Err(self.err_at(
                    at_type,
                    format!(
                        "element type {etype} is not known: adhesim reads {} volumes, {} faces",
                        volumes.join(", "),
                        face_type_names(" and ", true)
                    ),
                ));
            };
            if edim != dim {
                return Err(self.err_at(at_type,
                    format!("{name} (Gmsh type {etype}) in a block of dimension {dim}: expected dimension {edim}"),
                ));
            }
            let volume = ElementType::from_gmsh(etype);
            let surface = FaceType::from_gmsh(etype);
            let supported = volume.is_some() || surface.is_some() || dim <= 1;
            if !supported {
                let fix = if matches!(etype, 6 | 7 | 13 | 14 | 18 | 19) {
                    format!(
                        "adhesim meshes hold {} volumes only: remesh with hexahedra or tetrahedra",
                        volume_type_names(" and ")
                    )
                } else if dim == 3 {
                    format!(
                        "the volume elements adhesim reads are {}: remesh with first-order elements (Mesh.ElementOrder = 1), or at second order with Mesh.ElementOrder = 2 (tet10, hex27; with Mesh.SecondOrderIncomplete = 1, hex20)",
                        volume_type_names(", ")
                    )
                } else {
                    format!("adhesim reads {} surface elements: remesh with first-order elements (Mesh.ElementOrder = 1), or at second order (tet10 with tri6 faces, hex27 with quad9 faces; with Mesh.SecondOrderIncomplete = 1, hex20 with quad8 faces)", face_type_names(" and ", false))
                };
                return Err(self.err_at(
                    at_type,
                    format!("{name} (Gmsh type {etype}) is not supported: {fix}"),
                ));
            }
            let n = self.count("the number of elements in the block", (1 + nn) * size)?;
            read += n;
            if read > total {
                return Err(self.err_at(
                    at_total,
                    format!("the element blocks hold more elements than the {total} announced"),
                ));
            }
            let mut nodes = vec![0usize; nn];
            for _ in 0..n {
                let tag = self.size("an element tag")?;
                for slot in nodes.iter_mut().take(nn) {
                    let at = self.mark();
                    let t = self.size("a node tag of an element")?;
                    *slot = index.get(t).ok_or_else(|| {
                        self.err_at(
                            at,
                            format!("element {tag} refers to node {t}, which is not in $Nodes"),
                        )
                    })?;
                }
                if let Some(element) = volume {
                    let block = msh.volume_block_mut(element);
                    block.tags.push(tag);
                    block.entities.push(entity);
                    block
                        .nodes
                        .extend(element.gmsh_nodes.iter().map(|&g| nodes[g]));
                    continue;
                }
                if let Some(face_type) = surface {
                    let block = msh.surface_block_mut(face_type);
                    block.elements.push(SurfaceElement {
                        tag,
                        entity,
                        nodes: nodes.clone(),
                    });
                    continue;
                }
                match etype {
                    _ => {
                        // Points and lines: only their end nodes matter (node sets).
                        let used = if dim == 0 { 1 } else { 2 };
                        msh.low_dim
                            .push((dim, entity, nodes[..used.min(nn)].to_vec()));
                    }
                }
            }
        }
        if read != total {
            return Err(self.err_at(
                at_total,
                format!("$Elements announces {total} elements but its blocks hold {read}"),
            ));
        }
        self.skip_ws();
        self.expect_end("Elements")
    }
}

impl MshFile {
    /// Names of the physical volumes, sorted.
    pub fn physical_volumes(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .physical_names
            .iter()
            .filter(|((d, _), _)| *d == 3)
            .map(|(_, n)| n.clone())
            .collect();
        v.sort();
        v.dedup();
        v
    }

    fn err(&self, message: impl Into<String>) -> GmshError {
        GmshError {
            file: self.path.clone(),
            location: None,
            message: message.into(),
        }
    }

    /// Physical group names of an element of dimension `dim` in entity `entity`.
    fn groups(&self, dim: i32, entity: i32) -> impl Iterator<Item = &str> + '_ {
        self.entity_physicals
            .get(&(dim, entity))
            .into_iter()
            .flatten()
            .filter_map(move |&t| self.physical_names.get(&(dim, t)).map(String::as_str))
    }

    /// The body made of the volume elements of the physical volumes named in `volumes`
    /// (all volume elements when `None`), with its named sets.
    ///
    /// # Errors
    /// An unknown volume name, a selection without elements, a name used by physical groups
    /// of different dimensions, or a surface element that is not a face of any cell.
    pub fn body(&self, volumes: Option<&[String]>) -> Result<GmshBody, GmshError> {
        self.check_selection(volumes)?;
        self.check_group_dimensions()?;
        let chosen = self.chosen_elements(volumes)?;
        let (mut mesh, node_tags, new_id) = self.used_nodes(&chosen);
        for &(v, e) in &chosen {
            let conn = mesh.connectivity_mut(v.element);
            conn.extend(v.element_nodes(e).iter().map(|&i| new_id[i]));
        }
        let cell_tags: Vec<u64> = chosen.iter().map(|&(v, e)| v.tags[e]).collect();
        let cell_sets = self.volume_sets(&chosen, &mut mesh);
        self.surface_sets(&new_id, &mut mesh)?;
        self.low_dim_sets(&new_id, &mut mesh);
        Ok(GmshBody {
            mesh,
            cell_tags,
            node_tags,
            cell_sets,
        })
    }

    /// Checks that a selection of physical volumes is not empty and names only physical
    /// volumes of the file.
    fn check_selection(&self, volumes: Option<&[String]>) -> Result<(), GmshError> {
        let Some(sel) = volumes else {
            return Ok(());
        };
        let available = self.physical_volumes();
        if sel.is_empty() {
            return Err(self.err(format!(
                "`volumes` is empty: name at least one physical volume ({})",
                list(&available)
            )));
        }
        for v in sel {
            if !available.contains(v) {
                return Err(self.err(format!(
                    "{v:?} is not a physical volume of this file; its physical volumes are: {}",
                    list(&available)
                )));
            }
        }
        Ok(())
    }

    /// Checks that no name stands for physical groups of different dimensions (they would
    /// share a node set name).
    fn check_group_dimensions(&self) -> Result<(), GmshError> {
        let mut dims: BTreeMap<&str, i32> = BTreeMap::new();
        for ((d, _), name) in &self.physical_names {
            if let Some(d0) = dims.insert(name, *d) {
                if d0 != *d {
                    return Err(self.err(format!(
                        "the name {name:?} is used by physical groups of dimension {d0} and {d}; give them distinct names (each becomes a node set)"
                    )));
                }
            }
        }
        Ok(())
    }

    /// The selected elements of each volume block, block after block: (block, element
    /// index); at least one.
    fn chosen_elements(
        &self,
        volumes: Option<&[String]>,
    ) -> Result<Vec<(&VolumeElements, usize)>, GmshError> {
        let selected = |entity: i32| match volumes {
            None => true,
            Some(sel) => self.groups(3, entity).any(|g| sel.iter().any(|s| s == g)),
        };
        let chosen: Vec<(&VolumeElements, usize)> = self
            .volumes
            .iter()
            .flat_map(|v| {
                (0..v.len())
                    .filter(|&i| selected(v.entities[i]))
                    .map(move |i| (v, i))
            })
            .collect();
        if chosen.is_empty() {
            return Err(self.err(match volumes {
                Some(sel) => format!(
                    "the physical volumes {} hold no {} elements",
                    list(sel),
                    volume_type_names(" or ")
                ),
                None => format!("the file holds no {} elements", volume_type_names(" or ")),
            }));
        }
        Ok(chosen)
    }

    /// The nodes that the chosen cells use, in file order: a mesh holding them (no cells
    /// yet), their Gmsh tags, and the new index of each file node (`usize::MAX` for a node
    /// left out).
    fn used_nodes(&self, chosen: &[(&VolumeElements, usize)]) -> (Mesh, Vec<u64>, Vec<usize>) {
        let mut new_id = vec![usize::MAX; self.nodes.len()];
        for &i in chosen.iter().flat_map(|&(v, e)| v.element_nodes(e)) {
            new_id[i] = 0;
        }
        let mut mesh = Mesh::default();
        let mut node_tags = Vec::new();
        for (i, id) in new_id.iter_mut().enumerate() {
            if *id == 0 {
                *id = mesh.nodes.len();
                mesh.nodes.push(self.nodes[i]);
                node_tags.push(self.node_tags[i]);
            }
        }
        (mesh, node_tags, new_id)
    }

    /// Physical volumes: a node set of each in `mesh`; returns the cells of each (indices
    /// in the order of `chosen`).
    fn volume_sets(
        &self,
        chosen: &[(&VolumeElements, usize)],
        mesh: &mut Mesh,
    ) -> BTreeMap<String, Vec<usize>> {
        let mut cell_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        let entities = chosen.iter().map(|&(v, e)| v.entities[e]);
        for (c, entity) in entities.enumerate() {
            for g in self.groups(3, entity) {
                cell_sets.entry(g.to_string()).or_default().push(c);
            }
        }
        for (name, cells) in &cell_sets {
            let nodes = cells
                .iter()
                .flat_map(|&c| mesh.cell(c).1.to_vec())
                .collect();
            mesh.set_nodes(name, nodes);
        }
        cell_sets
    }

    /// Physical surfaces: a face set of each in `mesh` (its boundary faces re-oriented
    /// outward from their cell) and a node set of the nodes of all its faces; `new_id` maps
    /// file nodes to mesh nodes.
    fn surface_sets(&self, new_id: &[usize], mesh: &mut Mesh) -> Result<(), GmshError> {
        let owners = mesh.cell_faces();
        let mut faces: BTreeMap<String, (Vec<Face>, Vec<usize>)> = BTreeMap::new();
        let surface = self
            .surfaces
            .iter()
            .flat_map(|b| b.elements.iter().map(|e| (e.tag, e.entity, &e.nodes[..])));
        for (tag, entity, nodes) in surface {
            if self.groups(2, entity).next().is_none()
                || nodes.iter().any(|&i| new_id[i] == usize::MAX)
            {
                continue;
            }
            let local: Vec<usize> = nodes.iter().map(|&i| new_id[i]).collect();
            let mut key = local.clone();
            key.sort_unstable();
            let outward = match owners.get(&key) {
                Some((1, f)) => Some(*f),
                Some(_) => None, // interior face: its nodes only
                None => {
                    return Err(self.err(format!(
                        "surface element {tag} of physical surface {} is not a face of any volume element of the body: the surface and volume meshes do not match (mesh them together)",
                        self.groups(2, entity).next().unwrap_or("?")
                    )))
                }
            };
            for g in self.groups(2, entity) {
                let e = faces.entry(g.to_string()).or_default();
                e.0.extend(outward);
                e.1.extend_from_slice(&local);
            }
        }
        for (name, (f, nodes)) in faces {
            mesh.face_sets.insert(name.clone(), f);
            mesh.set_nodes(&name, nodes);
        }
        Ok(())
    }

    /// Physical curves and points: a node set of each in `mesh`; `new_id` maps file nodes
    /// to mesh nodes.
    fn low_dim_sets(&self, new_id: &[usize], mesh: &mut Mesh) {
        let mut low: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        for (dim, entity, nodes) in &self.low_dim {
            if nodes.iter().any(|&i| new_id[i] == usize::MAX) {
                continue;
            }
            for g in self.groups(*dim, *entity) {
                low.entry(g.to_string())
                    .or_default()
                    .extend(nodes.iter().map(|&i| new_id[i]));
            }
        }
        for (name, nodes) in low {
            mesh.set_nodes(&name, nodes);
        }
    }
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names
            .iter()
            .map(|n| format!("{n:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::quality;

    /// One unit cube as a hex8 in Gmsh order, its bottom face a physical surface, as an
    /// ASCII MSH 4.1 file.
    const CUBE: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
2 1 \"bottom\"
3 2 \"cube\"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 1 0 1 1 0
1 0 0 0 1 1 1 1 2 1 1
$EndEntities
$Nodes
1 8 1 8
3 1 0 8
1
2
3
4
5
6
7
8
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
$EndNodes
$Elements
2 2 1 2
2 1 3 1
1 1 2 3 4
3 1 5 1
2 1 2 3 4 5 6 7 8
$EndElements
";

    fn parse_str(s: &str) -> Result<MshFile, GmshError> {
        parse(s.as_bytes(), Path::new("cube.msh"))
    }

    #[test]
    fn gmsh_hex_order_is_adhesim_order() {
        let msh = parse_str(CUBE).unwrap();
        let body = msh.body(None).unwrap();
        assert_eq!(body.mesh.hexes().len(), 1);
        assert!(quality::inverted_cells(&body.mesh).is_empty());
        assert!((quality::hex_volume(&body.mesh, 0) - 1.0).abs() < 1e-14);
        assert!((quality::cell_min_jacobian_ratio(&body.mesh)[0] - 1.0).abs() < 1e-14);
        // The bottom face comes out outward (−z) whatever its order in the file.
        assert_eq!(body.mesh.face_sets["bottom"].len(), 1);
        quality::check_faces_outward(&body.mesh).unwrap();
        assert_eq!(body.mesh.node_sets["bottom"], vec![0, 1, 2, 3]);
        assert_eq!(body.mesh.node_sets["cube"].len(), 8);
        assert_eq!(body.cell_sets["cube"], vec![0]);
        assert_eq!(body.cell_tags, vec![2]);
    }

    #[test]
    fn gmsh_tet_order_is_adhesim_order() {
        let text = CUBE.replace(
            "2 2 1 2\n2 1 3 1\n1 1 2 3 4\n3 1 5 1\n2 1 2 3 4 5 6 7 8",
            "1 1 1 1\n3 1 4 1\n1 1 2 4 5",
        );
        let body = parse_str(&text).unwrap().body(None).unwrap();
        assert_eq!(body.mesh.tets().len(), 1);
        assert_eq!(body.mesh.num_nodes(), 4);
        assert!(quality::inverted_cells(&body.mesh).is_empty());
    }

    #[test]
    fn binary_matches_ascii() {
        let ascii = parse_str(CUBE).unwrap();
        let mut b: Vec<u8> = b"$MeshFormat\n4.1 1 8\n".to_vec();
        b.extend(1i32.to_le_bytes());
        b.extend(b"\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"bottom\"\n3 2 \"cube\"\n$EndPhysicalNames\n$Entities\n");
        let size = |b: &mut Vec<u8>, v: u64| b.extend(v.to_le_bytes());
        let int = |b: &mut Vec<u8>, v: i32| b.extend(v.to_le_bytes());
        let dbl = |b: &mut Vec<u8>, v: f64| b.extend(v.to_le_bytes());
        for v in [0, 0, 1, 1] {
            size(&mut b, v);
        }
        for (tag, phys, bound) in [(1, 1, 0u64), (1, 2, 1)] {
            int(&mut b, tag);
            for v in [0.0, 0.0, 0.0, 1.0, 1.0, f64::from(phys - 1)] {
                dbl(&mut b, v);
            }
            size(&mut b, 1);
            int(&mut b, phys);
            size(&mut b, bound);
            if bound == 1 {
                int(&mut b, 1);
            }
        }
        b.extend(b"\n$EndEntities\n$Nodes\n");
        for v in [1, 8, 1, 8] {
            size(&mut b, v);
        }
        int(&mut b, 3);
        int(&mut b, 1);
        int(&mut b, 0);
        size(&mut b, 8);
        for t in 1..=8 {
            size(&mut b, t);
        }
        for p in &ascii.nodes {
            for &c in p {
                dbl(&mut b, c);
            }
        }
        b.extend(b"\n$EndNodes\n$Elements\n");
        for v in [2, 2, 1, 2] {
            size(&mut b, v);
        }
        for (dim, ty, tag, nodes) in [
            (2, 3, 1u64, &[1u64, 2, 3, 4][..]),
            (3, 5, 2, &[1, 2, 3, 4, 5, 6, 7, 8]),
        ] {
            int(&mut b, dim);
            int(&mut b, 1);
            int(&mut b, ty);
            size(&mut b, 1);
            size(&mut b, tag);
            for &n in nodes {
                size(&mut b, n);
            }
        }
        b.extend(b"\n$EndElements\n");
        let binary = parse(&b, Path::new("cube.msh")).unwrap();
        assert_eq!(binary, ascii);
        // Every truncation fails cleanly.
        for k in 0..b.len() - 1 {
            let _ = parse(&b[..k], Path::new("cube.msh"));
        }
        // Big-endian marker.
        let mut be = b.clone();
        be[20..24].copy_from_slice(&1i32.to_be_bytes());
        let e = parse(&be, Path::new("cube.msh")).unwrap_err();
        assert!(e.message.contains("big-endian"), "{e}");
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_str(&CUBE.replace("1 1 0\n0 1 0", "1 1 0\n0 nan 0")).unwrap_err();
        assert_eq!(e.location, Some(Location::Line(28)), "{e}");
        assert!(e.to_string().starts_with("cube.msh:28: "), "{e}");
        let e = parse_str(&CUBE.replace("3 1 5 1", "3 1 13 1")).unwrap_err();
        assert!(
            e.message
                .contains("prism18 (Gmsh type 13) is not supported")
                && e.message.contains("remesh with hexahedra or tetrahedra"),
            "{e}"
        );
        let e = parse_str(&CUBE.replace("1 2 3 4 5 6 7 8\n", "1 2 3 4 5 6 7 9\n")).unwrap_err();
        assert!(e.message.contains("node 9"), "{e}");
        let e = parse_str(&CUBE.replace("4.1 0 8", "2.2 0 8")).unwrap_err();
        assert!(e.message.contains("version 2.2"), "{e}");
        assert_eq!(e.location, Some(Location::Line(2)));
        for k in 0..CUBE.len() - 1 {
            assert!(parse_str(&CUBE[..k]).is_err(), "truncated at {k}");
        }
    }

    /// A hex8 and a hex20 in one file: refused, naming both types.
    #[test]
    fn mixed_orders_are_refused_naming_the_types() {
        let mixed = CUBE.replace("2 2 1 2\n", "3 3 1 3\n").replace(
            "$EndElements",
            "3 1 17 1\n3 1 2 3 4 5 6 7 8 1 2 3 4 5 6 7 8 1 2 3 4\n$EndElements",
        );
        let e = parse_str(&mixed).unwrap_err();
        assert!(
            e.message.contains("mixes first- and second-order")
                && e.message.contains("hex8 and hex20"),
            "{e}"
        );
    }

    #[test]
    fn selection_by_physical_volume() {
        let msh = parse_str(CUBE).unwrap();
        let e = msh.body(Some(&["finger".to_string()])).unwrap_err();
        assert!(e.message.contains("\"cube\""), "{e}");
        let body = msh.body(Some(&["cube".to_string()])).unwrap();
        assert_eq!(body.mesh.num_cells(), 1);
    }
}
