//! Figures drawn from a finished run's `history.csv`: one PNG per tracked quantity with one
//! curve per tracked node, one per contact-pair quantity with one curve per pair, and the
//! reaction of each prescribed boundary and rigid master against its prescribed motion.

use super::csv::read_history;
use super::plot::{draw_line_plot, LinePlot, PlotError, Series};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Axis label (quantity and unit) of a history field suffix, or None for fields not plotted.
pub fn field_label(field: &str) -> Option<&'static str> {
    Some(match field {
        "ux" => "displacement u_x [m]",
        "uy" => "displacement u_y [m]",
        "uz" => "displacement u_z [m]",
        "rn" => "normal contact force r_n [N] (> 0 compression)",
        "rn_adh" => "normal adhesive force r̃_n [N] (< 0 tension)",
        "rt" => "tangential contact force ‖r_t‖ [N]",
        "rt_adh" => "tangential adhesive force ‖r̃_t‖ [N]",
        "gap" => "gap x_n [m]",
        "pn" => "contact pressure p_n [Pa] (> 0 compression)",
        "pn_adh" => "adhesive normal traction [Pa] (< 0 tension)",
        "tt" => "tangential traction ‖t_t‖ [Pa]",
        "tt_adh" => "adhesive tangential traction [Pa]",
        "fx" => "total contact force F_x [N]",
        "fy" => "total contact force F_y [N]",
        "fz" => "total contact force F_z [N]",
        "fn" => "total normal contact force [N]",
        "fn_adh" => "total normal adhesive force [N]",
        "ft_norm_sum" => "sum of the nodal tangential force norms Σ‖r_t‖ [N]",
        "ft_adh_norm_sum" => "sum of the nodal adhesive tangential force norms Σ‖r̃_t‖ [N]",
        "bonded" => "bonded contact nodes [-]",
        _ => return adhesim::contact::registry::field_label(field),
    })
}

/// Draws the figures of the run in `dir` into `dir/figures/`; returns the files written.
pub fn draw_history_figures(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let path = dir.join("history.csv");
    let (columns, rows) = read_history(&path).map_err(|source| PlotError::Io {
        path: path.clone(),
        source,
    })?;
    let t_col = columns
        .iter()
        .position(|c| c == "t")
        .ok_or_else(|| PlotError::InvalidData {
            path: path.clone(),
            message: "no column `t`".into(),
        })?;
    let t: Vec<f64> = rows.iter().map(|r| r[t_col]).collect();
    // field suffix → [(owner, column)]
    let mut groups: BTreeMap<String, Vec<(String, usize)>> = BTreeMap::new();
    for (i, c) in columns.iter().enumerate() {
        if let Some((owner, field)) = c.rsplit_once('.') {
            if field_label(field).is_some() {
                groups
                    .entry(field.to_string())
                    .or_default()
                    .push((owner.to_string(), i));
            }
        }
    }
    let out_dir = dir.join("figures");
    std::fs::create_dir_all(&out_dir).map_err(|source| PlotError::Io {
        path: out_dir.clone(),
        source,
    })?;
    let mut written = Vec::new();
    for (field, members) in groups {
        let label = field_label(&field).unwrap_or("");
        let series = members
            .iter()
            .map(|(owner, col)| Series {
                label: owner.clone(),
                x: t.clone(),
                y: rows.iter().map(|r| r[*col]).collect(),
            })
            .collect();
        let plot = LinePlot {
            title: format!(
                "{} against time",
                label.split(" [").next().unwrap_or(&field)
            ),
            x_label: "time t [s]".into(),
            y_label: label.into(),
            series,
        };
        let file = out_dir.join(format!("{field}.png"));
        draw_line_plot(&file, &plot)?;
        written.push(file);
    }
    for curve in reaction_curves(&columns) {
        let x: Vec<f64> = rows.iter().map(|r| r[curve.x]).collect();
        let moving = x.iter().any(|v| *v != x[0]);
        if !moving {
            continue;
        }
        let plot = LinePlot {
            title: format!("{}: reaction against prescribed motion", curve.owner),
            x_label: curve.x_label,
            y_label: curve.y_label,
            series: vec![Series {
                label: curve.owner.clone(),
                x,
                y: rows.iter().map(|r| r[curve.y]).collect(),
            }],
        };
        let file = out_dir.join(format!("reaction_{}_{}.png", curve.owner, curve.tag));
        draw_line_plot(&file, &plot)?;
        written.push(file);
    }
    Ok(written)
}

/// A force-displacement (or torque-angle) curve of a reaction's owner.
struct ReactionCurve {
    owner: String,
    tag: &'static str,
    x: usize,
    y: usize,
    x_label: String,
    y_label: String,
}

/// The curves of every reaction in the history: `<owner>.F<k>` against `<owner>.u<k>` for
/// each prescribed translation component and `<owner>.torque` against `<owner>.angle`.
fn reaction_curves(columns: &[String]) -> Vec<ReactionCurve> {
    let find = |name: String| columns.iter().position(|c| *c == name);
    let mut out = Vec::new();
    for c in columns {
        let Some(owner) = c.strip_suffix(".Fx") else {
            continue;
        };
        for (axis, tag) in ["x", "y", "z"].into_iter().zip(["Fx_ux", "Fy_uy", "Fz_uz"]) {
            if let (Some(x), Some(y)) = (
                find(format!("{owner}.u{axis}")),
                find(format!("{owner}.F{axis}")),
            ) {
                out.push(ReactionCurve {
                    owner: owner.to_string(),
                    tag,
                    x,
                    y,
                    x_label: format!("prescribed displacement u_{axis} [m]"),
                    y_label: format!("reaction force F_{axis} [N]"),
                });
            }
        }
        if let (Some(x), Some(y)) = (
            find(format!("{owner}.angle")),
            find(format!("{owner}.torque")),
        ) {
            out.push(ReactionCurve {
                owner: owner.to_string(),
                tag: "torque_angle",
                x,
                y,
                x_label: "prescribed rotation angle [rad]".into(),
                y_label: "reaction torque about the rotation axis [N·m]".into(),
            });
        }
    }
    out
}
