//! The curvature profiles: `κ1`, `κ2`, `Ω` against `s/L` of one rod or all, joints marked,
//! with optional shaded intervals of `s/L` (e.g. a measured bulk).

use super::style::{range, Caption, GRID_BOLD, GRID_LIGHT, MARK};
use crate::output::chart::{
    captioned, draw_svg, palette, tick_label, DrawError, CAPTION_LINE, FONT,
};
use crate::output::legend::{self, Entry, Sample};
use crate::output::read::{RunTables, StateNode, StateTable};
use plotters::coord::Shift;
use plotters::prelude::*;

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
    let entries = curvature_entries(run, &chosen, shaded);
    let w = 820u32;
    let h = 3 * 250 + CAPTION_LINE * caption.len() as u32 + legend::height(&entries, w);
    draw_svg("curvature profiles", (w, h), |root| {
        let body = captioned(root, &title, caption)?;
        let body = legend::above(&body, &entries)?;
        let panels = body.split_evenly((3, 1));
        for (k, area) in panels.iter().enumerate() {
            curvature_panel(area, run, &chosen, k, shaded)?;
        }
        Ok(())
    })
}

/// Fill of the shaded intervals of `s/L`.
const SHADE: ShapeStyle = ShapeStyle {
    color: RGBAColor(0xff, 0xd7, 0x00, 0.25),
    filled: true,
    stroke_width: 0,
};

/// The legend the three panels share: the shaded intervals, the rods when there are
/// several, the joints when a rod has some.
fn curvature_entries(
    run: &RunTables,
    rods: &[&(usize, Vec<StateNode>)],
    shaded: &[Shade],
) -> Vec<Entry> {
    let mut entries = Vec::new();
    if let Some(s) = shaded.first() {
        entries.push(Entry::new(s.label.clone(), Sample::Band(SHADE)));
    }
    if rods.len() > 1 {
        for (i, (id, _)) in rods.iter().enumerate() {
            entries.push(Entry::new(
                format!("rod {id}"),
                Sample::Line(palette(i).stroke_width(2)),
            ));
        }
    }
    if rods
        .iter()
        .any(|(id, _)| run.joints.get(id).is_some_and(|j| !j.is_empty()))
    {
        entries.push(Entry::new("joints", Sample::Circle(MARK.filled(), 3)));
    }
    entries
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
        .x_label_formatter(&|v| tick_label(*v, 1.0))
        .y_label_formatter(&|v| tick_label(*v, y.1 - y.0))
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()
        .map_err(e)?;
    for s in shaded {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(s.from, y.0), (s.to, y.1)],
                SHADE,
            )))
            .map_err(e)?;
    }
    let single = rods.len() == 1;
    for (i, (id, nodes)) in rods.iter().enumerate() {
        let color = if single { palette(0) } else { palette(i) };
        let line = color.stroke_width(2);
        chart
            .draw_series(LineSeries::new(
                nodes.iter().map(|p| (p.s_over_l, p.curvature[k])),
                line,
            ))
            .map_err(e)?;
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
    Ok(())
}
