//! `spira sweep`: the cases of a sweep file run in parallel into one table, or the tables
//! of shard folders merged (`--merge`).

use super::signals::stop_on_signal;
use anyhow::{bail, Result};
use spira::case::{Case, ImperfectionShape};
use spira::simulation::normal_form::normal_form;
use spira::sweep::{
    merge_dirs, run_curves, run_sweep, workers, CaseFinished, CaseStatus, Combine, RunOptions,
    Shard, Sweep, SweepReport, MAX_CASES,
};
use std::io::{IsTerminal as _, Write as _};
use std::path::{Path, PathBuf};

/// What `spira sweep` is asked for besides its file: the output folder (default:
/// out/<sweep name>), the cases at once (default: the cores), the shard (default: the Slurm
/// array task's, or all), only a check, and whether a sweep of more than
/// [`MAX_CASES`] cases is read.
pub struct SweepFlags<'a> {
    pub out: Option<PathBuf>,
    pub jobs: Option<usize>,
    pub shard: Option<&'a str>,
    pub check: bool,
    pub force: bool,
}

/// `spira sweep`: the cases of the sweep file at `path` of the shard asked for, on the
/// workers asked for (at most the cores and the cases), into the output folder; with
/// `check`, only the cases listed.
pub fn sweep(path: &Path, flags: SweepFlags) -> Result<()> {
    let SweepFlags {
        out,
        jobs,
        shard,
        check,
        force,
    } = flags;
    let sweep = Sweep::from_file_with(path, if force { usize::MAX } else { MAX_CASES })?;
    let shard = match shard {
        Some(s) => Shard::parse(s)?,
        None => Shard::from_slurm(|v| std::env::var(v).ok())?.unwrap_or(Shard::ALL),
    };
    let out = out.unwrap_or_else(|| Path::new("out").join(&sweep.name));
    let mine: Vec<_> = sweep
        .cases
        .iter()
        .filter(|c| shard.contains(c.index))
        .collect();
    let capped = workers(jobs, mine.len());
    if let Some(asked) = jobs.filter(|&j| j > capped) {
        println!("--jobs {asked}: {capped} worker(s), as many as there are cores and cases to run");
    }
    let jobs = capped;
    print_heading(&sweep, path, shard, mine.len(), &out, jobs);
    if check {
        for c in &mine {
            println!("  {}", c.id);
        }
        println!("all {} generated cases are valid", sweep.cases.len());
        return Ok(());
    }
    if sweep.continued.is_some() {
        if shard != Shard::ALL {
            bail!("a sweep with a continued axis runs its curves in one process: drop --shard (or the Slurm array)");
        }
        return curves(&sweep, &out);
    }
    let terminal = std::io::stdout().is_terminal();
    let interrupt = stop_on_signal(
        "spira sweep: interrupted; the cases under way stop and are not written, no case starts",
    );
    let opts = RunOptions {
        out,
        jobs: Some(jobs),
        shard,
        interrupt: Some(interrupt),
    };
    let report = run_sweep(&sweep, &opts, |p| {
        print_progress(p, terminal);
        std::ops::ControlFlow::Continue(())
    })?;
    if terminal {
        println!();
    }
    if report.table.column("imperfection.amplitude").is_some() {
        println!("{}", koiter_line(&report.table));
        if let Some(first) = sweep.cases.first() {
            println!("{}", normal_form_line(&first.case));
        }
    }
    conclude(&report)
}

/// The sweep, its shard, the number of its cases in the shard (`cases`), where they go and
/// on how many workers.
fn print_heading(sweep: &Sweep, path: &Path, shard: Shard, cases: usize, out: &Path, jobs: usize) {
    println!(
        "spira sweep: {} ({}): {} cases ({} axes, {}){}, {} into {} on {jobs} worker(s)",
        sweep.name,
        path.display(),
        sweep.cases.len(),
        sweep.axes.len(),
        match sweep.combine {
            Combine::Product => "product",
            Combine::Zip => "zip",
        },
        if shard == Shard::ALL {
            String::new()
        } else {
            format!(", shard {}", shard.label())
        },
        cases,
        out.display()
    );
}

/// The progress of a finished case: on a terminal one line, rewritten (a failure stays on
/// its own line), elsewhere one line per case.
fn print_progress(p: &CaseFinished, terminal: bool) {
    let eta = p
        .eta()
        .map(|d| format!(", ETA {:.0} s", d.as_secs_f64()))
        .unwrap_or_default();
    let what = match p.status {
        CaseStatus::Done => format!("done in {:.2} s", p.wall.as_secs_f64()),
        CaseStatus::Skipped => "complete already, skipped".to_string(),
        CaseStatus::Failed => format!(
            "FAILED after {:.2} s: {}",
            p.wall.as_secs_f64(),
            p.reason.as_deref().unwrap_or("")
        ),
    };
    if terminal {
        if p.status == CaseStatus::Failed {
            print!("\r\x1b[2K{}: {what}\n", p.case.id);
        }
        print!(
            "\r\x1b[2K[{}/{}] {:.0} s elapsed{eta}; last {}: {}",
            p.done,
            p.total,
            p.elapsed.as_secs_f64(),
            p.case.id,
            if p.status == CaseStatus::Failed {
                "failed"
            } else {
                &what
            }
        );
        let _ = std::io::stdout().flush();
    } else {
        println!(
            "[{}/{}] {} {what} ({:.1} s elapsed{eta})",
            p.done,
            p.total,
            p.case.id,
            p.elapsed.as_secs_f64()
        );
    }
}

/// Koiter's law over a sweep of flaws, in a line: the fitted exponent, or that no path
/// turned.
fn koiter_line(table: &spira::sweep::SweepTable) -> String {
    match table.koiter() {
        Some(fit) => format!(
            "Koiter: drop of the limit parameter ≈ {:.4e} |δ|^{:.4} (least squares of log drop on log |δ|, {} amplitudes over {:.1} decades)",
            fit.coefficient, fit.exponent, fit.samples, fit.decades
        ),
        None => "Koiter: fewer than two imperfect paths turned below the perfect critical point: no drop to fit (a stable symmetric point, or the flaw's sign on the stable side of an asymmetric one)".into(),
    }
}

/// The smallest mode amplitude (rod lengths) at which the normal form samples the branch.
const NORMAL_FORM_AMPLITUDE: f64 = 1e-3;

/// The normal form of the perfect point a sweep's flaws follow, in a line: Koiter's `a`
/// and `b` measured on its branch, its kind and the law of the drop it predicts.
fn normal_form_line(case: &Case) -> String {
    let Some(flaw) = case.imperfection.as_ref() else {
        return "normal form: the sweep's base case has no imperfection".into();
    };
    let ImperfectionShape::Mode(index) = flaw.shape else {
        return "normal form: the flaw is a named shape, not a critical mode".into();
    };
    match normal_form(case, index, NORMAL_FORM_AMPLITUDE) {
        Ok(nf) => format!(
            "normal form of the perfect point {index} at parameter {:.8}: λ − λc ≈ a ξ + b ξ², a = {:.4e}, b = {:.4e} (ξ the mode's largest displacement in rod lengths): {}, {}",
            nf.parameter,
            nf.a,
            nf.b,
            nf.kind.name(),
            match nf.kind.koiter_exponent() {
                Some(p) => format!("the limit parameter drops as |δ|^{p:.4}"),
                None => "no drop".into(),
            }
        ),
        Err(e) => format!("normal form: not measured ({e})"),
    }
}

/// The curves of a sweep with a continued axis, one after the other, into `out`.
fn curves(sweep: &Sweep, out: &Path) -> Result<()> {
    let t0 = std::time::Instant::now();
    let report = run_curves(sweep, out, |c| match &c.curve {
        Ok(curve) => println!("  {}: {} critical points", c.id, curve.rows.len()),
        Err(e) => println!("  {}: no curve: {e}", c.id),
    })?;
    println!(
        "{} curve(s) in {:.2} s",
        report.curves.len(),
        t0.elapsed().as_secs_f64()
    );
    for p in &report.written {
        println!("wrote {}", p.display());
    }
    let short = report.short();
    if short.is_empty() {
        Ok(())
    } else {
        for (id, why) in &short {
            eprintln!("  {id}: {why}");
        }
        bail!(
            "{} curve(s) failed or stopped short (their rows up to there are written)",
            short.len()
        )
    }
}

/// What the sweep did, and a failure when it was interrupted or a case failed.
fn conclude(report: &SweepReport) -> Result<()> {
    if report.interrupted {
        bail!(
            "interrupted after {:.1} s: {} of {} cases complete ({} run now, {} complete already, {} of them failed), {} not done; wrote {}, and the same command goes on with the rest",
            report.wall.as_secs_f64(),
            report.ran + report.skipped,
            report.total,
            report.ran,
            report.skipped,
            report.failed,
            report.pending,
            report.table_path.display()
        );
    }
    println!(
        "{} cases in {:.1} s: {} run, {} complete already, {} failed; wrote {}",
        report.total,
        report.wall.as_secs_f64(),
        report.ran,
        report.skipped,
        report.failed,
        report.table_path.display()
    );
    if report.failed > 0 {
        bail!(
            "{} of {} cases failed (status and reason in {})",
            report.failed,
            report.total,
            report.table_path.display()
        );
    }
    Ok(())
}

/// `spira sweep --merge`: the sweep tables in the folders (or files) `inputs` merged into
/// OUT/sweep.csv.
pub fn merge(inputs: &[PathBuf], out: Option<PathBuf>) -> Result<()> {
    let Some(out) = out else {
        bail!("--merge needs --out DIR for the merged sweep.csv");
    };
    let (table, path) = merge_dirs(inputs, &out)?;
    let failed = table
        .column("status")
        .map_or(0, |c| table.rows.iter().filter(|r| r[c] != "done").count());
    println!(
        "merged {} cases ({} failed) from {} input(s) into {}",
        table.rows.len(),
        failed,
        inputs.len(),
        path.display()
    );
    Ok(())
}
