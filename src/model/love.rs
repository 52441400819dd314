//! Love's helical equilibria (docs/theory.md §6): a rod held on a uniform helix of another radius
//! and pitch than its natural one stays that helix, loaded by an axial force and an axial
//! couple only, both in closed form — for Kirchhoff rods stress-free when helical (Love's
//! formula), when straight (the same with `K0 = τ0 = 0`), and for any energy density
//! `W(κ1, κ2, Ω)` whose couple `m = ∂W/∂u` has no `d2` component on the helix
//! (Sadowsky's ribbon, docs/theory.md §7), from the balance laws.

use super::elasticity::{Elasticity, Reference, StressFree};
use super::helix::Chirality;
use super::stiffness::Stiffness;
use nalgebra::Vector3;
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
    /// The elastic hypotheses of the rod.
    pub elasticity: Elasticity,
    /// How the discrete rod takes its reference curvatures (for the studies that solve it;
    /// the closed form is the continuum's).
    pub reference: Reference,
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
            elasticity: Elasticity::default(),
            reference: Reference::Discrete,
        }
    }

    /// The same problem for a rod of other elastic hypotheses and reference.
    pub fn with_hypotheses(self, elasticity: Elasticity, reference: Reference) -> LoveHelix {
        LoveHelix {
            elasticity,
            reference,
            ..self
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

    /// The couple `m = ∂W/∂u` (N m, body components) on the held helix of a right-handed
    /// rod, with the reference curvatures of the natural helix (zero when stress-free
    /// straight).
    fn couple(&self) -> Vector3<f64> {
        let u = Vector3::from(self.curvature(Chirality::Right));
        let reference = match self.elasticity.stress_free {
            StressFree::Straight => Vector3::zeros(),
            StressFree::Helix => {
                let c0 = self.c0();
                Vector3::new(-self.radius0 / (c0 * c0), 0.0, self.pitch0 / (c0 * c0))
            }
        };
        self.elasticity.density(&self.stiffness, &u, &reference).1
    }

    /// Axial force on the tip (N, tension positive), from `m' + d3 × n = 0` with `n = F e_z`
    /// on the helix: `F = c (Ω m1 − κ1 m3) / a`. For Kirchhoff rods this is Love's
    /// `F = [C (τ − τ0) a − B (K − K0) b] / (a c)` (`K0 = τ0 = 0` when straight).
    pub fn force(&self) -> f64 {
        let (a, c) = (self.radius(), self.c0());
        let u = self.curvature(Chirality::Right);
        let m = self.couple();
        c * (u[2] * m[0] - u[0] * m[2]) / a
    }

    /// Axial couple on the tip (N m), `M = m · e_z = χ (−a m1 + b m3)/c` with `m` the
    /// right-handed rod's couple (a left-handed rod is its mirror image); for Kirchhoff rods
    /// Love's `M = χ [B (K − K0) a + C (τ − τ0) b] / c`, `χ = ±1`.
    pub fn moment(&self, chirality: Chirality) -> f64 {
        let (a, b, c) = (self.radius(), self.pitch, self.c0());
        let m = self.couple();
        chirality.sign() * (-a * m[0] + b * m[2]) / c
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
/// turn (docs/theory.md §6): `F = [C (τ − τ0) a − B (K − K0) b] / (a c)`,
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
