//! The work-precision chart (`w`) in place of the curvature and load plots.

use super::chart::bold;
use super::colours::DIM;
use crate::output::precision::{self, StudyReport};
use crate::study::{Measure, Study, ORDERS};
use crate::tui::app::{App, PrecisionView};
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph, Wrap};
use ratatui::Frame;

/// Colours of the element orders in the work-precision chart, by their place in
/// [`ORDERS`].
const ORDER_PALETTE: [Color; ORDERS.len()] = [Color::LightBlue, Color::LightRed];

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
pub(super) fn draw_precision(frame: &mut Frame, area: Rect, app: &App) {
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
                .labels(decade_labels(xb.0, xb.1, 3))
                .style(Style::new().fg(DIM)),
        )
        .y_axis(
            Axis::default()
                .bounds([yb.0 as f64, yb.1 as f64])
                .labels(decade_labels(yb.0, yb.1, 5))
                .style(Style::new().fg(DIM)),
        );
    frame.render_widget(chart, area);
}

/// `10^k` decade labels for an axis of log10 values from `lo` to `hi` (whole numbers, an
/// even span): at most `most` of them (2 or more), at whole decades evenly spaced. The
/// abscissa takes 3: a chart places the first and last at the ends and, of more than 3,
/// the others not where their values are.
fn decade_labels(lo: i32, hi: i32, most: i32) -> Vec<Line<'static>> {
    let span = (hi - lo).max(1);
    let step = (1..=span)
        .find(|s| span % s == 0 && span / s < most.max(2))
        .unwrap_or(span);
    (0..=span / step)
        .map(|k| Line::from(format!("1e{}", lo + k * step)))
        .collect()
}

/// Whole decades around the log10 values `v`, an even number of them (so that the middle
/// of the axis is a decade too).
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
    let b = b.max(a + 1);
    Some((a, b + (b - a) % 2))
}
