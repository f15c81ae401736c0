//! Output: observers that record a run (VTU/PVD frames, CSV history) and the low-level
//! writers they use. Observers only read the state the stepper hands them.

pub mod atomic;
pub mod csv;
pub mod figures;
pub mod maps;
pub mod plot;
pub mod vtk;

use crate::assembly::Discretisation;
use crate::element::{element_cauchy_stress, von_mises};
use crate::problem::Problem;
use crate::time::{NodeContact, State, StepReport};
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
    /// Committed contact state per pair and slave node.
    pub contact: &'a [Vec<NodeContact>],
}

/// Records a run.
pub trait Observer {
    /// Called at t = 0 and after every committed step.
    fn observe(&mut self, view: &StepView) -> io::Result<()>;
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
    /// Frames go to `DIR/vtu/<name>_NNNNN.vtu`, the collection to `DIR/<name>.pvd`.
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

    /// What the writer needs to go on after a restart.
    pub fn progress(&self) -> FrameProgress {
        FrameProgress {
            frames: self.frames,
            next_time: self.next_time,
            entries: self.pvd.entries().to_vec(),
        }
    }

    /// Continues a collection in `dir` after `progress`: the PVD is rewritten with its
    /// entries, and frames numbered from `progress.frames` on (left by the interrupted run
    /// after its checkpoint) are removed; they are written again as the run goes on.
    pub fn resume(
        dir: &Path,
        name: &str,
        interval: f64,
        progress: FrameProgress,
    ) -> io::Result<Self> {
        let vtu = dir.join("vtu");
        std::fs::create_dir_all(&vtu)?;
        let prefix = format!("{name}_");
        for entry in std::fs::read_dir(&vtu)? {
            let file = entry?.file_name();
            let Some(file) = file.to_str() else { continue };
            let index = file
                .strip_prefix(&prefix)
                .and_then(|r| r.strip_suffix(".vtu"))
                .filter(|r| r.len() >= 5 && r.bytes().all(|b| b.is_ascii_digit()))
                .and_then(|r| r.parse::<usize>().ok());
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

/// How far a [`FrameWriter`] got: saved in checkpoints.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameProgress {
    /// Frames written.
    pub frames: usize,
    /// Time of the next frame [s].
    pub next_time: f64,
    /// Entries of the PVD collection.
    pub entries: Vec<vtk::PvdEntry>,
}

/// Per-body arrays of one frame.
struct BodyFrame {
    points: Vec<[f64; 3]>,
    hex_conn: Vec<usize>,
    tet_conn: Vec<usize>,
    u: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    cauchy: Vec<[f64; 9]>,
    mises: Vec<f64>,
    jac: Vec<f64>,
}

fn body_frames(view: &StepView) -> Vec<BodyFrame> {
    let disc = view.disc;
    let (u, v) = (&view.state.u, &view.state.v);
    let offsets = &disc.node_offset;
    let mut out = Vec::new();
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
            hex_conn: body.mesh.hexes.iter().flatten().copied().collect(),
            tet_conn: body.mesh.tets.iter().flatten().copied().collect(),
            u: uu,
            v: vv,
            cauchy: Vec::new(),
            mises: Vec::new(),
            jac: Vec::new(),
        };
        let mat = &*disc.materials[bi];
        let mut push = |s: crate::Mat3, j: f64| {
            f.cauchy.push(std::array::from_fn(|k| s[(k / 3, k % 3)]));
            f.mises.push(von_mises(&s));
            f.jac.push(j);
        };
        for e in 0..disc.hexes.len() {
            if disc.hexes.body[e] == bi {
                let ue = disc.hexes.nodes[e].map(|n| [u[3 * n], u[3 * n + 1], u[3 * n + 2]]);
                let (s, j) = element_cauchy_stress(&disc.hexes.gauss[e], &ue, mat);
                push(s, j);
            }
        }
        for e in 0..disc.tets.len() {
            if disc.tets.body[e] == bi {
                let ue = disc.tets.nodes[e].map(|n| [u[3 * n], u[3 * n + 1], u[3 * n + 2]]);
                let (s, j) = element_cauchy_stress(&disc.tets.gauss[e], &ue, mat);
                push(s, j);
            }
        }
        out.push(f);
    }
    out
}

impl Observer for FrameWriter {
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
        let frames = body_frames(view);
        let pieces: Vec<vtk::Piece> = frames
            .iter()
            .map(|f| {
                let mut p = vtk::Piece::new(&f.points);
                if !f.hex_conn.is_empty() {
                    p = p.with_cells(vtk::CellKind::Hex8, &f.hex_conn);
                }
                if !f.tet_conn.is_empty() {
                    p = p.with_cells(vtk::CellKind::Tet4, &f.tet_conn);
                }
                p.with_point_data("u", vtk::FieldData::Vector(&f.u))
                    .with_point_data("v", vtk::FieldData::Vector(&f.v))
                    .with_cell_data("cauchy", vtk::FieldData::Tensor(&f.cauchy))
                    .with_cell_data("von_mises", vtk::FieldData::Scalar(&f.mises))
                    .with_cell_data("J", vtk::FieldData::Scalar(&f.jac))
            })
            .collect();
        let surfaces: Vec<ContactFrame> = view
            .problem
            .contacts
            .iter()
            .zip(view.contact)
            .map(|(pair, nodes)| contact_frame(pair, nodes, view))
            .collect();
        let mut pieces = pieces;
        for c in &surfaces {
            pieces.push(
                vtk::Piece::new(&c.points)
                    .with_cells(vtk::CellKind::Vertex, &c.vertices)
                    .with_point_data("beta", vtk::FieldData::Scalar(&c.beta))
                    .with_point_data("rn", vtk::FieldData::Scalar(&c.rn))
                    .with_point_data("rn_dry", vtk::FieldData::Scalar(&c.rn_dry))
                    .with_point_data("rn_adh", vtk::FieldData::Scalar(&c.rn_adh))
                    .with_point_data("rt", vtk::FieldData::Vector(&c.rt))
                    .with_point_data("rt_adh", vtk::FieldData::Vector(&c.rt_adh))
                    .with_point_data("contact_force", vtk::FieldData::Vector(&c.force))
                    .with_point_data("gap", vtk::FieldData::Scalar(&c.gap))
                    .with_point_data("slip", vtk::FieldData::Scalar(&c.slip))
                    .with_point_data("ut", vtk::FieldData::Vector(&c.ut))
                    .with_point_data("state", vtk::FieldData::Int(&c.state)),
            );
        }
        let rel = format!("vtu/{}_{:05}.vtu", self.name, self.frames);
        vtk::write_vtu(&self.dir.join(&rel), &pieces)?;
        self.pvd.push(t, &rel)?;
        self.frames += 1;
        Ok(())
    }
}

/// Point data of one contact surface.
struct ContactFrame {
    points: Vec<[f64; 3]>,
    vertices: Vec<usize>,
    beta: Vec<f64>,
    rn: Vec<f64>,
    rn_dry: Vec<f64>,
    rn_adh: Vec<f64>,
    rt: Vec<[f64; 3]>,
    rt_adh: Vec<[f64; 3]>,
    force: Vec<[f64; 3]>,
    gap: Vec<f64>,
    slip: Vec<f64>,
    ut: Vec<[f64; 3]>,
    state: Vec<i32>,
}

fn contact_frame(
    pair: &crate::contact::ContactPair,
    nodes: &[NodeContact],
    view: &StepView,
) -> ContactFrame {
    let u = &view.state.u;
    let x = &view.disc.reference;
    let mut f = ContactFrame {
        points: pair
            .slave_nodes
            .iter()
            .map(|&n| std::array::from_fn(|k| x[n][k] + u[3 * n + k]))
            .collect(),
        vertices: (0..pair.slave_nodes.len()).collect(),
        beta: nodes.iter().map(|c| c.beta).collect(),
        rn: nodes.iter().map(|c| c.r_dry[2] + c.r_adh[2]).collect(),
        rn_dry: nodes.iter().map(|c| c.r_dry[2]).collect(),
        rn_adh: nodes.iter().map(|c| c.r_adh[2]).collect(),
        rt: Vec::new(),
        rt_adh: Vec::new(),
        force: nodes.iter().map(|c| c.force).collect(),
        gap: nodes.iter().map(|c| c.gap).collect(),
        slip: nodes
            .iter()
            .map(|c| (c.slip[0].powi(2) + c.slip[1].powi(2)).sqrt())
            .collect(),
        ut: nodes.iter().map(|c| c.ut).collect(),
        state: nodes.iter().map(|c| c.state).collect(),
    };
    for c in nodes {
        let t = c.tangent_axes;
        let g =
            |v: [f64; 2]| -> [f64; 3] { std::array::from_fn(|k| v[0] * t[0][k] + v[1] * t[1][k]) };
        f.rt.push(g([c.r_dry[0] + c.r_adh[0], c.r_dry[1] + c.r_adh[1]]));
        f.rt_adh.push(g([c.r_adh[0], c.r_adh[1]]));
    }
    f
}

/// Writes `history.csv`: one row per committed step.
pub struct HistoryObserver {
    writer: csv::HistoryWriter,
}

/// Column names of the history for a problem.
pub fn history_columns(problem: &Problem) -> Vec<String> {
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
        for f in ["fx", "fy", "fz", "fn", "fn_adh", "ft", "ft_adh", "bonded"] {
            c.push(format!("{}.{f}", pair.name));
        }
    }
    for tr in &problem.tracks {
        for f in ["ux", "uy", "uz", "vx", "vy", "vz"] {
            c.push(format!("{}.{f}", tr.name));
        }
        let pairs = track_contacts(problem, tr.node);
        for &(p, _) in &pairs {
            for f in CONTACT_NODE_FIELDS {
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

/// Contact fields of one slave node, as written for tracked nodes in the history and in the
/// contact maps; [`contact_node_values`] gives them in this order.
pub const CONTACT_NODE_FIELDS: [&str; 9] = [
    "beta", "rn", "rn_dry", "rn_adh", "rt", "rt_adh", "gap", "slip", "state",
];

/// The [`CONTACT_NODE_FIELDS`] of one slave node: β, total, dry and adhesive normal force
/// [N], norms of the total and adhesive tangential force [N], gap [m], slip of the step [m]
/// and state code.
pub fn contact_node_values(c: &NodeContact) -> [f64; 9] {
    [
        c.beta,
        c.r_dry[2] + c.r_adh[2],
        c.r_dry[2],
        c.r_adh[2],
        (c.r_dry[0] + c.r_adh[0]).hypot(c.r_dry[1] + c.r_adh[1]),
        c.r_adh[0].hypot(c.r_adh[1]),
        c.gap,
        c.slip[0].hypot(c.slip[1]),
        c.state as f64,
    ]
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
    /// Creates `path` with the header for `problem`.
    pub fn new(path: &Path, problem: &Problem) -> io::Result<Self> {
        Ok(HistoryObserver {
            writer: csv::HistoryWriter::create(path, &history_columns(problem))?,
        })
    }
}

impl HistoryObserver {
    /// Continues `path` after its first `rows` rows (see [`csv::HistoryWriter::reopen`]).
    pub fn resume(path: &Path, problem: &Problem, rows: u64) -> io::Result<Self> {
        Ok(HistoryObserver {
            writer: csv::HistoryWriter::reopen(path, &history_columns(problem), rows)?,
        })
    }

    /// Rows written (including those before a restart).
    pub fn rows_written(&self) -> u64 {
        self.writer.rows_written()
    }
}

impl Observer for HistoryObserver {
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
        row.push(r.contact_residual);
        let tm = &r.timings;
        row.extend_from_slice(&[tm.assembly, tm.factorisation, tm.delassus, tm.contact_solve]);
        for nodes in view.contact {
            let mut total = [0.0; 3];
            let (mut fn_, mut fn_adh, mut ft, mut ft_adh, mut bonded) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for c in nodes {
                for k in 0..3 {
                    total[k] += c.force[k];
                }
                fn_ += c.r_dry[2] + c.r_adh[2];
                fn_adh += c.r_adh[2];
                ft += (c.r_dry[0] + c.r_adh[0]).hypot(c.r_dry[1] + c.r_adh[1]);
                ft_adh += c.r_adh[0].hypot(c.r_adh[1]);
                if c.beta > 0.0 {
                    bonded += 1.0;
                }
            }
            row.extend_from_slice(&total);
            row.extend_from_slice(&[fn_, fn_adh, ft, ft_adh, bonded]);
        }
        for tr in &view.problem.tracks {
            let n = tr.node;
            row.extend_from_slice(&view.state.u[3 * n..3 * n + 3]);
            row.extend_from_slice(&view.state.v[3 * n..3 * n + 3]);
            for (p, i) in track_contacts(view.problem, n) {
                row.extend_from_slice(&contact_node_values(&view.contact[p][i]));
            }
        }
        self.writer.append(&row)
    }
}
