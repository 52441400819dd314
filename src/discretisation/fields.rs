//! What a discrete state says, as [`crate::results`] reports it: the reactions at the rod
//! ends (read off the support multipliers) and the shape of every rod (positions, rotations
//! and curvatures at the quaternion nodes), for the full assembly when the model is a
//! symmetric pair; and the curvature of a reported shape anywhere along a rod.

use super::discrete_model::{DiscreteModel, End};
use super::element;
use super::joint_fields;
use super::pressure;
use super::shape::{self, Order, GAUSS_3, MAX_NODES};
use super::support::{arc_chord, Moving, SupportPose};
use super::system::System;
use crate::model::assembly::RodId;
use crate::model::loading::{AxisLoad, SupportAxis};
use crate::model::quaternion;
use crate::model::symmetry::TurnZ;
use crate::results::{
    JointState, ModeShape, NodeState, Reaction, RodReaction, RodShape, Snapshot, SupportResponse,
};
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

/// The tube's answer to its twist, tilt and pressure at state `x` under `system`'s loads:
/// the support's angles and the pressure at the system's load parameter, the torque and
/// bending moment from the tip reactions `reactions` (of the whole assembly) about the
/// tip's centre `(0, 0, height)` (m), the mean radius by the pressure's own rule. For the
/// cell of an infinite tube the twist is its twist per cell and the torque the whole
/// tube's, `m` times its rods' share.
pub fn support_response(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    reactions: &[RodReaction],
    height: f64,
) -> SupportResponse {
    let loads = system.loads();
    let lambda = system.parameter();
    let angle = |axis| match loads.tip().axis(axis) {
        AxisLoad::Motion(r) => r.at(lambda),
        AxisLoad::Force(_) => 0.0,
    };
    let tips = tip_positions(model, x);
    let (mut torque, mut bending) = (0.0, 0.0);
    for (r, p) in reactions.iter().zip(&tips) {
        let arm = Vector3::new(p[0], p[1], p[2] - height);
        let about = Vector3::from(r.tip.moment) + arm.cross(&Vector3::from(r.tip.force));
        torque += about[2];
        bending += about[0];
    }
    if model.assembly.cell.is_some() {
        bending = cell_bending_moment(model, system, x, reactions);
    }
    // a cell's rods are one of the m sectors of the tube's cross-section (a bending cell's
    // are all of them)
    let sectors = model.assembly.cell.as_ref().map_or(1.0, |c| c.sectors());
    torque *= sectors;
    let pressure = loads.pressure(lambda).0;
    let radius = pressure::mean_radius(model, x);
    let n = reactions.len() as f64;
    let area = 2.0 * std::f64::consts::PI * radius * height;
    SupportResponse {
        twist: angle(SupportAxis::RotZ),
        torque,
        tilt: angle(SupportAxis::RotX),
        bending_moment: bending,
        pressure,
        radius,
        lateral_pressure: if area > 0.0 {
            n * pressure * model.length() / area
        } else {
            0.0
        },
        unit_moment: model.stiffness.b1 / model.length(),
    }
}

/// The bending moment (N m) of a cell, the rate `∂Π/∂θ` of its energy with its tilt `θ`:
/// the far ends' reactions `f`, `m` work on the motion of the map `x ↦ R_s x + t(θ)` with
/// `θ`, a turn about x and the translation `∂t/∂θ` of the far section's centre `t`:
/// `e_x·Σ (m + (r − t) × f) + (∂t/∂θ)·Σ f` (docs/theory.md §8), and the lateral load
/// holding the rods on the bent axis on the motion of the axis's sections, `ν ∂g/∂θ` of
/// its row `g` ([`Moving::Axis`]).
fn cell_bending_moment(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    reactions: &[RodReaction],
) -> f64 {
    let (loads, lambda) = (system.loads(), system.parameter());
    let theta = match loads.tip().axis(SupportAxis::RotX) {
        AxisLoad::Motion(r) => r.at(lambda),
        AxisLoad::Force(_) => 0.0,
    };
    let h = SupportPose::of(loads, model.height0(), lambda).centre[2];
    let centre = system.pose(lambda).centre;
    let [_, _, df, dg, _, _] = arc_chord(theta);
    let rate = Vector3::new(0.0, -h * df, h * dg);
    let tips = tip_positions(model, x);
    let far: f64 = reactions
        .iter()
        .zip(&tips)
        .map(|(r, p)| {
            let f = Vector3::from(r.tip.force);
            let arm = Vector3::from(*p) - centre;
            (Vector3::from(r.tip.moment) + arm.cross(&f))[0] + rate.dot(&f)
        })
        .sum();
    let ex = Vector3::x();
    let sections: f64 = system
        .linear
        .iter()
        .enumerate()
        .filter_map(|(i, c)| match c.moving.as_ref()? {
            Moving::Axis { sections, .. } => {
                let nu = x[system.linear_row(i)];
                let dg: f64 = sections
                    .iter()
                    .enumerate()
                    .map(|(k, &(f, w))| {
                        let (s, co) = (f * theta).sin_cos();
                        let a = Vector3::new(0.0, co, s);
                        let [u, v, du, dv, _, _] = arc_chord(f * theta);
                        let t = Vector3::new(0.0, -u, v) * (f * h);
                        let dt = Vector3::new(0.0, -du, dv) * (f * f * h);
                        let da = ex.cross(&a) * f;
                        let r = Vector3::new(
                            x[c.terms[3 * k].0],
                            x[c.terms[3 * k + 1].0],
                            x[c.terms[3 * k + 2].0],
                        );
                        w * (da.dot(&(r - t)) - a.dot(&dt))
                    })
                    .sum();
                Some(nu * dg)
            }
            _ => None,
        })
        .sum();
    far + sections
}

/// The tip positions of every rod (of the full assembly for a symmetric pair), in the
/// order of [`reactions`].
fn tip_positions(model: &DiscreteModel, x: &[f64]) -> Vec<[f64; 3]> {
    let own: Vec<[f64; 3]> = model
        .rods
        .iter()
        .enumerate()
        .map(|(id, rod)| model.vertex(x, id, rod.end_vertex(End::Tip)).into())
        .collect();
    match model.assembly.symmetry {
        None => own,
        Some(sym) => (0..sym.full_rods())
            .map(|k| {
                let (src, angle) = sym.image(k);
                TurnZ::new(angle).apply(own[src])
            })
            .collect(),
    }
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
                joint_states: r
                    .joint_states
                    .iter()
                    .map(|j| JointState {
                        moment: turn.apply(j.moment),
                        moment_before: turn.apply(j.moment_before),
                        moment_after: turn.apply(j.moment_after),
                        ..*j
                    })
                    .collect(),
                nodes: r
                    .nodes
                    .iter()
                    .map(|n| NodeState {
                        position: turn.apply(n.position),
                        quaternion: turn.rotate(&n.quaternion.into()).into(),
                        internal_force: turn.apply(n.internal_force),
                        ..*n
                    })
                    .collect(),
            }
        })
        .collect();
    Snapshot {
        compression_ratio: eps,
        rods,
    }
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
            let mut pos = vec![Vector3::zeros(); nq];
            let mut force = vec![Vector3::zeros(); nq];
            let mut count = vec![0.0; nq];
            for e in 0..rod.mesh.elements() {
                let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                let q = model.element_quaternions(x, rod, e);
                let ra = model.vertex(x, id, e);
                let n = system.internal_force(x, id, e);
                for a in 0..=p {
                    let xi = a as f64 / p as f64;
                    force[e * p + a] += n;
                    count[e * p + a] += 1.0;
                    pos[e * p + a] = if a == 0 {
                        ra
                    } else if a == p {
                        model.vertex(x, id, e + 1)
                    } else {
                        ra + chord(model, &q, xi, h)
                    };
                }
            }
            let joints = if system.bc.joints.active() {
                model.assembly.joint_arc_lengths(id)
            } else {
                vec![]
            };
            let curvature = recovered_curvature(model, id, &joints, |k| {
                std::array::from_fn(|c| x[rod.q_dof(k, c)])
            });
            let nodes = (0..nq)
                .map(|k| {
                    let s = rod.mesh.node_arc_length(k);
                    let qk = model.quaternion(x, id, k);
                    let qk = qk / qk.norm();
                    NodeState {
                        s,
                        s_over_l: s / length,
                        position: pos[k].into(),
                        quaternion: qk.into(),
                        curvature: curvature[k],
                        internal_force: (force[k] / count[k]).into(),
                    }
                })
                .collect();
            RodShape {
                rod: id,
                chirality: rod.helix.chirality,
                nodes,
                joint_states: joint_fields::joint_states(model, system, x, id, &joints),
                joints,
            }
        })
        .collect();
    Snapshot {
        compression_ratio: eps,
        rods,
    }
}

// ---------------------------------------------------------------- curvature

/// Where the curvature of an element converges fastest, `ξ ∈ [0, 1]`: the `p` Gauss–Legendre
/// points of an element of degree `p` (the Barlow points), the zeros of the derivative of
/// the interpolation error's leading term.
///
/// The error of a degree-`p` interpolant (and, in 1-D, of the finite-element solution) is
/// led by `f^{(p+1)} h^{p+1} ω(ξ)/(p+1)!` with `ω(ξ) = Π (ξ − ξ_a)` over the element's nodes;
/// its slope `ω'(ξ)` vanishes at the Gauss–Legendre points of `p` points (quadratic: `ω' =
/// 3ξ² − 3ξ + ½`, zeros `½ ∓ 1/(2√3)`; linear: the midpoint), so there `q'`, and with it the
/// curvature `2 Im(q̄ q')/|q|²`, is off by `O(h^{p+1})` instead of `O(h^p)`.
pub fn barlow_points(order: Order) -> &'static [f64] {
    const LINEAR: [f64; 1] = [0.5];
    // ½ ∓ 1/(2√3)
    const QUADRATIC: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];
    match order {
        Order::Linear => &LINEAR,
        Order::Quadratic => &QUADRATIC,
    }
}

/// A curvature sample at a Barlow point of an element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvatureSample {
    /// Element of the rod's mesh.
    pub element: usize,
    /// Arc length (m).
    pub s: f64,
    /// `(κ1, κ2, Ω)` (1/m).
    pub curvature: [f64; 3],
}

/// The curvature `(κ1, κ2, Ω)` of rod `rod` of `model` at the Barlow points
/// ([`barlow_points`]) of every element, element by element, from its nodal quaternions
/// (`node(k)` for quaternion node `k`).
pub fn gauss_curvatures(
    model: &DiscreteModel,
    rod: RodId,
    node: impl Fn(usize) -> [f64; 4],
) -> Vec<CurvatureSample> {
    let mesh = &model.rods[rod].mesh;
    let v = &mesh.vertices;
    let mut out = Vec::with_capacity(mesh.elements() * model.order.degree());
    for e in 0..mesh.elements() {
        let h = v[e + 1] - v[e];
        let q = model.element_nodes(e, &node);
        for &xi in barlow_points(model.order) {
            let (qv, dq) = shape::interpolate(model.order, &q, xi, h);
            out.push(CurvatureSample {
                element: e,
                s: v[e] + xi * h,
                curvature: element::curvature(&qv, &dq).into(),
            });
        }
    }
    out
}

/// The curvature at every quaternion node of a rod, recovered from its Barlow-point samples
/// by a local least-squares fit (superconvergent patch recovery, Zienkiewicz & Zhu 1992):
/// at each node a polynomial is fitted to the samples of a patch of elements around it and
/// evaluated there. The polynomial has degree `p + 1` (as many coefficients as a patch of two
/// elements has samples, fewer where a patch has fewer): the samples are accurate to
/// `O(h^{p+1})`, and a fit of degree `p` would add a bias `O(h^{p+1})` of its own that in the
/// boundary layers at the clamps is the larger error (at the thesis n = 8 mesh it is 4 times
/// the error of the degree-`p + 1` fit at the rod ends).
///
/// The patches never straddle a joint in `joints` (m) or a rod end: a pin joint passes a
/// force, so the curvature is continuous there but its slope jumps (`m' = −d3 × n`), and a
/// fit across the kink would lose the order. A node on a joint gets the mean of the fits
/// from either side.
///
/// Patches: the two elements that meet at a vertex inside a stretch between joints; the
/// element of a mid-node with its neighbours in the stretch (three elements, or as many as
/// the stretch has); at a joint or a rod end the two elements of the stretch nearest to it.
/// A stretch of a single element is fitted through its own samples only.
pub fn recovered_curvature(
    model: &DiscreteModel,
    rod: RodId,
    joints: &[f64],
    node: impl Fn(usize) -> [f64; 4],
) -> Vec<[f64; 3]> {
    let samples = gauss_curvatures(model, rod, node);
    let mesh = &model.rods[rod].mesh;
    let ne = mesh.elements();
    let p = model.order.degree();
    let per = barlow_points(model.order).len();
    // stretch boundaries, as vertex indices
    let mut breaks: Vec<usize> = vec![0, ne];
    breaks.extend(joints.iter().filter_map(|&s| mesh.vertex_at(s)));
    breaks.sort_unstable();
    breaks.dedup();
    // the stretch [first, last] (elements) holding element e
    let stretch = |e: usize| {
        let i = breaks.partition_point(|&b| b <= e);
        (breaks[i - 1], breaks[i] - 1)
    };
    let fit = |elements: std::ops::RangeInclusive<usize>, at: f64| -> [f64; 3] {
        let pts: Vec<&CurvatureSample> = elements
            .flat_map(|e| &samples[e * per..(e + 1) * per])
            .collect();
        least_squares_value(&pts, (p + 1).min(pts.len() - 1), at)
    };
    (0..mesh.quaternion_nodes())
        .map(|k| {
            let s = mesh.node_arc_length(k);
            let (e, a) = (k / p, k % p);
            if a != 0 {
                // a mid-node of element e: its neighbours in the stretch
                let (lo, hi) = stretch(e);
                let want = 3.min(hi - lo + 1);
                let mut first = e.saturating_sub(1).max(lo);
                let last = (first + want - 1).min(hi);
                first = first.min(last + 1 - want);
                return fit(first..=last, s);
            }
            // vertex e
            if breaks.binary_search(&e).is_err() {
                return fit(e - 1..=e, s);
            }
            let mut sum = [0.0; 3];
            let mut sides = 0.0;
            if e > 0 {
                let (lo, _) = stretch(e - 1);
                let v = fit((e - 1).saturating_sub(1).max(lo)..=e - 1, s);
                (0..3).for_each(|c| sum[c] += v[c]);
                sides += 1.0;
            }
            if e < ne {
                let (_, hi) = stretch(e);
                let v = fit(e..=(e + 1).min(hi), s);
                (0..3).for_each(|c| sum[c] += v[c]);
                sides += 1.0;
            }
            sum.map(|v| v / sides)
        })
        .collect()
}

/// Value at `at` of the least-squares polynomial of degree `degree` (≤ 3) through the
/// samples `pts`, in the local coordinate `t = (s − at)/spread` (so the value is the
/// constant coefficient and the normal equations stay well conditioned).
fn least_squares_value(pts: &[&CurvatureSample], degree: usize, at: f64) -> [f64; 3] {
    let spread = pts
        .iter()
        .map(|p| (p.s - at).abs())
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let m = degree + 1;
    let mut a = nalgebra::DMatrix::<f64>::zeros(m, m);
    let mut b = nalgebra::DMatrix::<f64>::zeros(m, 3);
    for pt in pts {
        let t = (pt.s - at) / spread;
        let basis: Vec<f64> = (0..m).map(|i| t.powi(i as i32)).collect();
        for i in 0..m {
            for j in 0..m {
                a[(i, j)] += basis[i] * basis[j];
            }
            for c in 0..3 {
                b[(i, c)] += basis[i] * pt.curvature[c];
            }
        }
    }
    match a.clone().cholesky() {
        Some(ch) => {
            let x = ch.solve(&b);
            [x[(0, 0)], x[(0, 1)], x[(0, 2)]]
        }
        // samples at coincident points (cannot happen on a mesh): their mean
        None => {
            let n = pts.len().max(1) as f64;
            std::array::from_fn(|c| pts.iter().map(|p| p.curvature[c]).sum::<f64>() / n)
        }
    }
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

/// Curvature `(κ1, κ2, Ω)` (1/m) of a rod of `model` at arc length `s` (m): the recovered
/// nodal curvatures of its reported shape ([`recovered_curvature`]) interpolated with the
/// element's shape functions, so that at a node it is the node's value. The curvatures are
/// body components, so an image of a rod turned about z has its source's, on its source's
/// mesh.
pub fn curvature_at(model: &DiscreteModel, shape: &RodShape, s: f64) -> [f64; 3] {
    let mesh = &model.rods[model.source_rod(shape.rod)].mesh;
    let v = &mesh.vertices;
    let ne = mesh.elements();
    let p = model.order.degree();
    let tol = 1e-9 * v[ne];
    let s = s.clamp(0.0, v[ne]);
    let e = v.partition_point(|&x| x <= s + tol).clamp(1, ne) - 1;
    let xi = ((s - v[e]) / (v[e + 1] - v[e])).clamp(0.0, 1.0);
    let (n, _) = shape::shape(model.order, xi);
    let mut out = [0.0; 3];
    for a in 0..=p {
        let k = shape.nodes[e * p + a].curvature;
        for c in 0..3 {
            out[c] += n[a] * k[c];
        }
    }
    out
}

/// A critical mode on the geometry of its state: the shape of the model's own rods at state
/// `x` (no images of a symmetric pair: the mode's unknowns are the model's), and the
/// centreline displacement of the mode `mode` (all unknowns) at every quaternion node
/// (m per unit mode): the vertex positions' own components at the vertices, and between
/// them the linearised chord, `δr(ξ) = δr_start + ∫_0^{ξh} (∂d3/∂q) δq ds`.
pub fn mode_shape(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    eps: f64,
    mode: &[f64],
) -> ModeShape {
    let shape = own_snapshot(model, system, x, eps);
    let p = model.order.degree();
    let displacement = model
        .rods
        .iter()
        .map(|rod| {
            let mut out = vec![[0.0; 3]; rod.mesh.quaternion_nodes()];
            for e in 0..rod.mesh.elements() {
                let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                let q = model.element_quaternions(x, rod, e);
                let dq = model.element_quaternions(mode, rod, e);
                let start = Vector3::from_fn(|k, _| mode[rod.r_dof(e, k)]);
                for a in 0..=p {
                    let d = if a == 0 {
                        start
                    } else if a == p {
                        Vector3::from_fn(|k, _| mode[rod.r_dof(e + 1, k)])
                    } else {
                        start + chord_variation(model, &q, &dq, a as f64 / p as f64, h)
                    };
                    out[e * p + a] = d.into();
                }
            }
            out
        })
        .collect();
    ModeShape {
        shape,
        displacement,
    }
}

/// `∫_0^{ξ h} (∂d3/∂q) δq ds` along an element, 3-point Gauss: the first variation of
/// [`chord`] in the direction of the nodal quaternions `dq`.
fn chord_variation(
    model: &DiscreteModel,
    q: &[[f64; 4]; MAX_NODES],
    dq: &[[f64; 4]; MAX_NODES],
    xi: f64,
    h: f64,
) -> Vector3<f64> {
    let mut out = Vector3::zeros();
    for (t, w) in GAUSS_3 {
        let x = 0.5 * (t + 1.0) * xi;
        let (qv, _) = shape::interpolate(model.order, q, x, h);
        let (dv, _) = shape::interpolate(model.order, dq, x, h);
        let (_, g, _) = element::tangent(&qv);
        for j in 0..3 {
            let v: f64 = (0..4).map(|k| g[j][k] * dv[k]).sum();
            out[j] += v * 0.5 * w * xi * h;
        }
    }
    out
}
