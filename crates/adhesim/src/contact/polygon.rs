//! Plane geometry of segment-to-segment contact: faces projected on a plane as polygons,
//! the clipping of one polygon by another, a triangle quadrature exact to degree 5 and the
//! shape functions of a projected face at a point of the plane.

/// A point of the projection plane, in its two in-plane coordinates [m].
pub type Point2 = [f64; 2];

/// Twice the signed area of a polygon [m²]: positive when its vertices turn
/// counter-clockwise.
pub fn twice_signed_area(poly: &[Point2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

/// The polygon with its vertices turning counter-clockwise.
pub fn counter_clockwise(mut poly: Vec<Point2>) -> Vec<Point2> {
    if twice_signed_area(&poly) < 0.0 {
        poly.reverse();
    }
    poly
}

/// The part of `subject` inside the convex polygon `clip` (both counter-clockwise), by
/// Sutherland-Hodgman: the subject is cut by each edge's half-plane in turn. Empty when they
/// do not overlap.
pub fn clip(subject: &[Point2], clip: &[Point2]) -> Vec<Point2> {
    let mut out: Vec<Point2> = subject.to_vec();
    let m = clip.len();
    for i in 0..m {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % m]);
        // Signed distance (scaled) of p to the edge a→b: ≥ 0 inside (on the left).
        let side = |p: Point2| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
        let input = std::mem::take(&mut out);
        let n = input.len();
        for k in 0..n {
            let (p, q) = (input[k], input[(k + 1) % n]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
    }
    if out.len() < 3 {
        out.clear();
    }
    out
}

/// Barycentric coordinates and weights (summing to 1) of a 7-point rule on a triangle,
/// exact for polynomials of degree 5 (Strang and Fix; Dunavant's rule 5).
pub fn triangle_rule() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a1, b1) = ((6.0 - s) / 21.0, (9.0 + 2.0 * s) / 21.0);
    let (a2, b2) = ((6.0 + s) / 21.0, (9.0 - 2.0 * s) / 21.0);
    let (w1, w2) = ((155.0 - s) / 1200.0, (155.0 + s) / 1200.0);
    let third = 1.0 / 3.0;
    [
        ([third, third, third], 9.0 / 40.0),
        ([b1, a1, a1], w1),
        ([a1, b1, a1], w1),
        ([a1, a1, b1], w1),
        ([b2, a2, a2], w2),
        ([a2, b2, a2], w2),
        ([a2, a2, b2], w2),
    ]
}

/// Quadrature points and weights [m²] over a convex polygon: the triangles from its centroid
/// to each edge, each with [`triangle_rule`]. Exact for polynomials of degree 5.
pub fn polygon_quadrature(poly: &[Point2]) -> Vec<(Point2, f64)> {
    let n = poly.len();
    let g: Point2 = std::array::from_fn(|k| poly.iter().map(|p| p[k]).sum::<f64>() / n as f64);
    let rule = triangle_rule();
    let mut out = Vec::with_capacity(7 * n);
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let area = 0.5 * twice_signed_area(&[g, a, b]);
        if area <= 0.0 {
            continue;
        }
        for (l, w) in rule {
            let p = std::array::from_fn(|k| l[0] * g[k] + l[1] * a[k] + l[2] * b[k]);
            out.push((p, w * area));
        }
    }
    out
}

/// The shape functions at `p` of a face projected on the plane: a bilinear quadrilateral
/// (four corners, its (ξ, η) found by Newton's method) or a linear triangle (three corners,
/// barycentric coordinates), in the corners' order. Not clamped: a point outside the face
/// gives values outside [0, 1].
pub fn shape_at(corners: &[Point2], p: Point2) -> Vec<f64> {
    match corners.len() {
        3 => {
            let [a, b, c] = [corners[0], corners[1], corners[2]];
            let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
            let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
            vec![1.0 - l1 - l2, l1, l2]
        }
        _ => {
            let (xi, eta) = quad_coordinates(corners, p);
            quad_shape(xi, eta).to_vec()
        }
    }
}

/// Bilinear shape functions of a quadrilateral at (ξ, η) ∈ [−1, 1]² (the quad4 face's).
pub use crate::element::quad4_shape as quad_shape;

/// (ξ, η) of `p` in the bilinear map of the quadrilateral `c`, by Newton's method from the
/// centre (exact in one step for a parallelogram).
fn quad_coordinates(c: &[Point2], p: Point2) -> (f64, f64) {
    let (mut xi, mut eta) = (0.0f64, 0.0f64);
    for _ in 0..30 {
        let n = quad_shape(xi, eta);
        let dxi = [-(1.0 - eta), 1.0 - eta, 1.0 + eta, -(1.0 + eta)].map(|v| 0.25 * v);
        let deta = [-(1.0 - xi), -(1.0 + xi), 1.0 + xi, 1.0 - xi].map(|v| 0.25 * v);
        let comb = |w: [f64; 4], k: usize| (0..4).map(|i| w[i] * c[i][k]).sum::<f64>();
        let r = [p[0] - comb(n, 0), p[1] - comb(n, 1)];
        let j = [[comb(dxi, 0), comb(deta, 0)], [comb(dxi, 1), comb(deta, 1)]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let d_xi = (j[1][1] * r[0] - j[0][1] * r[1]) / det;
        let d_eta = (j[0][0] * r[1] - j[1][0] * r[0]) / det;
        xi += d_xi;
        eta += d_eta;
        if d_xi.abs() + d_eta.abs() < 1e-14 {
            break;
        }
    }
    (xi, eta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_rule_is_exact_to_degree_five() {
        // ∫ over the unit right triangle of x^a y^b = a! b! / (a + b + 2)!.
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        let tri = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let q = polygon_quadrature(&tri);
        for a in 0..=5u32 {
            for b in 0..=(5 - a) {
                let exact = fact(a) * fact(b) / fact(a + b + 2);
                let got: f64 = q
                    .iter()
                    .map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32))
                    .sum();
                assert!((got - exact).abs() < 1e-15, "x^{a} y^{b}: {got} vs {exact}");
            }
        }
    }

    #[test]
    fn clipping_two_squares_gives_their_overlap() {
        let a = vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let b = vec![[1.0, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]];
        let c = clip(&a, &b);
        assert!((0.5 * twice_signed_area(&c) - 1.0).abs() < 1e-15);
        // Disjoint squares: nothing; one inside the other: the inner one.
        let far = b.iter().map(|p| [p[0] + 5.0, p[1]]).collect::<Vec<_>>();
        assert!(clip(&a, &far).is_empty());
        let inner = vec![[0.5, 0.5], [1.0, 0.5], [1.0, 1.5], [0.5, 1.5]];
        assert!((0.5 * twice_signed_area(&clip(&inner, &a)) - 0.5).abs() < 1e-15);
        // A triangle cut by a square.
        let t = vec![[-1.0, 0.0], [3.0, 0.0], [-1.0, 4.0]];
        let area = 0.5 * twice_signed_area(&clip(&t, &a));
        // The square minus the corner triangle beyond x + y = 3: 4 − 0.5.
        assert!((area - 3.5).abs() < 1e-14, "{area}");
    }

    #[test]
    fn shape_functions_interpolate_the_point_and_sum_to_one() {
        let quad = [[0.0, 0.0], [2.0, 0.2], [2.3, 1.9], [-0.1, 1.5]];
        let tri = [[0.0, 0.0], [2.0, 0.2], [0.4, 1.7]];
        for corners in [&quad[..], &tri[..]] {
            for p in [[0.7, 0.6], [1.5, 1.2], [0.1, 0.05]] {
                let n = shape_at(corners, p);
                assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
                for k in 0..2 {
                    let x: f64 = n.iter().zip(corners).map(|(w, c)| w * c[k]).sum();
                    assert!((x - p[k]).abs() < 1e-12, "{x} vs {}", p[k]);
                }
            }
        }
    }
}
