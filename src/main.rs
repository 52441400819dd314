//! `spira`: the command-line face. With no arguments it opens the explorer on the built-in
//! thesis case (n = 8).

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use spira::case::Case;
use spira::model::stiffness::euler_load;
use spira::output::figures::{run_figures, Kinds, Rods, Steps};
use spira::output::precision::{ChoiceReport, StudyReport};
use spira::output::read::RunTables;
use spira::run::{run_path, run_path_steps};
use spira::session::script::{replay_into, Script};
use spira::solver::interrupt::Interrupt;
use spira::study::{resolve_accuracy, run_study, Ladder, MeshChoice, Subject};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "spira",
    version,
    about = "Mechanics of tubular assemblies of helical rods"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a case's load path and write load.csv, reactions.csv and state.csv.
    Run {
        /// Case file (TOML).
        case: PathBuf,
        /// Target compression ratio (default: the case's loading.target).
        #[arg(long = "to", allow_hyphen_values = true, value_name = "X")]
        to: Option<f64>,
        /// Number of equally spaced output steps in (0, target] (default: the case's;
        /// 1 to 100000).
        #[arg(long)]
        steps: Option<u64>,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Solve even a case whose size estimate exceeds the memory available.
        #[arg(long)]
        force: bool,
        /// Also write the state of every output step, state-<step>.csv.
        #[arg(long)]
        states: bool,
        /// Also draw the figures (load.svg; curvature and views of the last state) and
        /// write the state of every output step (as --states).
        #[arg(long)]
        figures: bool,
        /// Also write a ParaView series: series.pvd and one step-<k>.vtp per output step
        /// (and mode-<k>.vtp per critical point).
        #[arg(long)]
        vtk: bool,
    },
    /// Draw the figures of `spira run` output folders: load.svg (the load curves of every
    /// run), and per run and state curvature-step<k>.svg and views-step<k>.svg.
    Plot {
        /// Output folders of `spira run`.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Folder for the figures (default: the run folder when one is given).
        #[arg(long)]
        out: Option<PathBuf>,
        /// States to draw: compression ratios (the nearest output state of each run),
        /// comma-separated, or `all`, or `last` (the default).
        #[arg(long, default_value = "last", allow_hyphen_values = true)]
        eps: String,
        /// Rod of the curvature profiles (from 0), or `all` to overlay every rod.
        #[arg(long, default_value = "0", allow_hyphen_values = true)]
        rod: String,
        /// Only these figures: `load`, `curvature`, `views`, comma-separated.
        #[arg(long, default_value = "load,curvature,views")]
        only: String,
    },
    /// Open the terminal explorer on a case (default: the built-in thesis n = 8 case).
    Tui {
        /// Case file (TOML).
        case: Option<PathBuf>,
        /// Folder for exported CSV files.
        #[arg(long, default_value = ".")]
        out: PathBuf,
    },
    /// Work-precision study: solve the case's path on a ladder of meshes of linear and
    /// quadratic elements, time each and measure its error; print the table and write
    /// precision.csv and precision.svg.
    Precision {
        /// Case file (TOML).
        case: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Timed runs per mesh after one warm-up run (the best is kept; at most 1000).
        #[arg(long, default_value_t = 3)]
        repeats: u64,
        /// Study even a case whose size estimate exceeds the memory available.
        #[arg(long)]
        force: bool,
    },
    /// Replay a session saved in the explorer (key `s`) headless and write the CSVs the
    /// explorer's export (`e`) would have written at its end.
    Replay {
        /// Session file (TOML) written by the explorer.
        session: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Time the load path of a case (default: thesis n = 8 to eps = 0.5).
    Bench {
        /// Case file (TOML).
        case: Option<PathBuf>,
        /// Timed repetitions after one warm-up run (at most 1000).
        #[arg(long, default_value_t = 5)]
        repeats: u64,
        /// Measure the explorer instead: key press to redrawn frame while a step solves.
        #[arg(long)]
        tui: bool,
        /// Measure a 16-case sweep instead: on every core, then one case after another.
        #[arg(long, conflicts_with = "tui")]
        sweep: bool,
        /// Measure the scaling with n instead: cold `spira run` processes of the thesis
        /// geometry for n = 8, 16, 32, 64, the symmetric pair and (up to n = FULL_MAX) the
        /// full model, time and peak memory.
        #[arg(long, conflicts_with_all = ["tui", "sweep"])]
        scaling: bool,
        /// Measure cold `spira run` processes instead: thesis n = 8 (the symmetric pair) and
        /// n = 1, one after the other REPEATS times (at least 3), their times and the ratio.
        #[arg(long, conflicts_with_all = ["tui", "sweep", "scaling", "case"])]
        cold: bool,
        /// With --scaling: the largest n solved as the full model too.
        #[arg(long, default_value_t = 16)]
        full_max: usize,
    },
    /// Run a sweep: the cases of a sweep file in parallel, each into its own folder, and one
    /// table, sweep.csv; or merge the tables of shard folders (--merge).
    Sweep {
        /// Sweep file (TOML).
        #[arg(required_unless_present = "merge")]
        sweep: Option<PathBuf>,
        /// Output folder (default: out/<sweep name>; with --merge, required).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Cases at once (default: the cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Run only every N-th case starting at the K-th (1-based), e.g. 2/8. Inside a Slurm
        /// job array it defaults to the array task's place in the array.
        #[arg(long)]
        shard: Option<String>,
        /// Only validate the sweep and list its cases.
        #[arg(long)]
        check: bool,
        /// Merge the sweep tables in these folders (or files) into OUT/sweep.csv.
        #[arg(long, num_args = 1.., conflicts_with_all = ["sweep", "jobs", "shard", "check"])]
        merge: Vec<PathBuf>,
    },
}

/// The signals that end a command: Ctrl-C, `kill` and a closed terminal.
const ENDING_SIGNALS: [i32; 3] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
];

/// Ends the process as `signal` would (status 128 + signal), once no file or folder is
/// being written: a write under way finishes first (it is bounded work), so the staging
/// folder of a run is never left behind and its target holds the old files or the whole
/// new set.
fn end_between_writes(signal: i32) -> ! {
    let _no_write = spira::output::files::hold_writes();
    std::process::exit(128 + signal)
}

/// For the commands that do not stop by themselves on a signal (`plot`, `precision`,
/// `replay`, `bench`): a signal ends them between writes ([`end_between_writes`]), with
/// the status a shell expects.
fn end_on_signal_between_writes() {
    if let Ok(mut signals) = signal_hook::iterator::Signals::new(ENDING_SIGNALS) {
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                end_between_writes(signal);
            }
        });
    }
}

/// For the commands that stop by themselves (`run`, `sweep`): the first signal says
/// `message` and raises the interrupt returned, the solves stop at their last converged
/// state and the command writes what it has; a second signal ends the process between
/// writes ([`end_between_writes`]).
fn stop_on_signal(message: &'static str) -> Interrupt {
    let interrupt = Interrupt::new();
    let raise = interrupt.clone();
    if let Ok(mut signals) = signal_hook::iterator::Signals::new(ENDING_SIGNALS) {
        std::thread::spawn(move || {
            let mut signals = signals.forever();
            if signals.next().is_some() {
                eprintln!("{message}");
                raise.raise();
            }
            if let Some(signal) = signals.next() {
                end_between_writes(signal);
            }
        });
    }
    interrupt
}

fn load_case(path: Option<&Path>) -> Result<Case> {
    Ok(match path {
        Some(p) => Case::from_file(p)?,
        None => Case::default_case(),
    })
}

fn main() {
    // Rust ignores SIGPIPE, so a closed pipe (`spira run … | head`) would make every
    // further print fail; a command-line tool ends quietly there instead
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default before any thread is started
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let result = match cli.command {
        None => spira::tui::run(Case::default_case()).map_err(Into::into),
        Some(Command::Tui { case, out }) => load_case(case.as_deref())
            .and_then(|c| spira::tui::run_with(c, out, case).map_err(Into::into)),
        Some(Command::Replay { session, out }) => replay(&session, &out),
        Some(Command::Run {
            case,
            to,
            steps,
            out,
            force,
            states,
            figures,
            vtk,
        }) => run(
            &case,
            to,
            steps,
            &out,
            force,
            Extras {
                states: states || figures,
                figures,
                vtk,
            },
        ),
        Some(Command::Plot {
            dirs,
            out,
            eps,
            rod,
            only,
        }) => plot(&dirs, out.as_deref(), &eps, &rod, &only),
        Some(Command::Bench {
            case,
            repeats,
            tui: true,
            ..
        }) => repeats_flag(repeats).and_then(|repeats| {
            load_case(case.as_deref()).and_then(|c| {
                for (w, h) in [(80, 24), (160, 48)] {
                    let r = spira::tui::measure_responsiveness(c.clone(), repeats.max(1), w, h)?;
                    println!("{r}");
                }
                Ok(())
            })
        }),
        Some(Command::Bench { sweep: true, .. }) => bench_sweep(),
        Some(Command::Bench {
            cold: true,
            repeats,
            ..
        }) => repeats_flag(repeats).and_then(|r| bench_cold(r.max(3))),
        Some(Command::Bench {
            scaling: true,
            full_max,
            ..
        }) => bench_scaling(full_max),
        Some(Command::Bench { case, repeats, .. }) => {
            repeats_flag(repeats).and_then(|r| bench(case.as_deref(), r))
        }
        Some(Command::Sweep {
            sweep,
            out,
            jobs,
            shard,
            check,
            merge,
        }) => {
            if merge.is_empty() {
                let file = sweep.expect("clap requires the sweep file without --merge");
                sweep_cmd(&file, out, jobs, shard.as_deref(), check)
            } else {
                merge_cmd(&merge, out)
            }
        }
        Some(Command::Precision {
            case,
            out,
            repeats,
            force,
        }) => repeats_flag(repeats).and_then(|r| precision(&case, &out, r, force)),
    };
    if let Err(e) = result {
        eprintln!("spira: error: {e:#}");
        std::process::exit(1);
    }
}

/// The most timed repetitions `--repeats` asks for.
const MAX_REPEATS: u64 = 1000;

/// `--repeats`, bounded so that a study or a benchmark ends.
fn repeats_flag(repeats: u64) -> Result<usize> {
    if repeats > MAX_REPEATS {
        bail!(
            "--repeats: expected a number of timed runs from 0 to {MAX_REPEATS}, found {repeats}"
        );
    }
    Ok(repeats as usize)
}

/// `--steps` (or the case's `loading.steps`), within the range of `loading.steps`.
fn steps_flag(steps: Option<u64>, case: &Case) -> Result<usize> {
    let Some(steps) = steps else {
        return Ok(case.loading.steps);
    };
    let max = spira::case::MAX_STEPS as u64;
    if steps == 0 {
        bail!("--steps: expected at least 1 output step (at most {max}), found 0");
    }
    if steps > max {
        bail!("--steps: expected a number of output steps from 1 to {max}, found {steps}");
    }
    Ok(steps as usize)
}

/// The size of the case's problem, said when it is large, and refused when it would not fit
/// in memory (unless `force`).
fn check_size(case: &Case, force: bool) -> Result<()> {
    let estimate = case.size_estimate();
    match estimate.check_fits(spira::case::available_memory()) {
        Err(e) if !force => bail!("{e}; --force solves it anyway"),
        Err(e) => println!("warning: {e}; solving anyway (--force)"),
        Ok(()) if estimate.is_large() => println!("size estimate: {estimate}"),
        Ok(()) => {}
    }
    Ok(())
}

/// What `spira run` writes beside its tables.
#[derive(Clone, Copy)]
struct Extras {
    /// `state-<step>.csv` of every output step.
    states: bool,
    /// The figures of the run.
    figures: bool,
    /// A ParaView series.
    vtk: bool,
}

/// The peak resident memory of this process (MB), where the system tells it (Linux's
/// `VmHWM`).
fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// The command line as typed, the program named `spira`, for captions.
fn command_line() -> String {
    let mut args: Vec<String> = std::env::args().collect();
    if let Some(first) = args.first_mut() {
        *first = "spira".to_string();
    }
    args.join(" ")
}

fn run(
    path: &Path,
    to: Option<f64>,
    steps: Option<u64>,
    out: &Path,
    force: bool,
    extras: Extras,
) -> Result<()> {
    let case = Case::from_file(path)?;
    let target = to.unwrap_or(case.loading.target);
    if to.is_some() {
        if let Err(msg) = case.check_target(target) {
            bail!("--to: {msg}");
        }
    }
    let steps = steps_flag(steps, &case)?;
    check_size(&case, force)?;
    let (case, choice) = resolve(case)?;
    if choice.is_some() {
        check_size(&case, force)?;
    }
    let n = case.geometry.helices;
    println!(
        "spira run: case {} (n = {n}, L = {:.5} m, h0 = {:.5} m, Pcrit = {:.4} N), {} control 0 -> {target} in {steps} steps",
        case.name,
        case.geometry.length,
        case.geometry.height0(),
        euler_load(case.stiffness.b1, case.geometry.length),
        case.loading.control.name()
    );
    if case.discretisation.symmetric {
        let m = n / 2;
        println!(
            "model: one right/left pair standing for {n} rods ({m}-fold symmetry), stability by Bloch blocks p = 0..{}",
            m / 2
        );
    } else {
        println!("model: the full assembly, {n} rods");
    }
    println!(
        "  elastic hypotheses: {}; reference curvatures: {}",
        case.rod.describe(),
        case.discretisation.reference.name()
    );
    println!(
        "{:>5} {:>10} {:>14} {:>5} {:>10} {:>10} {:>9}",
        "step", "eps", "fz/(n Pcrit)", "iter", "residual", "time (ms)", "unstable"
    );
    let eps = case.output_eps(target, steps);
    let t0 = Instant::now();
    // Ctrl-C (or SIGTERM, SIGHUP) stops the path at its last converged state; the files
    // are written as after a failure. A second signal ends the process, but never while
    // the files are being written
    let interrupt = stop_on_signal("spira run: interrupted; stopping at the last converged state");
    // progress of a step that takes long: at most one line every PROGRESS_EVERY
    let last_line = Arc::new(Mutex::new(Instant::now()));
    let seen = Arc::clone(&last_line);
    let mut inner = 0usize;
    let observer: spira::solver::continuation::Observer = Box::new(move |state| {
        inner += 1;
        let mut last = seen.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() >= PROGRESS_EVERY {
            *last = Instant::now();
            eprintln!(
                "  … still solving: inner step {inner} accepted at parameter {:.6} (step {:.2e}), {:.1} s into the run",
                state.lambda,
                state.step,
                t0.elapsed().as_secs_f64()
            );
        }
    });
    let mut shapes = Vec::new();
    let outcome = run_path_steps(&case, &eps, Some(interrupt), Some(observer), |step| {
        let (p, dt) = (step.point, step.time);
        if extras.vtk || extras.states {
            shapes.push(step.snapshot.clone());
        }
        *last_line.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
        let unstable = p
            .stability
            .map(|s| s.unstable_directions.to_string())
            .unwrap_or_else(|| "-".into());
        println!(
            "{:>5} {:>10.5} {:>14.6} {:>5} {:>10.2e} {:>10.2} {:>9}",
            p.step,
            p.eps,
            p.load[2],
            p.iterations,
            p.residual,
            dt.as_secs_f64() * 1e3,
            unstable
        );
        println!("      {}", bulk_line(step.bulk));
    })
    .with_context(|| format!("case {}: no equilibrium at eps = 0", path.display()))?;
    for (i, c) in outcome.critical.iter().enumerate() {
        println!(
            "critical point {i}: {} at eps = {:.6} ({} parameter {:.8}), fz/(n Pcrit) = {:.6}, unstable directions {} -> {}{}",
            c.kind.name(),
            c.eps,
            c.control.name(),
            c.parameter,
            c.load[2],
            c.unstable_before,
            c.unstable_after,
            if outcome.switched_at == Some(i) { "; the path switched branch here" } else { "" }
        );
    }
    let last = outcome.points.last().expect("step 0 is always there");
    // the a-posteriori estimate needs the response of the run itself
    let note = choice
        .as_ref()
        .map(|c| c.note(c.estimate_with(response(&case, last))));
    let states: Vec<(usize, spira::results::Snapshot)> = if extras.states {
        outcome
            .points
            .iter()
            .map(|p| p.step)
            .zip(shapes.iter().cloned())
            .collect()
    } else {
        Vec::new()
    };
    let mut run_files = spira::output::RunFiles::of(&case.name, note.as_deref(), &outcome);
    if extras.vtk {
        run_files.series = Some((&shapes, &outcome.modes));
    }
    run_files.states = &states;
    let mut files = spira::output::run_files(&run_files)?;
    // a figure that cannot be drawn does not cost the tables: they are written, and the
    // run fails afterwards saying why
    let mut figure_error = None;
    if extras.figures {
        let t = Instant::now();
        let tables: std::collections::BTreeMap<String, String> = files.iter().cloned().collect();
        let label = out
            .file_name()
            .map_or_else(|| case.name.clone(), |n| n.to_string_lossy().into_owned());
        let figures = RunTables::from_files(&label, out, &tables)
            .context("reading back the tables of the run for its figures")
            .and_then(|run| {
                run_figures(
                    &[run],
                    &Steps::Last,
                    Rods::One(0),
                    Kinds::ALL,
                    &command_line(),
                )
                .map_err(Into::into)
            });
        match figures {
            Ok(figures) => {
                println!(
                    "drew {} figures in {:.1} ms",
                    figures.len(),
                    t.elapsed().as_secs_f64() * 1e3
                );
                files.extend(figures);
            }
            Err(e) => figure_error = Some(e),
        }
    }
    let files = spira::output::write_run_files(out, &files)
        .with_context(|| format!("writing results into {}", out.display()))?;
    println!(
        "reached eps = {:.6} in {:.1} ms: {} steps ({} rejected), {} Newton iterations, {} factorisations, {} unknowns; fz/(n Pcrit) = {:.6}, energy = {:.6e} J",
        last.eps,
        t0.elapsed().as_secs_f64() * 1e3,
        outcome.stats.steps,
        outcome.stats.rejected,
        outcome.stats.iterations,
        outcome.stats.factorisations,
        outcome.unknowns,
        last.load[2],
        last.energy
    );
    if let Some(mb) = peak_memory_mb() {
        println!("peak memory {mb:.0} MB");
    }
    if let Some(n) = &note {
        println!("{n}");
    }
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!("wrote {}", names.join(", "));
    if let Some(err) = outcome.error {
        bail!(
            "{err}; the converged steps up to eps = {:.6} were written",
            err.eps
        );
    }
    if let Some(e) = figure_error {
        return Err(e.context("the tables were written, the figures not"));
    }
    Ok(())
}

/// `spira plot`: the figures of run folders `dirs` into `out` (default: the one run folder).
fn plot(dirs: &[PathBuf], out: Option<&Path>, eps: &str, rod: &str, only: &str) -> Result<()> {
    end_on_signal_between_writes();
    let mut kinds = Kinds {
        load: false,
        curvature: false,
        views: false,
    };
    for k in only.split(',') {
        match k.trim() {
            "load" => kinds.load = true,
            "curvature" => kinds.curvature = true,
            "views" => kinds.views = true,
            other => bail!("--only: expected `load`, `curvature` or `views`, found `{other}`"),
        }
    }
    let steps = match eps.trim() {
        "last" => Steps::Last,
        "all" => Steps::All,
        list => Steps::Near(
            list.split(',')
                .map(|v| match v.trim().parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    _ => bail!(
                        "--eps: expected compression ratios separated by commas, `all` or `last`, found `{}`",
                        v.trim()
                    ),
                })
                .collect::<Result<_>>()?,
        ),
    };
    let rods = match rod.trim() {
        "all" => Rods::All,
        k => Rods::One(k.parse::<usize>().map_err(|_| {
            anyhow::anyhow!("--rod: expected a rod number (from 0) or `all`, found `{k}`")
        })?),
    };
    let out = match (out, dirs) {
        (Some(o), _) => o.to_path_buf(),
        (None, [one]) => one.clone(),
        (None, _) => bail!("--out DIR is needed for the figures of several runs"),
    };
    let t = Instant::now();
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
    let files = run_figures(&runs, &steps, rods, kinds, &command_line())?;
    let drawn = t.elapsed();
    let names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    let paths =
        spira::output::files::write_folder(&out, &files, |name| names.iter().any(|n| n == name))
            .with_context(|| format!("writing figures into {}", out.display()))?;
    let shown: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!(
        "spira plot: {} run(s) read and drawn in {:.1} ms; wrote {}",
        runs.len(),
        drawn.as_secs_f64() * 1e3,
        shown.join(", ")
    );
    Ok(())
}

/// One line on the bulk of a step: the stretch of s/L common to every rod's bulk, the mean
/// fitted helix, Love's force for it against the rods' mean tip force, and the finite
/// assembly's force over the infinite tube's.
fn bulk_line(bulk: &spira::results::StepBulk) -> String {
    let n = bulk.rods.len().max(1) as f64;
    let start = bulk
        .rods
        .iter()
        .map(|b| b.start_over_l())
        .fold(0.0, f64::max);
    let end = bulk.rods.iter().map(|b| b.end_over_l()).fold(1.0, f64::min);
    let mean =
        |f: &dyn Fn(&spira::results::RodBulk) -> f64| bulk.rods.iter().map(f).sum::<f64>() / n;
    let love: Option<f64> = bulk
        .rods
        .iter()
        .map(|b| b.love_force)
        .sum::<Option<f64>>()
        .map(|f| f / n);
    let extent = if end > start {
        format!("bulk s/L {start:.3}-{end:.3}")
    } else {
        "no bulk common to all rods".to_string()
    };
    format!(
        "{extent}, helix a = {:.5} m, b = {:.5} m, Love F = {}, tip fz = {:.4} N, finite/infinite tube = {}",
        mean(&|b| b.radius),
        mean(&|b| b.pitch),
        love.map_or("-".to_string(), |f| format!("{f:.4} N")),
        mean(&|b| b.axial_force),
        bulk.tube_ratio.map_or("-".to_string(), |r| format!("{r:.4}"))
    )
}

/// How long `spira run` stays silent during a step before it reports progress.
const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_secs(2);

fn replay(session: &Path, out: &Path) -> Result<()> {
    end_on_signal_between_writes();
    let script = Script::read(session)?;
    let case = load_case(script.case.as_deref())?;
    let files = replay_into(&script, &case, out)?;
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!(
        "spira replay: {} actions of {}; wrote {}",
        script.actions.len(),
        session.display(),
        names.join(", ")
    );
    Ok(())
}

fn bench(path: Option<&Path>, repeats: usize) -> Result<()> {
    end_on_signal_between_writes();
    let (mut case, _) = resolve(load_case(path)?)?;
    // the full model first, the symmetric pair (what "auto" solves) beside it
    case.discretisation.symmetric = false;
    let eps = case.output_eps(case.loading.target, case.loading.steps);
    println!(
        "spira bench: case {} (n = {}, {} {:?} elements per rod), eps 0 -> {} in {} output steps, {} timed runs after a warm-up",
        case.name,
        case.geometry.helices,
        case.discretisation.elements,
        case.discretisation.order,
        case.loading.target,
        case.loading.steps,
        repeats.max(1)
    );
    let (best, mean, o) = time_path(&case, &eps, repeats)?;
    println!("unknowns (incl. multipliers): {}", o.unknowns);
    println!(
        "internal steps: {} ({} rejected), Newton iterations: {}, factorisations: {}",
        o.stats.steps, o.stats.rejected, o.stats.iterations, o.stats.factorisations
    );
    println!(
        "time per path: best {:.1} ms, mean {:.1} ms (stability of every step counted, lowest eigenvalue at every output step)",
        best * 1e3,
        mean * 1e3
    );
    println!(
        "time per output step: {:.2} ms; per internal step: {:.2} ms; per Newton iteration: {:.2} ms",
        best * 1e3 / eps.len() as f64,
        best * 1e3 / o.stats.steps.max(1) as f64,
        best * 1e3 / o.stats.iterations.max(1) as f64
    );
    // the same path without stability, and as a symmetric pair when the case has the symmetry
    let mut plain = case.clone();
    plain.solver.track_stability = false;
    let (plain_best, _, _) = time_path(&plain, &eps, repeats)?;
    println!(
        "without stability: best {:.1} ms per path, {:.2} ms per output step",
        plain_best * 1e3,
        plain_best * 1e3 / eps.len() as f64
    );
    let n = case.geometry.helices;
    if !case.discretisation.symmetric && n >= 4 && n % 2 == 0 {
        for track in [true, false] {
            let mut pair = case.clone();
            pair.discretisation.symmetric = true;
            pair.solver.track_stability = track;
            let (pb, _, po) = time_path(&pair, &eps, repeats)?;
            let reference = if track { best } else { plain_best };
            let (a, b) = (
                o.points.last().expect("points"),
                po.points.last().expect("points"),
            );
            let diff = a
                .reactions
                .iter()
                .zip(&b.reactions)
                .flat_map(|(ra, rb)| (0..3).map(move |k| (ra.tip.force[k] - rb.tip.force[k]).abs()))
                .fold(0.0f64, f64::max)
                / a.reactions[0]
                    .tip
                    .force
                    .iter()
                    .map(|f| f * f)
                    .sum::<f64>()
                    .sqrt();
            println!(
                "symmetric pair ({} unknowns{}): best {:.1} ms per path, {:.2} ms per output step, speed-up {:.1}x; largest tip-force difference to the full model {:.1e} (relative)",
                po.unknowns,
                if track { ", stability by Bloch blocks" } else { ", no stability" },
                pb * 1e3,
                pb * 1e3 / eps.len() as f64,
                reference / pb,
                diff
            );
        }
    }
    Ok(())
}

/// Best and mean wall time (s) of `repeats` runs of a path after a warm-up, and the last
/// outcome.
fn time_path(
    case: &Case,
    eps: &[f64],
    repeats: usize,
) -> Result<(f64, f64, spira::run::PathOutcome)> {
    let mut best = f64::INFINITY;
    let mut times = Vec::new();
    let mut last = None;
    for r in 0..=repeats.max(1) {
        let t = Instant::now();
        let outcome = run_path(case, eps, |_, _| {})?;
        let dt = t.elapsed().as_secs_f64();
        if r > 0 {
            best = best.min(dt);
            times.push(dt);
        }
        if let Some(e) = &outcome.error {
            bail!("{e}");
        }
        last = Some(outcome);
    }
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    Ok((best, mean, last.expect("at least one run")))
}

/// The case with its mesh: when it gives an accuracy instead, the mesh chosen for it
/// (issue 5), said on the way.
fn resolve(case: Case) -> Result<(Case, Option<MeshChoice>)> {
    let Some(acc) = case.discretisation.accuracy else {
        return Ok((case, None));
    };
    println!(
        "choosing the mesh for accuracy {:e} on the response ({}) from two coarse solves per element order:",
        acc.target,
        Subject::Path(Box::new(case.clone())).response_label()
    );
    let (resolved, choice) = resolve_accuracy(&case)?;
    if let Some(c) = &choice {
        for line in c.pilot_lines() {
            println!("  {line}");
        }
        println!(
            "  chosen: {} elements, {} per rod, predicted error {:.1e} ({:.0} ms of pilot solves)",
            c.order.name(),
            c.elements,
            c.estimated_error,
            c.cost.as_secs_f64() * 1e3
        );
    }
    Ok((resolved, choice))
}

/// The response an accuracy refers to: `Fz/(n Pcrit)` under displacement control, `ε` under
/// load control.
fn response(case: &Case, point: &spira::results::LoadPoint) -> f64 {
    match case.loading.control {
        spira::model::loading::Control::Displacement => point.load[2],
        spira::model::loading::Control::Force => point.eps,
    }
}

fn precision(path: &Path, out: &Path, repeats: usize, force: bool) -> Result<()> {
    end_on_signal_between_writes();
    let case = Case::from_file(path)?;
    check_size(&case, force)?;
    let problem = Subject::Path(Box::new(case.clone()));
    let ladder = Ladder::standard(&problem);
    println!(
        "spira precision: case {} ({}), {} meshes, each timed by {}",
        case.name,
        problem.describe(),
        ladder.rungs.len(),
        match repeats {
            0 => "one run (no warm-up)".to_string(),
            1 => "one run after a warm-up".to_string(),
            k => format!("the best of {k} runs after a warm-up"),
        }
    );
    let t0 = Instant::now();
    let study = run_study(&problem, &ladder, repeats, |p| {
        let r = p.last;
        match &r.values {
            Ok(v) => println!(
                "  [{}/{}] {} {} elements/rod: {:.1} ms",
                p.done,
                p.total,
                r.rung.order.name(),
                v.elements,
                r.time.as_secs_f64() * 1e3
            ),
            Err(e) => println!(
                "  [{}/{}] {} {} elements/rod: failed: {e}",
                p.done,
                p.total,
                r.rung.order.name(),
                r.rung.elements
            ),
        }
        std::ops::ControlFlow::Continue(())
    })?;
    println!();
    for line in study.header() {
        println!("{line}");
    }
    println!();
    print!("{}", study.table());
    if let Some(acc) = case.discretisation.accuracy {
        match study.cheapest_meeting(acc.target) {
            Some(r) => println!(
                "cheapest mesh of the ladder meeting the case's accuracy {:e}: {} {} elements/rod",
                acc.target,
                r.rung.order.name(),
                r.elements()
            ),
            None => println!(
                "no mesh of the ladder meets the case's accuracy {:e}",
                acc.target
            ),
        }
    }
    let csv = out.join("precision.csv");
    let svg = out.join("precision.svg");
    let files = [
        ("precision.csv".to_string(), study.csv()),
        ("precision.svg".to_string(), study.svg_for(&command_line())?),
    ];
    spira::output::files::write_folder(out, &files, spira::output::precision::is_precision_file)
        .with_context(|| format!("writing results into {}", out.display()))?;
    println!(
        "wrote {}, {} in {:.1} s",
        csv.display(),
        svg.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

fn sweep_cmd(
    path: &Path,
    out: Option<PathBuf>,
    jobs: Option<usize>,
    shard: Option<&str>,
    check: bool,
) -> Result<()> {
    use spira::sweep::{run_sweep, workers, CaseStatus, RunOptions, Shard, Sweep};
    use std::io::{IsTerminal as _, Write as _};
    let sweep = Sweep::from_file(path)?;
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
    let jobs = workers(jobs);
    println!(
        "spira sweep: {} ({}): {} cases ({} axes, {}){}, {} into {} on {jobs} worker(s)",
        sweep.name,
        path.display(),
        sweep.cases.len(),
        sweep.axes.len(),
        match sweep.combine {
            spira::sweep::Combine::Product => "product",
            spira::sweep::Combine::Zip => "zip",
        },
        if shard == Shard::ALL {
            String::new()
        } else {
            format!(", shard {}", shard.label())
        },
        mine.len(),
        out.display()
    );
    if check {
        for c in &mine {
            println!("  {}", c.id);
        }
        println!("all {} generated cases are valid", sweep.cases.len());
        return Ok(());
    }
    let terminal = std::io::stdout().is_terminal();
    let interrupt = stop_on_signal(
        "spira sweep: interrupted; the cases under way stop and are not written, no case starts",
    );
    let opts = RunOptions {
        out: out.clone(),
        jobs: Some(jobs),
        shard,
        interrupt: Some(interrupt),
    };
    let report = run_sweep(&sweep, &opts, |p| {
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
            // one progress line, rewritten; failures stay on their own line
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
        std::ops::ControlFlow::Continue(())
    })?;
    if terminal {
        println!();
    }
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

fn merge_cmd(inputs: &[PathBuf], out: Option<PathBuf>) -> Result<()> {
    let Some(out) = out else {
        bail!("--merge needs --out DIR for the merged sweep.csv");
    };
    let (table, path) = spira::sweep::merge_dirs(inputs, &out)?;
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

/// The sweep of `spira bench --sweep`: 16 cases of similar cost (n = 2, 8 lengths, fixed
/// and sliding tips).
const BENCH_SWEEP: &str = r#"
name = "bench"
combine = "product"
[case]
geometry.helices = 2
discretisation.elements = 24
loading.target = 0.3
loading.steps = 6
[axes]
"geometry.turns" = [2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5]
"boundary.tip" = [{ translation = "fixed", rotation = "clamped" }, { translation = "slide", rotation = "clamped" }]
"#;

/// One cold `spira run` process of this binary on the case `text` (written into `dir` as
/// `name.toml`, its output folder beside it): its wall time (s), and the unknowns and peak
/// memory (MB) it reports.
struct ColdRun {
    wall: f64,
    unknowns: String,
    memory: String,
}

fn cold_run(dir: &Path, name: &str, text: &str) -> Result<ColdRun> {
    let exe = std::env::current_exe().context("finding the spira binary")?;
    let case = dir.join(format!("{name}.toml"));
    std::fs::write(&case, text)?;
    let out = dir.join(format!("out-{name}"));
    let t = Instant::now();
    let output = std::process::Command::new(&exe)
        .args(["run", &case.to_string_lossy(), "--force", "--out"])
        .arg(&out)
        .output()
        .context("running spira run")?;
    let wall = t.elapsed().as_secs_f64();
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    if !output.status.success() {
        bail!(
            "{name}: spira run failed: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let unknowns = text
        .split(" unknowns;")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .unwrap_or("?")
        .to_string();
    let memory = text
        .lines()
        .find_map(|l| l.strip_prefix("peak memory "))
        .map_or("?".into(), |m| m.trim_end_matches(" MB").to_string());
    // the next run writes a folder of its own: a removed one leaves no trace to reuse
    std::fs::remove_dir_all(&out).ok();
    Ok(ColdRun {
        wall,
        unknowns,
        memory,
    })
}

/// `spira bench --cold`: what a user waits for, a whole `spira run` process, for the
/// thesis assembly of n = 8 helices (solved as the symmetric pair, its stability by Bloch
/// blocks) and of one helix, alternately so that both see the same load of the machine;
/// the best and median times of each and their ratios.
fn bench_cold(repeats: usize) -> Result<()> {
    let dir = tempfile::tempdir()?;
    println!(
        "spira bench --cold: thesis geometry (48 quadratic elements per rod), eps 0 -> 0.5 in 10 output steps, stability at every step, lowest eigenvalue at every output step; cold `spira run` processes, n = 8 and n = 1 alternately, {repeats} each"
    );
    let cases = [
        ("n8", "[geometry]\nhelices = 8\n"),
        ("n1", "[geometry]\nhelices = 1\n"),
    ];
    let mut times = [Vec::new(), Vec::new()];
    let mut memory = [String::new(), String::new()];
    for _ in 0..repeats {
        for (k, (name, text)) in cases.iter().enumerate() {
            let r = cold_run(dir.path(), name, text)?;
            times[k].push(r.wall);
            memory[k] = r.memory;
        }
    }
    let stats = |t: &mut Vec<f64>| {
        t.sort_by(f64::total_cmp);
        (t[0], t[t.len() / 2])
    };
    let (best8, median8) = stats(&mut times[0]);
    let (best1, median1) = stats(&mut times[1]);
    println!(
        "{:>6} {:>10} {:>12} {:>12}",
        "n", "best (ms)", "median (ms)", "memory (MB)"
    );
    for (n, best, median, mem) in [
        (8, best8, median8, &memory[0]),
        (1, best1, median1, &memory[1]),
    ] {
        println!(
            "{n:>6} {:>10.1} {:>12.1} {mem:>12}",
            best * 1e3,
            median * 1e3
        );
    }
    println!(
        "n = 8 / n = 1: {:.2} best, {:.2} median (the goals: n = 8 at most 250 ms, at most 2 times n = 1)",
        best8 / best1,
        median8 / median1
    );
    Ok(())
}

/// `spira bench --scaling`: cold `spira run` processes of this binary on the thesis
/// geometry (56 quadratic elements per rod, ε 0 → 0.5 in 10 output steps, stability of every
/// step, lowest eigenvalue at every output step) for n = 8 … 64, pair and full model side by
/// side, each process's wall time and peak memory (as it reports it).
fn bench_scaling(full_max: usize) -> Result<()> {
    let dir = tempfile::tempdir()?;
    println!(
        "spira bench --scaling: thesis geometry, 56 quadratic elements per rod, eps 0 -> 0.5 in 10 output steps, stability at every step, lowest eigenvalue at every output step; cold `spira run` processes"
    );
    println!(
        "{:>4} {:>6} {:>10} {:>10} {:>12}",
        "n", "model", "unknowns", "time (s)", "memory (MB)"
    );
    for n in [8usize, 16, 32, 64] {
        for pair in [true, false] {
            if !pair && n > full_max {
                continue;
            }
            let text = format!(
                "[geometry]\nhelices = {n}\n[discretisation]\nelements = 56\nsymmetric = {pair}\n"
            );
            let r = cold_run(dir.path(), &format!("n{n}-{pair}"), &text)?;
            println!(
                "{n:>4} {:>6} {:>10} {:>10.2} {:>12}",
                if pair { "pair" } else { "full" },
                r.unknowns,
                r.wall,
                r.memory
            );
        }
    }
    Ok(())
}

fn bench_sweep() -> Result<()> {
    use spira::sweep::{run_sweep, workers, RunOptions, Shard, Sweep};
    let sweep = Sweep::parse(
        BENCH_SWEEP,
        "bench sweep (built in)",
        "bench",
        Path::new("."),
    )?;
    let cores = workers(None);
    println!(
        "spira bench --sweep: {} cases (n = 2, 24 quadratic elements per rod, eps 0 -> 0.3 in 6 steps, turns 2 ... 5.5, fixed and sliding tips), {cores} core(s)",
        sweep.cases.len()
    );
    let mut times = Vec::new();
    for jobs in [cores, 1] {
        let dir = tempfile::tempdir()?;
        let opts = RunOptions {
            out: dir.path().to_path_buf(),
            jobs: Some(jobs),
            shard: Shard::ALL,
            interrupt: None,
        };
        let report = run_sweep(&sweep, &opts, |_| std::ops::ControlFlow::Continue(()))?;
        if report.failed > 0 {
            bail!("{} bench cases failed", report.failed);
        }
        let t = report.wall.as_secs_f64();
        println!("{jobs} worker(s): {t:.2} s for {} cases", report.total);
        times.push(t);
    }
    println!(
        "parallel / one after another: {:.2} (the goal: at most 0.6)",
        times[0] / times[1]
    );
    Ok(())
}
