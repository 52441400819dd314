//! Naturally free circular helices (docs/theory.md §2).

use super::quaternion::{self, Quat};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Handedness of a helix.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Chirality {
    Right,
    Left,
}

impl Chirality {
    /// `+1` for right-handed, `−1` for left-handed.
    pub fn sign(self) -> f64 {
        match self {
            Chirality::Right => 1.0,
            Chirality::Left => -1.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Chirality::Right => "right",
            Chirality::Left => "left",
        }
    }
}

/// A circular helix of radius `a` (m) and pitch `2π b` (m) about the z axis, with arc
/// length `s` from its base on the plane z = 0 at azimuth `t0`.
///
/// Right-handed: `r(s) = (a cos φ, a sin φ, b s/c)`, left-handed: `(a cos φ, −a sin φ, b s/c)`,
/// with `φ = s/c + t0` and `c = √(a² + b²)`.
///
/// Radius `a = 0` is taken as a straight rod along z with untwisted directors (no
/// intrinsic curvature or twist), for the Euler buckling checks; it is not the limit of a
/// helix, which keeps a twist `1/b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Helix {
    /// Radius `a` (m).
    pub radius: f64,
    /// Pitch parameter `b` (m): the helix rises `2π b` per turn.
    pub pitch: f64,
    pub chirality: Chirality,
    /// Base angle `t0` (rad).
    pub base_angle: f64,
}

impl Helix {
    /// `c = √(a² + b²)` (m); one turn has arc length `2π c`.
    pub fn c(&self) -> f64 {
        self.radius.hypot(self.pitch)
    }

    /// Arc length of `turns` turns (m).
    pub fn length_of_turns(&self, turns: f64) -> f64 {
        2.0 * PI * self.c() * turns
    }

    /// Whether this is the straight, untwisted rod (`a = 0`).
    pub fn is_straight(&self) -> bool {
        self.radius == 0.0
    }

    fn phase(&self, s: f64) -> f64 {
        if self.is_straight() {
            self.base_angle
        } else {
            s / self.c() + self.base_angle
        }
    }

    /// Centreline position at arc length `s` (m).
    pub fn position(&self, s: f64) -> Vector3<f64> {
        let (a, b, c) = (self.radius, self.pitch, self.c());
        let phi = self.phase(s);
        let chi = self.chirality.sign();
        Vector3::new(a * phi.cos(), chi * a * phi.sin(), b * s / c)
    }

    /// Directors `[d1 d2 d3]` as the columns of a rotation matrix: `d3` the tangent,
    /// `d2` the principal normal (towards the axis), `d1 = d2 × d3`.
    pub fn directors(&self, s: f64) -> Matrix3<f64> {
        let (a, b, c) = (self.radius, self.pitch, self.c());
        let phi = self.phase(s);
        let chi = self.chirality.sign();
        let (sp, cp) = phi.sin_cos();
        let d3 = Vector3::new(-a / c * sp, chi * a / c * cp, b / c);
        let d2 = Vector3::new(-cp, -chi * sp, 0.0);
        let d1 = d2.cross(&d3);
        Matrix3::from_columns(&[d1, d2, d3])
    }

    /// Intrinsic curvatures `(κ1*, κ2*, Ω*) = (−a/c², 0, χ b/c²)` (1/m).
    pub fn natural_curvature(&self) -> Vector3<f64> {
        if self.is_straight() {
            return Vector3::zeros();
        }
        let c2 = self.c() * self.c();
        Vector3::new(
            -self.radius / c2,
            0.0,
            self.chirality.sign() * self.pitch / c2,
        )
    }

    /// Unit quaternion of the directors at `s`, with the sign chosen closest to `previous`
    /// so that a field sampled in increasing `s` is continuous.
    pub fn quaternion(&self, s: f64, previous: Option<&Quat>) -> Quat {
        let q = quaternion::from_rotation(&self.directors(s));
        match previous {
            Some(p) if p.dot(&q) < 0.0 => -q,
            _ => q,
        }
    }

    /// Continuous quaternion field at the arc lengths `s` (increasing).
    pub fn quaternion_field(&self, s: &[f64]) -> Vec<Quat> {
        let mut out: Vec<Quat> = Vec::with_capacity(s.len());
        for &si in s {
            let q = self.quaternion(si, out.last());
            out.push(q);
        }
        out
    }
}
