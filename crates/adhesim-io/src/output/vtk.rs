//! VTK XML output: unstructured grids (`.vtu`), multiblock files grouping them (`.vtm`,
//! [`write_vtm`]) and ParaView time collections (`.pvd`).
//!
//! # File format
//!
//! [`write_vtu`] writes a `VTKFile type="UnstructuredGrid"` with `byte_order="LittleEndian"`
//! and `header_type="UInt64"`. Every `DataArray` is inline `format="binary"`: the base64
//! encoding of one byte stream made of a little-endian `UInt64` byte count followed by the raw
//! little-endian values (header and data encoded together, as VTK itself does for
//! uncompressed data). Coordinates and real fields are `Float64`, integer fields `Int32`,
//! `connectivity` and `offsets` `Int64`, `types` `UInt8`.
//!
//! # Cell representation
//!
//! A [`Piece`] lists its cells as [`CellBlock`]s: each block is one [`CellKind`] and one flat
//! connectivity slice holding `kind.num_nodes()` point indices per cell, cell after cell, in
//! VTK's node order. A homogeneous mesh of 100 000 hexahedra is therefore a single block
//! borrowing one `&[usize]` of 800 000 indices; mixed meshes use one block per kind. No
//! per-cell allocation is needed and offsets are derived from the kinds. Cells are numbered
//! block after block, in order, and cell data arrays follow that numbering.
//!
//! # Several pieces
//!
//! A file may hold several pieces. The run's frames do not use this (they write one grid per
//! body and per contact surface, grouped by a `.vtm`, since meshio keeps only the cells of
//! the last piece and every piece must carry every array). Point and
//! cell indices are local to each piece. Readers (ParaView, meshio) expect every piece to
//! carry the same arrays, so the file gets the union of the field names of all pieces, in
//! order of first appearance; a piece lacking a field is padded with `NaN` (real fields) or
//! `-1` (integer fields). A name used with two different [`FieldData`] kinds is an error.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;

use super::atomic::{write_atomic, write_atomic_with};

/// Kind of a cell, with VTK's linear node ordering.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellKind {
    /// 4-node quadrilateral (`VTK_QUAD`, 9).
    Quad4,
    /// 3-node triangle (`VTK_TRIANGLE`, 5).
    Tri3,
    /// Single point (`VTK_VERTEX`, 1).
    Vertex,
    /// A volume element type of the element-type table ([`adhesim::element::ELEMENT_TYPES`]:
    /// hex8 is `VTK_HEXAHEDRON`, 12, tet4 `VTK_TETRA`, 10), with its VTK type and node count.
    Element(&'static adhesim::element::ElementType),
}

impl CellKind {
    /// The VTK cell type number.
    pub const fn vtk_type(self) -> u8 {
        match self {
            CellKind::Element(e) => e.vtk_type,
            CellKind::Quad4 => 9,
            CellKind::Tri3 => 5,
            CellKind::Vertex => 1,
        }
    }

    /// Number of nodes of one cell of this kind.
    pub const fn num_nodes(self) -> usize {
        match self {
            CellKind::Element(e) => e.nodes,
            CellKind::Quad4 => 4,
            CellKind::Tri3 => 3,
            CellKind::Vertex => 1,
        }
    }
}

/// Cells of one kind: `connectivity` holds `kind.num_nodes()` point indices per cell.
#[derive(Debug, Clone, Copy)]
pub struct CellBlock<'a> {
    /// Kind shared by every cell of the block.
    pub kind: CellKind,
    /// Point indices (into the piece's points), cell after cell.
    pub connectivity: &'a [usize],
}

impl CellBlock<'_> {
    /// Number of cells in the block (a trailing incomplete cell is not counted; writing
    /// rejects it).
    pub fn num_cells(&self) -> usize {
        self.connectivity.len() / self.kind.num_nodes()
    }
}

/// Values of one field, one entry per point (point data) or per cell (cell data).
#[derive(Debug, Clone, Copy)]
pub enum FieldData<'a> {
    /// One real number per entry.
    Scalar(&'a [f64]),
    /// A 3-vector per entry.
    Vector(&'a [[f64; 3]]),
    /// A 3×3 tensor per entry, row-major (`[xx, xy, xz, yx, yy, yz, zx, zy, zz]`).
    Tensor(&'a [[f64; 9]]),
    /// One integer per entry (ids, flags, contact status).
    Int(&'a [i32]),
}

impl FieldData<'_> {
    /// Number of entries (points or cells).
    pub fn len(&self) -> usize {
        match self {
            FieldData::Scalar(v) => v.len(),
            FieldData::Vector(v) => v.len(),
            FieldData::Tensor(v) => v.len(),
            FieldData::Int(v) => v.len(),
        }
    }

    /// Whether there are no entries.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Components per entry: 1 for `Scalar` and `Int`, 3 for `Vector`, 9 for `Tensor`.
    pub fn num_components(&self) -> usize {
        self.kind().components()
    }

    fn kind(&self) -> FieldKind {
        match self {
            FieldData::Scalar(_) => FieldKind::Scalar,
            FieldData::Vector(_) => FieldKind::Vector,
            FieldData::Tensor(_) => FieldKind::Tensor,
            FieldData::Int(_) => FieldKind::Int,
        }
    }
}

/// One piece of an unstructured grid: points, cells and the fields defined on them.
#[derive(Debug, Clone, Default)]
pub struct Piece<'a> {
    /// Point coordinates.
    pub points: &'a [[f64; 3]],
    /// Cells, block after block (see the module documentation).
    pub cells: Vec<CellBlock<'a>>,
    /// Named point fields, each with `points.len()` entries.
    pub point_data: Vec<(&'a str, FieldData<'a>)>,
    /// Named cell fields, each with [`Piece::num_cells`] entries.
    pub cell_data: Vec<(&'a str, FieldData<'a>)>,
}

impl<'a> Piece<'a> {
    /// A piece with the given points and no cells or fields yet.
    pub fn new(points: &'a [[f64; 3]]) -> Self {
        Piece {
            points,
            ..Piece::default()
        }
    }

    /// Adds a block of cells of one kind (builder style).
    pub fn with_cells(mut self, kind: CellKind, connectivity: &'a [usize]) -> Self {
        self.cells.push(CellBlock { kind, connectivity });
        self
    }

    /// Adds a point field (builder style).
    pub fn with_point_data(mut self, name: &'a str, data: FieldData<'a>) -> Self {
        self.point_data.push((name, data));
        self
    }

    /// Adds a cell field (builder style).
    pub fn with_cell_data(mut self, name: &'a str, data: FieldData<'a>) -> Self {
        self.cell_data.push((name, data));
        self
    }

    /// Total number of cells over all blocks.
    pub fn num_cells(&self) -> usize {
        self.cells.iter().map(CellBlock::num_cells).sum()
    }
}

/// Writes `pieces` to `path` as one VTK XML unstructured grid file, atomically.
///
/// The input is checked before anything is written; inconsistent input (connectivity length
/// not a multiple of the node count, point index out of range, field length not matching the
/// number of points or cells, empty or duplicate field names, a field name used with two
/// kinds, no piece at all) is an [`io::ErrorKind::InvalidInput`] error naming `path`, and the
/// existing file is left untouched.
pub fn write_vtu(path: &Path, pieces: &[Piece]) -> io::Result<()> {
    let layout = Layout::check(path, pieces)?;
    write_atomic_with(path, |w| write_vtu_body(w, pieces, &layout))
}

/// Kind of a field, used to merge field lists across pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FieldKind {
    Scalar,
    Vector,
    Tensor,
    Int,
}

impl FieldKind {
    fn components(self) -> usize {
        match self {
            FieldKind::Scalar | FieldKind::Int => 1,
            FieldKind::Vector => 3,
            FieldKind::Tensor => 9,
        }
    }

    fn name(self) -> &'static str {
        match self {
            FieldKind::Scalar => "scalar",
            FieldKind::Vector => "vector",
            FieldKind::Tensor => "tensor",
            FieldKind::Int => "integer",
        }
    }
}

/// The validated shape of a file: the merged field lists.
struct Layout<'a> {
    point_fields: Vec<(&'a str, FieldKind)>,
    cell_fields: Vec<(&'a str, FieldKind)>,
}

impl<'a> Layout<'a> {
    fn check(path: &Path, pieces: &'a [Piece<'a>]) -> io::Result<Self> {
        let err = |msg: String| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{}: {msg}", path.display()),
            )
        };
        if pieces.is_empty() {
            return Err(err("a VTU file needs at least one piece".into()));
        }
        let mut layout = Layout {
            point_fields: Vec::new(),
            cell_fields: Vec::new(),
        };
        for (p, piece) in pieces.iter().enumerate() {
            let n_points = piece.points.len();
            for (b, block) in piece.cells.iter().enumerate() {
                let nn = block.kind.num_nodes();
                if block.connectivity.len() % nn != 0 {
                    return Err(err(format!(
                        "piece {p}, cell block {b} ({:?}): connectivity length {} is not a \
                         multiple of {nn}",
                        block.kind,
                        block.connectivity.len()
                    )));
                }
                if let Some(pos) = block.connectivity.iter().position(|&i| i >= n_points) {
                    return Err(err(format!(
                        "piece {p}, cell block {b}: cell {} refers to point {} but the piece \
                         has {n_points} points",
                        pos / nn,
                        block.connectivity[pos]
                    )));
                }
            }
            let n_cells = piece.num_cells();
            for (what, fields, expected, merged) in [
                (
                    "point",
                    &piece.point_data,
                    n_points,
                    &mut layout.point_fields,
                ),
                ("cell", &piece.cell_data, n_cells, &mut layout.cell_fields),
            ] {
                for (k, (name, data)) in fields.iter().enumerate() {
                    check_name(name).map_err(|m| err(format!("piece {p}, {what} field: {m}")))?;
                    if fields[..k].iter().any(|(other, _)| other == name) {
                        return Err(err(format!(
                            "piece {p}: duplicate {what} field name {name:?}"
                        )));
                    }
                    if data.len() != expected {
                        return Err(err(format!(
                            "piece {p}: {what} field {name:?} has {} entries, expected \
                             {expected} (one per {what})",
                            data.len()
                        )));
                    }
                    match merged.iter().find(|(other, _)| other == name) {
                        Some((_, kind)) if *kind != data.kind() => {
                            return Err(err(format!(
                                "{what} field {name:?} is {} in piece {p} but {} in an earlier \
                                 piece",
                                data.kind().name(),
                                kind.name()
                            )));
                        }
                        Some(_) => {}
                        None => merged.push((name, data.kind())),
                    }
                }
            }
        }
        Ok(layout)
    }
}

/// Rejects names that cannot be stored in an XML attribute or are empty.
fn check_name(name: &str) -> Result<(), String> {
    if name.is_empty() {
        return Err("empty field name".into());
    }
    if name.chars().any(|c| c.is_control()) {
        return Err(format!("field name {name:?} contains a control character"));
    }
    Ok(())
}

fn write_vtu_body(w: &mut dyn Write, pieces: &[Piece], layout: &Layout) -> io::Result<()> {
    w.write_all(
        b"<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
          byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n",
    )?;
    let mut scratch = Vec::with_capacity(CHUNK);
    for piece in pieces {
        let n_cells = piece.num_cells();
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{n_cells}\">",
            piece.points.len()
        )?;
        for (tag, merged, fields, n) in [
            (
                "PointData",
                &layout.point_fields,
                &piece.point_data,
                piece.points.len(),
            ),
            ("CellData", &layout.cell_fields, &piece.cell_data, n_cells),
        ] {
            writeln!(w, "      <{tag}>")?;
            for &(name, kind) in merged {
                let data = fields.iter().find(|(n, _)| *n == name).map(|(_, d)| *d);
                write_field(w, &mut scratch, name, kind, data, n)?;
            }
            writeln!(w, "      </{tag}>")?;
        }
        w.write_all(b"      <Points>\n")?;
        open_array(w, "Float64", "Points", 3)?;
        encode(
            w,
            &mut scratch,
            piece.points.len() * 3,
            piece.points.iter().flatten().copied(),
        )?;
        w.write_all(b"</DataArray>\n      </Points>\n      <Cells>\n")?;
        let n_conn: usize = piece.cells.iter().map(|b| b.connectivity.len()).sum();
        open_array(w, "Int64", "connectivity", 1)?;
        let conn = piece
            .cells
            .iter()
            .flat_map(|b| b.connectivity.iter().map(|&i| i as i64));
        encode(w, &mut scratch, n_conn, conn)?;
        w.write_all(b"</DataArray>\n")?;
        open_array(w, "Int64", "offsets", 1)?;
        let offsets = piece
            .cells
            .iter()
            .flat_map(|b| std::iter::repeat_n(b.kind.num_nodes() as i64, b.num_cells()))
            .scan(0i64, |end, n| {
                *end += n;
                Some(*end)
            });
        encode(w, &mut scratch, n_cells, offsets)?;
        w.write_all(b"</DataArray>\n")?;
        open_array(w, "UInt8", "types", 1)?;
        let types = piece
            .cells
            .iter()
            .flat_map(|b| std::iter::repeat_n(b.kind.vtk_type(), b.num_cells()));
        encode(w, &mut scratch, n_cells, types)?;
        w.write_all(b"</DataArray>\n      </Cells>\n    </Piece>\n")?;
    }
    w.write_all(b"  </UnstructuredGrid>\n</VTKFile>\n")
}

/// Writes one field array, or its padding when the piece does not define it.
fn write_field(
    w: &mut dyn Write,
    scratch: &mut Vec<u8>,
    name: &str,
    kind: FieldKind,
    data: Option<FieldData>,
    n: usize,
) -> io::Result<()> {
    let ty = if kind == FieldKind::Int {
        "Int32"
    } else {
        "Float64"
    };
    open_array(w, ty, name, kind.components())?;
    let count = n * kind.components();
    match data {
        Some(FieldData::Scalar(v)) => encode(w, scratch, count, v.iter().copied())?,
        Some(FieldData::Vector(v)) => encode(w, scratch, count, v.iter().flatten().copied())?,
        Some(FieldData::Tensor(v)) => encode(w, scratch, count, v.iter().flatten().copied())?,
        Some(FieldData::Int(v)) => encode(w, scratch, count, v.iter().copied())?,
        None if kind == FieldKind::Int => {
            encode(w, scratch, count, std::iter::repeat_n(-1i32, count))?
        }
        None => encode(w, scratch, count, std::iter::repeat_n(f64::NAN, count))?,
    }
    w.write_all(b"</DataArray>\n")
}

/// Writes the opening `<DataArray ...>` tag (the base64 text follows it directly).
fn open_array(w: &mut dyn Write, ty: &str, name: &str, components: usize) -> io::Result<()> {
    let mut tag = String::with_capacity(96);
    let _ = write!(tag, "        <DataArray type=\"{ty}\" Name=\"");
    push_escaped(&mut tag, name);
    tag.push('"');
    if components != 1 {
        let _ = write!(tag, " NumberOfComponents=\"{components}\"");
    }
    tag.push_str(" format=\"binary\">");
    w.write_all(tag.as_bytes())
}

/// Size of the staging buffer for raw bytes on their way to the base64 encoder.
const CHUNK: usize = 1 << 15;

/// A value stored little-endian in a binary data array.
trait LeValue: Copy {
    const SIZE: usize;
    fn put(self, out: &mut Vec<u8>);
}

impl LeValue for f64 {
    const SIZE: usize = 8;
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl LeValue for i64 {
    const SIZE: usize = 8;
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl LeValue for i32 {
    const SIZE: usize = 4;
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl LeValue for u8 {
    const SIZE: usize = 1;
    fn put(self, out: &mut Vec<u8>) {
        out.push(self);
    }
}

/// Base64-encodes the `UInt64` byte-count header followed by `count` values, streaming.
fn encode<T: LeValue>(
    w: &mut dyn Write,
    scratch: &mut Vec<u8>,
    count: usize,
    values: impl Iterator<Item = T>,
) -> io::Result<()> {
    let mut enc = EncoderWriter::new(w, &STANDARD);
    scratch.clear();
    scratch.extend_from_slice(&((count * T::SIZE) as u64).to_le_bytes());
    let mut written = 0usize;
    for v in values {
        v.put(scratch);
        written += 1;
        if scratch.len() + 8 > CHUNK {
            enc.write_all(scratch)?;
            scratch.clear();
        }
    }
    debug_assert_eq!(written, count, "array length disagrees with its header");
    enc.write_all(scratch)?;
    scratch.clear();
    enc.finish()?;
    Ok(())
}

/// Appends `s` with the five XML special characters escaped.
fn push_escaped(out: &mut String, s: &str) {
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
}

/// One data set of a ParaView collection.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PvdEntry {
    /// Simulation time.
    pub time: f64,
    /// Path of the data file, relative to the `.pvd` file's directory.
    pub file: String,
}

/// A ParaView collection (`.pvd`) listing one data file per output time.
///
/// The file is rewritten atomically on every [`PvdWriter::push`], so it is always a complete,
/// valid collection of the files written so far, even if the run is killed.
#[derive(Debug)]
pub struct PvdWriter {
    path: PathBuf,
    entries: Vec<PvdEntry>,
}

impl PvdWriter {
    /// Starts a collection at `path` and writes it (empty) right away.
    pub fn new(path: impl Into<PathBuf>) -> io::Result<Self> {
        let writer = PvdWriter {
            path: path.into(),
            entries: Vec::new(),
        };
        writer.rewrite()?;
        Ok(writer)
    }

    /// Continues a collection at `path` with `entries` already written (a resumed run) and
    /// rewrites it with exactly those entries.
    pub fn with_entries(path: impl Into<PathBuf>, entries: Vec<PvdEntry>) -> io::Result<Self> {
        let writer = PvdWriter {
            path: path.into(),
            entries,
        };
        writer.rewrite()?;
        Ok(writer)
    }

    /// Appends the data file `file` (relative to the `.pvd` file's directory) for `time` and
    /// rewrites the collection.
    ///
    /// A non-finite time or a path that is not valid UTF-8 is an
    /// [`io::ErrorKind::InvalidInput`] error. If rewriting fails the entry is not kept, so the
    /// writer's entries always match the file on disk.
    pub fn push(&mut self, time: f64, file: impl AsRef<Path>) -> io::Result<()> {
        let file = file.as_ref();
        let invalid = |msg: String| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{}: {msg}", self.path.display()),
            )
        };
        if !time.is_finite() {
            return Err(invalid(format!("time {time} is not finite")));
        }
        let file = file
            .to_str()
            .ok_or_else(|| invalid(format!("{} is not valid UTF-8", file.display())))?;
        check_name(file).map_err(|_| invalid(format!("bad data file name {file:?}")))?;
        self.entries.push(PvdEntry {
            time,
            file: file.to_owned(),
        });
        if let Err(e) = self.rewrite() {
            self.entries.pop();
            return Err(e);
        }
        Ok(())
    }

    /// The entries written so far, in push order.
    pub fn entries(&self) -> &[PvdEntry] {
        &self.entries
    }

    /// The collection file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn rewrite(&self) -> io::Result<()> {
        let mut xml = String::with_capacity(200 + 80 * self.entries.len());
        xml.push_str(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
             byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for e in &self.entries {
            xml.push_str("    <DataSet timestep=\"");
            push_time(&mut xml, e.time);
            xml.push_str("\" group=\"\" part=\"0\" file=\"");
            push_escaped(&mut xml, &e.file);
            xml.push_str("\"/>\n");
        }
        xml.push_str("  </Collection>\n</VTKFile>\n");
        write_atomic(&self.path, xml.as_bytes())
    }
}

/// One group of a multiblock file: a name and its data sets, each a name and a file path
/// relative to the `.vtm` file's directory.
#[derive(Debug, Clone, PartialEq)]
pub struct VtmGroup {
    /// Name of the group (shown in ParaView's pipeline browser).
    pub name: String,
    /// (data set name, file) pairs.
    pub datasets: Vec<(String, String)>,
}

/// Writes a VTK XML multiblock file (`vtkMultiBlockDataSet`, `.vtm`) at `path`, atomically:
/// one `Block` per group, holding one `DataSet` per file. Every file is written before the
/// `.vtm` that lists it, so a `.vtm` on disk never lists a missing file.
///
/// An empty or control-character name or file is an [`io::ErrorKind::InvalidInput`] error
/// naming `path`.
pub fn write_vtm(path: &Path, groups: &[VtmGroup]) -> io::Result<()> {
    let invalid = |msg: String| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}: {msg}", path.display()),
        )
    };
    let mut xml = String::with_capacity(300 + 120 * groups.len());
    xml.push_str(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <vtkMultiBlockDataSet>\n",
    );
    for (g, group) in groups.iter().enumerate() {
        check_name(&group.name).map_err(|m| invalid(format!("group {g}: {m}")))?;
        let _ = write!(xml, "    <Block index=\"{g}\" name=\"");
        push_escaped(&mut xml, &group.name);
        xml.push_str("\">\n");
        for (d, (name, file)) in group.datasets.iter().enumerate() {
            check_name(name).map_err(|m| invalid(format!("group {g}, data set {d}: {m}")))?;
            check_name(file).map_err(|m| invalid(format!("group {g}, data set {d}: {m}")))?;
            let _ = write!(xml, "      <DataSet index=\"{d}\" name=\"");
            push_escaped(&mut xml, name);
            xml.push_str("\" file=\"");
            push_escaped(&mut xml, file);
            xml.push_str("\"/>\n");
        }
        xml.push_str("    </Block>\n");
    }
    xml.push_str("  </vtkMultiBlockDataSet>\n</VTKFile>\n");
    write_atomic(path, xml.as_bytes())
}

/// Appends a finite time in shortest round-trip form, with an exponent for extreme
/// magnitudes.
fn push_time(out: &mut String, t: f64) {
    let a = t.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) {
        let _ = write!(out, "{t}");
    } else {
        let _ = write!(out, "{t:e}");
    }
}

#[cfg(test)]
mod tests {
    use super::super::atomic::test_support::TestDir;
    use super::*;
    use adhesim::element::{HEX8, TET4};
    use base64::Engine as _;

    /// A parsed XML element (test-only, strict subset of XML: no comments, CDATA or DTD).
    #[derive(Debug)]
    struct Elem {
        name: String,
        attrs: Vec<(String, String)>,
        children: Vec<Elem>,
        text: String,
    }

    impl Elem {
        fn attr(&self, key: &str) -> &str {
            self.attrs
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v.as_str())
                .unwrap_or_else(|| panic!("<{}> has no attribute {key}", self.name))
        }

        fn child(&self, name: &str) -> &Elem {
            let found: Vec<&Elem> = self.children.iter().filter(|c| c.name == name).collect();
            assert_eq!(found.len(), 1, "<{}> must have one <{name}>", self.name);
            found[0]
        }

        fn children_named<'s>(&'s self, name: &'s str) -> impl Iterator<Item = &'s Elem> {
            self.children.iter().filter(move |c| c.name == name)
        }
    }

    fn unescape(s: &str) -> String {
        let out = s
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&quot;", "\"")
            .replace("&apos;", "'");
        assert!(
            !out.replace("&amp;", "").contains('&'),
            "unknown entity in {s:?}"
        );
        out.replace("&amp;", "&")
    }

    /// Parses a whole document; panics on anything malformed (unbalanced tags, unquoted
    /// attributes, stray `<`, trailing content).
    fn parse_xml(doc: &str) -> Elem {
        let rest = doc
            .strip_prefix("<?xml version=\"1.0\"?>")
            .expect("XML declaration");
        let mut pos = 0;
        let root = parse_elem(rest, &mut pos);
        assert!(rest[pos..].trim().is_empty(), "content after the root");
        root
    }

    fn parse_elem(s: &str, pos: &mut usize) -> Elem {
        let skip_ws = |pos: &mut usize| {
            while s[*pos..].starts_with(|c: char| c.is_ascii_whitespace()) {
                *pos += 1;
            }
        };
        skip_ws(pos);
        assert!(s[*pos..].starts_with('<'), "expected a tag at {}", *pos);
        *pos += 1;
        let name_len = s[*pos..]
            .find(|c: char| c.is_ascii_whitespace() || c == '>' || c == '/')
            .expect("tag name");
        let name = s[*pos..*pos + name_len].to_string();
        assert!(!name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric()));
        *pos += name_len;
        let mut attrs = Vec::new();
        loop {
            skip_ws(pos);
            if s[*pos..].starts_with("/>") {
                *pos += 2;
                return Elem {
                    name,
                    attrs,
                    children: vec![],
                    text: String::new(),
                };
            }
            if s[*pos..].starts_with('>') {
                *pos += 1;
                break;
            }
            let eq = s[*pos..].find('=').expect("attribute '='");
            let key = s[*pos..*pos + eq].to_string();
            assert!(key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'));
            *pos += eq + 1;
            assert!(s[*pos..].starts_with('"'), "attribute value must be quoted");
            let end = s[*pos + 1..].find('"').expect("closing quote");
            let raw = &s[*pos + 1..*pos + 1 + end];
            assert!(!raw.contains('<'), "'<' in attribute value");
            assert!(
                attrs.iter().all(|(k, _): &(String, String)| *k != key),
                "duplicate attribute {key}"
            );
            attrs.push((key, unescape(raw)));
            *pos += end + 2;
        }
        let mut children = Vec::new();
        let mut text = String::new();
        loop {
            let lt = s[*pos..].find('<').expect("closing tag");
            text.push_str(&s[*pos..*pos + lt]);
            *pos += lt;
            if s[*pos..].starts_with("</") {
                let close = format!("</{name}>");
                assert!(
                    s[*pos..].starts_with(&close),
                    "mismatched close of <{name}>"
                );
                *pos += close.len();
                return Elem {
                    name,
                    attrs,
                    children,
                    text: unescape(&text),
                };
            }
            children.push(parse_elem(s, pos));
        }
    }

    /// Decodes a binary DataArray, checking the UInt64 header against the payload length.
    fn decode(array: &Elem) -> Vec<u8> {
        assert_eq!(array.attr("format"), "binary");
        let bytes = STANDARD.decode(array.text.trim()).expect("valid base64");
        assert!(bytes.len() >= 8);
        let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
        assert_eq!(
            n,
            bytes.len() - 8,
            "header byte count of {}",
            array.attr("Name")
        );
        bytes[8..].to_vec()
    }

    fn decode_f64(a: &Elem) -> Vec<f64> {
        assert_eq!(a.attr("type"), "Float64");
        decode(a)
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn decode_i64(a: &Elem) -> Vec<i64> {
        assert_eq!(a.attr("type"), "Int64");
        decode(a)
            .chunks_exact(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn decode_i32(a: &Elem) -> Vec<i32> {
        assert_eq!(a.attr("type"), "Int32");
        decode(a)
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn array<'e>(parent: &'e Elem, name: &str) -> &'e Elem {
        let found: Vec<&Elem> = parent
            .children_named("DataArray")
            .filter(|a| a.attr("Name") == name)
            .collect();
        assert_eq!(found.len(), 1, "array {name}");
        found[0]
    }

    /// Two hexahedra sharing a face, then the data used on them.
    struct Fixture {
        hex_points: Vec<[f64; 3]>,
        hex_conn: Vec<usize>,
        temperature: Vec<f64>,
        displacement: Vec<[f64; 3]>,
        stress: Vec<[f64; 9]>,
        material: Vec<i32>,
        quad_points: Vec<[f64; 3]>,
        quad_conn: Vec<usize>,
        vertex_conn: Vec<usize>,
        pressure: Vec<f64>,
        status: Vec<i32>,
    }

    fn fixture() -> Fixture {
        let mut hex_points = Vec::new();
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..3 {
                    hex_points.push([i as f64 * 0.5, j as f64 * 0.25, k as f64 * 0.1 + 1e-300]);
                }
            }
        }
        let id = |i: usize, j: usize, k: usize| i + 3 * j + 6 * k;
        let mut hex_conn = Vec::new();
        for e in 0..2 {
            hex_conn.extend([
                id(e, 0, 0),
                id(e + 1, 0, 0),
                id(e + 1, 1, 0),
                id(e, 1, 0),
                id(e, 0, 1),
                id(e + 1, 0, 1),
                id(e + 1, 1, 1),
                id(e, 1, 1),
            ]);
        }
        let n = hex_points.len();
        Fixture {
            temperature: (0..n).map(|i| (i as f64 * 0.1).sin() / 3.0).collect(),
            displacement: (0..n)
                .map(|i| [i as f64 / 7.0, -(i as f64) * 1e-9, f64::MIN_POSITIVE])
                .collect(),
            stress: (0..2)
                .map(|e| std::array::from_fn(|c| (e * 9 + c) as f64 * std::f64::consts::PI))
                .collect(),
            material: vec![7, -3],
            hex_points,
            hex_conn,
            quad_points: vec![
                [0.0, 0.0, -0.5],
                [1.0, 0.0, -0.5],
                [1.0, 0.5, -0.5],
                [0.0, 0.5, -0.5],
                [0.5, 0.25, -0.5],
            ],
            quad_conn: vec![0, 1, 2, 3],
            vertex_conn: vec![4],
            pressure: vec![1.5e6, f64::NAN],
            status: vec![1, 2],
        }
    }

    fn pieces(f: &Fixture) -> Vec<Piece<'_>> {
        vec![
            Piece::new(&f.hex_points)
                .with_cells(CellKind::Element(&HEX8), &f.hex_conn)
                .with_point_data("temperature", FieldData::Scalar(&f.temperature))
                .with_point_data("u", FieldData::Vector(&f.displacement))
                .with_cell_data("stress", FieldData::Tensor(&f.stress))
                .with_cell_data("material", FieldData::Int(&f.material)),
            Piece::new(&f.quad_points)
                .with_cells(CellKind::Quad4, &f.quad_conn)
                .with_cells(CellKind::Vertex, &f.vertex_conn)
                .with_cell_data("pressure <p>", FieldData::Scalar(&f.pressure))
                .with_cell_data("material", FieldData::Int(&f.status)),
        ]
    }

    #[test]
    fn vtu_round_trips_bit_exactly() {
        let dir = TestDir::new("vtu-roundtrip");
        let path = dir.path().join("mesh.vtu");
        let f = fixture();
        write_vtu(&path, &pieces(&f)).unwrap();
        assert_eq!(dir.entries(), vec!["mesh.vtu".to_string()]);

        let doc = std::fs::read_to_string(&path).unwrap();
        let root = parse_xml(&doc);
        assert_eq!(root.name, "VTKFile");
        assert_eq!(root.attr("type"), "UnstructuredGrid");
        assert_eq!(root.attr("header_type"), "UInt64");
        assert_eq!(root.attr("byte_order"), "LittleEndian");
        let grid = root.child("UnstructuredGrid");
        let ps: Vec<&Elem> = grid.children_named("Piece").collect();
        assert_eq!(ps.len(), 2);

        // Piece 0: two hexahedra.
        let p = ps[0];
        assert_eq!(p.attr("NumberOfPoints"), "12");
        assert_eq!(p.attr("NumberOfCells"), "2");
        let pts = p.child("Points").child("DataArray");
        assert_eq!(pts.attr("NumberOfComponents"), "3");
        let flat: Vec<f64> = f.hex_points.iter().flatten().copied().collect();
        assert_eq!(bits(&decode_f64(pts)), bits(&flat));
        let cells = p.child("Cells");
        let conn: Vec<i64> = f.hex_conn.iter().map(|&i| i as i64).collect();
        assert_eq!(decode_i64(array(cells, "connectivity")), conn);
        assert_eq!(decode_i64(array(cells, "offsets")), vec![8, 16]);
        let types = array(cells, "types");
        assert_eq!(types.attr("type"), "UInt8");
        assert_eq!(decode(types), vec![12, 12]);

        let pd = p.child("PointData");
        assert_eq!(
            bits(&decode_f64(array(pd, "temperature"))),
            bits(&f.temperature)
        );
        let u = array(pd, "u");
        assert_eq!(u.attr("NumberOfComponents"), "3");
        let flat: Vec<f64> = f.displacement.iter().flatten().copied().collect();
        assert_eq!(bits(&decode_f64(u)), bits(&flat));

        let cd = p.child("CellData");
        let names: Vec<&str> = cd
            .children_named("DataArray")
            .map(|a| a.attr("Name"))
            .collect();
        assert_eq!(names, vec!["stress", "material", "pressure <p>"]);
        let s = array(cd, "stress");
        assert_eq!(s.attr("NumberOfComponents"), "9");
        let flat: Vec<f64> = f.stress.iter().flatten().copied().collect();
        assert_eq!(bits(&decode_f64(s)), bits(&flat));
        assert_eq!(decode_i32(array(cd, "material")), f.material);
        let pad = decode_f64(array(cd, "pressure <p>"));
        assert!(pad.len() == 2 && pad.iter().all(|v| v.is_nan()));

        // Piece 1: a quad and a vertex; point fields of piece 0 padded.
        let p = ps[1];
        assert_eq!(p.attr("NumberOfPoints"), "5");
        assert_eq!(p.attr("NumberOfCells"), "2");
        let cells = p.child("Cells");
        assert_eq!(
            decode_i64(array(cells, "connectivity")),
            vec![0, 1, 2, 3, 4]
        );
        assert_eq!(decode_i64(array(cells, "offsets")), vec![4, 5]);
        assert_eq!(decode(array(cells, "types")), vec![9, 1]);
        let pd = p.child("PointData");
        let t = decode_f64(array(pd, "temperature"));
        assert!(t.len() == 5 && t.iter().all(|v| v.is_nan()));
        assert_eq!(decode_f64(array(pd, "u")).len(), 15);
        let cd = p.child("CellData");
        assert_eq!(
            bits(&decode_f64(array(cd, "pressure <p>"))),
            bits(&f.pressure)
        );
        assert_eq!(decode_i32(array(cd, "material")), f.status);
        assert_eq!(decode_f64(array(cd, "stress")).len(), 18);
    }

    #[test]
    fn large_mesh_is_streamed_correctly() {
        let dir = TestDir::new("vtu-large");
        let path = dir.path().join("big.vtu");
        let n_cells = 20_000;
        let points: Vec<[f64; 3]> = (0..n_cells + 3).map(|i| [i as f64, 0.5, -1.0]).collect();
        let conn: Vec<usize> = (0..n_cells)
            .flat_map(|c| [c, c + 1, c + 2, c + 3])
            .collect();
        let ids: Vec<i32> = (0..n_cells as i32).collect();
        let piece = Piece::new(&points)
            .with_cells(CellKind::Element(&TET4), &conn)
            .with_cell_data("id", FieldData::Int(&ids));
        write_vtu(&path, &[piece]).unwrap();
        let root = parse_xml(&std::fs::read_to_string(&path).unwrap());
        let p = root.child("UnstructuredGrid").child("Piece");
        let cells = p.child("Cells");
        let conn64: Vec<i64> = conn.iter().map(|&i| i as i64).collect();
        assert_eq!(decode_i64(array(cells, "connectivity")), conn64);
        let offsets = decode_i64(array(cells, "offsets"));
        assert_eq!(offsets.len(), n_cells);
        assert_eq!(*offsets.last().unwrap(), 4 * n_cells as i64);
        assert_eq!(decode_i32(array(p.child("CellData"), "id")), ids);
        let flat: Vec<f64> = points.iter().flatten().copied().collect();
        assert_eq!(decode_f64(p.child("Points").child("DataArray")), flat);
    }

    #[test]
    fn invalid_input_is_rejected_before_writing() {
        let dir = TestDir::new("vtu-invalid");
        let path = dir.path().join("m.vtu");
        std::fs::write(&path, "previous").unwrap();
        let f = fixture();
        let short = [1.0; 3];
        let bad_conn = [0usize, 1, 2, 3, 4, 5, 6, 99];
        let odd_conn = [0usize, 1, 2];
        let cases: Vec<(Vec<Piece>, &str)> = vec![
            (vec![], "at least one piece"),
            (
                vec![Piece::new(&f.hex_points).with_cells(CellKind::Element(&HEX8), &bad_conn)],
                "point 99",
            ),
            (
                vec![Piece::new(&f.hex_points).with_cells(CellKind::Quad4, &odd_conn)],
                "not a multiple of 4",
            ),
            (
                vec![Piece::new(&f.hex_points).with_point_data("t", FieldData::Scalar(&short))],
                "has 3 entries, expected 12",
            ),
            (
                vec![Piece::new(&f.hex_points)
                    .with_cells(CellKind::Element(&HEX8), &f.hex_conn)
                    .with_cell_data("t", FieldData::Scalar(&short))],
                "has 3 entries, expected 2",
            ),
            (
                vec![Piece::new(&f.hex_points)
                    .with_point_data("t", FieldData::Scalar(&f.temperature))
                    .with_point_data("t", FieldData::Scalar(&f.temperature))],
                "duplicate",
            ),
            (
                vec![Piece::new(&f.hex_points)
                    .with_point_data("", FieldData::Scalar(&f.temperature))],
                "empty field name",
            ),
            (
                vec![
                    Piece::new(&f.hex_points)
                        .with_cells(CellKind::Element(&HEX8), &f.hex_conn)
                        .with_cell_data("m", FieldData::Int(&f.material)),
                    Piece::new(&f.quad_points)
                        .with_cells(CellKind::Quad4, &f.quad_conn)
                        .with_cells(CellKind::Vertex, &f.vertex_conn)
                        .with_cell_data("m", FieldData::Scalar(&f.pressure)),
                ],
                "is scalar in piece 1 but integer",
            ),
        ];
        for (ps, expected) in cases {
            let err = write_vtu(&path, &ps).unwrap_err();
            assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
            let msg = err.to_string();
            assert!(msg.contains("m.vtu") && msg.contains(expected), "{msg}");
        }
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "previous");
        assert_eq!(dir.entries(), vec!["m.vtu".to_string()]);
    }

    #[test]
    fn empty_piece_is_valid() {
        let dir = TestDir::new("vtu-empty");
        let path = dir.path().join("e.vtu");
        let none: [[f64; 3]; 0] = [];
        write_vtu(&path, &[Piece::new(&none)]).unwrap();
        let root = parse_xml(&std::fs::read_to_string(&path).unwrap());
        let p = root.child("UnstructuredGrid").child("Piece");
        assert_eq!(p.attr("NumberOfPoints"), "0");
        assert_eq!(p.attr("NumberOfCells"), "0");
        assert!(decode_i64(array(p.child("Cells"), "offsets")).is_empty());
    }

    #[test]
    fn pvd_lists_every_push_in_order_and_stays_valid() {
        let dir = TestDir::new("pvd");
        let path = dir.path().join("run.pvd");
        let mut pvd = PvdWriter::new(&path).unwrap();
        let root = parse_xml(&std::fs::read_to_string(&path).unwrap());
        assert_eq!(root.attr("type"), "Collection");
        assert_eq!(root.child("Collection").children.len(), 0);

        let times = [0.0, 1e-7, 0.25, 0.5, 1.0 / 3.0, 1e20];
        for (k, &t) in times.iter().enumerate() {
            pvd.push(t, format!("frames/step_{k:04}&\"x\".vtu"))
                .unwrap();
            let root = parse_xml(&std::fs::read_to_string(&path).unwrap());
            assert_eq!(root.name, "VTKFile");
            let sets: Vec<&Elem> = root.child("Collection").children_named("DataSet").collect();
            assert_eq!(sets.len(), k + 1);
            for (j, s) in sets.iter().enumerate() {
                let parsed: f64 = s.attr("timestep").parse().unwrap();
                assert_eq!(parsed.to_bits(), times[j].to_bits());
                assert_eq!(s.attr("file"), format!("frames/step_{j:04}&\"x\".vtu"));
                assert_eq!(s.attr("part"), "0");
            }
        }
        assert_eq!(pvd.entries().len(), times.len());
        assert!(pvd.push(f64::NAN, "x.vtu").is_err());
        assert_eq!(pvd.entries().len(), times.len());
        assert_eq!(dir.entries(), vec!["run.pvd".to_string()]);
    }

    #[test]
    fn pvd_in_missing_directory_reports_the_path() {
        let dir = TestDir::new("pvd-missing");
        let path = dir.path().join("nope").join("run.pvd");
        let err = PvdWriter::new(&path).unwrap_err();
        assert!(err.to_string().contains("run.pvd"), "{err}");
    }

    #[test]
    fn vtm_lists_groups_and_files_escaped_and_rejects_empty_names() {
        let dir = TestDir::new("vtm");
        let path = dir.path().join("frame.vtm");
        let groups = [
            VtmGroup {
                name: "bodies".into(),
                datasets: vec![("a<b".into(), "f_body0.vtu".into())],
            },
            VtmGroup {
                name: "contacts".into(),
                datasets: vec![("c\"d".into(), "f_contact0.vtu".into())],
            },
        ];
        write_vtm(&path, &groups).unwrap();
        let doc = parse_xml(&std::fs::read_to_string(&path).unwrap());
        assert_eq!(doc.attr("type"), "vtkMultiBlockDataSet");
        let blocks: Vec<_> = doc
            .child("vtkMultiBlockDataSet")
            .children_named("Block")
            .collect();
        assert_eq!(blocks.len(), 2);
        let sets: Vec<(String, String, String)> = blocks
            .iter()
            .flat_map(|b| b.children_named("DataSet"))
            .map(|d| {
                (
                    d.attr("index").into(),
                    unescape(d.attr("name")),
                    d.attr("file").into(),
                )
            })
            .collect();
        assert_eq!(
            sets,
            [
                ("0".into(), "a<b".into(), "f_body0.vtu".into()),
                ("0".into(), "c\"d".into(), "f_contact0.vtu".into())
            ]
        );
        let bad = [VtmGroup {
            name: "bodies".into(),
            datasets: vec![(String::new(), "x.vtu".into())],
        }];
        let err = write_vtm(&dir.path().join("bad.vtm"), &bad).unwrap_err();
        assert!(err.to_string().contains("bad.vtm"), "{err}");
        assert!(!dir.path().join("bad.vtm").exists());
    }

    /// Python expression for a list of floats (exact: Rust's `{:?}` round-trips).
    fn py_floats(v: impl IntoIterator<Item = f64>) -> String {
        let items: Vec<String> = v
            .into_iter()
            .map(|x| {
                if x.is_nan() {
                    "nan".to_string()
                } else {
                    format!("{x:?}")
                }
            })
            .collect();
        format!("np.array([{}])", items.join(", "))
    }

    /// Runs a Python check script on `path`; panics with its output if it fails.
    fn run_python(script: &str, path: &Path) -> String {
        let script = format!("import sys\nimport numpy as np\nnan = float('nan')\n{script}");
        let out = std::process::Command::new("python3")
            .arg("-c")
            .arg(&script)
            .arg(path)
            .output()
            .expect("run python3");
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "python check failed:\n{stdout}\n{stderr}"
        );
        stdout
    }

    /// The fixture's data as one piece: hexahedra, a quad and a vertex in three blocks.
    fn single_piece_arrays(f: &Fixture) -> (Vec<[f64; 3]>, Vec<usize>, Vec<f64>, Vec<i32>) {
        let mut points = f.hex_points.clone();
        points.extend(&f.quad_points);
        let shifted: Vec<usize> = f
            .quad_conn
            .iter()
            .chain(&f.vertex_conn)
            .map(|i| i + f.hex_points.len())
            .collect();
        let mut temperature = f.temperature.clone();
        temperature.extend([-1.0, -2.0, -3.0, -4.0, -5.0]);
        let mut material = f.material.clone();
        material.extend(&f.status);
        (points, shifted, temperature, material)
    }

    /// Reads a single-piece file with mixed cell blocks with meshio (`pip install meshio`).
    #[test]
    #[ignore = "needs python3 with meshio"]
    fn meshio_reads_a_mixed_piece() {
        let dir = TestDir::new("vtu-meshio-single");
        let path = dir.path().join("mesh.vtu");
        let f = fixture();
        let (points, surface_conn, temperature, material) = single_piece_arrays(&f);
        let piece = Piece::new(&points)
            .with_cells(CellKind::Element(&HEX8), &f.hex_conn)
            .with_cells(CellKind::Quad4, &surface_conn[..4])
            .with_cells(CellKind::Vertex, &surface_conn[4..])
            .with_point_data("temperature", FieldData::Scalar(&temperature))
            .with_cell_data("material", FieldData::Int(&material));
        write_vtu(&path, &[piece]).unwrap();
        let hex: Vec<String> = f.hex_conn.chunks(8).map(|c| format!("{c:?}")).collect();
        let script = format!(
            r#"
import meshio
m = meshio.read(sys.argv[1])
assert np.array_equal(m.points, {pts}.reshape(-1, 3)), m.points
assert [b.type for b in m.cells] == ["hexahedron", "quad", "vertex"], m.cells
assert m.cells[0].data.tolist() == [{hex}], m.cells[0].data
assert m.cells[1].data.tolist() == [[12, 13, 14, 15]], m.cells[1].data
assert m.cells[2].data.tolist() == [[16]], m.cells[2].data
assert np.array_equal(m.point_data["temperature"], {temp})
assert [a.tolist() for a in m.cell_data["material"]] == [[7, -3], [1], [2]]
print("meshio", meshio.__version__, "read", len(m.points), "points,", sum(len(b.data) for b in m.cells), "cells")
"#,
            pts = py_floats(points.iter().flatten().copied()),
            hex = hex.join(", "),
            temp = py_floats(temperature),
        );
        println!("{}", run_python(&script, &path));
    }

    /// Reads the two-piece fixture with meshio. meshio 5.3 merges the points and point data
    /// of all pieces but keeps only the cells of the last piece (meshio issue #1444), so
    /// cells are checked for that piece only.
    #[test]
    #[ignore = "needs python3 with meshio"]
    fn meshio_reads_a_multi_piece_file() {
        let dir = TestDir::new("vtu-meshio-multi");
        let path = dir.path().join("mesh.vtu");
        let f = fixture();
        write_vtu(&path, &pieces(&f)).unwrap();
        let mut points = f.hex_points.clone();
        points.extend(&f.quad_points);
        let mut temperature = f.temperature.clone();
        temperature.extend([f64::NAN; 5]);
        let script = format!(
            r#"
import meshio
m = meshio.read(sys.argv[1])
assert np.array_equal(m.points, {pts}.reshape(-1, 3)), m.points
assert np.array_equal(m.point_data["temperature"], {temp}, equal_nan=True)
assert m.point_data["u"].shape == (17, 3)
assert np.array_equal(m.point_data["u"][:12].ravel(), {u})
last = [(b.type, b.data.tolist()) for b in m.cells]
assert last[-2:] == [("quad", [[12, 13, 14, 15]]), ("vertex", [[16]])], last
print("meshio", meshio.__version__, "read", len(m.points), "points; cells:", last)
"#,
            pts = py_floats(points.iter().flatten().copied()),
            temp = py_floats(temperature),
            u = py_floats(f.displacement.iter().flatten().copied()),
        );
        println!("{}", run_python(&script, &path));
    }

    /// Reads the two-piece fixture with VTK's own XML reader, the one ParaView uses
    /// (`pip install vtk`). Any VTK error or warning fails the test.
    #[test]
    #[ignore = "needs python3 with the vtk package"]
    fn vtk_reader_reads_a_multi_piece_file() {
        let dir = TestDir::new("vtu-vtk");
        let path = dir.path().join("mesh.vtu");
        let f = fixture();
        write_vtu(&path, &pieces(&f)).unwrap();
        let mut points = f.hex_points.clone();
        points.extend(&f.quad_points);
        let mut temperature = f.temperature.clone();
        temperature.extend([f64::NAN; 5]);
        let mut stress: Vec<f64> = f.stress.iter().flatten().copied().collect();
        stress.extend([f64::NAN; 18]);
        let mut material = f.material.clone();
        material.extend(&f.status);
        let script = format!(
            r#"
import vtk
from vtk.util.numpy_support import vtk_to_numpy
problems = []
def complain(obj, event):
    problems.append(event)
reader = vtk.vtkXMLUnstructuredGridReader()
reader.AddObserver("ErrorEvent", complain)
reader.AddObserver("WarningEvent", complain)
reader.GetExecutive().AddObserver("ErrorEvent", complain)
reader.SetFileName(sys.argv[1])
reader.Update()
assert not problems, problems
g = reader.GetOutput()
assert g.GetNumberOfPoints() == 17, g.GetNumberOfPoints()
assert g.GetNumberOfCells() == 4, g.GetNumberOfCells()
assert [g.GetCellType(i) for i in range(4)] == [12, 12, 9, 1]
assert np.array_equal(vtk_to_numpy(g.GetPoints().GetData()), {pts}.reshape(-1, 3))
ids = [[g.GetCell(c).GetPointId(k) for k in range(g.GetCell(c).GetNumberOfPoints())] for c in range(4)]
assert ids[2] == [12, 13, 14, 15] and ids[3] == [16], ids
assert ids[0] + ids[1] == {hex:?}, ids
pd, cd = g.GetPointData(), g.GetCellData()
assert np.array_equal(vtk_to_numpy(pd.GetArray("temperature")), {temp}, equal_nan=True)
assert pd.GetArray("u").GetNumberOfComponents() == 3
s = cd.GetArray("stress")
assert s.GetNumberOfComponents() == 9 and s.GetDataTypeAsString() == "double"
assert np.array_equal(vtk_to_numpy(s).ravel(), {stress}, equal_nan=True)
m = cd.GetArray("material")
assert m.GetDataTypeAsString() == "int", m.GetDataTypeAsString()
assert vtk_to_numpy(m).tolist() == {material:?}
assert vtk_to_numpy(cd.GetArray("pressure <p>"))[2] == 1.5e6
print("VTK", vtk.vtkVersion.GetVTKVersion(), "read", g.GetNumberOfPoints(), "points,", g.GetNumberOfCells(), "cells from 2 pieces")
"#,
            pts = py_floats(points.iter().flatten().copied()),
            hex = f.hex_conn,
            temp = py_floats(temperature),
            stress = py_floats(stress),
        );
        println!("{}", run_python(&script, &path));
    }
}
