//! A contact site in the step's matrix K̄, for all the solvers: the stiffness K̄ shows there,
//! which sets the ρ_α of every solver and of the step's natural-map residual ([`RHO_FACTOR`]
//! times it), and what the solves that put the contact conditions into K̄ (the augmented
//! Lagrangian and the semismooth solve) add to it: the node couplings of a site's stencil in
//! K̄'s pattern, and H_αᵀ k_α H_α.

use crate::contact::detect::ContactPoint;
use crate::system::SystemMatrix;

/// ρ_α as a multiple of the stiffness K̄ shows at contact point α: each multiplier update
/// contracts the error by about 1/(1 + this) at an isolated point.
pub const RHO_FACTOR: f64 = 1000.0;

/// Estimate of the stiffness [N/m] that K̄ shows at a contact point, from the largest free
/// diagonal entry k_n of K̄ at each node of its stencil (`diagonal` holds K̄_ii; constrained
/// unknowns are skipped). Returns `None` when every unknown involved is constrained.
///
/// - A node-to-surface site (one slave node, or a plane-strain line of them, against a face's
///   nodes): 1/(Σ_n w_n²/k_n), the nodes taken as independent springs, an upper bound
///   since 1/(e K̄⁻¹ e) ≤ e K̄ e along any unit direction e.
/// - A mortar site (each side the weighted mean of a patch of neighbouring nodes, the slave
///   side its node alone with dual multipliers): the nodes
///   of a patch move together, so each side is one spring of compliance (Σ_n |w_n|/√k_n)²
///   and the site 1/Σ_sides. The independent-spring bound would be several times too stiff
///   here (by about half the nodes of a patch), and a ρ that large makes the semismooth
///   solve with friction wander (docs/contact-surfaces.md).
pub fn point_stiffness(pt: &ContactPoint, diagonal: &[f64], constrained: &[bool]) -> Option<f64> {
    let node_k = |n: usize| -> Option<f64> {
        (0..3)
            .filter(|&k| !constrained[3 * n + k])
            .map(|k| diagonal[3 * n + k])
            .filter(|v| v.is_finite() && *v > 0.0)
            .reduce(f64::max)
    };
    let compliance = if pt.slave_weights.is_empty() {
        let mut compliance = 0.0;
        for (m, w) in pt.stencil() {
            if let Some(k) = node_k(m) {
                compliance += w * w / k;
            }
        }
        compliance
    } else {
        let patch = |nodes: &mut dyn Iterator<Item = (usize, f64)>| -> f64 {
            let sum: f64 = nodes
                .filter_map(|(n, w)| node_k(n).map(|k| w.abs() / k.sqrt()))
                .sum();
            sum * sum
        };
        patch(&mut pt.slave_nodes()) + patch(&mut pt.master.iter().copied())
    };
    (compliance > 0.0).then(|| 1.0 / compliance)
}

/// Node couplings (slave, master node) that H_αᵀ k H_α adds to the element pattern.
pub fn couplings(points: &[ContactPoint]) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for pt in points {
        let nodes: Vec<usize> = pt.stencil().map(|(n, _)| n).collect();
        for (i, &a) in nodes.iter().enumerate() {
            pairs.extend(nodes[..i].iter().map(|&b| (a, b)));
        }
    }
    pairs
}

/// Adds H_αᵀ k_α H_α of every point to the system matrix (whose pattern must hold
/// [`couplings`]).
pub fn add_contact_tangent(
    points: &[ContactPoint],
    stiffness: &[[[f64; 3]; 3]],
    system: &mut SystemMatrix,
) {
    for (pt, k) in points.iter().zip(stiffness) {
        if k.iter().flatten().all(|&v| v == 0.0) {
            continue;
        }
        // G = Fᵀ k F in global axes (F has rows T₁, T₂, N).
        let f = &pt.frame;
        let mut kf = [[0.0; 3]; 3];
        for a in 0..3 {
            for j in 0..3 {
                kf[a][j] = (0..3).map(|b| k[a][b] * f[b][j]).sum();
            }
        }
        let mut g = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                g[i][j] = (0..3).map(|a| f[a][i] * kf[a][j]).sum();
            }
        }
        // H = [w_s I at the slave nodes, −w_m I at master node m] before the rotation.
        let nodes: Vec<(usize, f64)> = pt.stencil().collect();
        for &(a, ca) in &nodes {
            for &(b, cb) in &nodes {
                if a <= b {
                    let c = ca * cb;
                    system.add_block(a, b, &g.map(|row| row.map(|v| c * v)));
                }
            }
        }
    }
}
