//! Reads the two small fclib problems shipped in tests/data and solves them with adhesim's
//! contact solvers. Reference values were read independently with h5py/numpy from the same
//! files (numpy condensed W = Hᵀ M⁻¹ H with a dense solve).

use adhesim::contact::solver::gauss_seidel::reduced::gauss_seidel_blocks;
use adhesim::contact::solver::natural_map::{natural_map_residual, relative_error};
use adhesim::contact::solver::semismooth::reduced::semismooth_newton;
use adhesim_fclib::{read, ReducedProblem, Storage};

fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Relative agreement to `tol`.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(f64::MIN_POSITIVE)
}

/// The condensation block by block of M equals W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w computed
/// with the whole of M dense (an LU factorisation, not the blocks' Cholesky), entry by entry to
/// 1e-10 of the largest |W_ij| (resp. |q_i|): the two differ by rounding only, and M's
/// condition number (up to 1e8 on these files) bounds that rounding near 1e-16 · 1e8.
#[test]
fn condensation_by_blocks_equals_the_dense_one() {
    for name in SMALL_GLOBAL {
        let file = read(data(name)).expect("readable");
        let p = file.global().expect("a global problem");
        let mut m = p.m.to_dense();
        // A file may store one triangle of M: complete it.
        for i in 0..m.nrows() {
            for j in 0..i {
                if m[(i, j)] == 0.0 {
                    m[(i, j)] = m[(j, i)];
                } else if m[(j, i)] == 0.0 {
                    m[(j, i)] = m[(i, j)];
                }
            }
        }
        let h = p.h.to_dense();
        let lu = m.lu();
        let w_ref = h.transpose() * lu.solve(&h).expect("M invertible");
        let f = nalgebra::DVector::from_column_slice(&p.f);
        let q_ref = h.transpose() * lu.solve(&f).expect("M invertible")
            + nalgebra::DVector::from_column_slice(&p.w);
        let red = ReducedProblem::condense(p).expect("condensable");
        let w = red.dense_w();
        let m3 = 3 * p.mu.len();
        let perm = adhesim_fclib::index_to_adhesim;
        let w_scale = w_ref.amax();
        let q_scale = q_ref.amax();
        for i in 0..m3 {
            for j in 0..m3 {
                let got = w[perm(i) * m3 + perm(j)];
                assert!(
                    (got - w_ref[(i, j)]).abs() <= 1e-10 * w_scale,
                    "{name}: W[{i}][{j}] = {got} against {}",
                    w_ref[(i, j)]
                );
            }
            let got = red.q[i / 3][adhesim_fclib::to_adhesim(i % 3)];
            assert!(
                (got - q_ref[i]).abs() <= 1e-10 * q_scale,
                "{name}: q[{i}] = {got} against {}",
                q_ref[i]
            );
        }
    }
}

#[test]
fn reads_lmgc_global_problem() {
    let file = read(data("LMGC_GFC3D-i00501-4-00000.hdf5")).expect("readable");
    let p = file.global().expect("a global problem");
    // Sizes and storage as h5py lists them: M 162×162 with 6174 triplets, H 162×12 with 288.
    assert_eq!((p.m.rows, p.m.cols, p.m.nnz()), (162, 162, 6174));
    assert_eq!(p.m.storage, Storage::Triplets);
    assert_eq!((p.h.rows, p.h.cols, p.h.nnz()), (162, 12, 288));
    assert_eq!(p.mu, vec![0.3; 4]);
    assert_eq!((p.f.len(), p.w.len()), (162, 12));
    // First triplet of M: (0, 0, 498024382.71604985).
    assert_eq!(p.m.entries[0], (0, 0, 498024382.71604985));
    assert_eq!(file.title.as_deref(), Some("LMGC dump in hdf5"));
    assert!(file.solution.is_none() && file.guesses.is_empty());
    // Condensed W in fclib order (N, T1, T2): W[0,0] = 0.005278594957878928,
    // W[0,1] = 0.000441442130880571, W[3,5] = -0.00012723061517053017 (contact 1, N and T2),
    // q[0] = -3.1652235372599938e-12 (numpy); the Cholesky and numpy's LU agree to ~1e-12.
    let red = ReducedProblem::of_file(&file).expect("M positive definite");
    let w0 = red.w.diagonal_block(0);
    // adhesim order (t1, t2, n): fclib (N, N) is (2, 2), (N, T1) is (2, 0).
    assert!(close(w0[2][2], 0.005278594957878928, 1e-10));
    assert!(close(w0[2][0], 0.000441442130880571, 1e-10));
    let w1 = red.w.diagonal_block(1);
    assert!(close(w1[2][1], -0.00012723061517053017, 1e-10));
    assert!(close(red.q[0][2], -3.1652235372599938e-12, 1e-8));
}

#[test]
fn reads_box_stacks_with_guesses() {
    let file = read(data("Box_Stacks-i0122-82-5.hdf5")).expect("readable");
    let p = file.global().expect("a global problem");
    assert_eq!((p.m.rows, p.m.nnz()), (450, 450));
    assert!(p.m.is_diagonal());
    assert_eq!((p.h.rows, p.h.cols, p.h.nnz()), (450, 246, 1284));
    assert_eq!(p.mu.len(), 82);
    assert_eq!(p.h.entries[0], (0, 0, -2.2709108060188126e-14));
    let sol = file.solution.as_ref().expect("a stored solution");
    assert_eq!(sol.v.as_ref().map(Vec::len), Some(450));
    let norm_u = sol.u.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(close(norm_u, 0.0021101214190482076, 1e-14));
    assert_eq!(file.guesses.len(), 1);
    assert_eq!(file.guesses[0].r.len(), 246);
}

#[test]
fn missing_file_names_the_file() {
    let err = read(data("no-such-problem.hdf5")).unwrap_err().to_string();
    assert!(err.contains("no-such-problem.hdf5"), "{err}");
}

/// The two small global problems of the shared data.
const SMALL_GLOBAL: [&str; 2] = [
    "LMGC_GFC3D-i00501-4-00000.hdf5",
    "Box_Stacks-i0122-82-5.hdf5",
];

/// Siconos's relative error of the forces `r` on the condensed problem `p`, recomputed from
/// r alone (x = q + W r).
fn recomputed_error(p: &ReducedProblem, r: &[[f64; 3]]) -> f64 {
    let mut x = vec![[0.0; 3]; p.w.points()];
    p.w.apply(r, &p.q, &mut x);
    relative_error(natural_map_residual(r, &x, &p.mu), &p.q, r, &x)
}

/// The largest normal force (third local component) [N].
fn largest_normal_force(r: &[[f64; 3]]) -> f64 {
    r.iter().map(|r| r[2].abs()).fold(0.0, f64::max)
}

/// The normal forces of `a` and `b` agree to 1e-5 of the largest of `b`'s.
fn assert_normal_forces_agree(name: &str, a: &[[f64; 3]], b: &[[f64; 3]]) {
    let scale = largest_normal_force(b);
    for (a, b) in a.iter().zip(b) {
        assert!(
            (a[2] - b[2]).abs() <= 1e-5 * scale,
            "{name}: {a:?} vs {b:?}"
        );
    }
}

/// Both solvers reach Siconos's error 1e-8 on both files; the error reported is recomputed
/// here from r alone (x = q + W r), and Newton and Gauss-Seidel agree on the normal forces to
/// 1e-5 of the largest (both errors ≤ 1e-8 relative; the problems are well conditioned enough
/// for the forces to follow to that level).
#[test]
fn solves_small_problems_to_1e8() {
    for name in SMALL_GLOBAL {
        let file = read(data(name)).expect("readable");
        let p = ReducedProblem::of_file(&file).expect("condensable");
        let r0 = vec![[0.0; 3]; p.w.points()];
        let (newton, _) = semismooth_newton(&p.w, &p.q, &p.mu, &r0, 1e-8, 200);
        let gs = gauss_seidel_blocks(&p.w, &p.q, &p.mu, &r0, 1e-8, 10_000);
        for (solver, sol) in [("newton", &newton), ("gauss-seidel", &gs)] {
            assert!(sol.converged, "{name} {solver}: error {}", sol.error);
            let err = recomputed_error(&p, &sol.r);
            assert!(err <= 1e-8, "{name} {solver}: recomputed error {err}");
        }
        assert_normal_forces_agree(name, &newton.r, &gs.r);
    }
}

/// The global problems solved in their global form (M and H, W never formed) reach Siconos's
/// error 1e-8 as measured on the condensed problem (r put into u = W r + q independently of the
/// solver), and their normal forces agree with the condensed semismooth solve to 1e-5 of the
/// largest (both at 1e-8, which leaves room of that order for the forces). The third file,
/// 98 rigid spheres with 256 contacts (more contact unknowns than freedoms), is the one on
/// which the global form used to stop at an error of 7.9e-5.
#[test]
fn global_form_solves_the_global_problems() {
    let spheres = ["spheres-in-a-box-98-i10000-256-10.hdf5"];
    for name in SMALL_GLOBAL.iter().chain(&spheres) {
        let file = read(data(name)).expect("readable");
        let global = file.global().expect("a global problem");
        let sol = adhesim_fclib::solve_global(global, 1e-8, 400).expect("solvable");
        assert!(sol.converged, "{name}: error {}", sol.error);
        let p = ReducedProblem::of_file(&file).expect("condensable");
        let err = recomputed_error(&p, &sol.r);
        assert!(err <= 1e-8, "{name}: recomputed error {err}");
        let r0 = vec![[0.0; 3]; p.w.points()];
        let (newton, _) = semismooth_newton(&p.w, &p.q, &p.mu, &r0, 1e-8, 200);
        let scale = largest_normal_force(&newton.r);
        assert!(scale > 0.0, "{name}: no contact force");
        assert_normal_forces_agree(name, &sol.r, &newton.r);
    }
}
