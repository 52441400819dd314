//! The four components of the loading of a tube (axial, twist, tilt, radial pressure) and
//! the values the ones not stepped are held at.

use serde::{Deserialize, Serialize};

/// A component of the loading of the whole tube: one is stepped by the load parameter, the
/// others are held ([`Held`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Component {
    /// Along the axis: the compression ratio `ε` or the compressive tip load `P/Pcrit`.
    Axial,
    /// The tip support turned about the tube's axis by `φ` (rad).
    Twist,
    /// The tip support turned about the x axis through the tip's centre by `θ` (rad).
    Tilt,
    /// Radial pressure `q` (N/m, inward) on every rod.
    Pressure,
}

impl Component {
    /// Every component, in the order the explorer cycles through them.
    pub const ALL: [Component; 4] = [
        Component::Axial,
        Component::Twist,
        Component::Pressure,
        Component::Tilt,
    ];

    /// Its name in case files and on screen.
    pub fn name(self) -> &'static str {
        match self {
            Component::Axial => "axial",
            Component::Twist => "twist",
            Component::Tilt => "tilt",
            Component::Pressure => "pressure",
        }
    }

    /// Whether a load of this component keeps the tube's cyclic symmetry (the tilt is a
    /// wavenumber-1 load).
    pub fn keeps_cyclic_symmetry(self) -> bool {
        self != Component::Tilt
    }
}

/// The axial component when it is held: at a compression ratio, or under a dead load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AxialHeld {
    /// The tip height held at `h = h0 (1 − ε)`.
    Ratio(f64),
    /// A dead compressive load `P/Pcrit` on every tip (0: the tips free along the axis).
    Load(f64),
}

/// The values at which the components that are not stepped are held.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Held {
    pub axial: AxialHeld,
    /// Twist `φ` (rad).
    pub twist: f64,
    /// Tilt `θ` (rad).
    pub tilt: f64,
    /// Radial pressure `q` (N/m, inward).
    pub pressure: f64,
}

impl Held {
    /// Everything held where it is in the natural state, the tip height included (the
    /// thesis's support).
    pub const NATURAL: Held = Held {
        axial: AxialHeld::Ratio(0.0),
        twist: 0.0,
        tilt: 0.0,
        pressure: 0.0,
    };

    /// Whether every held value is that of the natural state (a free axial position
    /// included: it carries no load).
    pub fn is_natural(&self) -> bool {
        let axial = match self.axial {
            AxialHeld::Ratio(e) | AxialHeld::Load(e) => e,
        };
        axial == 0.0 && self.twist == 0.0 && self.tilt == 0.0 && self.pressure == 0.0
    }
}
