//! Output: observers that record a run (VTU/PVD frames, CSV history) and the low-level
//! writers they use. Observers only read the state the stepper hands them.

pub mod atomic;
pub mod csv;
pub mod figures;
pub mod maps;
pub mod plot;
pub mod settings;
pub mod vtk;

use crate::codec::{decode_with, encode_with, Codec};
use adhesim::assembly::Discretisation;
use adhesim::contact::history::{FieldKind, HistoryField, Slot};
use adhesim::contact::{Interface, Master, RigidShape};
use adhesim::element::von_mises;
use adhesim::problem::{Dirichlet, Problem};
use adhesim::time::{SiteContact, State, StepReport};
use settings::OutputSettings;
use std::io;
use std::path::{Path, PathBuf};

/// What an observer sees after every committed step (and once at t = 0 with a default
/// report).
pub struct StepView<'a> {
    /// The problem.
    pub problem: &'a Problem,
    /// Its discretisation.
    pub disc: &'a Discretisation,
    /// The committed state.
    pub state: &'a State,
    /// What the step did.
    pub report: &'a StepReport,
    /// Committed contact state per pair and contact site.
    pub contact: &'a [Vec<SiteContact>],
    /// Nodal reaction forces of the step [N], 3 per node, zero on free degrees of freedom
    /// (see [`adhesim::time::Stepper::reactions`]).
    pub reactions: &'a [f64],
}

/// Records a run. A run hands every committed step (and t = 0) to a list of observers
/// ([`start_observers`]); each saves what it needs to go on after a restart
/// ([`Observer::resume_state`]) and reads it back itself ([`resume_observers`]), so the
/// checkpoint stores the states without knowing what they hold.
pub trait Observer {
    /// Its name in a checkpoint, unique among a run's observers.
    fn key(&self) -> &'static str;

    /// Called at t = 0 and after every committed step.
    fn observe(&mut self, view: &StepView) -> io::Result<()>;

    /// What it needs to go on after a restart, in a byte format that only it reads back.
    fn resume_state(&self) -> Vec<u8>;

    /// VTU frames written so far (the run summary's count); 0 for observers that write none.
    fn frames_written(&self) -> usize {
        0
    }
}

/// An observer's resume state as a checkpoint keeps it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SavedObserver {
    /// [`Observer::key`] of the observer that saved it.
    pub key: String,
    /// Its [`Observer::resume_state`].
    pub state: Vec<u8>,
}

/// The state saved under `key` among `saved`, if any.
pub fn saved_state<'a>(saved: &'a [SavedObserver], key: &str) -> Option<&'a [u8]> {
    saved.iter().find(|s| s.key == key).map(|s| &s.state[..])
}

/// Key of the [`FrameWriter`].
pub const FRAMES_KEY: &str = "frames";
/// Key of the [`HistoryObserver`].
pub const HISTORY_KEY: &str = "history";
/// Key of the [`maps::MapObserver`].
pub const MAPS_KEY: &str = "maps";

/// How a run's observers begin.
#[derive(Clone, Copy, Debug)]
pub enum Begin<'a> {
    /// A new run: each observer creates its files.
    New,
    /// Going on from the states `saved` of a checkpoint taken at time `t` [s].
    Resume {
        /// The observers' states in the checkpoint.
        saved: &'a [SavedObserver],
        /// Simulated time of the checkpoint [s].
        t: f64,
    },
}

/// The state saved under `key` among a checkpoint's `saved` states, an error when there is
/// none.
fn required_state<'a>(saved: &'a [SavedObserver], key: &str) -> io::Result<&'a [u8]> {
    saved_state(saved, key).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("the checkpoint holds no resume state for the {key} output"),
        )
    })
}

/// The observers of every run in `dir`, in the order they see each step: the VTU frames,
/// history.csv and the contact maps, each begun as `begin` says. A new observer is one line
/// here. When resuming, a state that is missing (the maps' in checkpoints of earlier formats)
/// is rebuilt from the checkpoint's time where the observer can, and is an error where it
/// cannot.
pub fn observers(
    dir: &Path,
    problem: &Problem,
    output: &OutputSettings,
    begin: Begin,
) -> io::Result<Vec<Box<dyn Observer>>> {
    Ok(vec![
        Box::new(FrameWriter::begin(
            dir,
            &problem.name,
            output.frame_interval,
            begin,
        )?),
        Box::new(HistoryObserver::begin(
            &dir.join("history.csv"),
            problem,
            output,
            begin,
        )?),
        Box::new(maps::MapObserver::begin(dir, &output.maps, begin)?),
    ])
}

/// An observer's resume state that cannot be read, as an I/O error of kind InvalidData.
pub(crate) fn bad_state(key: &str, reason: String) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("the {key} output's resume state in the checkpoint is damaged: {reason}"),
    )
}

/// Writes a VTU frame per output interval and keeps the PVD collection up to date.
pub struct FrameWriter {
    dir: PathBuf,
    name: String,
    pvd: vtk::PvdWriter,
    interval: f64,
    next_time: f64,
    frames: usize,
}

impl FrameWriter {
    /// A writer in `dir` for the run `name` every `interval` [s]: new, or going on from its
    /// state in a checkpoint ([`FrameWriter::new`], [`FrameWriter::resume`]).
    pub fn begin(dir: &Path, name: &str, interval: f64, begin: Begin) -> io::Result<Self> {
        match begin {
            Begin::New => FrameWriter::new(dir, name, interval),
            Begin::Resume { saved, .. } => {
                FrameWriter::resume(dir, name, interval, required_state(saved, FRAMES_KEY)?)
            }
        }
    }

    /// Frame `NNNNN` is the multiblock file `DIR/vtu/<name>_NNNNN.vtm` over one grid per body,
    /// `DIR/vtu/<name>_NNNNN_body<i>.vtu`, and one per contact pair,
    /// `DIR/vtu/<name>_NNNNN_contact<j>.vtu`; the collection over time is `DIR/<name>.pvd`.
    pub fn new(dir: &Path, name: &str, interval: f64) -> io::Result<Self> {
        std::fs::create_dir_all(dir.join("vtu"))?;
        let pvd = vtk::PvdWriter::new(dir.join(format!("{name}.pvd")))?;
        Ok(FrameWriter {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            pvd,
            interval,
            next_time: 0.0,
            frames: 0,
        })
    }

    /// Number of frames written.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// How far the writer got.
    pub fn progress(&self) -> FrameProgress {
        FrameProgress {
            frames: self.frames,
            next_time: self.next_time,
            entries: self.pvd.entries().to_vec(),
        }
    }

    /// Continues a collection in `dir` from the resume state `state` ([`FrameProgress`]'s
    /// bytes): the PVD is rewritten with its entries, and frames numbered from its frame
    /// count on (left by the interrupted run after its checkpoint) are removed; they are
    /// written again as the run goes on.
    pub fn resume(dir: &Path, name: &str, interval: f64, state: &[u8]) -> io::Result<Self> {
        let progress =
            FrameProgress::from_bytes(state).map_err(|reason| bad_state(FRAMES_KEY, reason))?;
        let vtu = dir.join("vtu");
        std::fs::create_dir_all(&vtu)?;
        let prefix = format!("{name}_");
        for entry in std::fs::read_dir(&vtu)? {
            let file = entry?.file_name();
            let Some(file) = file.to_str() else { continue };
            let index = file.strip_prefix(&prefix).and_then(frame_file_index);
            if index.is_some_and(|i| i >= progress.frames) {
                std::fs::remove_file(vtu.join(file))?;
            }
        }
        let pvd = vtk::PvdWriter::with_entries(dir.join(format!("{name}.pvd")), progress.entries)?;
        Ok(FrameWriter {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            pvd,
            interval,
            next_time: progress.next_time,
            frames: progress.frames,
        })
    }
}

/// How far a [`FrameWriter`] got: its resume state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameProgress {
    /// Frames written.
    pub frames: usize,
    /// Time of the next frame [s].
    pub next_time: f64,
    /// Entries of the PVD collection.
    pub entries: Vec<vtk::PvdEntry>,
}

impl FrameProgress {
    /// Its fields in order through `c` (the layout that checkpoints up to format 6 held
    /// inline): frames, next time, then the PVD entries (time, file).
    pub(crate) fn visit(&mut self, c: &mut impl Codec) -> Result<(), String> {
        c.usize(&mut self.frames)?;
        c.f64(&mut self.next_time)?;
        c.count(&mut self.entries, 16)?;
        for e in &mut self.entries {
            c.f64(&mut e.time)?;
            c.str(&mut e.file)?;
        }
        Ok(())
    }

    /// Its bytes, the [`FrameWriter`]'s resume state.
    pub fn to_bytes(&self) -> Vec<u8> {
        encode_with(|e| self.clone().visit(e))
    }

    /// The progress whose [`FrameProgress::to_bytes`] are `bytes`; Err says what is wrong.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        decode_with(bytes, |d| {
            let mut p = FrameProgress::default();
            p.visit(d)?;
            Ok(p)
        })
    }
}

/// The frame number of a file name with the `<name>_` prefix removed: `NNNNN.vtm`,
/// `NNNNN.vtu` (single-file frames of earlier versions) or `NNNNN_<block>.vtu`, with at least
/// five digits; `None` for any other name.
fn frame_file_index(rest: &str) -> Option<usize> {
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    let (number, tail) = rest.split_at(digits);
    let known = tail == ".vtm"
        || tail == ".vtu"
        || (tail.starts_with('_') && tail.len() > 5 && tail.ends_with(".vtu"));
    if digits >= 5 && known {
        number.parse().ok()
    } else {
        None
    }
}

/// Per-body arrays of one frame.
struct BodyFrame {
    points: Vec<[f64; 3]>,
    /// The body's cell blocks: element type and connectivity.
    blocks: Vec<adhesim::mesh::CellBlock>,
    u: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    cauchy: Vec<[f64; 9]>,
    mises: Vec<f64>,
    jac: Vec<f64>,
    node_id: Vec<i32>,
    body_id: Vec<i32>,
}

fn body_frames(view: &StepView) -> Vec<BodyFrame> {
    let disc = view.disc;
    let (u, v) = (&view.state.u, &view.state.v);
    let offsets = &disc.node_offset;
    let mut out = Vec::new();
    let patches = disc.patch_state(u);
    for (bi, body) in view.problem.bodies.iter().enumerate() {
        let off = offsets[bi];
        let nn = body.mesh.num_nodes();
        let node_vec = |x: &[f64], i: usize| -> [f64; 3] {
            let g = off + i;
            [x[3 * g], x[3 * g + 1], x[3 * g + 2]]
        };
        let uu: Vec<[f64; 3]> = (0..nn).map(|i| node_vec(u, i)).collect();
        let vv: Vec<[f64; 3]> = (0..nn).map(|i| node_vec(v, i)).collect();
        let points = (0..nn)
            .map(|i| std::array::from_fn(|k| body.mesh.nodes[i][k] + uu[i][k]))
            .collect();
        let mut f = BodyFrame {
            points,
            blocks: body.mesh.blocks.clone(),
            u: uu,
            v: vv,
            cauchy: Vec::new(),
            mises: Vec::new(),
            jac: Vec::new(),
            node_id: (0..nn).map(|i| id_i32(off + i)).collect(),
            body_id: vec![id_i32(bi); body.mesh.num_cells()],
        };
        let mut push = |s: adhesim::Mat3, j: f64| {
            f.cauchy.push(std::array::from_fn(|k| s[(k / 3, k % 3)]));
            f.mises.push(von_mises(&s));
            f.jac.push(j);
        };
        for (k, block) in disc.blocks.iter().enumerate() {
            for e in 0..block.len() {
                if block.body(e) == bi {
                    let (s, j) = disc.cell_cauchy_stress(k, e, u, patches.as_ref());
                    push(s, j);
                }
            }
        }
        out.push(f);
    }
    out
}

impl Observer for FrameWriter {
    fn key(&self) -> &'static str {
        FRAMES_KEY
    }

    fn resume_state(&self) -> Vec<u8> {
        self.progress().to_bytes()
    }

    fn frames_written(&self) -> usize {
        self.frames
    }

    fn observe(&mut self, view: &StepView) -> io::Result<()> {
        let t = view.state.t;
        let last = t >= view.problem.time.t_end * (1.0 - 1e-12);
        if t + 1e-12 * view.problem.time.t_end < self.next_time && !last {
            return Ok(());
        }
        while self.next_time <= t + 1e-12 * view.problem.time.t_end {
            self.next_time += if self.interval > 0.0 {
                self.interval
            } else {
                f64::INFINITY
            };
        }
        let stem = format!("{}_{:05}", self.name, self.frames);
        let mut bodies = Vec::new();
        for (i, f) in body_frames(view).iter().enumerate() {
            let mut p = vtk::Piece::new(&f.points);
            for b in f.blocks.iter().filter(|b| !b.is_empty()) {
                p = p.with_cells(vtk::CellKind::Element(b.element), &b.connectivity);
            }
            let p = p
                .with_point_data("u", vtk::FieldData::Vector(&f.u))
                .with_point_data("v", vtk::FieldData::Vector(&f.v))
                .with_point_data("node_id", vtk::FieldData::Int(&f.node_id))
                .with_cell_data("cauchy", vtk::FieldData::Tensor(&f.cauchy))
                .with_cell_data("von_mises", vtk::FieldData::Scalar(&f.mises))
                .with_cell_data("J", vtk::FieldData::Scalar(&f.jac))
                .with_cell_data("body_id", vtk::FieldData::Int(&f.body_id));
            let file = format!("{stem}_body{i}.vtu");
            vtk::write_vtu(&self.dir.join("vtu").join(&file), &[p])?;
            bodies.push((view.problem.bodies[i].name.clone(), file));
        }
        let mut contacts = Vec::new();
        for (j, (pair, nodes)) in view.problem.contacts.iter().zip(view.contact).enumerate() {
            let c = contact_frame(j, pair, nodes, view);
            let history = history_columns_of(pair.law.history_fields(), nodes);
            let mut p = vtk::Piece::new(&c.points);
            if !c.quads.is_empty() {
                p = p.with_cells(vtk::CellKind::Quad4, &c.quads);
            }
            if !c.triangles.is_empty() {
                p = p.with_cells(vtk::CellKind::Tri3, &c.triangles);
            }
            if !c.vertices.is_empty() {
                p = p.with_cells(vtk::CellKind::Vertex, &c.vertices);
            }
            let p = p
                .with_point_data("node_id", vtk::FieldData::Int(&c.node_id))
                .with_point_data("area", vtk::FieldData::Scalar(&pair.slave_area));
            let p = with_history(p, &history, Slot::First)
                .with_point_data("rn", vtk::FieldData::Scalar(&c.rn))
                .with_point_data("rn_dry", vtk::FieldData::Scalar(&c.rn_dry))
                .with_point_data("rn_adh", vtk::FieldData::Scalar(&c.rn_adh))
                .with_point_data("rt", vtk::FieldData::Vector(&c.rt))
                .with_point_data("rt_adh", vtk::FieldData::Vector(&c.rt_adh))
                .with_point_data("contact_force", vtk::FieldData::Vector(&c.force))
                .with_point_data("pn", vtk::FieldData::Scalar(&c.pn))
                .with_point_data("pn_adh", vtk::FieldData::Scalar(&c.pn_adh))
                .with_point_data("tt", vtk::FieldData::Vector(&c.tt))
                .with_point_data("tt_adh", vtk::FieldData::Vector(&c.tt_adh))
                .with_point_data("traction", vtk::FieldData::Vector(&c.traction))
                .with_point_data("gap", vtk::FieldData::Scalar(&c.gap))
                .with_point_data("slip", vtk::FieldData::Scalar(&c.slip));
            let p = with_history(p, &history, Slot::Motion)
                .with_point_data("state", vtk::FieldData::Int(&c.state));
            let p = with_history(p, &history, Slot::Last)
                .with_cell_data("pair_id", vtk::FieldData::Int(&c.pair_id))
                .with_cell_data("body_id", vtk::FieldData::Int(&c.body_id));
            let file = format!("{stem}_contact{j}.vtu");
            vtk::write_vtu(&self.dir.join("vtu").join(&file), &[p])?;
            contacts.push((pair.name.clone(), file));
        }
        let mut groups = vec![vtk::VtmGroup {
            name: "bodies".into(),
            datasets: bodies,
        }];
        if !contacts.is_empty() {
            groups.push(vtk::VtmGroup {
                name: "contacts".into(),
                datasets: contacts,
            });
        }
        let rel = format!("vtu/{stem}.vtm");
        vtk::write_vtm(&self.dir.join(&rel), &groups)?;
        self.pvd.push(t, &rel)?;
        self.frames += 1;
        Ok(())
    }
}

/// A node, body or pair index as a VTK integer (indices beyond `i32::MAX` are not expected:
/// the mesh generator caps the number of cells far below).
fn id_i32(i: usize) -> i32 {
    i32::try_from(i).unwrap_or(i32::MAX)
}

/// Traction [Pa]: a nodal force [N] over the node's tributary area [m²] (0 for a node
/// without area).
pub fn traction(force: f64, area: f64) -> f64 {
    if area > 0.0 {
        force / area
    } else {
        0.0
    }
}

/// Point and cell data of one contact surface.
struct ContactFrame {
    points: Vec<[f64; 3]>,
    quads: Vec<usize>,
    triangles: Vec<usize>,
    vertices: Vec<usize>,
    node_id: Vec<i32>,
    rn: Vec<f64>,
    rn_dry: Vec<f64>,
    rn_adh: Vec<f64>,
    rt: Vec<[f64; 3]>,
    rt_adh: Vec<[f64; 3]>,
    force: Vec<[f64; 3]>,
    pn: Vec<f64>,
    pn_adh: Vec<f64>,
    tt: Vec<[f64; 3]>,
    tt_adh: Vec<[f64; 3]>,
    traction: Vec<[f64; 3]>,
    gap: Vec<f64>,
    slip: Vec<f64>,
    state: Vec<i32>,
    pair_id: Vec<i32>,
    body_id: Vec<i32>,
}

fn contact_frame(
    index: usize,
    pair: &adhesim::contact::ContactPair,
    nodes: &[SiteContact],
    view: &StepView,
) -> ContactFrame {
    let u = &view.state.u;
    let x = &view.disc.reference;
    let (mut quads, mut triangles) = (Vec::new(), Vec::new());
    let mut on_face = vec![false; pair.slave_nodes.len()];
    for q in &pair.slave_quads {
        if q[3] == q[2] {
            triangles.extend_from_slice(&q[..3]);
        } else {
            quads.extend_from_slice(q);
        }
        for &i in q {
            on_face[i] = true;
        }
    }
    let vertices: Vec<usize> = (0..on_face.len()).filter(|&i| !on_face[i]).collect();
    let n_cells = quads.len() / 4 + triangles.len() / 3 + vertices.len();
    let slave_body = pair.slave_nodes.first().map_or(0, |&n| {
        view.disc
            .node_offset
            .iter()
            .rposition(|&off| off <= n)
            .unwrap_or(0)
    });
    let area = &pair.slave_area;
    let per_area = |v: [f64; 3], a: f64| -> [f64; 3] { v.map(|c| traction(c, a)) };
    let mut f = ContactFrame {
        points: pair
            .slave_nodes
            .iter()
            .map(|&n| std::array::from_fn(|k| x[n][k] + u[3 * n + k]))
            .collect(),
        quads,
        triangles,
        vertices,
        node_id: pair.slave_nodes.iter().map(|&n| id_i32(n)).collect(),
        rn: nodes.iter().map(|c| c.r_dry[2] + c.r_adh[2]).collect(),
        rn_dry: nodes.iter().map(|c| c.r_dry[2]).collect(),
        rn_adh: nodes.iter().map(|c| c.r_adh[2]).collect(),
        rt: Vec::new(),
        rt_adh: Vec::new(),
        force: nodes.iter().map(|c| c.force).collect(),
        pn: Vec::new(),
        pn_adh: Vec::new(),
        tt: Vec::new(),
        tt_adh: Vec::new(),
        traction: Vec::new(),
        gap: nodes.iter().map(|c| c.gap).collect(),
        slip: nodes
            .iter()
            .map(|c| (c.slip[0].powi(2) + c.slip[1].powi(2)).sqrt())
            .collect(),
        state: nodes.iter().map(|c| c.state).collect(),
        pair_id: vec![id_i32(index); n_cells],
        body_id: vec![id_i32(slave_body); n_cells],
    };
    for (c, &a) in nodes.iter().zip(area) {
        let t = c.tangent_axes;
        let g =
            |v: [f64; 2]| -> [f64; 3] { std::array::from_fn(|k| v[0] * t[0][k] + v[1] * t[1][k]) };
        let rt = g([c.r_dry[0] + c.r_adh[0], c.r_dry[1] + c.r_adh[1]]);
        let rt_adh = g([c.r_adh[0], c.r_adh[1]]);
        f.pn.push(traction(c.r_dry[2] + c.r_adh[2], a));
        f.pn_adh.push(traction(c.r_adh[2], a));
        f.tt.push(per_area(rt, a));
        f.tt_adh.push(per_area(rt_adh, a));
        f.traction.push(per_area(c.force, a));
        f.rt.push(rt);
        f.rt_adh.push(rt_adh);
    }
    f
}

/// The values of one history field over a pair's slave nodes.
enum HistoryColumn {
    Scalar(Vec<f64>),
    Vector(Vec<[f64; 3]>),
}

impl HistoryColumn {
    fn data(&self) -> vtk::FieldData<'_> {
        match self {
            HistoryColumn::Scalar(v) => vtk::FieldData::Scalar(v),
            HistoryColumn::Vector(v) => vtk::FieldData::Vector(v),
        }
    }
}

/// `p` with the history fields of `history` that go to `slot`, in order.
fn with_history<'a>(
    p: vtk::Piece<'a>,
    history: &'a [(&'static HistoryField, HistoryColumn)],
    slot: Slot,
) -> vtk::Piece<'a> {
    history
        .iter()
        .filter(|(f, _)| f.slot == slot)
        .fold(p, |p, (f, col)| p.with_point_data(f.name, col.data()))
}

/// Each of the law's history fields `fields` with its values over `nodes`.
fn history_columns_of(
    fields: &'static [HistoryField],
    nodes: &[SiteContact],
) -> Vec<(&'static HistoryField, HistoryColumn)> {
    let mut at = 0;
    fields
        .iter()
        .map(|f| {
            let k = at;
            at += f.len();
            let col = match f.kind {
                FieldKind::Scalar => {
                    HistoryColumn::Scalar(nodes.iter().map(|c| c.history.0[k]).collect())
                }
                FieldKind::Vector => HistoryColumn::Vector(
                    nodes
                        .iter()
                        .map(|c| [c.history.0[k], c.history.0[k + 1], c.history.0[k + 2]])
                        .collect(),
                ),
            };
            (f, col)
        })
        .collect()
}

/// Writes `history.csv`: one row per committed step.
pub struct HistoryObserver {
    writer: csv::HistoryWriter,
    /// The reactions' names and the tracked nodes.
    settings: OutputSettings,
}

/// Column names of the history for a problem with output settings `output`.
pub fn history_columns(problem: &Problem, output: &OutputSettings) -> Vec<String> {
    let mut c: Vec<String> = [
        "t",
        "step",
        "dt",
        "newton_iterations",
        "cutbacks",
        "residual",
        "kinetic_energy",
        "internal_energy",
        "external_work",
        "energy_balance",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    c.push("contact_sweeps".into());
    c.push("contact_points".into());
    c.push("delassus_builds".into());
    c.push("factorisations".into());
    c.push("contact_residual".into());
    for f in [
        "time_assembly",
        "time_factorisation",
        "time_delassus",
        "time_contact_solve",
    ] {
        c.push(f.into());
    }
    for pair in &problem.contacts {
        for f in PAIR_TOTAL_FIELDS {
            c.push(format!("{}.{f}", pair.name));
        }
    }
    for (name, d) in reported_boundaries(problem, output) {
        for f in REACTION_FIELDS {
            c.push(format!("{name}.{f}"));
        }
        c.extend(prescribed_columns(d.components, d.rotation.is_some(), name));
    }
    for pair in &problem.contacts {
        if let Master::Rigid { motion, .. } = &pair.master {
            let owner = format!("{}.master", pair.name);
            for f in REACTION_FIELDS {
                c.push(format!("{owner}.{f}"));
            }
            c.extend(prescribed_columns(
                [true; 3],
                motion.rotation.is_some(),
                &owner,
            ));
        }
    }
    for tr in &output.tracks {
        for f in ["ux", "uy", "uz", "vx", "vy", "vz"] {
            c.push(format!("{}.{f}", tr.name));
        }
        let pairs = track_contacts(problem, tr.node);
        for &(p, _) in &pairs {
            for f in contact_node_fields(problem.contacts[p].law.history_fields()) {
                if pairs.len() == 1 {
                    c.push(format!("{}.{f}", tr.name));
                } else {
                    c.push(format!("{}.{}.{f}", tr.name, problem.contacts[p].name));
                }
            }
        }
    }
    c
}

/// Per-pair columns of the history, `<pair>.<field>`, in the order of [`pair_totals`].
pub const PAIR_TOTAL_FIELDS: [&str; 14] = [
    "fx",
    "fy",
    "fz",
    "fn",
    "fn_adh",
    "ft_x",
    "ft_y",
    "ft_z",
    "ft_adh_x",
    "ft_adh_y",
    "ft_adh_z",
    "ft_norm_sum",
    "ft_adh_norm_sum",
    "bonded",
];

/// Totals of a pair's contact forces on its slave nodes, in the order of
/// [`PAIR_TOTAL_FIELDS`]: the resultant contact force (global components) [N]; the sums of
/// the nodal normal forces and of their adhesive parts [N] (signed, > 0 compression); the
/// resultant tangential force and the resultant adhesive tangential force (global
/// components) [N]; the sums of the norms of the nodal tangential forces and of their
/// adhesive parts [N] (a measure of how much tangential force the interface carries, not a
/// force: opposite nodal forces add up here and cancel in the resultant); the number of
/// bonded nodes (whose law's bond intensity, the first history value, is positive).
pub fn pair_totals(nodes: &[SiteContact]) -> [f64; 14] {
    let mut out = [0.0; 14];
    for c in nodes {
        let t = c.tangent_axes;
        let global =
            |a: f64, b: f64| -> [f64; 3] { std::array::from_fn(|k| a * t[0][k] + b * t[1][k]) };
        let rt = global(c.r_dry[0] + c.r_adh[0], c.r_dry[1] + c.r_adh[1]);
        let rt_adh = global(c.r_adh[0], c.r_adh[1]);
        for k in 0..3 {
            out[k] += c.force[k];
            out[5 + k] += rt[k];
            out[8 + k] += rt_adh[k];
        }
        out[3] += c.r_dry[2] + c.r_adh[2];
        out[4] += c.r_adh[2];
        out[11] += (c.r_dry[0] + c.r_adh[0]).hypot(c.r_dry[1] + c.r_adh[1]);
        out[12] += c.r_adh[0].hypot(c.r_adh[1]);
        if c.history.bonded() {
            out[13] += 1.0;
        }
    }
    out
}

/// Resultant force and moment columns of a reaction: `<owner>.Fx` ... `<owner>.Mz`.
pub const REACTION_FIELDS: [&str; 6] = ["Fx", "Fy", "Fz", "Mx", "My", "Mz"];

/// The boundaries whose reactions are written, with their names.
fn reported_boundaries<'a>(
    problem: &'a Problem,
    output: &'a OutputSettings,
) -> impl Iterator<Item = (&'a str, &'a Dirichlet)> {
    output
        .boundary_names
        .iter()
        .zip(&problem.dirichlet)
        .filter(|(name, _)| !name.is_empty())
        .map(|(name, d)| (name.as_str(), d))
}

/// Columns of the prescribed motion of a reaction's owner: `.ux`, `.uy`, `.uz` for the
/// prescribed translation components [m], then `.angle` [rad] and `.torque` (moment about
/// the rotation axis [N·m]) when it rotates.
fn prescribed_columns(components: [bool; 3], rotates: bool, owner: &str) -> Vec<String> {
    let mut c: Vec<String> = ["ux", "uy", "uz"]
        .iter()
        .zip(components)
        .filter(|(_, on)| *on)
        .map(|(f, _)| format!("{owner}.{f}"))
        .collect();
    if rotates {
        c.push(format!("{owner}.angle"));
        c.push(format!("{owner}.torque"));
    }
    c
}

/// Mean of a set of points [m] (the origin for none).
pub fn centroid(points: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0; 3], 0usize);
    for p in points {
        for k in 0..3 {
            sum[k] += p[k];
        }
        n += 1;
    }
    sum.map(|s| s / n.max(1) as f64)
}

/// Resultant force [N] and moment about `about` [N·m] of point forces given as
/// (application point [m], force [N]): F = Σ f, M = Σ (x − about) × f.
pub fn resultant_and_moment(
    forces: impl Iterator<Item = ([f64; 3], [f64; 3])>,
    about: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let (mut force, mut moment) = ([0.0; 3], [0.0; 3]);
    for (x, f) in forces {
        let r: [f64; 3] = std::array::from_fn(|k| x[k] - about[k]);
        let m = [
            r[1] * f[2] - r[2] * f[1],
            r[2] * f[0] - r[0] * f[2],
            r[0] * f[1] - r[1] * f[0],
        ];
        for k in 0..3 {
            force[k] += f[k];
            moment[k] += m[k];
        }
    }
    (force, moment)
}

/// The point of a rigid master about which its moment is taken, in its reference position:
/// the plane's or cylinder's `point`, the sphere's `center`.
pub fn shape_reference_point(shape: &RigidShape) -> [f64; 3] {
    match shape {
        RigidShape::Plane { point, .. } | RigidShape::Cylinder { point, .. } => *point,
        RigidShape::Sphere { center, .. } => *center,
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        a.map(|c| c / n)
    } else {
        a
    }
}

/// Contact fields that every interface law has, as written for tracked nodes in the history
/// and in the contact maps, in order: total, dry and adhesive normal force [N], norms of the
/// total and adhesive tangential force [N], gap [m], slip of the step [m], state code, then
/// the same forces as tractions [Pa]: contact pressure, adhesive normal traction, norms of
/// the total and adhesive tangential tractions. The law's scalar history fields go around
/// them by their [`Slot`]: `First` before, `Motion` after `slip`, `Last` after all
/// ([`contact_node_values`]).
pub const CONTACT_NODE_FIELDS: [&str; 12] = [
    "rn", "rn_dry", "rn_adh", "rt", "rt_adh", "gap", "slip", "state", "pn", "pn_adh", "tt",
    "tt_adh",
];

/// Names of the contact fields of a slave node whose law has the history fields `fields`,
/// in the order of [`contact_node_values`].
pub fn contact_node_fields(fields: &[HistoryField]) -> Vec<&'static str> {
    contact_node_values(&SiteContact::default(), fields, 0.0)
        .into_iter()
        .map(|(name, _)| name)
        .collect()
}

/// The contact fields of one slave node of tributary area `area` [m²] whose law has the
/// history fields `fields`, named: the [`CONTACT_NODE_FIELDS`] with the law's scalar history
/// fields placed by their [`Slot`].
pub fn contact_node_values(
    c: &SiteContact,
    fields: &[HistoryField],
    area: f64,
) -> Vec<(&'static str, f64)> {
    let rn = c.r_dry[2] + c.r_adh[2];
    let rt = (c.r_dry[0] + c.r_adh[0]).hypot(c.r_dry[1] + c.r_adh[1]);
    let rt_adh = c.r_adh[0].hypot(c.r_adh[1]);
    let history = |slot: Slot| {
        c.history
            .fields(fields)
            .filter(move |(f, _)| f.kind == FieldKind::Scalar && f.slot == slot)
            .map(|(f, v)| (f.name, v[0]))
    };
    let mut out = Vec::with_capacity(CONTACT_NODE_FIELDS.len() + fields.len());
    out.extend(history(Slot::First));
    out.extend([
        ("rn", rn),
        ("rn_dry", c.r_dry[2]),
        ("rn_adh", c.r_adh[2]),
        ("rt", rt),
        ("rt_adh", rt_adh),
        ("gap", c.gap),
        ("slip", c.slip[0].hypot(c.slip[1])),
    ]);
    out.extend(history(Slot::Motion));
    out.extend([
        ("state", c.state as f64),
        ("pn", traction(rn, area)),
        ("pn_adh", traction(c.r_adh[2], area)),
        ("tt", traction(rt, area)),
        ("tt_adh", traction(rt_adh, area)),
    ]);
    out.extend(history(Slot::Last));
    out
}

/// (pair, index within the pair) for every pair of which a tracked node is a slave node.
/// A node in one pair gets columns `<track>.<field>`; a node in several pairs (a wheel
/// between two plates) gets `<track>.<pair>.<field>` for each.
fn track_contacts(problem: &Problem, node: usize) -> Vec<(usize, usize)> {
    problem
        .contacts
        .iter()
        .enumerate()
        .filter_map(|(p, c)| {
            c.slave_nodes
                .iter()
                .position(|&n| n == node)
                .map(|i| (p, i))
        })
        .collect()
}

impl HistoryObserver {
    /// The history at `path`: new, or going on from its state in a checkpoint
    /// ([`HistoryObserver::new`], [`HistoryObserver::resume`]).
    pub fn begin(
        path: &Path,
        problem: &Problem,
        output: &OutputSettings,
        begin: Begin,
    ) -> io::Result<Self> {
        match begin {
            Begin::New => HistoryObserver::new(path, problem, output),
            Begin::Resume { saved, .. } => {
                HistoryObserver::resume(path, problem, output, required_state(saved, HISTORY_KEY)?)
            }
        }
    }
}

impl HistoryObserver {
    /// Creates `path` with the header for `problem` and `output`.
    pub fn new(path: &Path, problem: &Problem, output: &OutputSettings) -> io::Result<Self> {
        Ok(HistoryObserver {
            writer: csv::HistoryWriter::create(path, &history_columns(problem, output))?,
            settings: output.clone(),
        })
    }
}

impl HistoryObserver {
    /// Continues `path` after the rows its resume state `state` counts (see
    /// [`csv::HistoryWriter::reopen`]).
    pub fn resume(
        path: &Path,
        problem: &Problem,
        output: &OutputSettings,
        state: &[u8],
    ) -> io::Result<Self> {
        let rows = Self::rows_in_state(state).map_err(|reason| bad_state(HISTORY_KEY, reason))?;
        Ok(HistoryObserver {
            writer: csv::HistoryWriter::reopen(path, &history_columns(problem, output), rows)?,
            settings: output.clone(),
        })
    }

    /// Rows written (including those before a restart).
    pub fn rows_written(&self) -> u64 {
        self.writer.rows_written()
    }

    /// The resume state of a history with `rows` rows written (the row at t = 0 included).
    pub fn state_of_rows(rows: u64) -> Vec<u8> {
        encode_with(|e| e.u64(&mut { rows }))
    }

    /// The rows counted by the resume state `state` ([`HistoryObserver::state_of_rows`]).
    pub fn rows_in_state(state: &[u8]) -> Result<u64, String> {
        decode_with(state, |d| {
            let mut rows = 0;
            d.u64(&mut rows)?;
            Ok(rows)
        })
    }
}

impl Observer for HistoryObserver {
    fn key(&self) -> &'static str {
        HISTORY_KEY
    }

    fn resume_state(&self) -> Vec<u8> {
        Self::state_of_rows(self.rows_written())
    }

    fn observe(&mut self, view: &StepView) -> io::Result<()> {
        let r = view.report;
        let mut row = vec![
            view.state.t,
            view.state.step as f64,
            r.dt,
            r.newton_iterations as f64,
            r.cutbacks as f64,
            r.residual,
            r.kinetic,
            r.internal,
            r.external_work,
            r.kinetic + r.internal - r.external_work,
        ];
        row.push(r.contact_sweeps as f64);
        row.push(r.contact_points as f64);
        row.push(r.delassus_builds as f64);
        row.push(r.factorisations as f64);
        row.push(r.contact_residual);
        let tm = &r.timings;
        row.extend_from_slice(&[tm.assembly, tm.factorisation, tm.delassus, tm.contact_solve]);
        for nodes in view.contact {
            row.extend_from_slice(&pair_totals(nodes));
        }
        let x = &view.disc.reference;
        let u = &view.state.u;
        let t = view.state.t;
        let current = |n: usize| -> [f64; 3] { std::array::from_fn(|k| x[n][k] + u[3 * n + k]) };
        for (_, d) in reported_boundaries(view.problem, &self.settings) {
            let about = centroid(d.nodes.iter().map(|&n| x[n]));
            let (force, moment) = resultant_and_moment(
                d.nodes.iter().map(|&n| {
                    let r = &view.reactions[3 * n..3 * n + 3];
                    (current(n), [r[0], r[1], r[2]])
                }),
                about,
            );
            row.extend_from_slice(&force);
            row.extend_from_slice(&moment);
            for k in 0..3 {
                if d.components[k] {
                    row.push(d.translation[k].at(t));
                }
            }
            if let Some(r) = &d.rotation {
                row.push(r.angle.at(t));
                row.push(dot(moment, unit(r.axis)));
            }
        }
        for (pair, nodes) in view.problem.contacts.iter().zip(view.contact) {
            if let Master::Rigid { shape, motion } = &pair.master {
                let about = motion.apply(shape_reference_point(shape), t);
                let (force, moment) = resultant_and_moment(
                    pair.slave_nodes
                        .iter()
                        .zip(nodes)
                        .map(|(&n, c)| (current(n), c.force.map(|f| -f))),
                    about,
                );
                row.extend_from_slice(&force);
                row.extend_from_slice(&moment);
                for k in 0..3 {
                    row.push(motion.translation[k].at(t));
                }
                if let Some(r) = &motion.rotation {
                    row.push(r.angle.at(t));
                    row.push(dot(moment, unit(r.axis)));
                }
            }
        }
        for tr in &self.settings.tracks {
            let n = tr.node;
            row.extend_from_slice(&view.state.u[3 * n..3 * n + 3]);
            row.extend_from_slice(&view.state.v[3 * n..3 * n + 3]);
            for (p, i) in track_contacts(view.problem, n) {
                let pair = &view.problem.contacts[p];
                let fields = pair.law.history_fields();
                let values = contact_node_values(&view.contact[p][i], fields, pair.slave_area[i]);
                row.extend(values.into_iter().map(|(_, v)| v));
            }
        }
        self.writer.append(&row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use adhesim::contact::LawHistory;

    #[test]
    fn frame_files_are_recognised_by_their_number() {
        assert_eq!(frame_file_index("00012.vtm"), Some(12));
        assert_eq!(frame_file_index("00012.vtu"), Some(12));
        assert_eq!(frame_file_index("00012_body0.vtu"), Some(12));
        assert_eq!(frame_file_index("123456_contact3.vtu"), Some(123456));
        for other in [
            "0012.vtm",
            "00012.csv",
            "00012_.vtu",
            "x0012.vtm",
            "00012_body0.vtm",
        ] {
            assert_eq!(frame_file_index(other), None, "{other}");
        }
    }

    /// A couple (equal and opposite forces 2 m apart) has no resultant and a moment of
    /// force × arm whatever the point; a single force has r × f about another point.
    #[test]
    fn resultant_and_moment_of_a_couple_and_of_a_single_force() {
        let couple = [
            ([1.0, 0.0, 0.0], [0.0, 3.0, 0.0]),
            ([-1.0, 0.0, 0.0], [0.0, -3.0, 0.0]),
        ];
        for about in [[0.0; 3], [5.0, -2.0, 7.0]] {
            let (f, m) = resultant_and_moment(couple.into_iter(), about);
            assert_eq!(f, [0.0; 3]);
            assert_eq!(m, [0.0, 0.0, 6.0]);
        }
        let (f, m) =
            resultant_and_moment([([0.0, 2.0, 0.0], [4.0, 0.0, 0.0])].into_iter(), [0.0; 3]);
        assert_eq!(f, [4.0, 0.0, 0.0]);
        assert_eq!(m, [0.0, 0.0, -8.0]);
        assert_eq!(
            centroid([[0.0, 0.0, 0.0], [2.0, 4.0, 6.0]].into_iter()),
            [1.0, 2.0, 3.0]
        );
    }

    /// Two nodes with opposite tangential forces of 3 N (one of them adhesive) and normal
    /// forces 2 N and 5 N: the resultant tangential force is zero, the sum of norms 6 N.
    #[test]
    fn pair_totals_separate_the_resultant_from_the_sum_of_norms() {
        let axes = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
        let a = SiteContact {
            r_dry: [3.0, 0.0, 2.0],
            force: [0.0, 2.0, 3.0],
            tangent_axes: axes,
            history: adhesim::contact::RccHistory {
                beta: 0.5,
                ..Default::default()
            }
            .encode(),
            ..Default::default()
        };
        let b = SiteContact {
            r_adh: [-3.0, 0.0, 5.0],
            force: [0.0, 5.0, -3.0],
            tangent_axes: axes,
            ..Default::default()
        };
        let t = pair_totals(&[a, b]);
        let get = |name: &str| t[PAIR_TOTAL_FIELDS.iter().position(|f| *f == name).unwrap()];
        assert_eq!([get("fx"), get("fy"), get("fz")], [0.0, 7.0, 0.0]);
        assert_eq!([get("ft_x"), get("ft_y"), get("ft_z")], [0.0; 3]);
        assert_eq!(
            [get("ft_adh_x"), get("ft_adh_y"), get("ft_adh_z")],
            [0.0, 0.0, -3.0]
        );
        assert_eq!(get("ft_norm_sum"), 6.0);
        assert_eq!(get("ft_adh_norm_sum"), 3.0);
        assert_eq!((get("fn"), get("fn_adh"), get("bonded")), (7.0, 5.0, 1.0));
    }

    /// The RCC law's contact fields, in the order the history and the maps have always had
    /// them: β first, D last.
    #[test]
    fn rcc_contact_node_fields_keep_their_order() {
        use adhesim::contact::{InterfaceLaw, RccHistory};
        let fields = InterfaceLaw::coulomb(0.3).history_fields();
        assert_eq!(
            contact_node_fields(fields),
            [
                "beta", "rn", "rn_dry", "rn_adh", "rt", "rt_adh", "gap", "slip", "state", "pn",
                "pn_adh", "tt", "tt_adh", "damage"
            ]
        );
        let c = SiteContact {
            history: RccHistory {
                beta: 0.25,
                ut: [1.0, 2.0, 3.0],
                damage: 0.5,
            }
            .encode(),
            r_adh: [0.0, 0.0, -2.0],
            ..Default::default()
        };
        let v = contact_node_values(&c, fields, 4.0);
        assert_eq!(v[0], ("beta", 0.25));
        assert_eq!(v[3], ("rn_adh", -2.0));
        assert_eq!(v[10], ("pn_adh", -0.5));
        assert_eq!(v[13], ("damage", 0.5));
    }

    #[test]
    fn traction_is_force_over_area_and_zero_without_area() {
        assert_eq!(traction(3.0, 0.5), 6.0);
        assert_eq!(traction(3.0, 0.0), 0.0);
    }
}
