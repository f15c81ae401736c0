//! What a run writes besides the history's own columns: the `[[track]]` nodes, the
//! `[output]` table's frame interval and the `[[map]]` requests.

use super::bodies::Bodies;
use super::{Ctx, FileMap, FileOutput, FileTrack, ScenarioError};
use crate::output::settings::{MapRequest, Track};
use adhesim::contact::interface::Interface;
use adhesim::contact::ContactPair;
use adhesim::mesh::Mesh;

/// The `[[track]]` entries: one node each (global index), under a unique name.
pub(super) fn build_tracks(
    raw: &[FileTrack],
    bodies: &Bodies,
    ctx: &Ctx,
) -> Result<Vec<Track>, ScenarioError> {
    let mut tracks = Vec::new();
    for (i, t) in raw.iter().enumerate() {
        let key = format!("track[{i}]");
        if t.name.is_empty() || t.name.contains([',', '"', '\n']) {
            return Err(ctx.err(format!(
                "`{key}.name` must be non-empty and hold no comma or quote, got {:?}",
                t.name
            )));
        }
        if raw[..i].iter().any(|o| o.name == t.name) {
            return Err(ctx.err(format!(
                "`{key}.name`: the track name {:?} is used twice; names must be unique",
                t.name
            )));
        }
        let bi = bodies.body(&format!("{key}.body"), &t.body, ctx)?;
        let local = tracked_node(t, &bodies.list[bi].mesh, &key, ctx)?;
        tracks.push(Track {
            name: t.name.clone(),
            node: local + bodies.offsets[bi],
        });
    }
    Ok(tracks)
}

/// The body-local node that track `t` follows in `mesh`: the one nearest its `point` [m],
/// or its `node`.
fn tracked_node(t: &FileTrack, mesh: &Mesh, key: &str, ctx: &Ctx) -> Result<usize, ScenarioError> {
    match (t.point, t.node) {
        (Some(p), None) => Ok(nearest_node(mesh, ctx.finite3(&format!("{key}.point"), p)?)),
        (None, Some(n)) if n < mesh.num_nodes() => Ok(n),
        (None, Some(n)) => {
            Err(ctx.err(format!("`{key}.node` = {n} is out of range: body {:?} has {} nodes (0 to {})", t.body, mesh.num_nodes(), mesh.num_nodes() - 1)))
        }
        _ => Err(ctx.err(format!("`{key}` needs exactly one of `point` (a position [m]; the nearest node is tracked) or `node` (an index)"))),
    }
}

/// The node of `mesh` nearest `p` [m] (the first of equally near ones).
fn nearest_node(mesh: &Mesh, p: [f64; 3]) -> usize {
    let d2 = |x: &[f64; 3]| (0..3).map(|k| (x[k] - p[k]).powi(2)).sum::<f64>();
    (0..mesh.num_nodes())
        .min_by(|&a, &b| d2(&mesh.nodes[a]).total_cmp(&d2(&mesh.nodes[b])))
        .unwrap_or(0)
}

/// `output.frame_interval` [s]: the simulated time between two frames (0, the default, for
/// every step).
pub(super) fn frame_interval(output: Option<&FileOutput>, ctx: &Ctx) -> Result<f64, ScenarioError> {
    match output.and_then(|o| o.frame_interval) {
        None => Ok(0.0),
        Some(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Some(v) => Err(ctx.err(format!(
            "`output.frame_interval` must be ≥ 0 (0 = every step), got {v}"
        ))),
    }
}

/// The `[[map]]` requests: fields of a contact pair at given times.
pub(super) fn build_maps(
    raw: &[FileMap],
    contacts: &[ContactPair],
    ctx: &Ctx,
) -> Result<Vec<MapRequest>, ScenarioError> {
    let mut maps = Vec::new();
    for (i, m) in raw.iter().enumerate() {
        let key = format!("map[{i}]");
        let pair = map_pair(m, contacts, &key, ctx)?;
        check_map_fields(m, &contacts[pair], &key, ctx)?;
        check_map_times(&m.times, &key, ctx)?;
        maps.push(MapRequest {
            pair,
            fields: m.fields.clone(),
            times: m.times.clone(),
        });
    }
    Ok(maps)
}

/// Index of the contact pair that map `m` names.
fn map_pair(
    m: &FileMap,
    contacts: &[ContactPair],
    key: &str,
    ctx: &Ctx,
) -> Result<usize, ScenarioError> {
    contacts
        .iter()
        .position(|c| c.name == m.contact)
        .ok_or_else(|| {
            ctx.err(format!(
                "`{key}.contact` = {:?} is not a contact pair of this scenario; pairs are: {}",
                m.contact,
                contacts
                    .iter()
                    .map(|c| c.name.clone())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
}

/// Checks that map `m` asks for at least one field and only fields of `pair`'s law.
fn check_map_fields(
    m: &FileMap,
    pair: &ContactPair,
    key: &str,
    ctx: &Ctx,
) -> Result<(), ScenarioError> {
    let valid = crate::output::maps::map_fields(pair.law.history_fields());
    if m.fields.is_empty() {
        return Err(ctx.err(format!(
            "`{key}.fields` is empty; valid fields are: {}",
            valid.join(", ")
        )));
    }
    for f in &m.fields {
        if !valid.contains(&f.as_str()) {
            return Err(ctx.err(format!(
                "`{key}.fields` holds {f:?}; valid fields are: {}",
                valid.join(", ")
            )));
        }
    }
    Ok(())
}

/// Checks that a map's `times` [s] are given, finite and strictly increasing.
fn check_map_times(times: &[f64], key: &str, ctx: &Ctx) -> Result<(), ScenarioError> {
    if times.is_empty() {
        return Err(ctx.err(format!(
            "`{key}.times` is empty; give the times [s] of the maps"
        )));
    }
    for (j, t) in times.iter().enumerate() {
        ctx.finite(&format!("{key}.times[{j}]"), *t)?;
        if j > 0 && *t <= times[j - 1] {
            return Err(ctx.err(format!("`{key}.times` must increase strictly")));
        }
    }
    Ok(())
}
