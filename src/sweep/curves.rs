//! A sweep whose axis is continued as a critical curve (`continue = "key"`): for each
//! combination of the other axes, the first critical point of the case at the axis's first
//! value is continued along the axis through its values (`spira critical`'s continuation),
//! instead of a path being solved at each value. Each curve goes into its own folder
//! (`critical-curve.csv` and its figure), and all of them into one table,
//! `critical-curves.csv`: the other axes' values, then the curve's columns.

use super::error::SweepError;
use super::plan::{cell, Sweep, SweepCase};
use crate::output::curve::{curve_csv, curve_svg, CURVE_CSV, CURVE_SVG};
use crate::simulation::curve::{critical_curve, CriticalCurve, CurveSpec};
use std::path::{Path, PathBuf};

/// The table of all the curves of a continued sweep.
pub const CURVES_CSV: &str = "critical-curves.csv";

/// One curve of a continued sweep: the case at the continued axis's first value, the other
/// axes' values, and the curve, or why there is none.
#[derive(Debug)]
pub struct SweptCurve {
    /// The folder of the curve: the id of its first case.
    pub id: String,
    /// The values of the axes other than the continued one, in the order of the axes.
    pub others: Vec<String>,
    pub curve: Result<CriticalCurve, String>,
}

/// What a continued sweep did.
#[derive(Debug)]
pub struct CurvesReport {
    pub curves: Vec<SweptCurve>,
    /// The files written.
    pub written: Vec<PathBuf>,
}

impl CurvesReport {
    /// The curves that failed or stopped short of the axis's last value, with why.
    pub fn short(&self) -> Vec<(String, String)> {
        self.curves
            .iter()
            .filter_map(|c| match &c.curve {
                Err(e) => Some((c.id.clone(), e.clone())),
                Ok(curve) => curve
                    .stopped
                    .as_ref()
                    .map(|e| (c.id.clone(), e.to_string())),
            })
            .collect()
    }
}

/// The cases that start a curve, one per combination of the other axes (the continued
/// axis's first value), in the order of generation.
fn starts(sweep: &Sweep, k: usize) -> Vec<&SweepCase> {
    let first = &sweep.axes[k].values[0];
    sweep
        .cases
        .iter()
        .filter(|c| &c.values[k] == first)
        .collect()
}

/// Runs the curves of `sweep` (whose axis `sweep.continued` is continued) into `out`, one
/// after the other, calling `each` after each curve.
pub fn run_curves(
    sweep: &Sweep,
    out: &Path,
    mut each: impl FnMut(&SweptCurve),
) -> Result<CurvesReport, SweepError> {
    let Some(k) = sweep.continued else {
        return Ok(CurvesReport {
            curves: Vec::new(),
            written: Vec::new(),
        });
    };
    let axis = &sweep.axes[k];
    let values: Vec<f64> = axis
        .values
        .iter()
        .filter_map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
        .collect();
    let spec = CurveSpec::through(&axis.key, &values);
    let mut curves = Vec::new();
    let mut written = Vec::new();
    for start in starts(sweep, k) {
        let label = format!("{} [{}]", sweep.file, start.id);
        let curve =
            critical_curve(&start.text, &label, &start.id, &[], &spec).map_err(|e| e.to_string());
        let others = start
            .values
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != k)
            .map(|(_, v)| cell(v))
            .collect();
        let swept = SweptCurve {
            id: start.id.clone(),
            others,
            curve,
        };
        if let Ok(curve) = &swept.curve {
            written.extend(write_curve(out, &swept.id, &axis.key, curve)?);
        }
        each(&swept);
        curves.push(swept);
    }
    let table = curves_table(sweep, k, &curves);
    let path = out.join(CURVES_CSV);
    std::fs::create_dir_all(out).map_err(|e| write_error(out, e))?;
    std::fs::write(&path, table).map_err(|e| write_error(&path, e))?;
    written.push(path);
    Ok(CurvesReport { curves, written })
}

fn write_error(path: &Path, reason: std::io::Error) -> SweepError {
    SweepError::Write {
        path: path.display().to_string(),
        reason,
    }
}

/// A curve's folder: its table and figure.
fn write_curve(
    out: &Path,
    id: &str,
    key: &str,
    curve: &CriticalCurve,
) -> Result<Vec<PathBuf>, SweepError> {
    let dir = out.join(id);
    std::fs::create_dir_all(&dir).map_err(|e| write_error(&dir, e))?;
    let svg = curve_svg(key, &[format!("sweep curve {id}")], curve)
        .map_err(|e| write_error(&dir, std::io::Error::other(e.to_string())))?;
    let mut paths = Vec::new();
    for (name, text) in [(CURVE_CSV, curve_csv(id, key, curve)), (CURVE_SVG, svg)] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| write_error(&path, e))?;
        paths.push(path);
    }
    Ok(paths)
}

/// `critical-curves.csv`: a row per point of every curve, the other axes' values first.
fn curves_table(sweep: &Sweep, k: usize, curves: &[SweptCurve]) -> String {
    let axis = &sweep.axes[k].key;
    let mut text = format!(
        "# spira sweep {}: the first critical point continued along {axis}; value: {axis}, parameter: the load parameter at the critical point, eps: compression ratio there, fz: axial tip force (N, negative = compression)\n",
        sweep.name
    );
    let mut header: Vec<String> = (sweep.axes.iter().enumerate())
        .filter(|&(j, _)| j != k)
        .map(|(_, a)| a.key.clone())
        .collect();
    header.extend(
        [
            "value",
            "parameter",
            "eps",
            "fz",
            "kind",
            "wavenumber",
            "multiplicity",
        ]
        .map(String::from),
    );
    text.push_str(&header.join(","));
    text.push('\n');
    for c in curves {
        let Ok(curve) = &c.curve else { continue };
        for r in &curve.rows {
            let mut row = c.others.clone();
            row.extend([
                format!("{:.12e}", r.value),
                format!("{:.12e}", r.parameter),
                format!("{:.12e}", r.eps),
                format!("{:.12e}", r.fz),
                r.kind.name().to_string(),
                r.wavenumber.map_or(String::new(), |p| p.to_string()),
                r.multiplicity.to_string(),
            ]);
            text.push_str(&row.join(","));
            text.push('\n');
        }
    }
    text
}
