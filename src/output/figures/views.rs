//! The three views: the assembly seen along the three axes (X-Y, Z-Y, Z-X) at one scale,
//! rods coloured by `κ1`, with a colour bar.

use super::style::{range, Caption, GRID_BOLD, GRID_LIGHT};
use crate::output::chart::{captioned, draw_svg, tick_label, DrawError, CAPTION_LINE, FONT};
use crate::output::read::StateTable;
use plotters::coord::Shift;
use plotters::prelude::*;

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
    let cap_h = CAPTION_LINE * (1 + caption.len() as u32) + 8;
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
            let projection = Projection {
                name,
                axes: (hc, vc),
                x: widen(ext[hc], pw),
                y: widen(ext[vc], ph),
            };
            view_panel(area, state, &projection, k1, (LEFT, BOTTOM, M))?;
        }
        colour_bar(&bar, k1, (LEFT + M, M))
    })
}

/// One view of the assembly: its name, the coordinates (0 x, 1 y, 2 z) along its horizontal
/// and vertical axes, and their ranges (m).
#[derive(Clone, Copy)]
struct Projection<'a> {
    name: &'a str,
    axes: (usize, usize),
    x: (f64, f64),
    y: (f64, f64),
}

/// The rods of `state` in one `projection`, coloured by their κ1 bin of `k1` (the range,
/// 1/m); `(left, bottom, margin)` the label areas and the margin (px).
fn view_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    state: &StateTable,
    projection: &Projection,
    k1: (f64, f64),
    (left, bottom, margin): (u32, u32, u32),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let Projection {
        name,
        axes: (hc, vc),
        x,
        y,
    } = *projection;
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
        .x_label_formatter(&|v| tick_label(*v, x.1 - x.0))
        .y_label_formatter(&|v| tick_label(*v, y.1 - y.0))
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
        .x_label_formatter(&|v| tick_label(*v, k1.1 - k1.0))
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
