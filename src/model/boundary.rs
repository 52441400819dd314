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

/// Stiffnesses (N m/rad) of the springs of an elastic joint: `scissor` about the normal to
/// the tube's surface at the crossing (the angle between the rods), `out_of_plane` about the
/// two axes in the surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointStiffness {
    pub scissor: f64,
    pub out_of_plane: f64,
}

/// What the crossings of a right- and a left-handed rod are (docs/theory.md §2).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Joints {
    /// No joints: the rods pass through one another.
    None,
    /// Positions shared, rotations free.
    #[default]
    Pin,
    /// Positions shared, the relative rotation of the two rods held at its natural value.
    Welded,
    /// Positions shared, the relative rotation resisted by springs.
    Elastic(JointStiffness),
    /// The crossing point slides along both rods, without friction: the two rods share a
    /// point whose arc length on each is free, rotations free.
    Sliding,
}

impl Joints {
    /// Whether the crossings tie the rods' positions at all.
    pub fn active(&self) -> bool {
        !matches!(self, Joints::None)
    }

    /// The kind after this one in the cycle pin → welded → elastic → sliding → none → pin;
    /// elastic joints get the springs `springs`.
    pub fn next(&self, springs: JointStiffness) -> Joints {
        match self {
            Joints::Pin => Joints::Welded,
            Joints::Welded => Joints::Elastic(springs),
            Joints::Elastic(_) => Joints::Sliding,
            Joints::Sliding => Joints::None,
            Joints::None => Joints::Pin,
        }
    }

    /// Whether the crossings slide along the rods.
    pub fn slides(&self) -> bool {
        matches!(self, Joints::Sliding)
    }

    /// Short name: `none`, `pin`, `welded`, `elastic`, `sliding`.
    pub fn name(&self) -> &'static str {
        match self {
            Joints::None => "none",
            Joints::Pin => "pin",
            Joints::Welded => "welded",
            Joints::Elastic(_) => "elastic",
            Joints::Sliding => "sliding",
        }
    }
}

/// How joints are written in session scripts: `true`/`false` for pin/none (as before other
/// kinds existed), `"welded"`, or `{ elastic = { scissor, out_of_plane } }`.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum JointsForm {
    Flag(bool),
    Name(JointName),
    Elastic { elastic: JointStiffness },
}

#[derive(Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum JointName {
    None,
    Pin,
    Welded,
    Sliding,
}

impl Serialize for Joints {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Joints::None => JointsForm::Flag(false),
            Joints::Pin => JointsForm::Flag(true),
            Joints::Welded => JointsForm::Name(JointName::Welded),
            Joints::Sliding => JointsForm::Name(JointName::Sliding),
            Joints::Elastic(k) => JointsForm::Elastic { elastic: k },
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Joints {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(match JointsForm::deserialize(d)? {
            JointsForm::Flag(false) | JointsForm::Name(JointName::None) => Joints::None,
            JointsForm::Flag(true) | JointsForm::Name(JointName::Pin) => Joints::Pin,
            JointsForm::Name(JointName::Welded) => Joints::Welded,
            JointsForm::Name(JointName::Sliding) => Joints::Sliding,
            JointsForm::Elastic { elastic } => Joints::Elastic(elastic),
        })
    }
}

/// Boundary conditions of an assembly: the same at every rod's base and tip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundaryConditions {
    pub base: EndCondition,
    pub tip: EndCondition,
    /// What the crossings are.
    pub joints: Joints,
}

impl Default for BoundaryConditions {
    /// The thesis's set: both ends clamped, joints on.
    fn default() -> Self {
        BoundaryConditions {
            base: EndCondition::CLAMPED,
            tip: EndCondition::CLAMPED,
            joints: Joints::Pin,
        }
    }
}

impl BoundaryConditions {
    pub fn label(&self) -> String {
        format!(
            "base {} tip {} joints {}",
            self.base.label(),
            self.tip.label(),
            self.joints_label()
        )
    }

    /// The joints as status lines say them: `on` for pins (as before other kinds existed),
    /// `off` without, else the kind.
    pub fn joints_label(&self) -> &'static str {
        match self.joints {
            Joints::Pin => "on",
            Joints::None => "off",
            other => other.name(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Session scripts write the conditions as TOML: pins and none as the flags they were
    /// before other kinds existed, and every kind reads back as itself.
    #[test]
    fn joints_are_written_as_flags_names_and_springs_and_read_back() {
        let springs = JointStiffness {
            scissor: 0.5,
            out_of_plane: 2.0,
        };
        for (joints, written) in [
            (Joints::Pin, "joints = true"),
            (Joints::None, "joints = false"),
            (Joints::Welded, "joints = \"welded\""),
            (Joints::Elastic(springs), "[joints.elastic]"),
        ] {
            let bc = BoundaryConditions {
                joints,
                ..BoundaryConditions::default()
            };
            let text = toml::to_string(&bc).expect("conditions as TOML");
            assert!(text.contains(written), "{text}");
            let back: BoundaryConditions = toml::from_str(&text).expect("read back");
            assert_eq!(back, bc);
        }
    }
}
