//! The three projections of the assembly (X-Y, Z-Y, Z-X): rods coloured by κ1 on a common
//! scale, the selected rod and the joints marked, and while the critical-point list is
//! open the chosen point's mode over the state.

use super::chart::placeholder;
use super::colours::{JOINT, K1_PALETTE, MODE, SELECTED};
use super::numbers::fmt_num;
use crate::case::Geometry;
use crate::results::{ModeShape, NodeState, RodShape, Snapshot};
use crate::tui::app::{App, ViewMode};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line as Segment, Points};
use ratatui::widgets::{Block, Borders};
use ratatui::Frame;

/// The views in `area`: the X-Y view square on the left and the two side views stacked
/// on the right, or the one view chosen alone.
pub(super) fn draw_views(frame: &mut Frame, area: Rect, app: &App) {
    // the X-Y view square on screen: braille dots are about square, 2 x 4 per cell
    let xy_width = (area.height.saturating_sub(2) * 2 + 2).min(area.width / 3);
    let [xy, side] =
        Layout::horizontal([Constraint::Length(xy_width), Constraint::Min(0)]).areas(area);
    // the Z-Y view has no bottom border (the Z-X view's top one parts them) and its
    // legend on the Z-X view's top border: rows for the drawings, the same in both
    let zy_rows = 1 + side.height.saturating_sub(3) / 2;
    let [zy, zx] = Layout::vertical([Constraint::Length(zy_rows), Constraint::Min(0)]).areas(side);
    let scale = app
        .screen
        .state
        .as_ref()
        .map(|s| K1Scale::of(&s.snapshot, app.screen.natural_k1));
    match app.view.mode {
        ViewMode::All => {
            // the two side views at one scale, so their shapes compare
            let per_dot = app.screen.state.as_ref().map_or(0.0, |s| {
                [(zy, View::ZY), (zx, View::ZX)]
                    .iter()
                    .map(|&(a, v)| {
                        let inner = Block::new().borders(borders(v, true)).inner(a);
                        let (x, y) = view_extent(app, &s.snapshot, v);
                        dot_size(inner.width, inner.height, x, y)
                    })
                    .fold(0.0, f64::max)
            });
            draw_view(frame, xy, app, (View::XY, false), scale, 0.0);
            draw_view(frame, zy, app, (View::ZY, true), scale, per_dot);
            draw_view(frame, zx, app, (View::ZX, true), scale, per_dot);
        }
        ViewMode::XY => draw_view(frame, area, app, (View::XY, false), scale, 0.0),
        ViewMode::ZY => draw_view(frame, area, app, (View::ZY, false), scale, 0.0),
        ViewMode::ZX => draw_view(frame, area, app, (View::ZX, false), scale, 0.0),
    }
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

/// The borders of `view`'s box: the Z-Y view stacked over the Z-X one has no bottom
/// border.
fn borders(view: View, stacked: bool) -> Borders {
    if stacked && view == View::ZY {
        Borders::TOP | Borders::LEFT | Borders::RIGHT
    } else {
        Borders::ALL
    }
}

/// The legend of `view`: for the Z-Y view the mode previewed, or the selected rod and the
/// joints; for the Z-X view the κ1 colour scale (none without colour, where every rod is
/// drawn alike).
fn legend(app: &App, view: View, snapshot: &Snapshot, scale: K1Scale) -> Option<Line<'static>> {
    match view {
        View::ZY if app.view.show_critical && mode_preview(app).is_some() => {
            let k = app.view.critical_cursor;
            let mark = if app.view.no_color {
                PREVIEW_MARK
            } else {
                "━"
            };
            Some(Line::from(vec![
                Span::raw(" "),
                Span::styled(mark, Style::new().fg(MODE)),
                Span::raw(format!(" mode of critical point {k} ")),
            ]))
        }
        View::ZY if snapshot.rods.len() > 1 => {
            let sel = snapshot.rods.get(app.view.selected_rod);
            let chir = sel.map_or("", |r| r.chirality.name());
            Some(Line::from(vec![
                Span::raw(" "),
                Span::styled("━", Style::new().fg(SELECTED)),
                Span::raw(format!(" rod {} ({chir}) ", app.view.selected_rod)),
                Span::styled("•", Style::new().fg(JOINT)),
                Span::raw(" joints "),
            ]))
        }
        View::ZY if snapshot.rods.iter().any(|r| !r.joints.is_empty()) => Some(Line::from(vec![
            Span::styled(" •", Style::new().fg(JOINT)),
            Span::raw(" joints "),
        ])),
        View::ZX if !app.view.no_color => Some(scale.legend()),
        _ => None,
    }
}

/// One projection of the assembly (`stacked`: a side view over or under the other): rods
/// coloured by κ1, the selected rod in white on top, joints in magenta.
fn draw_view(
    frame: &mut Frame,
    area: Rect,
    app: &App,
    (view, stacked): (View, bool),
    scale: Option<K1Scale>,
    per_dot: f64,
) {
    let mut block = Block::new()
        .borders(borders(view, stacked))
        .title(Span::styled(
            format!(" {} ", view.title()),
            Style::new().add_modifier(Modifier::BOLD),
        ));
    let (Some(state), Some(scale)) = (app.screen.state.as_ref(), scale) else {
        return placeholder(frame, area, block, app);
    };
    let snapshot = &state.snapshot;
    let highlight = snapshot.rods.len() > 1;
    let preview = mode_preview(app);
    if stacked && view == View::ZX {
        if let Some(l) = legend(app, View::ZY, snapshot, scale) {
            block = block.title(l.alignment(ratatui::layout::Alignment::Right));
        }
    }
    if !(stacked && view == View::ZY) {
        if let Some(l) = legend(app, view, snapshot, scale) {
            block = block.title_bottom(l);
        }
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
    let selected = app.view.selected_rod;
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
            if let Some(rods) = &preview {
                ctx.layer();
                // without colour, marks a cell apart: a dotted outline, not a blot
                let cell = (
                    (x_bounds[1] - x_bounds[0]) / f64::from(inner.width.max(1)),
                    (y_bounds[1] - y_bounds[0]) / f64::from(inner.height.max(1)),
                );
                let apart = app.view.no_color.then_some(cell);
                draw_preview(ctx, rods, (view, snap), apart);
            }
        });
    frame.render_widget(canvas, area);
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

/// The mark of a mode's preview without colour (printed at its nodes).
const PREVIEW_MARK: &str = "∘";

/// The mode's largest centreline displacement drawn as this part of the helix radius.
const PREVIEW_AMPLITUDE: f64 = 0.3;

/// While the critical-point list is open: the chosen point's mode on the geometry of its
/// state, scaled for the eye (its largest displacement [`PREVIEW_AMPLITUDE`] of the helix
/// radius), as the centreline of each rod.
fn mode_preview(app: &App) -> Option<Vec<Vec<[f64; 3]>>> {
    if !app.view.show_critical {
        return None;
    }
    let mode: &ModeShape = &app.screen.modes.get(app.view.critical_cursor)?.shape;
    let largest = mode
        .displacement
        .iter()
        .flatten()
        .map(|d| d[0].hypot(d[1]).hypot(d[2]))
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    if largest <= 0.0 {
        return None;
    }
    let amplitude = PREVIEW_AMPLITUDE * app.case().geometry.radius / largest;
    Some(
        mode.shape
            .rods
            .iter()
            .zip(&mode.displacement)
            .map(|(rod, d)| {
                rod.nodes
                    .iter()
                    .zip(d)
                    .map(|(n, d)| std::array::from_fn(|i| n.position[i] + amplitude * d[i]))
                    .collect()
            })
            .collect(),
    )
}

/// The preview's rods: lines in the mode's colour, or (`apart`: the size of a cell) its
/// mark at nodes two cells across or a row apart.
fn draw_preview(
    ctx: &mut Context,
    rods: &[Vec<[f64; 3]>],
    (view, snap): (View, Snap),
    apart: Option<(f64, f64)>,
) {
    for rod in rods {
        if let Some((w, h)) = apart {
            let mut last: Option<(f64, f64)> = None;
            for p in rod {
                let (x, y) = snap.point(view.project(*p));
                if last.is_some_and(|(a, b)| (x - a).abs() < 2.0 * w && (y - b).abs() < h) {
                    continue;
                }
                last = Some((x, y));
                ctx.print(x, y, Span::styled(PREVIEW_MARK, Style::new().fg(MODE)));
            }
            continue;
        }
        for w in rod.windows(2) {
            let (x1, y1) = snap.point(view.project(w[0]));
            let (x2, y2) = snap.point(view.project(w[1]));
            ctx.draw(&Segment {
                x1,
                y1,
                x2,
                y2,
                color: MODE,
            });
        }
    }
}
