//! How an assembly is loaded (DESIGN.md §3): the control of the load parameter, what a path
//! does at a bifurcation, and the axial loading of the tips it sets.

use serde::{Deserialize, Serialize};

/// What the load parameter `λ` prescribes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Control {
    /// Tip height prescribed: `λ = ε = (h0 − h)/h0`, the compression ratio.
    Displacement,
    /// Dead compressive load `P = λ Pcrit` on every tip, along −z.
    Force,
}

impl Control {
    pub fn name(self) -> &'static str {
        match self {
            Control::Displacement => "displacement",
            Control::Force => "force",
        }
    }
}

/// What a path does at its first bifurcation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Branch {
    /// Stay on the fundamental branch (critical points are only reported).
    Fundamental,
    /// Switch to the bifurcated branch along the critical mode.
    Switch,
    /// Switch along the opposite of the critical mode.
    SwitchNegative,
}

impl Branch {
    /// The direction (±1) along the critical mode in which the path leaves the fundamental
    /// branch, if it does.
    pub fn direction(self) -> Option<f64> {
        match self {
            Branch::Fundamental => None,
            Branch::Switch => Some(1.0),
            Branch::SwitchNegative => Some(-1.0),
        }
    }
}

/// How the tips are loaded along the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipLoad {
    /// Displacement control: every tip held at height `z = h` (m).
    Height(f64),
    /// Load control: a dead compressive force `P` (N) on every tip, along −z.
    Force(f64),
}

impl TipLoad {
    /// The tip loading at load parameter `lambda`: height `h0 (1 − λ)` (m) under
    /// displacement control, force `λ Pcrit` (N) under load control.
    pub fn at(control: Control, lambda: f64, height0: f64, pcrit: f64) -> TipLoad {
        match control {
            Control::Displacement => TipLoad::Height(height0 * (1.0 - lambda)),
            Control::Force => TipLoad::Force(lambda * pcrit),
        }
    }

    /// `d(h or P)/dλ`: `−h0` (m) under displacement control, `Pcrit` (N) under load control.
    pub fn rate(control: Control, height0: f64, pcrit: f64) -> f64 {
        match control {
            Control::Displacement => -height0,
            Control::Force => pcrit,
        }
    }
}
