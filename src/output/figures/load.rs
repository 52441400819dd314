//! The load curves: the averaged normalised tip loads `Σ F/(n Pcrit)` (x, y, z) against `ε`,
//! one curve per run, solid where the state is stable and dashed where it is not (the
//! convention of continuation tools), critical points marked (thesis Figs. 4.17–4.19).

use super::style::{range, Caption, DASH, GRID_BOLD, GRID_LIGHT, MARK};
use crate::output::chart::{captioned, draw_svg, palette, DrawError, CAPTION_LINE, FONT};
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

/// Legend text of a run: its label, the case when another, and the number of rods.
fn run_legend(run: &RunTables) -> String {
    let n = run.rods();
    let mut s = run.label.clone();
    if !run.case.is_empty() && run.case != run.label {
        s = format!("{s} ({})", run.case);
    }
    if n > 0 {
        s = format!("{s}, n = {n}");
    }
    s
}

/// The axis label of load component `k`.
fn load_label(k: usize) -> String {
    format!("Σ F{} / (n Pcrit) (–)", ["x", "y", "z"][k])
}

const EPS_LABEL: &str = "compression ratio ε = (h0 − h)/h0 (–)";

/// The load curves of `runs`: three panels side by side, `Σ Fx`, `Σ Fy`, `Σ Fz` over
/// `n Pcrit` against `ε`, one colour per run, dashed where unstable, critical points as
/// rings (bifurcations) and squares (limit points).
pub fn load_figure(runs: &[&RunTables], caption: &Caption) -> Result<String, DrawError> {
    let (w, h) = (1260u32, 440 + CAPTION_LINE * caption.len() as u32);
    draw_svg("load curves", (w, h), |root| {
        let body = captioned(
            root,
            "averaged normalised tip loads against compression",
            caption,
        )?;
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

/// A panel's chart: `ε` across, a normalised load up.
type LoadChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The panel of load component `k` (x, y, z): every run's curve and critical points, and
/// the legend; `x` and `y` the ranges of `ε` and of the load, `labels` the axes'.
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
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()
        .map_err(e)?;
    for (i, (run, stretches)) in runs.iter().zip(curves).enumerate() {
        run_curve(&mut chart, run, stretches, palette(i), k)?;
    }
    legend_of_marks(&mut chart, runs)?;
    chart
        .configure_series_labels()
        .position(if k == 2 {
            SeriesLabelPosition::LowerLeft
        } else {
            SeriesLabelPosition::UpperLeft
        })
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(0x99, 0x99, 0x99))
        .label_font((FONT, 11))
        .draw()
        .map_err(e)?;
    Ok(())
}

/// The curve of load component `k` of one run in `color`, dashed where unstable, with its
/// legend entry, and its critical points: rings (bifurcations) and squares (limit points).
fn run_curve<'a, 'b: 'a>(
    chart: &mut LoadChart<'a, 'b>,
    run: &RunTables,
    stretches: &[Stretch],
    color: RGBColor,
    k: usize,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let line = color.stroke_width(2);
    let mut labelled = false;
    for s in stretches {
        let pts = s.vertices.iter().map(|(eps, f)| (*eps, f[k]));
        let annotation = if s.unstable {
            chart
                .draw_series(DashedLineSeries::new(pts, DASH.0, DASH.1, line))
                .map_err(e)?
        } else {
            chart.draw_series(LineSeries::new(pts, line)).map_err(e)?
        };
        if !labelled {
            labelled = true;
            annotation
                .label(run_legend(run))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], line));
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

/// Legend entries of the marks any of `runs` has: bifurcations, limit points, unstable
/// (dashed) stretches.
fn legend_of_marks<'a, 'b: 'a>(
    chart: &mut LoadChart<'a, 'b>,
    runs: &[&RunTables],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let any = |kind: &str| {
        runs.iter()
            .any(|r| r.critical.iter().any(|c| c.kind == kind))
    };
    let mark = MARK.stroke_width(2);
    if any("bifurcation") {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label("bifurcation")
            .legend(move |(x, y)| Circle::new((x + 11, y), 5, mark));
    }
    if any("limit-point") {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label("limit point")
            .legend(move |(x, y)| Rectangle::new([(x + 6, y - 5), (x + 16, y + 5)], mark));
    }
    if runs
        .iter()
        .any(|r| r.path.iter().any(|p| p.stable == Some(false)))
    {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label("unstable (dashed)")
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (8, 0)], mark)
                    + PathElement::new(vec![(14, 0), (22, 0)], mark)
            });
    }
    Ok(())
}
