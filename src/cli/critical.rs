//! `spira critical`: the first critical point of a case's path continued in a second
//! parameter, a numeric key of the case, into `critical-curve.csv` and its figure.

use anyhow::{bail, Context as _, Result};
use spira::case::{settings_line, Setting};
use spira::output::curve::{curve_csv, curve_svg, CURVE_CSV, CURVE_SVG};
use spira::output::files::write_folder;
use spira::simulation::curve::{critical_curve, CurveSpec};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The most rows a curve may ask for.
const MAX_ROWS: u64 = 100_000;

/// The command line of `spira critical`.
#[derive(clap::Args)]
pub struct CriticalArgs {
    /// Case file (TOML).
    case: PathBuf,
    /// The key varied, a dotted numeric key of the case file (e.g. geometry.length).
    #[arg(long, value_name = "KEY")]
    vary: String,
    /// Its value where the critical point is located by the case's path.
    #[arg(long, allow_hyphen_values = true, value_name = "A")]
    from: f64,
    /// Its value where the curve ends.
    #[arg(long, allow_hyphen_values = true, value_name = "B")]
    to: f64,
    /// Rows of the table, equally spaced in the key from A to B (2 to 100000).
    #[arg(long, default_value_t = 16)]
    rows: usize,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Override a key of the case, e.g. `--set stiffness.b3=1.5` (repeatable); the value is
    /// checked as in the file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<Setting>,
}

/// `spira critical CASE --vary KEY --from A --to B`: the curve into `--out`.
pub fn critical(args: CriticalArgs) -> Result<()> {
    let spec = CurveSpec {
        key: args.vary,
        from: args.from,
        to: args.to,
        rows: args.rows,
        at: Vec::new(),
    };
    curve(&args.case, &args.set, spec, &args.out)
}

/// The critical curve of `spec` of the case at `case` with `set` into `out`.
fn curve(case: &Path, set: &[Setting], spec: CurveSpec, out: &Path) -> Result<()> {
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
        "{} critical points of {stem} against {} in {:.2} s{}",
        curve.rows.len(),
        spec.key,
        elapsed.as_secs_f64(),
        match curve.relocated {
            0 => String::new(),
            k => format!(
                " (located afresh by the case's path {k} time(s), where the mesh's layout changed)"
            ),
        }
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
