//! The symmetric pair and the full assembly it stands for (DESIGN.md §7): a state of the
//! pair expanded to the state of every rod.

use super::model::DiscreteModel;
use super::system::System;
use crate::model::symmetry::TurnZ;

/// Expands the state `x` of a symmetric pair (in `pair_system`'s layout) to the state of
/// the full model in `full_system`'s layout: every rod is the image of one rod of the pair
/// turned about z; support and joint multipliers are zero (they do not enter the Hessian).
/// `out` has the length of the full system's unknowns.
pub fn expand_state(
    pair: &DiscreteModel,
    pair_system: &System,
    x: &[f64],
    full: &DiscreteModel,
    full_system: &System,
    out: &mut [f64],
) {
    let sym = pair
        .assembly
        .symmetry
        .expect("expand_state needs a symmetric pair");
    out.iter_mut().for_each(|v| *v = 0.0);
    for (k, rod) in full.rods.iter().enumerate() {
        let (src, angle) = sym.image(k);
        let from = &pair.rods[src];
        let turn = TurnZ::new(angle);
        for node in 0..rod.mesh.quaternion_nodes() {
            let q = pair.quaternion(x, src, node);
            let q = turn.rotate(&q);
            for c in 0..4 {
                out[rod.q_dof(node, c)] = q[c];
            }
            out[full_system.unit_row(k, node)] = x[pair_system.unit_row(src, node)];
        }
        for v in 0..=rod.mesh.elements() {
            let r = turn.apply([
                x[from.r_dof(v, 0)],
                x[from.r_dof(v, 1)],
                x[from.r_dof(v, 2)],
            ]);
            for c in 0..3 {
                out[rod.r_dof(v, c)] = r[c];
            }
        }
        for e in 0..rod.mesh.elements() {
            let row = pair_system.compat_row(src, e);
            let l = turn.apply([x[row], x[row + 1], x[row + 2]]);
            let full_row = full_system.compat_row(k, e);
            out[full_row..full_row + 3].copy_from_slice(&l);
        }
    }
}
