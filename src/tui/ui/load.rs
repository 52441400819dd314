//! The load panel: the averaged normalised tip loads along the path against the motion the
//! load parameter drives (the compression ratio, under either control), or (`o`) the
//! lowest eigenvalue of each state or the tip's sway; unstable stretches dotted, critical
//! points and the path cursor marked.

use super::chart::{
    axis_labels, first_fitting, key_span, legend_marks, line_style, nice_bounds, padded_range,
    placeholder, unstable_style, CRITICAL_MARK, CURSOR_MARK, NOW_MARK,
};
use super::colours::{DIM, FX_LINE, FY_LINE, FZ_LINE, SELECTED};
use super::numbers::{fmt_load, fmt_num};
use crate::model::loading::{Component, Control};
use crate::results::{LoadPoint, SupportResponse};
use crate::tui::app::{App, LoadSeries};
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
    let width = area.width.saturating_sub(2);
    let mut block = load_block(
        app.case().loading.parameter,
        app.view.load_series,
        stretches.iter().any(|s| s.unstable),
        app.view.no_color,
        width,
    );
    let readout = cursor_readout(app, width);
    let used = readout.as_ref().map_or(0, Line::width);
    if let Some(key) = critical_key(app, width, used) {
        block = block.title_bottom(key);
    }
    if let Some(line) = readout {
        block = block.title_bottom(line.alignment(Alignment::Right));
    }
    if path.is_empty() {
        return placeholder(frame, area, block, app);
    }
    let x = parameter_bounds(app);
    // a flat sway (the fundamental path) and flat loads read as a line at 0, not as noise
    let min_span = match app.view.load_series {
        LoadSeries::Loads | LoadSeries::Sway => 0.2,
        LoadSeries::Stability => 1e-9,
    };
    let y = nice_bounds(padded_range(
        (0..path.len()).flat_map(|k| values(app, k)).chain([0.0]),
        min_span,
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

/// The path cursor's readout for the bottom border, in `width` columns less the room the
/// critical points' key needs in its shortest form (` ×n ` and a rule).
fn cursor_readout(app: &App, width: u16) -> Option<Line<'static>> {
    let (path, c) = (&app.screen.path, app.case().loading.parameter);
    let key_room = match app.screen.critical.len() {
        0 => 0,
        n => n.to_string().len() as u16 + 4,
    };
    let k = app.view.path_cursor.filter(|&k| k < path.len())?;
    let p = &path[k];
    let (loads, fz) = match (app.view.load_series, p.support.pair(c)) {
        (LoadSeries::Stability, _) => {
            let l = values(app, k)
                .first()
                .map_or("–".to_string(), |&l| fmt_num(l));
            (format!("λmin {l}"), format!("λmin {l}"))
        }
        (LoadSeries::Sway, _) => {
            let w = values(app, k)
                .first()
                .map_or("–".to_string(), |w| format!("{w:.4}"));
            (format!("sway/a {w}"), format!("sway/a {w}"))
        }
        (LoadSeries::Loads, None) => (
            format!(
                "fx {} fy {} fz {}",
                fmt_load(p.load[0], &p.load),
                fmt_load(p.load[1], &p.load),
                fmt_load(p.load[2], &p.load)
            ),
            format!("fz {}", fmt_load(p.load[2], &p.load)),
        ),
        (LoadSeries::Loads, Some([_, (force, name)])) => {
            let both = format!("{name} {force:.5e}");
            (both.clone(), both)
        }
    };
    let motion = app.load_parameter().motion_symbol();
    let at = along(c, p);
    let step = p.step;
    Some(first_fitting(
        vec![
            Line::from(format!(
                " {CURSOR_MARK} step {step} {motion} {at:.5}: {loads} "
            )),
            Line::from(format!(" {CURSOR_MARK}{step} {motion} {at:.4} {loads} ")),
            Line::from(format!(" {CURSOR_MARK}{step} {motion} {at:.4} {fz} ")),
            Line::from(format!(" {CURSOR_MARK}{step} {motion} {at:.4} ")),
            Line::from(format!(" {CURSOR_MARK}{step} ")),
        ],
        width.saturating_sub(key_room),
    ))
}

/// The critical points' key for the bottom border, in what `used` columns of the readout
/// leave of `width`; `None` without critical points or room.
fn critical_key(app: &App, width: u16, used: usize) -> Option<Line<'static>> {
    let n = app.screen.critical.len();
    if n == 0 {
        return None;
    }
    let mark = Span::styled(format!(" {CRITICAL_MARK}"), Style::new().fg(Color::Yellow));
    let key = first_fitting(
        vec![
            Line::from(vec![
                mark.clone(),
                Span::raw(format!("critical {n} (x lists) ")),
            ]),
            Line::from(vec![mark.clone(), Span::raw(format!("critical {n} "))]),
            Line::from(vec![mark, Span::raw(format!("{n} "))]),
        ],
        width.saturating_sub(used as u16 + 1),
    );
    (key.width() + used < width as usize).then_some(key)
}

/// Where the chart places `p` with component `c` stepped: at the motion of what the load
/// parameter drives, under either control (the compression ratio for the axial load, the
/// angle of a twist or tilt, the mean radius under pressure), so that a load's curve is the
/// load against the motion it causes.
fn along(c: Component, p: &LoadPoint) -> f64 {
    p.support.pair(c).map_or(p.compression_ratio, |[m, _]| m.0)
}

/// The curves' values at point `k` of the path: with the loads shown, the averaged
/// normalised tip loads fx, fy, fz for the axial load, the conjugate force (torque, moment,
/// pressure) for the others; else the lowest eigenvalue (none where not computed) or the
/// tip's sway over the helix radius.
fn values(app: &App, k: usize) -> Vec<f64> {
    let p = &app.screen.path[k];
    match app.view.load_series {
        LoadSeries::Loads => p
            .support
            .pair(app.case().loading.parameter)
            .map_or(p.load.to_vec(), |[_, f]| vec![f.0]),
        LoadSeries::Stability => p
            .stability
            .and_then(|s| s.lowest_eigenvalue)
            .into_iter()
            .collect(),
        LoadSeries::Sway => {
            let radius = app.case().geometry.radius;
            app.screen
                .sway
                .get(k)
                .map(|w| w / radius)
                .into_iter()
                .collect()
        }
    }
}

/// How many curves the panel draws: fx, fy, fz for the axial loads, else one.
fn curves(app: &App) -> usize {
    match (app.view.load_series, app.case().loading.parameter) {
        (LoadSeries::Loads, Component::Axial) => 3,
        _ => 1,
    }
}

/// The point of the path at load parameter `lambda`, linearly between the points either
/// side: `(along, the last value)`, for a critical point's mark.
fn on_path(app: &App, lambda: f64) -> Option<(f64, f64)> {
    let (c, path) = (app.case().loading.parameter, &app.screen.path);
    let at = |k: usize| Some((along(c, &path[k]), *values(app, k).last()?));
    (1..path.len()).find_map(|k| {
        let (a, b) = (path[k - 1].parameter, path[k].parameter);
        let inside = (a <= lambda && lambda <= b) || (b <= lambda && lambda <= a);
        if !inside || a == b {
            return None;
        }
        let t = (lambda - a) / (b - a);
        let ((x0, y0), (x1, y1)) = (at(k - 1)?, at(k)?);
        Some((x0 + t * (x1 - x0), y0 + t * (y1 - y0)))
    })
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
        let c = app.case().loading.parameter;
        let path = &app.screen.path;
        let loads = |k: usize| {
            values(app, k)
                .into_iter()
                .map(|v| (along(c, &path[k]), v))
                .collect()
        };
        let axial = c == Component::Axial && app.view.load_series == LoadSeries::Loads;
        Marks {
            now: path.len().checked_sub(1).map(loads).unwrap_or_default(),
            cursor: app
                .view
                .path_cursor
                .filter(|&k| k < path.len())
                .map(loads)
                .unwrap_or_default(),
            critical: app
                .screen
                .critical
                .iter()
                .filter_map(|k| match axial {
                    true => Some((k.compression_ratio, k.load[2])),
                    false => on_path(app, k.parameter),
                })
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
                let (graph, marker, _) = unstable_style(s.no_color);
                (graph, marker)
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
            .marker(Marker::Custom(NOW_MARK))
            .style(Style::new().fg(SELECTED)),
    );
    datasets.push(
        Dataset::default()
            .data(&marks.cursor)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Custom(CURSOR_MARK))
            .style(Style::new().fg(Color::White)),
    );
    datasets.push(
        Dataset::default()
            .data(&marks.critical)
            .graph_type(GraphType::Scatter)
            .marker(Marker::Custom(CRITICAL_MARK))
            .style(Style::new().fg(Color::Yellow)),
    );
    datasets
}

/// The load panel's frame: the legend of its lines (unstable stretches once there are),
/// shortened to fit `width` columns.
fn load_block(
    c: Component,
    series: LoadSeries,
    any_unstable: bool,
    no_color: bool,
    width: u16,
) -> Block<'static> {
    let marks = legend_marks(no_color);
    let title = |short: bool| {
        let mut title = Vec::new();
        let bold = Style::new().add_modifier(Modifier::BOLD);
        match (series, SupportResponse::default().pair(c)) {
            (LoadSeries::Stability, _) => {
                let name = if short {
                    " λmin "
                } else {
                    " lowest eigenvalue λmin "
                };
                title.push(Span::styled(name, bold));
                title.extend(key_span(marks[0], "J/m", FZ_LINE));
            }
            (LoadSeries::Sway, _) => {
                let name = if short {
                    " sway/a "
                } else {
                    " tip sway / helix radius "
                };
                title.push(Span::styled(name, bold));
                title.extend(key_span(marks[0], "sway", FZ_LINE));
            }
            (LoadSeries::Loads, None) => {
                title.push(Span::styled(
                    if short {
                        " Σf/nPc "
                    } else {
                        " load Σf/(n Pcrit) "
                    },
                    Style::new().add_modifier(Modifier::BOLD),
                ));
                title.extend(key_span(marks[0], "fx", FX_LINE));
                title.extend(key_span(marks[1], "fy", FY_LINE));
                title.extend(key_span(marks[2], "fz", FZ_LINE));
            }
            (LoadSeries::Loads, Some([_, (_, name)])) => {
                title.push(Span::styled(format!(" {} {name} ", c.name()), bold));
            }
        }
        if any_unstable {
            title.extend(key_span(
                unstable_style(no_color).2.to_string(),
                "unstable",
                DIM,
            ));
        }
        title.extend(key_span(NOW_MARK.to_string(), "now", SELECTED));
        Line::from(title)
    };
    Block::new()
        .borders(Borders::ALL)
        .title(first_fitting(vec![title(false), title(true)], width))
}

/// The abscissa's range: from 0 to as far as the path went, and under displacement control
/// to the target and the request.
fn parameter_bounds(app: &App) -> [f64; 2] {
    let c = app.case().loading.parameter;
    // the target and the request are on the abscissa when the parameter is the motion itself
    let ahead = match app.load_parameter().control {
        Control::Displacement => vec![app.target(), app.screen.requested_parameter],
        Control::Force => Vec::new(),
    };
    // the abscissa starts at 0 but for the pressure's, the mean radius: from the path alone
    let origin = (c != Component::Pressure).then_some(0.0);
    let start = origin.unwrap_or(f64::INFINITY);
    let (lo, hi) = app
        .screen
        .path
        .iter()
        .map(|p| along(c, p))
        .chain(origin)
        .chain(ahead)
        .filter(|e| e.is_finite())
        .fold((start, -start), |(lo, hi), e| (lo.min(e), hi.max(e)));
    if hi > lo {
        [lo, hi]
    } else if lo.is_finite() {
        // one point: a span around it of its own size
        let half = 0.5 * lo.abs().clamp(1e-12, 0.5) * if origin.is_some() { 1.0 } else { 0.01 };
        [lo - half, hi + half]
    } else {
        [-0.5, 0.5]
    }
}

/// The panel's curves along each stretch of stable or unstable states.
fn load_series(app: &App, stretches: &[stability::Stretch]) -> Vec<Series> {
    let (path, no_color) = (&app.screen.path, app.view.no_color);
    let stepped = app.case().loading.parameter;
    let colors = match curves(app) {
        3 => vec![FX_LINE, FY_LINE, FZ_LINE],
        _ => vec![FZ_LINE],
    };
    stretches
        .iter()
        .flat_map(|s| {
            let colors = colors.clone();
            (0..colors.len()).map(move |c| Series {
                points: s
                    .points
                    .clone()
                    .filter_map(|k| Some((along(stepped, &path[k]), *values(app, k).get(c)?)))
                    .collect(),
                color: colors[c],
                unstable: s.unstable,
                component: c,
                no_color,
            })
        })
        .collect()
}
