//! Force against the flat's position for scenarios/soft/ball-pull-off.toml (a soft ball of
//! second-order tetrahedra pressed onto an adhesive flat and pulled off), beside the
//! Derjaguin-Muller-Toporov answer: F = 4/3 E* √R d^(3/2) − 2π w R in contact (d ≥ 0), and
//! the pull-off force 2π w R.
//!
//! Usage: `cargo run --release --example ball_pull_off_figure -- OUT.png DIR`, DIR the run
//! directory (with history.csv). The flat's position d (positive into the ball) comes from
//! the scenario's motion, the force is 4 × `flat.fy` (four quarters) [N]. Prints the largest
//! pull and the force at the end of the hold.

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

/// The scenario's radius [m], indentation [m], times [s], pull speed [m/s], moduli [Pa] and
/// work of adhesion [J/m²].
const RADIUS: f64 = 5e-3;
const PRESS: f64 = 0.02e-3;
const T_PRESS: f64 = 0.1;
const T_HOLD: f64 = 0.15;
const V_PULL: f64 = 1e-4;
const MU: f64 = 0.6e6;
const KAPPA: f64 = 3e9;
const W: f64 = 0.05;

/// The flat's position at time t [m], positive into the ball.
fn flat(t: f64) -> f64 {
    if t <= T_PRESS {
        PRESS * t / T_PRESS
    } else if t <= T_HOLD {
        PRESS
    } else {
        PRESS - V_PULL * (t - T_HOLD)
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 2 {
        eprintln!("usage: ball_pull_off_figure OUT.png DIR");
        std::process::exit(2);
    }
    let nu = (3.0 * KAPPA - 2.0 * MU) / (2.0 * (3.0 * KAPPA + MU));
    let e_star = 2.0 * MU * (1.0 + nu) / (1.0 - nu * nu);
    let pull_off = 2.0 * std::f64::consts::PI * W * RADIUS;
    let (columns, rows) =
        read_history(Path::new(&args[1]).join("history.csv")).expect("a run's history.csv");
    let col = |name: &str| {
        columns
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (kt, kf) = (col("t"), col("flat.fy"));
    let (mut load, mut unload) = (
        (Vec::<f64>::new(), Vec::<f64>::new()),
        (Vec::<f64>::new(), Vec::<f64>::new()),
    );
    let mut largest_pull: f64 = 0.0;
    for r in &rows {
        let (t, f) = (r[kt], 4.0 * r[kf]);
        let side = if t <= T_HOLD { &mut load } else { &mut unload };
        side.0.push(flat(t) * 1e3);
        side.1.push(f * 1e3);
        if (t - T_HOLD).abs() < 1e-9 {
            println!("end of the hold: F = {:.4} mN", f * 1e3);
        }
        largest_pull = largest_pull.max(-f);
    }
    println!(
        "largest pull {:.4} mN; 2π w R = {:.4} mN; ratio {:.4}",
        largest_pull * 1e3,
        pull_off * 1e3,
        largest_pull / pull_off
    );
    let d: Vec<f64> = (0..=50).map(|i| PRESS * i as f64 / 50.0).collect();
    let hertz = |d: f64| 4.0 / 3.0 * e_star * RADIUS.sqrt() * d.powf(1.5);
    let lowest = unload.0.iter().copied().fold(0.0, f64::min);
    let series = vec![
        Series {
            label: "tet10, pressing and hold".into(),
            x: load.0,
            y: load.1,
        },
        Series {
            label: "tet10, pulling off".into(),
            x: unload.0,
            y: unload.1,
        },
        Series {
            label: "DMT: 4/3 E* √R d^3/2 − 2π w R".into(),
            x: d.iter().map(|d| d * 1e3).collect(),
            y: d.iter().map(|&d| (hertz(d) - pull_off) * 1e3).collect(),
        },
        Series {
            label: "DMT pull-off force −2π w R".into(),
            x: vec![lowest, PRESS * 1e3],
            y: vec![-pull_off * 1e3; 2],
        },
    ];
    let plot = LinePlot {
        title: "Soft ball (tet10, ν = 0.4999) on an adhesive flat: press, hold, pull off".into(),
        x_label: "position of the flat d [mm] (into the ball)".into(),
        y_label: "force on the flat [mN]".into(),
        series,
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
