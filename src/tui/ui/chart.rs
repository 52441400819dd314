//! What the charts share: ranges and round bounds of their axes, legend marks, line styles
//! with and without colour, the placeholder of a panel without a state, separators.

use super::colours::DIM;
use super::numbers::fmt_num;
use crate::tui::app::App;
use ratatui::layout::{Alignment, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, GraphType, Paragraph};
use ratatui::Frame;

/// `[lo, hi]` of finite values with 5 % head room, at least `min_span` wide.
pub(super) fn padded_range(values: impl Iterator<Item = f64>, min_span: f64) -> [f64; 2] {
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
pub(super) fn nice_bounds(b: [f64; 2]) -> [f64; 2] {
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
pub(super) fn axis_labels(b: [f64; 2]) -> Vec<Line<'static>> {
    [b[0], 0.5 * (b[0] + b[1]), b[1]]
        .into_iter()
        .map(|v| Line::from(fmt_num(v)))
        .collect()
}

pub(super) fn key_span(
    mark: impl Into<std::borrow::Cow<'static, str>>,
    name: &'static str,
    color: Color,
) -> [Span<'static>; 2] {
    [
        Span::styled(mark, Style::new().fg(color)),
        Span::raw(format!("{name} ")),
    ]
}

/// How curve `c` (0, 1, 2) of a plot is drawn: all lines in colour; without colour
/// (`NO_COLOR`) a braille line, a line of dots and a line of crosses, so the legend's marks
/// tell them apart (and none is a mark of the load panel's points: [`UNSTABLE_MARK`],
/// [`NOW_MARK`], [`CRITICAL_MARK`]).
pub(super) fn line_style(no_color: bool, c: usize) -> (GraphType, Marker) {
    match (no_color, c) {
        (false, _) | (true, 0) => (GraphType::Line, Marker::Braille),
        (true, 1) => (GraphType::Line, Marker::Custom('•')),
        (true, _) => (GraphType::Line, Marker::Custom('+')),
    }
}

/// The legend's marks of the three curves of a plot (see [`line_style`]).
pub(super) fn legend_marks(no_color: bool) -> [&'static str; 3] {
    if no_color {
        ["━", "•", "+"]
    } else {
        ["━", "━", "━"]
    }
}

/// How an unstable stretch of the load path is drawn, and its legend's mark: a dotted
/// line in colour (each curve keeps its colour), a shaded line without.
pub(super) fn unstable_style(no_color: bool) -> (GraphType, Marker, char) {
    if no_color {
        (
            GraphType::Line,
            Marker::Custom(UNSTABLE_MARK),
            UNSTABLE_MARK,
        )
    } else {
        (GraphType::Line, Marker::Dot, '•')
    }
}

/// The shaded line of an unstable stretch without colour.
pub(super) const UNSTABLE_MARK: char = '░';
/// The state on screen on the load panel.
pub(super) const NOW_MARK: char = '█';
/// A critical point on the load panel.
pub(super) const CRITICAL_MARK: char = '×';
/// The path cursor on the load panel (its readout starts with it).
pub(super) const CURSOR_MARK: char = '◆';

pub(super) fn placeholder(frame: &mut Frame, area: Rect, block: Block, app: &App) {
    let inner = block.inner(area);
    let text = match (app.requests.solving.is_some(), inner.width >= 26) {
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

/// The first of `lines` (longest first) that fits `width` columns, else the last.
pub(super) fn first_fitting(lines: Vec<Line<'static>>, width: u16) -> Line<'static> {
    let mut last = Line::default();
    for line in lines {
        if line.width() <= width as usize {
            return line;
        }
        last = line;
    }
    last
}

pub(super) fn sep() -> Span<'static> {
    Span::styled(" │ ", Style::new().fg(DIM))
}

pub(super) fn bold(s: String) -> Span<'static> {
    Span::styled(s, Style::new().add_modifier(Modifier::BOLD))
}
