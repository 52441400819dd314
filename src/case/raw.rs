//! The layout of a case file as serde reads it: every key optional, unknown keys refused.
//! Values that are checked against a range keep their place in the text (`Spanned`) so
//! that a value out of range can be pointed at.

use super::error::CaseError;
use crate::discretisation::discrete_model::Reference;
use crate::discretisation::shape::Order;
use crate::model::boundary::{Rotation, Translation};
use crate::model::loading::{Branch, Component, Control};
use serde::Deserialize;
use toml::Spanned;

/// A whole case file.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCase {
    pub name: Option<String>,
    #[serde(default)]
    pub geometry: RawGeometry,
    #[serde(default)]
    pub stiffness: RawStiffness,
    #[serde(default)]
    pub rod: RawRod,
    #[serde(default)]
    pub boundary: RawBoundary,
    #[serde(default)]
    pub loading: RawLoading,
    #[serde(default)]
    pub discretisation: RawDiscretisation,
    #[serde(default)]
    pub solver: RawSolver,
    pub imperfection: Option<Spanned<RawImperfection>>,
}

impl RawCase {
    /// Reads the layout of case text: the TOML grammar first, then the keys and the types
    /// of their values. `file` names the text in errors.
    pub fn from_text(text: &str, file: &str) -> Result<RawCase, CaseError> {
        let document =
            toml::Deserializer::parse(text).map_err(|e| CaseError::syntax(&e, text, file))?;
        serde_path_to_error::deserialize(document).map_err(|e| CaseError::layout(&e, text, file))
    }
}

/// `[geometry]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGeometry {
    /// Number of helices `n`.
    pub helices: Option<Spanned<i64>>,
    /// Helix radius `a` (m).
    pub radius: Option<Spanned<f64>>,
    /// Pitch parameter `b` (m).
    pub pitch: Option<Spanned<f64>>,
    /// Number of turns (the length is `2π c` per turn); not with `length`.
    pub turns: Option<Spanned<f64>>,
    /// Rod length `L` (m); not with `turns`.
    pub length: Option<Spanned<f64>>,
}

/// `[stiffness]` (N m²).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawStiffness {
    /// Bending about `d1`.
    pub b1: Option<Spanned<f64>>,
    /// Bending about `d2`.
    pub b2: Option<Spanned<f64>>,
    /// Torsion.
    pub b3: Option<Spanned<f64>>,
}

/// `[rod]`: the elastic hypotheses.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawRod {
    /// `"helix"` or `"straight"`.
    pub stress_free: Option<Spanned<StressFreeName>>,
    /// `"kirchhoff"` or `"sadowsky"`.
    pub energy: Option<Spanned<EnergyName>>,
    /// Ribbon width `w` (m), Sadowsky only.
    pub width: Option<Spanned<f64>>,
    /// Ribbon thickness `t` (m), Sadowsky only.
    pub thickness: Option<Spanned<f64>>,
}

/// The names `rod.stress_free` takes.
#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub(super) enum StressFreeName {
    Helix,
    Straight,
}

/// The names `rod.energy` takes.
#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub(super) enum EnergyName {
    Kirchhoff,
    Sadowsky,
}

/// `[boundary]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBoundary {
    pub base: Option<RawEnd>,
    pub tip: Option<RawEnd>,
    /// The joints at the crossings: `true`/`false` or a kind's name (checked by the tables).
    pub joints: Option<Spanned<toml::Value>>,
    /// The springs of elastic joints.
    pub joint_stiffness: Option<Spanned<RawJointStiffness>>,
}

/// `joint_stiffness = { scissor = …, out_of_plane = … }` (N m/rad).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawJointStiffness {
    pub scissor: Option<Spanned<f64>>,
    pub out_of_plane: Option<Spanned<f64>>,
}

/// One end, `{ translation = …, rotation = … }`; a missing half keeps the thesis's value
/// (`fixed`, `clamped`).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawEnd {
    pub translation: Option<Translation>,
    pub rotation: Option<Rotation>,
}

/// `[loading]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLoading {
    /// The component stepped: `"axial"` (the default), `"twist"`, `"tilt"`, `"pressure"`.
    pub parameter: Option<Component>,
    pub control: Option<Control>,
    /// The values the other components are held at.
    pub hold: Option<RawHold>,
    /// `ε` under displacement control, `P / Pcrit` under load control.
    pub target: Option<Spanned<f64>>,
    /// Number of output steps.
    pub steps: Option<Spanned<i64>>,
    pub branch: Option<Branch>,
}

/// `[loading] hold = { … }`: the held values of the components not stepped.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawHold {
    /// Compression ratio `ε` the tip height is held at; not with `axial_force`.
    pub axial: Option<Spanned<f64>>,
    /// Dead compressive load `P/Pcrit` on every tip (0: free along the axis).
    pub axial_force: Option<Spanned<f64>>,
    /// Twist `φ` (rad).
    pub twist: Option<Spanned<f64>>,
    /// Tilt `θ` (rad).
    pub tilt: Option<Spanned<f64>>,
    /// Radial pressure `q` (N/m, inward).
    pub pressure: Option<Spanned<f64>>,
}

/// `[discretisation]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDiscretisation {
    /// Elements per rod; not with `accuracy`.
    pub elements: Option<Spanned<i64>>,
    pub order: Option<Order>,
    /// Target relative accuracy; not with `elements`.
    pub accuracy: Option<Spanned<f64>>,
    pub symmetric: Option<Spanned<SymmetricKey>>,
    /// `"auto"`, `"pair"`, `"full"` or `"cell"`; not with `symmetric`.
    pub model: Option<ModelKey>,
    /// Reference curvatures: `"discrete"` or `"continuum"`.
    pub reference: Option<Reference>,
}

/// `discretisation.model`: the model that stands for the assembly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum ModelKey {
    Auto,
    Pair,
    Full,
    Cell,
}

/// `discretisation.symmetric`: `true`, `false` or `"auto"`.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum SymmetricKey {
    Flag(bool),
    Word(String),
}

impl<'de> Deserialize<'de> for SymmetricKey {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<SymmetricKey, D::Error> {
        struct Key;
        impl serde::de::Visitor<'_> for Key {
            type Value = SymmetricKey;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("true, false or \"auto\"")
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<SymmetricKey, E> {
                Ok(SymmetricKey::Flag(v))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<SymmetricKey, E> {
                Ok(SymmetricKey::Word(v.to_string()))
            }
        }
        d.deserialize_any(Key)
    }
}

/// `[solver]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSolver {
    /// Newton tolerance on the residual `‖R‖∞`.
    pub tolerance: Option<Spanned<f64>>,
    /// Step lengths of the continuation, in the load parameter.
    pub initial_step: Option<Spanned<f64>>,
    pub max_step: Option<Spanned<f64>>,
    pub min_step: Option<Spanned<f64>>,
    /// Newton iterations per step.
    pub max_iterations: Option<Spanned<i64>>,
}

/// `[imperfection]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawImperfection {
    /// Index of the perfect path's critical point whose mode the flaw follows.
    pub mode: Option<Spanned<i64>>,
    /// A named shape (`"bow"`), checked here so that the names can be offered.
    pub shape: Option<Spanned<toml::Value>>,
    /// `δ`, in rod lengths.
    pub amplitude: Option<Spanned<f64>>,
}
