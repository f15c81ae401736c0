//! Interface fatigue through the whole solver, on the shipped scenario
//! scenarios/interface/fatigue-pull-off.toml: a stiff pad pressed on an adhesive flat and
//! pulled off five times.
//!
//! Independent answers (docs/model.md §5.4): each complete debonding dissipates the current
//! decohesion energy, so after k cycles the dissipated energy is D_k = D_f ln(1 + k w/D_f) at
//! every node, and the pull-off force of cycle k + 1 is A √(C_n w/(1 + k w/D_f)). Without
//! fatigue every cycle is the same.

use adhesim::contact::RccHistory;
use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;

const W: f64 = 20.0;
const CN: f64 = 2e9;
const DF: f64 = 40.0;
const AREA: f64 = 1e-6;

/// Per cycle: (peak tensile force [N], dissipated energy at the centre at the cycle's end
/// [J/m²], largest opening increment of a step near the peak [m]).
fn run(fatigue: bool) -> Vec<(f64, f64, f64)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenarios/interface/fatigue-pull-off.toml");
    let mut text = std::fs::read_to_string(&path).unwrap();
    if !fatigue {
        let key = ", fatigue_energy = \"= fatigue_energy\"";
        assert!(text.contains(key));
        text = text.replace(key, "");
    }
    let problem = adhesim_io::scenario::parse(&text, &path)
        .unwrap_or_else(|e| panic!("{e}"))
        .problem;
    let centre = problem.contacts[0]
        .slave_nodes
        .iter()
        .position(|&n| {
            let p = problem.bodies[0].mesh.nodes[n];
            (p[0] - 5e-4).abs() < 1e-12 && (p[2] - 5e-4).abs() < 1e-12
        })
        .expect("a node at the centre of the pad's bottom face");
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    let mut cycles = vec![(0.0f64, 0.0, 0.0f64); 5];
    let mut last_gap = f64::NAN;
    while !s.finished() {
        s.step().unwrap();
        let k = ((s.state.t - 1e-9).floor() as usize).min(4);
        let fy: f64 = s.contact[0].iter().map(|c| c.force[1]).sum();
        let c = &s.contact[0][centre];
        let tension = -fy;
        if tension > cycles[k].0 {
            cycles[k].0 = tension;
            cycles[k].2 = (c.gap - last_gap).abs();
        }
        cycles[k].1 = RccHistory::from(&c.history).damage;
        last_gap = c.gap;
    }
    cycles
}

#[test]
fn pull_off_force_falls_as_the_fatigue_law_says() {
    let cycles = run(true);
    for (k, &(peak, damage, step)) in cycles.iter().enumerate() {
        let kf = k as f64;
        // Every debonding is complete (β → 0 by the detection distance), and the update is
        // exact for any split of the decrease of β: round-off only.
        let d_closed = DF * (1.0 + (kf + 1.0) * W / DF).ln();
        assert!(
            (damage - d_closed).abs() < 1e-9 * d_closed,
            "cycle {}: dissipated {damage} J/m², closed form {d_closed}",
            k + 1
        );
        // The force rises linearly to a kink at x_c and falls as x⁻³ beyond it, so the largest
        // force at the steps' openings is below the true peak by at most ¾ of one opening
        // increment relative to x_c (the two steps bracketing x_c); the pad, 1000 times
        // stiffer than the interface, adds about 1e-3.
        let w_k = W / (1.0 + kf * W / DF);
        let expect = AREA * (CN * w_k).sqrt();
        let xc = (w_k / CN).sqrt();
        let tol = step / xc + 2e-3;
        eprintln!(
            "cycle {}: pull-off {peak:.6} N, closed form {expect:.6} N ({:+.2e}, tolerance {tol:.1e}); D = {damage:.6} J/m²",
            k + 1,
            peak / expect - 1.0
        );
        assert!(
            (peak / expect - 1.0).abs() < tol,
            "cycle {}: {peak} vs {expect}",
            k + 1
        );
    }
    // And it does fall: each cycle needs less force than the one before.
    for pair in cycles.windows(2) {
        assert!(pair[1].0 < pair[0].0);
    }
}

#[test]
fn without_fatigue_every_cycle_is_the_same() {
    let cycles = run(false);
    let first = cycles[0].0;
    for (k, &(peak, damage, _)) in cycles.iter().enumerate() {
        // The same displacement history each cycle, a bond that is fully re-formed at each
        // press (b = 0): the same forces to round-off.
        assert!(
            (peak - first).abs() < 1e-9 * first,
            "cycle {}: {peak} vs {first}",
            k + 1
        );
        // The dissipated energy still counts w per complete debonding.
        let d = W * (k as f64 + 1.0);
        assert!(
            (damage - d).abs() < 1e-9 * d,
            "cycle {}: D = {damage}",
            k + 1
        );
    }
}
