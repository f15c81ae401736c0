//! Figures drawn from a finished run's `history.csv`: one PNG per tracked quantity with one
//! curve per tracked node, and one per contact-pair quantity with one curve per pair.

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
        "beta" => "intensity of adhesion β [-]",
        "rn" => "normal contact force r_n [N] (> 0 compression)",
        "rn_adh" => "normal adhesive force r̃_n [N] (< 0 tension)",
        "rt" => "tangential contact force ‖r_t‖ [N]",
        "rt_adh" => "tangential adhesive force ‖r̃_t‖ [N]",
        "gap" => "gap x_n [m]",
        "fx" => "total contact force F_x [N]",
        "fy" => "total contact force F_y [N]",
        "fz" => "total contact force F_z [N]",
        "fn" => "total normal contact force [N]",
        "fn_adh" => "total normal adhesive force [N]",
        "ft_adh" => "total tangential adhesive force [N]",
        "bonded" => "bonded contact nodes [-]",
        _ => return None,
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
    Ok(written)
}
