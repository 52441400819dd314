//! The values of each table of a case file checked against their ranges, with the thesis
//! case (§4.1) filling in what is not given. One function per table.

use super::error::{line_of, CaseError};
use super::helices::{elements_message, helices_message, joints_message, straight_rod_message};
use super::limits::*;
use super::motion::free_motion_of;
use super::raw::{
    EnergyName, RawBoundary, RawDiscretisation, RawEnd, RawGeometry, RawRod, RawSolver,
    RawStiffness, StressFreeName, SymmetricKey,
};
use super::settings::{AccuracyTarget, Discretisation, Geometry};
use crate::discretisation::discrete_model::Reference;
use crate::discretisation::shape::Order;
use crate::model::boundary::{BoundaryConditions, EndCondition};
use crate::model::elasticity::{Elasticity, Energy, Ribbon, StressFree};
use crate::model::stiffness::Stiffness;
use crate::solver::continuation::ContinuationSettings;
use std::f64::consts::PI;
use std::fmt;
use std::ops::Range;
use toml::Spanned;

/// `[geometry]`: the number of helices, the helix radius `a` and pitch parameter `b` (m),
/// and the rod length `L` (m), given as such or as a number of turns `L / (2π c)`.
pub(super) fn geometry(g: &RawGeometry, ck: &Checker) -> Result<Geometry, CaseError> {
    let helices = helices(g, ck)?;
    let radius = ck.number(
        "geometry.radius",
        &g.radius,
        0.06,
        |a| a == 0.0 || in_range(a, LENGTH_RANGE),
        &format!(
            "a positive radius in m {} (0 for a straight rod)",
            range(LENGTH_RANGE)
        ),
    )?;
    let straight = Geometry {
        helices,
        radius,
        pitch: 1.0,
        length: 1.0,
    };
    if let Some(m) = straight_rod_message(&straight) {
        return Err(ck.invalid("geometry.radius", span(&g.radius), m));
    }
    let pitch = ck.number(
        "geometry.pitch",
        &g.pitch,
        0.025,
        |b| in_range(b, LENGTH_RANGE),
        &format!("a positive pitch parameter b in m {}", range(LENGTH_RANGE)),
    )?;
    if radius > 0.0 && !in_range(pitch / radius, PITCH_RATIO) {
        let (key, at) = if g.pitch.is_some() {
            ("geometry.pitch", span(&g.pitch))
        } else {
            ("geometry.radius", span(&g.radius))
        };
        return Err(ck.invalid(
            key,
            at,
            format!(
                "expected a pitch/radius ratio b/a from {} to {}, found {} (b = {} m, a = {} m)",
                PITCH_RATIO.0,
                PITCH_RATIO.1,
                num(pitch / radius),
                num(pitch),
                num(radius)
            ),
        ));
    }
    let length = rod_length(g, radius.hypot(pitch), ck)?;
    let geometry = Geometry {
        helices,
        radius,
        pitch,
        length,
    };
    derived_geometry(g, &geometry, ck)?;
    Ok(geometry)
}

/// The quantities derived from the geometry: the rod length `L` within
/// [`LENGTH_RANGE`], the number of turns within [`TURNS_RANGE`] (a helix), the initial
/// height `h0` finite and positive, and the number of joints at most [`MAX_JOINTS`].
fn derived_geometry(g: &RawGeometry, geometry: &Geometry, ck: &Checker) -> Result<(), CaseError> {
    // the key the length comes from
    let (key, at) = if g.length.is_some() {
        ("geometry.length", span(&g.length))
    } else if g.turns.is_some() {
        ("geometry.turns", span(&g.turns))
    } else if g.radius.is_some() {
        ("geometry.radius", span(&g.radius))
    } else {
        ("geometry.pitch", span(&g.pitch))
    };
    let length = geometry.length;
    if !in_range(length, LENGTH_RANGE) {
        return Err(ck.invalid(
            key,
            at,
            format!(
                "the rod length L would be {} m; expected L {} m",
                num(length),
                range(LENGTH_RANGE)
            ),
        ));
    }
    if geometry.radius > 0.0 {
        let turns = geometry.turns();
        if !in_range(turns, TURNS_RANGE) {
            return Err(ck.invalid(
                key,
                at,
                format!(
                    "the helices would have {} turns (L = {} m); expected from {} to {} turns",
                    num(turns),
                    num(length),
                    TURNS_RANGE.0,
                    TURNS_RANGE.1
                ),
            ));
        }
    }
    let h0 = geometry.height0();
    if !(h0.is_finite() && h0 > 0.0) {
        return Err(ck.invalid(
            key,
            at,
            format!("the initial height h0 = b L / c would be {}", num(h0)),
        ));
    }
    if let Some(m) = joints_message(geometry) {
        let (key, at) = if g.helices.is_some() {
            ("geometry.helices", span(&g.helices))
        } else {
            (key, at)
        };
        return Err(ck.invalid(key, at, m));
    }
    Ok(())
}

/// `geometry.helices`: 1, or an even number (as many right- as left-handed helices).
fn helices(g: &RawGeometry, ck: &Checker) -> Result<usize, CaseError> {
    let Some(v) = &g.helices else {
        return Ok(1);
    };
    match helices_message(*v.get_ref()) {
        Some(m) => Err(ck.invalid("geometry.helices", v.span(), m)),
        // in HELICES_RANGE: positive and small
        None => Ok(*v.get_ref() as usize),
    }
}

/// The rod length `L` (m) from `geometry.length`, or from `geometry.turns` (3.5 by default)
/// as `2π c` per turn, `c = √(a² + b²)` (m); not both.
fn rod_length(g: &RawGeometry, c: f64, ck: &Checker) -> Result<f64, CaseError> {
    match (&g.turns, &g.length) {
        (Some(_), Some(length)) => Err(ck.invalid(
            "geometry.length",
            length.span(),
            "give either `turns` or `length`, not both",
        )),
        (None, Some(_)) => ck.number(
            "geometry.length",
            &g.length,
            0.0,
            |l| in_range(l, LENGTH_RANGE),
            &format!("a positive rod length in m {}", range(LENGTH_RANGE)),
        ),
        (turns, None) => {
            let turns = ck.number(
                "geometry.turns",
                turns,
                3.5,
                |t| in_range(t, TURNS_RANGE),
                &format!(
                    "a number of turns from {} to {}",
                    TURNS_RANGE.0, TURNS_RANGE.1
                ),
            )?;
            Ok(2.0 * PI * c * turns)
        }
    }
}

/// `[stiffness]`: bending stiffnesses `B1`, `B2` about `d1`, `d2` and torsional stiffness
/// `B3` (N m²); the thesis's 1, 1, 2.
pub(super) fn stiffness(
    s: &RawStiffness,
    geometry: &Geometry,
    ck: &Checker,
) -> Result<Stiffness, CaseError> {
    let bending = format!(
        "a positive bending stiffness in N m² {}",
        range(STIFFNESS_RANGE)
    );
    let ok = |b: f64| in_range(b, STIFFNESS_RANGE);
    let stiffness = Stiffness {
        b1: ck.number("stiffness.b1", &s.b1, 1.0, ok, &bending)?,
        b2: ck.number("stiffness.b2", &s.b2, 1.0, ok, &bending)?,
        b3: ck.number(
            "stiffness.b3",
            &s.b3,
            2.0,
            ok,
            &format!(
                "a positive torsional stiffness in N m² {}",
                range(STIFFNESS_RANGE)
            ),
        )?,
    };
    for (key, value, given) in [
        ("stiffness.b2", stiffness.b2, &s.b2),
        ("stiffness.b3", stiffness.b3, &s.b3),
    ] {
        let ratio = value / stiffness.b1;
        if !in_range(ratio, STIFFNESS_RATIO) {
            let (key, at) = if given.is_some() {
                (key, span(given))
            } else {
                ("stiffness.b1", span(&s.b1))
            };
            return Err(ck.invalid(
                key,
                at,
                format!(
                    "expected {}/B1 from {} to {}, found {} (B1 = {} N m²)",
                    key.trim_start_matches("stiffness.").to_uppercase(),
                    STIFFNESS_RATIO.0,
                    STIFFNESS_RATIO.1,
                    num(ratio),
                    num(stiffness.b1)
                ),
            ));
        }
    }
    let pcrit = stiffness.euler_load(geometry.length);
    if !(pcrit.is_finite() && pcrit > 0.0 && pcrit.is_normal()) {
        return Err(ck.invalid(
            "stiffness.b1",
            span(&s.b1),
            format!(
                "the reference load Pcrit = B1 (2π/L)² would be {} N",
                num(pcrit)
            ),
        ));
    }
    Ok(stiffness)
}

/// `[rod]`: the elastic hypotheses, Kirchhoff rods stress-free when helical unless given.
/// Sadowsky's ribbon is stress-free when flat, so it needs `stress_free = "straight"`
/// (no form for naturally curved ribbons is implemented), and its width and thickness
/// (m, thickness below width), which set the regularisation of its energy
/// ([`crate::model::elasticity`]); they are refused for Kirchhoff rods.
pub(super) fn rod(r: &RawRod, ck: &Checker) -> Result<Elasticity, CaseError> {
    let stress_free = match r.stress_free.as_ref().map(|v| *v.get_ref()) {
        None | Some(StressFreeName::Helix) => StressFree::Helix,
        Some(StressFreeName::Straight) => StressFree::Straight,
    };
    let sadowsky = r
        .energy
        .as_ref()
        .is_some_and(|e| *e.get_ref() == EnergyName::Sadowsky);
    if !sadowsky {
        for (key, value) in [("rod.width", &r.width), ("rod.thickness", &r.thickness)] {
            if let Some(v) = value {
                return Err(ck.invalid(
                    key,
                    v.span(),
                    "a ribbon's width and thickness are only used with energy = \"sadowsky\"; remove it, or set rod.energy = \"sadowsky\"",
                ));
            }
        }
        return Ok(Elasticity {
            stress_free,
            energy: Energy::Kirchhoff,
        });
    }
    let energy_span = span(&r.energy);
    if stress_free != StressFree::Straight {
        return Err(ck.invalid(
            "rod.energy",
            energy_span,
            "Sadowsky's ribbon is stress-free when flat: it needs rod.stress_free = \"straight\" (found \"helix\", the default; no form for naturally curved ribbons is implemented)",
        ));
    }
    let length = |key: &str, value: &Option<Spanned<f64>>| -> Result<f64, CaseError> {
        if value.is_none() {
            return Err(ck.invalid(
                key,
                energy_span.clone(),
                format!(
                    "energy = \"sadowsky\" needs the ribbon's `{}` in m {} (width and thickness set the regularisation of the energy)",
                    key.trim_start_matches("rod."),
                    range(LENGTH_RANGE)
                ),
            ));
        }
        ck.number(
            key,
            value,
            0.0,
            |v| in_range(v, LENGTH_RANGE),
            &format!("a positive length in m {}", range(LENGTH_RANGE)),
        )
    };
    let width = length("rod.width", &r.width)?;
    let thickness = length("rod.thickness", &r.thickness)?;
    if thickness >= width {
        return Err(ck.invalid(
            "rod.thickness",
            span(&r.thickness),
            format!(
                "a ribbon is thinner than it is wide: expected a thickness below the width {} m, found {} m",
                num(width),
                num(thickness)
            ),
        ));
    }
    Ok(Elasticity {
        stress_free,
        energy: Energy::Sadowsky(Ribbon { width, thickness }),
    })
}

/// `[boundary]`: the supports of the base and the tip, and pin joints at the crossings (the
/// file's joints are read by `joints`). Every support the file can hold is admissible (serde
/// has refused the others).
pub(super) fn boundary(b: &RawBoundary) -> BoundaryConditions {
    let thesis = BoundaryConditions::default();
    BoundaryConditions {
        base: end_condition(&b.base, thesis.base),
        tip: end_condition(&b.tip, thesis.tip),
        joints: thesis.joints,
    }
}

/// Refuses supports that leave a rigid motion of the assembly free ([`free_motion_of`]).
pub(super) fn free_motion(
    b: &BoundaryConditions,
    geometry: &Geometry,
    tip_height_held: bool,
    ck: &Checker,
) -> Result<(), CaseError> {
    match free_motion_of(b, geometry, tip_height_held) {
        None => Ok(()),
        Some(motion) => {
            let at = ck.line_of_key("tip");
            Err(CaseError::Invalid {
                file: ck.file.to_string(),
                line: at,
                key: format!("boundary.tip.{}", motion.half),
                message: motion.message,
            })
        }
    }
}

/// One end: a half not given keeps the default's.
fn end_condition(end: &Option<RawEnd>, default: EndCondition) -> EndCondition {
    match end {
        None => default,
        Some(e) => EndCondition {
            translation: e.translation.unwrap_or(default.translation),
            rotation: e.rotation.unwrap_or(default.rotation),
        },
    }
}

use super::model_key;
use crate::discretisation::cell::default_elements;

/// `[discretisation]`: the mesh of every rod (or a target accuracy it is chosen for), and
/// whether the symmetric reduction is used; it needs the number of helices.
pub(super) fn discretisation(
    d: &RawDiscretisation,
    geometry: &Geometry,
    ck: &Checker,
) -> Result<Discretisation, CaseError> {
    let helices = geometry.helices;
    let accuracy = accuracy(d, ck)?;
    let elements = ck.integer(
        "discretisation.elements",
        &d.elements,
        48,
        (1, 100_000),
        "a number of elements per rod",
    )?;
    let chosen = model_key::model_choice(d, geometry).map_err(|message| CaseError::Invalid {
        file: ck.file.to_string(),
        line: ck.line_of_key("model"),
        key: "discretisation.model".into(),
        message,
    })?;
    let cell = chosen.is_some_and(|c| c.2);
    if accuracy.is_none() && !cell {
        // the mesh a rod gets: at least `elements`, and a vertex at every joint
        if let Some(m) = elements_message(geometry, elements) {
            return Err(ck.invalid("discretisation.elements", span(&d.elements), m));
        }
    }
    let (symmetric, symmetric_auto) = match chosen {
        Some((symmetric, auto, _)) => (symmetric, auto),
        None => symmetric(d, helices, ck)?,
    };
    // a cell's rods are 1/n of a turn: its own default mesh
    let elements = match (cell, &d.elements) {
        (true, None) => default_elements(helices),
        _ => elements,
    };
    Ok(Discretisation {
        cell,
        elements,
        order: d.order.unwrap_or(Order::Quadratic),
        accuracy,
        symmetric,
        symmetric_auto,
        reference: d.reference.unwrap_or(Reference::Discrete),
    })
}

/// `discretisation.accuracy`: a relative accuracy in (0, 1), given instead of `elements`.
fn accuracy(d: &RawDiscretisation, ck: &Checker) -> Result<Option<AccuracyTarget>, CaseError> {
    match (&d.accuracy, &d.elements) {
        (None, _) => Ok(None),
        (Some(a), Some(_)) => Err(ck.invalid(
            "discretisation.accuracy",
            a.span(),
            "give either `elements` (a mesh) or `accuracy` (a target the mesh is chosen for), not both",
        )),
        (Some(_), None) => Ok(Some(AccuracyTarget {
            target: ck.number(
                "discretisation.accuracy",
                &d.accuracy,
                0.0,
                |v| v > 0.0 && v < 1.0,
                "a relative accuracy between 0 and 1 (e.g. 1e-3)",
            )?,
            order: d.order,
        })),
    }
}

/// `discretisation.symmetric`: `true` only for `n = 2m` helices, `m ≥ 2`; `"auto"` (the
/// default) is `true` where the assembly has that symmetry. Returns the choice and whether
/// it was automatic.
fn symmetric(
    d: &RawDiscretisation,
    helices: usize,
    ck: &Checker,
) -> Result<(bool, bool), CaseError> {
    let has = helices >= 4 && helices % 2 == 0;
    match &d.symmetric {
        None => Ok((has, true)),
        Some(key) => match key.get_ref() {
            SymmetricKey::Word(w) if w == "auto" => Ok((has, true)),
            SymmetricKey::Word(w) => Err(ck.invalid(
                "discretisation.symmetric",
                key.span(),
                format!("expected true, false or \"auto\", found \"{w}\""),
            )),
            SymmetricKey::Flag(true) if !has => Err(ck.invalid(
                "discretisation.symmetric",
                key.span(),
                format!("expected false or \"auto\": {helices} helix(es) have no rotational symmetry to reduce (it needs n = 2m helices with m ≥ 2)"),
            )),
            SymmetricKey::Flag(flag) => Ok((*flag, false)),
        },
    }
}

/// `[solver]`: the step lengths of the continuation (in the load parameter, `min_step ≤
/// max_step`), the Newton tolerance on `‖R‖∞` and the Newton iterations per step. The
/// settings a case file cannot give keep their defaults.
pub(super) fn solver(s: &RawSolver, ck: &Checker) -> Result<ContinuationSettings, CaseError> {
    let d = ContinuationSettings::default();
    let step = &format!(
        "a positive step in the load parameter {}",
        range(STEP_RANGE)
    );
    let ok = |h: f64| in_range(h, STEP_RANGE);
    let mut solver = ContinuationSettings {
        initial_step: ck.number(
            "solver.initial_step",
            &s.initial_step,
            d.initial_step,
            ok,
            step,
        )?,
        max_step: ck.number("solver.max_step", &s.max_step, d.max_step, ok, step)?,
        min_step: ck.number("solver.min_step", &s.min_step, d.min_step, ok, step)?,
        ..d
    };
    solver.newton.tolerance = ck.number(
        "solver.tolerance",
        &s.tolerance,
        d.newton.tolerance,
        |t| in_range(t, TOLERANCE_RANGE),
        &format!(
            "a residual tolerance from {:e} to {:e} (relative to the stiffness B1: a looser one accepts states that are not equilibria)",
            TOLERANCE_RANGE.0, TOLERANCE_RANGE.1
        ),
    )?;
    solver.newton.max_iterations = ck.integer(
        "solver.max_iterations",
        &s.max_iterations,
        d.newton.max_iterations,
        (1, 1000),
        "a number of Newton iterations",
    )?;
    if solver.min_step > solver.max_step {
        // point at whichever of the two the file gives (both defaults are consistent)
        let (key, span) = match (&s.min_step, &s.max_step) {
            (Some(min), _) => ("solver.min_step", min.span()),
            (None, Some(max)) => ("solver.max_step", max.span()),
            (None, None) => ("solver.min_step", 0..0),
        };
        return Err(ck.invalid(
            key,
            span,
            format!(
                "expected min_step ≤ max_step, found min_step = {} and max_step = {}",
                num(solver.min_step),
                num(solver.max_step)
            ),
        ));
    }
    Ok(solver)
}

/// Where a value given in the file is (the start of the text when it is not given).
pub(super) fn span<T>(value: &Option<Spanned<T>>) -> Range<usize> {
    value.as_ref().map_or(0..0, Spanned::span)
}

/// Checks values of the case text named `file` and says where a bad one is.
pub(super) struct Checker<'a> {
    pub file: &'a str,
    pub text: &'a str,
}

impl Checker<'_> {
    /// The line of the first key `name = …` of the text (1 when there is none).
    pub(super) fn line_of_key(&self, name: &str) -> usize {
        self.text
            .lines()
            .position(|l| {
                let l = l.trim_start();
                l.strip_prefix(name)
                    .is_some_and(|r| r.trim_start().starts_with('=') || r.starts_with('.'))
                    || l.starts_with(&format!("[boundary.{name}]"))
            })
            .map_or(1, |i| i + 1)
    }

    /// A value out of range, at `span` in the text.
    pub(super) fn invalid(
        &self,
        key: &str,
        span: Range<usize>,
        message: impl fmt::Display,
    ) -> CaseError {
        CaseError::Invalid {
            file: self.file.to_string(),
            line: line_of(self.text, span.start),
            key: key.to_string(),
            message: message.to_string(),
        }
    }

    /// A finite number satisfying `ok`, or the default; `expected` says what `ok` asks.
    pub(super) fn number(
        &self,
        key: &str,
        value: &Option<Spanned<f64>>,
        default: f64,
        ok: impl Fn(f64) -> bool,
        expected: &str,
    ) -> Result<f64, CaseError> {
        match value {
            None => Ok(default),
            Some(v) if v.get_ref().is_finite() && ok(*v.get_ref()) => Ok(*v.get_ref()),
            Some(v) => Err(self.invalid(
                key,
                v.span(),
                format!("expected {expected}, found {}", num(*v.get_ref())),
            )),
        }
    }

    /// A whole number in `min..=max`, or the default; `what` names it in the message.
    pub(super) fn integer(
        &self,
        key: &str,
        value: &Option<Spanned<i64>>,
        default: usize,
        (min, max): (i64, i64),
        what: &str,
    ) -> Result<usize, CaseError> {
        match value {
            None => Ok(default),
            Some(v) if (min..=max).contains(v.get_ref()) => Ok(*v.get_ref() as usize),
            Some(v) => Err(self.invalid(
                key,
                v.span(),
                format!("expected {what} from {min} to {max}, found {}", v.get_ref()),
            )),
        }
    }
}
