//! The linear constraints of the KKT system: supports at the rod ends (docs/theory.md §3), the
//! prescribed tip height, and the pin joints at the crossings (docs/theory.md §2).

use super::discrete_model::{DiscreteModel, End};
use super::mirror::Mirror;
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
    /// The phase condition that fixes a state on its orbit under the rotation about the
    /// axis (see [`phase_condition`]); its multiplier vanishes at every solution.
    Phase,
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
            Moving::Position { .. } | Moving::Axis { .. } => {
                positions.iter().map(|t| t.0).collect()
            }
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

/// The phase condition of a state `x` off the axis of a problem invariant under rotation
/// about it (a straight isotropic rod, axisymmetric supports and loads: its buckled shapes
/// turn about the axis at no cost): `(e_z × r_v(x))·r_v = 0` at the vertex `v` furthest
/// from the axis, its angle about z held at that of `x`. It is transverse to the orbit at
/// `x` and, as the energy is invariant, puts no force on the rod (its multiplier is zero at
/// a solution: the orbit's direction is admissible and does no work), so it removes the
/// orbit's neutral direction and nothing else — the phase condition of AUTO and
/// BifurcationKit for relative equilibria, on two unknowns to keep the KKT matrix sparse.
/// `None` when every vertex of `x` is on the axis (the orbit is a point).
pub fn axis_phase(model: &DiscreteModel, x: &[f64]) -> Option<LinearConstraint> {
    let mut furthest = None;
    let mut reach = 1e-9 * model.length();
    for (id, rod) in model.rods.iter().enumerate() {
        for v in 0..=rod.mesh.elements() {
            let r = model.vertex(x, id, v);
            let rho = r[0].hypot(r[1]);
            if rho > reach {
                reach = rho;
                furthest = Some((rod.r_dof(v, 0), rod.r_dof(v, 1), r));
            }
        }
    }
    let (dx, dy, r) = furthest?;
    // e_z × r = (−y, x, 0)
    normalised_phase(vec![(dx, -r[1]), (dy, r[0])], 0.0)
}

/// The phase condition that holds, at its value in the state `at`, the component of the
/// state along the part of `direction` that the mirror `mirror` reverses, on a few
/// unknowns: `c·x = c·x_at` with `c = (d_S − σ d_S)/2`, `d_S` the largest entries of
/// `direction`'s primal unknowns. Every state the mirror keeps (`σx = x`) satisfies it,
/// with no force (its multiplier zero), so on a branch of such states it removes the
/// nearly neutral direction along `direction` (the mirror's reversed direction in the
/// plane of a double point's modes, in which the branch would turn) and nothing else.
/// `None` for a direction the mirror does not reverse at all.
pub fn mirror_phase(
    model: &DiscreteModel,
    mirror: &Mirror,
    direction: &[f64],
    at: &[f64],
) -> Option<LinearConstraint> {
    const ENTRIES: usize = 6;
    let np = model.n_primal;
    let mut largest: Vec<usize> = (0..np).collect();
    largest.sort_by(|&i, &j| direction[j].abs().total_cmp(&direction[i].abs()));
    let mut d = vec![0.0; np];
    for &i in largest.iter().take(ENTRIES) {
        d[i] = direction[i];
    }
    let image = mirror.apply(model, &d);
    let terms: Vec<(usize, f64)> = d
        .iter()
        .zip(&image)
        .enumerate()
        .map(|(i, (a, b))| (i, 0.5 * (a - b)))
        .collect();
    // what the mirror keeps of the largest entries cancels to rounding
    let largest = terms.iter().fold(0.0f64, |m, t| m.max(t.1.abs()));
    let terms: Vec<(usize, f64)> = terms
        .into_iter()
        .filter(|t| t.1.abs() > 1e-12 * largest)
        .collect();
    let value = terms.iter().map(|&(i, c)| c * at[i]).sum();
    normalised_phase(terms, value)
}

/// `Σ terms = value` scaled to unit coefficients; `None` when every coefficient is zero.
fn normalised_phase(mut terms: Vec<(usize, f64)>, value: f64) -> Option<LinearConstraint> {
    terms.retain(|t| t.1 != 0.0);
    let norm = terms.iter().map(|t| t.1 * t.1).sum::<f64>().sqrt();
    if terms.is_empty() || !norm.is_finite() {
        return None;
    }
    for t in &mut terms {
        t.1 /= norm;
    }
    Some(LinearConstraint {
        terms,
        value: value / norm,
        role: Role::Phase,
        moving: None,
    })
}
