//! Cost of the F-bar hex8 against the standard fully integrated hex8, on an n³ cube of the
//! nearly incompressible neo-Hookean solid (E = 1 MPa, ν = 0.4999) deformed by a smooth
//! finite displacement field:
//!
//! 1. one element's `element_response` / `fbar_element_response` with tangent (µs);
//! 2. `Discretisation::assemble(u, true)` on one thread, per element (µs);
//! 3. the same for the cube split into tetrahedra, linear tet4 against the
//!    averaged-nodal-pressure tetrahedron, and the sizes of their sparsity patterns.
//!
//! The two formulations are timed alternately (standard, F-bar, standard, F-bar, ...) after
//! one warm-up run of each, so that both see the same machine load; reported are the median
//! of each, the ratio of the medians and the median of the per-pair ratios.
//! Usage: `cargo run --release --example bench_fbar -- [n] [reps]`.

use adhesim::assembly::Discretisation;
use adhesim::element::{element_response, hex8_geometry};
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
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(30);
    let reps: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(7);
    let material: Arc<dyn Hyperelastic> =
        Arc::new(UncoupledNeoHookean::from_young_poisson(1.0e6, 0.4999));

    // 1. One element.
    let h = 0.05;
    let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
        let xi = adhesim::element::HEX_NODE_XI[a];
        std::array::from_fn(|k| 0.4 + 0.5 * h * (xi[k] + 1.0))
    });
    let gps = hex8_geometry(&x).expect("valid element");
    let ue: [[f64; 3]; 8] = std::array::from_fn(|a| displacement(x[a]));
    let iters = 20_000;
    let mat = &*material;
    let (standard_el, fbar_el, el_ratio) = alternate(
        reps,
        || {
            for _ in 0..iters {
                black_box(element_response(black_box(&gps), black_box(&ue), mat, true));
            }
        },
        || {
            for _ in 0..iters {
                black_box(fbar_element_response(
                    black_box(&gps),
                    black_box(&ue),
                    mat,
                    true,
                ));
            }
        },
    );
    let (standard_el, fbar_el) = (standard_el / iters as f64, fbar_el / iters as f64);

    // 2. Assembly of an n³ cube on one thread.
    let mesh = generate::block([1.0, 1.0, 1.0], [n, n, n]);
    let u: Vec<f64> = mesh.nodes.iter().flat_map(|&p| displacement(p)).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let disc = |f: Formulation| {
        Discretisation::with_formulations(&[(&mesh, material.clone())], &[f]).expect("valid mesh")
    };
    let (standard, fbar) = (disc(Formulation::Standard), disc(Formulation::FBar));
    let ne = mesh.hexes().len() as f64;
    let (standard_asm, fbar_asm, asm_ratio) = pool.install(|| {
        alternate(
            reps,
            || drop(black_box(standard.assemble(black_box(&u), true))),
            || drop(black_box(fbar.assemble(black_box(&u), true))),
        )
    });
    let (standard_asm, fbar_asm) = (standard_asm / ne, fbar_asm / ne);

    println!("| measurement | standard hex8 [µs] | F-bar hex8 [µs] | ratio of medians | median of pair ratios |");
    println!("|---|---|---|---|---|");
    println!(
        "| element response with tangent | {:.2} | {:.2} | {:.2} | {:.2} |",
        standard_el * 1e6,
        fbar_el * 1e6,
        fbar_el / standard_el,
        el_ratio
    );
    println!(
        "| assembly K + f per element, {n}³ cube, 1 thread | {:.2} | {:.2} | {:.2} | {:.2} |",
        standard_asm * 1e6,
        fbar_asm * 1e6,
        fbar_asm / standard_asm,
        asm_ratio
    );

    // 3. The same cube split into tetrahedra: linear tet4 against the averaged-nodal-pressure
    // tetrahedron (whose patches widen the pattern), per tetrahedron.
    let tets = mesh.split_hexes_into_tets();
    let u: Vec<f64> = tets.nodes.iter().flat_map(|&p| displacement(p)).collect();
    let tdisc = |f: Formulation| {
        Discretisation::with_formulations(&[(&tets, material.clone())], &[f]).expect("valid mesh")
    };
    let (linear, anp) = (
        tdisc(Formulation::Standard),
        tdisc(Formulation::AveragedNodalPressure),
    );
    let nt = tets.tets().len() as f64;
    let (linear_asm, anp_asm, tet_ratio) = pool.install(|| {
        alternate(
            reps,
            || drop(black_box(linear.assemble(black_box(&u), true))),
            || drop(black_box(anp.assemble(black_box(&u), true))),
        )
    });
    println!();
    println!("| measurement | linear tet4 [µs] | averaged nodal pressure tet4 [µs] | ratio of medians | median of pair ratios |");
    println!("|---|---|---|---|---|");
    println!(
        "| assembly K + f per tetrahedron, {n}³ cube × 6, 1 thread | {:.2} | {:.2} | {:.2} | {:.2} |",
        linear_asm / nt * 1e6,
        anp_asm / nt * 1e6,
        anp_asm / linear_asm,
        tet_ratio
    );
    println!(
        "| stored tangent values | {} | {} | {:.2} | |",
        linear.pattern.nnz(),
        anp.pattern.nnz(),
        anp.pattern.nnz() as f64 / linear.pattern.nnz() as f64
    );
}
