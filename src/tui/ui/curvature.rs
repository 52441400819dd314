//! The curvature panel: κ1, κ2, Ω of the selected rod against s/L, with the joints, the
//! bulk and a cursor that reads the values.

use super::chart::{
    axis_labels, first_fitting, key_span, legend_marks, line_style, nice_bounds, padded_range,
    placeholder,
};
use super::colours::{BULK, DIM, JOINT, K1_LINE, K2_LINE, OMEGA_LINE};
use super::numbers::{fmt_short, largest};
use crate::results::{NodeState, RodShape};
use crate::tui::app::{App, CURSOR_STEPS};
use ratatui::layout::{Alignment, Rect};
use ratatui::style::{Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType};
use ratatui::Frame;

/// κ1, κ2, Ω of the selected rod against s/L, joints marked by ticks along the bottom.
pub(super) fn draw_curvature(frame: &mut Frame, area: Rect, app: &App) {
    let state = app.screen.state.as_ref();
    let rod = state.and_then(|s| s.snapshot.rods.get(app.view.selected_rod));
    let bulk = state.and_then(|s| s.bulk.rods.get(app.view.selected_rod));
    let width = area.width.saturating_sub(2);
    let block = curvature_block(rod, app.view.no_color, bulk.is_some(), width);
    let Some(rod) = rod else {
        return placeholder(frame, area, block, app);
    };
    let at = app.view.cursor as f64 / CURSOR_STEPS as f64;
    let curves = Curves::of(rod, bulk.map(|b| [b.start_over_l(), b.end_over_l()]), at);
    let values = curvature_at(&rod.nodes, at);
    // the cursor's readout, the unit then the spaces given up where it does not fit
    let big = largest(&values);
    let [k1, k2, omega] = values.map(|v| fmt_short(v, big));
    let block = block.title_bottom(
        first_fitting(
            vec![
                Line::from(format!(" s/L {at:.2} κ1 {k1} κ2 {k2} Ω {omega} 1/m ")),
                Line::from(format!(" s/L {at:.2} κ1 {k1} κ2 {k2} Ω {omega} ")),
                Line::from(format!("s/L {at:.2}:{k1} {k2} {omega}")),
            ],
            width,
        )
        .alignment(Alignment::Right),
    );
    let y = curves.y;
    let chart = Chart::new(curves.datasets(app.view.no_color))
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

/// What the curvature plot draws of a rod: its three curves, the joint ticks in a band
/// below them, the bulk's bar in a band above, the cursor, and the vertical bounds.
struct Curves {
    /// κ1, κ2, Ω against s/L.
    series: [Vec<(f64, f64)>; 3],
    ticks: Vec<[(f64, f64); 2]>,
    bulk_bar: Vec<(f64, f64)>,
    cursor: [(f64, f64); 2],
    y: [f64; 2],
}

impl Curves {
    /// The curves of `rod`, with its bulk from `bulk[0]` to `bulk[1]` (s/L) when it has
    /// one, and the cursor at `s/L = at`.
    fn of(rod: &RodShape, bulk: Option<[f64; 2]>, at: f64) -> Curves {
        let series: [Vec<(f64, f64)>; 3] = std::array::from_fn(|c| {
            rod.nodes
                .iter()
                .map(|n| (n.s_over_l, n.curvature[c]))
                .collect()
        });
        let y = padded_range(series.iter().flatten().map(|p| p.1), 1.0);
        // a band below the curves for the joint ticks, and one above for the bulk
        let tick = 0.08 * (y[1] - y[0]);
        let y = nice_bounds([
            if rod.joints.is_empty() {
                y[0]
            } else {
                y[0] - tick
            },
            if bulk.is_some() { y[1] + tick } else { y[1] },
        ]);
        let top = y[1] - 0.25 * tick;
        Curves {
            ticks: joint_ticks(rod, y[0], tick),
            bulk_bar: bulk
                .map(|[start, end]| vec![(start, top), (end, top)])
                .unwrap_or_default(),
            cursor: [(at, y[0]), (at, y[1])],
            series,
            y,
        }
    }

    /// The ticks, the curves, the bulk's bar over them (so that a curve in the top band
    /// does not hide it), the cursor.
    fn datasets(&self, no_color: bool) -> Vec<Dataset<'_>> {
        let mut datasets: Vec<Dataset> = self
            .ticks
            .iter()
            .map(|t| {
                Dataset::default()
                    .data(t)
                    .graph_type(GraphType::Line)
                    .marker(Marker::Braille)
                    .style(Style::new().fg(JOINT))
            })
            .collect();
        for (c, (data, color)) in self
            .series
            .iter()
            .zip([K1_LINE, K2_LINE, OMEGA_LINE])
            .enumerate()
        {
            let (graph, marker) = line_style(no_color, c);
            datasets.push(
                Dataset::default()
                    .data(data)
                    .graph_type(graph)
                    .marker(marker)
                    .style(Style::new().fg(color)),
            );
        }
        if !self.bulk_bar.is_empty() {
            datasets.push(
                Dataset::default()
                    .data(&self.bulk_bar)
                    .graph_type(GraphType::Line)
                    .marker(Marker::Bar)
                    .style(Style::new().fg(BULK)),
            );
        }
        datasets.push(
            Dataset::default()
                .data(&self.cursor)
                .graph_type(GraphType::Line)
                .marker(Marker::Braille)
                .style(Style::new().fg(DIM)),
        );
        datasets
    }
}

/// The curvature panel's frame: the rod and the legend of its lines, shortened to fit
/// `width` columns (the rod's chirality is in the Z-Y view's legend too).
fn curvature_block(
    rod: Option<&RodShape>,
    no_color: bool,
    bulk: bool,
    width: u16,
) -> Block<'static> {
    let marks = legend_marks(no_color);
    let title = |short: bool| {
        let name = match rod {
            Some(r) if short => format!(" rod {} ", r.rod),
            Some(r) => format!(" rod {} ({}) ", r.rod, r.chirality.name()),
            None => " curvature ".to_string(),
        };
        let mut title = vec![Span::styled(
            name,
            Style::new().add_modifier(Modifier::BOLD),
        )];
        title.extend(key_span(marks[0], "κ1", K1_LINE));
        title.extend(key_span(marks[1], "κ2", K2_LINE));
        title.extend(key_span(marks[2], "Ω", OMEGA_LINE));
        if rod.is_some_and(|r| !r.joints.is_empty()) {
            title.extend(key_span("╷", "joints", JOINT));
        }
        if bulk {
            title.extend(key_span("▄", "bulk", BULK));
        }
        Line::from(title)
    };
    Block::new()
        .borders(Borders::ALL)
        .title(first_fitting(vec![title(false), title(true)], width))
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
