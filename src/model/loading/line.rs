//! Loads distributed along the rods: dead line loads and the radial pressure.

use super::support::Ramp;

/// A load distributed along every rod, per unit arc length: a dead one has its slot in the
/// element kernel ([`crate::discretisation::element::ElementLoad`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LineLoad {
    /// A dead force `f(λ) = ramp(λ) · direction` (N/m) of fixed direction, such as the rods'
    /// weight: potential `−∫ f·r ds`.
    Dead { direction: [f64; 3], ramp: Ramp },
    /// Radial pressure on the tube: a force `q(λ) = ramp(λ)` (N/m) per unit length of rod
    /// directed at the tube's axis from the rod's current point (inward for `q > 0`), a
    /// central field in x–y with potential `q ∫ ρ ds`, `ρ = √(x² + y²)`.
    Radial { ramp: Ramp },
}

impl LineLoad {
    /// The dead force per unit length (N/m) at `lambda` (zero for a radial load).
    pub fn force(&self, lambda: f64) -> [f64; 3] {
        match *self {
            LineLoad::Dead { direction, ramp } => direction.map(|d| d * ramp.at(lambda)),
            LineLoad::Radial { .. } => [0.0; 3],
        }
    }

    /// `d f/dλ` (N/m) at `lambda` of the dead force.
    pub fn rate(&self, lambda: f64) -> [f64; 3] {
        match *self {
            LineLoad::Dead { direction, ramp } => direction.map(|d| d * ramp.rate(lambda)),
            LineLoad::Radial { .. } => [0.0; 3],
        }
    }

    /// The radial pressure `q` (N/m, inward positive) and its rate `dq/dλ` at `lambda`.
    pub fn pressure(&self, lambda: f64) -> (f64, f64) {
        match *self {
            LineLoad::Radial { ramp } => (ramp.at(lambda), ramp.rate(lambda)),
            LineLoad::Dead { .. } => (0.0, 0.0),
        }
    }
}

/// The natural scale of a radial line pressure on rods of bending stiffness `b1` (N m²)
/// wound as helices of radius `a` and pitch parameter `b` (m): `B1 a/c⁴` (N/m), the
/// pressure that changes their curvature `a/c²` by its own size (1 when it is not a
/// positive number, for rods on the axis).
pub fn pressure_unit(b1: f64, a: f64, b: f64) -> f64 {
    let c2 = a * a + b * b;
    let unit = b1 * a / (c2 * c2);
    if unit.is_finite() && unit > 0.0 {
        unit
    } else {
        1.0
    }
}
