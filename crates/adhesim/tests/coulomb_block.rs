//! Coulomb block on a rigid plane: a stiff block resting under gravity g_y is pulled
//! sideways by a uniform body force g_x (gravity tilted). With friction μ it sticks while
//! g_x < μ g_y and slides with a = g_x − μ g_y, i.e. a = (F − μN)/m, above.

use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;

fn block_on_plane(gx: f64, mu: f64, theta: f64) -> (Stepper, Vec<usize>) {
    let text = format!(
        r#"
gravity = [{gx}, -10.0, 0.0]
[time]
t_end = 0.1
dt = 1e-3
theta = {theta}
xi = {theta}
[[body]]
name = "block"
mesh = {{ generator = "block", size = [0.01, 0.01, 0.01], divisions = [2, 2, 2] }}
material = {{ model = "neo-hookean", young = 1e7, poisson = 0.3 }}
density = 1000.0
[[contact]]
name = "ground"
slave = {{ body = "block", set = "bottom" }}
master = {{ rigid = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
friction = {mu}
detection_distance = 1e-3
"#
    );
    let problem = adhesim_io::scenario::parse(&text, Path::new("coulomb.toml"))
        .expect("valid scenario")
        .problem;
    let nodes = (0..problem.bodies[0].mesh.num_nodes()).collect();
    (Stepper::new(Arc::new(problem)).unwrap(), nodes)
}

fn mean_x(s: &Stepper, nodes: &[usize]) -> f64 {
    nodes.iter().map(|&n| s.state.u[3 * n]).sum::<f64>() / nodes.len() as f64
}

#[test]
fn block_sticks_below_the_friction_limit() {
    // μ g_y = 5 m/s² > g_x = 3 m/s².
    let (mut s, nodes) = block_on_plane(3.0, 0.5, 1.0);
    while !s.finished() {
        s.step().unwrap();
    }
    // A free block would have moved ½·3·0.1² = 15 mm; a sticking one only deforms
    // elastically (shear strain ~ ρ g_x h / G ~ 1e-5): far below a micrometre.
    let x = mean_x(&s, &nodes);
    assert!(x.abs() < 1e-6, "the block moved {x:e} m");
    // Normal force balances the weight: N = m g_y = 1e-3 kg · 10 m/s².
    let fy: f64 = s.contact[0].iter().map(|c| c.force[1]).sum();
    assert!((fy - 1e-2).abs() < 1e-4, "normal force {fy}");
}

#[test]
fn block_slides_with_the_coulomb_acceleration() {
    for &(gx, mu) in &[(8.0, 0.5), (4.0, 0.2), (6.0, 0.0)] {
        let (mut s, nodes) = block_on_plane(gx, mu, 1.0);
        while !s.finished() {
            s.step().unwrap();
        }
        let a = gx - mu * 10.0;
        let expected = 0.5 * a * 0.1f64.powi(2);
        let x = mean_x(&s, &nodes);
        // θ = 1 shifts the position by O(a·t·Δt): Δt/t = 1 % of the travel.
        assert!(
            (x - expected).abs() < 0.015 * expected,
            "g_x = {gx}, μ = {mu}: x = {x}, expected {expected}"
        );
        // The friction force is μN and opposes the motion.
        let fx: f64 = s.contact[0].iter().map(|c| c.force[0]).sum();
        assert!(
            (fx + mu * 1e-2).abs() < 1e-3 * 1e-2 + 1e-9,
            "friction force {fx}"
        );
    }
}
