//! `[imperfection]`: a small flaw of the natural (stress-free) state, along a critical mode
//! of the perfect structure or of a named shape, of a given amplitude.

use super::error::CaseError;
use super::limits::num;
use super::raw::RawImperfection;
use super::settings::Geometry;
use super::tables::{span, Checker};
use toml::Spanned;

/// Largest `|imperfection.amplitude|` (in rod lengths): a small flaw.
pub const MAX_AMPLITUDE: f64 = 0.1;
/// Largest `imperfection.mode`: the critical points a path locates at most, less one.
pub const MAX_MODE: i64 = crate::solver::continuation::MAX_CRITICAL_POINTS as i64 - 1;
/// The names `imperfection.shape` takes.
pub const SHAPES: [&str; 1] = ["bow"];

/// The shape of an imperfection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImperfectionShape {
    /// The mode of critical point `k` of the perfect structure's path (as spira numbers
    /// them, from 0), scaled so that its largest centreline displacement is 1.
    Mode(usize),
    /// A half sine lateral bow of a straight rod, `x(s) = sin(π s/L)` (largest displacement
    /// 1, at mid-length, along the x axis).
    Bow,
}

impl ImperfectionShape {
    /// The shape as the outputs name it: `mode 2`, `bow`.
    pub fn name(self) -> String {
        match self {
            ImperfectionShape::Mode(k) => format!("mode {k}"),
            ImperfectionShape::Bow => "bow".into(),
        }
    }
}

/// An imperfection of the natural state: its reference curvatures are those of the natural
/// state displaced by `amplitude · L` times the shape (largest displacement 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Imperfection {
    pub shape: ImperfectionShape,
    /// `δ`: the largest displacement of the flaw over the rod length `L` (signed: the sign
    /// chooses the side of the shape).
    pub amplitude: f64,
}

impl Imperfection {
    /// The flaw in a phrase: `mode 0 of the perfect path, amplitude 1e-3 L`.
    pub fn describe(&self) -> String {
        let shape = match self.shape {
            ImperfectionShape::Mode(k) => format!("mode {k} of the perfect path"),
            ImperfectionShape::Bow => "half sine bow".into(),
        };
        format!("{shape}, amplitude {} L", num(self.amplitude))
    }
}

/// Checks `[imperfection]` (`None`: no table, a perfect structure). Each value is checked
/// against its range first, then the table as a whole: one of `mode` or `shape`, and an
/// amplitude.
pub(super) fn imperfection(
    raw: &Option<Spanned<RawImperfection>>,
    geometry: &Geometry,
    ck: &Checker,
) -> Result<Option<Imperfection>, CaseError> {
    let Some(table) = raw else {
        return Ok(None);
    };
    let t = table.get_ref();
    let mode = match &t.mode {
        Some(m) if (0..=MAX_MODE).contains(m.get_ref()) => Some(*m.get_ref() as usize),
        Some(m) => {
            return Err(ck.invalid(
                "imperfection.mode",
                m.span(),
                format!(
                    "expected the index of a critical point of the perfect path (as critical.csv numbers them) from 0 to {MAX_MODE}, found {}",
                    m.get_ref()
                ),
            ))
        }
        None => None,
    };
    let bow = match &t.shape {
        Some(s) => Some(shape(s, geometry, ck)?),
        None => None,
    };
    let amplitude = match &t.amplitude {
        Some(a) if valid_amplitude(*a.get_ref()) => Some(*a.get_ref()),
        Some(a) => {
            return Err(ck.invalid(
                "imperfection.amplitude",
                a.span(),
                format!(
                    "expected a nonzero amplitude in rod lengths from -{m} to {m}, found {}",
                    num(*a.get_ref()),
                    m = num(MAX_AMPLITUDE)
                ),
            ))
        }
        None => None,
    };
    let shape = match (mode, bow) {
        (Some(k), None) => ImperfectionShape::Mode(k),
        (None, Some(s)) => s,
        (Some(_), Some(_)) => {
            return Err(ck.invalid(
                "imperfection.shape",
                span(&t.shape),
                "expected one of `mode` or `shape`, found both",
            ))
        }
        (None, None) => {
            return Err(ck.invalid(
                "imperfection",
                table.span(),
                "expected `mode = k` (a critical mode of the perfect path) or `shape = \"bow\"`, found neither",
            ))
        }
    };
    let Some(amplitude) = amplitude else {
        return Err(ck.invalid(
            "imperfection.amplitude",
            table.span(),
            format!(
                "expected an amplitude in rod lengths (nonzero, from -{m} to {m}) with the {}, found none",
                shape.name(),
                m = num(MAX_AMPLITUDE)
            ),
        ));
    };
    Ok(Some(Imperfection { shape, amplitude }))
}

/// Whether `δ` is an amplitude a case may give: finite, nonzero, at most
/// [`MAX_AMPLITUDE`] in size.
fn valid_amplitude(a: f64) -> bool {
    a.is_finite() && a != 0.0 && a.abs() <= MAX_AMPLITUDE
}

/// `imperfection.shape`: one of [`SHAPES`], and a bow only of a straight rod.
fn shape(
    value: &Spanned<toml::Value>,
    geometry: &Geometry,
    ck: &Checker,
) -> Result<ImperfectionShape, CaseError> {
    let names = SHAPES
        .iter()
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ");
    match value.get_ref().as_str() {
        Some("bow") if geometry.radius == 0.0 => Ok(ImperfectionShape::Bow),
        Some("bow") => Err(ck.invalid(
            "imperfection.shape",
            value.span(),
            format!(
                "expected a straight rod (geometry.radius = 0) for the half sine bow, found radius {} m",
                num(geometry.radius)
            ),
        )),
        _ => Err(ck.invalid(
            "imperfection.shape",
            value.span(),
            format!("expected one of {names}, found {}", value.get_ref()),
        )),
    }
}
