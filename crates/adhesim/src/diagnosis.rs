//! What a failed step most likely means, said in terms of the scenario.
//!
//! A step fails when Newton's method does not converge even at the smallest Δt. In a
//! quasi-static run a tangent matrix that is not positive definite has two usual causes,
//! told apart here from the problem itself: a body that nothing holds (no prescribed
//! displacement, no contact pair), or, with every body held, a load increment too large for
//! the Newton iterations, typically gravity or a load applied in full from t = 0, whose
//! first increment no Δt cut-back can make smaller.

use crate::problem::Problem;
use crate::time::StepError;

/// The message of a failed step, with the likely cause and a remedy where one can be
/// named.
pub fn describe_step_failure(problem: &Problem, err: &StepError) -> String {
    match step_failure_hint(problem, &err.reason) {
        Some(hint) => format!("{err}\n{hint}"),
        None => err.to_string(),
    }
}

/// The likely cause of a step failure whose last reason was `reason`, when one can be
/// named: only for a quasi-static run whose matrix was not positive definite.
pub fn step_failure_hint(problem: &Problem, reason: &str) -> Option<String> {
    if !problem.time.quasi_static || !reason.contains("not positive definite") {
        return None;
    }
    let free = unheld_bodies(problem);
    if !free.is_empty() {
        return Some(format!(
            "Likely cause: in a quasi-static run every body must be held against rigid motion, \
             and {} ha{} no prescribed displacement ([[boundary]]) and no contact pair.",
            free.iter()
                .map(|b| format!("body {b:?}"))
                .collect::<Vec<_>>()
                .join(", "),
            if free.len() == 1 { "s" } else { "ve" }
        ));
    }
    let sudden = applied_at_once(problem);
    let many = sudden.len() > 1;
    let mut hint = String::from(
        "Likely cause: every body is held, so the load increment is too large for the Newton \
         iterations (the tangent stiffness of the iterate lost positive definiteness).",
    );
    if sudden.is_empty() {
        hint.push_str(" Take a smaller time.dt or ramp the loads more slowly.");
    } else {
        let mut sudden = sudden.join(" and ");
        sudden[..1].make_ascii_uppercase();
        hint.push_str(&format!(
            " {sudden} act{} in full from t = 0, so cutting Δt back cannot make the first \
             increment smaller: ramp {} from zero with a table over time, e.g. {} \
             (docs/scenario.md).",
            if many { "" } else { "s" },
            if many { "them" } else { "it" },
            ramp_example(problem),
        ));
    }
    Some(hint)
}

/// A table that ramps the run's gravity (or, without gravity, a load) from zero to its value
/// over the first half of the run, in scenario syntax.
fn ramp_example(problem: &Problem) -> String {
    let t1 = 0.5 * problem.time.t_end;
    let ramp = |values: [f64; 3]| {
        let parts: Vec<String> = ["x", "y", "z"]
            .iter()
            .zip(values)
            .filter(|(_, v)| *v != 0.0)
            .map(|(c, v)| format!("{c} = [[0.0, 0.0], [{t1:?}, {v:?}]]"))
            .collect();
        format!("{{ {} }}", parts.join(", "))
    };
    let g = problem.gravity.at(0.0);
    if g.iter().any(|&v| v != 0.0) {
        return format!("gravity = {}", ramp(g));
    }
    match problem
        .loads
        .iter()
        .map(|l| std::array::from_fn(|k| l.total_force[k].at(0.0)))
        .find(|f: &[f64; 3]| f.iter().any(|&v| v != 0.0))
    {
        Some(f) => format!("force = {}", ramp(f)),
        None => "force = { y = [[0.0, 0.0], [1.0, -1.0]] }".into(),
    }
}

/// Names of the bodies with no prescribed displacement on any node and in no contact pair
/// (as slave or as master).
pub fn unheld_bodies(problem: &Problem) -> Vec<String> {
    let offsets = problem.node_offsets();
    let body_of = |node: usize| offsets.partition_point(|&o| o <= node).saturating_sub(1);
    let mut held = vec![false; problem.bodies.len()];
    let mut mark = |node: usize| {
        if let Some(h) = held.get_mut(body_of(node)) {
            *h = true;
        }
    };
    for d in &problem.dirichlet {
        if d.components.iter().any(|&c| c) || d.rotation.is_some() {
            d.nodes.iter().for_each(|&n| mark(n));
        }
    }
    for c in &problem.contacts {
        c.slave_nodes.iter().for_each(|&n| mark(n));
        if let crate::contact::Master::Faces(faces) = &c.master {
            faces
                .iter()
                .flat_map(|f| f.nodes().iter())
                .for_each(|&n| mark(n));
        }
    }
    problem
        .bodies
        .iter()
        .zip(&held)
        .filter(|(_, &h)| !h)
        .map(|(b, _)| b.name.clone())
        .collect()
}

/// Gravity and loads that are not zero at t = 0 (applied at once), described for a message.
pub fn applied_at_once(problem: &Problem) -> Vec<String> {
    let mut out = Vec::new();
    let g = problem.gravity.at(0.0);
    let g_norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if g_norm > 0.0 {
        out.push(format!("gravity ({g_norm} m/s²)"));
    }
    for (i, load) in problem.loads.iter().enumerate() {
        let f: Vec<f64> = load.total_force.iter().map(|t| t.at(0.0)).collect();
        let f_norm = f.iter().map(|v| v * v).sum::<f64>().sqrt();
        if f_norm > 0.0 {
            out.push(format!("load[{i}] ({f_norm} N)"));
        }
    }
    out
}
