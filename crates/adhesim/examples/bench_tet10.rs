//! Assembly cost of the quadratic tetrahedron (tet10) against the hexahedron (hex8), on an
//! n³ cube of the nearly incompressible neo-Hookean solid (E = 1 MPa, ν = 0.4999) deformed by
//! a smooth finite displacement field, on one thread:
//!
//! 1. one element's `element_response` with tangent, hex8 (8 Gauss points) and tet10
//!    (4 points) (µs);
//! 2. `Discretisation::assemble(u, true)` (internal force and tangent into the global
//!    arrays) per element: the n³ hexahedra, standard and F-bar, against the same cube split
//!    into 6 n³ tetrahedra with a node at the middle of every edge, standard and with one
//!    pressure per element (`Formulation::FBar`) (µs), and the whole mesh's assembly.
//!
//! 3. the same assembly per element of the cube's n³ 20-node hexahedra (hex20, 27 Gauss
//!    points), standard and `Formulation::FBar` (on a hex20 the linear volume change,
//!    Q2/P1), against hex8;
//! 4. one hex20 element's response with tangent: the linear volume change (Q2/P1) against
//!    the standard element and against the element-constant one (F-bar, Q2/P0) (µs);
//! 5. the 27-node hexahedron (hex27, 27 Gauss points) against the hex20 and the hex8: one
//!    element's response with tangent (standard), and the assembly per element of the cube's
//!    n³ cells, standard and `Formulation::FBar` (the linear volume change on hex20 and hex27,
//!    the element-constant one on hex8).
//!
//! Each pair (hex8, tet10 or hex20; hex27 against hex8, and against hex20) is timed
//! alternately after one warm-up run of each, so that both see the same machine load;
//! reported are the median of each and the median of the per-pair ratios. Usage:
//! `cargo run --release --example bench_tet10 -- [n] [reps] [hex27]`; with `hex27` only
//! item 5 runs.

use adhesim::assembly::Discretisation;
use adhesim::dilatation::{linear_dilatation_response, LinearDilatation};
use adhesim::element::{
    element_response, hex20_geometry, hex27_geometry, hex8_geometry, tet10_geometry, HEX20, HEX27,
    TET10,
};
use adhesim::fbar::{fbar_element_response, Formulation};
use adhesim::material::{Hyperelastic, UncoupledNeoHookean};
use adhesim::mesh::generate;
use std::f64::consts::PI;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

fn displacement(x: [f64; 3]) -> [f64; 3] {
    let s = (PI * x[0]).sin() * (PI * x[1]).sin() * (PI * x[2]).sin();
    [
        0.05 * x[0] + 0.03 * x[1] + 0.01 * s,
        -0.025 * x[1] + 0.02 * x[2] + 0.005 * s,
        0.01 * x[0] - 0.025 * x[2] - 0.008 * s,
    ]
}

fn time(f: &mut impl FnMut()) -> f64 {
    let t0 = Instant::now();
    f();
    t0.elapsed().as_secs_f64()
}

fn median_of(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Alternating timings of `a` and `b` after one warm-up of each: (median a, median b,
/// median of the per-pair ratios b/a) [s].
fn alternate(reps: usize, mut a: impl FnMut(), mut b: impl FnMut()) -> (f64, f64, f64) {
    a();
    b();
    let (mut ta, mut tb, mut r) = (vec![], vec![], vec![]);
    for _ in 0..reps {
        let x = time(&mut a);
        let y = time(&mut b);
        ta.push(x);
        tb.push(y);
        r.push(y / x);
    }
    (median_of(ta), median_of(tb), median_of(r))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(20);
    let reps: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(7);
    let material: Arc<dyn Hyperelastic> =
        Arc::new(UncoupledNeoHookean::from_young_poisson(1.0e6, 0.4999));
    let mat = &*material;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");

    // 1. One element of each, in the same cube cell.
    let mesh = generate::block([1.0, 1.0, 1.0], [n, n, n]);
    let hex20 = mesh.with_mid_side_nodes();
    if args.get(2).map(String::as_str) == Some("hex27") {
        hex27_cost(&mesh, &hex20, &material, reps, &pool);
        return;
    }
    let tet10 = mesh.split_hexes_into_tets().with_mid_side_nodes();
    let hex = mesh.hexes()[0];
    let xh: [[f64; 3]; 8] = hex.map(|a| mesh.nodes[a]);
    let gh = hex8_geometry(&xh).expect("valid element");
    let uh: [[f64; 3]; 8] = xh.map(displacement);
    let tet = tet10.cells_of::<10>(&TET10)[0];
    let xt: [[f64; 3]; 10] = tet.map(|a| tet10.nodes[a]);
    let gt = tet10_geometry(&xt).expect("valid element");
    let ut: [[f64; 3]; 10] = xt.map(displacement);
    let iters = 20_000;
    let (hex_el, tet_el, el_ratio) = alternate(
        reps,
        || {
            for _ in 0..iters {
                black_box(element_response(black_box(&gh), black_box(&uh), mat, true));
            }
        },
        || {
            for _ in 0..iters {
                black_box(element_response(black_box(&gt), black_box(&ut), mat, true));
            }
        },
    );
    let (hex_el, tet_el) = (hex_el / iters as f64, tet_el / iters as f64);

    // 2. Assembly on one thread.
    let uh: Vec<f64> = mesh.nodes.iter().flat_map(|&p| displacement(p)).collect();
    let ut: Vec<f64> = tet10.nodes.iter().flat_map(|&p| displacement(p)).collect();
    let nh = mesh.hexes().len() as f64;
    let nt = tet10.cells_of::<10>(&TET10).len() as f64;
    println!(
        "{n}³ cube: {} hex8 ({} nodes), {} tet10 ({} nodes), one thread, {reps} alternating pairs",
        nh,
        mesh.num_nodes(),
        nt,
        tet10.num_nodes()
    );
    println!();
    println!("| measurement | hex8 [µs] | tet10 [µs] | median of pair ratios tet10/hex8 |");
    println!("|---|---|---|---|");
    println!(
        "| one element's response with tangent | {:.2} | {:.2} | {:.2} |",
        hex_el * 1e6,
        tet_el * 1e6,
        el_ratio
    );
    for (name, f) in [
        ("standard", Formulation::Standard),
        ("F-bar / one pressure per element", Formulation::FBar),
    ] {
        let dh = Discretisation::with_formulations(&[(&mesh, material.clone())], &[f])
            .expect("valid mesh");
        let dt = Discretisation::with_formulations(&[(&tet10, material.clone())], &[f])
            .expect("valid mesh");
        let (th, tt, ratio) = pool.install(|| {
            alternate(
                reps,
                || drop(black_box(dh.assemble(black_box(&uh), true))),
                || drop(black_box(dt.assemble(black_box(&ut), true))),
            )
        });
        println!(
            "| assembly K + f per element, {name} | {:.2} | {:.2} | {:.2} |",
            th / nh * 1e6,
            tt / nt * 1e6,
            ratio * nh / nt
        );
        println!(
            "| assembly K + f of the whole cube, {name} [ms] | {:.1} | {:.1} | {:.2} |",
            th * 1e3,
            tt * 1e3,
            ratio
        );
        println!(
            "| stored tangent values, {name} | {} | {} | {:.2} |",
            dh.pattern.nnz(),
            dt.pattern.nnz(),
            dt.pattern.nnz() as f64 / dh.pattern.nnz() as f64
        );
    }
    hex20_assembly(&mesh, &hex20, &material, reps, &pool);
    hex20_kernels(&hex20, mat, reps);
    hex27_cost(&mesh, &hex20, &material, reps, &pool);
}

/// Item 5: the hex27 against the hex20 and the hex8, one element's response with tangent and
/// the assembly per element of the cube's n³ cells, each pair timed alternately.
fn hex27_cost(
    mesh: &adhesim::mesh::Mesh,
    hex20: &adhesim::mesh::Mesh,
    material: &Arc<dyn Hyperelastic>,
    reps: usize,
    pool: &rayon::ThreadPool,
) {
    let mat = &**material;
    let hex27 = hex20.with_face_and_centre_nodes();
    let x8: [[f64; 3]; 8] = mesh.hexes()[0].map(|a| mesh.nodes[a]);
    let x20: [[f64; 3]; 20] = hex20.cells_of::<20>(&HEX20)[0].map(|a| hex20.nodes[a]);
    let x27: [[f64; 3]; 27] = hex27.cells_of::<27>(&HEX27)[0].map(|a| hex27.nodes[a]);
    let (g8, g20, g27) = (
        hex8_geometry(&x8).expect("valid element"),
        hex20_geometry(&x20).expect("valid element"),
        hex27_geometry(&x27).expect("valid element"),
    );
    let (u8, u20, u27) = (
        x8.map(displacement),
        x20.map(displacement),
        x27.map(displacement),
    );
    let iters = 2_000;
    let per = |t: f64| t / iters as f64 * 1e6;
    let e8 = || {
        for _ in 0..iters {
            black_box(element_response(black_box(&g8), black_box(&u8), mat, true));
        }
    };
    let e20 = || {
        for _ in 0..iters {
            black_box(element_response(
                black_box(&g20),
                black_box(&u20),
                mat,
                true,
            ));
        }
    };
    let e27 = || {
        for _ in 0..iters {
            black_box(element_response(
                black_box(&g27),
                black_box(&u27),
                mat,
                true,
            ));
        }
    };
    let (t8, t27a, r8) = alternate(reps, e8, e27);
    let (t20, t27b, r20) = alternate(reps, e20, e27);
    let cells = mesh.hexes().len() as f64;
    println!();
    println!(
        "{n}³ cube: {cells} cells; hex8 {} nodes, hex20 {}, hex27 {}; one thread, {reps} \
         alternating pairs",
        mesh.num_nodes(),
        hex20.num_nodes(),
        hex27.num_nodes(),
        n = (cells.cbrt()).round()
    );
    println!();
    println!("| measurement | hex8 [µs] | hex20 [µs] | hex27 [µs] (against hex8 / against hex20) | hex27/hex8 | hex27/hex20 |");
    println!("|---|---|---|---|---|---|");
    println!(
        "| one element's response with tangent, standard | {:.2} | {:.2} | {:.2} / {:.2} | {r8:.2} | {r20:.2} |",
        per(t8),
        per(t20),
        per(t27a),
        per(t27b)
    );
    let u_of = |m: &adhesim::mesh::Mesh| -> Vec<f64> {
        m.nodes.iter().flat_map(|&p| displacement(p)).collect()
    };
    let (uh, uq, ut) = (u_of(mesh), u_of(hex20), u_of(&hex27));
    for (name, f) in [
        ("standard", Formulation::Standard),
        ("F-bar (linear θ on hex20 and hex27)", Formulation::FBar),
    ] {
        let d = |m: &adhesim::mesh::Mesh| {
            Discretisation::with_formulations(&[(m, material.clone())], &[f]).expect("valid mesh")
        };
        let (d8, d20, d27) = (d(mesh), d(hex20), d(&hex27));
        let ((t8, t27a, r8), (t20, t27b, r20)) = pool.install(|| {
            (
                alternate(
                    reps,
                    || drop(black_box(d8.assemble(black_box(&uh), true))),
                    || drop(black_box(d27.assemble(black_box(&ut), true))),
                ),
                alternate(
                    reps,
                    || drop(black_box(d20.assemble(black_box(&uq), true))),
                    || drop(black_box(d27.assemble(black_box(&ut), true))),
                ),
            )
        });
        println!(
            "| assembly K + f per element, {name} | {:.2} | {:.2} | {:.2} / {:.2} | {r8:.2} | {r20:.2} |",
            t8 / cells * 1e6,
            t20 / cells * 1e6,
            t27a / cells * 1e6,
            t27b / cells * 1e6
        );
        println!(
            "| stored tangent values, {name} | {} | {} | {} | {:.2} | {:.2} |",
            d8.pattern.nnz(),
            d20.pattern.nnz(),
            d27.pattern.nnz(),
            d27.pattern.nnz() as f64 / d8.pattern.nnz() as f64,
            d27.pattern.nnz() as f64 / d20.pattern.nnz() as f64
        );
    }
}

/// Item 4: one hex20's response with tangent, the linear volume change against the standard
/// element and the element-constant volume change.
fn hex20_kernels(hex20: &adhesim::mesh::Mesh, mat: &dyn Hyperelastic, reps: usize) {
    let cell = hex20.cells_of::<20>(&HEX20)[0];
    let x: [[f64; 3]; 20] = cell.map(|a| hex20.nodes[a]);
    let gps = hex20_geometry(&x).expect("valid element");
    let lin = LinearDilatation::new(&gps, &x).expect("valid element");
    let u: [[f64; 3]; 20] = x.map(displacement);
    let iters = 2_000;
    let linear = || {
        for _ in 0..iters {
            black_box(linear_dilatation_response(
                black_box(&gps),
                &lin,
                black_box(&u),
                mat,
                true,
                None,
            ));
        }
    };
    println!();
    println!("| one hex20's response with tangent | other [µs] | linear volume change [µs] | median of pair ratios linear/other |");
    println!("|---|---|---|---|");
    let standard = || {
        for _ in 0..iters {
            black_box(element_response(black_box(&gps), black_box(&u), mat, true));
        }
    };
    let constant = || {
        for _ in 0..iters {
            black_box(fbar_element_response(
                black_box(&gps),
                black_box(&u),
                mat,
                true,
            ));
        }
    };
    for (name, (t_other, t_lin, ratio)) in [
        ("standard", alternate(reps, standard, linear)),
        (
            "element-constant (F-bar, Q2/P0)",
            alternate(reps, constant, linear),
        ),
    ] {
        println!(
            "| against {name} | {:.1} | {:.1} | {ratio:.2} |",
            t_other / iters as f64 * 1e6,
            t_lin / iters as f64 * 1e6
        );
    }
}

/// Item 3: assembly per element of the hex20 cube `hex20` against the hex8 cube `mesh`.
fn hex20_assembly(
    mesh: &adhesim::mesh::Mesh,
    hex20: &adhesim::mesh::Mesh,
    material: &Arc<dyn Hyperelastic>,
    reps: usize,
    pool: &rayon::ThreadPool,
) {
    let uh: Vec<f64> = mesh.nodes.iter().flat_map(|&p| displacement(p)).collect();
    let uq: Vec<f64> = hex20.nodes.iter().flat_map(|&p| displacement(p)).collect();
    let cells = mesh.hexes().len() as f64;
    println!();
    println!("| measurement | hex8 [µs] | hex20 [µs] | median of pair ratios hex20/hex8 |");
    println!("|---|---|---|---|");
    for (name, f) in [
        ("standard", Formulation::Standard),
        ("F-bar", Formulation::FBar),
    ] {
        let dh = Discretisation::with_formulations(&[(mesh, material.clone())], &[f])
            .expect("valid mesh");
        let dq = Discretisation::with_formulations(&[(hex20, material.clone())], &[f])
            .expect("valid mesh");
        let (th, tq, ratio) = pool.install(|| {
            alternate(
                reps,
                || drop(black_box(dh.assemble(black_box(&uh), true))),
                || drop(black_box(dq.assemble(black_box(&uq), true))),
            )
        });
        println!(
            "| assembly K + f per element, {name} | {:.2} | {:.2} | {:.2} |",
            th / cells * 1e6,
            tq / cells * 1e6,
            ratio
        );
        println!(
            "| stored tangent values, {name} | {} | {} | {:.2} |",
            dh.pattern.nnz(),
            dq.pattern.nnz(),
            dq.pattern.nnz() as f64 / dh.pattern.nnz() as f64
        );
    }
}
