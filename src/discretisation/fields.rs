//! What a discrete state says, as [`crate::results`] reports it: the reactions at the rod
//! ends (read off the support multipliers) and the shape of every rod (positions, rotations
//! and curvatures at the quaternion nodes), for the full assembly when the model is a
//! symmetric pair; and the curvature of a reported shape anywhere along a rod.

use super::element;
use super::model::{DiscreteModel, End};
use super::shape::{self, GAUSS_3, MAX_NODES};
use super::system::System;
use crate::model::quaternion;
use crate::model::symmetry::TurnZ;
use crate::results::{NodeState, Reaction, RodReaction, RodShape, Snapshot};
use nalgebra::Vector3;

/// Reactions of every rod at state `x` (of every rod of the full assembly when the model
/// is a symmetric pair: the others are its images).
pub fn reactions(model: &DiscreteModel, system: &System, x: &[f64]) -> Vec<RodReaction> {
    let own = own_reactions(model, system, x);
    let Some(sym) = model.assembly.symmetry else {
        return own;
    };
    (0..sym.full_rods())
        .map(|k| {
            let (src, angle) = sym.image(k);
            let r = &own[src];
            let turn = TurnZ::new(angle);
            let t = |re: Reaction| Reaction {
                force: turn.apply(re.force),
                moment: turn.apply(re.moment),
            };
            RodReaction {
                rod: k,
                chirality: r.chirality,
                tip: t(r.tip),
                base: t(r.base),
            }
        })
        .collect()
}

fn own_reactions(model: &DiscreteModel, system: &System, x: &[f64]) -> Vec<RodReaction> {
    (0..model.rods.len())
        .map(|id| {
            let r = |end| {
                let (f, m) = system.reaction(model, x, id, end);
                Reaction {
                    force: f.into(),
                    moment: m.into(),
                }
            };
            RodReaction {
                rod: id,
                chirality: model.rods[id].helix.chirality,
                tip: r(End::Tip),
                base: r(End::Base),
            }
        })
        .collect()
}

/// `(1/(n Pcrit)) Σ F_tip`.
pub fn normalised_load(model: &DiscreteModel, reactions: &[RodReaction]) -> [f64; 3] {
    let scale = 1.0 / (reactions.len() as f64 * model.stiffness.euler_load(model.length()));
    let mut f = [0.0; 3];
    for r in reactions {
        for k in 0..3 {
            f[k] += r.tip.force[k] * scale;
        }
    }
    f
}

/// Shapes of all rods at state `x` (of the full assembly when the model is a symmetric
/// pair: the other rods are its images turned about z).
pub fn snapshot(model: &DiscreteModel, system: &System, x: &[f64], eps: f64) -> Snapshot {
    let own = own_snapshot(model, system, x, eps);
    let Some(sym) = model.assembly.symmetry else {
        return own;
    };
    let rods = (0..sym.full_rods())
        .map(|k| {
            let (src, angle) = sym.image(k);
            let r = &own.rods[src];
            let turn = TurnZ::new(angle);
            RodShape {
                rod: k,
                chirality: r.chirality,
                joints: r.joints.clone(),
                nodes: r
                    .nodes
                    .iter()
                    .map(|n| NodeState {
                        position: turn.apply(n.position),
                        quaternion: turn.rotate(&n.quaternion.into()).into(),
                        ..*n
                    })
                    .collect(),
            }
        })
        .collect();
    Snapshot { eps, rods }
}

fn own_snapshot(model: &DiscreteModel, system: &System, x: &[f64], eps: f64) -> Snapshot {
    let p = model.order.degree();
    let length = model.length();
    let rods = model
        .rods
        .iter()
        .enumerate()
        .map(|(id, rod)| {
            let nq = rod.mesh.quaternion_nodes();
            let mut curv = vec![Vector3::zeros(); nq];
            let mut count = vec![0usize; nq];
            let mut pos = vec![Vector3::zeros(); nq];
            for e in 0..rod.mesh.elements() {
                let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                let q = model.element_quaternions(x, rod, e);
                let ra = model.vertex(x, id, e);
                for a in 0..=p {
                    let xi = a as f64 / p as f64;
                    let (qv, dq) = shape::interpolate(model.order, &q, xi, h);
                    curv[e * p + a] += element::curvature(&qv, &dq);
                    count[e * p + a] += 1;
                    pos[e * p + a] = if a == 0 {
                        ra
                    } else if a == p {
                        model.vertex(x, id, e + 1)
                    } else {
                        ra + chord(model, &q, xi, h)
                    };
                }
            }
            let nodes = (0..nq)
                .map(|k| {
                    let s = rod.mesh.node_arc_length(k);
                    let qk = model.quaternion(x, id, k);
                    let qk = qk / qk.norm();
                    let c = curv[k] / count[k] as f64;
                    NodeState {
                        s,
                        s_over_l: s / length,
                        position: pos[k].into(),
                        quaternion: qk.into(),
                        curvature: c.into(),
                    }
                })
                .collect();
            let joints = if system.bc.joints {
                model.assembly.joint_arc_lengths(id)
            } else {
                vec![]
            };
            RodShape {
                rod: id,
                chirality: rod.helix.chirality,
                nodes,
                joints,
            }
        })
        .collect();
    Snapshot { eps, rods }
}

/// `∫_0^{ξ h} d3 ds` along an element, 3-point Gauss.
fn chord(model: &DiscreteModel, q: &[[f64; 4]; MAX_NODES], xi: f64, h: f64) -> Vector3<f64> {
    let mut out = Vector3::zeros();
    for (t, w) in GAUSS_3 {
        let x = 0.5 * (t + 1.0) * xi;
        let (qv, _) = shape::interpolate(model.order, q, x, h);
        let r = quaternion::rotation(&qv.into());
        out += r.column(2) * (0.5 * w * xi * h);
    }
    out
}

/// Curvature `(κ1, κ2, Ω)` (1/m) of a rod of `model` at arc length `s` (m), from the nodal
/// quaternions of its reported shape: at an element vertex the mean of the limits from the
/// elements that meet there (as [`snapshot`] reports it), elsewhere the element's
/// interpolation. The curvatures are body components, so an image of a rod turned about z
/// has its source's, on its source's mesh.
pub fn curvature_at(model: &DiscreteModel, shape: &RodShape, s: f64) -> [f64; 3] {
    let mesh = &model.rods[model.source_rod(shape.rod)].mesh;
    let v = &mesh.vertices;
    let ne = mesh.elements();
    // the limit at `xi` in [0, 1] of element `e`
    let limit = |e: usize, xi: f64| {
        let q = model.element_nodes(e, |k| shape.nodes[k].quaternion);
        let (qv, dq) = shape::interpolate(model.order, &q, xi, v[e + 1] - v[e]);
        element::curvature(&qv, &dq)
    };
    if let Some(k) = mesh.vertex_at(s) {
        let mut sum = Vector3::zeros();
        let mut count = 0.0;
        if k > 0 {
            sum += limit(k - 1, 1.0);
            count += 1.0;
        }
        if k < ne {
            sum += limit(k, 0.0);
            count += 1.0;
        }
        return (sum / count).into();
    }
    let tol = 1e-9 * v[ne];
    let s = s.clamp(0.0, v[ne]);
    let e = v.partition_point(|&x| x <= s + tol).clamp(1, ne) - 1;
    let xi = ((s - v[e]) / (v[e + 1] - v[e])).clamp(0.0, 1.0);
    limit(e, xi).into()
}
