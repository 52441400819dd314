//! `spira bench`: the timings the performance goals are stated in: a case's load path in
//! this process, the explorer's response to a key, a sweep on every core, and cold
//! `spira run` processes.

mod cell;
mod cold;
mod sweep;

use super::mesh::resolve;
use super::signals::end_on_signal_between_writes;
use super::{load_case, repeats_flag};
use anyhow::{bail, Result};
use spira::case::Case;
use spira::run::{run_path, PathOutcome};
use spira::solver::interrupt::Interrupt;
use std::path::Path;
use std::time::Instant;

/// What `spira bench` measures.
#[derive(Clone, Copy, Debug)]
pub enum Measure {
    /// The load path of a case in this process: the full model, without stability, and the
    /// symmetric pair.
    Path,
    /// The explorer: key press to redrawn frame while a step solves (`--tui`).
    Explorer,
    /// A 16-case sweep on every core, then one case after another (`--sweep`).
    Sweep,
    /// The stability map of one state of the infinite tube's cell, n = 8 and 64, beside the
    /// finite pair's (`--cell`).
    Cell,
    /// Cold `spira run` processes of thesis n = 8 and n = 1 (`--cold`).
    Cold,
    /// Cold `spira run` processes for n = 8 … 64, the full model up to `full_max` helices
    /// (`--scaling`).
    Scaling { full_max: usize },
}

/// `spira bench`: `measure` on the case at `case` (default: the built-in thesis case,
/// n = 8) where it takes one, with `repeats` timed runs where it repeats.
pub fn bench(case: Option<&Path>, repeats: u64, measure: Measure) -> Result<()> {
    match measure {
        Measure::Path => bench_path(case, repeats_flag(repeats)?),
        Measure::Explorer => {
            let repeats = repeats_flag(repeats)?;
            let case = load_case(case)?;
            for (w, h) in [(80, 24), (160, 48)] {
                let r = spira::tui::measure_responsiveness(case.clone(), repeats.max(1), w, h)?;
                println!("{r}");
            }
            Ok(())
        }
        Measure::Sweep => sweep::bench_sweep(),
        Measure::Cell => cell::bench_cell(repeats_flag(repeats)?.max(1)),
        Measure::Cold => cold::bench_cold(repeats_flag(repeats)?.max(3)),
        Measure::Scaling { full_max } => cold::bench_scaling(full_max),
    }
}

/// `spira bench [CASE]`: the load path of the case timed by `repeats` runs after a warm-up,
/// as the full model, without stability, and as the symmetric pair when the case has the
/// symmetry.
fn bench_path(path: Option<&Path>, repeats: usize) -> Result<()> {
    end_on_signal_between_writes();
    let (mut case, _) = resolve(load_case(path)?, &Interrupt::new())?;
    // the full model first, the symmetric pair (what "auto" solves) beside it
    case.discretisation.symmetric = false;
    let parameters = case.output_parameters(case.loading.target, case.loading.steps);
    println!(
        "spira bench: case {} (n = {}, {} {:?} elements per rod), {} 0 -> {} in {} output steps, {} timed runs after a warm-up",
        case.name,
        case.geometry.helices,
        case.discretisation.elements,
        case.discretisation.order,
        case.load_parameter().ascii(),
        spira::case::num(case.loading.target),
        case.loading.steps,
        repeats.max(1)
    );
    let (best, mean, o) = time_path(&case, &parameters, repeats)?;
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
    let outputs = parameters.len() as f64;
    println!(
        "time per output step: {:.2} ms; per internal step: {:.2} ms; per Newton iteration: {:.2} ms",
        best * 1e3 / outputs,
        best * 1e3 / o.stats.steps.max(1) as f64,
        best * 1e3 / o.stats.iterations.max(1) as f64
    );
    // the same path without stability, and as a symmetric pair when the case has the symmetry
    let mut plain = case.clone();
    plain.solver.track_stability = false;
    let (plain_best, _, _) = time_path(&plain, &parameters, repeats)?;
    println!(
        "without stability: best {:.1} ms per path, {:.2} ms per output step",
        plain_best * 1e3,
        plain_best * 1e3 / outputs
    );
    let n = case.geometry.helices;
    if !case.discretisation.symmetric && n >= 4 && n % 2 == 0 {
        bench_pair(&case, &parameters, repeats, [best, plain_best], &o)?;
    }
    Ok(())
}

/// The path of `case` (the full model) as the symmetric pair, with and without stability,
/// timed against the full model's best times `full` (s; with and without stability), its
/// tip forces compared with the full model's `outcome`.
fn bench_pair(
    case: &Case,
    parameters: &[f64],
    repeats: usize,
    full: [f64; 2],
    outcome: &PathOutcome,
) -> Result<()> {
    for (track, reference) in [(true, full[0]), (false, full[1])] {
        let mut pair = case.clone();
        pair.discretisation.symmetric = true;
        pair.solver.track_stability = track;
        let (pb, _, po) = time_path(&pair, parameters, repeats)?;
        let (a, b) = (
            outcome.points.last().expect("points"),
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
            pb * 1e3 / parameters.len() as f64,
            reference / pb,
            diff
        );
    }
    Ok(())
}

/// Best and mean wall time (s) of `repeats` runs of a path to the load parameters
/// `parameters` after a warm-up, and the last outcome.
fn time_path(case: &Case, parameters: &[f64], repeats: usize) -> Result<(f64, f64, PathOutcome)> {
    let mut best = f64::INFINITY;
    let mut times = Vec::new();
    let mut last = None;
    for r in 0..=repeats.max(1) {
        let t = Instant::now();
        let outcome = run_path(case, parameters, |_, _| {})?;
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
