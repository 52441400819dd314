//! The answer to each load other than the axial one, as its designers read it, in the style
//! of the load curves (one curve per run, dashed where unstable, critical points marked):
//! a stent's radial force against its diameter, the torque against the twist, the bending
//! moment against the tube's curvature. A figure is drawn for a load only when some run
//! moves it.

use super::load::{legend_entries, load_panel, stretches, Stretch};
use super::style::{range, Caption};
use crate::output::chart::{captioned, draw_svg, DrawError, CAPTION_LINE};
use crate::output::legend;
use crate::output::read::{CriticalMark, PathPoint, RunTables, SupportColumns};

/// One figure: its file name, title, axes, and the pair it plots from a row of `load.csv`.
struct Pair {
    file: &'static str,
    title: &'static str,
    x_label: &'static str,
    y_label: &'static str,
    /// `(displacement, force)` of a row.
    of: fn(&SupportColumns) -> (f64, f64),
}

const PAIRS: [Pair; 3] = [
    Pair {
        file: "radial-force-diameter.svg",
        title: "radial force against diameter",
        x_label: "mean diameter 2 × radius (m)",
        y_label: "radial force 2π radius h × lateral pressure (N)",
        of: |s| {
            let area = 2.0 * std::f64::consts::PI * s.radius * s.height;
            (2.0 * s.radius, s.lateral_pressure * area)
        },
    },
    Pair {
        file: "torque-twist.svg",
        title: "torque against twist",
        x_label: "twist φ of the tip support (rad)",
        y_label: "torque about the axis T (N m)",
        of: |s| (s.twist, s.torque),
    },
    Pair {
        file: "moment-curvature.svg",
        title: "bending moment against curvature",
        x_label: "curvature of the tube θ/h (1/m)",
        y_label: "bending moment M (N m)",
        of: |s| (s.tilt / s.height, s.bending_moment),
    },
];

/// Whether a run moves the pair's displacement (it varies along the path).
fn moves(run: &RunTables, pair: &Pair) -> bool {
    let xs: Vec<f64> = run
        .path
        .iter()
        .filter_map(|p| p.support.as_ref().map(|s| (pair.of)(s).0))
        .collect();
    let (lo, hi) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
            (l.min(x), h.max(x))
        });
    // the pressure's diameter moves with every axial load too: only a run that presses
    let pressed = pair.file.starts_with("radial")
        && run
            .path
            .iter()
            .any(|p| p.support.is_some_and(|s| s.pressure != 0.0));
    xs.len() == run.path.len() && hi > lo && (pressed || !pair.file.starts_with("radial"))
}

/// The run as the pair's curve: every point at `(displacement, [force, 0, 0])`, the critical
/// points where the path passes their load parameter (linearly between output steps).
fn as_pair(run: &RunTables, pair: &Pair) -> RunTables {
    let at = |p: &PathPoint| p.support.map_or((0.0, 0.0), |s| (pair.of)(&s));
    let path: Vec<PathPoint> = run
        .path
        .iter()
        .map(|p| {
            let (x, y) = at(p);
            PathPoint {
                eps: x,
                load: [y, 0.0, 0.0],
                ..p.clone()
            }
        })
        .collect();
    let critical = run
        .critical
        .iter()
        .filter_map(|c| {
            run.path.windows(2).find_map(|w| {
                let (a, b) = (w[0].parameter, w[1].parameter);
                let inside = a.min(b) <= c.parameter && c.parameter <= a.max(b) && a != b;
                inside.then(|| {
                    let t = (c.parameter - a) / (b - a);
                    let ((x0, y0), (x1, y1)) = (at(&w[0]), at(&w[1]));
                    CriticalMark {
                        eps: x0 + t * (x1 - x0),
                        load: [y0 + t * (y1 - y0), 0.0, 0.0],
                        ..c.clone()
                    }
                })
            })
        })
        .collect();
    RunTables {
        label: run.label.clone(),
        case: run.case.clone(),
        path,
        critical,
        states: Vec::new(),
        joints: Default::default(),
        infinite_tube: run.infinite_tube,
    }
}

/// The figures of the loads that some of `runs` move, as (file name, SVG).
pub fn pair_figures(
    runs: &[&RunTables],
    caption: &Caption,
) -> Result<Vec<(String, String)>, DrawError> {
    let mut files = Vec::new();
    for pair in &PAIRS {
        let moved: Vec<RunTables> = runs
            .iter()
            .filter(|r| moves(r, pair))
            .map(|r| as_pair(r, pair))
            .collect();
        if moved.is_empty() {
            continue;
        }
        let all: Vec<&RunTables> = moved.iter().collect();
        let entries = legend_entries(&all);
        let w = 720u32;
        let h = 480 + CAPTION_LINE * caption.len() as u32 + legend::height(&entries, w);
        let svg = draw_svg(pair.title, (w, h), |root| {
            let body = captioned(root, pair.title, caption)?;
            let body = legend::above(&body, &entries)?;
            let curves: Vec<Vec<Stretch>> = all
                .iter()
                .map(|r| stretches(&r.path, &r.critical))
                .collect();
            let points = || all.iter().flat_map(|r| r.path.iter());
            let x = range(points().map(|p| p.eps), 0.05);
            let y = range(points().map(|p| p.load[0]).chain([0.0]), 0.2);
            let labels = (pair.x_label, pair.y_label.to_string());
            load_panel(&body, &all, &curves, 0, x, y, labels)
        })?;
        files.push((pair.file.to_string(), svg));
    }
    Ok(files)
}
