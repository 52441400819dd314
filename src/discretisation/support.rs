//! A tip support that turns: its pose at a load parameter (the twist and tilt of the loads,
//! docs/theory.md §3: the support carried rigidly), and the constraints by which it holds the rods'
//! tips in its own frame, whose coefficients move with the load parameter.
//!
//! A support at rotation `q_s` (matrix `R_s`) and centre `c` holds a tip translation `d`
//! (a direction of the support's frame) by `(R_s d)·(r − c) = d·p`, `p` the tip's position
//! in the support's frame, and a tip rotation by `w·Im(q̄_t ∘ q) = 0`, `q_t = q_s ∘ q_ref`
//! the held rotation (`q_ref` in the support's frame). Both are linear in the unknowns with
//! coefficients that depend on `λ` only, so the KKT matrix keeps its form and `∂R/∂λ` has
//! the terms `(∂a/∂λ)·x − ∂b/∂λ` on the constraint's row and `ν ∂a/∂λ` on its unknowns.

use crate::model::loading::{AxisLoad, Loads, SupportAxis};
use crate::model::quaternion::{self, Quat};
use nalgebra::Vector3;

/// Where the tip support is at a load parameter, and how fast it moves.
#[derive(Clone, Copy, Debug)]
pub struct SupportPose {
    /// Rotation of the support from its natural pose, and its rate `d/dλ`.
    pub rotation: Quat,
    pub rotation_rate: Quat,
    /// The tip's centre on the axis (m), and its rate `d/dλ` (m).
    pub centre: Vector3<f64>,
    pub centre_rate: Vector3<f64>,
    /// A cell's tilt `θ` (rad) about x and its rate, and the cell's rise `h` (m) and its
    /// rate: the bent axis through the sections inside the cell (zero tilt off a cell).
    pub tilt: f64,
    pub tilt_rate: f64,
    pub rise: f64,
    pub rise_rate: f64,
}

impl SupportPose {
    /// The pose under `loads` at `lambda`: the support's twist and tilt, its centre at the
    /// prescribed tip height `h0 (1 − ε)` (at `h0` when the axis is free: a free axial
    /// position with a turning support holds no translation that the height enters).
    pub fn of(loads: &Loads, height0: f64, lambda: f64) -> SupportPose {
        let (rotation, rotation_rate) = loads.tip().rotation(lambda);
        let (h, dh) = match loads.tip().axis(SupportAxis::Z) {
            AxisLoad::Motion(r) => (height0 * (1.0 - r.at(lambda)), -height0 * r.rate(lambda)),
            AxisLoad::Force(_) => (height0, 0.0),
        };
        SupportPose {
            rotation,
            rotation_rate,
            centre: Vector3::new(0.0, 0.0, h),
            centre_rate: Vector3::new(0.0, 0.0, dh),
            tilt: 0.0,
            tilt_rate: 0.0,
            rise: h,
            rise_rate: dh,
        }
    }

    /// The pose of a finite tube's tip support ([`SupportPose::of`]) or, for a cell
    /// (`cell`), of its far ends ([`SupportPose::of_cell`]).
    pub fn at(loads: &Loads, height0: f64, lambda: f64, cell: bool) -> SupportPose {
        if cell {
            SupportPose::of_cell(loads, height0, lambda)
        } else {
            SupportPose::of(loads, height0, lambda)
        }
    }

    /// The map carrying a cell's near ends onto its far ends, `x ↦ R_s x + t`: `R_s` the
    /// twist `φ` about the axis then the tilt `θ` about x, and `t` the chord of the tube's
    /// axis bent to the curvature `θ/h` (`h = h0 (1 − ε)` the cell's rise), the image of the
    /// near section's centre (the origin) under the rotation by `θ` about the transverse
    /// axis through the centre of curvature `(0, −h/θ, 0)`:
    /// `t = h (0, −(1 − cos θ)/θ, sin θ/θ)`, `(0, 0, h)` at `θ = 0`.
    pub fn of_cell(loads: &Loads, height0: f64, lambda: f64) -> SupportPose {
        let mut pose = SupportPose::of(loads, height0, lambda);
        let (theta, dtheta) = match loads.tip().axis(SupportAxis::RotX) {
            AxisLoad::Motion(r) => (r.at(lambda), r.rate(lambda)),
            AxisLoad::Force(_) => (0.0, 0.0),
        };
        let (h, dh) = (pose.centre[2], pose.centre_rate[2]);
        let [f, g, df, dg, _, _] = arc_chord(theta);
        pose.centre = Vector3::new(0.0, -h * f, h * g);
        pose.centre_rate = Vector3::new(0.0, -(dh * f + h * df * dtheta), dh * g + h * dg * dtheta);
        pose.tilt = theta;
        pose.tilt_rate = dtheta;
        pose
    }

    /// The section of an untwisted bent cell a fraction `f` of its rise along the bent
    /// axis: its turn by `fθ` about x and its centre `t_f = f h (0, −(1 − cos fθ)/(fθ),
    /// sin fθ/(fθ))`, the image of the near section's centre under the rotation by `fθ`
    /// about the centre of curvature `(0, −h/θ, 0)`; with `rate`, the rates `d/dλ` of the
    /// turned `d` and of `t_f`.
    pub fn section(
        &self,
        fraction: f64,
        d: &Vector3<f64>,
        rate: bool,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (f, theta, h) = (fraction, self.tilt, self.rise);
        let (s, c) = (f * theta).sin_cos();
        let a = Vector3::new(d[0], c * d[1] - s * d[2], s * d[1] + c * d[2]);
        let [u, v, du, dv, _, _] = arc_chord(f * theta);
        if rate {
            let da = Vector3::x().cross(&a) * (f * self.tilt_rate);
            let dt = Vector3::new(0.0, -u, v) * (f * self.rise_rate)
                + Vector3::new(0.0, -du, dv) * (f * f * h * self.tilt_rate);
            (da, dt)
        } else {
            (a, Vector3::new(0.0, -u, v) * (f * h))
        }
    }

    /// `R_s v`.
    pub fn turn(&self, v: &Vector3<f64>) -> Vector3<f64> {
        quaternion::rotation(&self.rotation) * v
    }

    /// `(dR_s/dλ) v`: `d/dλ (q v q̄) = q̇ v q̄ + q v q̄̇` for a unit `q`.
    fn turn_rate(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let pure = Quat::new(v[0], v[1], v[2], 0.0);
        let (q, dq) = (&self.rotation, &self.rotation_rate);
        let a = quaternion::mul(&quaternion::mul(dq, &pure), &quaternion::conj(q));
        let b = quaternion::mul(&quaternion::mul(q, &pure), &quaternion::conj(dq));
        Vector3::new(a[0] + b[0], a[1] + b[1], a[2] + b[2])
    }
}

/// `[f, g, f', g', f'', g'']` at `θ` (rad): `f = (1 − cos θ)/θ`, `g = sin θ/θ` and their
/// first and second derivatives, by their series where `|θ| < 0.01` (then the terms left
/// out are below 1e-16).
pub fn arc_chord(theta: f64) -> [f64; 6] {
    let t = theta;
    if t.abs() < 0.01 {
        let t2 = t * t;
        return [
            t / 2.0 - t * t2 / 24.0 + t * t2 * t2 / 720.0,
            1.0 - t2 / 6.0 + t2 * t2 / 120.0,
            0.5 - t2 / 8.0 + t2 * t2 / 144.0,
            -t / 3.0 + t * t2 / 30.0 - t * t2 * t2 / 840.0,
            -t / 4.0 + t * t2 / 36.0,
            -1.0 / 3.0 + t2 / 10.0 - t2 * t2 / 168.0,
        ];
    }
    let (s, c) = t.sin_cos();
    let t2 = t * t;
    let t3 = t2 * t;
    [
        (1.0 - c) / t,
        s / t,
        (t * s - (1.0 - c)) / t2,
        (t * c - s) / t2,
        (t2 * c - 2.0 * t * s + 2.0 * (1.0 - c)) / t3,
        (-t2 * s - 2.0 * t * c + 2.0 * s) / t3,
    ]
}

/// How a tip constraint held by a turning support depends on the load parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Moving {
    /// `(R_s d)·(r − c) = offset` over the tip vertex's three position unknowns (in order).
    Position {
        direction: Vector3<f64>,
        offset: f64,
    },
    /// `w·Im(q̄_t ∘ q) = 0`, `q_t = q_s ∘ reference`, over the tip node's four quaternion
    /// unknowns (in order).
    Orientation {
        reference: Quat,
        weights: Vector3<f64>,
    },
    /// `Σ_v w_v (R_v e_y)·(r_v − t_v) = offset` over the position unknowns of the vertices
    /// of `sections` (three each, in order, the row's first terms), each with its fraction
    /// `f_v` of the cell's rise and its weight `w_v`: the lateral offsets of the rods from
    /// the bent axis of an untwisted bent cell, each vertex against the axis's section at
    /// its own height (turned by `f_v θ`, centre `t_v`, [`SupportPose::section`]).
    Axis {
        offset: f64,
        sections: std::sync::Arc<[(f64, f64)]>,
    },
}

impl Moving {
    /// The coefficients (in the order of the constraint's terms) and the value at `pose`;
    /// with `rate`, their rates `d/dλ`.
    pub fn coefficients(&self, pose: &SupportPose, rate: bool) -> (Vec<f64>, f64) {
        match *self {
            Moving::Position { direction, offset } => {
                let a = pose.turn(&direction);
                if rate {
                    let da = pose.turn_rate(&direction);
                    let db = da.dot(&pose.centre) + a.dot(&pose.centre_rate);
                    (da.iter().copied().collect(), db)
                } else {
                    (a.iter().copied().collect(), offset + a.dot(&pose.centre))
                }
            }
            Moving::Orientation { reference, weights } => {
                let q = if rate {
                    pose.rotation_rate
                } else {
                    pose.rotation
                };
                let conj = quaternion::conj(&quaternion::mul(&q, &reference));
                let coeffs = (0..4)
                    .map(|k| {
                        let mut ek = Quat::zeros();
                        ek[k] = 1.0;
                        let g = quaternion::mul(&conj, &ek);
                        (0..3).map(|i| weights[i] * g[i]).sum()
                    })
                    .collect();
                (coeffs, 0.0)
            }
            Moving::Axis {
                offset,
                ref sections,
            } => {
                let mut coeffs = Vec::with_capacity(3 * sections.len());
                let mut value = if rate { 0.0 } else { offset };
                for &(f, w) in sections.iter() {
                    let (a, t) = pose.section(f, &Vector3::y(), false);
                    if rate {
                        let (da, dt) = pose.section(f, &Vector3::y(), true);
                        coeffs.extend((da * w).iter());
                        value += w * (da.dot(&t) + a.dot(&dt));
                    } else {
                        coeffs.extend((a * w).iter());
                        value += w * a.dot(&t);
                    }
                }
                (coeffs, value)
            }
        }
    }
}
