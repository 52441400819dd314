//! Running a sweep: the cases of a shard in parallel (a local rayon pool), each into its own
//! folder written atomically (a temporary folder beside it, renamed into place once its
//! marker, `row.csv`, is written last), finished cases skipped, and the table written.

use super::error::SweepError;
use super::plan::{cell, Sweep, SweepCase};
use super::shard::Shard;
use super::table::SweepTable;
use crate::case::Case;
use crate::model::loading::Control;
use crate::output::precision::ChoiceReport as _;
use crate::run::{run_path_steps, PathOutcome};
use crate::solver::interrupt::Interrupt;
use crate::study::resolve_accuracy_with;
use rayon::prelude::*;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The marker of a complete case folder: the case's row of the sweep table, written last.
pub const MARKER: &str = "row.csv";
/// The generated case, as run, in every case folder.
pub const CASE_FILE: &str = "case.toml";

/// How to run a sweep.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The folder of the case folders and the table.
    pub out: PathBuf,
    /// Cases at once (default: the cores).
    pub jobs: Option<usize>,
    pub shard: Shard,
    /// Raised (by a signal), it stops the sweep: no case starts, the cases under way stop
    /// at their next Newton iteration and are not written (they stay to do), the table of
    /// the finished ones is written.
    pub interrupt: Option<Interrupt>,
}

/// What became of a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaseStatus {
    Done,
    Failed,
    /// Its complete results were there already.
    Skipped,
}

/// A case of the shard finished (run, failed, or found done), with the shard's tally so
/// far: what a sweep says after every case.
#[derive(Clone, Debug)]
pub struct CaseFinished<'a> {
    pub case: &'a SweepCase,
    pub status: CaseStatus,
    /// The case's reason of failure, if it failed.
    pub reason: Option<String>,
    /// Wall time of the case's solve (of the original run for a skipped case).
    pub wall: Duration,
    /// Cases of the shard finished so far (skipped ones included), and their number.
    pub done: usize,
    pub total: usize,
    /// Since the sweep started.
    pub elapsed: Duration,
    /// Cases run (not skipped) so far.
    pub ran: usize,
}

impl CaseFinished<'_> {
    /// Estimated time to go: the cases left at the rate cases have been run so far (which
    /// includes the parallelism).
    pub fn eta(&self) -> Option<Duration> {
        (self.ran > 0).then(|| {
            let left = (self.total - self.done) as f64;
            Duration::from_secs_f64(self.elapsed.as_secs_f64() / self.ran as f64 * left)
        })
    }
}

/// What a sweep did.
#[derive(Clone, Debug)]
pub struct SweepReport {
    /// Rows of every finished case of the shard (done, failed, or found done).
    pub table: SweepTable,
    pub table_path: PathBuf,
    /// Cases of the shard, run now, found complete, failed, and left (a stop was asked).
    pub total: usize,
    pub ran: usize,
    pub skipped: usize,
    pub failed: usize,
    pub pending: usize,
    /// The sweep was stopped by [`RunOptions::interrupt`].
    pub interrupted: bool,
    pub jobs: usize,
    pub wall: Duration,
}

/// The table's file name: `sweep.csv` for the whole sweep, `sweep-shard-K-of-N.csv` for a
/// shard (so shards may share a folder).
pub fn table_name(shard: Shard) -> String {
    if shard == Shard::ALL {
        "sweep.csv".into()
    } else {
        format!("sweep-shard-{}-of-{}.csv", shard.k, shard.n)
    }
}

/// The number of workers `jobs` asks for (default: the cores), at most the cores and the
/// `cases` to run (and at least one): more threads would only wait.
pub fn workers(jobs: Option<usize>, cases: usize) -> usize {
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    jobs.filter(|&j| j > 0)
        .unwrap_or(cores)
        .min(cores)
        .min(cases)
        .max(1)
}

/// Runs the cases of `opts.shard` not yet complete in `opts.out`, `on_case` told after each
/// (one call at a time); when it breaks, no further case starts. Writes the table of the
/// shard's finished cases and returns it.
pub fn run_sweep(
    sweep: &Sweep,
    opts: &RunOptions,
    on_case: impl FnMut(&CaseFinished) -> ControlFlow<()> + Send,
) -> Result<SweepReport, SweepError> {
    let t0 = Instant::now();
    let out = &opts.out;
    std::fs::create_dir_all(out).map_err(|reason| write_err(out, reason))?;
    // case folders a killed sweep was writing
    crate::output::staging::remove_stale(out);
    let interrupt = opts.interrupt.as_ref();
    let interrupted = || interrupt.is_some_and(|i| i.check().is_some());
    let empty = SweepTable::new(&sweep.axes);
    let selected: Vec<&SweepCase> = sweep
        .cases
        .iter()
        .filter(|c| opts.shard.contains(c.index))
        .collect();
    let total = selected.len();
    let tally = Tally::new(on_case, total, t0);
    // finished cases first, in order
    let mut rows = Vec::new();
    let mut todo = Vec::new();
    for c in selected {
        match finished_row(out, c, &empty) {
            Some(row) => {
                let wall = wall_of(&empty, &row);
                rows.push(row);
                tally.tell(c, CaseStatus::Skipped, None, wall);
            }
            None => todo.push(c),
        }
    }
    let skipped = rows.len();
    let jobs = workers(opts.jobs, todo.len());
    let results = run_cases(&todo, jobs, out, &empty, interrupt, &tally)?;
    let pending = results.iter().filter(|r| r.is_none()).count();
    rows.extend(results.into_iter().flatten());
    let ran = rows.len() - skipped;
    let status = empty.column("status").expect("status column");
    let failed = rows.iter().filter(|r| r[status] == "failed").count();
    let mut table = empty;
    table.rows = rows;
    table.sort();
    let table_path = out.join(table_name(opts.shard));
    crate::output::write_atomic(&table_path, &table.to_csv())
        .map_err(|reason| write_err(&table_path, reason))?;
    Ok(SweepReport {
        table,
        table_path,
        total,
        ran,
        skipped,
        failed,
        pending,
        interrupted: interrupted(),
        jobs,
        wall: t0.elapsed(),
    })
}

/// The cases of a shard finished so far, told to the caller's `on_case` after each (one
/// call at a time, from any worker); `stop` is raised once it breaks.
struct Tally<F> {
    counts: Mutex<Counts<F>>,
    total: usize,
    t0: Instant,
    stop: AtomicBool,
}

/// What [`Tally`] keeps under its lock: the caller's callback, the cases finished and run.
struct Counts<F> {
    on_case: F,
    done: usize,
    ran: usize,
}

impl<F: FnMut(&CaseFinished) -> ControlFlow<()>> Tally<F> {
    fn new(on_case: F, total: usize, t0: Instant) -> Self {
        Tally {
            counts: Mutex::new(Counts {
                on_case,
                done: 0,
                ran: 0,
            }),
            total,
            t0,
            stop: AtomicBool::new(false),
        }
    }

    /// Counts `case` as finished with `status` and tells the caller.
    fn tell(&self, case: &SweepCase, status: CaseStatus, reason: Option<String>, wall: Duration) {
        let mut s = self.counts.lock().unwrap_or_else(|e| e.into_inner());
        s.done += 1;
        if status != CaseStatus::Skipped {
            s.ran += 1;
        }
        let p = CaseFinished {
            case,
            status,
            reason,
            wall,
            done: s.done,
            total: self.total,
            elapsed: self.t0.elapsed(),
            ran: s.ran,
        };
        if (s.on_case)(&p).is_break() {
            self.stop.store(true, Ordering::SeqCst);
        }
    }

    /// Whether the caller asked that no further case start.
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }
}

/// Runs `todo` on `jobs` workers (a local pool), each case told to `tally` as it finishes:
/// the rows of the cases run, `None` for those left to do (a stop was asked, or the solve
/// was interrupted).
fn run_cases<F: FnMut(&CaseFinished) -> ControlFlow<()> + Send>(
    todo: &[&SweepCase],
    jobs: usize,
    out: &Path,
    empty: &SweepTable,
    interrupt: Option<&Interrupt>,
    tally: &Tally<F>,
) -> Result<Vec<Option<Vec<String>>>, SweepError> {
    let interrupted = || interrupt.is_some_and(|i| i.check().is_some());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .thread_name(|i| format!("spira-sweep-{i}"))
        .build()
        .map_err(|e| SweepError::Shard(format!("cannot start {jobs} workers: {e}")))?;
    Ok(pool.install(|| {
        todo.par_iter()
            .with_max_len(1)
            .map(|c| {
                if tally.stopped() || interrupted() {
                    return None;
                }
                let (row, reason, wall) = run_case(out, c, empty, interrupt)?;
                let status = if reason.is_some() {
                    CaseStatus::Failed
                } else {
                    CaseStatus::Done
                };
                tally.tell(c, status, reason, wall);
                Some(row)
            })
            .collect()
    }))
}

fn write_err(path: &Path, reason: std::io::Error) -> SweepError {
    SweepError::Write {
        path: path.display().to_string(),
        reason,
    }
}

/// The row of a complete case folder (its marker, for this sweep's columns), if there is one.
fn finished_row(out: &Path, c: &SweepCase, empty: &SweepTable) -> Option<Vec<String>> {
    let marker = out.join(&c.id).join(MARKER);
    let text = std::fs::read_to_string(&marker).ok()?;
    let t = SweepTable::from_csv(&text, &marker.display().to_string()).ok()?;
    (t.headers == empty.headers && t.rows.len() == 1 && t.rows[0][0] == c.id)
        .then(|| t.rows.into_iter().next().expect("one row"))
}

fn wall_of(t: &SweepTable, row: &[String]) -> Duration {
    t.column("wall_s")
        .and_then(|i| row[i].parse::<f64>().ok())
        .map(|s| Duration::from_secs_f64(s.max(0.0)))
        .unwrap_or_default()
}

/// Solves a case and writes its folder; returns its row, its reason of failure, and the
/// solve's wall time. A failure of the case (no equilibrium, a solver failure mid-path, a
/// panic, a file that cannot be written) is a failed row, never an error of the sweep.
/// A case whose solve `interrupt` stopped is not written: `None`, it stays to do.
fn run_case(
    out: &Path,
    c: &SweepCase,
    empty: &SweepTable,
    interrupt: Option<&Interrupt>,
) -> Option<(Vec<String>, Option<String>, Duration)> {
    let t = Instant::now();
    let solved =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| solve(&c.case, interrupt)));
    let wall = t.elapsed();
    let stopped = match &solved {
        Ok(Ok(s)) => s.outcome.error.is_some(),
        _ => true,
    };
    if stopped && interrupt.is_some_and(|i| i.check().is_some()) {
        // cut short by the interrupt, not a result of the case
        return None;
    }
    let solved = solved.unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown".into());
        Err(format!("the solver panicked: {what}"))
    });
    let mut reason = match &solved {
        Ok(s) => s.outcome.error.as_ref().map(|e| {
            format!(
                "{e}; the converged steps up to eps = {:.6} were written",
                e.compression_ratio
            )
        }),
        Err(e) => Some(e.clone()),
    };
    let written = write_folder(out, c, solved.as_ref().ok(), &empty.headers, |extra| {
        // the row is built last, with any failure to write the result files in it
        if let Some(e) = extra {
            reason = Some(match reason.take() {
                Some(r) => format!("{r}; {e}"),
                None => e,
            });
        }
        row(c, solved.as_ref().ok(), reason.as_deref(), wall, empty)
    });
    Some(match written {
        Ok(row) => (row, reason, wall),
        Err(e) => {
            let why = format!("writing its folder: {e}");
            let reason = Some(match reason {
                Some(r) => format!("{r}; {why}"),
                None => why,
            });
            let row = row(c, solved.as_ref().ok(), reason.as_deref(), wall, empty);
            (row, reason, wall)
        }
    })
}

/// A solved case: the case as run (its mesh chosen when it asks for an accuracy), the path,
/// and the accuracy note.
struct Solved {
    case: Case,
    outcome: PathOutcome,
    note: Option<String>,
}

fn solve(case: &Case, interrupt: Option<&Interrupt>) -> Result<Solved, String> {
    let (case, choice) =
        resolve_accuracy_with(case, interrupt).map_err(|e| format!("choosing the mesh: {e}"))?;
    let eps = case.output_parameters(case.loading.target, case.loading.steps);
    let outcome = run_path_steps(&case, &eps, interrupt.cloned(), None, |_| {})
        .map_err(|e| format!("no equilibrium at eps = 0: {e}"))?;
    let note = choice.as_ref().map(|ch| {
        let last = outcome.points.last().expect("step 0 is always there");
        let response = match case.loading.control {
            Control::Displacement => last.load[2],
            Control::Force => last.compression_ratio,
        };
        ch.note(ch.estimate_with(response))
    });
    Ok(Solved {
        case,
        outcome,
        note,
    })
}

/// Writes a case folder atomically: the result files, `case.toml`, then the marker (the row
/// `make_row` gives, told of a failure to write the result files), all into a temporary
/// folder beside the target (named by its owner, [`crate::output::staging::staging_dir`]),
/// renamed into place. No signal ends the process during it (it holds the writes), so the
/// temporary folder is never left behind but by `kill -9`, and then the next sweep into
/// `out` removes it. Returns the row.
fn write_folder(
    out: &Path,
    c: &SweepCase,
    solved: Option<&Solved>,
    headers: &[String],
    make_row: impl FnOnce(Option<String>) -> Vec<String>,
) -> std::io::Result<Vec<String>> {
    // declared first, dropped last: after the temporary folder is removed
    let _writing = crate::output::files::hold_writes();
    let tmp = crate::output::staging::staging_dir(out, &format!(".spira-{}-", c.id))?;
    let mut failure = None;
    if let Some(s) = solved {
        let o = &s.outcome;
        let files = crate::output::RunFiles::of(&s.case.name, s.note.as_deref(), o);
        if let Err(e) = crate::output::write_run(tmp.path(), &files) {
            failure = Some(format!("writing the result files: {e}"));
        }
    }
    crate::output::write_atomic(&tmp.path().join(CASE_FILE), &c.text)?;
    let row = make_row(failure);
    let t = SweepTable {
        headers: headers.to_vec(),
        rows: vec![row.clone()],
    };
    crate::output::write_atomic(&tmp.path().join(MARKER), &t.to_csv())?;
    let target = out.join(&c.id);
    if target.exists() {
        // an incomplete folder (no marker) of an earlier run
        std::fs::remove_dir_all(&target)?;
    }
    std::fs::remove_file(tmp.path().join(crate::output::staging::OWNER_FILE))?;
    let kept = tmp.keep();
    if let Err(e) = std::fs::rename(&kept, &target) {
        let _ = std::fs::remove_dir_all(&kept);
        return Err(e);
    }
    // permissions of a plain folder, not the temporary one's private 0o700
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        let _ = std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o755));
    }
    Ok(row)
}

/// The row of a case.
fn row(
    c: &SweepCase,
    solved: Option<&Solved>,
    reason: Option<&str>,
    wall: Duration,
    empty: &SweepTable,
) -> Vec<String> {
    let num = |v: f64| format!("{}", crate::output::csv::format::unsigned_zero(v));
    let mut r = vec![
        c.id.clone(),
        if reason.is_some() { "failed" } else { "done" }.to_string(),
    ];
    r.extend(c.values.iter().map(cell));
    let case = solved.map_or(&c.case, |s| &s.case);
    let d = &case.discretisation;
    let mut rest: Vec<String> = vec![
        if d.symmetric { "pair" } else { "full" }.into(),
        d.order.name().into(),
        d.elements.to_string(),
    ];
    match solved {
        Some(s) => {
            let o = &s.outcome;
            let last = o.points.last().expect("step 0 is always there");
            let first = o.critical.first();
            let imperfect = o.imperfection.as_ref();
            let stab = last.stability;
            rest.extend([
                o.unknowns.to_string(),
                num(case.loading.target),
                num(last.compression_ratio),
                num(last.load[2]),
                num(last.energy),
                stab.map_or(String::new(), |s| {
                    u8::from(s.unstable_directions == 0).to_string()
                }),
                stab.map_or(String::new(), |s| s.unstable_directions.to_string()),
                stab.and_then(|s| s.lowest_eigenvalue)
                    .map_or(String::new(), num),
                first.map_or(String::new(), |f| num(f.compression_ratio)),
                first.map_or(String::new(), |f| f.kind.name().into()),
                first.map_or(String::new(), |f| {
                    format!("{}->{}", f.unstable_before, f.unstable_after)
                }),
                first.map_or(String::new(), |f| num(f.load[2])),
                o.critical.len().to_string(),
                imperfect
                    .and_then(|i| i.limit_parameter)
                    .map_or(String::new(), num),
                imperfect.and_then(|i| i.drop).map_or(String::new(), num),
                o.stats.steps.to_string(),
                o.stats.iterations.to_string(),
            ]);
        }
        None => {
            // unknowns, then the target, then nothing found up to the steps
            rest.push(String::new());
            rest.push(num(case.loading.target));
            rest.extend(std::iter::repeat_n(String::new(), 15));
        }
    }
    rest.push(format!("{:.3}", wall.as_secs_f64()));
    rest.push(reason.unwrap_or("").to_string());
    r.extend(rest);
    debug_assert_eq!(r.len(), empty.headers.len());
    r
}
