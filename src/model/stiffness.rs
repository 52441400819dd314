//! Elastic stiffnesses of a rod and the Euler load that is the unit of force (docs/theory.md §1, §4).

use std::f64::consts::PI;

/// Bending stiffnesses `B1`, `B2` (about `d1`, `d2`) and torsional stiffness `B3` (N m²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stiffness {
    pub b1: f64,
    pub b2: f64,
    pub b3: f64,
}

impl Stiffness {
    /// `[B1, B2, B3]` (N m²).
    pub fn as_array(&self) -> [f64; 3] {
        [self.b1, self.b2, self.b3]
    }

    /// Euler load of a clamped–clamped rod of length `L` (m) bending about `d1`:
    /// `Pcrit = B1 (2π/L)²` (N), the unit of the reported forces.
    pub fn euler_load(&self, length: f64) -> f64 {
        euler_load(self.b1, length)
    }
}

/// Euler load of a clamped–clamped rod of bending stiffness `b1` (N m²) and length `L` (m):
/// `Pcrit = B1 (2π/L)²` (N).
pub fn euler_load(b1: f64, length: f64) -> f64 {
    b1 * (2.0 * PI / length).powi(2)
}
