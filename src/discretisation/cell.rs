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
use super::support::{Moving, SupportPose};
use crate::model::boundary::BoundaryConditions;
use crate::model::cell::Cell;
use crate::model::quaternion::{self, Quat};
use crate::model::symmetry::TurnZ;
use nalgebra::Vector3;

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
        let (height, spin) = match tip {
            TipPlace::Upright { height } => (height, None),
            TipPlace::Turned { pose, height_held } => {
                (height_held.then_some(pose.centre[2]), Some(pose))
            }
        };
        cell_constraints(model, x, cell, height, spin.as_ref(), out);
        return;
    }
    for id in 0..model.rods.len() {
        for (end, cond) in [(End::Base, bc.base), (End::Tip, bc.tip)] {
            support_constraints(model, x, id, end, cond, tip, out);
        }
    }
}

/// The constraints of a cell in the state `x`: the gauge of its rigid motions, the pin
/// joints inside it (a sliding joint's rows are its own) and the periodic conditions of every rod, its rise held at `height`
/// (m; at its value in `x` when `None`), its screw turned further by the twist of `spin`
/// (the tube's twist per cell, moving with the load parameter) when there is one.
fn cell_constraints(
    model: &DiscreteModel,
    x: &[f64],
    cell: &Cell,
    height: Option<f64>,
    spin: Option<&SupportPose>,
    out: &mut Vec<LinearConstraint>,
) {
    gauge(model, x, spin, out);
    for (j, joint) in model.assembly.joints.iter().enumerate() {
        // a sliding joint's rows are its own (super::slide)
        if model.slide_of(j).is_some() {
            continue;
        }
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
    for id in 0..model.rods.len() {
        let ends = Ends {
            far: id,
            near: cell.partners[id],
            bending: cell.bending,
        };
        periodic_constraints(model, x, ends, cell.turns[id], height, spin, out);
    }
}

/// The rods a periodic condition ties: the far end of rod `far` to the image of rod
/// `near`'s near end; in a bending cell (`bending`) the rise is a row of the map too.
#[derive(Clone, Copy)]
struct Ends {
    far: usize,
    near: usize,
    bending: bool,
}

/// The periodic conditions of rod `ends.far`, whose far end is the near end of rod
/// `ends.near` (itself but in a bending cell) carried by the screw of turn `turn` (rad) and
/// the cell's rise: `R_s^T (r_far − t) − R_ψ r_near` held at zero in x and y, the rise at
/// `height`, and the far frame held at `σ q_s ∘ q_ψ ∘ q_near`, `R_s` (`q_s`) the turn of
/// `spin` (the twist `φ` per cell, then a bending cell's tilt), `t` its centre (`(0, 0, h)`
/// but under a tilt, [`SupportPose::of_cell`]). Under a turn the rows on the far end move
/// with the load parameter ([`Moving`]): `(R_s e_i)·(r_far − t)` and `Im(w̄ ∘ q_far)` with
/// `w = q_s ∘ q_ψ ∘ q_near` (at `x`), while the rows' terms on the near end, `R_ψ r_near`
/// and `Im(w̄ ∘ q_s ∘ q_ψ ∘ q_near)`, do not depend on the turn. In a bending cell the rise
/// is such a row too (`(R_s e_z)·(r_far − t) = z_near`).
fn periodic_constraints(
    model: &DiscreteModel,
    x: &[f64],
    ends: Ends,
    turn: f64,
    height: Option<f64>,
    spin: Option<&SupportPose>,
    out: &mut Vec<LinearConstraint>,
) {
    let id = ends.far;
    let rod = &model.rods[id];
    let partner = &model.rods[ends.near];
    let turn = TurnZ::new(turn);
    let (v, node) = (rod.end_vertex(End::Tip), rod.end_node(End::Tip));
    let tip = Role::Support {
        rod: id,
        end: End::Tip,
    };
    let spin_turn = |e: Vector3<f64>| spin.map_or(e, |pose| pose.turn(&e));
    for i in 0..2 {
        let direction = Vector3::ith(i, 1.0);
        let a = spin_turn(direction);
        // the far vertex's three unknowns first, in order, whatever their coefficients
        let mut terms: Vec<(usize, f64)> = (0..3).map(|k| (rod.r_dof(v, k), a[k])).collect();
        for j in 0..2 {
            let mut e = [0.0; 3];
            e[j] = 1.0;
            terms.push((partner.r_dof(0, j), -turn.apply(e)[i]));
        }
        out.push(LinearConstraint {
            terms,
            value: spin.map_or(0.0, |pose| a.dot(&pose.centre)),
            role: tip,
            moving: spin.map(|_| Moving::Position {
                direction,
                offset: 0.0,
            }),
        });
    }
    let mut terms = vec![(rod.r_dof(v, 2), 1.0), (partner.r_dof(0, 2), -1.0)];
    match (height, spin) {
        (Some(_), Some(pose)) if ends.bending => {
            let a = pose.turn(&Vector3::z());
            terms = (0..3).map(|k| (rod.r_dof(v, k), a[k])).collect();
            terms.push((partner.r_dof(0, 2), -1.0));
            out.push(LinearConstraint {
                terms,
                value: a.dot(&pose.centre),
                role: Role::TipHeight { rod: id },
                moving: Some(Moving::Position {
                    direction: Vector3::z(),
                    offset: 0.0,
                }),
            });
        }
        (Some(h), _) => out.push(row(terms, h, Role::TipHeight { rod: id })),
        (None, _) => {
            let rise = model.vertex(x, id, v)[2] - model.vertex(x, ends.near, 0)[2];
            out.push(row(terms, rise, tip));
        }
    }
    let near = model.quaternion(x, ends.near, 0);
    let far = model.quaternion(x, id, node);
    let reference = turn.rotate(&near);
    let reference = reference / reference.norm();
    let w = spin.map_or(reference, |pose| {
        quaternion::mul(&pose.rotation, &reference)
    });
    let sigma = if far.dot(&w) < 0.0 { -1.0 } else { 1.0 };
    let (far_rows, near_rows) = (held_rows(&w), held_rows(&reference));
    let turned: [Quat; 4] = std::array::from_fn(|k| {
        let mut ek = Quat::zeros();
        ek[k] = 1.0;
        turn.rotate(&ek)
    });
    for i in 0..3 {
        let mut terms: Vec<(usize, f64)> = (0..4)
            .map(|k| (rod.q_dof(node, k), far_rows[i][k]))
            .collect();
        for (k, tk) in turned.iter().enumerate() {
            let c: f64 = (0..4).map(|l| near_rows[i][l] * tk[l]).sum();
            terms.push((partner.q_dof(0, k), -sigma * c));
        }
        out.push(LinearConstraint {
            terms,
            value: 0.0,
            role: tip,
            moving: spin.map(|_| Moving::Orientation {
                reference,
                weights: Vector3::ith(i, 1.0),
            }),
        });
    }
}

/// The weights of a cell's vertices in the mean along its rods: each rod's vertices but
/// its far one (another cell's near one), weighted by arc length (half of each element
/// beside the vertex, the near vertex's far element being the rod's last), over the total
/// length of the cell's rods: `(vertex, weight)` of rod `id`.
pub fn axis_weights(model: &DiscreteModel, id: usize) -> Vec<(usize, f64)> {
    let total = model.length() * model.rods.len() as f64;
    let s = &model.rods[id].mesh.vertices;
    let count = s.len() - 1;
    (0..count)
        .map(|v| {
            let before = if v == 0 {
                s[count] - s[count - 1]
            } else {
                s[v] - s[v - 1]
            };
            (v, 0.5 * (before + s[v + 1] - s[v]) / total)
        })
        .collect()
}

/// The gauge of a cell's rigid motions, on rod 0's near end: its height, and its azimuth
/// (y, the vertex being at azimuth 0) off the axis; on the axis x, y and the twist of its
/// frame about the axis (a straight rod is its own axis, held at its near end). A bending
/// cell of a tube also holds x of its near section's centre (the mean of its n near ends),
/// a rigid motion, and the tube's axis across the bending plane by one row on the mean of
/// the rods' lateral offsets from it along their length
/// ([`axis_weights`]), each vertex against the axis's section at its own height, a fraction
/// `s/ℓ` of the rise along the bent axis ([`Moving::Axis`], turning with the tilt of `spin`):
/// the tube's axis is the arc-length mean of its rods, as in the bending wave's amplitude,
/// and the lateral load a bent tube under an axial force needs falls along the rods. With
/// sliding crossings it also holds the sums of the contacts' arc lengths on the right and on
/// the left rods (see docs/joints.md, "The cell of the infinite tube").
fn gauge(
    model: &DiscreteModel,
    x: &[f64],
    spin: Option<&SupportPose>,
    out: &mut Vec<LinearConstraint>,
) {
    let rod = &model.rods[0];
    let r = model.vertex(x, 0, 0);
    let base = Role::Support {
        rod: 0,
        end: End::Base,
    };
    out.push(row(vec![(rod.r_dof(0, 2), 1.0)], r[2], base));
    out.push(row(vec![(rod.r_dof(0, 1), 1.0)], r[1], base));
    if model.rods.len() > 2 {
        let terms = (0..model.rods.len())
            .map(|id| (model.rods[id].r_dof(0, 0), 1.0))
            .collect();
        let sum = (0..model.rods.len())
            .map(|id| model.vertex(x, id, 0)[0])
            .sum();
        out.push(row(terms, sum, base));
    }
    if model.rods.len() > 2 {
        let length = model.length();
        let vertices: Vec<(usize, usize, f64, f64)> = (0..model.rods.len())
            .flat_map(|id| {
                let s = &model.rods[id].mesh.vertices;
                axis_weights(model, id)
                    .into_iter()
                    .map(move |(v, w)| (id, v, s[v] / length, w))
            })
            .collect();
        let sections: std::sync::Arc<[(f64, f64)]> =
            vertices.iter().map(|&(_, _, f, w)| (f, w)).collect();
        let moving = Moving::Axis {
            offset: 0.0,
            sections: sections.clone(),
        };
        let (coeffs, value) = match spin {
            Some(pose) => moving.coefficients(pose, false),
            None => (
                sections.iter().flat_map(|&(_, w)| [0.0, w, 0.0]).collect(),
                0.0,
            ),
        };
        let terms: Vec<(usize, f64)> = vertices
            .iter()
            .flat_map(|&(id, v, _, _)| (0..3).map(move |k| (id, v, k)))
            .map(|(id, v, k)| model.rods[id].r_dof(v, k))
            .zip(coeffs)
            .collect();
        // the offset at the state the row is built at (the rods centred on the axis)
        let offset = vertices
            .iter()
            .flat_map(|&(id, v, _, _)| (0..3).map(move |k| (id, v, k)))
            .zip(&terms)
            .map(|((id, v, k), &(_, a))| a * model.vertex(x, id, v)[k])
            .sum::<f64>()
            - value;
        out.push(LinearConstraint {
            terms,
            value: value + offset,
            role: base,
            moving: spin.map(|_| Moving::Axis { offset, sections }),
        });
    }
    if !model.slides.is_empty() {
        // sliding crossings between uniform helices: the left rods turn and rise together
        // against the right ones at no cost, the contacts following; the sums of the
        // contacts' arc lengths on the right rods and on the left ones held hold them (a
        // uniform slip of every contact, as the gauge's other rows perturbations of the
        // block of the rigid motions alone)
        for side in 0..2 {
            let dofs: Vec<usize> = (0..model.slides.len())
                .map(|k| model.slide_dof(k, side))
                .collect();
            let sum = dofs.iter().map(|&d| x[d]).sum();
            out.push(row(dofs.iter().map(|&d| (d, 1.0)).collect(), sum, base));
        }
    }
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

/// Rod `rod` of the state `x` turning about the tube's axis (z) as a direction of the
/// primal unknowns: `δr = e_z × r`, `δq = ½ e_z ∘ q` (rad⁻¹) on that rod, zero elsewhere. The
/// cell's rods turning together are its rigid rotation, a neutral mode of every cell; one rod
/// turning alone is one with sliding crossings (its contacts sliding). A Bloch block holds
/// them by gauge rows at points ([`super::cell_blocks::CellBlocks::turning_rods`]).
pub fn turning_mode(model: &DiscreteModel, x: &[f64], rod: usize) -> Vec<f64> {
    let ez = Quat::new(0.0, 0.0, 1.0, 0.0);
    let mut t = vec![0.0; model.n_primal];
    let (id, rod) = (rod, &model.rods[rod]);
    for node in 0..rod.mesh.quaternion_nodes() {
        let dq = 0.5 * quaternion::mul(&ez, &model.quaternion(x, id, node));
        for k in 0..4 {
            t[rod.q_dof(node, k)] = dq[k];
        }
    }
    for v in 0..=rod.mesh.elements() {
        let r = model.vertex(x, id, v);
        t[rod.r_dof(v, 0)] = -r[1];
        t[rod.r_dof(v, 1)] = r[0];
    }
    t
}
