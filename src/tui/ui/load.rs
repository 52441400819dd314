//! The load panel: the averaged normalised tip loads along the path against the motion the
//! load parameter drives (the compression ratio, under either control), unstable stretches
//! dotted, critical points and the path cursor marked.

use super::chart::{
    axis_labels, key_span, legend_marks, line_style, nice_bounds, padded_range, placeholder,
};
use super::colours::{DIM, FX_LINE, FY_LINE, FZ_LINE, SELECTED};
use super::numbers::fmt_load;
use crate::model::loading::Control;
use crate::results::LoadPoint;
use crate::tui::app::App;
use crate::tui::stability;
use ratatui::layout::{Alignment, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType};
use ratatui::Frame;

/// One load component along one stretch of the path.
struct Series {
    points: Vec<(f64, f64)>,
    color: Color,
    unstable: bool,
    component: usize,
    no_color: bool,
}

/// The load path so far: averaged normalised fx, fy, fz against the motion, the
/// current point as a block, unstable stretches dotted.
pub(super) fn draw_load_path(frame: &mut Frame, area: Rect, app: &App) {
    let path = &app.screen.path;
    let stretches = stability::stretches(path.len(), |k| stability::is_unstable(&path[k]));
    let mut block = load_block(stretches.iter().any(|s| s.unstable), app.view.no_color);
    if !app.screen.critical.is_empty() {
        block = block.title_bottom(Line::from(vec![
            Span::styled(" ×", Style::new().fg(Color::Yellow)),
            Span::raw(format!("critical {} (x lists) ", app.screen.critical.len())),
        ]));
    }
    if let Some(p) = app.view.path_cursor.and_then(|k| path.get(k)) {
        block = block.title_bottom(
            Line::from(format!(
                " ◆ step {} {} {:.5}: fx {} fy {} fz {} ",
                p.step,
                app.load_parameter().motion_symbol(),
                along(p),
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
    let x = parameter_bounds(app);
    let y = nice_bounds(padded_range(
        path.iter().flat_map(|p| p.load).chain([0.0]),
        0.2,
    ));
    let series = load_series(app, &stretches);
    let marks = Marks::of(app);
    let chart = Chart::new(datasets(&series, &marks))
        .block(block)
        .legend_position(None)
        .x_axis(
            Axis::default()
                .title(app.load_parameter().motion_symbol())
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

/// Where the chart places `p`: at the motion of what the load parameter drives, under
/// either control (the compression ratio for the axial load), so that a dead load's curve is
/// its load against the motion it causes.
fn along(p: &LoadPoint) -> f64 {
    p.compression_ratio
}

/// The points marked over the curves: the state on screen, the path cursor's loads, the
/// critical points' fz.
struct Marks {
    now: Vec<(f64, f64)>,
    cursor: Vec<(f64, f64)>,
    critical: Vec<(f64, f64)>,
}

impl Marks {
    fn of(app: &App) -> Marks {
        let loads = |p: &LoadPoint| (0..3).map(|c| (along(p), p.load[c])).collect();
        Marks {
            now: app
                .screen
                .state
                .as_ref()
                .map(|s| loads(&s.point))
                .unwrap_or_default(),
            cursor: app
                .view
                .path_cursor
                .and_then(|k| app.screen.path.get(k))
                .map(loads)
                .unwrap_or_default(),
            critical: app
                .screen
                .critical
                .iter()
                .map(|c| (c.compression_ratio, c.load[2]))
                .collect(),
        }
    }
}

/// The curves, then the marks over them.
fn datasets<'a>(series: &'a [Series], marks: &'a Marks) -> Vec<Dataset<'a>> {
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
            .data(&marks.now)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Block)
            .style(Style::new().fg(SELECTED)),
    );
    datasets.push(
        Dataset::default()
            .data(&marks.cursor)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Bar)
            .style(Style::new().fg(Color::White)),
    );
    datasets.push(
        Dataset::default()
            .data(&marks.critical)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Block)
            .style(Style::new().fg(Color::Yellow)),
    );
    datasets
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

/// The abscissa's range: from 0 to as far as the path went, and under displacement control
/// to the target and the request.
fn parameter_bounds(app: &App) -> [f64; 2] {
    // the target and the request are on the abscissa when the parameter is the motion itself
    let ahead = match app.load_parameter().control {
        Control::Displacement => vec![app.target(), app.screen.requested_parameter],
        Control::Force => Vec::new(),
    };
    let (lo, hi) = app
        .screen
        .path
        .iter()
        .map(along)
        .chain([0.0])
        .chain(ahead)
        .filter(|e| e.is_finite())
        .fold((0.0f64, 0.0f64), |(lo, hi), e| (lo.min(e), hi.max(e)));
    if hi > lo {
        [lo, hi]
    } else {
        [lo - 0.5, hi + 0.5]
    }
}

/// fx, fy, fz along each stretch of stable or unstable states.
fn load_series(app: &App, stretches: &[stability::Stretch]) -> Vec<Series> {
    let (path, no_color) = (&app.screen.path, app.view.no_color);
    let colors = [FX_LINE, FY_LINE, FZ_LINE];
    stretches
        .iter()
        .flat_map(|s| {
            (0..3).map(move |c| Series {
                points: path[s.points.clone()]
                    .iter()
                    .map(|p: &LoadPoint| (along(p), p.load[c]))
                    .collect(),
                color: colors[c],
                unstable: s.unstable,
                component: c,
                no_color,
            })
        })
        .collect()
}
