//! Hertz contact (exploration draft).

use adhesim::contact::detect::tributary_areas;
use adhesim::time::Stepper;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

const R: f64 = 0.01;
fn d_ind() -> f64 {
    std::env::var("HZD")
        .map(|v| v.parse().unwrap())
        .unwrap_or(2.5e-5)
}
const G: f64 = 1.0e6;

fn grading(h: f64, fine: f64, q: f64, total: f64) -> Vec<f64> {
    let mut x = vec![0.0];
    while *x.last().unwrap() < fine - 1e-9 * h {
        let l = *x.last().unwrap();
        x.push(l + h);
    }
    let x_f = *x.last().unwrap();
    let mut sizes = Vec::new();
    let mut s = h;
    let mut sum = 0.0;
    while sum < total - x_f {
        s *= q;
        sizes.push(s);
        sum += s;
    }
    let scale = (total - x_f) / sum;
    let mut c = x_f;
    for s in sizes {
        c += s * scale;
        x.push(c);
    }
    *x.last_mut().unwrap() = total;
    x
}

struct Outcome {
    force: f64,
    radius: f64,
    h: f64,
    dofs: usize,
    candidates: usize,
    secs: f64,
}

fn run(m: usize, q: f64, extent: f64, steps: usize, det: f64) -> Outcome {
    let a = (R * d_ind()).sqrt();
    let h = a / m as f64;
    let dom = extent * a;
    let g = grading(h, 1.25 * a, q, dom);
    let n = g.len() - 1;
    let text = format!(
        r#"
[time]
t_end = 1.0
dt = {dt}
mode = "quasi-static"
[[body]]
name = "block"
mesh = {{ generator = "block", size = [{dom}, {dom}, {dom}], divisions = [{n}, {n}, {n}] }}
material = {mat}
density = 1000.0
[[boundary]]
body = "block"
set = "left"
fix = ["x"]
[[boundary]]
body = "block"
set = "back"
fix = ["z"]
[[boundary]]
body = "block"
set = "bottom"
fix = ["y"]
[[contact]]
name = "indenter"
slave = {{ body = "block", set = "top" }}
master = {{ rigid = "sphere", center = [0.0, {cy}, 0.0], radius = {R} }}
motion = {{ displacement = {{ y = [[0.0, 0.0], [1.0, {md}]] }} }}
friction = 0.0
detection_distance = {det}
"#,
        dt = 1.0 / steps as f64,
        cy = dom + R,
        md = -d_ind(),
        det = det * d_ind(),
        mat = std::env::var("HZM").unwrap_or(format!("{{ model = \"blatz-ko\", g = {G} }}")),
    );
    let mut problem =
        adhesim::scenario::parse(&text, Path::new("hertz.toml")).expect("valid scenario");
    {
        let mesh = &mut problem.bodies[0].mesh;
        for p in mesh.nodes.iter_mut() {
            let idx = |v: f64| (v / dom * n as f64).round() as usize;
            p[0] = g[idx(p[0])];
            p[2] = g[idx(p[2])];
            p[1] = dom - g[n - idx(p[1])];
        }
    }
    let mesh = problem.bodies[0].mesh.clone();
    let area = tributary_areas(&mesh.face_sets["top"], &mesh.nodes, &mesh.node_sets["top"]);
    problem.contacts[0].slave_area = area;
    let dofs = 3 * mesh.num_nodes();
    let t0 = Instant::now();
    let mut s = Stepper::new(Arc::new(problem)).unwrap();
    let mut candidates = 0;
    while !s.finished() {
        let rep = s.step().unwrap();
        eprintln!(
            "  step {} t {:.3} newton {} cutbacks {} sweeps {} points {} res {:.1e}",
            rep.step,
            rep.t,
            rep.newton_iterations,
            rep.cutbacks,
            rep.contact_sweeps,
            rep.contact_points,
            rep.residual
        );
        candidates = rep.contact_points;
    }
    let slave = &s.problem.contacts[0].slave_nodes;
    let mut fy = 0.0;
    let mut radius: f64 = 0.0;
    for (i, c) in s.contact[0].iter().enumerate() {
        fy += c.force[1];
        if c.r_dry[2] > 0.0 {
            let x = s.disc.reference[slave[i]];
            radius = radius.max(x[0].hypot(x[2]));
        }
    }
    Outcome {
        force: -4.0 * fy,
        radius,
        h,
        dofs,
        candidates,
        secs: t0.elapsed().as_secs_f64(),
    }
}

#[test]
fn explore() {
    let a = (R * d_ind()).sqrt();
    let e = 2.5 * G;
    let es = e / (1.0 - 0.0625);
    let f_h = 4.0 / 3.0 * es * R.sqrt() * d_ind().powf(1.5);
    let args: Vec<f64> = std::env::var("HZ")
        .unwrap_or("3,1.4,40,4,0.5".into())
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let o = run(
        args[0] as usize,
        args[1],
        args[2],
        args[3] as usize,
        args[4],
    );
    eprintln!(
        "m {} q {} ext {}: dofs {} cand {} F {:.5e} (Hertz {:.5e}, err {:+.2}%) a_fe {:.3e} (a {:.3e}, h {:.2e}) {:.1}s",
        args[0], args[1], args[2], o.dofs, o.candidates, o.force, f_h, 100.0 * (o.force / f_h - 1.0), o.radius, a, o.h, o.secs
    );
}
