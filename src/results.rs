//! What a solve reports: load points along the path and the shape of a state.

use crate::discretisation::element::{self, MAX_NODES};
use crate::discretisation::system::{DiscreteModel, End, System};
use crate::model::assembly::RodId;
use crate::model::helix::Chirality;
use crate::model::quaternion;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Force (N) and moment (N m) applied by a support to a rod end, global frame.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Reaction {
    pub force: [f64; 3],
    pub moment: [f64; 3],
}

/// The reactions on one rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodReaction {
    pub rod: RodId,
    pub chirality: Chirality,
    pub tip: Reaction,
    pub base: Reaction,
}

/// One converged point of the load path.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadPoint {
    /// Output step number (0 for the natural state).
    pub step: usize,
    /// Compression ratio `ε = (h0 − h)/h0` (negative in extension), from the mean tip height.
    pub eps: f64,
    /// Load parameter: `ε` under displacement control, `P/Pcrit` under load control.
    pub parameter: f64,
    /// Tip height `h` (m).
    pub height: f64,
    pub reactions: Vec<RodReaction>,
    /// `(1/(n Pcrit)) Σ_rods F_tip` per component (negative z = compression).
    pub load: [f64; 3],
    /// Total elastic energy (J).
    pub energy: f64,
    /// Newton iterations of the last solve that reached this point.
    pub iterations: usize,
    /// `‖R‖∞` at this point.
    pub residual: f64,
    /// Stability of the state, when tracked.
    pub stability: Option<crate::solver::continuation::Stability>,
}

/// One quaternion node of a rod in a state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeState {
    /// Arc length `s` (m).
    pub s: f64,
    /// `s / L`.
    pub s_over_l: f64,
    /// Centreline position (m).
    pub position: [f64; 3],
    /// Unit quaternion `(q1, q2, q3, q4)`.
    pub quaternion: [f64; 4],
    /// `(κ1, κ2, Ω)` (1/m); at element vertices the mean of the two adjacent elements.
    pub curvature: [f64; 3],
}

/// The shape of one rod.
#[derive(Clone, Debug, PartialEq)]
pub struct RodShape {
    pub rod: RodId,
    pub chirality: Chirality,
    pub nodes: Vec<NodeState>,
    /// Arc lengths of its active joints (m).
    pub joints: Vec<f64>,
}

/// The shape of every rod in a state.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub eps: f64,
    pub rods: Vec<RodShape>,
}

/// Euler load of a clamped–clamped rod of length `L`: `Pcrit = B1 (2π/L)²` (N).
pub fn euler_load(b1: f64, length: f64) -> f64 {
    b1 * (2.0 * PI / length).powi(2)
}

/// Rotation about z by `angle` (rad) of a vector.
fn turn(v: [f64; 3], angle: f64) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

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
            let t = |re: Reaction| Reaction {
                force: turn(re.force, angle),
                moment: turn(re.moment, angle),
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
    let scale = 1.0 / (reactions.len() as f64 * euler_load(model.stiffness.b1, model.length()));
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
            let qz = quaternion::about_z(angle);
            RodShape {
                rod: k,
                chirality: r.chirality,
                joints: r.joints.clone(),
                nodes: r
                    .nodes
                    .iter()
                    .map(|n| NodeState {
                        position: turn(n.position, angle),
                        quaternion: quaternion::mul(&qz, &n.quaternion.into()).into(),
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
                let mut q = [[0.0; 4]; MAX_NODES];
                for (a, qa) in q.iter_mut().enumerate().take(p + 1) {
                    for (k, v) in qa.iter_mut().enumerate() {
                        *v = x[rod.q_dof(e * p + a, k)];
                    }
                }
                let ra = model.vertex(x, id, e);
                for a in 0..=p {
                    let xi = a as f64 / p as f64;
                    let (qv, dq) = interpolate(model, &q, xi, h);
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

fn interpolate(
    model: &DiscreteModel,
    q: &[[f64; 4]; MAX_NODES],
    xi: f64,
    h: f64,
) -> ([f64; 4], [f64; 4]) {
    let (n, dn) = element::shape(model.order, xi);
    let mut qv = [0.0; 4];
    let mut dq = [0.0; 4];
    for a in 0..model.order.nodes() {
        for k in 0..4 {
            qv[k] += n[a] * q[a][k];
            dq[k] += dn[a] / h * q[a][k];
        }
    }
    (qv, dq)
}

/// `∫_0^{ξ h} d3 ds` along an element, 3-point Gauss.
fn chord(model: &DiscreteModel, q: &[[f64; 4]; MAX_NODES], xi: f64, h: f64) -> Vector3<f64> {
    let g = [
        (-0.774_596_669_241_483_4, 5.0 / 9.0),
        (0.0, 8.0 / 9.0),
        (0.774_596_669_241_483_4, 5.0 / 9.0),
    ];
    let mut out = Vector3::zeros();
    for (t, w) in g {
        let x = 0.5 * (t + 1.0) * xi;
        let (qv, _) = interpolate(model, q, x, h);
        let r = quaternion::rotation(&qv.into());
        out += r.column(2) * (0.5 * w * xi * h);
    }
    out
}
