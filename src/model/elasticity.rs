//! The elastic hypotheses of a rod (docs/theory.md §1, §7): the configuration it is stress-free
//! in, and its energy per unit length as a function of its curvatures `u = (κ1, κ2, Ω)`
//! (1/m, body components of the Darboux vector).
//!
//! - **Kirchhoff's rod**: `W = ½ Σ B_i (u_i − u*_i)²` with the reference curvatures `u*`.
//! - **Sadowsky's ribbon** (Sadowsky 1930): a narrow inextensible ribbon of width along `d1`
//!   and surface normal `d2` (it lies on the cylinder when the rod lies on a helix) bends
//!   about its width and twists with `W = ½ D (κ1² + Ω²)² / κ1²` (`D = B1`, the plate's
//!   bending stiffness times the width, N m²); its in-plane bending `κ2` is resisted by
//!   `½ B2 κ2²`. It is stress-free when flat. Written as `½ D (κ1² + 2 Ω² + Ω⁴/κ1²)`, the
//!   energy is singular only through `Ω⁴/κ1²`, which is regularised as `Ω⁴/(κ1² + η²)`:
//!
//!   `W = ½ D [κ1² + 2 Ω² + Ω⁴ / (κ1² + η²)] + ½ B2 κ2²,   η² = 60 t² / w⁴`
//!
//!   with the ribbon's thickness `t` and width `w` (m). Why this form: where `|κ1| ≫ η` it
//!   is Sadowsky's energy (relative change `O(η²/κ1²)`); where `|κ1|, |Ω| ≪ η` it is a
//!   Kirchhoff rod with bending stiffness `D` and torsional stiffness `2D`, the thin strip's
//!   `G w t³/3` for Poisson's ratio 0; and at `κ1 = 0` it is `D Ω² + D Ω⁴/(2η²)`, the
//!   energy of a flat strip twisted at rate `Ω`, whose quartic term is the stretching of its
//!   edge fibres, `E t w⁵ Ω⁴/1440` (Green, Proc. R. Soc. A 154, 1936; with `D = E t³ w/12`
//!   this fixes `η² = 60 t²/w⁴`). The crossover curvature `η ~ t/w²` is the parameter of
//!   Audoly & Neukirch's rod–ribbon interpolation (J. Mech. Phys. Solids 153, 104457, 2021),
//!   which this simpler form follows in its two limits without reproducing their
//!   interpolating function. `W` is smooth for `η > 0`; like Sadowsky's it is not convex
//!   where `|Ω|` exceeds about `|κ1|`, which the stability analysis sees.

use super::stiffness::Stiffness;
use nalgebra::{Matrix3, Vector3};

/// The configuration a rod stores no energy in (case key `rod.stress_free`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StressFree {
    /// Naturally helical: the reference curvatures are those of the natural helix.
    Helix,
    /// Naturally straight (no intrinsic curvature or twist): the rods are assembled on the
    /// helices of the natural geometry, so the assembly is prestressed at `ε = 0`.
    Straight,
}

impl StressFree {
    /// Name in case files and outputs.
    pub fn name(self) -> &'static str {
        match self {
            StressFree::Helix => "helix",
            StressFree::Straight => "straight",
        }
    }
}

/// The geometry of a ribbon's cross-section (m), which sets the regularisation of
/// Sadowsky's energy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ribbon {
    /// Width `w` (m), along `d1`.
    pub width: f64,
    /// Thickness `t` (m), along `d2`; `t < w`.
    pub thickness: f64,
}

impl Ribbon {
    /// The regularising curvature `η = √60 t / w²` (1/m) of the module docs: below it the
    /// ribbon behaves as a rod, above it as Sadowsky's ribbon.
    pub fn regularisation(&self) -> f64 {
        60f64.sqrt() * self.thickness / (self.width * self.width)
    }
}

/// The energy per unit length of a rod (case key `rod.energy`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Energy {
    /// `½ Σ B_i (u_i − u*_i)²`.
    Kirchhoff,
    /// The regularised Sadowsky ribbon of the module docs.
    Sadowsky(Ribbon),
}

impl Energy {
    /// Name in case files and outputs.
    pub fn name(&self) -> &'static str {
        match self {
            Energy::Kirchhoff => "kirchhoff",
            Energy::Sadowsky(_) => "sadowsky",
        }
    }
}

/// Where the reference (stress-free) curvatures of naturally helical rods come from (case
/// key `discretisation.reference`).
///
/// The interpolated quaternion field of a helix is not a helix: its curvature at a
/// quadrature point differs from the helix's by `O(h²)`, and its chords from the helix's
/// by `O(h⁴)`. With the continuum's curvatures the natural state is therefore not stress-free
/// (the thesis's discretisation: at `ε = 0` each rod of the n = 8 thesis mesh carries about
/// 2e-3 Pcrit); with the discrete ones it is, exactly, at every mesh, as in discrete-rod
/// codes that take the rest curvature from the rest shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Reference {
    /// The curvature of the interpolated natural quaternion field at each quadrature point,
    /// and the natural state's vertices where its chords `∫ d3 ds` put them (from the
    /// base of the helix), so that it is an exact, unloaded equilibrium. The default.
    Discrete,
    /// The helix's own constant curvatures (docs/theory.md §2) and its vertices on the analytic
    /// helix, as in the thesis.
    Continuum,
}

impl Reference {
    /// Name in case files and outputs.
    pub fn name(self) -> &'static str {
        match self {
            Reference::Discrete => "discrete",
            Reference::Continuum => "continuum",
        }
    }
}

/// Energy density `W(u)` (J/m), its gradient `∂W/∂u` (N m) and Hessian `∂²W/∂u²` (N m²).
pub type Density = (f64, Vector3<f64>, Matrix3<f64>);

/// The elastic hypotheses of the rods of an assembly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elasticity {
    pub stress_free: StressFree,
    pub energy: Energy,
}

impl Default for Elasticity {
    /// The thesis's hypotheses: Kirchhoff rods stress-free when helical.
    fn default() -> Elasticity {
        Elasticity {
            stress_free: StressFree::Helix,
            energy: Energy::Kirchhoff,
        }
    }
}

impl Elasticity {
    /// `W(u)` with its first and second derivatives, for stiffness `s` and reference
    /// curvatures `reference` (1/m; zero for rods stress-free when straight, and ignored by
    /// Sadowsky's ribbon, which is stress-free when flat).
    pub fn density(&self, s: &Stiffness, u: &Vector3<f64>, reference: &Vector3<f64>) -> Density {
        match self.energy {
            Energy::Kirchhoff => {
                let b = Vector3::new(s.b1, s.b2, s.b3);
                let e = u - reference;
                let g = b.component_mul(&e);
                (0.5 * e.dot(&g), g, Matrix3::from_diagonal(&b))
            }
            Energy::Sadowsky(ribbon) => sadowsky(s.b1, s.b2, ribbon.regularisation(), u),
        }
    }

    /// One line naming the hypotheses, for output headers and summaries; Sadowsky's names
    /// the regularisation and its source.
    pub fn describe(&self) -> String {
        match self.energy {
            Energy::Kirchhoff => format!(
                "Kirchhoff rods stress-free when {}",
                match self.stress_free {
                    StressFree::Helix => "helical",
                    StressFree::Straight => "straight",
                }
            ),
            Energy::Sadowsky(r) => format!(
                "Sadowsky ribbons stress-free when flat, W = D/2 [k1^2 + 2 om^2 + om^4/(k1^2 + eta^2)] + B2/2 k2^2 (om = twist) \
                 with eta = sqrt(60) t/w^2 = {:.6e} 1/m (w = {} m, t = {} m; rod-ribbon limits of \
                 Audoly & Neukirch, JMPS 2021, twisted-strip term of Green 1936)",
                r.regularisation(),
                r.width,
                r.thickness
            ),
        }
    }
}

/// The regularised Sadowsky density of the module docs with `D = d`, in-plane stiffness
/// `b2` and regularising curvature `eta` (1/m).
fn sadowsky(d: f64, b2: f64, eta: f64, u: &Vector3<f64>) -> Density {
    let (k, k2, t) = (u[0], u[1], u[2]);
    let g = k * k + eta * eta;
    let (t2, t3, t4) = (t * t, t * t * t, t * t * t * t);
    let w = 0.5 * d * (k * k + 2.0 * t2 + t4 / g) + 0.5 * b2 * k2 * k2;
    let grad = Vector3::new(
        d * (k - t4 * k / (g * g)),
        b2 * k2,
        d * (2.0 * t + 2.0 * t3 / g),
    );
    let mut hess = Matrix3::zeros();
    hess[(0, 0)] = d * (1.0 - t4 / (g * g) + 4.0 * t4 * k * k / (g * g * g));
    hess[(0, 2)] = -4.0 * d * t3 * k / (g * g);
    hess[(2, 0)] = hess[(0, 2)];
    hess[(2, 2)] = d * (2.0 + 6.0 * t2 / g);
    hess[(1, 1)] = b2;
    (w, grad, hess)
}
