//! Case files (TOML): geometry, stiffness, boundary conditions, loading, discretisation.
//!
//! Every key is optional; a missing key takes the value of the thesis case (§4.1), so a
//! minimal case is a few lines. Unknown keys and bad values are rejected with the file,
//! line, key and what was expected.

use crate::discretisation::model::DiscreteModel;
use crate::discretisation::shape::Order;
use crate::model::assembly::Assembly;
use crate::model::boundary::{BoundaryConditions, EndCondition, Rotation, Translation};
use crate::model::loading::{Branch, Control};
use crate::model::stiffness::Stiffness;
use crate::solver::continuation::ContinuationSettings;
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
    /// `elements` and `order` are placeholders: `precision::resolve_accuracy` replaces them
    /// by the mesh it chooses (and clears this) before anything is solved.
    pub accuracy: Option<Accuracy>,
    /// Solve one right/left pair and take the other rods as its images (the assembly's
    /// `m`-fold rotational symmetry, `n = 2m`, `m ≥ 2`); stability is still judged on the
    /// full model. Key `symmetric`, default false.
    pub symmetric: bool,
}

/// A relative accuracy asked of the response (the axial reaction `Fz` at the target under
/// displacement control, `ε` under load control): issue 5, part 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    /// Relative error allowed, in (0, 1).
    pub target: f64,
    /// The element order when the case names one; otherwise both are tried.
    pub order: Option<Order>,
}

/// A case-file error: where, which key, what was expected. Every variant displays as one
/// line: the file and line, the key (dotted, e.g. `geometry.radius`), what was expected and
/// what was found.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// The file cannot be read.
    #[error("cannot read case file {file}: {reason}")]
    Io {
        file: String,
        /// Kept out of the error chain: the message already says it, and a report that
        /// walks the chain would say it twice.
        reason: std::io::Error,
    },
    /// Not TOML: an unclosed bracket, a missing value, a duplicate key.
    #[error("{file}:{line}: not valid TOML: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    /// A key or table that is not part of a case file (usually a typo); `key` is its full
    /// dotted path.
    #[error("{file}:{line}: key `{key}`: {message}")]
    UnknownKey {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
    /// A value of the wrong type (a string for a number, a fraction for a whole number) or
    /// a name that is not one of the allowed ones.
    #[error("{file}:{line}: key `{key}`: {message}")]
    WrongType {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
    /// A value of the right type but outside its physical or numerical range.
    #[error("{file}:{line}: key `{key}`: {message}")]
    Invalid {
        file: String,
        line: usize,
        key: String,
        message: String,
    },
}

impl CaseError {
    /// The file the error is about.
    pub fn file(&self) -> &str {
        match self {
            CaseError::Io { file, .. }
            | CaseError::Syntax { file, .. }
            | CaseError::UnknownKey { file, .. }
            | CaseError::WrongType { file, .. }
            | CaseError::Invalid { file, .. } => file,
        }
    }
    /// Line (1-based) the error points at, if any.
    pub fn line(&self) -> Option<usize> {
        match self {
            CaseError::Io { .. } => None,
            CaseError::Syntax { line, .. }
            | CaseError::UnknownKey { line, .. }
            | CaseError::WrongType { line, .. }
            | CaseError::Invalid { line, .. } => Some(*line),
        }
    }
    /// The key at fault (dotted path, e.g. `geometry.radius`), if the error is about one.
    pub fn key(&self) -> Option<&str> {
        match self {
            CaseError::UnknownKey { key, .. }
            | CaseError::WrongType { key, .. }
            | CaseError::Invalid { key, .. } => Some(key),
            CaseError::Io { .. } | CaseError::Syntax { .. } => None,
        }
    }
    /// What was expected and what was found, without the location.
    pub fn message(&self) -> String {
        match self {
            CaseError::Io { reason, .. } => reason.to_string(),
            CaseError::Syntax { message, .. }
            | CaseError::UnknownKey { message, .. }
            | CaseError::WrongType { message, .. }
            | CaseError::Invalid { message, .. } => message.clone(),
        }
    }

    /// Sorts an error of the `toml` crate: grammar errors are [`CaseError::Syntax`];
    /// errors against the layout of [`RawCase`] name their key.
    fn from_toml(e: &toml::de::Error, text: &str, file: &str, grammar: bool) -> CaseError {
        let span = e.span().unwrap_or(0..0);
        let line = line_of(text, span.start);
        let file = file.to_string();
        let message = plain_types(e.message().trim());
        if grammar {
            return CaseError::Syntax {
                file,
                line,
                message,
            };
        }
        let mut keys = error_keys(e);
        if message.starts_with("unknown field") {
            // the span is the offending key itself; the path held by the error is its table's
            let name = text.get(span.clone()).unwrap_or("").trim();
            let name = name.trim_matches(|c| c == '"' || c == '\'');
            let header = text[..span.start.min(text.len())]
                .rsplit('\n')
                .next()
                .is_some_and(|before| before.trim_start().starts_with('['));
            keys.push(name.to_string());
            let key = keys.join(".");
            let message = if header {
                message.replacen(
                    &format!("unknown field `{name}`"),
                    &format!("unknown table `[{key}]`"),
                    1,
                )
            } else {
                message
            };
            return CaseError::UnknownKey {
                file,
                line,
                key,
                message,
            };
        }
        let line_text = text.lines().nth(line - 1).unwrap_or("");
        if line_text.trim_start().starts_with("[[") {
            // serde would read the array as the fields of the table in order, and complain
            // about the first field
            let name = keys.join(".");
            let message =
                format!("expected a table `[{name}]`, found an array of tables `[[{name}]]`");
            return CaseError::WrongType {
                file,
                line,
                key: name,
                message,
            };
        }
        if keys.is_empty() {
            return CaseError::Syntax {
                file,
                line,
                message,
            };
        }
        CaseError::WrongType {
            file,
            line,
            key: keys.join("."),
            message,
        }
    }
}

/// The path of keys down to the value a `toml` error is about. The error keeps it but shows
/// it only when it has no source text to point into (as a last line ``in `a.b` ``), so it
/// is rendered that way and read back.
fn error_keys(e: &toml::de::Error) -> Vec<String> {
    let mut bare = e.clone();
    bare.set_input(None);
    bare.to_string()
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("in `")?.strip_suffix('`'))
        .map(|k| k.split('.').map(str::to_string).collect())
        .unwrap_or_default()
}

/// serde names Rust types in its messages; a case file has numbers, whole numbers, arrays
/// and tables.
fn plain_types(message: &str) -> String {
    let mut m = message
        .replace("expected i64", "expected a whole number")
        .replace("expected f64", "expected a number")
        .replace("expected a boolean", "expected true or false")
        .replace("invalid type: map", "invalid type: table")
        .replace("invalid type: sequence", "invalid type: array");
    // `expected struct RawGeometry` and the like
    while let Some(at) = m.find("expected struct Raw") {
        let end = m[at..]
            .find(|c: char| !(c.is_alphanumeric() || c == ' '))
            .map_or(m.len(), |e| at + e);
        m.replace_range(at..end, "expected a table");
    }
    m
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
    base: Option<RawEnd>,
    tip: Option<RawEnd>,
    joints: Option<bool>,
}

/// One end; a missing half keeps the thesis's value (`fixed`, `clamped`).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawEnd {
    translation: Option<Translation>,
    rotation: Option<Rotation>,
}

impl RawEnd {
    fn or(end: &Option<RawEnd>, default: EndCondition) -> EndCondition {
        match end {
            None => default,
            Some(e) => EndCondition {
                translation: e.translation.unwrap_or(default.translation),
                rotation: e.rotation.unwrap_or(default.rotation),
            },
        }
    }
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawLoading {
    control: Option<Control>,
    target: Option<Spanned<f64>>,
    steps: Option<Spanned<i64>>,
    branch: Option<Branch>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawDiscretisation {
    elements: Option<Spanned<i64>>,
    order: Option<Order>,
    accuracy: Option<Spanned<f64>>,
    symmetric: Option<Spanned<bool>>,
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

    /// A whole number in `min..=max`, or the default; `what` names it in the message.
    fn integer(
        &self,
        key: &str,
        v: &Option<Spanned<i64>>,
        default: usize,
        (min, max): (i64, i64),
        what: &str,
    ) -> Result<usize, CaseError> {
        match v {
            None => Ok(default),
            Some(s) if (min..=max).contains(s.get_ref()) => Ok(*s.get_ref() as usize),
            Some(s) => Err(self.invalid(
                key,
                s.span(),
                format!("expected {what} from {min} to {max}, found {}", s.get_ref()),
            )),
        }
    }
}

impl Case {
    /// Reads and validates a case file.
    pub fn from_file(path: &Path) -> Result<Case, CaseError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|reason| CaseError::Io {
            file: file.clone(),
            reason,
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
        // grammar first, then the layout: the two kinds of error read differently
        let document = toml::Deserializer::parse(text)
            .map_err(|e| CaseError::from_toml(&e, text, file, true))?;
        let raw = RawCase::deserialize(document)
            .map_err(|e| CaseError::from_toml(&e, text, file, false))?;
        let ck = Checker { file, text };
        let g = &raw.geometry;
        let helices = ck.integer(
            "geometry.helices",
            &g.helices,
            1,
            (1, 1024),
            "a number of helices",
        )?;
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
            |v| v >= 0.0,
            "a positive radius in m (0 for a straight rod)",
        )?;
        if radius == 0.0 && helices > 1 {
            let span = g.radius.as_ref().map(|s| s.span()).unwrap_or(0..0);
            return Err(ck.invalid(
                "geometry.radius",
                span,
                format!("a straight rod (radius 0) needs helices = 1, found {helices}"),
            ));
        }
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
            base: RawEnd::or(&raw.boundary.base, defaults.base),
            tip: RawEnd::or(&raw.boundary.tip, defaults.tip),
            joints: raw.boundary.joints.unwrap_or(defaults.joints),
        };
        let control = raw.loading.control.unwrap_or(Control::Displacement);
        let target = match &raw.loading.target {
            None => 0.5,
            Some(t) => match target_problem(&geometry, control, *t.get_ref()) {
                None => *t.get_ref(),
                Some(message) => return Err(ck.invalid("loading.target", t.span(), message)),
            },
        };
        let steps = ck.integer(
            "loading.steps",
            &raw.loading.steps,
            10,
            (1, 100_000),
            "a number of output steps",
        )?;
        let loading = Loading {
            control,
            target,
            steps,
            branch: raw.loading.branch.unwrap_or(Branch::Fundamental),
        };
        let rd = &raw.discretisation;
        let accuracy = match (&rd.accuracy, &rd.elements) {
            (Some(a), Some(_)) => {
                return Err(ck.invalid(
                    "discretisation.accuracy",
                    a.span(),
                    "give either `elements` (a mesh) or `accuracy` (a target the mesh is chosen for), not both",
                ))
            }
            (Some(_), None) => Some(Accuracy {
                target: ck.number(
                    "discretisation.accuracy",
                    &rd.accuracy,
                    0.0,
                    |v| v > 0.0 && v < 1.0,
                    "a relative accuracy between 0 and 1 (e.g. 1e-3)",
                )?,
                order: rd.order,
            }),
            (None, _) => None,
        };
        let discretisation = Discretisation {
            elements: ck.integer(
                "discretisation.elements",
                &rd.elements,
                48,
                (1, 100_000),
                "a number of elements per rod",
            )?,
            order: rd.order.unwrap_or(Order::Quadratic),
            accuracy,
            symmetric: match &rd.symmetric {
                Some(flag) if *flag.get_ref() && (helices < 4 || helices % 2 == 1) => {
                    return Err(ck.invalid(
                        "discretisation.symmetric",
                        flag.span(),
                        format!("expected false: {helices} helix(es) have no rotational symmetry to reduce (it needs n = 2m helices with m ≥ 2)"),
                    ))
                }
                Some(flag) => *flag.get_ref(),
                None => false,
            },
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
            (1, 1000),
            "a number of Newton iterations",
        )?;
        if solver.min_step > solver.max_step {
            // point at whichever of the two the file gives (both defaults are consistent)
            let (key, span) = match (&sv.min_step, &sv.max_step) {
                (Some(s), _) => ("solver.min_step", s.span()),
                (None, Some(s)) => ("solver.max_step", s.span()),
                (None, None) => ("solver.min_step", 0..0),
            };
            return Err(ck.invalid(
                key,
                span,
                format!(
                    "expected min_step ≤ max_step, found min_step = {} and max_step = {}",
                    solver.min_step, solver.max_step
                ),
            ));
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
        // the symmetric reduction needs n = 2m, m ≥ 2
        c.discretisation.symmetric &= n >= 4 && n % 2 == 0;
        c
    }

    /// The case as the explorer solves it interactively (issue 5, "a model no bigger than
    /// the scene"): one symmetric pair standing for the assembly when it has the symmetry,
    /// and stability as the count of unstable directions only (on the full model), without
    /// the lowest eigenvalue. Everything shown is still of the whole assembly.
    pub fn for_explorer(&self) -> Case {
        let mut c = self.clone();
        let n = c.geometry.helices;
        c.discretisation.symmetric |= n >= 4 && n % 2 == 0;
        c.solver.lowest_eigenvalue = false;
        c
    }

    /// The discrete model of the case.
    pub fn model(&self) -> DiscreteModel {
        let g = &self.geometry;
        let full = Assembly::new(g.helices, g.radius, g.pitch, g.length);
        let assembly = if self.discretisation.symmetric {
            full.symmetric_pair()
                .expect("validated: the case has the symmetry")
        } else {
            full
        };
        DiscreteModel::new(
            assembly,
            self.stiffness,
            self.discretisation.elements,
            self.discretisation.order,
        )
    }

    /// The output compression ratios: `steps` equal increments from 0 (exclusive) to `target`.
    /// The fraction is formed first so that the last value is `target` exactly.
    pub fn output_eps(&self, target: f64, steps: usize) -> Vec<f64> {
        (1..=steps)
            .map(|k| target * (k as f64 / steps as f64))
            .collect()
    }

    /// Validates a target compression ratio against the geometry (`0 < h < L`); the error
    /// says which limit is crossed.
    pub fn check_target(&self, eps: f64) -> Result<(), String> {
        match target_problem(&self.geometry, self.loading.control, eps) {
            None => Ok(()),
            Some(message) => Err(message),
        }
    }
}

/// Why `eps` is not a reachable compression ratio for `geometry`, if it is not. The tip
/// height `h = h0 (1 − ε)` must stay above the base (`h > 0`, `ε < 1`) and below the length
/// of the rod pulled straight (`h < L`, `ε > 1 − L/h0`): both limits are singular states.
fn target_problem(geometry: &Geometry, control: Control, eps: f64) -> Option<String> {
    if control == Control::Force {
        return (!eps.is_finite()).then(|| format!("expected a finite load P/Pcrit, found {eps}"));
    }
    let h0 = geometry.height0();
    let length = geometry.length;
    let lo = 1.0 - length / h0;
    let range = format!(
        "expected a compression ratio ε = (h0 − h)/h0 in ({}, 1)",
        short(lo)
    );
    if !eps.is_finite() {
        return Some(format!("{range}, found {eps}"));
    }
    let h = h0 * (1.0 - eps);
    let at = format!("the tip would be at height h = h0 (1 − ε) = {} m", short(h));
    let why = if eps >= 1.0 {
        let place = if eps == 1.0 { "on" } else { "below" };
        format!("{at}, {place} the base")
    } else if eps <= lo {
        let place = if eps == lo { "equal to" } else { "beyond" };
        format!(
            "{at}, {place} the rod length L = {} m (the rod pulled straight; h0 = {} m)",
            short(length),
            short(h0)
        )
    } else {
        return None;
    };
    Some(format!("{range}, found {eps}: {why}"))
}

/// A number to 6 significant figures without trailing zeros, for messages.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (5 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}
