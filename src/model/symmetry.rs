//! The rotational symmetry of an assembly of `n = 2m` helices (docs/theory.md §7): rotation by
//! `2π/m` about the axis maps right rod `k` to right rod `k + 1` and left rod `k` to left rod
//! `k − 1`, so one right/left pair stands for the whole assembly.

use super::quaternion::{self, Quat};
use std::f64::consts::PI;

/// The `m`-fold rotational symmetry of an assembly of `n = 2m` helices reduced to one
/// right/left pair: rod `R_k` is `R_0` turned by `2πk/m`, `L_k` is `L_0` turned by `−2πk/m`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Symmetry {
    pub m: usize,
}

impl Symmetry {
    /// Number of rods of the full assembly.
    pub fn full_rods(&self) -> usize {
        2 * self.m
    }

    /// For rod `k` of the full assembly: the rod of the pair it is an image of (0 right,
    /// 1 left) and the angle (rad) it is turned by about z.
    pub fn image(&self, k: usize) -> (usize, f64) {
        let step = 2.0 * PI / self.m as f64;
        if k < self.m {
            (0, step * k as f64)
        } else {
            (1, -step * (k - self.m) as f64)
        }
    }
}

/// Why an assembly cannot be reduced by its symmetry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SymmetryError {
    #[error("{n} helix(es) have no rotational symmetry to reduce: the reduction needs n = 2m helices with m ≥ 2")]
    TooFewHelices { n: usize },
}

/// A rotation about the z axis by `angle` (rad), acting on vectors and on rotations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurnZ {
    sin: f64,
    cos: f64,
    angle: f64,
}

impl TurnZ {
    pub fn new(angle: f64) -> TurnZ {
        let (sin, cos) = angle.sin_cos();
        TurnZ { sin, cos, angle }
    }

    /// The vector `v` turned.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        [
            self.cos * v[0] - self.sin * v[1],
            self.sin * v[0] + self.cos * v[1],
            v[2],
        ]
    }

    /// The vector `v` turned back (by `−angle`).
    pub fn apply_inverse(&self, v: [f64; 3]) -> [f64; 3] {
        [
            self.cos * v[0] + self.sin * v[1],
            -self.sin * v[0] + self.cos * v[1],
            v[2],
        ]
    }

    /// The rotation `q` followed by this turn: `q_z ∘ q`.
    pub fn rotate(&self, q: &Quat) -> Quat {
        quaternion::mul(&quaternion::about_z(self.angle), q)
    }
}
