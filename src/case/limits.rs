//! The ranges a case's values and derived quantities must lie in, and the
//! helpers that say them in messages.

use super::settings::Geometry;

/// The most output steps a case (`loading.steps`) or the command line (`--steps`) may ask.
pub const MAX_STEPS: usize = 100_000;

/// Lengths (radius when not 0, pitch parameter, rod length), m.
pub const LENGTH_RANGE: (f64, f64) = (1e-6, 1e6);
/// Pitch over radius `b/a` of a helix: flatter or steeper helices make the KKT matrix
/// ill-conditioned (the rise per turn against the circumference).
pub const PITCH_RATIO: (f64, f64) = (1e-3, 1e3);
/// Turns of a helix (`L / (2π c)`).
pub const TURNS_RANGE: (f64, f64) = (1e-2, 1e3);
/// Stiffnesses `B1`, `B2`, `B3`, N m².
pub const STIFFNESS_RANGE: (f64, f64) = (1e-12, 1e12);
/// The largest stiffness (N m/rad) of an elastic joint's springs.
pub const JOINT_STIFFNESS_MAX: f64 = 1e12;
/// `B2/B1` and `B3/B1`.
pub const STIFFNESS_RATIO: (f64, f64) = (1e-4, 1e4);
/// Elements per turn of a helix (the elements per rod, joints' vertices included, over the
/// turns): fewer cannot represent the turn, more is all round-off.
pub const MIN_ELEMENTS_PER_TURN: f64 = 1.0;
pub const MAX_ELEMENTS_PER_TURN: f64 = 1e4;
/// `solver.tolerance`: below round-off Newton never converges, above it accepts states
/// that are not equilibria (the natural state as the answer of the first step).
pub const TOLERANCE_RANGE: (f64, f64) = (1e-14, 1e-6);
/// `solver.initial_step`, `max_step`, `min_step`, in the load parameter.
pub const STEP_RANGE: (f64, f64) = (1e-12, 100.0);
/// Pin joints of an assembly.
pub const MAX_JOINTS: usize = 1_000_000;
/// `|P/Pcrit|` of a load-control target.
pub const MAX_LOAD: f64 = 100.0;

/// "from lo to hi", the bounds as [`num`] writes them.
pub(super) fn range((lo, hi): (f64, f64)) -> String {
    format!("from {} to {}", num(lo), num(hi))
}

/// `lo ≤ v ≤ hi` (false for NaN).
pub(super) fn in_range(v: f64, (lo, hi): (f64, f64)) -> bool {
    v >= lo && v <= hi
}

/// A number for a message: as Rust prints it, in scientific notation when it would be long.
pub fn num(x: f64) -> String {
    let a = x.abs();
    if x != 0.0 && a.is_finite() && !(1e-4..1e6).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// An upper estimate of the number of pin joints: each of the `(n/2)²` right/left pairs of
/// rods crosses twice per turn, and possibly at both ends.
pub fn estimated_joints(geometry: &Geometry) -> f64 {
    if geometry.helices < 2 || geometry.radius == 0.0 {
        return 0.0;
    }
    let half = (geometry.helices / 2) as f64;
    half * half * (2.0 * geometry.turns() + 2.0)
}
