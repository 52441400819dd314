//! The linear constraints of the KKT system: supports at the rod ends (docs/theory.md §3), the
//! prescribed tip height, and the pin joints at the crossings (docs/theory.md §2).

use super::discrete_model::{DiscreteModel, End};
use super::support::{Moving, SupportPose};
use crate::model::assembly::{Joint, RodId};
use crate::model::boundary::{BoundaryConditions, EndCondition, Rotation, Translation};
use crate::model::quaternion::{self, Quat};
use crate::model::symmetry::TurnZ;
use nalgebra::Vector3;

/// What a linear constraint represents (used to read reactions off its multiplier).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Held by the support at a rod end.
    Support { rod: RodId, end: End },
    /// The prescribed tip height `z = h` of a rod.
    TipHeight { rod: RodId },
    /// A pin joint (index into the model's joints).
    Joint(usize),
}

/// `Σ c_k x_k − value = 0`.
#[derive(Clone, Debug)]
pub struct LinearConstraint {
    pub terms: Vec<(usize, f64)>,
    pub value: f64,
    pub role: Role,
    /// How the coefficients and value move with the load parameter (a turning tip
    /// support), if they do.
    pub moving: Option<Moving>,
}

/// Orthonormal directions along which a support of this kind holds an end at `position`,
/// besides the axial one: `Fixed` holds x and y, `Radial` the azimuthal direction,
/// `Slide` nothing.
fn held_directions(t: Translation, position: &Vector3<f64>) -> Vec<Vector3<f64>> {
    match t {
        Translation::Fixed => vec![Vector3::x(), Vector3::y()],
        Translation::Slide => vec![],
        Translation::Radial => {
            let radial = Vector3::new(position[0], position[1], 0.0);
            if radial.norm() > 0.0 {
                let er = radial / radial.norm();
                vec![Vector3::new(-er[1], er[0], 0.0)]
            } else {
                vec![Vector3::x(), Vector3::y()]
            }
        }
    }
}

/// In-plane directions left free by a support of this kind (the complement of
/// [`held_directions`] in the x–y plane).
fn free_directions(t: Translation, position: &Vector3<f64>) -> Vec<Vector3<f64>> {
    match t {
        Translation::Fixed => vec![],
        Translation::Slide => vec![Vector3::x(), Vector3::y()],
        Translation::Radial => {
            let radial = Vector3::new(position[0], position[1], 0.0);
            if radial.norm() > 0.0 {
                vec![radial / radial.norm()]
            } else {
                vec![]
            }
        }
    }
}

/// Where the tip support is: not turned, with the tip's height (m) held when its axial
/// motion is prescribed (`None`: under a dead load, free); or turned, at a pose.
#[derive(Clone, Copy, Debug)]
pub(super) enum TipPlace {
    Upright {
        height: Option<f64>,
    },
    Turned {
        pose: SupportPose,
        height_held: bool,
    },
}

/// The constraints by which the support at `end` holds rod `id` under the conditions `cond`,
/// holding what it holds at its value in the state `x`; the tip support is at `tip`.
pub(super) fn support_constraints(
    model: &DiscreteModel,
    x: &[f64],
    id: RodId,
    end: End,
    cond: EndCondition,
    tip: TipPlace,
    out: &mut Vec<LinearConstraint>,
) {
    let tip_height = match (end, tip) {
        (End::Tip, TipPlace::Turned { pose, height_held }) => {
            turning_tip_constraints(model, x, id, cond, &pose, height_held, out);
            return;
        }
        (_, TipPlace::Upright { height }) => height,
        (End::Base, TipPlace::Turned { .. }) => None,
    };
    let rod = &model.rods[id];
    let v = rod.end_vertex(end);
    let r = model.vertex(x, id, v);
    let role = Role::Support { rod: id, end };
    // axial: the base held where it is (z = 0), the tip at the support's height `tip_height`
    // when the support's z is a prescribed motion (free under a dead load)
    match (end, tip_height) {
        (End::Base, _) => out.push(LinearConstraint {
            terms: vec![(rod.r_dof(v, 2), 1.0)],
            value: r[2],
            role,
            moving: None,
        }),
        (End::Tip, Some(h)) => out.push(LinearConstraint {
            terms: vec![(rod.r_dof(v, 2), 1.0)],
            value: h,
            role: Role::TipHeight { rod: id },
            moving: None,
        }),
        (End::Tip, None) => {}
    }
    for dir in held_directions(cond.translation, &r) {
        let terms: Vec<(usize, f64)> = (0..2)
            .filter(|&k| dir[k] != 0.0)
            .map(|k| (rod.r_dof(v, k), dir[k]))
            .collect();
        out.push(LinearConstraint {
            terms,
            value: dir.dot(&r),
            role,
            moving: None,
        });
    }
    // g = Im(q̄_held ∘ q) is linear in q and, with |q| = 1, zero only at q = ±q_held; near
    // q_held it is half the rotation from q_held in the body frame, R_heldᵀ δθ / 2, so
    // R_held g is half the spatial rotation and its z row holds the twist about z only
    let node = rod.end_node(end);
    let held = model.quaternion(x, id, node);
    let held = held / held.norm();
    let conj = quaternion::conj(&held);
    // rows[i][k] = ∂g_i/∂q_k
    let rows: [[f64; 4]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|k| {
            let mut ek = Quat::zeros();
            ek[k] = 1.0;
            quaternion::mul(&conj, &ek)[i]
        })
    });
    let push = |coeffs: [f64; 4], out: &mut Vec<LinearConstraint>| {
        let terms: Vec<(usize, f64)> = (0..4)
            .filter(|&k| coeffs[k].abs() > 1e-15)
            .map(|k| (rod.q_dof(node, k), coeffs[k]))
            .collect();
        out.push(LinearConstraint {
            terms,
            value: 0.0,
            role,
            moving: None,
        });
    };
    match cond.rotation {
        Rotation::Clamped => {
            for row in rows {
                push(row, out);
            }
        }
        Rotation::Pinned => {
            let rh = quaternion::rotation(&held);
            let twist: [f64; 4] =
                std::array::from_fn(|k| (0..3).map(|i| rh[(2, i)] * rows[i][k]).sum());
            push(twist, out);
        }
        Rotation::Free => {}
    }
}

/// Pin joint: equal positions of the two rods at the joint's arc length. At a rod end,
/// only the directions that the supports leave free are tied (the others are already
/// prescribed on both rods, and tying them again would make the system singular).
pub(super) fn joint_constraints(
    model: &DiscreteModel,
    x: &[f64],
    bc: &BoundaryConditions,
    index: usize,
    joint: &Joint,
    out: &mut Vec<LinearConstraint>,
) {
    let (ri, rj) = (&model.rods[joint.right], &model.rods[joint.left]);
    let (Some(vi), Some(vj)) = (ri.mesh.vertex_at(joint.s), rj.mesh.vertex_at(joint.s)) else {
        return;
    };
    let length = model.length();
    let position = model.vertex(x, joint.right, vi);
    let dirs: Vec<Vector3<f64>> = if joint.s <= 1e-9 * length {
        free_directions(bc.base.translation, &position)
    } else if joint.s >= length * (1.0 - 1e-9) {
        free_directions(bc.tip.translation, &position)
    } else {
        vec![Vector3::x(), Vector3::y(), Vector3::z()]
    };
    // dir · (r_right − Rot(turn) r_left) = dir · r_right − (Rotᵀ dir) · r_left
    let turn = TurnZ::new(joint.left_turn);
    let turned = |d: &Vector3<f64>| Vector3::from(turn.apply_inverse([d[0], d[1], d[2]]));
    let left_position = model.vertex(x, joint.left, vj);
    for dir in dirs {
        let back = turned(&dir);
        let mut terms = Vec::new();
        for k in 0..3 {
            if dir[k].abs() > 1e-15 {
                terms.push((ri.r_dof(vi, k), dir[k]));
            }
            if back[k].abs() > 1e-15 {
                terms.push((rj.r_dof(vj, k), -back[k]));
            }
        }
        out.push(LinearConstraint {
            terms,
            value: dir.dot(&position) - back.dot(&left_position),
            role: Role::Joint(index),
            moving: None,
        });
    }
}

/// The constraints by which a turning support at `pose` holds rod `id`'s tip under the
/// conditions `cond`, holding what it holds where the state `x` has it (`x` at `pose`); the
/// height along the support's axis is held when `height_held` (the axial motion prescribed).
fn turning_tip_constraints(
    model: &DiscreteModel,
    x: &[f64],
    id: RodId,
    cond: EndCondition,
    pose: &SupportPose,
    height_held: bool,
    out: &mut Vec<LinearConstraint>,
) {
    let rod = &model.rods[id];
    let v = rod.end_vertex(End::Tip);
    let r = model.vertex(x, id, v);
    let rot = quaternion::rotation(&pose.rotation);
    // the tip's position in the support's frame, in its plane
    let mut p = rot.transpose() * (r - pose.centre);
    p[2] = 0.0;
    let role = Role::Support {
        rod: id,
        end: End::Tip,
    };
    let positions: Vec<(usize, f64)> = (0..3).map(|k| (rod.r_dof(v, k), 0.0)).collect();
    let mut push = |moving: Moving, role: Role| {
        let dofs: Vec<usize> = match moving {
            Moving::Position { .. } => positions.iter().map(|t| t.0).collect(),
            Moving::Orientation { .. } => (0..4)
                .map(|k| rod.q_dof(rod.end_node(End::Tip), k))
                .collect(),
        };
        let (coeffs, value) = moving.coefficients(pose, false);
        out.push(LinearConstraint {
            terms: dofs.into_iter().zip(coeffs).collect(),
            value,
            role,
            moving: Some(moving),
        });
    };
    if height_held {
        push(
            Moving::Position {
                direction: Vector3::z(),
                offset: 0.0,
            },
            Role::TipHeight { rod: id },
        );
    }
    let held: Vec<Vector3<f64>> = match cond.translation {
        Translation::Fixed => vec![Vector3::x(), Vector3::y()],
        Translation::Slide => vec![],
        Translation::Radial if p.norm() > 0.0 => {
            let er = p / p.norm();
            vec![Vector3::new(-er[1], er[0], 0.0)]
        }
        Translation::Radial => vec![Vector3::x(), Vector3::y()],
    };
    for d in held {
        push(
            Moving::Position {
                direction: d,
                offset: d.dot(&p),
            },
            role,
        );
    }
    let node = rod.end_node(End::Tip);
    let q = model.quaternion(x, id, node);
    let reference = quaternion::mul(&quaternion::conj(&pose.rotation), &(q / q.norm()));
    match cond.rotation {
        Rotation::Clamped => {
            for weights in [Vector3::x(), Vector3::y(), Vector3::z()] {
                push(Moving::Orientation { reference, weights }, role);
            }
        }
        Rotation::Pinned => {
            let rr = quaternion::rotation(&reference);
            let weights = Vector3::new(rr[(2, 0)], rr[(2, 1)], rr[(2, 2)]);
            push(Moving::Orientation { reference, weights }, role);
        }
        Rotation::Free => {}
    }
}
