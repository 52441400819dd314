//! The values a case sets, table by table, once read and checked: the geometry of the
//! assembly, its loading and the mesh of its rods.

use crate::discretisation::discrete_model::Reference;
use crate::discretisation::shape::Order;
use crate::model::loading::{Branch, Component, Control, Held};
use std::f64::consts::PI;

/// Assembly geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Number of helices `n`: 1, or even (half right-, half left-handed).
    pub helices: usize,
    /// Helix radius `a` (m).
    pub radius: f64,
    /// Pitch parameter `b` (m): the helix rises `2π b` per turn.
    pub pitch: f64,
    /// Rod length `L` (m).
    pub length: f64,
}

impl Geometry {
    /// `c = √(a² + b²)` (m).
    pub fn c(&self) -> f64 {
        self.radius.hypot(self.pitch)
    }
    /// Initial tip height `h0 = b L / c` (m).
    pub fn height0(&self) -> f64 {
        self.pitch * self.length / self.c()
    }
    /// Number of turns `L / (2π c)`.
    pub fn turns(&self) -> f64 {
        self.length / (2.0 * PI * self.c())
    }
}

/// The loading: what is controlled, up to where, and which branch is followed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loading {
    /// The component the load parameter steps (axial by default).
    pub parameter: Component,
    /// The values the other components are held at.
    pub hold: Held,
    /// Displacement control (tip height) or load control (dead load on the tips).
    pub control: Control,
    /// Target load parameter: the compression ratio `ε = (h0 − h)/h0` (negative:
    /// extension) under displacement control, `P / Pcrit` (compressive tip force per rod
    /// over `B1 (2π/L)²`; negative: tension) under load control.
    pub target: f64,
    /// Number of equally spaced output steps in `(0, target]`.
    pub steps: usize,
    /// At the first bifurcation: stay on the fundamental branch or switch.
    pub branch: Branch,
}

/// Mesh of every rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Discretisation {
    /// Elements per rod (at least; vertices are added at joints).
    pub elements: usize,
    pub order: Order,
    /// A target accuracy given instead of a mesh (`accuracy` key). While it is set,
    /// `elements` and `order` are placeholders: `study::resolve_accuracy` replaces them
    /// by the mesh it chooses (and clears this) before anything is solved.
    pub accuracy: Option<AccuracyTarget>,
    /// Solve one right/left pair and take the other rods as its images (the assembly's
    /// `m`-fold rotational symmetry, `n = 2m`, `m ≥ 2`); stability is judged on the whole
    /// assembly by the pair's Bloch blocks. Key `symmetric`: `true`, `false`, or `"auto"`
    /// (the default: the pair wherever the assembly has the symmetry, unless the case
    /// switches branches, which may leave the symmetry).
    pub symmetric: bool,
    /// Whether `symmetric` was chosen automatically (and is chosen again when the number
    /// of helices changes).
    pub symmetric_auto: bool,
    /// Solve the cell of the infinitely long tube of the case's helices instead of the
    /// finite assembly (key `model = "cell"`, docs/theory.md §8): the geometry's length and
    /// the supports are not used, the axial strain, the twist per cell and a radial
    /// pressure load it.
    pub cell: bool,
    /// Where the reference curvatures of helical rods come from (key `reference`,
    /// default `"discrete"`: the natural state is exactly stress-free).
    pub reference: Reference,
}

/// A relative accuracy asked of the response (the axial reaction `Fz` at the target under
/// displacement control, `ε` under load control).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccuracyTarget {
    /// Relative error allowed, in (0, 1).
    pub target: f64,
    /// The element order when the case names one; otherwise both are tried.
    pub order: Option<Order>,
}

impl Loading {
    /// Whether the tip's height is held (the axial component a prescribed motion): not
    /// under a dead axial load, stepped or held.
    pub fn tip_height_held(&self) -> bool {
        match self.parameter {
            Component::Axial => self.control == Control::Displacement,
            _ => matches!(self.hold.axial, crate::model::loading::AxialHeld::Ratio(_)),
        }
    }
}
