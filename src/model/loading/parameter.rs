//! What the load parameter is: what it drives, by which control, and how the faces name it.

use super::support::SupportAxis;
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

/// What the load parameter `λ` drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Driven {
    /// An axis of the tip support, by its motion or by a dead load on it.
    Tip(SupportAxis),
    /// The loads along the rods.
    AlongRods,
    /// The held loads of a path stepped otherwise, brought from zero (`λ = 0`) to their
    /// values (`λ = 1`) before it starts.
    Held,
}

/// What the load parameter `λ` is: what it drives and whether by motion or force. The faces
/// print its symbol, unit and label instead of assuming `ε`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadParameter {
    pub driven: Driven,
    pub control: Control,
}

impl LoadParameter {
    /// The axial parameter of `control`: `ε` or `P/Pcrit`.
    pub fn axial(control: Control) -> LoadParameter {
        LoadParameter {
            driven: Driven::Tip(SupportAxis::Z),
            control,
        }
    }

    /// Its symbol on screen: `ε`, `P/Pcrit`, `θ`, `q` …
    pub fn symbol(&self) -> &'static str {
        use SupportAxis::*;
        match (self.driven, self.control) {
            (Driven::Tip(Z), Control::Displacement) => "ε",
            (Driven::Tip(Z), Control::Force) => "P/Pcrit",
            (Driven::Tip(X | Y), Control::Displacement) => "u",
            (Driven::Tip(X | Y), Control::Force) => "F",
            (Driven::Tip(RotZ), Control::Displacement) => "φ",
            (Driven::Tip(RotZ), Control::Force) => "T",
            (Driven::Tip(_), Control::Displacement) => "θ",
            (Driven::Tip(_), Control::Force) => "M",
            (Driven::AlongRods, _) => "q",
            (Driven::Held, _) => "s",
        }
    }

    /// The symbol of the motion of what it drives, which a load curve takes for its abscissa
    /// under either control: the compression ratio `ε` for the axial load (a dead load's
    /// curve is drawn against the motion it causes, not against itself).
    pub fn motion_symbol(&self) -> &'static str {
        use SupportAxis::*;
        match self.driven {
            Driven::Tip(Z) => "ε",
            Driven::AlongRods => "a",
            Driven::Held => "s",
            Driven::Tip(X | Y) => "u",
            Driven::Tip(RotZ) => "φ",
            Driven::Tip(RotX | RotY) => "θ",
        }
    }

    /// Its name in plain ASCII, for files and command lines: `eps`, `P/Pcrit`, `theta` …
    pub fn ascii(&self) -> &'static str {
        match self.symbol() {
            "ε" => "eps",
            "θ" => "theta",
            "φ" => "phi",
            other => other,
        }
    }

    /// Its unit (empty for a ratio).
    pub fn unit(&self) -> &'static str {
        use SupportAxis::*;
        match (self.driven, self.control) {
            (Driven::Tip(Z), _) => "",
            (Driven::Tip(X | Y), Control::Displacement) => "m",
            (Driven::Tip(X | Y), Control::Force) => "N",
            (Driven::Tip(_), Control::Displacement) => "rad",
            (Driven::Tip(_), Control::Force) => "N m",
            (Driven::AlongRods, _) => "N/m",
            (Driven::Held, _) => "",
        }
    }

    /// What it is, in words: `compression ratio`, `compressive tip load over Pcrit` …
    pub fn label(&self) -> &'static str {
        use SupportAxis::*;
        match (self.driven, self.control) {
            (Driven::Tip(Z), Control::Displacement) => "compression ratio",
            (Driven::Tip(Z), Control::Force) => "compressive tip load over Pcrit",
            (Driven::Tip(X | Y), Control::Displacement) => "lateral tip displacement",
            (Driven::Tip(X | Y), Control::Force) => "lateral tip force",
            (Driven::Tip(RotZ), Control::Displacement) => "twist angle",
            (Driven::Tip(RotZ), Control::Force) => "axial torque",
            (Driven::Tip(_), Control::Displacement) => "tilt angle",
            (Driven::Tip(_), Control::Force) => "bending moment",
            (Driven::AlongRods, _) => "line load",
            (Driven::Held, _) => "fraction of the held loads",
        }
    }
}
