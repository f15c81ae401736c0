//! Pull-off force against cycle number from runs of scenarios/interface/fatigue-pull-off.toml.
//!
//! Usage: `cargo run --release --example fatigue_figure -- OUT.png DIR=LABEL...`, each DIR a
//! run directory (with history.csv) and LABEL its legend. The pull-off force of cycle k is
//! the largest tensile force of the `flat` pair on the pad within second k, −min(flat.fy)
//! [N]. The closed form of the fatigue law, A √(C_n w/(1 + (k−1) w/D_f)) with the scenario's
//! values, is drawn beside them. Prints a table.

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: fatigue_figure OUT.png DIR=LABEL...");
        std::process::exit(2);
    }
    let (w, cn, df, area) = (20.0f64, 2e9f64, 40.0f64, 1e-6f64);
    let cycles: Vec<f64> = (1..=5).map(f64::from).collect();
    let closed: Vec<f64> = cycles
        .iter()
        .map(|k| area * (cn * w / (1.0 + (k - 1.0) * w / df)).sqrt())
        .collect();
    let mut series = Vec::new();
    let mut table = vec![closed.clone()];
    for arg in &args[1..] {
        let (dir, label) = arg.split_once('=').expect("DIR=LABEL");
        let (columns, rows) =
            read_history(Path::new(dir).join("history.csv")).expect("a run's history.csv");
        let col = |name: &str| columns.iter().position(|c| c == name).expect(name);
        let (t, fy) = (col("t"), col("flat.fy"));
        let peaks: Vec<f64> = cycles
            .iter()
            .map(|k| {
                rows.iter()
                    .filter(|r| r[t] > k - 1.0 && r[t] <= *k)
                    .map(|r| -r[fy])
                    .fold(0.0, f64::max)
            })
            .collect();
        table.push(peaks.clone());
        series.push(Series {
            label: label.into(),
            x: cycles.clone(),
            y: peaks,
        });
    }
    series.push(Series {
        label: "closed form A√(C_n w/(1 + (k−1) w/D_f))".into(),
        x: cycles.clone(),
        y: closed,
    });
    print!("| cycle | closed form [N] |");
    for arg in &args[1..] {
        print!(" {} [N] |", arg.split_once('=').unwrap().1);
    }
    println!();
    println!("|---:|---:|{}", "---:|".repeat(args.len() - 1));
    for (i, k) in cycles.iter().enumerate() {
        print!("| {k} |");
        for col in &table {
            print!(" {:.5} |", col[i]);
        }
        println!();
    }
    let plot = LinePlot {
        title: "Stiff pad pulled off an adhesive flat, five times".into(),
        x_label: "cycle".into(),
        y_label: "pull-off force [N]".into(),
        series,
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
