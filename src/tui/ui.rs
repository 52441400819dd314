//! Drawing the explorer: one function per panel, each taking the [`App`] read-only. Only the
//! 16 ANSI colours are used, so the screen reads the same on any terminal and over SSH.

use super::app::{fmt_step, App, Message, PrecisionView, ViewMode, CURSOR_STEPS};
use super::keys::BINDINGS;
use super::stability;
use crate::case::Geometry;
use crate::output::precision::{self, StudyReport};
use crate::results::{LoadPoint, NodeState, RodShape, Snapshot};
use crate::study::{Measure, Study, ORDERS};
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line as Segment, Points};
use ratatui::widgets::{Axis, Block, Borders, Chart, Clear, Dataset, GraphType, Paragraph, Wrap};
use ratatui::Frame;

/// Smallest usable terminal.
pub const MIN_WIDTH: u16 = 80;
pub const MIN_HEIGHT: u16 = 24;

/// κ1 colour scale, most negative to most positive (bins of equal width over the state's
/// range).
pub const K1_PALETTE: [Color; 5] = [
    Color::Blue,
    Color::Cyan,
    Color::Green,
    Color::Yellow,
    Color::Red,
];
const SELECTED: Color = Color::White;
const JOINT: Color = Color::Gray;
/// The bar over the bulk of the rod on the curvature plot.
const BULK: Color = Color::Cyan;
const K1_LINE: Color = Color::LightYellow;
const K2_LINE: Color = Color::LightCyan;
const OMEGA_LINE: Color = Color::LightMagenta;
const FX_LINE: Color = Color::LightRed;
const FY_LINE: Color = Color::LightGreen;
const FZ_LINE: Color = Color::LightBlue;
const DIM: Color = Color::DarkGray;

/// Draws the whole screen (or the too-small message).
pub fn draw(frame: &mut Frame, app: &App) {
    let area = frame.area();
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        draw_too_small(frame, area);
        return;
    }
    let [main, status] = Layout::vertical([
        Constraint::Min(0),
        Constraint::Length(4 + message_lines(app, area.width)),
    ])
    .areas(area);
    let [views, plots] =
        Layout::vertical([Constraint::Percentage(50), Constraint::Percentage(50)]).areas(main);
    // the X-Y view square on screen: braille dots are about square, 2 x 4 per cell
    let xy_width = (views.height.saturating_sub(2) * 2 + 2).min(views.width / 3);
    let [xy, side] =
        Layout::horizontal([Constraint::Length(xy_width), Constraint::Min(0)]).areas(views);
    let [zy, zx] = Layout::vertical([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)]).areas(side);
    let [curvature, load] =
        Layout::horizontal([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)]).areas(plots);
    let scale = app
        .state
        .as_ref()
        .map(|s| K1Scale::of(&s.snapshot, app.natural_k1));
    match app.view {
        ViewMode::All => {
            // the two side views at one scale, so their shapes compare
            let per_dot = app.state.as_ref().map_or(0.0, |s| {
                [(zy, View::ZY), (zx, View::ZX)]
                    .iter()
                    .map(|&(a, v)| {
                        let inner = Block::new().borders(Borders::ALL).inner(a);
                        let (x, y) = view_extent(app, &s.snapshot, v);
                        dot_size(inner.width, inner.height, x, y)
                    })
                    .fold(0.0, f64::max)
            });
            draw_view(frame, xy, app, View::XY, scale, 0.0);
            draw_view(frame, zy, app, View::ZY, scale, per_dot);
            draw_view(frame, zx, app, View::ZX, scale, per_dot);
        }
        ViewMode::XY => draw_view(frame, views, app, View::XY, scale, 0.0),
        ViewMode::ZY => draw_view(frame, views, app, View::ZY, scale, 0.0),
        ViewMode::ZX => draw_view(frame, views, app, View::ZX, scale, 0.0),
    }
    if app.show_precision {
        draw_precision(frame, plots, app);
    } else {
        draw_curvature(frame, curvature, app);
        draw_load_path(frame, load, app);
    }
    draw_status(frame, status, app);
    if app.show_critical {
        draw_critical(frame, area, app);
    }
    if app.show_help {
        draw_help(frame, area, app);
    }
}

/// The critical points crossed so far, as a list over the screen, the chosen one
/// highlighted (a bifurcation's branch is switched onto from here).
fn draw_critical(frame: &mut Frame, area: Rect, app: &App) {
    let mut lines = vec![Line::from(Span::styled(
        "  #  kind           ε         fz/(n Pcrit)  unstable  p",
        Style::new().fg(DIM),
    ))];
    if app.critical.is_empty() {
        lines.push(Line::from(" none crossed on this path yet"));
    }
    for (i, c) in app.critical.iter().enumerate() {
        let text = format!(
            "{} {i:>2}  {:<13} {:>9.5}  {:>12.5}  {} → {}{}",
            if i == app.critical_cursor { '▸' } else { ' ' },
            c.kind.name(),
            c.eps,
            c.load[2],
            c.unstable_before,
            c.unstable_after,
            c.wavenumber.map_or(String::new(), |p| format!("     {p}"))
        );
        let style = if i == app.critical_cursor {
            Style::new().add_modifier(Modifier::REVERSED)
        } else {
            Style::new()
        };
        lines.push(Line::from(Span::styled(text, style)));
    }
    if !app.critical.is_empty() {
        lines.push(Line::from(Span::styled(
            " ↑↓ choose · ⏎/g switch onto its branch (G: other side)",
            Style::new().fg(DIM),
        )));
    }
    draw_overlay(frame, area, lines, " critical points ", " x closes ");
}

/// The message for a terminal below [`MIN_WIDTH`] x [`MIN_HEIGHT`].
pub fn draw_too_small(frame: &mut Frame, area: Rect) {
    let text = vec![
        Line::from(Span::styled(
            "terminal too small",
            Style::new().add_modifier(Modifier::BOLD),
        )),
        Line::from(format!(
            "spira needs {MIN_WIDTH}x{MIN_HEIGHT}, this one is {}x{}.",
            area.width, area.height
        )),
        Line::from("Enlarge the window, or press q to quit."),
    ];
    let top = area.height.saturating_sub(text.len() as u16) / 2;
    let rect = Rect {
        y: area.y + top,
        height: area.height - top,
        ..area
    };
    frame.render_widget(
        Paragraph::new(text)
            .alignment(Alignment::Center)
            .wrap(Wrap { trim: true }),
        rect,
    );
}

/// The three projections, named by (horizontal axis)-(vertical axis).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    XY,
    ZY,
    ZX,
}

impl View {
    fn title(self) -> &'static str {
        match self {
            View::XY => "X-Y",
            View::ZY => "Z-Y",
            View::ZX => "Z-X",
        }
    }
    /// Global coordinate indices drawn horizontally and vertically.
    fn axes(self) -> (usize, usize) {
        match self {
            View::XY => (0, 1),
            View::ZY => (2, 1),
            View::ZX => (2, 0),
        }
    }
    fn project(self, p: [f64; 3]) -> (f64, f64) {
        let (h, v) = self.axes();
        (p[h], p[v])
    }
}

/// Equal-width bins of κ1 over a state's range, one colour each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct K1Scale {
    pub lo: f64,
    pub hi: f64,
}

impl K1Scale {
    /// The range of κ1 over `snapshot`, widened to at least ±25 % around `natural` (κ1 of
    /// the natural state, when known), so that the natural state is one colour and the
    /// colours keep their meaning as the assembly deforms.
    pub fn of(snapshot: &Snapshot, natural: Option<f64>) -> K1Scale {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for node in snapshot.rods.iter().flat_map(|r| &r.nodes) {
            let k1 = node.curvature[0];
            if k1.is_finite() {
                lo = lo.min(k1);
                hi = hi.max(k1);
            }
        }
        if let Some(k) = natural.filter(|k| k.is_finite()) {
            let half = 0.25 * k.abs();
            lo = lo.min(k - half);
            hi = hi.max(k + half);
        }
        if lo > hi {
            (lo, hi) = (0.0, 0.0);
        }
        K1Scale { lo, hi }
    }

    /// True when the range is too narrow to split (e.g. the natural state).
    pub fn is_flat(&self) -> bool {
        self.hi - self.lo <= 1e-6 * self.hi.abs().max(self.lo.abs()).max(1.0)
    }

    pub fn color(&self, k1: f64) -> Color {
        let n = K1_PALETTE.len();
        if self.is_flat() || !k1.is_finite() {
            return K1_PALETTE[n / 2];
        }
        let t = ((k1 - self.lo) / (self.hi - self.lo) * n as f64).floor();
        K1_PALETTE[(t.max(0.0) as usize).min(n - 1)]
    }

    /// The legend: `κ1 (1/m) lo █████ hi`.
    pub fn legend(&self) -> Line<'static> {
        let mut spans = vec![Span::raw(format!(" κ1 (1/m) {} ", fmt_num(self.lo)))];
        if self.is_flat() {
            spans.push(Span::styled("█", Style::new().fg(self.color(self.lo))));
            spans.push(Span::raw(" "));
        } else {
            for c in K1_PALETTE {
                spans.push(Span::styled("█", Style::new().fg(c)));
            }
            spans.push(Span::raw(format!(" {} ", fmt_num(self.hi))));
        }
        Line::from(spans)
    }
}

/// A number in a few characters: 3 significant digits.
/// A short number for the readout: as [`fmt_num`], with one digit in scientific notation
/// and values below `1e-9` of `scale` shown as 0 (round-off of a symmetric state).
pub fn fmt_short(v: f64, scale: f64) -> String {
    if is_round_off(v, scale) {
        return "0".into();
    }
    let a = v.abs();
    if a.is_finite() && !(1e-3..1e4).contains(&a) {
        return format!("{v:.1e}");
    }
    fmt_num(v)
}

/// Whether `v` is below `1e-9` of `scale`: the round-off of a zero (a lateral force or a
/// curvature of a symmetric state).
fn is_round_off(v: f64, scale: f64) -> bool {
    v.abs() <= 1e-9 * scale.abs()
}

/// The largest magnitude among `v`: the scale of a vector's round-off.
fn largest(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, c| m.max(c.abs()))
}

/// A component of a load as [`fmt_num`], 0 when it is the round-off of the load's largest.
fn fmt_load(v: f64, load: &[f64; 3]) -> String {
    if is_round_off(v, largest(load)) {
        return "0".into();
    }
    fmt_num(v)
}

pub fn fmt_num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            format!("{v}")
        };
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = (2 - a.log10().floor() as i32).clamp(0, 5) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        s
    }
}

/// Position on a rod at arc length `s`, linear between its nodes.
fn position_at(nodes: &[NodeState], s: f64) -> Option<[f64; 3]> {
    let first = nodes.first()?;
    let k = nodes.partition_point(|n| n.s < s);
    if k == 0 {
        return Some(first.position);
    }
    let b = nodes.get(k).unwrap_or(&nodes[nodes.len() - 1]);
    let a = &nodes[k - 1];
    let t = if b.s > a.s {
        ((s - a.s) / (b.s - a.s)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Some(std::array::from_fn(|i| {
        a.position[i] + t * (b.position[i] - a.position[i])
    }))
}

/// Bounds `[lo, hi]` of `range` grown so that both axes have the same length per braille
/// dot in an area of `width` x `height` cells, centred on the data.
pub fn fit_aspect(width: u16, height: u16, x: [f64; 2], y: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    fit_scale(width, height, x, y, 0.0)
}

/// Length per braille dot that [`fit_aspect`] needs to show `x` by `y` in `width` x
/// `height` cells.
pub fn dot_size(width: u16, height: u16, x: [f64; 2], y: [f64; 2]) -> f64 {
    let (w, h) = (2.0 * width.max(1) as f64, 4.0 * height.max(1) as f64);
    let (dx, dy) = ((x[1] - x[0]).max(1e-9), (y[1] - y[0]).max(1e-9));
    (dx / w).max(dy / h)
}

/// As [`fit_aspect`], at a length per dot of at least `min_per_dot` (views drawn at one
/// scale share it).
pub fn fit_scale(
    width: u16,
    height: u16,
    x: [f64; 2],
    y: [f64; 2],
    min_per_dot: f64,
) -> ([f64; 2], [f64; 2]) {
    let (w, h) = (2.0 * width.max(1) as f64, 4.0 * height.max(1) as f64);
    let per_dot = dot_size(width, height, x, y).max(min_per_dot);
    let (cx, cy) = (0.5 * (x[0] + x[1]), 0.5 * (y[0] + y[1]));
    let (hx, hy) = (0.5 * per_dot * w, 0.5 * per_dot * h);
    ([cx - hx, cx + hx], [cy - hy, cy + hy])
}

/// Extent of the data in a view: the natural assembly (so compression shows) and the state.
fn view_extent(app: &App, snapshot: &Snapshot, view: View) -> ([f64; 2], [f64; 2]) {
    let g = &app.case().geometry;
    let natural_lo = [-g.radius, -g.radius, 0.0];
    let natural_hi = [g.radius, g.radius, g.height0()];
    let (h, v) = view.axes();
    let mut x = [natural_lo[h], natural_hi[h]];
    let mut y = [natural_lo[v], natural_hi[v]];
    for n in snapshot.rods.iter().flat_map(|r| &r.nodes) {
        let (px, py) = view.project(n.position);
        if px.is_finite() && py.is_finite() {
            x = [x[0].min(px), x[1].max(px)];
            y = [y[0].min(py), y[1].max(py)];
        }
    }
    let pad = 0.04 * (x[1] - x[0]).max(y[1] - y[0]);
    let snap = Snap::of(g);
    (
        [snap.value(x[0] - pad), snap.value(x[1] + pad)],
        [snap.value(y[0] - pad), snap.value(y[1] + pad)],
    )
}

fn placeholder(frame: &mut Frame, area: Rect, block: Block, app: &App) {
    let inner = block.inner(area);
    let text = match (app.solving.is_some(), inner.width >= 26) {
        (true, true) => "solving the natural state…",
        (true, false) => "solving…",
        (false, true) => "no converged state",
        (false, false) => "no state",
    };
    frame.render_widget(block, area);
    let y = inner.y + inner.height / 2;
    if inner.height > 0 {
        frame.render_widget(
            Paragraph::new(text)
                .style(Style::new().fg(DIM))
                .alignment(Alignment::Center),
            Rect {
                y,
                height: 1,
                ..inner
            },
        );
    }
}

fn draw_rod(
    ctx: &mut Context,
    rod: &RodShape,
    view: View,
    snap: Snap,
    color: impl Fn(f64) -> Color,
) {
    for w in rod.nodes.windows(2) {
        let (x1, y1) = snap.point(view.project(w[0].position));
        let (x2, y2) = snap.point(view.project(w[1].position));
        let k1 = 0.5 * (w[0].curvature[0] + w[1].curvature[0]);
        ctx.draw(&Segment {
            x1,
            y1,
            x2,
            y2,
            color: color(k1),
        });
    }
}

/// Plotted coordinates and the views' extents rounded to a millionth of the natural
/// assembly's size (far below a dot): a node on a braille dot's boundary (on a symmetry
/// axis, at ±1e-24) then falls on the same dot whatever the last bits of the solve, and
/// the picture does not change with rounding.
#[derive(Clone, Copy, Debug)]
struct Snap {
    quantum: f64,
}

impl Snap {
    fn of(g: &Geometry) -> Snap {
        Snap {
            quantum: 1e-6 * (2.0 * g.radius).max(g.height0()),
        }
    }

    fn value(self, v: f64) -> f64 {
        let q = self.quantum;
        if q > 0.0 && q.is_finite() && v.is_finite() {
            (v / q).round() * q
        } else {
            v
        }
    }

    fn point(self, (x, y): (f64, f64)) -> (f64, f64) {
        (self.value(x), self.value(y))
    }
}

/// One projection of the assembly: rods coloured by κ1, the selected rod in white on top,
/// joints in magenta.
fn draw_view(
    frame: &mut Frame,
    area: Rect,
    app: &App,
    view: View,
    scale: Option<K1Scale>,
    per_dot: f64,
) {
    let mut block = Block::new().borders(Borders::ALL).title(Span::styled(
        format!(" {} ", view.title()),
        Style::new().add_modifier(Modifier::BOLD),
    ));
    let (Some(state), Some(scale)) = (app.state.as_ref(), scale) else {
        return placeholder(frame, area, block, app);
    };
    let snapshot = &state.snapshot;
    let highlight = snapshot.rods.len() > 1;
    match view {
        View::ZY if highlight => {
            let sel = snapshot.rods.get(app.selected_rod);
            let chir = sel.map_or("", |r| r.chirality.name());
            block = block.title_bottom(Line::from(vec![
                Span::raw(" "),
                Span::styled("━", Style::new().fg(SELECTED)),
                Span::raw(format!(" rod {} ({chir}) ", app.selected_rod)),
                Span::styled("•", Style::new().fg(JOINT)),
                Span::raw(" joints "),
            ]));
        }
        View::ZY if snapshot.rods.iter().any(|r| !r.joints.is_empty()) => {
            block = block.title_bottom(Line::from(vec![
                Span::styled(" •", Style::new().fg(JOINT)),
                Span::raw(" joints "),
            ]));
        }
        View::ZX => block = block.title_bottom(scale.legend()),
        _ => {}
    }
    let inner = block.inner(area);
    let (x, y) = view_extent(app, snapshot, view);
    let (x_bounds, y_bounds) = fit_scale(inner.width, inner.height, x, y, per_dot);
    let snap = Snap::of(&app.case().geometry);
    let joints: Vec<(f64, f64)> = snapshot
        .rods
        .iter()
        .flat_map(|r| {
            r.joints
                .iter()
                .filter_map(|&s| position_at(&r.nodes, s))
                .map(move |p| snap.point(view.project(p)))
        })
        .collect();
    let selected = app.selected_rod;
    let canvas = Canvas::default()
        .block(block)
        .marker(Marker::Braille)
        .x_bounds(x_bounds)
        .y_bounds(y_bounds)
        .paint(|ctx| {
            for (i, rod) in snapshot.rods.iter().enumerate() {
                if !highlight || i != selected {
                    draw_rod(ctx, rod, view, snap, |k1| scale.color(k1));
                }
            }
            if let Some(rod) = snapshot.rods.get(selected).filter(|_| highlight) {
                draw_rod(ctx, rod, view, snap, |_| SELECTED);
            }
            ctx.draw(&Points {
                coords: &joints,
                color: JOINT,
            });
        });
    frame.render_widget(canvas, area);
}

/// `[lo, hi]` of finite values with 5 % head room, at least `min_span` wide.
fn padded_range(values: impl Iterator<Item = f64>, min_span: f64) -> [f64; 2] {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return [-1.0, 1.0];
    }
    let pad = 0.05 * (hi - lo);
    let (lo, hi) = (lo - pad, hi + pad);
    let grow = 0.5 * (min_span - (hi - lo)).max(0.0);
    [lo - grow, hi + grow]
}

/// `b` widened to round numbers such that its middle is round too: `lo`, `mid`, `hi`
/// multiples of a 1-2-5 step.
fn nice_bounds(b: [f64; 2]) -> [f64; 2] {
    let span = b[1] - b[0];
    if !(span.is_finite() && span > 0.0) {
        return b;
    }
    let raw = span / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * mag);
    let lo = (b[0] / step).floor();
    let mut hi = (b[1] / step).ceil();
    if (hi - lo) as i64 % 2 == 1 {
        hi += 1.0;
    }
    [lo * step, hi * step]
}

/// Labels at both ends and the middle (a chart spaces its labels evenly).
fn axis_labels(b: [f64; 2]) -> Vec<Line<'static>> {
    [b[0], 0.5 * (b[0] + b[1]), b[1]]
        .into_iter()
        .map(|v| Line::from(fmt_num(v)))
        .collect()
}

fn key_span(mark: &'static str, name: &'static str, color: Color) -> [Span<'static>; 2] {
    [
        Span::styled(mark, Style::new().fg(color)),
        Span::raw(format!("{name} ")),
    ]
}

/// κ1, κ2, Ω of the selected rod against s/L, joints marked by ticks along the bottom.
fn draw_curvature(frame: &mut Frame, area: Rect, app: &App) {
    let rod = app
        .state
        .as_ref()
        .and_then(|s| s.snapshot.rods.get(app.selected_rod));
    let has_bulk = app
        .state
        .as_ref()
        .is_some_and(|s| s.bulk.rods.get(app.selected_rod).is_some());
    let block = curvature_block(rod, app.no_color, has_bulk);
    let Some(rod) = rod else {
        return placeholder(frame, area, block, app);
    };
    let series: Vec<Vec<(f64, f64)>> = (0..3)
        .map(|c| {
            rod.nodes
                .iter()
                .map(|n| (n.s_over_l, n.curvature[c]))
                .collect()
        })
        .collect();
    let y = padded_range(series.iter().flatten().map(|p| p.1), 1.0);
    // a band below the curves for the joint ticks, and one above for the bulk
    let tick = 0.08 * (y[1] - y[0]);
    let bulk = app
        .state
        .as_ref()
        .and_then(|s| s.bulk.rods.get(app.selected_rod));
    let y = nice_bounds([
        if rod.joints.is_empty() {
            y[0]
        } else {
            y[0] - tick
        },
        if bulk.is_some() { y[1] + tick } else { y[1] },
    ]);
    let ticks = joint_ticks(rod, y[0], tick);
    let bulk_bar: Vec<(f64, f64)> = bulk
        .map(|b| {
            let top = y[1] - 0.25 * tick;
            vec![(b.start_over_l(), top), (b.end_over_l(), top)]
        })
        .unwrap_or_default();
    let mut datasets: Vec<Dataset> = ticks
        .iter()
        .map(|t| {
            Dataset::default()
                .data(t)
                .graph_type(GraphType::Line)
                .marker(Marker::Braille)
                .style(Style::new().fg(JOINT))
        })
        .collect();
    for (c, (data, color)) in series
        .iter()
        .zip([K1_LINE, K2_LINE, OMEGA_LINE])
        .enumerate()
    {
        let (graph, marker) = line_style(app.no_color, c);
        datasets.push(
            Dataset::default()
                .data(data)
                .graph_type(graph)
                .marker(marker)
                .style(Style::new().fg(color)),
        );
    }
    // over the curves, so that a curve in the top band does not hide it
    if !bulk_bar.is_empty() {
        datasets.push(
            Dataset::default()
                .data(&bulk_bar)
                .graph_type(GraphType::Line)
                .marker(Marker::Bar)
                .style(Style::new().fg(BULK)),
        );
    }
    let at = app.cursor as f64 / CURSOR_STEPS as f64;
    let cursor = [(at, y[0]), (at, y[1])];
    datasets.push(
        Dataset::default()
            .data(&cursor)
            .graph_type(GraphType::Line)
            .marker(Marker::Braille)
            .style(Style::new().fg(DIM)),
    );
    let values = curvature_at(&rod.nodes, at);
    let block = block.title_bottom(
        Line::from({
            let big = largest(&values);
            format!(
                " s/L {at:.2} κ1 {} κ2 {} Ω {} ",
                fmt_short(values[0], big),
                fmt_short(values[1], big),
                fmt_short(values[2], big)
            )
        })
        .alignment(Alignment::Right),
    );
    let chart = Chart::new(datasets)
        .block(block)
        .legend_position(None)
        .x_axis(
            Axis::default()
                .title("s/L")
                .bounds([0.0, 1.0])
                .labels(["0", "0.5", "1"])
                .style(Style::new().fg(DIM)),
        )
        .y_axis(
            Axis::default()
                .bounds(y)
                .labels(axis_labels(y))
                .style(Style::new().fg(DIM)),
        );
    frame.render_widget(chart, area);
}

/// The curvature panel's frame: the rod and the legend of its lines.
fn curvature_block(rod: Option<&RodShape>, no_color: bool, bulk: bool) -> Block<'static> {
    let mut title = vec![Span::styled(
        match rod {
            Some(r) => format!(" rod {} ({}) ", r.rod, r.chirality.name()),
            None => " curvature ".to_string(),
        },
        Style::new().add_modifier(Modifier::BOLD),
    )];
    let marks = legend_marks(no_color);
    title.extend(key_span(marks[0], "κ1", K1_LINE));
    title.extend(key_span(marks[1], "κ2", K2_LINE));
    title.extend(key_span(marks[2], "Ω", OMEGA_LINE));
    if rod.is_some_and(|r| !r.joints.is_empty()) {
        title.extend(key_span("╷", "joints", JOINT));
    }
    if bulk {
        title.extend(key_span("▄", "bulk", BULK));
    }
    Block::new()
        .borders(Borders::ALL)
        .title(Line::from(title))
        .title_bottom(Line::from(" (1/m) ").alignment(Alignment::Left))
}

/// How curve `c` (0, 1, 2) of a plot is drawn: all lines in colour; without colour
/// (`NO_COLOR`) a line, dots and blocks, so the legend's marks tell them apart.
fn line_style(no_color: bool, c: usize) -> (GraphType, Marker) {
    match (no_color, c) {
        (false, _) | (true, 0) => (GraphType::Line, Marker::Braille),
        (true, 1) => (GraphType::Scatter, Marker::Dot),
        (true, _) => (GraphType::Scatter, Marker::HalfBlock),
    }
}

/// The legend's marks of the three curves of a plot (see [`line_style`]).
fn legend_marks(no_color: bool) -> [&'static str; 3] {
    if no_color {
        ["━", "•", "▀"]
    } else {
        ["━", "━", "━"]
    }
}

/// κ1, κ2, Ω at `s/L = at`, interpolated between nodes.
fn curvature_at(nodes: &[NodeState], at: f64) -> [f64; 3] {
    let Some(k) = nodes.windows(2).position(|w| w[1].s_over_l >= at) else {
        return nodes.last().map_or([f64::NAN; 3], |n| n.curvature);
    };
    let (a, b) = (&nodes[k], &nodes[k + 1]);
    let t = if b.s_over_l > a.s_over_l {
        ((at - a.s_over_l) / (b.s_over_l - a.s_over_l)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    std::array::from_fn(|i| a.curvature[i] + t * (b.curvature[i] - a.curvature[i]))
}

/// A tick of height `tick` up from `bottom` at each joint of `rod`, at its s/L.
fn joint_ticks(rod: &RodShape, bottom: f64, tick: f64) -> Vec<[(f64, f64); 2]> {
    let length = rod.nodes.last().map_or(1.0, |n| {
        if n.s_over_l > 0.0 {
            n.s / n.s_over_l
        } else {
            1.0
        }
    });
    rod.joints
        .iter()
        .map(|&s| [(s / length, bottom), (s / length, bottom + tick)])
        .collect()
}

/// One load component along one stretch of the path.
struct Series {
    points: Vec<(f64, f64)>,
    color: Color,
    unstable: bool,
    component: usize,
    no_color: bool,
}

/// The load path so far: averaged normalised fx, fy, fz against ε, the current point as a
/// block, unstable stretches dotted.
fn draw_load_path(frame: &mut Frame, area: Rect, app: &App) {
    let path = &app.path;
    let stretches = stability::stretches(path.len(), |k| stability::is_unstable(&path[k]));
    let mut block = load_block(stretches.iter().any(|s| s.unstable), app.no_color);
    if !app.critical.is_empty() {
        block = block.title_bottom(Line::from(vec![
            Span::styled(" ×", Style::new().fg(Color::Yellow)),
            Span::raw(format!("critical {} (x lists) ", app.critical.len())),
        ]));
    }
    if let Some(p) = app.path_cursor.and_then(|k| path.get(k)) {
        block = block.title_bottom(
            Line::from(format!(
                " ◆ step {} ε {:.5}: fx {} fy {} fz {} ",
                p.step,
                p.eps,
                fmt_load(p.load[0], &p.load),
                fmt_load(p.load[1], &p.load),
                fmt_load(p.load[2], &p.load)
            ))
            .alignment(Alignment::Right),
        );
    }
    if path.is_empty() {
        return placeholder(frame, area, block, app);
    }
    let x = eps_bounds(app);
    let y = nice_bounds(padded_range(
        path.iter().flat_map(|p| p.load).chain([0.0]),
        0.2,
    ));
    let series = load_series(path, &stretches, app.no_color);
    let critical: Vec<(f64, f64)> = app.critical.iter().map(|c| (c.eps, c.load[2])).collect();
    let cursor: Vec<(f64, f64)> = app
        .path_cursor
        .and_then(|k| path.get(k))
        .map(|p| (0..3).map(|c| (p.eps, p.load[c])).collect())
        .unwrap_or_default();
    let now: Vec<(f64, f64)> = app
        .state
        .as_ref()
        .map(|s| (0..3).map(|c| (s.point.eps, s.point.load[c])).collect())
        .unwrap_or_default();
    let mut datasets: Vec<Dataset> = series
        .iter()
        .map(|s| {
            let (graph, marker) = if s.unstable {
                (GraphType::Scatter, Marker::Dot)
            } else {
                line_style(s.no_color, s.component)
            };
            Dataset::default()
                .data(&s.points)
                .graph_type(graph)
                .marker(marker)
                .style(Style::new().fg(s.color))
        })
        .collect();
    datasets.push(
        Dataset::default()
            .data(&now)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Block)
            .style(Style::new().fg(SELECTED)),
    );
    datasets.push(
        Dataset::default()
            .data(&cursor)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Bar)
            .style(Style::new().fg(Color::White)),
    );
    datasets.push(
        Dataset::default()
            .data(&critical)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Block)
            .style(Style::new().fg(Color::Yellow)),
    );
    let chart = Chart::new(datasets)
        .block(block)
        .legend_position(None)
        .x_axis(
            Axis::default()
                .title("ε")
                .bounds(x)
                .labels(axis_labels(x))
                .style(Style::new().fg(DIM)),
        )
        .y_axis(
            Axis::default()
                .bounds(y)
                .labels(axis_labels(y))
                .style(Style::new().fg(DIM)),
        );
    frame.render_widget(chart, area);
}

/// The load panel's frame: the legend of its lines (unstable stretches once there are).
fn load_block(any_unstable: bool, no_color: bool) -> Block<'static> {
    let mut title = vec![Span::styled(
        " load Σf/(n Pcrit) ",
        Style::new().add_modifier(Modifier::BOLD),
    )];
    let marks = legend_marks(no_color);
    title.extend(key_span(marks[0], "fx", FX_LINE));
    title.extend(key_span(marks[1], "fy", FY_LINE));
    title.extend(key_span(marks[2], "fz", FZ_LINE));
    if any_unstable {
        title.extend(key_span("•", "unstable", DIM));
    }
    title.extend(key_span("█", "now", SELECTED));
    Block::new().borders(Borders::ALL).title(Line::from(title))
}

/// The ε axis: from 0 to the target, or as far as the path (or the request) went.
fn eps_bounds(app: &App) -> [f64; 2] {
    let (lo, hi) = app
        .path
        .iter()
        .map(|p| p.eps)
        .chain([0.0, app.target(), app.requested_eps])
        .filter(|e| e.is_finite())
        .fold((0.0f64, 0.0f64), |(lo, hi), e| (lo.min(e), hi.max(e)));
    if hi > lo {
        [lo, hi]
    } else {
        [lo - 0.5, hi + 0.5]
    }
}

/// fx, fy, fz along each stretch of stable or unstable states.
fn load_series(
    path: &[LoadPoint],
    stretches: &[stability::Stretch],
    no_color: bool,
) -> Vec<Series> {
    let colors = [FX_LINE, FY_LINE, FZ_LINE];
    stretches
        .iter()
        .flat_map(|s| {
            (0..3).map(move |c| Series {
                points: path[s.points.clone()]
                    .iter()
                    .map(|p: &LoadPoint| (p.eps, p.load[c]))
                    .collect(),
                color: colors[c],
                unstable: s.unstable,
                component: c,
                no_color,
            })
        })
        .collect()
}

/// Colours of the element orders in the work-precision chart, by their place in
/// [`ORDERS`].
const ORDER_PALETTE: [Color; ORDERS.len()] = [Color::LightBlue, Color::LightRed];

/// `10^k` decade labels for an axis of log10 values from `lo` to `hi` (whole numbers): at
/// most 5, evenly spaced (a chart spaces its labels evenly).
fn decade_labels(lo: i32, hi: i32) -> Vec<Line<'static>> {
    let span = (hi - lo).max(1);
    let step = (1..=span)
        .find(|s| span % s == 0 && span / s <= 4)
        .unwrap_or(span);
    (0..=span / step)
        .map(|k| Line::from(format!("1e{}", lo + k * step)))
        .collect()
}

/// Whole decades around the log10 values `v`.
fn decade_bounds(v: impl Iterator<Item = f64>) -> Option<(i32, i32)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if lo > hi {
        return None;
    }
    let (a, b) = (lo.floor() as i32, hi.ceil() as i32);
    Some((a, b.max(a + 1)))
}

/// One panel of the work-precision chart: the measure it plots and its title.
struct PrecisionPanel {
    measure: Measure,
    title: &'static str,
    /// The panel carries the chart's caption (else the reference, once there is a study).
    caption: bool,
}

/// The work-precision chart's panels, left to right.
const PRECISION_PANELS: [PrecisionPanel; 2] = [
    PrecisionPanel {
        measure: Measure::Response,
        title: " Fz error ",
        caption: true,
    },
    PrecisionPanel {
        measure: Measure::Curvature,
        title: " κ error ",
        caption: false,
    },
];

/// The work-precision chart of the case in place of the curvature and load plots: the
/// error of Fz and of the curvature profiles against the wall time, log-log, one line per
/// element order (the chart `spira precision` writes).
fn draw_precision(frame: &mut Frame, area: Rect, app: &App) {
    let areas: [Rect; PRECISION_PANELS.len()] =
        Layout::horizontal([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)]).areas(area);
    let study = match &app.precision {
        PrecisionView::Ready(s) => Some(s.as_ref()),
        _ => None,
    };
    for (area, panel) in areas.into_iter().zip(&PRECISION_PANELS) {
        let block = precision_block(panel, study);
        match study {
            Some(study) => draw_precision_chart(frame, area, block, panel, study),
            None => draw_precision_pending(frame, area, block, &app.precision),
        }
    }
}

/// A panel's frame: its title with the legend of the orders (and the finest observed
/// order of each, once known), the caption on the left panel.
fn precision_block(panel: &PrecisionPanel, study: Option<&Study>) -> Block<'static> {
    let mut title = vec![bold(panel.title.to_string())];
    for (o, color) in ORDERS.into_iter().zip(ORDER_PALETTE) {
        let order = study
            .and_then(|s| s.finest_observed(panel.measure, o))
            .map_or(String::new(), |k| format!(" {k:.1}"));
        title.push(Span::styled("━", Style::new().fg(color)));
        title.push(Span::raw(format!("{}{order} ", o.name())));
    }
    let block = Block::new().borders(Borders::ALL).title(Line::from(title));
    if panel.caption {
        block.title_bottom(Line::from(" work-precision, log-log ").alignment(Alignment::Left))
    } else {
        block
    }
}

/// A panel before its study is ready: how far the study is, or why it failed.
fn draw_precision_pending(frame: &mut Frame, area: Rect, block: Block, view: &PrecisionView) {
    let text = match view {
        PrecisionView::Running { done, total } if *total > 0 => {
            format!("work-precision study: {done} of {total} meshes solved…")
        }
        PrecisionView::Running { .. } => "work-precision study: starting…".to_string(),
        PrecisionView::Failed(e) => format!("work-precision study failed: {e}"),
        _ => "no study (w asks for one)".to_string(),
    };
    let inner = block.inner(area);
    frame.render_widget(block, area);
    if inner.height > 0 {
        frame.render_widget(
            Paragraph::new(text)
                .style(Style::new().fg(DIM))
                .alignment(Alignment::Center)
                .wrap(Wrap { trim: true }),
            Rect {
                y: inner.y + inner.height / 2,
                height: inner.height - inner.height / 2,
                ..inner
            },
        );
    }
}

/// A panel's log-log lines, one per order (log10 of time, log10 of error), with their
/// colours.
fn precision_series(study: &Study, m: Measure) -> Vec<(Color, Vec<(f64, f64)>)> {
    ORDERS
        .into_iter()
        .zip(ORDER_PALETTE)
        .map(|(o, color)| {
            let pts = study
                .points(o, m)
                .iter()
                .map(|p| (p.x.log10(), p.y.log10()))
                .collect();
            (color, pts)
        })
        .collect()
}

/// A panel of a finished study: error against time per order, the reference named on the
/// right panel.
fn draw_precision_chart(
    frame: &mut Frame,
    area: Rect,
    mut block: Block,
    panel: &PrecisionPanel,
    study: &Study,
) {
    if !panel.caption {
        let reference = format!(" ref: {} ", precision::reference_label(&study.reference));
        block = block.title_bottom(Line::from(reference).alignment(Alignment::Right));
    }
    let series = precision_series(study, panel.measure);
    let all = || series.iter().flat_map(|(_, p)| p.iter());
    let (Some(xb), Some(yb)) = (
        decade_bounds(all().map(|p| p.0)),
        decade_bounds(all().map(|p| p.1)),
    ) else {
        frame.render_widget(block, area);
        return;
    };
    let mut datasets = Vec::new();
    for (color, pts) in &series {
        let style = Style::new().fg(*color);
        datasets.push(
            Dataset::default()
                .data(pts)
                .graph_type(GraphType::Line)
                .marker(Marker::Braille)
                .style(style),
        );
        datasets.push(
            Dataset::default()
                .data(pts)
                .graph_type(GraphType::Scatter)
                .marker(Marker::Block)
                .style(style),
        );
    }
    let chart = Chart::new(datasets)
        .block(block)
        .legend_position(None)
        .x_axis(
            Axis::default()
                .title("time (s)")
                .bounds([xb.0 as f64, xb.1 as f64])
                .labels(decade_labels(xb.0, xb.1))
                .style(Style::new().fg(DIM)),
        )
        .y_axis(
            Axis::default()
                .bounds([yb.0 as f64, yb.1 as f64])
                .labels(decade_labels(yb.0, yb.1))
                .style(Style::new().fg(DIM)),
        );
    frame.render_widget(chart, area);
}

fn sep() -> Span<'static> {
    Span::styled(" │ ", Style::new().fg(DIM))
}

fn bold(s: String) -> Span<'static> {
    Span::styled(s, Style::new().add_modifier(Modifier::BOLD))
}

/// Lines the message (or the key hint) takes at `width`, wrapped, at most 3.
fn message_lines(app: &App, width: u16) -> u16 {
    let len = match &app.message {
        Some(Message::Error(m)) | Some(Message::Info(m)) => Line::from(m.as_str()).width(),
        None => 0,
    };
    (len.div_ceil(width.max(1) as usize) as u16).clamp(1, 3)
}

/// Case and loading; boundary conditions; the last solve; messages (wrapped).
fn draw_status(frame: &mut Frame, area: Rect, app: &App) {
    let [a, r, b, c, d] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Min(0),
    ])
    .areas(area);
    frame.render_widget(Paragraph::new(case_line(app)), a);
    frame.render_widget(Paragraph::new(readout_line(app, r.width)), r);
    frame.render_widget(Paragraph::new(boundary_line(app)), b);
    frame.render_widget(Paragraph::new(solve_line(app)), c);
    frame.render_widget(
        Paragraph::new(message_line(app)).wrap(Wrap { trim: false }),
        d,
    );
}

/// The numbers of the state on screen: h, the loads, the selected rod's bulk (s/L),
/// energy, stability, and the selected rod's tip reaction, in `width` columns: the loads
/// and the stability (unstable directions, λmin) always, the others as they fit (the rod's
/// tip reaction given up first, then h, which line 1's ε gives; then the labels are
/// shortened; then E and last the bulk are given up).
fn readout_line(app: &App, width: u16) -> Line<'static> {
    let full = readout_fields(app, false);
    let Some(mut fields) = full else {
        return Line::from(Span::styled("no converged state", Style::new().fg(DIM)));
    };
    let fits = |fields: &[(u8, Vec<Span<'static>>)]| {
        let line = join_fields(fields);
        (line.width() <= width as usize).then_some(line)
    };
    let drop_above = |fields: &mut Vec<(u8, Vec<Span<'static>>)>, floor: u8| {
        let worst = fields
            .iter()
            .enumerate()
            .filter(|(_, (priority, _))| *priority > floor)
            .max_by_key(|(_, (priority, _))| *priority)
            .map(|(k, _)| k);
        worst.map(|k| fields.remove(k)).is_some()
    };
    loop {
        if let Some(line) = fits(&fields) {
            return line;
        }
        if !drop_above(&mut fields, 3) {
            break;
        }
    }
    // shorter labels, then the lesser fields
    let mut fields = readout_fields(app, true).unwrap_or_default();
    fields.retain(|(priority, _)| *priority <= 3);
    loop {
        if let Some(line) = fits(&fields) {
            return line;
        }
        if !drop_above(&mut fields, 0) {
            return join_fields(&fields);
        }
    }
}

/// The fields joined by separators.
fn join_fields(fields: &[(u8, Vec<Span<'static>>)]) -> Line<'static> {
    let mut spans = Vec::new();
    for (k, (_, f)) in fields.iter().enumerate() {
        if k > 0 {
            spans.push(sep());
        }
        spans.extend(f.iter().cloned());
    }
    Line::from(spans)
}

/// The readout's fields with the priority to keep each (0 always, higher given up
/// first), with shorter labels when `short`; `None` without a converged state.
fn readout_fields(app: &App, short: bool) -> Option<Vec<(u8, Vec<Span<'static>>)>> {
    let s = app.state.as_ref()?;
    let p = &s.point;
    let (dirs, lowest) = match p.stability {
        Some(st) => (
            st.unstable_directions.to_string(),
            st.lowest_eigenvalue.map_or("–".into(), fmt_num),
        ),
        None => ("–".into(), "–".into()),
    };
    let big = largest(&p.load);
    // (priority to keep: 0 always, higher given up first; the spans)
    let mut fields: Vec<(u8, Vec<Span<'static>>)> = vec![
        (4, vec![Span::raw(format!("h {} m", fmt_num(p.height)))]),
        (
            0,
            vec![
                Span::raw(format!(
                    "fx {} fy {} fz/nPc ",
                    fmt_short(p.load[0], big),
                    fmt_short(p.load[1], big)
                )),
                bold(fmt_short(p.load[2], big)),
            ],
        ),
    ];
    if let Some(b) = s.bulk.rods.get(app.selected_rod) {
        fields.push((
            2,
            vec![Span::raw(format!(
                "bulk {:.2}–{:.2}",
                b.start_over_l(),
                b.end_over_l()
            ))],
        ));
    }
    fields.push((3, vec![Span::raw(format!("E {} J", fmt_num(p.energy)))]));
    let unstable = if short { "unst." } else { "unstable" };
    fields.push((
        0,
        vec![Span::raw(format!("{unstable} {dirs} λmin {lowest}"))],
    ));
    if let Some(r) = p.reactions.get(app.selected_rod) {
        let f = r.tip.force;
        let big = largest(&f);
        fields.push((
            5,
            vec![Span::raw(format!(
                "rod {} tip F ({}, {}, {}) N",
                r.rod,
                fmt_short(f[0], big),
                fmt_short(f[1], big),
                fmt_short(f[2], big)
            ))],
        ));
    }
    Some(fields)
}

/// What the explorer is doing: solving (what, for how long, how far), running, or idle.
fn activity(app: &App) -> Span<'static> {
    let solving = |job: &str| {
        // a step, and the natural state (whose n the line shows already), drop "solving"
        // so that the cancel key fits 80 columns
        let what = if job.starts_with('ε') {
            job.to_string()
        } else if job.starts_with("natural state") {
            "natural state".to_string()
        } else {
            format!("solving {job}")
        };
        let mut text = match app.elapsed {
            Some(e) => format!("{what}… {:.1} s · c cancels", e.as_secs_f64()),
            None => format!("solving {job}…"),
        };
        if let Some(p) = app.progress {
            text.push_str(&format!(" · at {:.5} ({} steps)", p.parameter, p.steps));
        }
        text
    };
    match (&app.solving, app.running) {
        (Some(job), true) => Span::styled(
            format!("▶ running · {}", solving(job)),
            Style::new().fg(Color::Yellow),
        ),
        (Some(job), false) => Span::styled(solving(job), Style::new().fg(Color::Yellow)),
        (None, true) => Span::styled("▶ running", Style::new().fg(Color::Yellow)),
        (None, false) => Span::styled("idle", Style::new().fg(Color::Green)),
    }
}

/// Status line 1: case, `n`, `ε` and its target, the step, the activity.
fn case_line(app: &App) -> Line<'static> {
    let eps = app
        .state
        .as_ref()
        .map_or("–".to_string(), |s| format!("{:.5}", s.point.eps));
    Line::from(vec![
        bold(app.case_label()),
        sep(),
        Span::raw(format!(
            "n {} {}",
            app.helices,
            if app.solves_pair() { "pair" } else { "full" }
        )),
        sep(),
        Span::raw("ε "),
        bold(eps),
        Span::raw(format!(" → {}", app.target())),
        sep(),
        Span::raw(format!("Δε {}", fmt_step(app.step))),
        sep(),
        activity(app),
    ])
}

/// Status line 2: the conditions in force, the mesh an accuracy target chose, and the
/// conditions asked for when they are not in force yet.
fn boundary_line(app: &App) -> Line<'static> {
    let in_force = app.state.as_ref().map_or(app.boundary, |s| s.boundary);
    let mut line = vec![
        Span::raw(format!("base {}", in_force.base.label())),
        sep(),
        Span::raw(format!("tip {}", in_force.tip.label())),
        sep(),
        Span::raw(format!(
            "joints {}",
            if in_force.joints { "on" } else { "off" }
        )),
    ];
    if let Some(m) = &app.mesh {
        // the mesh an accuracy target chose, with the error estimated for it
        line.push(sep());
        line.push(Span::raw(format!(
            "mesh {} {}, err {:.0e}",
            m.elements,
            m.order.name(),
            m.estimated_error
        )));
    }
    // the elastic hypotheses, when they are not the thesis's (issue 11)
    let case = app.case();
    let hypotheses = match (case.rod.stress_free, case.rod.energy) {
        (_, crate::model::elasticity::Energy::Sadowsky(_)) => Some("Sadowsky ribbons"),
        (crate::model::elasticity::StressFree::Straight, _) => Some("rods straight at rest"),
        _ => None,
    };
    if let Some(h) = hypotheses {
        line.push(sep());
        line.push(Span::raw(h));
    }
    if case.discretisation.reference == crate::model::elasticity::Reference::Continuum {
        line.push(sep());
        line.push(Span::raw("continuum κ*"));
    }
    if in_force != app.boundary {
        line.push(sep());
        line.push(Span::styled(
            format!("asked: {}", app.boundary.label()),
            Style::new().fg(Color::Yellow),
        ));
    }
    Line::from(line)
}

/// Status line 3: stability of the state on screen and how its solve went.
fn solve_line(app: &App) -> Line<'static> {
    let unstable = app.stability();
    let stability_style = match unstable {
        Some(true) => Style::new()
            .fg(Color::LightRed)
            .add_modifier(Modifier::BOLD),
        _ => Style::new(),
    };
    match app.state.as_ref() {
        // stability first: on a narrow screen the line is cut from the right
        Some(s) => Line::from(vec![
            Span::raw("stability "),
            Span::styled(stability::label(unstable), stability_style),
            sep(),
            Span::raw(format!(
                "Newton {} it, |R| {:.1e}",
                s.point.iterations, s.point.residual
            )),
            sep(),
            Span::raw(format!("solve {}", fmt_duration(s.time))),
            sep(),
            Span::raw(format!("inner step {}", fmt_num(s.step_length))),
        ]),
        None => Line::from(vec![Span::raw("stability "), Span::raw("n/a")]),
    }
}

/// The message for the user, or the key hint.
fn message_line(app: &App) -> Line<'static> {
    match &app.message {
        Some(Message::Error(m)) => {
            Line::from(Span::styled(m.clone(), Style::new().fg(Color::LightRed)))
        }
        Some(Message::Info(m)) => {
            Line::from(Span::styled(m.clone(), Style::new().fg(Color::Green)))
        }
        None => Line::from(Span::styled(
            "←→ step  ↑↓ rod  space run  +- Δε  e export  ? help (all keys)  q quit",
            Style::new().fg(DIM),
        )),
    }
}

fn fmt_duration(d: std::time::Duration) -> String {
    let ms = d.as_secs_f64() * 1e3;
    if ms < 10.0 {
        format!("{ms:.1} ms")
    } else if ms < 10_000.0 {
        format!("{ms:.0} ms")
    } else {
        format!("{:.1} s", ms / 1e3)
    }
}

/// The keys, in the help overlay: (keys, what they do), made from the key table
/// [`BINDINGS`] that the key handling reads.
pub const KEYS: [(&str, &str); BINDINGS.len()] = {
    let mut keys = [("", ""); BINDINGS.len()];
    let mut i = 0;
    while i < keys.len() {
        keys[i] = (BINDINGS[i].label, BINDINGS[i].help);
        i += 1;
    }
    keys
};

fn draw_help(frame: &mut Frame, area: Rect, app: &App) {
    let mut lines: Vec<Line> = KEYS
        .iter()
        .map(|(k, what)| {
            Line::from(vec![
                Span::styled(format!(" {k:<6} "), Style::new().fg(Color::Yellow)),
                Span::raw(*what),
            ])
        })
        .collect();
    lines.push(Line::from(Span::styled(
        if app.out_dir == std::path::Path::new(".") {
            " exports go to the current folder".to_string()
        } else {
            format!(" exports go to {}", app.out_dir.display())
        },
        Style::new().fg(DIM),
    )));
    draw_overlay(frame, area, lines, " keys ", " any key closes ");
}

/// A box of `lines` centred over the screen, titled, with how to close it at the bottom.
fn draw_overlay(frame: &mut Frame, area: Rect, lines: Vec<Line>, title: &str, close: &str) {
    let width = (lines.iter().map(|l| l.width()).max().unwrap_or(0) as u16 + 3).min(area.width);
    let height = (lines.len() as u16 + 2).min(area.height);
    let rect = Rect {
        x: area.x + (area.width - width) / 2,
        y: area.y + (area.height - height) / 2,
        width,
        height,
    };
    frame.render_widget(Clear, rect);
    frame.render_widget(
        Paragraph::new(lines).block(
            Block::new()
                .borders(Borders::ALL)
                .title(title.to_string())
                .title_bottom(Line::from(close.to_string()).alignment(Alignment::Right)),
        ),
        rect,
    );
}
