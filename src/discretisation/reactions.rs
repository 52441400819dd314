//! The reactions of the supports read off the multipliers of their constraints.

use super::constraints::Role;
use super::discrete_model::{DiscreteModel, End};
use super::system::System;
use crate::model::assembly::RodId;
use crate::model::quaternion::{self, Quat};
use nalgebra::{Vector3, Vector4};

impl System {
    /// Force (N) and moment (N m) that the support (and, under load control, the dead
    /// load at the tip) applies to rod `rod` at `end`, in the global frame, from the
    /// multipliers of its support constraints: the generalised
    /// reaction is `−ν ∂g/∂x`, and a virtual rotation `δθ` moves `q` by `½ (δθ, 0) ∘ q`.
    pub fn reaction(
        &self,
        model: &DiscreteModel,
        x: &[f64],
        rod: RodId,
        end: End,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let r = &model.rods[rod];
        let node = r.end_node(end);
        let vertex = r.end_vertex(end);
        let mut force = Vector3::zeros();
        let mut fq = Vector4::zeros();
        for (i, c) in self.linear.iter().enumerate() {
            let held = match c.role {
                Role::Support { rod: rr, end: ee } => rr == rod && ee == end,
                Role::TipHeight { rod: rr } => rr == rod && end == End::Tip,
                Role::Joint(_) | Role::Phase => false,
            };
            if !held {
                continue;
            }
            let nu = x[self.linear_row(i)];
            for &(d, a) in &c.terms {
                for k in 0..3 {
                    if d == r.r_dof(vertex, k) {
                        force[k] -= nu * a;
                    }
                }
                for k in 0..4 {
                    if d == r.q_dof(node, k) {
                        fq[k] -= nu * a;
                    }
                }
            }
        }
        if let (Some(f), End::Tip) = (self.tip_force_z(), end) {
            // under a dead axial load the tip is loaded by the dead load itself
            force[2] += f;
        }
        let q = model.quaternion(x, rod, node);
        let moment = Vector3::from_fn(|i, _| {
            let mut e = Quat::zeros();
            e[i] = 1.0;
            0.5 * fq.dot(&quaternion::mul(&e, &q))
        });
        (force, moment)
    }
}
