//! Force against pull distance of scenarios/contact/pad-on-pad-pull-off.toml (two soft pads
//! on non-matching meshes, bonded on mortar sites and pulled apart) beside the closed form of
//! the rate-independent RCC interface in series with the two pads.
//!
//! Usage: `cargo run --release --example pad_on_pad_figure -- OUT.png DIR`, DIR the run
//! directory (with history.csv). The closed form: the interface opens by u under the
//! traction C_n u up to u_c = √(w / C_n), then w² / (C_n u³) as the bonds break; the pads
//! (2 mm together, plane strain, free to contract sideways) stretch by F H / (E' A) with
//! E' = E / (1 − ν²); the pull distance is their sum. Prints the peak force and the work of
//! separation against A √(C_n w) and w A.

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

/// The scenario's interface (C_n [N/m³], w [J/m²]), contact area [m²], pads' total height [m],
/// Young's modulus [Pa] and Poisson's ratio.
const CN: f64 = 1e10;
const W: f64 = 0.05;
const AREA: f64 = 4e-6;
const HEIGHT: f64 = 2e-3;
const YOUNG: f64 = 100e6;
const POISSON: f64 = 0.3;

/// The closed form's (pull distance [m], tensile force [N]) at interface opening `u` [m].
fn closed_form(u: f64) -> (f64, f64) {
    let u_c = (W / CN).sqrt();
    let traction = if u <= u_c {
        CN * u
    } else {
        W * W / (CN * u.powi(3))
    };
    let force = AREA * traction;
    let stiffness = YOUNG / (1.0 - POISSON * POISSON) * AREA / HEIGHT;
    (u + force / stiffness, force)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 2 {
        eprintln!("usage: pad_on_pad_figure OUT.png DIR");
        std::process::exit(2);
    }
    let (columns, rows) =
        read_history(Path::new(&args[1]).join("history.csv")).expect("a run's history.csv");
    let col = |name: &str| {
        columns
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (ku, kf) = (col("lower.bottom.uy"), col("lower.bottom.Fy"));
    // The pull: the lower pad's bottom below its undeformed position, tension positive.
    let pulled: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r[ku] <= 0.0)
        .map(|r| (-r[ku], -r[kf]))
        .collect();
    let peak = pulled.iter().map(|p| p.1).fold(0.0, f64::max);
    let work: f64 = pulled
        .windows(2)
        .map(|p| 0.5 * (p[0].1.max(0.0) + p[1].1.max(0.0)) * (p[1].0 - p[0].0))
        .sum();
    println!(
        "peak {peak:.5e} N (A √(C_n w) = {:.5e} N), work {work:.5e} J (w A = {:.5e} J)",
        AREA * (CN * W).sqrt(),
        W * AREA
    );
    let um = |p: &[(f64, f64)]| -> (Vec<f64>, Vec<f64>) {
        (
            p.iter().map(|q| q.0 * 1e6).collect(),
            p.iter().map(|q| q.1 * 1e3).collect(),
        )
    };
    // Drawn up to 15 µm, where the force is 1 % of its peak.
    let end = 15e-6;
    let shown: Vec<(f64, f64)> = pulled.iter().copied().filter(|p| p.0 <= end).collect();
    let (x, y) = um(&shown);
    let closed: Vec<(f64, f64)> = (0..=400)
        .map(|i| closed_form(end * (i as f64 / 400.0).powi(2)))
        .filter(|p| p.0 <= end)
        .collect();
    let (cx, cy) = um(&closed);
    let plot = LinePlot {
        title: "Two soft pads on non-matching meshes pulled apart (mortar contact)".into(),
        x_label: "pull distance [µm]".into(),
        y_label: "tensile force [mN]".into(),
        series: vec![
            Series {
                label: "mortar, 8 on 5 faces".into(),
                x,
                y,
            },
            Series {
                label: "closed form".into(),
                x: cx,
                y: cy,
            },
        ],
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
