//! The files of a critical curve: `critical-curve.csv` and `critical-curve.svg`.

use super::chart::{lines_svg, Curve, DrawError, LinePanel};
use super::csv::{format, table};
use crate::simulation::curve::CriticalCurve;
use serde::Serialize;

/// The table of a critical curve.
pub const CURVE_CSV: &str = "critical-curve.csv";
/// Its figure.
pub const CURVE_SVG: &str = "critical-curve.svg";

/// A row of `critical-curve.csv`.
#[derive(Serialize, Default)]
struct CurveCsvRow {
    #[serde(serialize_with = "format::e12")]
    value: f64,
    #[serde(serialize_with = "format::e12")]
    parameter: f64,
    #[serde(serialize_with = "format::e12")]
    eps: f64,
    #[serde(serialize_with = "format::e12")]
    fz: f64,
    kind: &'static str,
    wavenumber: Option<usize>,
    multiplicity: usize,
}

/// `critical-curve.csv` of `curve`, the case and key named in its comment lines.
pub fn curve_csv(case: &str, key: &str, curve: &CriticalCurve) -> String {
    let comments = [
        format!("spira critical curve, case {case}, varied key {key}"),
        format!("value: the value of {key}; parameter: the load parameter at the critical point ({}); eps: compression ratio (h0-h)/h0 there; fz: axial tip force, the tip reactions summed over the rods (N, negative = compression); kind: limit-point or bifurcation (of the point continued); wavenumber: circumferential wavenumber p of its mode for a symmetric pair (empty for the full model); multiplicity: modes critical together", curve.parameter_label),
    ];
    let rows = curve.rows.iter().map(|r| CurveCsvRow {
        value: r.value,
        parameter: r.parameter,
        eps: r.eps,
        fz: r.fz,
        kind: r.kind.name(),
        wavenumber: r.wavenumber,
        multiplicity: r.multiplicity,
    });
    table(&comments, rows)
}

/// `critical-curve.svg`: the critical load parameter and the axial force against the key.
pub fn curve_svg(key: &str, notes: &[String], curve: &CriticalCurve) -> Result<String, DrawError> {
    let panel =
        |title: &str, y_label: &str, y: fn(&crate::simulation::curve::CurveRow) -> f64| LinePanel {
            title: title.to_string(),
            x_label: key.to_string(),
            y_label: y_label.to_string(),
            curves: vec![Curve {
                label: String::new(),
                points: curve.rows.iter().map(|r| (r.value, y(r))).collect(),
                dashed: false,
                marked: true,
                color: 0,
            }],
            shaded: Vec::new(),
        };
    let panels = [
        panel(
            "load parameter at the critical point",
            &curve.parameter_label,
            |r| r.parameter,
        ),
        panel("axial tip force there", "Σ Fz (N)", |r| r.fz),
    ];
    lines_svg(&format!("critical curve against {key}"), notes, &panels)
}
