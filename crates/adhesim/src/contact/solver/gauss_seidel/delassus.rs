//! The reduced contact system inside a Newton iteration (docs/model.md §6): the Delassus operator
//! W = H K̄⁻¹ Hᵀ from one multi-right-hand-side solve with the iteration's factorisation, turned
//! to new frames and probed for reuse; [`super::sweep`] solves the system on it.

use crate::contact::detect::ContactPoint;
use crate::linalg::LinearSolve;
use crate::{mat3_from_rows, Mat3};

/// The dense Delassus operator W = H K̄⁻¹ Hᵀ of the contact points.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Delassus {
    /// W, 3N_c × 3N_c, row-major [m/N].
    pub w: Vec<f64>,
    /// 3N_c.
    pub m: usize,
}

/// Right-hand sides solved at a time when building W: the columns K̄⁻¹Hᵀ of one chunk are
/// reduced to rows of W and dropped, so the memory is that of W plus DOFs × this.
const DELASSUS_CHUNK: usize = 64;

/// Columns `start..start + cols` of W (the contact force components 3p + c) into `out`,
/// column-major (`cols` × 3N_c), with one multi-right-hand-side solve: the columns K̄⁻¹Hᵀ go
/// through `scratch` (DOFs × cols) and are reduced by H. Constrained unknowns get no force.
fn w_columns(
    points: &[ContactPoint],
    start: usize,
    cols: usize,
    chol: &mut impl LinearSolve,
    constrained: &[bool],
    scratch: &mut [f64],
    out: &mut [f64],
) {
    let n = constrained.len();
    let m = 3 * points.len();
    let block = &mut scratch[..n * cols];
    block.iter_mut().for_each(|v| *v = 0.0);
    for (j, col) in block.chunks_exact_mut(n).enumerate() {
        let (p, c) = ((start + j) / 3, (start + j) % 3);
        let mut r = [0.0; 3];
        r[c] = 1.0;
        points[p].add_ht(r, col);
        for (v, &fixed) in col.iter_mut().zip(constrained) {
            if fixed {
                *v = 0.0;
            }
        }
    }
    chol.solve_in_place(block);
    for (zc, wc) in block.chunks_exact(n).zip(out.chunks_exact_mut(m)) {
        for (pt, w3) in points.iter().zip(wc.chunks_exact_mut(3)) {
            w3.copy_from_slice(&pt.apply_h(zc));
        }
    }
}

/// Builds W with the current factorisation, 64 columns of K̄⁻¹Hᵀ at a time.
pub fn delassus(
    points: &[ContactPoint],
    chol: &mut impl LinearSolve,
    constrained: &[bool],
) -> Delassus {
    let n = constrained.len();
    let m = 3 * points.len();
    let chunk = DELASSUS_CHUNK.min(m.max(1));
    let mut scratch = vec![0.0; n * chunk];
    let mut cols_out = vec![0.0; m * chunk];
    let mut w = vec![0.0; m * m];
    for start in (0..m).step_by(chunk) {
        let cols = chunk.min(m - start);
        w_columns(
            points,
            start,
            cols,
            chol,
            constrained,
            &mut scratch,
            &mut cols_out,
        );
        for (j, wc) in cols_out.chunks_exact(m).take(cols).enumerate() {
            for (row, &v) in wc.iter().enumerate() {
                w[row * m + start + j] = v;
            }
        }
    }
    // Symmetrise (W is symmetric in exact arithmetic).
    for i in 0..m {
        for j in 0..i {
            let s = 0.5 * (w[i * m + j] + w[j * m + i]);
            w[i * m + j] = s;
            w[j * m + i] = s;
        }
    }
    Delassus { w, m }
}

impl Delassus {
    /// Turns W, built in the local frames `from` of its points (rows T₁, T₂, N), to the
    /// frames `to`: block αβ becomes R_α W_αβ R_βᵀ with R_α = F_to,α F_from,αᵀ. Exact when
    /// the points' nodes, master weights and K̄ are the same, since W_αβ = F_α W^g_αβ F_βᵀ
    /// with W^g in global axes.
    pub fn rotate_frames(&mut self, from: &[[[f64; 3]; 3]], to: &[[[f64; 3]; 3]]) {
        assert_eq!(from.len(), to.len());
        assert_eq!(3 * from.len(), self.m);
        let mat = |f: &[[f64; 3]; 3]| mat3_from_rows(*f);
        // None where a point's frame is unchanged: its blocks stay bit for bit.
        let rot: Vec<Option<Mat3>> = from
            .iter()
            .zip(to)
            .map(|(f, t)| (f != t).then(|| mat(t) * mat(f).transpose()))
            .collect();
        let m = self.m;
        for (a, ra) in rot.iter().enumerate() {
            for (b, rb) in rot.iter().enumerate() {
                if ra.is_none() && rb.is_none() {
                    continue;
                }
                let at = |i: usize, j: usize| (3 * a + i) * m + 3 * b + j;
                let block = Mat3::from_fn(|i, j| self.w[at(i, j)]);
                let turned = ra.unwrap_or_else(Mat3::identity)
                    * block
                    * rb.unwrap_or_else(Mat3::identity).transpose();
                for i in 0..3 {
                    for j in 0..3 {
                        self.w[at(i, j)] = turned[(i, j)];
                    }
                }
            }
        }
    }

    /// Relative change ‖W_now − W‖ / ‖W_now‖ over the three columns of contact point `probe`,
    /// with W_now from the current factorisation: three solves instead of the 3N_c of a
    /// rebuild, to tell whether this W can still be used.
    pub fn probed_change(
        &self,
        points: &[ContactPoint],
        probe: usize,
        chol: &mut impl LinearSolve,
        constrained: &[bool],
    ) -> f64 {
        let m = self.m;
        let mut scratch = vec![0.0; 3 * constrained.len()];
        let mut fresh = vec![0.0; 3 * m];
        w_columns(
            points,
            3 * probe,
            3,
            chol,
            constrained,
            &mut scratch,
            &mut fresh,
        );
        let (mut diff, mut size) = (0.0f64, 0.0f64);
        for (c, wc) in fresh.chunks_exact(m).enumerate() {
            for (row, &a) in wc.iter().enumerate() {
                let b = self.w[row * m + 3 * probe + c];
                diff += (a - b) * (a - b);
                size += a * a;
            }
        }
        if size > 0.0 {
            (diff / size).sqrt()
        } else if diff == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::detect::frame_from_normal as unit_frame;
    use crate::Vec3;

    /// The frame of the (not necessarily unit) normal `n`.
    fn frame_from_normal(n: [f64; 3]) -> [[f64; 3]; 3] {
        unit_frame(Vec3::from(n).normalize().into())
    }

    /// W in local frames from W^g in global axes: W_αβ = F_α W^g_αβ F_βᵀ.
    fn local(wg: &[f64], frames: &[[[f64; 3]; 3]]) -> Delassus {
        let m = 3 * frames.len();
        let mat = |f: &[[f64; 3]; 3]| mat3_from_rows(*f);
        let mut w = vec![0.0; m * m];
        for (a, fa) in frames.iter().enumerate() {
            for (b, fb) in frames.iter().enumerate() {
                let at = |i: usize, j: usize| (3 * a + i) * m + 3 * b + j;
                let block = mat(fa) * Mat3::from_fn(|i, j| wg[at(i, j)]) * mat(fb).transpose();
                for i in 0..3 {
                    for j in 0..3 {
                        w[at(i, j)] = block[(i, j)];
                    }
                }
            }
        }
        Delassus { w, m }
    }

    /// Turning W from one set of frames to another gives W built in the new frames, to
    /// round-off (1e-15 of its largest entry: a handful of products of unit rotations).
    #[test]
    fn turning_w_to_new_frames_equals_building_it_there() {
        let m = 9;
        // A symmetric positive definite W^g: AᵀA + I with a fixed, uneven A.
        let a: Vec<f64> = (0..m * m)
            .map(|k| ((k * 37 % 11) as f64 - 5.0) * 0.1)
            .collect();
        let wg: Vec<f64> = (0..m * m)
            .map(|k| {
                let (i, j) = (k / m, k % m);
                (0..m).map(|r| a[r * m + i] * a[r * m + j]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 }
            })
            .collect();
        let old = [
            frame_from_normal([0.0, 1.0, 0.0]),
            frame_from_normal([0.3, 0.9, 0.1]),
            frame_from_normal([-0.5, 0.5, 0.7]),
        ];
        let new = [
            frame_from_normal([0.1, 1.0, 0.0]),
            frame_from_normal([0.3, 0.9, 0.1]),
            frame_from_normal([0.0, 0.2, 1.0]),
        ];
        let mut w = local(&wg, &old);
        w.rotate_frames(&old, &new);
        let expected = local(&wg, &new);
        let scale = expected.w.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let err =
            w.w.iter()
                .zip(&expected.w)
                .fold(0.0f64, |s, (x, y)| s.max((x - y).abs()));
        assert!(err <= 1e-15 * scale * 10.0, "error {err:e} of {scale:e}");
        // Unchanged frames leave W bit for bit as it was.
        let before = w.clone();
        w.rotate_frames(&new, &new);
        assert_eq!(w, before);
    }
}
