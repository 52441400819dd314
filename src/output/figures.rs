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

use super::chart::{captioned, draw_svg, palette, DrawError, FONT};
use super::read::{CriticalMark, PathPoint, RunTables, StateNode, StateTable};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Dashes of unstable stretches: dash and gap lengths (px).
const DASH: (u32, u32) = (7, 5);
/// Colour of joints and other marks that are not a curve.
const MARK: RGBColor = RGBColor(0x40, 0x40, 0x40);
const GRID_BOLD: RGBColor = RGBColor(0xdd, 0xdd, 0xdd);
/// Minor grid lines are left out (transparent: plotters writes nothing for them), which
/// keeps the files small.
const GRID_LIGHT: RGBAColor = RGBAColor(0xff, 0xff, 0xff, 0.0);

/// The lines under a figure's title: the case and the command that drew it, e.g.
/// `["case thesis-n8", "command: spira plot out/n8"]`.
pub type Caption = [String];

/// An interval of `s/L` shaded on a curvature profile, with its legend text (e.g. the
/// bulk of a rod: `bulk`).
#[derive(Clone, Debug, PartialEq)]
pub struct Shade {
    /// Start and end, `s/L`.
    pub from: f64,
    pub to: f64,
    pub label: String,
}

/// The rods a curvature profile shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rods {
    /// The rod of this index (as in the CSV files, from 0).
    One(usize),
    /// Every rod, overlaid.
    All,
}

/// `[lo, hi]` of the finite values, padded by 5 % and at least `min_span` wide.
fn range(values: impl Iterator<Item = f64>, min_span: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (-0.5 * min_span, 0.5 * min_span);
    }
    let pad = 0.05 * (hi - lo);
    let (mut lo, mut hi) = (lo - pad, hi + pad);
    if hi - lo < min_span {
        let mid = 0.5 * (lo + hi);
        lo = mid - 0.5 * min_span;
        hi = mid + 0.5 * min_span;
    }
    (lo, hi)
}

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
    let (w, h) = (
        1260u32,
        440 + super::chart::CAPTION_LINE * caption.len() as u32,
    );
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
            load_panel(area, runs, &curves, k, (eps.0.min(0.0), eps.1), y)?;
        }
        Ok(())
    })
}

fn load_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    runs: &[&RunTables],
    curves: &[Vec<Stretch>],
    k: usize,
    x: (f64, f64),
    y: (f64, f64),
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
        .x_desc(EPS_LABEL)
        .y_desc(load_label(k))
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()
        .map_err(e)?;
    for (i, (run, stretches)) in runs.iter().zip(curves).enumerate() {
        let color = palette(i);
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
    }
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

/// The node of `nodes` at `s/L` (the nearest; joints fall on mesh nodes).
fn node_at(nodes: &[StateNode], s: f64) -> Option<&StateNode> {
    nodes
        .iter()
        .min_by(|a, b| (a.s_over_l - s).abs().total_cmp(&(b.s_over_l - s).abs()))
}

const CURVATURE_NAMES: [&str; 3] = ["κ1 = d2′·d3 (1/m)", "κ2 = d3′·d1 (1/m)", "Ω = d1′·d2 (1/m)"];

/// The curvature profiles of `rods` in `state` of `run`: κ1, κ2 and Ω against `s/L`, one
/// panel each, stacked; joints as dots on the curves; `shaded` intervals of `s/L` filled
/// behind the curves (legend: their label).
pub fn curvature_figure(
    run: &RunTables,
    state: &StateTable,
    rods: Rods,
    shaded: &[Shade],
    caption: &Caption,
) -> Result<String, DrawError> {
    let chosen: Vec<&(usize, Vec<StateNode>)> = match rods {
        Rods::All => state.rods.iter().collect(),
        Rods::One(k) => state.rods.iter().filter(|(id, _)| *id == k).collect(),
    };
    if chosen.is_empty() {
        return Err(DrawError {
            figure: "curvature profiles".to_string(),
            reason: match rods {
                Rods::One(k) => format!(
                    "the state has no rod {k} (rods 0 to {})",
                    state.rods.len().saturating_sub(1)
                ),
                Rods::All => "the state has no rods".to_string(),
            },
        });
    }
    let which = match rods {
        Rods::One(k) => format!("rod {k}"),
        Rods::All => format!("all {} rods", chosen.len()),
    };
    let title = format!(
        "curvature profiles, {which}, step {} (ε = {:.4})",
        state.step, state.eps
    );
    let (w, h) = (
        820u32,
        3 * 250 + super::chart::CAPTION_LINE * caption.len() as u32,
    );
    draw_svg("curvature profiles", (w, h), |root| {
        let body = captioned(root, &title, caption)?;
        let panels = body.split_evenly((3, 1));
        for (k, area) in panels.iter().enumerate() {
            curvature_panel(area, run, &chosen, k, shaded)?;
        }
        Ok(())
    })
}

fn curvature_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    run: &RunTables,
    rods: &[&(usize, Vec<StateNode>)],
    k: usize,
    shaded: &[Shade],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let values = rods
        .iter()
        .flat_map(|(_, n)| n.iter().map(|p| p.curvature[k]));
    let y = range(values, 0.5);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..1.0, y.0..y.1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("arc length s/L (–)")
        .y_desc(CURVATURE_NAMES[k])
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()
        .map_err(e)?;
    for (i, s) in shaded.iter().enumerate() {
        let fill = RGBColor(0xff, 0xd7, 0x00).mix(0.25).filled();
        let a = chart
            .draw_series(std::iter::once(Rectangle::new(
                [(s.from, y.0), (s.to, y.1)],
                fill,
            )))
            .map_err(e)?;
        if i == 0 {
            a.label(s.label.clone())
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 22, y + 5)], fill));
        }
    }
    let single = rods.len() == 1;
    for (i, (id, nodes)) in rods.iter().enumerate() {
        let color = if single { palette(0) } else { palette(i) };
        let line = color.stroke_width(2);
        let a = chart
            .draw_series(LineSeries::new(
                nodes.iter().map(|p| (p.s_over_l, p.curvature[k])),
                line,
            ))
            .map_err(e)?;
        if !single {
            a.label(format!("rod {id}"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], line));
        }
        let joints = run.joints.get(id).map(Vec::as_slice).unwrap_or(&[]);
        chart
            .draw_series(
                joints
                    .iter()
                    .filter_map(|&s| node_at(nodes, s))
                    .map(|p| Circle::new((p.s_over_l, p.curvature[k]), 3, MARK.filled())),
            )
            .map_err(e)?;
    }
    if rods
        .iter()
        .any(|(id, _)| run.joints.get(id).is_some_and(|j| !j.is_empty()))
    {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label("joints")
            .legend(move |(x, y)| Circle::new((x + 11, y), 3, MARK.filled()));
    }
    if !single || !shaded.is_empty() || rods.iter().any(|(id, _)| run.joints.contains_key(id)) {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(0x99, 0x99, 0x99))
            .label_font((FONT, 11))
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

/// Number of colours of κ1 in the views (equal bins over the state's range).
pub const K1_LEVELS: usize = 16;

/// A colour of the viridis map at `t` in [0, 1].
fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 5] = [
        (0x44, 0x01, 0x54),
        (0x3b, 0x52, 0x8b),
        (0x21, 0x91, 0x8c),
        (0x5e, 0xc9, 0x62),
        (0xfd, 0xe7, 0x25),
    ];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + f * (b as f64 - a as f64)).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The κ1 bins of a state: `[lo, hi]` (1/m) of its values, widened to at least 2 % of their
/// size so that a uniform state is one colour.
fn k1_range(state: &StateTable) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for n in state.rods.iter().flat_map(|(_, n)| n) {
        lo = lo.min(n.curvature[0]);
        hi = hi.max(n.curvature[0]);
    }
    if lo > hi {
        return (-1.0, 1.0);
    }
    let span = (0.02 * lo.abs().max(hi.abs())).max(1e-9);
    if hi - lo < span {
        let mid = 0.5 * (lo + hi);
        return (mid - 0.5 * span, mid + 0.5 * span);
    }
    (lo, hi)
}

fn k1_level(k1: f64, (lo, hi): (f64, f64)) -> usize {
    (((k1 - lo) / (hi - lo) * K1_LEVELS as f64).floor().max(0.0) as usize).min(K1_LEVELS - 1)
}

fn level_color(level: usize) -> RGBColor {
    viridis((level as f64 + 0.5) / K1_LEVELS as f64)
}

/// The three projections, named (horizontal axis)-(vertical axis), as in the explorer.
const VIEWS: [(&str, usize, usize); 3] = [("X-Y", 0, 1), ("Z-Y", 2, 1), ("Z-X", 2, 0)];
const AXIS_NAMES: [&str; 3] = ["x (m)", "y (m)", "z (m)"];

/// The assembly of `state` seen along the three axes at one scale: X-Y on the left, Z-Y
/// and Z-X stacked on the right, rods coloured by κ1 in [`K1_LEVELS`] bins, a colour bar.
pub fn views_figure(state: &StateTable, caption: &Caption) -> Result<String, DrawError> {
    // extents of the coordinates, and one scale (px per m) for all views
    let mut ext = [(0.0f64, 0.0f64); 3];
    for (c, e) in ext.iter_mut().enumerate() {
        *e = range(
            state
                .rods
                .iter()
                .flat_map(|(_, n)| n.iter().map(move |p| p.position[c]))
                .chain(std::iter::once(0.0)),
            0.0,
        );
    }
    let largest = ext.iter().map(|e| e.1 - e.0).fold(0.0, f64::max).max(1e-9);
    for e in &mut ext {
        if e.1 - e.0 < 0.05 * largest {
            let mid = 0.5 * (e.0 + e.1);
            *e = (mid - 0.025 * largest, mid + 0.025 * largest);
        }
    }
    let span = |c: usize| ext[c].1 - ext[c].0;
    // label areas and margins of a view (px)
    const LEFT: u32 = 62;
    const BOTTOM: u32 = 40;
    const TOP: u32 = 26;
    const M: u32 = 8;
    let (max_w, max_h) = (900.0, 620.0);
    let fixed_w = 2.0 * (LEFT + 2 * M) as f64;
    let fixed_h = 2.0 * (BOTTOM + TOP + 2 * M) as f64;
    let side_v = span(1).max(span(0));
    let scale = ((max_w - fixed_w) / (span(0) + span(2))).min((max_h - fixed_h) / (2.0 * side_v));
    let px = |m: f64| (m * scale).round().max(20.0) as u32;
    let left_w = px(span(0)) + LEFT + 2 * M;
    let right_w = px(span(2)) + LEFT + 2 * M;
    let row_h = px(side_v) + BOTTOM + TOP + 2 * M;
    let cap_h = super::chart::CAPTION_LINE * (1 + caption.len() as u32) + 8;
    let (w, h) = (left_w + right_w, cap_h + 2 * row_h);
    let k1 = k1_range(state);
    let title = format!(
        "three views, step {} (ε = {:.4}), rods coloured by κ1",
        state.step, state.eps
    );
    draw_svg("three views", (w, h), |root| {
        let body = captioned(root, &title, caption)?;
        let (left, right) = body.split_horizontally(left_w);
        let (top_right, bottom_right) = right.split_vertically(row_h);
        let (top_left, bar) = left.split_vertically(row_h);
        for (area, view) in [(&top_left, 0), (&top_right, 1), (&bottom_right, 2)] {
            let (name, hc, vc) = VIEWS[view];
            // the view's ranges, widened to the area at the common scale
            let (pw, ph) = if view == 0 {
                (px(span(0)), px(side_v))
            } else {
                (px(span(2)), px(side_v))
            };
            let widen = |(lo, hi): (f64, f64), pixels: u32| {
                let half = 0.5 * pixels as f64 / scale;
                let mid = 0.5 * (lo + hi);
                (mid - half, mid + half)
            };
            let x = widen(ext[hc], pw);
            let y = widen(ext[vc], ph);
            view_panel(area, state, name, (hc, vc), x, y, k1, (LEFT, BOTTOM, M))?;
        }
        colour_bar(&bar, k1, (LEFT + M, M))
    })
}

#[allow(clippy::too_many_arguments)]
fn view_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    state: &StateTable,
    name: &str,
    (hc, vc): (usize, usize),
    x: (f64, f64),
    y: (f64, f64),
    k1: (f64, f64),
    (left, bottom, margin): (u32, u32, u32),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let mut chart = ChartBuilder::on(area)
        .margin(margin)
        .caption(name, (FONT, 13).into_font().style(FontStyle::Bold))
        .x_label_area_size(bottom)
        .y_label_area_size(left)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(AXIS_NAMES[hc])
        .y_desc(AXIS_NAMES[vc])
        .x_labels(6)
        .y_labels(5)
        .axis_desc_style((FONT, 12))
        .label_style((FONT, 10))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()
        .map_err(e)?;
    for (_, nodes) in &state.rods {
        // one polyline per run of segments in the same κ1 bin
        let mut start = 0;
        while start + 1 < nodes.len() {
            let level = |i: usize| {
                k1_level(
                    0.5 * (nodes[i].curvature[0] + nodes[i + 1].curvature[0]),
                    k1,
                )
            };
            let l = level(start);
            let mut end = start + 1;
            while end + 1 < nodes.len() && level(end) == l {
                end += 1;
            }
            let pts: Vec<(f64, f64)> = nodes[start..=end]
                .iter()
                .map(|p| (p.position[hc], p.position[vc]))
                .collect();
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts,
                    level_color(l).stroke_width(2),
                )))
                .map_err(e)?;
            start = end;
        }
    }
    Ok(())
}

/// A horizontal colour bar of the κ1 bins, under the X-Y view; `(left, right)` margins
/// (px) that align it with the view's plot area.
fn colour_bar(
    area: &DrawingArea<SVGBackend, Shift>,
    k1: (f64, f64),
    (left, right): (u32, u32),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let (_, h) = area.dim_in_pixel();
    const BAR_H: u32 = 26;
    const LABELS: u32 = 40;
    let top = 36u32.min(h.saturating_sub(BAR_H + LABELS));
    let mut chart = ChartBuilder::on(area)
        .margin_top(top)
        .margin_bottom(h.saturating_sub(top + BAR_H + LABELS))
        .margin_left(left)
        .margin_right(right)
        .x_label_area_size(LABELS)
        .build_cartesian_2d(k1.0..k1.1, 0.0..1.0)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_y_axis()
        .disable_x_mesh()
        .disable_y_mesh()
        .x_desc("κ1 (1/m)")
        .x_labels(5)
        .axis_desc_style((FONT, 12))
        .label_style((FONT, 10))
        .draw()
        .map_err(e)?;
    let step = (k1.1 - k1.0) / K1_LEVELS as f64;
    chart
        .draw_series((0..K1_LEVELS).map(|l| {
            let lo = k1.0 + step * l as f64;
            Rectangle::new([(lo, 0.0), (lo + step, 1.0)], level_color(l).filled())
        }))
        .map_err(e)?;
    Ok(())
}

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
