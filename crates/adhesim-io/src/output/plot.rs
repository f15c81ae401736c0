//! PNG figures drawn with plotters' bitmap backend: line plots of time histories and filled
//! colour maps of a scalar over a 2D quad mesh (contact-face maps).
//!
//! Text is drawn with DejaVu Sans, embedded in the binary (`assets/DejaVuSans.ttf`, Bitstream
//! Vera licence, see `assets/DejaVuSans-LICENSE.txt`) and registered with plotters once, so no
//! system font is needed. Files are written atomically: the PNG is encoded to a temporary file
//! beside the target, then renamed over it.
//!
//! Both kinds of figure tolerate awkward data: non-finite values are skipped (a line is broken
//! at each gap, a map cell with a `NaN` value is drawn grey), empty input gives empty axes,
//! and a constant range is padded so that the axes stay valid.

use std::io;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use super::atomic::TempPath;

/// Width of every figure, in pixels.
pub const FIGURE_WIDTH: u32 = 1000;
/// Height of every figure, in pixels.
pub const FIGURE_HEIGHT: u32 = 700;

/// The embedded text font (DejaVu Sans Book).
static FONT_TTF: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Font family name under which [`FONT_TTF`] is registered.
const FAMILY: &str = "sans-serif";

/// Colours of successive series (matplotlib's "tab10" palette); cycled past ten series.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Fill colour of map cells whose value is not finite.
const MISSING: RGBColor = RGBColor(200, 200, 200);

/// Errors of the plotting functions; every variant names the file being drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The data cannot be plotted (mismatched lengths, indices out of range, bad range).
    #[error("{}: invalid plot data: {message}", path.display())]
    InvalidData {
        /// The figure that was to be written.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Creating, encoding or renaming the image file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The figure that was to be written.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// The plotting backend failed while drawing or encoding.
    #[error("{}: cannot draw the figure: {message}", path.display())]
    Draw {
        /// The figure that was to be written.
        path: PathBuf,
        /// The backend's message.
        message: String,
    },
    /// The embedded font could not be registered with plotters.
    #[error("{}: the embedded font could not be loaded", path.display())]
    Font {
        /// The figure that was to be written.
        path: PathBuf,
    },
}

/// One curve of a [`LinePlot`]: points `(x[i], y[i])` joined in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Legend entry (an empty label gives no legend entry).
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates; must have the same length as `x`.
    pub y: Vec<f64>,
}

/// A line plot with several series, a legend and labelled axes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinePlot {
    /// Title drawn above the plot.
    pub title: String,
    /// Label of the horizontal axis (with units).
    pub x_label: String,
    /// Label of the vertical axis (with units).
    pub y_label: String,
    /// The curves, drawn in order with distinct colours.
    pub series: Vec<Series>,
}

/// Draws `plot` into a [`FIGURE_WIDTH`]×[`FIGURE_HEIGHT`] PNG at `path`.
///
/// Points with a non-finite coordinate are skipped and break the line; isolated points are
/// drawn as dots. A series whose `x` and `y` lengths differ is an
/// [`PlotError::InvalidData`] error.
pub fn draw_line_plot(path: &Path, plot: &LinePlot) -> Result<(), PlotError> {
    for (i, s) in plot.series.iter().enumerate() {
        if s.x.len() != s.y.len() {
            return Err(PlotError::InvalidData {
                path: path.to_path_buf(),
                message: format!(
                    "series {i} ({:?}) has {} x values but {} y values",
                    s.label,
                    s.x.len(),
                    s.y.len()
                ),
            });
        }
    }
    render_png(path, |root| render_line_plot(root, plot))
}

/// A colour scale: evenly spaced colour stops, linearly interpolated.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColorMap {
    stops: Vec<[u8; 3]>,
}

impl ColorMap {
    /// The perceptually uniform "viridis" scale (dark purple → blue → green → yellow).
    pub fn viridis() -> Self {
        ColorMap {
            stops: vec![
                [0x44, 0x01, 0x54],
                [0x48, 0x28, 0x78],
                [0x3e, 0x49, 0x89],
                [0x31, 0x68, 0x8e],
                [0x26, 0x82, 0x8e],
                [0x1f, 0x9e, 0x89],
                [0x35, 0xb7, 0x79],
                [0x6d, 0xcd, 0x59],
                [0xfd, 0xe7, 0x25],
            ],
        }
    }

    /// A scale through the given colours, evenly spaced from the low to the high end. Returns
    /// `None` for fewer than two stops.
    pub fn new(stops: Vec<[u8; 3]>) -> Option<Self> {
        (stops.len() >= 2).then_some(ColorMap { stops })
    }

    /// Colour at `t` in `[0, 1]` (clamped); `NaN` gives the grey used for missing values.
    pub fn color(&self, t: f64) -> [u8; 3] {
        if t.is_nan() {
            return [MISSING.0, MISSING.1, MISSING.2];
        }
        let pos = t.clamp(0.0, 1.0) * (self.stops.len() - 1) as f64;
        let i = (pos.floor() as usize).min(self.stops.len() - 2);
        let f = pos - i as f64;
        let (a, b) = (self.stops[i], self.stops[i + 1]);
        std::array::from_fn(|c| (a[c] as f64 + f * (b[c] as f64 - a[c] as f64)).round() as u8)
    }

    fn rgb(&self, t: f64) -> RGBColor {
        let [r, g, b] = self.color(t);
        RGBColor(r, g, b)
    }
}

impl Default for ColorMap {
    fn default() -> Self {
        ColorMap::viridis()
    }
}

/// Where the values of a [`ScalarMap`] live.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScalarValues<'a> {
    /// One value per point, interpolated bilinearly over each quad.
    Nodal(&'a [f64]),
    /// One value per quad, drawn flat.
    PerCell(&'a [f64]),
}

/// A filled colour map of a scalar over a 2D quad mesh, with a colour bar.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarMap<'a> {
    /// Title drawn above the map.
    pub title: &'a str,
    /// Label of the horizontal axis.
    pub x_label: &'a str,
    /// Label of the vertical axis.
    pub y_label: &'a str,
    /// Point coordinates.
    pub points_xy: &'a [[f64; 2]],
    /// Quads as four point indices, in order around the quad.
    pub cell_quads: &'a [[usize; 4]],
    /// The scalar, per point or per quad.
    pub values: ScalarValues<'a>,
    /// Label of the colour bar (quantity and units).
    pub colorbar_label: &'a str,
    /// Colour scale.
    pub colormap: ColorMap,
    /// Value range of the colour scale; `None` uses the finite values' range. A fixed range
    /// keeps colours comparable across frames; values outside it are clamped.
    pub range: Option<(f64, f64)>,
}

/// Draws a colour map of nodal `values` over `cell_quads` into a PNG at `path`, with the
/// viridis scale spanning the values' range and a colour bar labelled `colorbar_label`.
///
/// `values` has one entry per point of `points_xy`; see [`draw_scalar_map_with`] for per-cell
/// values, a fixed range or another scale. The axes have equal scales, so the map keeps the
/// face's shape.
pub fn draw_scalar_map(
    path: &Path,
    title: &str,
    points_xy: &[[f64; 2]],
    values: &[f64],
    cell_quads: &[[usize; 4]],
    colorbar_label: &str,
) -> Result<(), PlotError> {
    draw_scalar_map_with(
        path,
        &ScalarMap {
            title,
            x_label: "x",
            y_label: "y",
            points_xy,
            cell_quads,
            values: ScalarValues::Nodal(values),
            colorbar_label,
            colormap: ColorMap::viridis(),
            range: None,
        },
    )
}

/// Draws `map` into a [`FIGURE_WIDTH`]×[`FIGURE_HEIGHT`] PNG at `path`.
///
/// Errors: value count not matching the points (nodal) or quads (per cell), a quad index out
/// of range, or a `range` that is not finite and increasing.
pub fn draw_scalar_map_with(path: &Path, map: &ScalarMap) -> Result<(), PlotError> {
    let invalid = |message: String| PlotError::InvalidData {
        path: path.to_path_buf(),
        message,
    };
    let (n_values, n_expected, what) = match map.values {
        ScalarValues::Nodal(v) => (v.len(), map.points_xy.len(), "points"),
        ScalarValues::PerCell(v) => (v.len(), map.cell_quads.len(), "quads"),
    };
    if n_values != n_expected {
        return Err(invalid(format!(
            "{n_values} values for {n_expected} {what}"
        )));
    }
    let n_points = map.points_xy.len();
    if let Some((q, quad)) = map
        .cell_quads
        .iter()
        .enumerate()
        .find(|(_, quad)| quad.iter().any(|&i| i >= n_points))
    {
        return Err(invalid(format!(
            "quad {q} {quad:?} refers to a point beyond the {n_points} points"
        )));
    }
    if let Some((lo, hi)) = map.range {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(invalid(format!(
                "colour range ({lo}, {hi}) is not finite and increasing"
            )));
        }
    }
    render_png(path, |root| render_scalar_map(root, map))
}

/// Registers the embedded font with plotters, once per process.
fn ensure_font() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, FONT_TTF).is_ok())
}

/// Result of drawing on a backend `DB`.
type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Renders with `draw` into a PNG at `path`, through a temporary file renamed into place.
fn render_png<F>(path: &Path, draw: F) -> Result<(), PlotError>
where
    F: for<'b> FnOnce(&DrawingArea<BitMapBackend<'b>, Shift>) -> DrawResult<BitMapBackend<'b>>,
{
    if !ensure_font() {
        return Err(PlotError::Font {
            path: path.to_path_buf(),
        });
    }
    let io_err = |source: io::Error| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };
    let draw_err = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let tmp = TempPath::reserve(path, ".png").map_err(io_err)?;
    {
        let root =
            BitMapBackend::new(tmp.path(), (FIGURE_WIDTH, FIGURE_HEIGHT)).into_drawing_area();
        draw(&root).map_err(|e| draw_err(&e))?;
        root.present().map_err(|e| draw_err(&e))?;
    }
    tmp.persist(path).map_err(io_err)
}

/// `(lo, hi)` widened so that it is a usable, non-empty axis range: an empty range becomes
/// `[0, 1]`, a constant one is padded around its value, and `margin` (a fraction of the
/// span) is added on both sides.
fn axis_range(lo: f64, hi: f64, margin: f64) -> Range<f64> {
    if !(lo.is_finite() && hi.is_finite()) || lo > hi {
        return 0.0..1.0;
    }
    let span = hi - lo;
    if !span.is_finite() {
        return lo..hi;
    }
    let scale = lo.abs().max(hi.abs());
    if span <= scale * 1e-12 || span == 0.0 {
        let pad = if scale > 0.0 { scale * 0.05 } else { 1.0 };
        return (lo - pad)..(hi + pad);
    }
    let pad = span * margin;
    if (lo - pad).is_finite() && (hi + pad).is_finite() {
        (lo - pad)..(hi + pad)
    } else {
        lo..hi
    }
}

/// Smallest and largest of the finite values, if any.
fn finite_bounds(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A tick-label formatter suited to the axis range `r`: fixed-point with as many decimals as
/// the tick spacing needs, or scientific notation (with as many mantissa digits as the
/// spacing needs) for very large or very small magnitudes.
fn tick_format(r: &Range<f64>) -> impl Fn(&f64) -> String {
    let span = (r.end - r.start).abs();
    let step = if span > 0.0 && span.is_finite() {
        span / 10.0
    } else {
        1.0
    };
    let magnitude = r.start.abs().max(r.end.abs());
    let scientific = !(1e-2..1e5).contains(&magnitude);
    let decimals = (-step.log10()).ceil().clamp(0.0, 10.0) as usize;
    let step_exponent = step.log10().floor();
    move |v: &f64| {
        let v = if v.abs() < step * 1e-6 { 0.0 } else { *v };
        if v == 0.0 {
            "0".to_string()
        } else if scientific {
            let digits = (v.abs().log10().floor() - step_exponent).clamp(0.0, 8.0) as usize;
            format!("{v:.digits$e}")
        } else {
            format!("{v:.decimals$}")
        }
    }
}

/// Splits a series into runs of consecutive finite points.
fn finite_runs(s: &Series) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut current = Vec::new();
    for (&x, &y) in s.x.iter().zip(&s.y) {
        if x.is_finite() && y.is_finite() {
            current.push((x, y));
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

fn render_line_plot<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &LinePlot,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let body = root.margin(8, 0, 0, 0).titled(&plot.title, (FAMILY, 26))?;

    let legend: Vec<(String, ShapeStyle)> = plot
        .series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
        .map(|(i, s)| {
            let style = PALETTE[i % PALETTE.len()].stroke_width(2);
            if finite_runs(s).is_empty() {
                (format!("{} (no data)", s.label), style)
            } else {
                (s.label.clone(), style)
            }
        })
        .collect();
    let legend_font = TextStyle::from((FAMILY, 16).into_font()).color(&BLACK);
    let (chart_area, legend_area) = if legend.is_empty() {
        (body, None)
    } else {
        let mut widest = 0;
        for (label, _) in &legend {
            widest = widest.max(body.estimate_text_size(label, &legend_font)?.0);
        }
        let legend_width = (widest + LEGEND_TEXT_X + 16).clamp(110, 330);
        let (width, _) = body.dim_in_pixel();
        let (a, b) = body.split_horizontally(width.saturating_sub(legend_width));
        (a, Some(b))
    };

    let xs = plot.series.iter().flat_map(|s| s.x.iter().zip(&s.y));
    let bounds_x = finite_bounds(xs.clone().filter(|(_, y)| y.is_finite()).map(|(x, _)| *x));
    let bounds_y = finite_bounds(xs.filter(|(x, _)| x.is_finite()).map(|(_, y)| *y));
    let (x0, x1) = bounds_x.unwrap_or((0.0, 1.0));
    let (y0, y1) = bounds_y.unwrap_or((0.0, 1.0));
    let x_range = axis_range(x0, x1, 0.0);
    let y_range = axis_range(y0, y1, 0.05);
    let (fx, fy) = (tick_format(&x_range), tick_format(&y_range));

    let mut chart = ChartBuilder::on(&chart_area)
        .margin(PLOT_MARGIN)
        .x_label_area_size(55)
        .y_label_area_size(95)
        .build_cartesian_2d(x_range, y_range)?;
    chart
        .configure_mesh()
        .x_desc(plot.x_label.as_str())
        .y_desc(plot.y_label.as_str())
        .axis_desc_style((FAMILY, 20))
        .label_style((FAMILY, 15))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()?;

    for (i, s) in plot.series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        for run in finite_runs(s) {
            if run.len() == 1 {
                chart.draw_series(run.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
            } else {
                chart.draw_series(LineSeries::new(run, color.stroke_width(2)))?;
            }
        }
    }

    if let Some(area) = legend_area {
        draw_legend(&area, &legend, &legend_font)?;
    }
    Ok(())
}

/// Margin around the plot panel, in pixels.
const PLOT_MARGIN: u32 = 20;
/// Horizontal position of legend texts (after the line sample), in pixels.
const LEGEND_TEXT_X: u32 = 48;
/// Height of one legend row, in pixels.
const LEGEND_ROW: i32 = 24;

/// Draws the legend as a boxed column of (line sample, label) rows.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, ShapeStyle)],
    font: &TextStyle,
) -> DrawResult<DB> {
    let (width, _) = area.dim_in_pixel();
    let top = PLOT_MARGIN as i32;
    let bottom = top + LEGEND_ROW * entries.len() as i32 + 8;
    area.draw(&Rectangle::new(
        [(2, top), (width as i32 - 8, bottom)],
        RGBColor(150, 150, 150).stroke_width(1),
    ))?;
    for (k, (label, style)) in entries.iter().enumerate() {
        let y = top + 4 + LEGEND_ROW * k as i32 + LEGEND_ROW / 2;
        area.draw(&PathElement::new(vec![(10, y), (40, y)], *style))?;
        let text_style = font.pos(Pos::new(HPos::Left, VPos::Center));
        area.draw_text(label, &text_style, (LEGEND_TEXT_X as i32, y))?;
    }
    Ok(())
}

/// Width of the colour-bar column, in pixels.
const COLORBAR_WIDTH: u32 = 170;
/// Number of colour bands drawn in the colour bar.
const COLORBAR_BANDS: usize = 256;

fn render_scalar_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    map: &ScalarMap,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let body = root.margin(8, 0, 0, 0).titled(map.title, (FAMILY, 26))?;
    let (width, _) = body.dim_in_pixel();
    let (main, bar) = body.split_horizontally(width.saturating_sub(COLORBAR_WIDTH));

    let values: &[f64] = match map.values {
        ScalarValues::Nodal(v) | ScalarValues::PerCell(v) => v,
    };
    let (v_lo, v_hi) = match map.range {
        Some(r) => r,
        None => {
            let r = finite_bounds(values.iter().copied()).unwrap_or((0.0, 1.0));
            let padded = axis_range(r.0, r.1, 0.0);
            (padded.start, padded.end)
        }
    };
    let to_unit = |v: f64| (v - v_lo) / (v_hi - v_lo);

    // Geometry of the quads actually drawn (all corners finite).
    let drawable: Vec<(usize, [usize; 4])> = map
        .cell_quads
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, q)| {
            q.iter()
                .all(|&i| map.points_xy[i].iter().all(|c| c.is_finite()))
        })
        .collect();
    let used = drawable
        .iter()
        .flat_map(|(_, q)| q.iter().map(|&i| map.points_xy[i]));
    let bx = finite_bounds(used.clone().map(|p| p[0])).unwrap_or((0.0, 1.0));
    let by = finite_bounds(used.map(|p| p[1])).unwrap_or((0.0, 1.0));
    let (x_range, y_range) = equal_aspect(
        &main,
        axis_range(bx.0, bx.1, 0.02),
        axis_range(by.0, by.1, 0.02),
    )?;
    let (fx, fy) = (tick_format(&x_range), tick_format(&y_range));
    let mut chart = map_chart(&main).build_cartesian_2d(x_range, y_range)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.x_label)
        .y_desc(map.y_label)
        .axis_desc_style((FAMILY, 20))
        .label_style((FAMILY, 15))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()?;

    for &(q, quad) in &drawable {
        let corners = quad.map(|i| map.points_xy[i]);
        match map.values {
            ScalarValues::PerCell(v) => {
                let color = map.colormap.rgb(to_unit(v[q]));
                let poly: Vec<(f64, f64)> = corners.iter().map(|p| (p[0], p[1])).collect();
                chart.draw_series(std::iter::once(Polygon::new(poly, color.filled())))?;
            }
            ScalarValues::Nodal(v) => {
                let nodal = quad.map(|i| v[i]);
                let pixels = corners.map(|p| chart.backend_coord(&(p[0], p[1])));
                let longest = (0..4)
                    .map(|k| {
                        let (a, b) = (pixels[k], pixels[(k + 1) % 4]);
                        ((a.0 - b.0).abs()).max((a.1 - b.1).abs())
                    })
                    .max()
                    .unwrap_or(0);
                let n = (longest / 4).clamp(1, 32) as usize;
                let cells = subdivide(&corners, &nodal, n).map(|(poly, value)| {
                    Polygon::new(poly, map.colormap.rgb(to_unit(value)).filled())
                });
                chart.draw_series(cells)?;
            }
        }
    }
    if drawable.len() <= 2500 {
        let edges = drawable.iter().map(|(_, quad)| {
            let mut poly: Vec<(f64, f64)> = quad
                .iter()
                .map(|&i| (map.points_xy[i][0], map.points_xy[i][1]))
                .collect();
            poly.push(poly[0]);
            PathElement::new(poly, BLACK.mix(0.35))
        });
        chart.draw_series(edges)?;
    }

    draw_colorbar(&bar, map, v_lo, v_hi)
}

/// Chart layout of the map panel (shared by the measuring and the drawing pass).
fn map_chart<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(15)
        .x_label_area_size(55)
        .y_label_area_size(95);
    builder
}

/// Widens one of the two ranges so that one unit has the same length in x and y on `area`.
#[allow(clippy::type_complexity)]
fn equal_aspect<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x: Range<f64>,
    y: Range<f64>,
) -> Result<(Range<f64>, Range<f64>), DrawingAreaErrorKind<DB::ErrorType>> {
    let probe = map_chart(area).build_cartesian_2d(x.clone(), y.clone())?;
    let (pw, ph) = probe.plotting_area().dim_in_pixel();
    let (pw, ph) = (pw.max(1) as f64, ph.max(1) as f64);
    let (dx, dy) = (x.end - x.start, y.end - y.start);
    if !(dx.is_finite() && dy.is_finite()) {
        return Ok((x, y));
    }
    let scale = (pw / dx).min(ph / dy);
    let (half_x, half_y) = (pw / scale / 2.0, ph / scale / 2.0);
    let (cx, cy) = ((x.start + x.end) / 2.0, (y.start + y.end) / 2.0);
    Ok(((cx - half_x)..(cx + half_x), (cy - half_y)..(cy + half_y)))
}

/// Splits a quad into `n`×`n` sub-quads by bilinear interpolation of corners and values;
/// each sub-quad carries the interpolated value at its centre.
fn subdivide(
    corners: &[[f64; 2]; 4],
    values: &[f64; 4],
    n: usize,
) -> impl Iterator<Item = (Vec<(f64, f64)>, f64)> {
    let corners = *corners;
    let values = *values;
    let at = move |s: f64, t: f64| {
        let w = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
        let x = (0..4).map(|k| w[k] * corners[k][0]).sum::<f64>();
        let y = (0..4).map(|k| w[k] * corners[k][1]).sum::<f64>();
        let v = (0..4).map(|k| w[k] * values[k]).sum::<f64>();
        (x, y, v)
    };
    let h = 1.0 / n as f64;
    (0..n * n).map(move |k| {
        let (i, j) = ((k % n) as f64, (k / n) as f64);
        let poly = [(i, j), (i + 1.0, j), (i + 1.0, j + 1.0), (i, j + 1.0)]
            .iter()
            .map(|&(a, b)| {
                let (x, y, _) = at(a * h, b * h);
                (x, y)
            })
            .collect();
        let (_, _, v) = at((i + 0.5) * h, (j + 0.5) * h);
        (poly, v)
    })
}

/// Draws the vertical colour bar with its value axis and label.
fn draw_colorbar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    map: &ScalarMap,
    lo: f64,
    hi: f64,
) -> DrawResult<DB> {
    let range = lo..hi;
    let fmt = tick_format(&range);
    let mut chart = ChartBuilder::on(area)
        .margin_top(15)
        .margin_bottom(15 + 55)
        .margin_left(10)
        .margin_right(15)
        .set_label_area_size(LabelAreaPosition::Right, 110)
        .build_cartesian_2d(0.0..1.0, range)?;
    let band = (hi - lo) / COLORBAR_BANDS as f64;
    chart.draw_series((0..COLORBAR_BANDS).map(|k| {
        let (a, b) = (lo + band * k as f64, lo + band * (k + 1) as f64);
        let t = (k as f64 + 0.5) / COLORBAR_BANDS as f64;
        Rectangle::new([(0.0, a), (1.0, b)], map.colormap.rgb(t).filled())
    }))?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, lo), (1.0, hi)],
        BLACK.mix(0.6),
    )))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(map.colorbar_label)
        .axis_desc_style((FAMILY, 18))
        .label_style((FAMILY, 15))
        .y_label_formatter(&fmt)
        .draw()
}

#[cfg(test)]
mod tests {
    use super::super::atomic::test_support::TestDir;
    use super::*;

    const W: u32 = FIGURE_WIDTH;
    const H: u32 = FIGURE_HEIGHT;

    /// Renders into an RGB buffer (what the PNG file holds, without the encoding).
    fn render_buffer<F>(draw: F) -> Vec<u8>
    where
        F: for<'b> FnOnce(&DrawingArea<BitMapBackend<'b>, Shift>) -> DrawResult<BitMapBackend<'b>>,
    {
        assert!(ensure_font());
        let mut buf = vec![0u8; (W * H * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
            draw(&root).unwrap();
            root.present().unwrap();
        }
        buf
    }

    fn pixel(buf: &[u8], x: u32, y: u32) -> [u8; 3] {
        let i = ((y * W + x) * 3) as usize;
        [buf[i], buf[i + 1], buf[i + 2]]
    }

    /// Counts pixels in the rectangle `[x0, x1) × [y0, y1)` satisfying `pred`.
    fn count(
        buf: &[u8],
        (x0, x1): (u32, u32),
        (y0, y1): (u32, u32),
        pred: impl Fn([u8; 3]) -> bool,
    ) -> usize {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| pred(pixel(buf, x, y)))
            .count()
    }

    fn near(a: [u8; 3], b: RGBColor, tol: i32) -> bool {
        (a[0] as i32 - b.0 as i32).abs() <= tol
            && (a[1] as i32 - b.1 as i32).abs() <= tol
            && (a[2] as i32 - b.2 as i32).abs() <= tol
    }

    /// Checks the PNG signature and the IHDR width and height.
    fn png_size(path: &Path) -> (u32, u32) {
        let bytes = std::fs::read(path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&bytes[12..16], b"IHDR");
        let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        (w, h)
    }

    fn sample_plot() -> LinePlot {
        let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.01).collect();
        LinePlot {
            title: "Normal force on the indenter".into(),
            x_label: "time (s)".into(),
            y_label: "force (N)".into(),
            series: vec![
                Series {
                    label: "F_z".into(),
                    x: t.clone(),
                    y: t.iter().map(|t| (6.0 * t).sin() * 1e3).collect(),
                },
                Series {
                    label: "F_x (with gaps)".into(),
                    x: t.clone(),
                    y: t.iter()
                        .enumerate()
                        .map(|(i, t)| {
                            if i % 50 == 25 {
                                f64::NAN
                            } else {
                                400.0 * t - 300.0
                            }
                        })
                        .collect(),
                },
                Series {
                    label: "adhesion".into(),
                    x: t.clone(),
                    y: vec![250.0; t.len()],
                },
            ],
        }
    }

    #[test]
    fn line_plot_draws_series_in_the_plot_area() {
        let plot = sample_plot();
        let buf = render_buffer(|root| render_line_plot(root, &plot));
        let plot_area = ((150, 900), (80, 600));
        let non_white = count(&buf, plot_area.0, plot_area.1, |p| p != [255, 255, 255]);
        assert!(non_white > 2000, "only {non_white} drawn pixels");
        for (i, expected) in [(0, 300), (1, 300), (2, 300)] {
            let c = PALETTE[i];
            let n = count(&buf, (0, W), (0, H), |p| near(p, c, 10));
            assert!(n > expected, "series {i}: {n} pixels of its colour");
        }
        // Axis labels and title are drawn as dark text outside the plot area.
        let title = count(&buf, (300, 700), (0, 45), |p| p[0] < 100);
        assert!(title > 100, "title pixels: {title}");
        let y_label = count(&buf, (0, 40), (200, 500), |p| p[0] < 100);
        assert!(y_label > 50, "y label pixels: {y_label}");
        // The legend column right of the plot holds a sample of every series' colour.
        for c in &PALETTE[..3] {
            let n = count(&buf, (800, W), (40, 200), |p| near(p, *c, 10));
            assert!(n > 20, "legend sample of {c:?}: {n} pixels");
        }
    }

    #[test]
    fn line_plot_file_is_a_png_of_the_expected_size() {
        let dir = TestDir::new("plot-line");
        let path = dir.path().join("force.png");
        draw_line_plot(&path, &sample_plot()).unwrap();
        assert_eq!(png_size(&path), (W, H));
        assert_eq!(dir.entries(), vec!["force.png".to_string()]);
        draw_line_plot(&path, &sample_plot()).unwrap();
        assert_eq!(dir.entries(), vec!["force.png".to_string()]);
    }

    #[test]
    fn degenerate_data_does_not_panic() {
        let dir = TestDir::new("plot-degenerate");
        let cases = [
            LinePlot::default(),
            LinePlot {
                series: vec![Series {
                    label: "empty".into(),
                    ..Series::default()
                }],
                ..LinePlot::default()
            },
            LinePlot {
                series: vec![Series {
                    label: "all nan".into(),
                    x: vec![f64::NAN; 3],
                    y: vec![1.0, f64::NAN, f64::INFINITY],
                }],
                ..LinePlot::default()
            },
            LinePlot {
                series: vec![Series {
                    label: "constant".into(),
                    x: vec![2.0; 4],
                    y: vec![0.0; 4],
                }],
                ..LinePlot::default()
            },
            LinePlot {
                series: vec![Series {
                    label: "one point".into(),
                    x: vec![1e300],
                    y: vec![-1e-300],
                }],
                ..LinePlot::default()
            },
            LinePlot {
                series: (0..14)
                    .map(|i| Series {
                        label: format!("s{i}"),
                        x: vec![0.0, 1.0],
                        y: vec![i as f64, f64::MAX / 2.0],
                    })
                    .collect(),
                ..LinePlot::default()
            },
        ];
        for (k, plot) in cases.iter().enumerate() {
            let path = dir.path().join(format!("case{k}.png"));
            draw_line_plot(&path, plot).unwrap();
            assert_eq!(png_size(&path), (W, H));
        }
        let bad = LinePlot {
            series: vec![Series {
                label: "bad".into(),
                x: vec![1.0, 2.0],
                y: vec![1.0],
            }],
            ..LinePlot::default()
        };
        let path = dir.path().join("bad.png");
        let err = draw_line_plot(&path, &bad).unwrap_err();
        assert!(matches!(err, PlotError::InvalidData { .. }));
        assert!(err.to_string().contains("bad.png"), "{err}");
        assert!(!path.exists());
    }

    #[test]
    fn missing_directory_is_an_io_error_naming_the_file() {
        let dir = TestDir::new("plot-missing");
        let path = dir.path().join("nope").join("x.png");
        let err = draw_line_plot(&path, &sample_plot()).unwrap_err();
        assert!(matches!(err, PlotError::Io { .. }));
        assert!(err.to_string().contains("x.png"), "{err}");
    }

    /// A 6×3 grid of quads on [0, 3] × [0, 1.5] with a value increasing along x.
    fn grid() -> (Vec<[f64; 2]>, Vec<[usize; 4]>, Vec<f64>) {
        let (nx, ny) = (6, 3);
        let mut points = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                points.push([i as f64 * 0.5, j as f64 * 0.5]);
            }
        }
        let id = |i: usize, j: usize| i + (nx + 1) * j;
        let quads = (0..ny)
            .flat_map(|j| {
                (0..nx).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
            })
            .collect();
        let values = points.iter().map(|p| 1e5 * p[0] + 2e4 * p[1]).collect();
        (points, quads, values)
    }

    #[test]
    fn scalar_map_spans_the_colour_scale() {
        let (points, quads, values) = grid();
        let map = ScalarMap {
            title: "Contact pressure",
            x_label: "x (m)",
            y_label: "y (m)",
            points_xy: &points,
            cell_quads: &quads,
            values: ScalarValues::Nodal(&values),
            colorbar_label: "p (Pa)",
            colormap: ColorMap::viridis(),
            range: None,
        };
        let buf = render_buffer(|root| render_scalar_map(root, &map));
        let cm = ColorMap::viridis();
        let low = cm.rgb(0.02);
        let high = cm.rgb(0.98);
        let map_area = ((100, 800), (40, 640));
        let n_low = count(&buf, map_area.0, map_area.1, |p| near(p, low, 30));
        let n_high = count(&buf, map_area.0, map_area.1, |p| near(p, high, 30));
        assert!(n_low > 500 && n_high > 500, "low {n_low}, high {n_high}");
        // The colour bar column holds the whole scale too.
        let bar = ((W - COLORBAR_WIDTH, W), (0, H));
        assert!(count(&buf, bar.0, bar.1, |p| near(p, low, 20)) > 100);
        assert!(count(&buf, bar.0, bar.1, |p| near(p, high, 20)) > 100);
    }

    #[test]
    fn scalar_map_marks_missing_values_and_writes_png() {
        let dir = TestDir::new("plot-map");
        let (points, quads, mut values) = grid();
        values[0] = f64::NAN;
        let path = dir.path().join("pressure.png");
        draw_scalar_map(
            &path,
            "Contact pressure",
            &points,
            &values,
            &quads,
            "p (Pa)",
        )
        .unwrap();
        assert_eq!(png_size(&path), (W, H));
        assert_eq!(dir.entries(), vec!["pressure.png".to_string()]);

        let per_cell: Vec<f64> = (0..quads.len())
            .map(|q| if q == 7 { f64::NAN } else { q as f64 })
            .collect();
        let map = ScalarMap {
            title: "Per-cell status",
            x_label: "x",
            y_label: "y",
            points_xy: &points,
            cell_quads: &quads,
            values: ScalarValues::PerCell(&per_cell),
            colorbar_label: "state",
            colormap: ColorMap::viridis(),
            range: Some((0.0, 10.0)),
        };
        let buf = render_buffer(|root| render_scalar_map(root, &map));
        let grey = count(&buf, (0, W - COLORBAR_WIDTH), (0, H), |p| {
            near(p, MISSING, 2)
        });
        assert!(grey > 200, "NaN cell pixels: {grey}");
        draw_scalar_map_with(&dir.path().join("cells.png"), &map).unwrap();
    }

    #[test]
    fn scalar_map_rejects_inconsistent_input_and_survives_empty_input() {
        let dir = TestDir::new("plot-map-bad");
        let (points, quads, values) = grid();
        let path = dir.path().join("m.png");
        let err = draw_scalar_map(&path, "t", &points, &values[1..], &quads, "v").unwrap_err();
        assert!(matches!(err, PlotError::InvalidData { .. }), "{err}");
        let bad_quads = [[0, 1, 2, 999]];
        let err = draw_scalar_map(&path, "t", &points, &values, &bad_quads, "v").unwrap_err();
        assert!(err.to_string().contains("m.png"), "{err}");
        assert!(!path.exists());
        draw_scalar_map(&path, "empty", &[], &[], &[], "v").unwrap();
        let constant = vec![3.0; points.len()];
        draw_scalar_map(&path, "constant", &points, &constant, &quads, "v").unwrap();
        assert_eq!(png_size(&path), (W, H));
    }

    #[test]
    fn colormap_interpolates_and_clamps() {
        let cm = ColorMap::viridis();
        assert_eq!(cm.color(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(cm.color(1.0), [0xfd, 0xe7, 0x25]);
        assert_eq!(cm.color(-3.0), cm.color(0.0));
        assert_eq!(cm.color(7.0), cm.color(1.0));
        assert_eq!(cm.color(f64::NAN), [200, 200, 200]);
        let two = ColorMap::new(vec![[0, 0, 0], [200, 100, 50]]).unwrap();
        assert_eq!(two.color(0.5), [100, 50, 25]);
        assert!(ColorMap::new(vec![[0, 0, 0]]).is_none());
    }

    #[test]
    fn tick_labels_are_short_and_exact_enough() {
        let f = tick_format(&(0.0..2.0));
        assert_eq!(f(&0.5), "0.5");
        assert_eq!(f(&1e-17), "0");
        let f = tick_format(&(0.0..3e6));
        assert_eq!(f(&1.5e6), "1.5e6");
        let f = tick_format(&(1e-6..3e-6));
        assert_eq!(f(&2e-6), "2.0e-6");
        let f = tick_format(&(1e6..1.0002e6));
        assert_eq!(f(&1.00001e6), "1.00001e6");
        let f = tick_format(&(100.0..400.0));
        assert_eq!(f(&250.0), "250");
    }
}
