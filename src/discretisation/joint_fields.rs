//! What the joints of a rod carry in a state (docs/theory.md §2): the relative rotation of
//! the two rods, the joint's moment on the rod, and the rod's internal moments on either side
//! of the crossing, read off the discrete balance of the crossing's quaternion node.

use super::discrete_model::DiscreteModel;
use super::element;
use super::joint_rotation::JointRotation;
use super::system::System;
use crate::model::assembly::RodId;
use crate::model::quaternion::{self, Quat};
use crate::results::JointState;
use nalgebra::Vector3;

/// The moment (N m) of a generalised force `f` on a nodal quaternion `q`: a virtual
/// rotation `δθ` moves `q` by `½ (δθ, 0) ∘ q`, so `m_i = ½ f · (e_i ∘ q)`.
fn moment_of(f: &[f64], q: &Quat) -> Vector3<f64> {
    Vector3::from_fn(|i, _| {
        let mut e = Quat::zeros();
        e[i] = 1.0;
        let d = quaternion::mul(&e, q);
        0.5 * (0..4).map(|k| f[k] * d[k]).sum::<f64>()
    })
}

/// The state of the joints of rod `id` at the arc lengths `joints` (m), in the state `x`.
pub fn joint_states(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    id: RodId,
    joints: &[f64],
) -> Vec<JointState> {
    let rod = &model.rods[id];
    let natural = if joints.is_empty() {
        Vec::new()
    } else {
        model.natural_state()
    };
    let tol = 1e-9 * model.length();
    joints
        .iter()
        .map(|&s| {
            let found = model
                .assembly
                .joints
                .iter()
                .enumerate()
                .find(|(_, j)| (j.right == id || j.left == id) && (j.s - s).abs() <= tol);
            let mut state = JointState {
                s,
                ..JointState::default()
            };
            let Some((index, joint)) = found else {
                return state;
            };
            if let Some(measure) = JointRotation::measure(model, &natural, index, joint) {
                state.rotation = measure.rotation(x).into();
            }
            if let Some(k) = model.slide_of(index) {
                let side = usize::from(joint.right != id);
                state.slip = x[model.slide_dof(k, side)] - joint.s;
            }
            let held = system.rotations.iter().position(|r| r.joint == index);
            if let Some(i) = held {
                let (right, left) =
                    system.rotations[i].moments(x, system.rotation_multipliers(x, i));
                state.moment = if joint.right == id { right } else { left }.into();
            }
            if let Some(v) = rod.mesh.vertex_at(s) {
                let (before, after) = rod_moments(model, system, x, id, v);
                state.moment_before = before.into();
                state.moment_after = after.into();
            }
            state
        })
        .collect()
}

/// The internal moments of rod `id` just before and just after vertex `v`: the moments of
/// the generalised forces of the elements on either side on the vertex's quaternion node
/// (elastic energy, inextensibility and loads along the rod), `m(s⁻) = M(R_before)` and
/// `m(s⁺) = −M(R_after)`.
fn rod_moments(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    id: RodId,
    v: usize,
) -> (Vector3<f64>, Vector3<f64>) {
    let rod = &model.rods[id];
    let p = model.order.degree();
    let node = v * p;
    let q = model.quaternion(x, id, node);
    let load = system.element_load();
    let force_on = |e: usize, a: usize| {
        let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
        let qe = model.element_quaternions(x, rod, e);
        let n = system.internal_force(x, id, e);
        let t = element::element_terms(
            model.order,
            &model.rule,
            h,
            &qe,
            &model.stiffness,
            &model.elasticity,
            rod.element_reference(e, model.rule.len()),
            &[n[0], n[1], n[2]],
            &load,
            false,
        );
        let f: [f64; 4] = std::array::from_fn(|k| {
            let i = 4 * a + k;
            t.energy_gradient[i] - (0..3).map(|j| n[j] * t.chord_gradient[j][i]).sum::<f64>()
                + t.load_gradient[i]
        });
        moment_of(&f, &q)
    };
    let before = if v > 0 {
        force_on(v - 1, p)
    } else {
        Vector3::zeros()
    };
    let after = if v < rod.mesh.elements() {
        -force_on(v, 0)
    } else {
        Vector3::zeros()
    };
    (before, after)
}
