//! Maps of contact fields over the slave surface of a contact pair.
//!
//! During a run, [`MapObserver`] writes the contact fields of every slave node at the first
//! committed step at or after each requested time to `DIR/maps/<pair>_t<time>.csv` (columns
//! `node, x, y, z` in the reference configuration [m], the actual time `t` [s], then the
//! fields), and the surface's faces once to `DIR/maps/<pair>_faces.csv`. At the end (and by
//! `adhesim plot DIR`), [`draw_map_figures`] draws one PNG per field and time into
//! `DIR/figures/`, with one colour range per field and pair across all times so that the
//! frames compare at a glance.

use super::csv::read_history;
use super::plot::{draw_scalar_map_with, ColorMap, PlotError, ScalarMap, ScalarValues};
use super::{
    bad_state, contact_node_fields, contact_node_values, saved_state, Begin, Observer, StepView,
    CONTACT_NODE_FIELDS, MAPS_KEY,
};
use crate::codec::{decode_with, encode_with, Codec};
use crate::output::settings::MapRequest;
use adhesim::contact::history::{FieldKind, HistoryField};
use adhesim::contact::registry;
use adhesim::contact::Interface;
use std::collections::BTreeMap;
use std::io;
use std::path::{Path, PathBuf};

/// The contact fields of a pair whose law has the history fields `fields` that can be
/// mapped, in the order of the map CSV columns.
pub fn map_fields(fields: &[HistoryField]) -> Vec<&'static str> {
    contact_node_fields(fields)
}

/// Whether a map CSV column is a contact field of some law.
fn is_map_field(name: &str) -> bool {
    CONTACT_NODE_FIELDS.contains(&name)
        || registry::registered_fields().any(|f| f.kind == FieldKind::Scalar && f.name == name)
}

/// Colour-bar label (quantity and units) of a map field.
fn map_label(field: &str) -> &'static str {
    match field {
        "rn" => "normal contact force r_n [N]",
        "rn_dry" => "dry normal force r̄_n [N]",
        "rn_adh" => "normal adhesive force r̃_n [N]",
        "rt" => "tangential force ‖r_t‖ [N]",
        "rt_adh" => "tangential adhesive force ‖r̃_t‖ [N]",
        "gap" => "gap x_n [m]",
        "slip" => "slip over the step [m]",
        "state" => "0 none, 1 apart, 2 stick, 3 slide",
        "pn" => "contact pressure p_n [Pa]",
        "pn_adh" => "adhesive normal traction [Pa]",
        "tt" => "tangential traction ‖t_t‖ [Pa]",
        "tt_adh" => "adhesive tangential traction [Pa]",
        _ => registry::field_label(field).unwrap_or(""),
    }
}

/// Writes the map CSVs of the requested pairs and times.
pub struct MapObserver {
    dir: PathBuf,
    requests: Vec<MapRequest>,
    /// Next time index per request.
    next: Vec<usize>,
    faces_written: Vec<bool>,
}

impl MapObserver {
    /// The maps of `requests` in `dir`: new, or going on from the checkpoint's state (or its
    /// time, for a checkpoint without one; [`MapObserver::resume`]).
    pub fn begin(dir: &Path, requests: &[MapRequest], begin: Begin) -> io::Result<Self> {
        match begin {
            Begin::New => MapObserver::new(dir, requests),
            Begin::Resume { saved, t } => {
                MapObserver::resume(dir, requests, saved_state(saved, MAPS_KEY), t)
            }
        }
    }

    /// Maps go to `dir/maps/`.
    pub fn new(dir: &Path, requests: &[MapRequest]) -> io::Result<Self> {
        if !requests.is_empty() {
            std::fs::create_dir_all(dir.join("maps"))?;
        }
        Ok(MapObserver {
            dir: dir.to_path_buf(),
            requests: requests.to_vec(),
            next: vec![0; requests.len()],
            faces_written: vec![false; requests.len()],
        })
    }
}

impl MapObserver {
    /// Goes on after a checkpoint at time `t` [s] from the resume state `state`: the maps of
    /// earlier times are written. Without a state (checkpoints of format 6 and earlier) the
    /// maps due up to `t` count as written.
    pub fn resume(
        dir: &Path,
        requests: &[MapRequest],
        state: Option<&[u8]>,
        t: f64,
    ) -> io::Result<Self> {
        let mut m = MapObserver::new(dir, requests)?;
        match state {
            Some(bytes) => {
                m.read_state(bytes)
                    .map_err(|reason| bad_state(MAPS_KEY, reason))?;
            }
            None => {
                for (r, req) in requests.iter().enumerate() {
                    m.next[r] = req
                        .times
                        .iter()
                        .filter(|&&w| t >= w - 1e-9 * w.abs())
                        .count();
                    m.faces_written[r] = true;
                }
            }
        }
        Ok(m)
    }

    /// Per request the next time index and whether its faces are written, through `c`.
    fn visit(
        next: &mut Vec<usize>,
        faces: &mut Vec<bool>,
        c: &mut impl Codec,
    ) -> Result<(), String> {
        c.count(next, 16)?;
        faces.resize(next.len(), false);
        for (n, f) in next.iter_mut().zip(faces.iter_mut()) {
            c.usize(n)?;
            let mut written = usize::from(*f);
            c.usize(&mut written)?;
            *f = written != 0;
        }
        Ok(())
    }

    /// Reads the state written by [`Observer::resume_state`] into `self`, which must have as
    /// many requests.
    fn read_state(&mut self, bytes: &[u8]) -> Result<(), String> {
        let (next, faces) = decode_with(bytes, |d| {
            let (mut next, mut faces) = (Vec::new(), Vec::new());
            Self::visit(&mut next, &mut faces, d)?;
            Ok((next, faces))
        })?;
        if next.len() != self.requests.len() {
            return Err(format!(
                "it holds {} map requests, the scenario {}",
                next.len(),
                self.requests.len()
            ));
        }
        (self.next, self.faces_written) = (next, faces);
        Ok(())
    }
}

/// File stem of the map of `pair` at requested time `t`.
fn map_stem(pair: &str, t: f64) -> String {
    format!("{pair}_t{t}")
}

impl Observer for MapObserver {
    fn key(&self) -> &'static str {
        MAPS_KEY
    }

    fn resume_state(&self) -> Vec<u8> {
        encode_with(|e| Self::visit(&mut self.next.clone(), &mut self.faces_written.clone(), e))
    }

    fn observe(&mut self, view: &StepView) -> io::Result<()> {
        let t = view.state.t;
        for (r, req) in self.requests.iter().enumerate() {
            let pair = &view.problem.contacts[req.pair];
            if !self.faces_written[r] {
                let mut text = String::from("a,b,c,d\n");
                for q in &pair.slave_quads {
                    text.push_str(&format!("{},{},{},{}\n", q[0], q[1], q[2], q[3]));
                }
                super::atomic::write_atomic(
                    &self
                        .dir
                        .join("maps")
                        .join(format!("{}_faces.csv", pair.name)),
                    text.as_bytes(),
                )?;
                self.faces_written[r] = true;
            }
            // Several requested times may fall within one step: each gets this step's state.
            while self.next[r] < req.times.len() {
                let wanted = req.times[self.next[r]];
                if t < wanted - 1e-9 * wanted.abs().max(view.report.dt) {
                    break;
                }
                let fields = pair.law.history_fields();
                let names = map_fields(fields);
                let cols: Vec<usize> = req
                    .fields
                    .iter()
                    .filter_map(|f| names.iter().position(|m| m == f))
                    .collect();
                let mut text = String::from("node,x,y,z,t");
                for &k in &cols {
                    text.push(',');
                    text.push_str(names[k]);
                }
                text.push('\n');
                for (i, (&n, c)) in pair
                    .slave_nodes
                    .iter()
                    .zip(&view.contact[req.pair])
                    .enumerate()
                {
                    let x = view.disc.reference[n];
                    text.push_str(&format!("{i},{:e},{:e},{:e},{:e}", x[0], x[1], x[2], t));
                    let values = contact_node_values(c, fields, pair.slave_area[i]);
                    for &k in &cols {
                        text.push_str(&format!(",{:e}", values[k].1));
                    }
                    text.push('\n');
                }
                super::atomic::write_atomic(
                    &self
                        .dir
                        .join("maps")
                        .join(format!("{}.csv", map_stem(&pair.name, wanted))),
                    text.as_bytes(),
                )?;
                self.next[r] += 1;
            }
        }
        Ok(())
    }
}

/// One map read back from its CSV.
struct MapData {
    pair: String,
    requested: String,
    t: f64,
    columns: Vec<String>,
    rows: Vec<Vec<f64>>,
}

/// Draws every map found in `dir/maps/` into `dir/figures/map_<pair>_<field>_t<time>.png`;
/// returns the files written. No `maps` folder means no maps (not an error).
pub fn draw_map_figures(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let maps_dir = dir.join("maps");
    let io_err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| PlotError::Io { path, source }
    };
    let entries = match std::fs::read_dir(&maps_dir) {
        Ok(e) => e,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io_err(&maps_dir)(e)),
    };
    let mut maps: Vec<MapData> = Vec::new();
    let mut faces: BTreeMap<String, Vec<[usize; 4]>> = BTreeMap::new();
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    for path in files {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let (columns, rows) = read_history(&path).map_err(io_err(&path))?;
        if let Some(pair) = stem.strip_suffix("_faces") {
            let quads = rows
                .iter()
                .map(|r| std::array::from_fn(|k| r.get(k).copied().unwrap_or(0.0) as usize))
                .collect();
            faces.insert(pair.to_string(), quads);
        } else if let Some((pair, requested)) = stem.rsplit_once("_t") {
            let t_col = columns.iter().position(|c| c == "t");
            let t = t_col
                .and_then(|c| rows.first().map(|r| r[c]))
                .unwrap_or(f64::NAN);
            maps.push(MapData {
                pair: pair.to_string(),
                requested: requested.to_string(),
                t,
                columns,
                rows,
            });
        }
    }
    let out_dir = dir.join("figures");
    std::fs::create_dir_all(&out_dir).map_err(io_err(&out_dir))?;
    // Common colour range per (pair, field).
    let mut ranges: BTreeMap<(String, String), (f64, f64)> = BTreeMap::new();
    for m in &maps {
        for (c, name) in m.columns.iter().enumerate() {
            if !is_map_field(name) {
                continue;
            }
            let e = ranges
                .entry((m.pair.clone(), name.clone()))
                .or_insert((f64::INFINITY, f64::NEG_INFINITY));
            for r in &m.rows {
                if r[c].is_finite() {
                    e.0 = e.0.min(r[c]);
                    e.1 = e.1.max(r[c]);
                }
            }
        }
    }
    let mut written = Vec::new();
    for m in &maps {
        let Some(quads) = faces.get(&m.pair) else {
            continue;
        };
        let col = |name: &str| m.columns.iter().position(|c| c == name);
        let (Some(cx), Some(cy), Some(cz)) = (col("x"), col("y"), col("z")) else {
            continue;
        };
        // Drop the axis along which the surface is flattest.
        let extent = |c: usize| {
            let (lo, hi) = m
                .rows
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
                    (a.0.min(r[c]), a.1.max(r[c]))
                });
            hi - lo
        };
        let axes = [(cx, "x [m]"), (cy, "y [m]"), (cz, "z [m]")];
        let flat = (0..3)
            .min_by(|&a, &b| extent(axes[a].0).total_cmp(&extent(axes[b].0)))
            .unwrap_or(1);
        let keep: Vec<(usize, &str)> = (0..3).filter(|&k| k != flat).map(|k| axes[k]).collect();
        let points: Vec<[f64; 2]> = m
            .rows
            .iter()
            .map(|r| [r[keep[0].0], r[keep[1].0]])
            .collect();
        let n = points.len();
        let valid: Vec<[usize; 4]> = quads
            .iter()
            .copied()
            .filter(|q| q.iter().all(|&i| i < n))
            .collect();
        for (c, name) in m.columns.iter().enumerate() {
            if !is_map_field(name) {
                continue;
            }
            let values: Vec<f64> = m.rows.iter().map(|r| r[c]).collect();
            let range = match name.as_str() {
                "state" => Some((0.0, 3.0)),
                _ if registry::field_range(name).is_some() => registry::field_range(name),
                _ => ranges
                    .get(&(m.pair.clone(), name.clone()))
                    .copied()
                    .filter(|(lo, hi)| lo.is_finite() && hi.is_finite() && lo < hi),
            };
            let title = format!("{name} on {} at t = {:.4e} s", m.pair, m.t);
            let file = out_dir.join(format!("map_{}_{name}_t{}.png", m.pair, m.requested));
            draw_scalar_map_with(
                &file,
                &ScalarMap {
                    title: &title,
                    x_label: keep[0].1,
                    y_label: keep[1].1,
                    points_xy: &points,
                    cell_quads: &valid,
                    values: ScalarValues::Nodal(&values),
                    colorbar_label: map_label(name),
                    colormap: ColorMap::viridis(),
                    range,
                },
            )?;
            written.push(file);
        }
    }
    Ok(written)
}
