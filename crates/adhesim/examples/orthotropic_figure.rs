//! Direction and size of the friction force against the drag direction, from runs of
//! scenarios/interface/orthotropic-drag.toml.
//!
//! Usage: `cargo run --release --example orthotropic_figure -- OUT.png DIR=ANGLE...`, each DIR a
//! run directory (with history.csv) and ANGLE its `drag_angle` [degrees]. Reads the `flat`
//! pair's resultant at the end of the drag, draws the direction of −F_t (degrees from x)
//! against the drag angle beside the closed form of maximal dissipation on the elliptic cone
//! (μ₁ = 0.6 along x, μ₂ = 0.2 along z) and the isotropic answer (along the drag), and prints
//! a table with |F_t|/N.

use adhesim_io::output::csv::read_history;
use adhesim_io::output::plot::{draw_line_plot, LinePlot, Series};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: orthotropic_figure OUT.png DIR=ANGLE...");
        std::process::exit(2);
    }
    let (mu1, mu2) = (0.6f64, 0.2f64);
    let closed = |deg: f64| {
        let th = deg.to_radians();
        let m = (mu1 * th.cos()).hypot(mu2 * th.sin());
        (mu1 * mu1 * th.cos() / m, mu2 * mu2 * th.sin() / m)
    };
    let mut computed = Vec::new();
    println!(
        "| drag angle [°] | −F_t direction [°] | closed form [°] | \\|F_t\\|/N | closed form |"
    );
    println!("|---:|---:|---:|---:|---:|");
    for arg in &args[1..] {
        let (dir, angle) = arg.split_once('=').expect("DIR=ANGLE");
        let angle: f64 = angle.parse().expect("an angle in degrees");
        let (columns, rows) =
            read_history(Path::new(dir).join("history.csv")).expect("a run's history.csv");
        let col = |name: &str| columns.iter().position(|c| c == name).expect(name);
        let last = rows.last().expect("a finished run");
        let (n, fx, fz) = (
            last[col("flat.fn")],
            last[col("flat.ft_x")],
            last[col("flat.ft_z")],
        );
        let direction = (-fz).atan2(-fx).to_degrees();
        let (cx, cz) = closed(angle);
        println!(
            "| {angle} | {direction:.4} | {:.4} | {:.6} | {:.6} |",
            cz.atan2(cx).to_degrees(),
            fx.hypot(fz) / n,
            cx.hypot(cz)
        );
        computed.push((angle, direction));
    }
    computed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let fine: Vec<f64> = (0..=90).map(f64::from).collect();
    let plot = LinePlot {
        title: "Pad dragged on an orthotropic flat (μ = 0.6 along x, 0.2 along z)".into(),
        x_label: "drag direction θ [degrees from x]".into(),
        y_label: "direction of the friction force −F_t [degrees from x]".into(),
        series: vec![
            Series {
                label: "computed".into(),
                x: computed.iter().map(|p| p.0).collect(),
                y: computed.iter().map(|p| p.1).collect(),
            },
            Series {
                label: "maximal dissipation on the elliptic cone".into(),
                x: fine.clone(),
                y: fine
                    .iter()
                    .map(|&d| {
                        let (cx, cz) = closed(d);
                        cz.atan2(cx).to_degrees()
                    })
                    .collect(),
            },
            Series {
                label: "isotropic friction (along the drag)".into(),
                x: fine.clone(),
                y: fine,
            },
        ],
    };
    draw_line_plot(Path::new(&args[0]), &plot).expect("figure written");
}
