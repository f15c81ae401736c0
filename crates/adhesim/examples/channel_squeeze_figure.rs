//! Plate force against plate travel of scenarios/contact/channel-squeeze.toml (a soft tube
//! squeezed until its inner walls touch and bond, then pulled open): the squeeze, the way
//! back while the walls are bonded, and the way back after the bonds broke.
//!
//! Usage: `cargo run --release --example channel_squeeze_figure -- OUT.png DIR`, DIR the run
//! directory (with history.csv). Prints where the first bonds formed, where the plate force
//! changed sign with the walls bonded, and where the last bond broke.

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

/// The squeeze ends at 1 s and the plate starts back at 1.5 s (the scenario's table).
const SQUEEZE_END: f64 = 1.0;
const RETURN_START: f64 = 1.5;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 2 {
        eprintln!("usage: channel_squeeze_figure OUT.png DIR");
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
    let (kt, ku, kf, kb) = (
        col("t"),
        col("tube.top_grip.uy"),
        col("tube.top_grip.Fy"),
        col("walls.bonded"),
    );
    // Travel downwards [mm] and the plate's push on the tube [mN] (negative: it pulls).
    let point = |r: &Vec<f64>| (-1e3 * r[ku], -1e3 * r[kf]);
    let series = |label: &str, keep: &dyn Fn(&Vec<f64>) -> bool| {
        let (x, y) = rows.iter().filter(|r| keep(r)).map(point).unzip();
        Series {
            label: label.into(),
            x,
            y,
        }
    };
    if let Some(r) = rows.iter().find(|r| r[kb] > 0.0) {
        println!("first bonds at {:.3} mm of travel", -1e3 * r[ku]);
    }
    if let Some(r) = rows
        .iter()
        .find(|r| r[kt] > RETURN_START && r[kf] > 0.0 && r[kb] > 0.0)
    {
        println!(
            "plate force changes sign at {:.3} mm with {} sites bonded",
            -1e3 * r[ku],
            r[kb]
        );
    }
    let broken = rows
        .iter()
        .position(|r| r[kt] > RETURN_START && r[kb] == 0.0)
        .unwrap_or(rows.len());
    if broken < rows.len() {
        println!("last bond broken at {:.3} mm", -1e3 * rows[broken][ku]);
    }
    let t_broken = rows.get(broken).map_or(f64::INFINITY, |r| r[kt]);
    let plot = LinePlot {
        title: "A soft channel squeezed shut, bonded to itself and pulled open".into(),
        x_label: "plate travel downwards [mm]".into(),
        y_label: "plate force, pushing [mN]".into(),
        series: vec![
            series("squeeze", &|r| r[kt] <= SQUEEZE_END),
            series("back, walls bonded", &|r| {
                r[kt] >= RETURN_START && r[kt] < t_broken
            }),
            series("back, bonds broken", &|r| r[kt] >= t_broken),
        ],
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
