//! `imperfection.csv`: what the flaw of an imperfect case did to its path.

use super::csv::{format, table};
use crate::simulation::flaw::ImperfectPath;
use serde::Serialize;

/// The row of `imperfection.csv`.
#[derive(Serialize, Default)]
struct ImperfectionRow {
    shape: String,
    #[serde(serialize_with = "format::e10")]
    amplitude: f64,
    perfect_index: Option<usize>,
    perfect_kind: &'static str,
    #[serde(serialize_with = "format::opt_e10")]
    perfect_parameter: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    perfect_fz: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    limit_parameter: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    limit_fz: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    drop: Option<f64>,
    #[serde(serialize_with = "format::e10")]
    max_load: f64,
    #[serde(serialize_with = "format::e10")]
    max_load_parameter: f64,
    whole_assembly: bool,
}

/// `imperfection.csv`: one row, the flaw and where the imperfect path turns against the
/// perfect critical point.
pub fn imperfection_csv(case: &str, path: &ImperfectPath) -> String {
    let comments = [
        format!("spira imperfection, case {case}"),
        "shape: the flaw's shape (mode k: the mode of critical point k of the perfect path; bow: a half sine of a straight rod); amplitude: delta, its largest displacement over the rod length L; perfect_index,perfect_kind,perfect_parameter,perfect_fz: the perfect path's critical point it is measured against (for a bow, its first), its kind, load parameter and fz/(n Pcrit); limit_parameter,limit_fz: the first limit point of the imperfect path (where it turns in its parameter; empty: it does not turn); drop: perfect_parameter - limit_parameter, in the sense the path goes; max_load,max_load_parameter: the largest |fz|/(n Pcrit) of the output points and the limit point, and the parameter there; whole_assembly: the flaw breaks the symmetry of the pair the case asks for, and the whole assembly was solved".to_string(),
    ];
    let f = &path.flaw;
    let p = f.perfect.as_ref();
    let row = ImperfectionRow {
        shape: f.imperfection.shape.name(),
        amplitude: f.imperfection.amplitude,
        perfect_index: p.map(|p| p.index),
        perfect_kind: p.map_or("", |p| p.kind.name()),
        perfect_parameter: p.map(|p| p.parameter),
        perfect_fz: p.map(|p| p.fz),
        limit_parameter: path.limit_parameter,
        limit_fz: path.limit_fz,
        drop: path.drop,
        max_load: path.max_load,
        max_load_parameter: path.max_load_parameter,
        whole_assembly: f.whole_assembly,
    };
    table(&comments, [row])
}
