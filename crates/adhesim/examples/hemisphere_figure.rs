//! Force against indentation of scenarios/soft/tet-hemisphere.toml (a quarter of a nearly
//! incompressible hemisphere on a rigid flat) beside Hertz's 4/3 E* √R d^(3/2).
//!
//! Usage: `cargo run --release --example hemisphere_figure -- OUT.png LABEL=DIR...`, each
//! DIR a run directory (with history.csv) of the scenario. The indentation is d = press · t
//! (the flat's motion, 0.25 mm over 1 s), the force 4 × `flat.fy` (four quarters) [N].
//! Prints the table of force over Hertz at each step.

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

/// Sphere radius [m], indentation at t = 1 s [m], shear and bulk moduli [Pa] of the scenario.
const RADIUS: f64 = 5e-3;
const PRESS: f64 = 0.25e-3;
const MU: f64 = 0.6e6;
const KAPPA: f64 = 3e9;

/// Hertz's force [N] of a sphere of radius `r` [m] pressed by `d` [m] on a rigid flat.
fn hertz(e_star: f64, r: f64, d: f64) -> f64 {
    4.0 / 3.0 * e_star * r.sqrt() * d.powf(1.5)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: hemisphere_figure OUT.png LABEL=DIR...");
        std::process::exit(2);
    }
    let nu = (3.0 * KAPPA - 2.0 * MU) / (2.0 * (3.0 * KAPPA + MU));
    let e_star = 2.0 * MU * (1.0 + nu) / (1.0 - nu * nu);
    let mut series = Vec::new();
    for arg in &args[1..] {
        let (label, dir) = arg.split_once('=').expect("LABEL=DIR");
        let (columns, rows) =
            read_history(Path::new(dir).join("history.csv")).expect("a run's history.csv");
        let col = |name: &str| {
            columns
                .iter()
                .position(|c| c == name)
                .unwrap_or_else(|| panic!("no column {name}"))
        };
        let (kt, kf) = (col("t"), col("flat.fy"));
        println!("{label}:");
        println!("| d [mm] | F [N] | F / Hertz |");
        println!("|---|---|---|");
        let (mut x, mut y) = (vec![0.0], vec![0.0]);
        for r in rows.iter().filter(|r| r[kt] > 0.0) {
            let d = PRESS * r[kt];
            let f = 4.0 * r[kf];
            println!(
                "| {:.4} | {f:.4} | {:.3} |",
                d * 1e3,
                f / hertz(e_star, RADIUS, d)
            );
            x.push(d * 1e3);
            y.push(f);
        }
        series.push(Series {
            label: label.to_string(),
            x,
            y,
        });
    }
    let d: Vec<f64> = (0..=50).map(|i| PRESS * i as f64 / 50.0).collect();
    series.push(Series {
        label: "Hertz, 4/3 E* √R d^3/2".into(),
        x: d.iter().map(|d| d * 1e3).collect(),
        y: d.iter().map(|&d| hertz(e_star, RADIUS, d)).collect(),
    });
    let plot = LinePlot {
        title: "Nearly incompressible hemisphere (ν = 0.4999) on a rigid flat, tetrahedra".into(),
        x_label: "indentation d [mm]".into(),
        y_label: "force [N]".into(),
        series,
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
