//! The figures of runs, as SVG text, from the tables a run writes ([`super::read`]):
//!
//! - [`load_figure`]: the averaged normalised tip loads `Σ F/(n Pcrit)` (x, y, z) against
//!   `ε`, one curve per run, solid where the state is stable and dashed where it is not
//!   (the convention of continuation tools), critical points marked (thesis Figs. 4.17–4.19);
//! - [`curvature_figure`]: `κ1`, `κ2`, `Ω` against `s/L` of one rod or all, joints marked,
//!   with optional shaded intervals of `s/L` (e.g. a measured bulk);
//! - [`views_figure`]: the assembly seen along the three axes (X-Y, Z-Y, Z-X) at one
//!   scale, rods coloured by `κ1`, with a colour bar.
//!
//! Every number drawn is read from the tables: nothing here computes mechanics.
//!
//! One file per figure (`load`, `curvature`, `views`) and the look they share
//! (`style`); [`run_figures`] draws the set a run folder asks for.

mod curvature;
mod load;
mod pairs;
mod style;
mod views;

pub use curvature::{curvature_figure, Rods, Shade};
pub use load::{load_figure, stretches, Stretch, Vertex};
pub use pairs::pair_figures;
pub use style::Caption;
pub use views::{views_figure, K1_LEVELS};

use super::chart::DrawError;
use super::read::{RunTables, StateTable};

/// The states a set of figures shows.
#[derive(Clone, Debug, PartialEq)]
pub enum Steps {
    /// The last state of each run.
    Last,
    /// Every state a run folder has.
    All,
    /// For each compression ratio, the state nearest to it.
    Near(Vec<f64>),
}

/// Which kinds of figure to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Kinds {
    pub load: bool,
    pub curvature: bool,
    pub views: bool,
}

impl Kinds {
    pub const ALL: Kinds = Kinds {
        load: true,
        curvature: true,
        views: true,
    };
}

/// The figures of `runs` as (file name, SVG), of the `kinds` asked: `load.svg` with every
/// run's load curves, and for each run and chosen state `curvature-step<k>.svg` and
/// `views-step<k>.svg`, the names prefixed by `<run label>-` when there are several runs.
/// `command` (the command line that drew them) is in every caption.
pub fn run_figures(
    runs: &[RunTables],
    steps: &Steps,
    rods: Rods,
    kinds: Kinds,
    command: &str,
) -> Result<Vec<(String, String)>, DrawError> {
    let cases: Vec<&str> = runs
        .iter()
        .map(|r| {
            if r.case.is_empty() {
                r.label.as_str()
            } else {
                r.case.as_str()
            }
        })
        .collect();
    let command_line = format!("command: {command}");
    let load_caption = [
        format!(
            "{} {}",
            if cases.len() == 1 { "case" } else { "cases" },
            cases.join(", ")
        ),
        command_line.clone(),
    ];
    let all: Vec<&RunTables> = runs.iter().collect();
    let mut files = Vec::new();
    if kinds.load {
        files.push(("load.svg".to_string(), load_figure(&all, &load_caption)?));
        files.extend(pair_figures(&all, &load_caption)?);
    }
    for (run, case) in runs.iter().zip(&cases) {
        let prefix = if runs.len() > 1 {
            format!("{}-", run.label)
        } else {
            String::new()
        };
        let mut chosen: Vec<&StateTable> = match steps {
            Steps::Last => run.states.last().into_iter().collect(),
            Steps::All => run.states.iter().collect(),
            Steps::Near(eps) => eps.iter().filter_map(|&e| run.state_near(e)).collect(),
        };
        chosen.sort_by_key(|s| s.step);
        chosen.dedup_by_key(|s| s.step);
        for state in chosen {
            let caption = [format!("case {case} ({})", run.label), command_line.clone()];
            if kinds.curvature {
                files.push((
                    format!("{prefix}curvature-step{}.svg", state.step),
                    curvature_figure(run, state, rods, &[], &caption)?,
                ));
            }
            if kinds.views {
                files.push((
                    format!("{prefix}views-step{}.svg", state.step),
                    views_figure(state, &caption)?,
                ));
            }
        }
    }
    Ok(files)
}
