//! The infinite pin-jointed tube under radial pressure, in closed form (docs/loads.md): the
//! crossings of a long tube form a rhombic lattice of fixed sides on a cylinder, so uniform
//! helices keep their arc length per turn `c = c0` and have one motion left, radius against
//! height (the pantograph). Stationarity of `Π = L W(K, τ) + q L a` on it, with no axial
//! force and Kirchhoff rods stress-free on the natural helix (`W = B1 (K − K0)²/2 +
//! B3 (τ − τ0)²/2`, `K = a/c²`, `τ = b/c²`, `b = √(c0² − a²)`), gives the inward line
//! pressure (N/m) that holds radius `a`:
//! `q = [B3 (τ − τ0) a/b − B1 (K − K0)] / c²`.

use super::helix::Helix;
use super::stiffness::Stiffness;

/// The line pressure `q` (N/m, inward) that holds the bulk of the tube of rods naturally
/// `natural` at radius `a` (m) with no axial force.
pub fn pantograph_pressure(natural: &Helix, stiffness: &Stiffness, a: f64) -> f64 {
    let c = natural.c();
    let c2 = c * c;
    let b = (c2 - a * a).sqrt();
    let (k, k0) = (a / c2, natural.radius / c2);
    let (t, t0) = (b / c2, natural.pitch / c2);
    (stiffness.b3 * (t - t0) * a / b - stiffness.b1 * (k - k0)) / c2
}

/// The bulk radius (m) the pressure `q` (N/m, inward) holds with no axial force, on the
/// branch of the natural radius (`None` past the largest pressure that branch carries, or
/// for rods on the axis).
pub fn pantograph_radius(natural: &Helix, stiffness: &Stiffness, q: f64) -> Option<f64> {
    let (a0, c) = (natural.radius, natural.c());
    if !(a0 > 0.0 && q.is_finite()) {
        return None;
    }
    if q == 0.0 {
        return Some(a0);
    }
    // from a0 towards the axis (q > 0) or towards c (q < 0), in small steps to a bracket
    let (end, steps) = (if q > 0.0 { 0.0 } else { c }, 400);
    let excess = |a: f64| pantograph_pressure(natural, stiffness, a) - q;
    let mut previous = a0;
    for k in 1..steps {
        let a = a0 + (end - a0) * k as f64 / steps as f64;
        let f = excess(a);
        if !f.is_finite() {
            return None;
        }
        // the branch turns back before reaching q: no radius carries it
        if (f > 0.0) == (q > 0.0) || f == 0.0 {
            let (mut lo, mut hi) = (previous, a);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if (excess(mid) > 0.0) == (excess(hi) > 0.0) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(0.5 * (lo + hi));
        }
        if q > 0.0
            && pantograph_pressure(natural, stiffness, a)
                < pantograph_pressure(natural, stiffness, previous)
        {
            return None;
        }
        previous = a;
    }
    None
}
