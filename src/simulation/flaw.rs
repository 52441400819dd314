//! A flaw of the natural state (docs/theory.md §9) as built — its reference curvatures
//! changed by the rotations a shape makes of the natural frames — and what it did to a path:
//! where the imperfect path turns (its limit point) against the perfect critical point.

use crate::case::Imperfection;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::element;
use crate::model::quaternion::{darboux, mul, Quat};
use crate::results::{CriticalKind, CriticalPoint, LoadPoint};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// The perfect structure's critical point a flaw was measured against.
#[derive(Clone, Debug, PartialEq)]
pub struct PerfectPoint {
    /// Its index on the perfect path (as `critical.csv` numbers them).
    pub index: usize,
    pub kind: CriticalKind,
    /// Load parameter there.
    pub parameter: f64,
    /// `fz / (n Pcrit)` there.
    pub fz: f64,
    pub wavenumber: Option<usize>,
    pub multiplicity: usize,
}

/// A flaw as built: what the case asked for and the perfect critical point it follows (or,
/// for a named shape, the perfect path's first critical point, when it has one).
#[derive(Clone, Debug, PartialEq)]
pub struct Flaw {
    pub imperfection: Imperfection,
    pub perfect: Option<PerfectPoint>,
    /// Whether the flawed structure is solved as the whole assembly where the case asked
    /// for a symmetric pair (the mode breaks the pair's symmetry).
    pub whole_assembly: bool,
}

/// What a flaw did to a path: where the imperfect path turns in its parameter (its first
/// limit point), and the drop of that parameter below the perfect critical point's.
#[derive(Clone, Debug, PartialEq)]
pub struct ImperfectPath {
    pub flaw: Flaw,
    /// The parameter of the first limit point of the imperfect path, if it has one.
    pub limit_parameter: Option<f64>,
    /// `fz / (n Pcrit)` there.
    pub limit_fz: Option<f64>,
    /// `λc − λ_limit` (in the sense the path went), where both exist.
    pub drop: Option<f64>,
    /// The largest `|fz| / (n Pcrit)` of the path's output points and the limit point, and
    /// the parameter where it is.
    pub max_load: f64,
    pub max_load_parameter: f64,
}

impl ImperfectPath {
    /// One line: the flaw, the perfect critical point, where the imperfect path turns (or
    /// that it does not) and the drop.
    pub fn summary(&self) -> String {
        let flaw = self.flaw.imperfection.describe();
        let perfect = match &self.flaw.perfect {
            Some(p) => format!(
                "perfect {} {} at parameter {:.8}",
                p.kind.name(),
                p.index,
                p.parameter
            ),
            None => "no perfect critical point".into(),
        };
        let turn = match (self.limit_parameter, self.drop) {
            (Some(l), Some(d)) => format!("the path turns at parameter {l:.8} (drop {d:.4e})"),
            (Some(l), None) => format!("the path turns at parameter {l:.8}"),
            (None, _) => "the path does not turn (no limit point)".into(),
        };
        format!(
            "imperfection: {flaw}; {perfect}; {turn}; max |fz|/(n Pcrit) = {:.6} at parameter {:.6}",
            self.max_load, self.max_load_parameter
        )
    }

    /// The summary of a path run with `flaw`, from its critical points and output points.
    pub fn of(flaw: &Flaw, critical: &[CriticalPoint], points: &[LoadPoint]) -> ImperfectPath {
        let limit = critical.iter().find(|c| c.kind == CriticalKind::LimitPoint);
        let dir = points
            .last()
            .map_or(1.0, |p| if p.parameter < 0.0 { -1.0 } else { 1.0 });
        let drop = match (&flaw.perfect, limit) {
            (Some(p), Some(l)) => Some(dir * (p.parameter - l.parameter)),
            _ => None,
        };
        let candidates = points
            .iter()
            .map(|p| (p.load[2].abs(), p.parameter))
            .chain(limit.map(|l| (l.load[2].abs(), l.parameter)));
        let (max_load, max_load_parameter) = candidates
            .filter(|(f, _)| f.is_finite())
            .fold((0.0, 0.0), |best, c| if c.0 > best.0 { c } else { best });
        ImperfectPath {
            flaw: flaw.clone(),
            limit_parameter: limit.map(|l| l.parameter),
            limit_fz: limit.map(|l| l.load[2]),
            drop,
            max_load,
            max_load_parameter,
        }
    }
}

pub(super) fn perfect_point(index: usize, cp: &CriticalPoint) -> PerfectPoint {
    PerfectPoint {
        index,
        kind: cp.kind,
        parameter: cp.parameter,
        fz: cp.load[2],
        wavenumber: cp.wavenumber,
        multiplicity: cp.multiplicity,
    }
}

/// The largest centreline displacement of `mode` over the vertices of `model` (m per unit).
pub(super) fn max_displacement(model: &DiscreteModel, mode: &[f64]) -> f64 {
    model
        .rods
        .iter()
        .flat_map(|rod| {
            (0..=rod.mesh.elements()).map(move |v| {
                Vector3::from_fn(|k, _| mode.get(rod.r_dof(v, k)).copied().unwrap_or(0.0)).norm()
            })
        })
        .fold(0.0, f64::max)
}

/// The factor that scales `mode` to a largest displacement of `amplitude · L`; `None` for
/// a mode that moves no centreline point.
pub(super) fn mode_scale(model: &DiscreteModel, mode: &[f64], amplitude: f64) -> Option<f64> {
    let largest = max_displacement(model, mode);
    (largest > 0.0 && largest.is_finite()).then(|| amplitude * model.length() / largest)
}

/// The rotation each quaternion node of the natural state turns by (a quaternion to
/// compose on the right, in its material frame), rod by rod: the mode's nodal rotations
/// `2 Im(q̄ ∘ δq)` at the critical state, times `scale`.
pub(super) fn mode_rotations(
    model: &DiscreteModel,
    state: &[f64],
    mode: &[f64],
    scale: f64,
) -> Vec<Vec<Quat>> {
    model
        .rods
        .iter()
        .enumerate()
        .map(|(id, rod)| {
            (0..rod.mesh.quaternion_nodes())
                .map(|k| {
                    let q = model.quaternion(state, id, k);
                    let dq = Quat::from_fn(|c, _| mode[rod.q_dof(k, c)]);
                    rotation_quat(&(darboux(&q, &dq) * scale))
                })
                .collect()
        })
        .collect()
}

/// The unit quaternion of the rotation vector `theta` (rad).
fn rotation_quat(theta: &Vector3<f64>) -> Quat {
    let angle = theta.norm();
    if angle == 0.0 {
        return Quat::new(0.0, 0.0, 0.0, 1.0);
    }
    let axis = theta / angle;
    let s = (0.5 * angle).sin();
    Quat::new(axis[0] * s, axis[1] * s, axis[2] * s, (0.5 * angle).cos())
}

/// The half sine bow `x(s) = δ L sin(π s/L)` of a straight rod as material rotations of its
/// natural frames: each turned about the global y axis by the bow's slope
/// `θ(s) = π δ cos(π s/L)`, written in the node's material frame.
pub(super) fn bow_rotations(model: &DiscreteModel, amplitude: f64) -> Vec<Vec<Quat>> {
    let natural = model.natural_state();
    let length = model.length();
    model
        .rods
        .iter()
        .enumerate()
        .map(|(id, rod)| {
            (0..rod.mesh.quaternion_nodes())
                .map(|k| {
                    let s = rod.mesh.node_arc_length(k);
                    let theta = PI * amplitude * (PI * s / length).cos();
                    let q = model.quaternion(&natural, id, k);
                    let frame: Matrix3<f64> = crate::model::quaternion::rotation(&q);
                    let spatial = Vector3::new(0.0, theta, 0.0);
                    rotation_quat(&(frame.transpose() * spatial))
                })
                .collect()
        })
        .collect()
}

/// Adds to the reference curvatures of every rod the change of curvature its natural
/// frames make when turned by `rotations` (node by node, in their material frames): the
/// flawed natural state is then stress-free, whatever the rods' stress-free shape was.
pub(super) fn flaw_references(model: &mut DiscreteModel, rotations: &[Vec<Quat>]) {
    let natural = model.natural_state();
    let flawed: Vec<f64> = {
        let mut x = natural.clone();
        for (rod, turns) in model.rods.iter().zip(rotations) {
            for (k, turn) in turns.iter().enumerate() {
                let q = Quat::from_fn(|c, _| natural[rod.q_dof(k, c)]);
                let turned = mul(&q, turn);
                for c in 0..4 {
                    x[rod.q_dof(k, c)] = turned[c];
                }
            }
        }
        x
    };
    let (order, rule) = (model.order, model.rule.clone());
    let points = rule.len();
    let changes: Vec<Vec<Vector3<f64>>> = model
        .rods
        .iter()
        .map(|rod| {
            (0..rod.mesh.elements())
                .flat_map(|e| {
                    let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
                    let before = element::curvatures_at_points(
                        order,
                        &rule,
                        h,
                        &model.element_quaternions(&natural, rod, e),
                    );
                    let after = element::curvatures_at_points(
                        order,
                        &rule,
                        h,
                        &model.element_quaternions(&flawed, rod, e),
                    );
                    after
                        .into_iter()
                        .zip(before)
                        .map(|(a, b)| a - b)
                        .collect::<Vec<_>>()
                })
                .collect()
        })
        .collect();
    for (rod, change) in model.rods.iter_mut().zip(changes) {
        debug_assert_eq!(rod.reference.len(), change.len());
        debug_assert_eq!(rod.reference.len(), rod.mesh.elements() * points);
        for (r, c) in rod.reference.iter_mut().zip(change) {
            *r += c;
        }
    }
}
