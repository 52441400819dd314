//! The bulk of a rod (thesis §4, docs/theory.md §7): the longest stretch of arc length where its
//! curvatures stay within a tolerance of one uniform helix, the helix fitted there, and
//! Love's closed-form axial force and couple for it (docs/theory.md §6) beside the rod's
//! reactions; and the infinitely long tube's force beside the finite assembly's.
//!
//! The curvatures read are those of a reported shape: the nodal values recovered from the
//! Barlow points ([`super::fields::recovered_curvature`]), accurate to `O(h^{p+1})`.

use super::discrete_model::DiscreteModel;
use crate::model::elasticity::Elasticity;
use crate::model::helix::Helix;
use crate::model::love::{axial_wrench, LoveHelix};
use crate::model::pantograph::pantograph_radius;
use crate::model::stiffness::Stiffness;
use crate::results::{LoadPoint, RodBulk, RodReaction, RodShape, Snapshot, StepBulk};
use nalgebra::Vector3;
use std::collections::VecDeque;

/// The bulk tolerance: every curvature component stays within this fraction of the natural
/// helix's curvature magnitude `1/c0` of one constant value. 1 % keeps the boundary layers'
/// decaying oscillations out (they start at tens of per cent near a clamp) and lets in the
/// small ripple the joints leave in the bulk of an assembly.
pub const BULK_TOLERANCE: f64 = 0.01;

/// Compressions `|ε|` below this are the natural state for the tube comparison: the forces
/// of both the finite and the infinite tube vanish there and their ratio is noise.
const EPS_FLOOR: f64 = 1e-9;

/// The absolute tolerance (1/m) for a rod: [`BULK_TOLERANCE`] times its natural curvature
/// magnitude, or, for a naturally straight rod, times the largest curvature magnitude
/// of its shape (and a bare `BULK_TOLERANCE` 1/m for a rod straight in the state too).
pub fn tolerance(natural: &Helix, shape: &RodShape) -> f64 {
    let scale = natural.natural_curvature().norm();
    let scale = if scale > 0.0 && !natural.is_straight() {
        scale
    } else {
        shape
            .nodes
            .iter()
            .map(|n| Vector3::from(n.curvature).norm())
            .fold(0.0, f64::max)
    };
    BULK_TOLERANCE * if scale > 0.0 { scale } else { 1.0 }
}

/// The longest stretch `[first, last]` of consecutive nodes (by arc length) over which every
/// component of the curvature has a spread `max − min ≤ 2 tol`, i.e. stays within `tol`
/// of one constant (the mid-range): one pass with monotone queues of the running maxima
/// and minima. The first such stretch wins a tie.
pub fn longest_uniform_stretch(s: &[f64], curvature: &[[f64; 3]], tol: f64) -> (usize, usize) {
    let n = s.len().min(curvature.len());
    if n == 0 {
        return (0, 0);
    }
    let mut maxq: [VecDeque<usize>; 3] = Default::default();
    let mut minq: [VecDeque<usize>; 3] = Default::default();
    let mut best = (0, 0);
    let mut first = 0;
    for last in 0..n {
        for c in 0..3 {
            let v = curvature[last][c];
            while maxq[c].back().is_some_and(|&i| curvature[i][c] <= v) {
                maxq[c].pop_back();
            }
            maxq[c].push_back(last);
            while minq[c].back().is_some_and(|&i| curvature[i][c] >= v) {
                minq[c].pop_back();
            }
            minq[c].push_back(last);
        }
        let spread_ok = |maxq: &[VecDeque<usize>; 3], minq: &[VecDeque<usize>; 3]| {
            (0..3).all(|c| {
                let (hi, lo) = (maxq[c][0], minq[c][0]);
                curvature[hi][c] - curvature[lo][c] <= 2.0 * tol
            })
        };
        while !spread_ok(&maxq, &minq) {
            first += 1;
            for c in 0..3 {
                while maxq[c].front().is_some_and(|&i| i < first) {
                    maxq[c].pop_front();
                }
                while minq[c].front().is_some_and(|&i| i < first) {
                    minq[c].pop_front();
                }
            }
        }
        if s[last] - s[first] > s[best.1] - s[best.0] {
            best = (first, last);
        }
    }
    best
}

/// The bulk of one rod: the longest uniform stretch of its shape's nodal curvatures within
/// [`tolerance`], the mean curvature there (the integral mean of the piecewise-linear
/// profile through the nodes), the helix of that curvature, Love's wrench for it, and the
/// rod's tip reaction as an axial force and a couple about the tube axis (z through the
/// origin, the axis of the natural helices).
pub fn rod_bulk(
    natural: &Helix,
    stiffness: &Stiffness,
    length: f64,
    shape: &RodShape,
    reaction: &RodReaction,
) -> RodBulk {
    let s: Vec<f64> = shape.nodes.iter().map(|n| n.s).collect();
    let k: Vec<[f64; 3]> = shape.nodes.iter().map(|n| n.curvature).collect();
    let (first, last) = longest_uniform_stretch(&s, &k, tolerance(natural, shape));
    let curvature = if last > first {
        let mut sum = [0.0; 3];
        for i in first..last {
            let ds = s[i + 1] - s[i];
            for c in 0..3 {
                sum[c] += 0.5 * ds * (k[i][c] + k[i + 1][c]);
            }
        }
        sum.map(|v| v / (s[last] - s[first]))
    } else {
        k.get(first).copied().unwrap_or([0.0; 3])
    };
    let (radius, pitch) = helix_of(curvature, natural.chirality.sign());
    let wrench = if natural.is_straight() {
        None
    } else {
        axial_wrench(
            (natural.radius, natural.pitch),
            (radius, pitch),
            stiffness,
            natural.chirality,
        )
    };
    let f = Vector3::from(reaction.tip.force);
    let tip = shape.nodes.last().map_or([0.0; 3], |n| n.position);
    let axial_moment = reaction.tip.moment[2] + (tip[0] * f[1] - tip[1] * f[0]);
    RodBulk {
        rod: shape.rod,
        chirality: shape.chirality,
        length,
        start: s.get(first).copied().unwrap_or(0.0),
        end: s.get(last).copied().unwrap_or(0.0),
        curvature,
        radius,
        pitch,
        love_force: wrench.map(|w| w.0),
        love_moment: wrench.map(|w| w.1),
        axial_force: f[2],
        axial_moment,
    }
}

/// Radius `a` and pitch parameter `b` (m) of the uniform helix of curvatures
/// `(κ1, κ2, Ω)` whose material frame may be turned about the tangent (κ2 ≠ 0): its
/// curvature `K = √(κ1² + κ2²) = a/c²` and torsion `χ Ω = b/c²`, so `c² = 1/(K² + Ω²)`.
/// Zero curvature is a straight rod, `(0, 0)`.
pub fn helix_of(curvature: [f64; 3], chirality: f64) -> (f64, f64) {
    let kk = curvature[0].hypot(curvature[1]);
    let d = kk * kk + curvature[2] * curvature[2];
    if d > 0.0 {
        (kk / d, chirality * curvature[2] / d)
    } else {
        (0.0, 0.0)
    }
}

/// The bulk of every rod of `snapshot` (the state of load point `point` of `model`), and the
/// infinite tube at its `ε` beside the finite assembly (docs/theory.md §7): Love's axial force on
/// the helix of the same arc length per turn `c = c0` and pitch `b0 (1 − ε)`, and the ratio
/// of the finite assembly's mean tip `Fz` to it.
pub fn step_bulk(model: &DiscreteModel, snapshot: &Snapshot, point: &LoadPoint) -> StepBulk {
    let length = model.length();
    let rods: Vec<RodBulk> = snapshot
        .rods
        .iter()
        .zip(&point.reactions)
        .map(|(shape, reaction)| {
            let helix = &model.rods[model.source_rod(shape.rod)].helix;
            rod_bulk(helix, &model.stiffness, length, shape, reaction)
        })
        .collect();
    let natural = model.rods.first().map(|r| r.helix);
    let tube_force = natural
        .filter(|h| !h.is_straight() && point.compression_ratio < 1.0)
        .map(|h| tube_force(&h, model, length, point.compression_ratio))
        .filter(|f| f.is_finite());
    let tube_ratio = tube_force.and_then(|tf| {
        if point.compression_ratio.abs() <= EPS_FLOOR || tf == 0.0 || rods.is_empty() {
            return None;
        }
        let mean = rods.iter().map(|r| r.axial_force).sum::<f64>() / rods.len() as f64;
        Some(mean / tf).filter(|r| r.is_finite())
    });
    // the pantograph's radius, for Kirchhoff rods stress-free on their natural helices
    let tube_radius = natural
        .filter(|h| !h.is_straight() && point.support.pressure != 0.0)
        .filter(|_| model.elasticity == Elasticity::default())
        .and_then(|h| pantograph_radius(&h, &model.stiffness, point.support.pressure));
    let radius_ratio = tube_radius.and_then(|a| {
        let mean = rods.iter().map(|r| r.radius).sum::<f64>() / rods.len().max(1) as f64;
        Some(mean / a).filter(|r| r.is_finite() && !rods.is_empty())
    });
    StepBulk {
        step: point.step,
        compression_ratio: point.compression_ratio,
        rods,
        tube_force,
        tube_ratio,
        tube_radius,
        radius_ratio,
    }
}

/// Love's axial force per rod (N, tension positive) of the infinitely long tube of rods
/// naturally `natural`, compressed by `ε`: the helix `c = c0`, `b = b0 (1 − ε)`, which pin
/// joints at fixed material points impose far from the ends (docs/theory.md §7), under the
/// model's elastic hypotheses.
pub fn tube_force(natural: &Helix, model: &DiscreteModel, length: f64, eps: f64) -> f64 {
    LoveHelix {
        radius0: natural.radius,
        pitch0: natural.pitch,
        length,
        stiffness: model.stiffness,
        pitch: natural.pitch * (1.0 - eps),
        elasticity: model.elasticity,
        reference: model.reference,
    }
    .force()
}
