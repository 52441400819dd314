//! `spira run`: a case's load path, its progress as a table, its files (tables, and on
//! request the states, a ParaView series and the figures) and a summary.

use super::mesh::{resolve, response};
use super::signals::stop_on_signal;
use super::{check_size, command_line};
use anyhow::{bail, Context, Result};
use spira::case::{settings_line, Case, Setting};
use spira::model::loading::{AxialHeld, Component};
use spira::model::stiffness::euler_load;
use spira::output::figures::{run_figures, Kinds, Rods, Steps};
use spira::output::precision::ChoiceReport as _;
use spira::output::read::RunTables;
use spira::results::{RodBulk, Snapshot, StepBulk, SupportResponse};
use spira::run::{run_path_steps, PathOutcome, Step};
use spira::solver::continuation::{Observer, StopReason};
use spira::solver::interrupt::Interrupt;
use spira::study::MeshChoice;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What `spira run` writes beside its tables.
#[derive(Clone, Copy)]
pub struct Extras {
    /// `state-<step>.csv` of every output step.
    pub states: bool,
    /// The figures of the run.
    pub figures: bool,
    /// A ParaView series.
    pub vtk: bool,
}

/// The flags of `spira run` that bound its path.
#[derive(Clone, Copy)]
pub struct Flags {
    /// Target load parameter (default: the case's).
    pub to: Option<f64>,
    /// Output steps (default: the case's).
    pub steps: Option<u64>,
    /// Solve even a case too large for the memory available.
    pub force: bool,
}

/// How long `spira run` stays silent during a step before it reports progress.
const PROGRESS_EVERY: Duration = Duration::from_secs(2);

/// `spira run`: the path of the case at `path` with the overrides `set`, to `flags.to`
/// (default: the case's target) in `flags.steps` output steps (default: the case's), its
/// files written into `out`.
pub fn run(path: &Path, set: &[Setting], flags: Flags, out: &Path, extras: Extras) -> Result<()> {
    // Ctrl-C (or SIGTERM, SIGHUP) stops the mesh choice (nothing is written) or the path at
    // its last converged state (the files are written as after a failure). A second signal
    // ends the process, but never while the files are being written
    let interrupt = stop_on_signal("spira run: interrupted; stopping");
    let (case, target, steps, choice) = prepare(path, set, flags, &interrupt)?;
    let set_line = (!set.is_empty()).then(|| set_note(set));
    print_heading(&case, target, steps, set_line.as_deref());
    let parameters = case.output_parameters(target, steps);
    let t0 = Instant::now();
    let (last_line, observer) = still_solving(t0);
    let mut shapes = Vec::new();
    let outcome = run_path_steps(
        &case,
        &parameters,
        Some(interrupt),
        Some(observer),
        |step| {
            if extras.vtk || extras.states {
                shapes.push(step.snapshot.clone());
            }
            *last_line.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
            print_step(step, case.loading.parameter);
        },
    )
    .with_context(|| format!("case {}: no equilibrium at eps = 0", path.display()))?;
    print_critical_points(&outcome);
    if let Some(imperfect) = &outcome.imperfection {
        println!("{}", imperfect.summary());
    }
    if let Some(bands) = spira::output::dispersion::bands_summary(&outcome.dispersion) {
        println!("{bands}");
    }
    if let Some(beam) = spira::output::beam::beam_summary(&outcome.beam) {
        println!("{beam}");
    }
    let last = outcome.points.last().expect("step 0 is always there");
    // the a-posteriori estimate needs the response of the run itself
    let note = choice
        .as_ref()
        .map(|c| c.note(c.estimate_with(response(&case, last))));
    let notes = Notes {
        mesh: note.as_deref(),
        set: set_line.as_deref(),
    };
    let mut files = tables(&case, notes, &outcome, &shapes, extras)?;
    // a figure that cannot be drawn does not cost the tables: they are written, and the
    // run fails afterwards saying why
    let mut figure_error = None;
    if extras.figures {
        match figures(&case, out, &files) {
            Ok(figures) => files.extend(figures),
            Err(e) => figure_error = Some(e),
        }
    }
    let written = spira::output::write_run_files(out, &files)
        .with_context(|| format!("writing results into {}", out.display()))?;
    print_summary(
        &outcome,
        case.loading.parameter,
        t0,
        note.as_deref(),
        (out, &written),
    );
    if let Some(err) = outcome.error {
        bail!(
            "{err}; the converged steps up to eps = {:.6} were written",
            err.compression_ratio
        );
    }
    if let Some(e) = figure_error {
        return Err(e.context("the tables were written, the figures not"));
    }
    Ok(())
}

/// The case at `path` with its mesh (chosen for its accuracy target if it gives one), the
/// target load parameter and the number of output steps, the flags checked and the size of
/// the problem with them.
fn prepare(
    path: &Path,
    set: &[Setting],
    flags: Flags,
    interrupt: &Interrupt,
) -> Result<(Case, f64, usize, Option<MeshChoice>)> {
    let Flags { to, steps, force } = flags;
    let case = Case::from_file_with(path, set)?;
    let target = to.unwrap_or(case.loading.target);
    if to.is_some() {
        if let Err(msg) = case.check_target(target) {
            bail!("--to: {msg}");
        }
    }
    let steps = steps_flag(steps, &case)?;
    check_size(&case, force)?;
    let (case, choice) = resolve(case, interrupt)?;
    if choice.is_some() {
        check_size(&case, force)?;
    }
    Ok((case, target, steps, choice))
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

/// The case, the keys `--set` overrode (`set_line`), the model solved and the head of the
/// progress table.
fn print_heading(case: &Case, target: f64, steps: usize, set_line: Option<&str>) {
    let n = case.geometry.helices;
    let parameter = case.loading.parameter;
    let stepped = match parameter {
        Component::Axial => format!("{} control", case.loading.control.name()),
        _ => format!("{} {}", parameter.name(), case.load_parameter().ascii()),
    };
    let unit = case.load_parameter().unit();
    println!(
        "spira run: case {} (n = {n}, L = {:.5} m, h0 = {:.5} m, Pcrit = {:.4} N), {stepped} 0 -> {}{}{unit} in {steps} steps",
        case.name,
        case.geometry.length,
        case.geometry.height0(),
        euler_load(case.stiffness.b1, case.geometry.length),
        spira::case::num(target),
        if unit.is_empty() { "" } else { " " },
    );
    if let Some(line) = set_line {
        println!("{line}");
    }
    if let Some(imp) = &case.imperfection {
        println!("imperfection: {}", imp.describe());
    }
    if !case.loading.hold.is_natural() || parameter != Component::Axial {
        println!("held: {}", held_line(case));
    }
    if case.bends_cell() {
        let model = case.model();
        println!(
            "model: the bending cell of an infinitely long tube of {n} helices, all {n} rods over 1/{} turn (L = {:.5} m), periodic under the turn by the tilt about a transverse axis; stability of a bent cell: only against perturbations of its own period (its Bloch blocks are not computed)",
            n / 2,
            model.length(),
        );
    } else if case.discretisation.cell {
        let model = case.model();
        println!(
            "model: the cell of an infinitely long tube of {n} helices, rods of 1/{n} turn (L = {:.5} m, Pcrit = {:.4} N of a cell's rod), stability by the blocks H(p, k), p = 0..{}",
            model.length(),
            euler_load(case.stiffness.b1, model.length()),
            n / 2 - 1
        );
    } else if case.discretisation.symmetric {
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
    let pair = SupportResponse::default()
        .pair(parameter)
        .map_or(String::new(), |[m, f]| format!(" {:>13} {:>13}", m.1, f.1));
    println!(
        "{:>5} {:>10} {:>14} {:>5} {:>10} {:>10} {:>9}{pair}",
        "step", "eps", "fz/(n Pcrit)", "iter", "residual", "time (ms)", "unstable"
    );
}

/// The values the components not stepped are held at.
fn held_line(case: &Case) -> String {
    let h = case.loading.hold;
    let parameter = case.loading.parameter;
    let mut parts = Vec::new();
    if parameter != Component::Axial {
        parts.push(match h.axial {
            AxialHeld::Ratio(e) => format!("eps = {e}"),
            AxialHeld::Load(0.0) => "axial position free".to_string(),
            AxialHeld::Load(p) => format!("P/Pcrit = {p}"),
        });
    }
    for (c, v, unit) in [
        (Component::Twist, h.twist, "rad"),
        (Component::Tilt, h.tilt, "rad"),
        (Component::Pressure, h.pressure, "N/m"),
    ] {
        if c != parameter {
            parts.push(format!("{} = {v} {unit}", c.name()));
        }
    }
    parts.join(", ")
}

/// The progress of a step that takes long: an observer of the inner steps that says, at
/// most once every [`PROGRESS_EVERY`] since the last line (whose time is shared, to be
/// renewed by every line of the table), where the path is, `t0` being the start of the run.
fn still_solving(t0: Instant) -> (Arc<Mutex<Instant>>, Observer) {
    let last_line = Arc::new(Mutex::new(Instant::now()));
    let seen = Arc::clone(&last_line);
    let mut inner = 0usize;
    let observer: Observer = Box::new(move |state| {
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
    (last_line, observer)
}

/// The line of the progress table of an output step, and the line on its bulk.
fn print_step(step: &Step, parameter: Component) {
    let (p, dt) = (step.point, step.time);
    let unstable = p
        .stability
        .map(|s| s.unstable_directions.to_string())
        .unwrap_or_else(|| "-".into());
    let pair = p.support.pair(parameter).map_or(String::new(), |[m, f]| {
        format!(" {:>13.6e} {:>13.6e}", m.0, f.0)
    });
    println!(
        "{:>5} {:>10.5} {:>14.6} {:>5} {:>10.2e} {:>10.2} {:>9}{pair}",
        p.step,
        p.compression_ratio,
        p.load[2],
        p.iterations,
        p.residual,
        dt.as_secs_f64() * 1e3,
        unstable
    );
    println!("      {}", bulk_line(step.bulk));
}

/// One line on the bulk of a step: the stretch of s/L common to every rod's bulk, the mean
/// fitted helix, Love's force for it against the rods' mean tip force, and the finite
/// assembly's force over the infinite tube's.
fn bulk_line(bulk: &StepBulk) -> String {
    let n = bulk.rods.len().max(1) as f64;
    let start = bulk
        .rods
        .iter()
        .map(|b| b.start_over_l())
        .fold(0.0, f64::max);
    let end = bulk.rods.iter().map(|b| b.end_over_l()).fold(1.0, f64::min);
    let mean = |f: &dyn Fn(&RodBulk) -> f64| bulk.rods.iter().map(f).sum::<f64>() / n;
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
    ) + &match (bulk.tube_radius, bulk.radius_ratio) {
        (Some(a), Some(r)) => format!(", infinite tube under this pressure a = {a:.5} m (ratio {r:.4})"),
        _ => String::new(),
    }
}

/// One line per critical point of the path.
fn print_critical_points(outcome: &PathOutcome) {
    for (i, c) in outcome.critical.iter().enumerate() {
        println!(
            "critical point {i}: {} at eps = {:.6} ({} parameter {:.8}), fz/(n Pcrit) = {:.6}, unstable directions {}{}",
            c.kind.name(),
            c.compression_ratio,
            c.control.name(),
            c.parameter,
            c.load[2],
            c.count_change("->"),
            if outcome.switched_at == Some(i) { "; the path switched branch here" } else { "" }
        );
    }
}

/// The line that says which keys of the case `--set` overrode, for the summary and the
/// header of every table.
pub fn set_note(set: &[Setting]) -> String {
    format!(
        "case keys set on the command line (--set): {}",
        settings_line(set)
    )
}

/// The `#` lines of a run's tables beside the case's: the mesh an accuracy target chose,
/// the keys `--set` overrode.
#[derive(Clone, Copy)]
struct Notes<'a> {
    mesh: Option<&'a str>,
    set: Option<&'a str>,
}

/// The tables of the run as (file name, text), with the states of the output steps and a
/// ParaView series as `extras` asks (`shapes`: the shape of every output step, kept when
/// either is asked).
fn tables(
    case: &Case,
    notes: Notes,
    outcome: &PathOutcome,
    shapes: &[Snapshot],
    extras: Extras,
) -> Result<Vec<(String, String)>> {
    let states: Vec<(usize, Snapshot)> = if extras.states {
        outcome
            .points
            .iter()
            .map(|p| p.step)
            .zip(shapes.iter().cloned())
            .collect()
    } else {
        Vec::new()
    };
    let mut run_files = spira::output::RunFiles::of(&case.name, notes.mesh, outcome);
    run_files.set = notes.set;
    if extras.vtk {
        run_files.series = Some((shapes, &outcome.modes));
    }
    run_files.states = &states;
    Ok(spira::output::run_files(&run_files)?)
}

/// The figures of the run (the load curves, the curvature and the views of the last state),
/// drawn from its tables `files` as `spira plot` would read them back from `out`.
fn figures(case: &Case, out: &Path, files: &[(String, String)]) -> Result<Vec<(String, String)>> {
    let t = Instant::now();
    let tables: BTreeMap<String, String> = files.iter().cloned().collect();
    let label = out
        .file_name()
        .map_or_else(|| case.name.clone(), |n| n.to_string_lossy().into_owned());
    let run = RunTables::from_files(&label, out, &tables)
        .context("reading back the tables of the run for its figures")?;
    let figures = run_figures(
        &[run],
        &Steps::Last,
        Rods::One(0),
        Kinds::ALL,
        &command_line(),
    )?;
    println!(
        "drew {} figures in {:.1} ms",
        figures.len(),
        t.elapsed().as_secs_f64() * 1e3
    );
    Ok(figures)
}

/// Where the path ended, what it cost (from `t0`), the mesh's note and the files written
/// into `out`.
fn print_summary(
    outcome: &PathOutcome,
    parameter: Component,
    t0: Instant,
    note: Option<&str>,
    (out, written): (&Path, &[PathBuf]),
) {
    let last = outcome.points.last().expect("step 0 is always there");
    if let Some([m, f]) = last.support.pair(parameter) {
        println!(
            "{}: {} = {:.6e}, {} = {:.6e}",
            parameter.name(),
            m.1,
            m.0,
            f.1,
            f.0
        );
    }
    // a path stopped short of its target did not reach anything
    let ended = match &outcome.error {
        None => "reached",
        Some(e) if matches!(e.reason, StopReason::Interrupted(_)) => "interrupted at",
        Some(_) => "stopped at",
    };
    println!(
        "{ended} eps = {:.6} in {:.1} ms: {} steps ({} rejected), {} Newton iterations, {} factorisations, {} unknowns; fz/(n Pcrit) = {:.6}, energy = {:.6e} J",
        last.compression_ratio,
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
    if let Some(n) = note {
        println!("{n}");
    }
    println!("{}", spira::output::written_summary(out, written));
}

/// The peak resident memory of this process (MB), where the system tells it (Linux's
/// `VmHWM`).
fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}
