//! The critical curve of the scene (`u`) in place of the curvature and load plots: the
//! critical load parameter and the axial tip force at the critical point against the design
//! key, the scene's own value marked.

use super::chart::{axis_labels, bold, nice_bounds, padded_range};
use super::colours::DIM;
use super::numbers::fmt_num;
use crate::simulation::curve::CurveRow;
use crate::tui::app::{App, CurveView, CURVE_WIDTH};
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::symbols::Marker;
use ratatui::text::Line;
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph, Wrap};
use ratatui::Frame;

/// The colour of the curve, and of the scene's own value.
const CURVE_COLOUR: Color = Color::LightCyan;
const SCENE_COLOUR: Color = Color::Yellow;

/// One panel: its title and what it plots of a row.
struct CurvePanel {
    title: fn(&App) -> String,
    y: fn(&CurveRow) -> f64,
}

const CURVE_PANELS: [CurvePanel; 2] = [
    CurvePanel {
        title: |app| format!(" critical {} ", app.symbol()),
        y: |r| r.parameter,
    },
    CurvePanel {
        title: |_| " fz at the critical point (N) ".to_string(),
        y: |r| r.fz,
    },
];

/// The two panels of the critical curve side by side, with how far the curve is (or why
/// there is none) under the left one.
pub(super) fn draw_curve(frame: &mut Frame, area: Rect, app: &App) {
    let areas: [Rect; 2] =
        Layout::horizontal([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)]).areas(area);
    let rows = curve_rows(&app.curve);
    for (k, (area, panel)) in areas.into_iter().zip(&CURVE_PANELS).enumerate() {
        let mut block = Block::new()
            .borders(Borders::ALL)
            .title(Line::from(bold((panel.title)(app))));
        if k == 0 {
            block = block.title_bottom(
                Line::from(format!(" {} ", curve_state(&app.curve))).alignment(Alignment::Left),
            );
        } else {
            block = block.title_bottom(
                Line::from(format!(
                    " against {}, ±{:.0} % ",
                    app.view.curve_key.label(),
                    100.0 * CURVE_WIDTH
                ))
                .alignment(Alignment::Right),
            );
        }
        if rows.is_empty() {
            let note = if k == 0 {
                curve_note(&app.curve)
            } else {
                String::new()
            };
            draw_note(frame, area, block, note);
        } else {
            draw_curve_chart(frame, area, block, app, &rows, panel.y);
        }
    }
}

/// The rows found so far, in increasing order of the key.
fn curve_rows(view: &CurveView) -> Vec<CurveRow> {
    let mut rows = match view {
        CurveView::Running { rows, .. } => rows.clone(),
        CurveView::Ready(done) => done.rows.clone(),
        _ => Vec::new(),
    };
    rows.sort_by(|a, b| a.value.total_cmp(&b.value));
    rows
}

/// How far the curve is, in a few words (the left panel's foot).
fn curve_state(view: &CurveView) -> String {
    match view {
        CurveView::None => "no curve: u asks for one".into(),
        CurveView::Running {
            cancelling: true, ..
        } => "cancelling…".into(),
        CurveView::Running { done, total, .. } => {
            format!("{done} of {total} points, c cancels")
        }
        CurveView::Ready(d) if d.cancelled => format!("cancelled at {}", points(d.rows.len())),
        CurveView::Ready(d) if !d.stopped.is_empty() => {
            format!("{}, stopped short", points(d.rows.len()))
        }
        CurveView::Ready(d) => points(d.rows.len()),
        CurveView::Failed(_) => "no curve".into(),
    }
}

fn points(n: usize) -> String {
    if n == 1 {
        "1 point".into()
    } else {
        format!("{n} points")
    }
}

/// The text of a panel without rows: the locating path's progress, or why there is none.
fn curve_note(view: &CurveView) -> String {
    match view {
        CurveView::Running {
            locating: Some(p), ..
        } => format!(
            "locating the critical point: the path is at {}",
            fmt_num(*p)
        ),
        CurveView::Running { .. } => "critical curve: starting…".into(),
        CurveView::Failed(e) => format!("no critical curve: {e}"),
        CurveView::Ready(d) if !d.stopped.is_empty() => d.stopped.join("; "),
        _ => "no critical curve (u asks for one)".into(),
    }
}

fn draw_note(frame: &mut Frame, area: Rect, block: Block, text: String) {
    let inner = block.inner(area);
    frame.render_widget(block, area);
    if inner.height > 0 {
        let top = inner.height / 3;
        frame.render_widget(
            Paragraph::new(text)
                .style(Style::new().fg(DIM))
                .alignment(Alignment::Center)
                .wrap(Wrap { trim: true }),
            Rect {
                y: inner.y + top,
                height: inner.height - top,
                ..inner
            },
        );
    }
}

/// One panel's chart: the curve in braille, its points, and the scene's value as a
/// vertical line.
fn draw_curve_chart(
    frame: &mut Frame,
    area: Rect,
    block: Block,
    app: &App,
    rows: &[CurveRow],
    y: fn(&CurveRow) -> f64,
) {
    let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.value, y(r))).collect();
    let scene = app.case().design_value(app.view.curve_key);
    // the whole window asked for, whatever part of it the curve covers
    let xb = nice_bounds(padded_range(
        pts.iter()
            .map(|p| p.0)
            .chain([scene * (1.0 - CURVE_WIDTH), scene * (1.0 + CURVE_WIDTH)]),
        0.0,
    ));
    let yb = nice_bounds(padded_range(
        pts.iter().map(|p| p.1),
        // a flat curve shows flat: the axis spans at least 2 % of its values
        0.02 * pts.iter().map(|p| p.1.abs()).fold(0.0, f64::max).max(1e-12),
    ));
    let mark = [(scene, yb[0]), (scene, yb[1])];
    let style = Style::new().fg(CURVE_COLOUR);
    let datasets = vec![
        Dataset::default()
            .data(&mark)
            .graph_type(GraphType::Line)
            .marker(Marker::Braille)
            .style(Style::new().fg(SCENE_COLOUR)),
        Dataset::default()
            .data(&pts)
            .graph_type(GraphType::Line)
            .marker(Marker::Braille)
            .style(style),
        Dataset::default()
            .data(&pts)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Dot)
            .style(style),
    ];
    let chart = Chart::new(datasets)
        .block(block)
        .legend_position(None)
        .x_axis(
            Axis::default()
                .bounds(xb)
                .labels(axis_labels(xb))
                .style(Style::new().fg(DIM)),
        )
        .y_axis(
            Axis::default()
                .bounds(yb)
                .labels(axis_labels(yb))
                .style(Style::new().fg(DIM)),
        );
    frame.render_widget(chart, area);
}
