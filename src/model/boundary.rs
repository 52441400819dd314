//! Boundary conditions at the rod ends (docs/theory.md §3).
//!
//! The axial coordinate of both ends is always prescribed: z = 0 at the base and
//! z = h at the tip (displacement control). What else is held is chosen per end.

use serde::{Deserialize, Serialize};

/// How an end may translate in the plane normal to the assembly axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Translation {
    /// x and y held.
    Fixed,
    /// x and y free: the end slides on its plane (Haringx 1950).
    Slide,
    /// Only the radial direction free: the end slides along the radius through its
    /// position (Olson et al. 2013, deployable antennas).
    Radial,
}

/// Whether the directors of an end are held.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rotation {
    /// Orientation held (clamped).
    Clamped,
    /// Free to rotate (a spherical hinge).
    Free,
    /// Free to rotate about every axis normal to z, the rotation about z held (a ball
    /// joint with the twist locked: the pinned end of Euler's column).
    Pinned,
}

/// Conditions at one end of every rod.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EndCondition {
    pub translation: Translation,
    pub rotation: Rotation,
}

impl EndCondition {
    pub const CLAMPED: EndCondition = EndCondition {
        translation: Translation::Fixed,
        rotation: Rotation::Clamped,
    };

    /// Short label for status lines: e.g. `fixed/clamped`.
    pub fn label(&self) -> String {
        let t = match self.translation {
            Translation::Fixed => "fixed",
            Translation::Slide => "slide",
            Translation::Radial => "radial",
        };
        let r = match self.rotation {
            Rotation::Clamped => "clamped",
            Rotation::Free => "free",
            Rotation::Pinned => "pinned",
        };
        format!("{t}/{r}")
    }
}

/// Boundary conditions of an assembly: the same at every rod's base and tip.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundaryConditions {
    pub base: EndCondition,
    pub tip: EndCondition,
    /// Pin joints at the crossings active.
    pub joints: bool,
}

impl Default for BoundaryConditions {
    /// The thesis's set: both ends clamped, joints on.
    fn default() -> Self {
        BoundaryConditions {
            base: EndCondition::CLAMPED,
            tip: EndCondition::CLAMPED,
            joints: true,
        }
    }
}

impl BoundaryConditions {
    pub fn label(&self) -> String {
        format!(
            "base {} tip {} joints {}",
            self.base.label(),
            self.tip.label(),
            if self.joints { "on" } else { "off" }
        )
    }
}
