//! Every prescribed displacement of a problem in one place: which unknowns are fixed, their
//! values at a time, and the quantities measured on them (reactions).

use crate::contact::detect::{thickness_twins, Master};
use crate::problem::{Dirichlet, Problem};

/// The Dirichlet conditions of a problem and the mask of the unknowns they fix.
#[derive(Clone, Debug)]
pub struct Constraints {
    conditions: Vec<Dirichlet>,
    fixed: Vec<bool>,
}

impl Constraints {
    /// The conditions `conditions` on a model with `num_dofs` unknowns (3 per node).
    pub fn new(conditions: &[Dirichlet], num_dofs: usize) -> Self {
        let mut fixed = vec![false; num_dofs];
        for d in conditions {
            for &node in &d.nodes {
                for k in 0..3 {
                    if d.components[k] {
                        fixed[3 * node + k] = true;
                    }
                }
            }
        }
        Constraints {
            conditions: conditions.to_vec(),
            fixed,
        }
    }

    /// True for every unknown some condition prescribes.
    pub fn mask(&self) -> &[bool] {
        &self.fixed
    }

    /// Sets the prescribed components of `u` [m] to their values at time `t` [s];
    /// `reference` holds the nodes' reference positions [m].
    pub fn impose(&self, reference: &[[f64; 3]], t: f64, u: &mut [f64]) {
        for d in &self.conditions {
            for &node in &d.nodes {
                let ud = d.displacement(reference[node], t);
                for k in 0..3 {
                    if d.components[k] {
                        u[3 * node + k] = ud[k];
                    }
                }
            }
        }
    }

    /// Sets the prescribed components of `v` to zero (a residual or a force on free unknowns).
    pub fn zero_fixed(&self, v: &mut [f64]) {
        for (x, &fixed) in v.iter_mut().zip(&self.fixed) {
            if fixed {
                *x = 0.0;
            }
        }
    }

    /// The components of `out_of_balance` [N] on prescribed unknowns, zero elsewhere: the
    /// force the supports exert on the bodies when `out_of_balance` is the residual.
    pub fn reactions(&self, out_of_balance: &[f64]) -> Vec<f64> {
        out_of_balance
            .iter()
            .zip(&self.fixed)
            .map(|(&g, &fixed)| if fixed { g } else { 0.0 })
            .collect()
    }

    /// ‖a − b‖ over the free unknowns.
    pub fn free_distance(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.fixed)
            .filter(|(_, &fixed)| !fixed)
            .map(|((x, y), _)| (x - y) * (x - y))
            .sum::<f64>()
            .sqrt()
    }
}

/// The representative of each node (see `SystemMatrix`). In a plane-strain
/// body the nodes of one line through the thickness (same reference x and y) share the
/// unknowns of the line's first node, provided they have the same prescribed components
/// (`fixed`, per unknown) and every contact pair that touches the body makes such a line one
/// contact point: the plane solution has them move alike, and the system of a slab one
/// element thick then has half its free unknowns. Every other node is its own representative.
pub fn thickness_ties(problem: &Problem, fixed: &[bool]) -> Vec<usize> {
    let offsets = problem.node_offsets();
    let mut rep: Vec<usize> = (0..fixed.len() / 3).collect();
    for (body, &offset) in problem.bodies.iter().zip(&offsets) {
        let nodes = offset..offset + body.mesh.num_nodes();
        let touches = |pair: &crate::contact::ContactPair| {
            pair.slave_nodes.iter().any(|n| nodes.contains(n))
                || matches!(&pair.master, Master::Faces(faces)
                    if faces.iter().any(|f| f.nodes().iter().any(|n| nodes.contains(n))))
        };
        let plane_pairs = problem
            .contacts
            .iter()
            .filter(|pair| touches(pair))
            .all(|pair| pair.thickness_twins.iter().any(|t| !t.is_empty()));
        if !body.plane_strain || !plane_pairs {
            continue;
        }
        let local: Vec<usize> = (0..body.mesh.num_nodes()).collect();
        let same_fixed = |a: usize, b: usize| fixed[3 * a..3 * a + 3] == fixed[3 * b..3 * b + 3];
        for (i, twins) in thickness_twins(&local, &body.mesh.nodes).iter().enumerate() {
            let first = twins
                .iter()
                .copied()
                .chain([i])
                .min()
                .expect("the line holds i");
            let line_alike = twins.iter().all(|&j| same_fixed(offset + i, offset + j));
            if line_alike {
                rep[offset + i] = offset + first;
            }
        }
    }
    rep
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::Table;

    fn clamp_x(nodes: Vec<usize>, ux: f64) -> Dirichlet {
        Dirichlet {
            nodes,
            components: [true, false, false],
            translation: [
                Table::constant(ux),
                Table::constant(0.0),
                Table::constant(0.0),
            ],
            rotation: None,
        }
    }

    #[test]
    fn imposes_only_prescribed_components_and_measures_reactions_there() {
        let c = Constraints::new(&[clamp_x(vec![1], 0.25)], 6);
        assert_eq!(c.mask(), &[false, false, false, true, false, false]);
        let mut u = vec![1.0; 6];
        c.impose(&[[0.0; 3], [1.0, 0.0, 0.0]], 0.0, &mut u);
        assert_eq!(u, vec![1.0, 1.0, 1.0, 0.25, 1.0, 1.0]);
        let g = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        assert_eq!(c.reactions(&g), vec![0.0, 0.0, 0.0, 4.0, 0.0, 0.0]);
        let mut z = g;
        c.zero_fixed(&mut z);
        assert_eq!(z, [1.0, 2.0, 3.0, 0.0, 5.0, 6.0]);
        // Only the free components count: (1−0)² + (5−1)² → √17.
        let d = c.free_distance(
            &[1.0, 0.0, 0.0, 9.0, 5.0, 0.0],
            &[0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        );
        assert!((d - 17f64.sqrt()).abs() < 1e-15);
    }
}
