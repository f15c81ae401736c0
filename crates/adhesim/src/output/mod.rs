//! Output: observers that record a run (VTU/PVD frames, CSV history) and the low-level
//! writers they use. Observers only read the state the stepper hands them.

pub mod atomic;
pub mod csv;
// pub mod plot;
pub mod vtk;

use crate::assembly::Discretisation;
use crate::element::{element_cauchy_stress, von_mises};
use crate::problem::Problem;
use crate::time::{State, StepReport};
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
        let rel = format!("vtu/{}_{:05}.vtu", self.name, self.frames);
        vtk::write_vtu(&self.dir.join(&rel), &pieces)?;
        self.pvd.push(t, &rel)?;
        self.frames += 1;
        Ok(())
    }
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
    for tr in &problem.tracks {
        for f in ["ux", "uy", "uz", "vx", "vy", "vz"] {
            c.push(format!("{}.{f}", tr.name));
        }
    }
    c
}

impl HistoryObserver {
    /// Creates `path` with the header for `problem`.
    pub fn new(path: &Path, problem: &Problem) -> io::Result<Self> {
        Ok(HistoryObserver {
            writer: csv::HistoryWriter::create(path, &history_columns(problem))?,
        })
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
        for tr in &view.problem.tracks {
            let n = tr.node;
            row.extend_from_slice(&view.state.u[3 * n..3 * n + 3]);
            row.extend_from_slice(&view.state.v[3 * n..3 * n + 3]);
        }
        self.writer.append(&row)
    }
}
