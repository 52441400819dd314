//! `spira plot`: the figures of run folders, and the parsers of its options `--eps`,
//! `--rod` and `--only`.

use super::command_line;
use super::signals::end_on_signal_between_writes;
use anyhow::{bail, Context, Result};
use spira::output::figures::{run_figures, Kinds, Rods, Steps};
use spira::output::read::RunTables;
use spira::sweep::figure::summary_figures;
use spira::sweep::SweepTable;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `--eps`: the states to draw, `last`, `all`, or compression ratios separated by commas
/// (the nearest output state of each run to each).
pub fn states_flag(text: &str) -> Result<Steps, String> {
    Ok(match text.trim() {
        "last" => Steps::Last,
        "all" => Steps::All,
        list => Steps::Near(
            list.split(',')
                .map(|v| match v.trim().parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    _ => Err(format!(
                        "--eps: expected compression ratios separated by commas, `all` or `last`, found `{}`",
                        v.trim()
                    )),
                })
                .collect::<Result<_, _>>()?,
        ),
    })
}

/// `--rod`: the rod of the curvature profiles (from 0), or `all`.
pub fn rods_flag(text: &str) -> Result<Rods, String> {
    match text.trim() {
        "all" => Ok(Rods::All),
        k => k
            .parse::<usize>()
            .map(Rods::One)
            .map_err(|_| format!("--rod: expected a rod number (from 0) or `all`, found `{k}`")),
    }
}

/// `--only`: the kinds of figure, `load`, `curvature` and `views`, separated by commas.
pub fn kinds_flag(text: &str) -> Result<Kinds, String> {
    let mut kinds = Kinds {
        load: false,
        curvature: false,
        views: false,
    };
    for k in text.split(',') {
        match k.trim() {
            "load" => kinds.load = true,
            "curvature" => kinds.curvature = true,
            "views" => kinds.views = true,
            other => {
                return Err(format!(
                    "--only: expected `load`, `curvature` or `views`, found `{other}`"
                ))
            }
        }
    }
    Ok(kinds)
}

/// `spira plot`: the figures of the run folders `dirs` into `out` (default: the one run
/// folder): the states `states` of each, the curvature profiles of `rods`, the `kinds` asked.
/// A sweep's folder alone (with `sweep.csv`) gets its summary figures instead.
pub fn plot(
    dirs: &[PathBuf],
    out: Option<&Path>,
    states: &Steps,
    rods: Rods,
    kinds: Kinds,
) -> Result<()> {
    end_on_signal_between_writes();
    let out = match (out, dirs) {
        (Some(o), _) => o.to_path_buf(),
        (None, [one]) => one.clone(),
        (None, _) => bail!("--out DIR is needed for the figures of several runs"),
    };
    let t = Instant::now();
    if let [dir] = dirs {
        if dir.join("sweep.csv").is_file() && !dir.join("load.csv").exists() {
            return sweep_summary(dir, &out, t);
        }
    }
    let runs = dirs
        .iter()
        .map(|d| RunTables::read(d))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let mut labels: Vec<&str> = runs.iter().map(|r| r.label.as_str()).collect();
    labels.sort_unstable();
    if let Some(w) = labels.windows(2).find(|w| w[0] == w[1]) {
        bail!(
            "two run folders are named `{}`: the figures of each are named after its folder",
            w[0]
        );
    }
    let files = run_figures(&runs, states, rods, kinds, &command_line())?;
    let drawn = t.elapsed();
    let names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    let paths =
        spira::output::files::write_folder(&out, &files, |name| names.iter().any(|n| n == name))
            .with_context(|| format!("writing figures into {}", out.display()))?;
    println!(
        "spira plot: {} run(s) read and drawn in {:.1} ms; {}",
        runs.len(),
        drawn.as_secs_f64() * 1e3,
        spira::output::written_summary(&out, &paths)
    );
    Ok(())
}

/// `spira plot SWEEP_DIR`: the summary figures of the sweep whose table is in `dir`
/// (`sweep-<key>.svg` per swept key), written into `out`; `t` the start of the command.
fn sweep_summary(dir: &Path, out: &Path, t: Instant) -> Result<()> {
    let table_path = dir.join("sweep.csv");
    let text = std::fs::read_to_string(&table_path)
        .with_context(|| format!("reading {}", table_path.display()))?;
    let table = SweepTable::from_csv(&text, &table_path.display().to_string())?;
    if table.rows.is_empty() {
        bail!(
            "{}: the sweep table has no cases to draw",
            table_path.display()
        );
    }
    let name = dir
        .file_name()
        .map_or_else(|| "sweep".to_string(), |n| n.to_string_lossy().into_owned());
    let caption = [
        format!("sweep {name}, {} cases", table.rows.len()),
        format!("command: {}", command_line()),
    ];
    let files = summary_figures(&table, &caption)?;
    let names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    let paths =
        spira::output::files::write_folder(out, &files, |name| names.iter().any(|n| n == name))
            .with_context(|| format!("writing figures into {}", out.display()))?;
    println!(
        "spira plot: sweep {name} read and drawn in {:.1} ms; {}",
        t.elapsed().as_secs_f64() * 1e3,
        spira::output::written_summary(out, &paths)
    );
    Ok(())
}
