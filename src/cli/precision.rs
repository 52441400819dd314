//! `spira precision`: the work-precision study of a case's path on a ladder of meshes.

use super::signals::stop_on_signal;
use super::{check_size, command_line};
use anyhow::{anyhow, Context, Result};
use spira::case::{Case, Setting};
use spira::output::csv::with_note;
use spira::output::precision::StudyReport as _;
use spira::study::{run_study_with, Ladder, StudyError, Subject};
use std::path::Path;
use std::time::Instant;

/// `spira precision`: the study of the case at `path` with the overrides `set`, each mesh timed by the best of
/// `repeats` runs after a warm-up, its table printed and precision.csv and precision.svg
/// written into `out`.
pub fn precision(
    path: &Path,
    set: &[Setting],
    out: &Path,
    repeats: usize,
    force: bool,
) -> Result<()> {
    // a signal stops the study after the Newton iteration under way; nothing is written
    let interrupt = stop_on_signal("spira precision: interrupted; stopping");
    let case = Case::from_file_with(path, set)?;
    check_size(&case, force)?;
    let set_line = (!set.is_empty()).then(|| super::run::set_note(set));
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
    let study = run_study_with(&problem, &ladder, repeats, Some(&interrupt), |p| {
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
    })
    .map_err(|e| match e {
        StudyError::Interrupted { .. } => anyhow!(
            "{e}, in {:.1} s; nothing was written",
            t0.elapsed().as_secs_f64()
        ),
        e => e.into(),
    })?;
    if let Some(line) = &set_line {
        println!("{line}");
    }
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
        (
            "precision.csv".to_string(),
            match &set_line {
                Some(line) => with_note(&study.csv(), line),
                None => study.csv(),
            },
        ),
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
