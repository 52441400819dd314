//! Love's helical equilibria (DESIGN.md §6): a rod held on a uniform helix of another radius
//! and pitch than its natural one stays that helix, loaded by an axial force and an axial
//! couple only, both in closed form.

use super::helix::Chirality;
use super::stiffness::Stiffness;
use std::f64::consts::PI;

/// A rod, naturally a helix of radius `a0` and pitch parameter `b0`, held on the helix of
/// the same arc length per turn (`c = c0`) with pitch parameter `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoveHelix {
    /// Natural radius `a0` and pitch parameter `b0` (m).
    pub radius0: f64,
    pub pitch0: f64,
    /// Rod length `L` (m).
    pub length: f64,
    /// `B1 = B2 = B` (bending) and `B3 = C` (torsion), N m².
    pub stiffness: Stiffness,
    /// Pitch parameter `b` of the held helix (m).
    pub pitch: f64,
}

impl LoveHelix {
    /// The thesis rods (a0 = 0.06 m, b0 = 0.025 m, 3.5 turns, B = 1, C = 2 N m²) held on
    /// the helix of pitch parameter `pitch` with the same `c`.
    pub fn thesis(pitch: f64) -> LoveHelix {
        let (a0, b0) = (0.06, 0.025);
        LoveHelix {
            radius0: a0,
            pitch0: b0,
            length: 7.0 * PI * f64::hypot(a0, b0),
            stiffness: Stiffness {
                b1: 1.0,
                b2: 1.0,
                b3: 2.0,
            },
            pitch,
        }
    }

    /// `c0 = √(a0² + b0²)` (m).
    pub fn c0(&self) -> f64 {
        self.radius0.hypot(self.pitch0)
    }

    /// Number of turns `L / (2π c0)`.
    pub fn turns(&self) -> f64 {
        self.length / (2.0 * PI * self.c0())
    }

    /// Radius `a` of the held helix: the same `c` (arc length per turn) as the natural one.
    pub fn radius(&self) -> f64 {
        (self.c0().powi(2) - self.pitch.powi(2)).sqrt()
    }

    /// `(K − K0, τ − τ0)` (1/m) with `K = a/c²`, `τ = b/c²`, and `c`.
    fn changes(&self) -> (f64, f64, f64) {
        let (a, b) = (self.radius(), self.pitch);
        let (c0, c) = (self.c0(), a.hypot(b));
        let (k0, t0) = (self.radius0 / (c0 * c0), self.pitch0 / (c0 * c0));
        let (k, t) = (a / (c * c), b / (c * c));
        (k - k0, t - t0, c)
    }

    /// Axial force on the tip (N, tension positive):
    /// `F = [C (τ − τ0) a − B (K − K0) b] / (a c)`.
    pub fn force(&self) -> f64 {
        let (a, b) = (self.radius(), self.pitch);
        let (dk, dt, c) = self.changes();
        (self.stiffness.b3 * dt * a - self.stiffness.b1 * dk * b) / (a * c)
    }

    /// Axial couple on the tip (N m): `M = χ [B (K − K0) a + C (τ − τ0) b] / c`, `χ = ±1`
    /// for a right- or left-handed rod.
    pub fn moment(&self, chirality: Chirality) -> f64 {
        let (a, b) = (self.radius(), self.pitch);
        let (dk, dt, c) = self.changes();
        chirality.sign() * (self.stiffness.b1 * dk * a + self.stiffness.b3 * dt * b) / c
    }

    /// Curvatures `(−a/c², 0, χ b/c²)` of the held helix (1/m).
    pub fn curvature(&self, chirality: Chirality) -> [f64; 3] {
        let (a, b) = (self.radius(), self.pitch);
        let c2 = a * a + b * b;
        [-a / c2, 0.0, chirality.sign() * b / c2]
    }
}

/// Love's axial force on the tip (N, tension positive) and axial couple (N m) of a rod
/// naturally the helix `(a0, b0)` held on the uniform helix `(a, b)` of any arc length per
/// turn (DESIGN.md §6): `F = [C (τ − τ0) a − B (K − K0) b] / (a c)`,
/// `M = χ [B (K − K0) a + C (τ − τ0) b] / c`, with `K = a/c²`, `τ = b/c²`, `B = B1`, `C = B3`.
/// `None` when `a ≤ 0` (a straight rod is no helix).
pub fn axial_wrench(
    natural: (f64, f64),
    held: (f64, f64),
    stiffness: &Stiffness,
    chirality: Chirality,
) -> Option<(f64, f64)> {
    let ((a0, b0), (a, b)) = (natural, held);
    if a.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let (c0, c) = (a0.hypot(b0), a.hypot(b));
    let (k0, t0) = (a0 / (c0 * c0), b0 / (c0 * c0));
    let (dk, dt) = (a / (c * c) - k0, b / (c * c) - t0);
    let f = (stiffness.b3 * dt * a - stiffness.b1 * dk * b) / (a * c);
    let m = chirality.sign() * (stiffness.b1 * dk * a + stiffness.b3 * dt * b) / c;
    (f.is_finite() && m.is_finite()).then_some((f, m))
}
