//! `time.predictor = "secant"` against the default start of quasi-static steps (the last
//! converged state): the same answer to the Newton tolerance, in fewer iterations where the
//! load moves steadily (the pad of the FEBio comparison, bench/febio/pad.toml, at 100 contact
//! nodes: 27 → 21 iterations without friction, 15 → 11 with μ = 0.3), and a step that does not converge from the secant
//! start solved again from the last state instead of being cut back (the sagging
//! cantilever, whose step after the end of its gravity ramp starts from an overshoot).
//!
//! The force tolerance is that of tests/modified_newton.rs: on this pad Newton's own answer at
//! its default tolerance (1e-8) sits up to 4.8e-7 of the force from the answer both starts
//! converge to, so 1e-5 holds that spread and fails on a step stopped short of the tolerance
//! (a residual of 1e-6 moves the force by some 5e-5) or on another solution.

mod common;

use adhesim::problem::Problem;
use adhesim::time::{StepReport, Stepper};
use common::scenario;
use std::sync::Arc;

/// Runs `problem` to its end: each step's report and the value `probe` reads after it.
fn run(problem: Problem, probe: impl Fn(&Stepper) -> f64) -> Vec<(StepReport, f64)> {
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    let mut steps = Vec::new();
    while !s.finished() {
        let rep = s.step().unwrap_or_else(|e| panic!("{e}"));
        steps.push((rep, probe(&s)));
    }
    steps
}

fn newton_iterations(steps: &[(StepReport, f64)]) -> usize {
    steps.iter().map(|(r, _)| r.newton_iterations).sum()
}

/// The normal contact force of the first pair [N].
fn normal_force(s: &Stepper) -> f64 {
    s.contact[0].iter().map(|c| c.force[1]).sum()
}

#[test]
fn the_secant_start_keeps_the_pads_force_in_fewer_iterations() {
    for mu in ["mu=0", "mu=0.3"] {
        let with = |start: &str| {
            let key = format!("time.predictor={start}");
            run(scenario("bench/febio/pad.toml", &[mu, &key]), normal_force)
        };
        let (last, secant) = (with("last"), with("secant"));
        assert_eq!(last.len(), secant.len(), "{mu}: steps differ");
        for (k, ((_, a), (_, b))) in last.iter().zip(&secant).enumerate() {
            assert!(
                (a - b).abs() <= 1e-5 * a.abs(),
                "{mu}, step {}: f_y {a} N (last state) against {b} N (secant)",
                k + 1
            );
        }
        let (n_last, n_secant) = (newton_iterations(&last), newton_iterations(&secant));
        assert!(
            n_secant < n_last,
            "{mu}: {n_secant} Newton iterations from the secant start, {n_last} from the last state"
        );
    }
}

#[test]
fn a_step_that_fails_from_the_secant_start_is_solved_from_the_last_state() {
    // With `max_newton = 5` (4 corrections), every step of the ramp converges from either start,
    // and the first step after the ramp does not from the secant start (it needs 5 there):
    // it is solved again from the last state, which balances the held load already.
    // The deflection: the largest vertical displacement of any node (the free end's).
    let tip = |s: &Stepper| {
        s.state
            .u
            .iter()
            .skip(1)
            .step_by(3)
            .fold(0.0f64, |m, &v| m.max(v.abs()))
    };
    let with = |start: &str| {
        let key = format!("time.predictor={start}");
        run(
            scenario(
                "scenarios/cantilever-sag.toml",
                &[&key, "time.max_newton=5"],
            ),
            tip,
        )
    };
    let (last, secant) = (with("last"), with("secant"));
    assert_eq!(last.len(), secant.len(), "steps differ");
    for (k, ((a, ua), (b, ub))) in last.iter().zip(&secant).enumerate() {
        assert_eq!((a.cutbacks, b.cutbacks), (0, 0), "step {}", k + 1);
        assert!(
            (ua - ub).abs() <= 1e-6 * ua.abs().max(1e-3),
            "step {}: tip u_y {ua} m (last state) against {ub} m (secant)",
            k + 1
        );
    }
    let after_ramp = |steps: &[(StepReport, f64)]| {
        let k = steps
            .iter()
            .position(|(r, _)| r.newton_iterations == 0)
            .expect("a step that the held load leaves in balance");
        steps[k].0.t
    };
    assert_eq!(after_ramp(&last), after_ramp(&secant));
}
