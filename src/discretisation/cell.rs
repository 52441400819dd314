//! The cell of an infinite tube discretised (docs/theory.md §8): its helically periodic
//! conditions as linear constraints and the gauge that fixes its rigid motions (its Bloch
//! blocks are in [`super::cell_blocks`]).
//!
//! Each rod of the cell keeps its far-end vertex and quaternion node as unknowns, tied to
//! the screw image of its near end: `r_far = R_ψ r_near + h e_z` (three rows: x and y held
//! at zero, z at the cell's rise `h`, the axial motion the load parameter drives) and
//! `Im(w̄ ∘ (q_far − σ q_ψ ∘ q_near)) = 0` with `w = q_ψ ∘ q_near` at the state the rows are
//! built at (three rows, linear: with both unit norms they hold `q_far = σ q_ψ ∘ q_near`
//! exactly, as a clamp holds a frame). The rows are the far end's "support": their
//! multipliers are the force and moment the next cell applies to the rod.

use super::constraints::{support_constraints, LinearConstraint, Role, TipPlace};
use super::discrete_model::{DiscreteModel, End};
use crate::model::boundary::BoundaryConditions;
use crate::model::cell::Cell;
use crate::model::quaternion::{self, Quat};
use crate::model::symmetry::TurnZ;

/// Quadratic elements per rod of the cell of a tube of `n` helices by default: `128/n`, at
/// least 8 — 64 per turn of the helix for n ≤ 16 (the cell's rods are `1/n` of a turn), so
/// that the cell's axial force is Love's to 1e-9 and below.
pub fn default_elements(n: usize) -> usize {
    (128 / n.max(1)).max(8)
}

/// `rows[i][k] = ∂ Im(w̄ ∘ q)_i / ∂q_k`: the rows by which a frame near `w` is held.
fn held_rows(w: &Quat) -> [[f64; 4]; 3] {
    let conj = quaternion::conj(w);
    std::array::from_fn(|i| {
        std::array::from_fn(|k| {
            let mut ek = Quat::zeros();
            ek[k] = 1.0;
            quaternion::mul(&conj, &ek)[i]
        })
    })
}

/// A constraint of the given terms (zero coefficients dropped).
fn row(terms: Vec<(usize, f64)>, value: f64, role: Role) -> LinearConstraint {
    LinearConstraint {
        terms: terms.into_iter().filter(|t| t.1.abs() > 1e-15).collect(),
        value,
        role,
        moving: None,
    }
}

/// The constraints at the rods' ends: every rod's supports, or for the cell of an infinite
/// tube its periodic conditions, gauge and joints ([`cell_constraints`]).
pub(super) fn end_constraints(
    model: &DiscreteModel,
    x: &[f64],
    bc: &BoundaryConditions,
    tip: TipPlace,
    out: &mut Vec<LinearConstraint>,
) {
    if let Some(cell) = &model.assembly.cell {
        let height = match tip {
            TipPlace::Upright { height } => height,
            TipPlace::Turned { .. } => None,
        };
        cell_constraints(model, x, cell, height, out);
        return;
    }
    for id in 0..model.rods.len() {
        for (end, cond) in [(End::Base, bc.base), (End::Tip, bc.tip)] {
            support_constraints(model, x, id, end, cond, tip, out);
        }
    }
}

/// The constraints of a cell in the state `x`: the gauge of its rigid motions, the pin
/// joints inside it and the periodic conditions of every rod, its rise held at `height`
/// (m; at its value in `x` when `None`).
fn cell_constraints(
    model: &DiscreteModel,
    x: &[f64],
    cell: &Cell,
    height: Option<f64>,
    out: &mut Vec<LinearConstraint>,
) {
    gauge(model, x, out);
    for (j, joint) in model.assembly.joints.iter().enumerate() {
        let (ri, rj) = (&model.rods[joint.right], &model.rods[joint.left]);
        let (Some(vi), Some(vj)) = (ri.mesh.vertex_at(joint.s), rj.mesh.vertex_at(joint.s)) else {
            continue;
        };
        // r_right − Rot(turn) r_left = 0, held at its value in `x`
        let turn = TurnZ::new(joint.left_turn);
        let a = model.vertex(x, joint.right, vi);
        let b = model.vertex(x, joint.left, vj);
        let b = turn.apply([b[0], b[1], b[2]]);
        for i in 0..3 {
            let mut terms = vec![(ri.r_dof(vi, i), 1.0)];
            for k in 0..3 {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                terms.push((rj.r_dof(vj, k), -turn.apply(e)[i]));
            }
            out.push(row(terms, a[i] - b[i], Role::Joint(j)));
        }
    }
    for (id, rod) in model.rods.iter().enumerate() {
        let turn = TurnZ::new(cell.turns[id]);
        let (v, node) = (rod.end_vertex(End::Tip), rod.end_node(End::Tip));
        let tip = Role::Support {
            rod: id,
            end: End::Tip,
        };
        for i in 0..2 {
            let mut terms = vec![(rod.r_dof(v, i), 1.0)];
            for j in 0..2 {
                let mut e = [0.0; 3];
                e[j] = 1.0;
                terms.push((rod.r_dof(0, j), -turn.apply(e)[i]));
            }
            out.push(row(terms, 0.0, tip));
        }
        let terms = vec![(rod.r_dof(v, 2), 1.0), (rod.r_dof(0, 2), -1.0)];
        match height {
            Some(h) => out.push(row(terms, h, Role::TipHeight { rod: id })),
            None => {
                let rise = model.vertex(x, id, v)[2] - model.vertex(x, id, 0)[2];
                out.push(row(terms, rise, tip));
            }
        }
        let near = model.quaternion(x, id, 0);
        let far = model.quaternion(x, id, node);
        let w = turn.rotate(&near);
        let w = w / w.norm();
        let sigma = if far.dot(&w) < 0.0 { -1.0 } else { 1.0 };
        let rows = held_rows(&w);
        let turned: [Quat; 4] = std::array::from_fn(|k| {
            let mut ek = Quat::zeros();
            ek[k] = 1.0;
            turn.rotate(&ek)
        });
        for held in rows {
            let mut terms: Vec<(usize, f64)> =
                (0..4).map(|k| (rod.q_dof(node, k), held[k])).collect();
            for (k, tk) in turned.iter().enumerate() {
                let c: f64 = (0..4).map(|l| held[l] * tk[l]).sum();
                terms.push((rod.q_dof(0, k), -sigma * c));
            }
            out.push(row(terms, 0.0, tip));
        }
    }
}

/// The gauge of a cell's rigid motions, on rod 0's near end: its height, and its azimuth
/// (y, the vertex being at azimuth 0) off the axis; on the axis x, y and the twist of its
/// frame about the axis.
fn gauge(model: &DiscreteModel, x: &[f64], out: &mut Vec<LinearConstraint>) {
    let rod = &model.rods[0];
    let r = model.vertex(x, 0, 0);
    let base = Role::Support {
        rod: 0,
        end: End::Base,
    };
    out.push(row(vec![(rod.r_dof(0, 2), 1.0)], r[2], base));
    out.push(row(vec![(rod.r_dof(0, 1), 1.0)], r[1], base));
    if rod.helix.is_straight() {
        out.push(row(vec![(rod.r_dof(0, 0), 1.0)], r[0], base));
        let held = model.quaternion(x, 0, 0);
        let held = held / held.norm();
        let rh = quaternion::rotation(&held);
        let rows = held_rows(&held);
        let twist: Vec<(usize, f64)> = (0..4)
            .map(|k| {
                (
                    rod.q_dof(0, k),
                    (0..3).map(|i| rh[(2, i)] * rows[i][k]).sum(),
                )
            })
            .collect();
        out.push(row(twist, 0.0, base));
    }
}
