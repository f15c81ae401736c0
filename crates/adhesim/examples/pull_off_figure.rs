//! Pull-off force against pull speed from runs of scenarios/soft/pdms-pull-off.toml.
//!
//! Usage: `cargo run --release --example pull_off_figure -- OUT.png DIR=SPEED...`, each DIR a
//! run directory (with history.csv) and SPEED its `v_pull` [m/s]. The pull-off force is the
//! largest tensile force of the `flat` contact pair on the cap, −min(flat.fy) [N]. Prints a
//! table and draws the figure (x: log₁₀ of the speed).

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: pull_off_figure OUT.png DIR=SPEED...");
        std::process::exit(2);
    }
    let mut points = Vec::new();
    println!("| v_pull [m/s] | pull-off force [N] |");
    println!("|---|---|");
    for arg in &args[1..] {
        let (dir, speed) = arg.rsplit_once('=').expect("DIR=SPEED");
        let speed: f64 = speed.parse().expect("a speed in m/s");
        let (columns, rows) =
            read_history(Path::new(dir).join("history.csv")).expect("a run's history.csv");
        let k = columns
            .iter()
            .position(|c| c == "flat.fy")
            .expect("a `flat.fy` column");
        let pull_off = -rows.iter().map(|r| r[k]).fold(f64::INFINITY, f64::min);
        println!("| {speed:e} | {pull_off:.5} |");
        points.push((speed.log10(), pull_off));
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let plot = LinePlot {
        title: "PDMS-like cap pulled off an adhesive flat".into(),
        x_label: "log10 of the pull speed [m/s]".into(),
        y_label: "pull-off force [N]".into(),
        series: vec![Series {
            label: "viscoelastic, F-bar".into(),
            x: points.iter().map(|p| p.0).collect(),
            y: points.iter().map(|p| p.1).collect(),
        }],
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
