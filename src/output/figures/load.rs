//! The load curves: the averaged normalised tip loads `Σ F/(n Pcrit)` (x, y, z) against `ε`,
//! one curve per run, solid where the state is stable and dashed where it is not (the
//! convention of continuation tools), critical points marked (thesis Figs. 4.17–4.19).

use super::style::{range, Caption, DASH, GRID_BOLD, GRID_LIGHT, MARK};
use crate::output::chart::{
    captioned, draw_svg, palette, tick_label, DrawError, CAPTION_LINE, FONT,
};
use crate::output::legend::{self, Entry, Sample};
use crate::output::read::{CriticalMark, PathPoint, RunTables};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A vertex of a load curve: `ε` and the three normalised loads.
pub type Vertex = (f64, [f64; 3]);

/// A stretch of a load curve drawn in one style.
#[derive(Clone, Debug, PartialEq)]
pub struct Stretch {
    pub unstable: bool,
    pub vertices: Vec<Vertex>,
}

/// The load path as stretches of one stability each. A critical point located between two
/// output steps becomes a vertex where the stretch before it ends and the one after it
/// begins; elsewhere a segment is unstable when either end is (where stability was not
/// judged, a point counts as stable).
pub fn stretches(path: &[PathPoint], critical: &[CriticalMark]) -> Vec<Stretch> {
    let unstable = |p: &PathPoint| p.stable == Some(false);
    // segments: from, to, unstable
    let mut segments: Vec<(Vertex, Vertex, bool)> = Vec::new();
    let mut used = vec![false; critical.len()];
    for w in path.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let (lo, hi) = if a.parameter <= b.parameter {
            (a.parameter, b.parameter)
        } else {
            (b.parameter, a.parameter)
        };
        let split = (unstable(a) != unstable(b))
            .then(|| {
                critical
                    .iter()
                    .enumerate()
                    .find(|(i, c)| !used[*i] && c.parameter >= lo && c.parameter <= hi)
            })
            .flatten();
        match split {
            Some((i, c)) => {
                used[i] = true;
                segments.push(((a.eps, a.load), (c.eps, c.load), unstable(a)));
                segments.push(((c.eps, c.load), (b.eps, b.load), unstable(b)));
            }
            None => segments.push(((a.eps, a.load), (b.eps, b.load), unstable(a) || unstable(b))),
        }
    }
    let mut out: Vec<Stretch> = Vec::new();
    for (from, to, u) in segments {
        match out.last_mut() {
            Some(s) if s.unstable == u => s.vertices.push(to),
            _ => out.push(Stretch {
                unstable: u,
                vertices: vec![from, to],
            }),
        }
    }
    if out.is_empty() {
        if let Some(p) = path.first() {
            out.push(Stretch {
                unstable: unstable(p),
                vertices: vec![(p.eps, p.load)],
            });
        }
    }
    out
}

/// Legend text of a run: its label, the case when another, and the number of rods (of the
/// infinitely long tube, for a cell).
fn run_legend(run: &RunTables) -> String {
    let mut s = run.label.clone();
    if !run.case.is_empty() && run.case != run.label {
        s = format!("{s} ({})", run.case);
    }
    match (run.infinite_tube, run.rods()) {
        (Some(n), _) => s = format!("{s}, infinite tube, n = {n}"),
        (None, n) if n > 0 => s = format!("{s}, n = {n}"),
        _ => {}
    }
    s
}

/// The axis label of load component `k`.
fn load_label(k: usize) -> String {
    format!("Σ F{} / (n Pcrit) (–)", ["x", "y", "z"][k])
}

const EPS_LABEL: &str = "compression ratio ε = (h0 − h)/h0 (–)";

/// Whether a run steps a dead axial load (load control, `P/Pcrit`): its load parameter
/// is not its compression ratio and balances the axial tip load, `fz/(n Pcrit) = −P/Pcrit`,
/// at every point.
pub fn load_controlled(run: &RunTables) -> bool {
    let moves = run.path.iter().any(|p| (p.parameter - p.eps).abs() > 1e-12);
    let balanced = run
        .path
        .iter()
        .all(|p| (p.parameter + p.load[2]).abs() <= 1e-6 * p.parameter.abs().max(1.0));
    moves && balanced && !run.path.is_empty()
}

/// A load-controlled run as its curve of the end-shortening against the load: every point
/// at `(P/Pcrit, [ε, 0, 0])`, the critical points likewise.
fn against_load(run: &RunTables) -> RunTables {
    RunTables {
        path: run
            .path
            .iter()
            .map(|p| PathPoint {
                eps: p.parameter,
                load: [p.eps, 0.0, 0.0],
                ..p.clone()
            })
            .collect(),
        critical: run
            .critical
            .iter()
            .map(|c| CriticalMark {
                eps: c.parameter,
                load: [c.eps, 0.0, 0.0],
                ..c.clone()
            })
            .collect(),
        label: run.label.clone(),
        case: run.case.clone(),
        states: Vec::new(),
        joints: Default::default(),
        infinite_tube: run.infinite_tube,
    }
}

/// The legend of load curves: one entry per run, and the marks any of them has
/// (bifurcations, limit points, unstable stretches).
pub(super) fn legend_entries(runs: &[&RunTables]) -> Vec<Entry> {
    let mut entries: Vec<Entry> = runs
        .iter()
        .enumerate()
        .map(|(i, r)| Entry::new(run_legend(r), Sample::Line(palette(i).stroke_width(2))))
        .collect();
    let any = |kind: &str| {
        runs.iter()
            .any(|r| r.critical.iter().any(|c| c.kind == kind))
    };
    let mark = MARK.stroke_width(2);
    if any("bifurcation") {
        entries.push(Entry::new("bifurcation", Sample::Circle(mark, 5)));
    }
    if any("limit-point") {
        entries.push(Entry::new("limit point", Sample::Square(mark, 5)));
    }
    if runs
        .iter()
        .any(|r| r.path.iter().any(|p| p.stable == Some(false)))
    {
        entries.push(Entry::new("unstable (dashed)", Sample::Dashed(mark)));
    }
    entries
}

/// The load curves of `runs`: three panels side by side, `Σ Fx`, `Σ Fy`, `Σ Fz` over
/// `n Pcrit` against `ε`, one colour per run, dashed where unstable, critical points as
/// rings (bifurcations) and squares (limit points), one legend above the panels. When every
/// run steps a dead axial load, one panel instead: the end-shortening `ε` against `P/Pcrit`.
pub fn load_figure(runs: &[&RunTables], caption: &Caption) -> Result<String, DrawError> {
    if runs.iter().all(|r| load_controlled(r)) {
        return load_controlled_figure(runs, caption);
    }
    let entries = legend_entries(runs);
    let w = 1260u32;
    let h = 440 + CAPTION_LINE * caption.len() as u32 + legend::height(&entries, w);
    draw_svg("load curves", (w, h), |root| {
        let body = captioned(
            root,
            "averaged normalised tip loads against compression",
            caption,
        )?;
        let body = legend::above(&body, &entries)?;
        let panels = body.split_evenly((1, 3));
        let curves: Vec<Vec<Stretch>> = runs
            .iter()
            .map(|r| stretches(&r.path, &r.critical))
            .collect();
        let eps = range(runs.iter().flat_map(|r| r.path.iter().map(|p| p.eps)), 0.05);
        for (k, area) in panels.iter().enumerate() {
            let values = runs.iter().flat_map(|r| {
                r.path
                    .iter()
                    .map(move |p| p.load[k])
                    .chain(r.critical.iter().map(move |c| c.load[k]))
            });
            let y = range(values, 0.2);
            let labels = (EPS_LABEL, load_label(k));
            load_panel(area, runs, &curves, k, (eps.0.min(0.0), eps.1), y, labels)?;
        }
        Ok(())
    })
}

/// The load curves of load-controlled `runs`: the end-shortening `ε` against the dead load
/// `P/Pcrit`, one panel.
fn load_controlled_figure(runs: &[&RunTables], caption: &Caption) -> Result<String, DrawError> {
    let moved: Vec<RunTables> = runs.iter().map(|r| against_load(r)).collect();
    let all: Vec<&RunTables> = moved.iter().collect();
    let entries = legend_entries(&all);
    let w = 760u32;
    let h = 480 + CAPTION_LINE * caption.len() as u32 + legend::height(&entries, w);
    draw_svg("load curves", (w, h), |root| {
        let body = captioned(root, "end-shortening against the axial load", caption)?;
        let body = legend::above(&body, &entries)?;
        let curves: Vec<Vec<Stretch>> = all
            .iter()
            .map(|r| stretches(&r.path, &r.critical))
            .collect();
        let points = || all.iter().flat_map(|r| r.path.iter());
        let x = range(points().map(|p| p.eps).chain([0.0]), 0.05);
        let y = range(points().map(|p| p.load[0]).chain([0.0]), 0.05);
        let labels = (P_LABEL, SHORTENING_LABEL.to_string());
        load_panel(&body, &all, &curves, 0, (x.0.max(0.0), x.1), y, labels)
    })
}

const P_LABEL: &str = "dead axial load on every tip P / Pcrit (–)";
const SHORTENING_LABEL: &str = "end-shortening ε = (h0 − h)/h0 (–)";

/// A panel's chart: `ε` across, a normalised load up.
type LoadChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The panel of load component `k` (x, y, z): every run's curve and critical points (the
/// legend is the figure's); `x` and `y` the ranges of `ε` and of the load, `labels` the axes'.
pub(super) fn load_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    runs: &[&RunTables],
    curves: &[Vec<Stretch>],
    k: usize,
    x: (f64, f64),
    y: (f64, f64),
    labels: (&str, String),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(labels.0)
        .y_desc(labels.1)
        .x_label_formatter(&|v| tick_label(*v, x.1 - x.0))
        .y_label_formatter(&|v| tick_label(*v, y.1 - y.0))
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()
        .map_err(e)?;
    for (i, (run, stretches)) in runs.iter().zip(curves).enumerate() {
        run_curve(&mut chart, run, stretches, palette(i), k)?;
    }
    Ok(())
}

/// The curve of load component `k` of one run in `color`, dashed where unstable, and its
/// critical points: rings (bifurcations) and squares (limit points).
fn run_curve<'a, 'b: 'a>(
    chart: &mut LoadChart<'a, 'b>,
    run: &RunTables,
    stretches: &[Stretch],
    color: RGBColor,
    k: usize,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let line = color.stroke_width(2);
    for s in stretches {
        let pts = s.vertices.iter().map(|(eps, f)| (*eps, f[k]));
        if s.unstable {
            chart
                .draw_series(DashedLineSeries::new(pts, DASH.0, DASH.1, line))
                .map_err(e)?;
        } else {
            chart.draw_series(LineSeries::new(pts, line)).map_err(e)?;
        }
    }
    // a neutral direction is not a point of the path where stability changes
    for c in run.critical.iter().filter(|c| c.kind != "neutral") {
        let at = (c.eps, c.load[k]);
        if c.kind == "limit-point" {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(at) + Rectangle::new([(-5, -5), (5, 5)], line),
                ))
                .map_err(e)?;
        } else {
            chart
                .draw_series(std::iter::once(Circle::new(at, 5, line)))
                .map_err(e)?;
        }
    }
    Ok(())
}
