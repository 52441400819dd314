//! Case files (TOML): geometry, stiffness, boundary conditions, loading, discretisation.
//!
//! Every key is optional; a missing key takes the value of the thesis case (§4.1), so a
//! minimal case is a few lines. Unknown keys and bad values are rejected with the file,
//! line, key and what was expected.

use crate::discretisation::element::{Order, Stiffness};
use crate::discretisation::system::DiscreteModel;
use crate::model::assembly::Assembly;
use crate::model::boundary::{BoundaryConditions, EndCondition};
use crate::solver::continuation::{ContinuationSettings, Simulation, SolveError};
use serde::Deserialize;
use std::f64::consts::PI;
use std::fmt;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// The case run by `spira` with no arguments: the thesis assembly of 8 helices.
pub const DEFAULT_CASE: &str = include_str!("../cases/thesis-n8.toml");
/// Name of the default case in messages.
pub const DEFAULT_CASE_NAME: &str = "thesis-n8 (built in)";

/// A validated case.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Name shown in outputs (the file stem unless given).
    pub name: String,
    pub geometry: Geometry,
    pub stiffness: Stiffness,
    pub boundary: BoundaryConditions,
    pub loading: Loading,
    pub discretisation: Discretisation,
    pub solver: ContinuationSettings,
}

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

/// Displacement-controlled loading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loading {
    /// Target compression ratio `ε = (h0 − h)/h0` (negative: extension).
    pub target: f64,
    /// Number of equally spaced output steps in `(0, target]`.
    pub steps: usize,
}

/// Mesh of every rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Discretisation {
    /// Elements per rod (at least; vertices are added at joints).
    pub elements: usize,
    pub order: Order,
}

/// A case-file error: where, which key, what was expected.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("cannot read case file {file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}:{line}: key `{key}`: {message}")]
    Invalid {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
}

impl CaseError {
    /// Line (1-based) the error points at, if any.
    pub fn line(&self) -> Option<usize> {
        match self {
            CaseError::Io { .. } => None,
            CaseError::Syntax { line, .. } | CaseError::Invalid { line, .. } => Some(*line),
        }
    }
    /// The key at fault, if the error is about one.
    pub fn key(&self) -> Option<&str> {
        match self {
            CaseError::Invalid { key, .. } => Some(key),
            _ => None,
        }
    }
}

// ---- raw file layout (serde) ----

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawCase {
    name: Option<String>,
    #[serde(default)]
    geometry: RawGeometry,
    #[serde(default)]
    stiffness: RawStiffness,
    #[serde(default)]
    boundary: RawBoundary,
    #[serde(default)]
    loading: RawLoading,
    #[serde(default)]
    discretisation: RawDiscretisation,
    #[serde(default)]
    solver: RawSolver,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawGeometry {
    helices: Option<Spanned<i64>>,
    radius: Option<Spanned<f64>>,
    pitch: Option<Spanned<f64>>,
    turns: Option<Spanned<f64>>,
    length: Option<Spanned<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawStiffness {
    b1: Option<Spanned<f64>>,
    b2: Option<Spanned<f64>>,
    b3: Option<Spanned<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawBoundary {
    base: Option<EndCondition>,
    tip: Option<EndCondition>,
    joints: Option<bool>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawLoading {
    target: Option<Spanned<f64>>,
    steps: Option<Spanned<i64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawDiscretisation {
    elements: Option<Spanned<i64>>,
    order: Option<Order>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSolver {
    tolerance: Option<Spanned<f64>>,
    initial_step: Option<Spanned<f64>>,
    max_step: Option<Spanned<f64>>,
    min_step: Option<Spanned<f64>>,
    max_iterations: Option<Spanned<i64>>,
}

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

struct Checker<'a> {
    file: &'a str,
    text: &'a str,
}

impl Checker<'_> {
    fn invalid(&self, key: &str, span: Range<usize>, message: impl fmt::Display) -> CaseError {
        CaseError::Invalid {
            file: self.file.to_string(),
            line: line_of(self.text, span.start),
            key: key.to_string(),
            message: message.to_string(),
        }
    }

    /// A finite number satisfying `ok`, or the default.
    fn number(
        &self,
        key: &str,
        v: &Option<Spanned<f64>>,
        default: f64,
        ok: impl Fn(f64) -> bool,
        expected: &str,
    ) -> Result<f64, CaseError> {
        match v {
            None => Ok(default),
            Some(s) if s.get_ref().is_finite() && ok(*s.get_ref()) => Ok(*s.get_ref()),
            Some(s) => Err(self.invalid(
                key,
                s.span(),
                format!("expected {expected}, found {}", s.get_ref()),
            )),
        }
    }

    fn integer(
        &self,
        key: &str,
        v: &Option<Spanned<i64>>,
        default: usize,
        min: i64,
        max: i64,
    ) -> Result<usize, CaseError> {
        match v {
            None => Ok(default),
            Some(s) if (min..=max).contains(s.get_ref()) => Ok(*s.get_ref() as usize),
            Some(s) => Err(self.invalid(
                key,
                s.span(),
                format!(
                    "expected an integer from {min} to {max}, found {}",
                    s.get_ref()
                ),
            )),
        }
    }
}

impl Case {
    /// Reads and validates a case file.
    pub fn from_file(path: &Path) -> Result<Case, CaseError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| CaseError::Io {
            file: file.clone(),
            source,
        })?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "case".into());
        Case::parse(&text, &file, &stem)
    }

    /// The built-in default case (thesis, n = 8).
    pub fn default_case() -> Case {
        Case::parse(DEFAULT_CASE, DEFAULT_CASE_NAME, "thesis-n8")
            .expect("the built-in case is valid")
    }

    /// Parses and validates case text; `file` names it in errors, `stem` is the name used
    /// when the case gives none.
    pub fn parse(text: &str, file: &str, stem: &str) -> Result<Case, CaseError> {
        let raw: RawCase = toml::from_str(text).map_err(|e| CaseError::Syntax {
            file: file.to_string(),
            line: e.span().map(|s| line_of(text, s.start)).unwrap_or(1),
            message: e.message().trim().to_string(),
        })?;
        let ck = Checker { file, text };
        let g = &raw.geometry;
        let helices = ck.integer("geometry.helices", &g.helices, 1, 1, 1024)?;
        if helices > 1 && helices % 2 == 1 {
            let span = g.helices.as_ref().map(|s| s.span()).unwrap_or(0..0);
            return Err(ck.invalid(
                "geometry.helices",
                span,
                format!("expected 1 or an even number (pairs of right- and left-handed helices), found {helices}"),
            ));
        }
        let positive = |v: f64| v > 0.0;
        let radius = ck.number(
            "geometry.radius",
            &g.radius,
            0.06,
            positive,
            "a positive radius in m",
        )?;
        let pitch = ck.number(
            "geometry.pitch",
            &g.pitch,
            0.025,
            positive,
            "a positive pitch parameter b in m",
        )?;
        let c = radius.hypot(pitch);
        let length = match (&g.turns, &g.length) {
            (Some(_), Some(l)) => {
                return Err(ck.invalid(
                    "geometry.length",
                    l.span(),
                    "give either `turns` or `length`, not both",
                ))
            }
            (_, Some(_)) => ck.number(
                "geometry.length",
                &g.length,
                0.0,
                positive,
                "a positive rod length in m",
            )?,
            (t, None) => {
                2.0 * PI
                    * c
                    * ck.number(
                        "geometry.turns",
                        t,
                        3.5,
                        positive,
                        "a positive number of turns",
                    )?
            }
        };
        let geometry = Geometry {
            helices,
            radius,
            pitch,
            length,
        };
        let s = &raw.stiffness;
        let stiffness = Stiffness {
            b1: ck.number(
                "stiffness.b1",
                &s.b1,
                1.0,
                positive,
                "a positive bending stiffness in N m²",
            )?,
            b2: ck.number(
                "stiffness.b2",
                &s.b2,
                1.0,
                positive,
                "a positive bending stiffness in N m²",
            )?,
            b3: ck.number(
                "stiffness.b3",
                &s.b3,
                2.0,
                positive,
                "a positive torsional stiffness in N m²",
            )?,
        };
        let defaults = BoundaryConditions::default();
        let boundary = BoundaryConditions {
            base: raw.boundary.base.unwrap_or(defaults.base),
            tip: raw.boundary.tip.unwrap_or(defaults.tip),
            joints: raw.boundary.joints.unwrap_or(defaults.joints),
        };
        // the tip must stay above the base and below the straightened rod: 0 < h < L
        let h0 = geometry.height0();
        let (lo, hi) = (1.0 - length / h0, 1.0);
        let target = ck.number(
            "loading.target",
            &raw.loading.target,
            0.5,
            |e| e > lo && e < hi,
            &format!("a compression ratio in ({lo:.4}, 1): the tip height h0 (1 − ε) must stay above the base and below the rod length"),
        )?;
        let steps = ck.integer("loading.steps", &raw.loading.steps, 10, 1, 100_000)?;
        let loading = Loading { target, steps };
        let discretisation = Discretisation {
            elements: ck.integer(
                "discretisation.elements",
                &raw.discretisation.elements,
                48,
                1,
                100_000,
            )?,
            order: raw.discretisation.order.unwrap_or(Order::Quadratic),
        };
        let d = ContinuationSettings::default();
        let sv = &raw.solver;
        let mut solver = ContinuationSettings {
            initial_step: ck.number(
                "solver.initial_step",
                &sv.initial_step,
                d.initial_step,
                positive,
                "a positive step in ε",
            )?,
            max_step: ck.number(
                "solver.max_step",
                &sv.max_step,
                d.max_step,
                positive,
                "a positive step in ε",
            )?,
            min_step: ck.number(
                "solver.min_step",
                &sv.min_step,
                d.min_step,
                positive,
                "a positive step in ε",
            )?,
            ..d
        };
        solver.newton.tolerance = ck.number(
            "solver.tolerance",
            &sv.tolerance,
            d.newton.tolerance,
            positive,
            "a positive residual tolerance",
        )?;
        solver.newton.max_iterations = ck.integer(
            "solver.max_iterations",
            &sv.max_iterations,
            d.newton.max_iterations,
            1,
            1000,
        )?;
        if solver.min_step > solver.max_step {
            let span = sv.min_step.as_ref().map(|s| s.span()).unwrap_or(0..0);
            return Err(ck.invalid("solver.min_step", span, "expected min_step ≤ max_step"));
        }
        Ok(Case {
            name: raw.name.unwrap_or_else(|| stem.to_string()),
            geometry,
            stiffness,
            boundary,
            loading,
            discretisation,
            solver,
        })
    }

    /// The same case with `n` helices (what the explorer does when n changes).
    pub fn with_helices(&self, n: usize) -> Case {
        let mut c = self.clone();
        c.geometry.helices = n;
        c
    }

    /// The discrete model of the case.
    pub fn model(&self) -> DiscreteModel {
        let g = &self.geometry;
        DiscreteModel::new(
            Assembly::new(g.helices, g.radius, g.pitch, g.length),
            self.stiffness,
            self.discretisation.elements,
            self.discretisation.order,
        )
    }

    /// A simulation at the natural state (`ε = 0`, solved).
    pub fn simulation(&self) -> Result<Simulation, SolveError> {
        Simulation::new(self.model(), self.boundary, self.solver)
    }

    /// The output compression ratios: `steps` equal increments from 0 (exclusive) to `target`.
    pub fn output_eps(&self, target: f64, steps: usize) -> Vec<f64> {
        (1..=steps)
            .map(|k| target * k as f64 / steps as f64)
            .collect()
    }

    /// Validates a target compression ratio against the geometry (`0 < h < L`).
    pub fn check_target(&self, eps: f64) -> Result<(), String> {
        let h0 = self.geometry.height0();
        let lo = 1.0 - self.geometry.length / h0;
        if eps.is_finite() && eps > lo && eps < 1.0 {
            Ok(())
        } else {
            Err(format!(
                "target compression ratio {eps} is outside ({lo:.4}, 1): the tip height h0 (1 − ε) must stay above the base and below the rod length"
            ))
        }
    }
}
