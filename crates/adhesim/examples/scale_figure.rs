//! CPU time of the scale benchmark (bench/scale/) against the number of contact nodes, one
//! curve per adhesim contact solver and one for CalculiX, on logarithmic axes.
//!
//! Usage: `cargo run --release --example scale_figure -- RESULTS.jsonl OUT.png`, RESULTS the
//! data file of `bench/scale/run.sh`. Each point is the median CPU time (user + system) of
//! the runs of one program, solver and size; contact nodes are (n + 1)². Prints a table.

use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::collections::BTreeMap;
use std::path::Path;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = v.len();
    if k % 2 == 1 {
        v[k / 2]
    } else {
        0.5 * (v[k / 2 - 1] + v[k / 2])
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 2 {
        eprintln!("usage: scale_figure RESULTS.jsonl OUT.png");
        std::process::exit(2);
    }
    let text = std::fs::read_to_string(&args[0]).expect("the results file");
    // (curve, contact nodes) → CPU times of the runs.
    let mut runs: BTreeMap<(String, u64), Vec<f64>> = BTreeMap::new();
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let r: serde_json::Value = serde_json::from_str(line).expect("one JSON record per line");
        if r["exit"].as_i64() != Some(0) {
            continue;
        }
        let n = r["n"].as_u64().expect("n");
        let curve = match r["tool"].as_str() {
            Some("ccx") => "CalculiX 2.20".to_string(),
            _ => format!("adhesim, {}", r["solver"].as_str().unwrap_or("default")),
        };
        let cpu = r["cpu"].as_f64().expect("cpu");
        runs.entry((curve, (n + 1) * (n + 1)))
            .or_default()
            .push(cpu);
    }
    let mut curves: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    println!("| curve | contact nodes | runs | CPU (median) [s] |");
    println!("|---|---:|---:|---:|");
    for ((curve, nodes), cpu) in runs {
        let (count, t) = (cpu.len(), median(cpu));
        println!("| {curve} | {nodes} | {count} | {t:.2} |");
        curves.entry(curve).or_default().push((nodes as f64, t));
    }
    let series = curves
        .into_iter()
        .map(|(label, pts)| Series {
            label,
            x: pts.iter().map(|p| p.0.log10()).collect(),
            y: pts.iter().map(|p| p.1.log10()).collect(),
        })
        .collect();
    let plot = LinePlot {
        title: "Pad pressed on a rigid plane (μ = 0.3), 5 increments, one thread".into(),
        x_label: "log10 of the contact nodes".into(),
        y_label: "log10 of the CPU time [s]".into(),
        series,
    };
    draw_line_plot(Path::new(&args[1]), &plot).expect("figure written");
}
