//! `spira critical`: the first critical point of a case's path continued in a second
//! parameter, a numeric key of the case, into `critical-curve.csv` and its figure.

use anyhow::{bail, Context as _, Result};
use spira::case::{settings_line, Setting};
use spira::output::curve::{curve_csv, curve_svg, CURVE_CSV, CURVE_SVG};
use spira::output::files::write_folder;
use spira::simulation::curve::{critical_curve, CurveSpec};
use std::path::Path;
use std::time::Instant;

/// The most rows a curve may ask for.
const MAX_ROWS: u64 = 100_000;

/// `spira critical CASE --vary KEY --from A --to B`: the curve into `out`.
pub fn critical(case: &Path, set: &[Setting], spec: CurveSpec, out: &Path) -> Result<()> {
    if spec.rows < 2 || spec.rows as u64 > MAX_ROWS {
        bail!("--rows: expected 2 to {MAX_ROWS} rows, found {}", spec.rows);
    }
    let file = case.display().to_string();
    let text = std::fs::read_to_string(case).with_context(|| format!("cannot read {file}"))?;
    let stem = case
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "case".into());
    let t0 = Instant::now();
    let curve = critical_curve(&text, &file, &stem, set, &spec)?;
    let elapsed = t0.elapsed();
    let mut notes = vec![format!(
        "{file}, {} from {} to {}",
        spec.key, spec.from, spec.to
    )];
    if !set.is_empty() {
        notes.push(format!("with {}", settings_line(set)));
    }
    let csv = curve_csv(&stem, &spec.key, &curve);
    let svg = curve_svg(&spec.key, &notes, &curve)?;
    let files = [(CURVE_CSV.to_string(), csv), (CURVE_SVG.to_string(), svg)];
    let written = write_folder(out, &files, |name| name == CURVE_CSV || name == CURVE_SVG)
        .with_context(|| format!("cannot write into {}", out.display()))?;
    println!(
        "{} critical points of {stem} against {} in {:.2} s",
        curve.rows.len(),
        spec.key,
        elapsed.as_secs_f64()
    );
    for r in &curve.rows {
        println!(
            "  {} = {:.6}  parameter {:.8}  fz {:.8} N  {}",
            spec.key,
            r.value,
            r.parameter,
            r.fz,
            r.kind.name()
        );
    }
    for p in written {
        println!("wrote {}", p.display());
    }
    match curve.stopped {
        Some(why) => bail!("{why} (the rows up to there are written)"),
        None => Ok(()),
    }
}
