//! Charts drawn with `plotters` into SVG text: the pieces every figure shares (the caption
//! lines, the palette, the drawing error), a chart of curves on linear axes ([`lines_svg`],
//! e.g. a finite assembly against a closed form) and the log-log work-precision chart of
//! [`crate::output::precision`] — panels side by side, decades on both axes, one line with
//! markers per series, a label beside each point, a legend.
//!
//! SVG only: the text is set by whatever shows the file, so no font is bundled or needed.

use plotters::coord::Shift;
use plotters::prelude::*;

/// Font family of every text.
pub const FONT: &str = "sans-serif";
/// Height of one caption line (px).
pub const CAPTION_LINE: u32 = 18;

/// A figure that could not be drawn (a range plotters refuses, a drawing call failing).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("drawing {figure}: {reason}")]
pub struct DrawError {
    /// The figure, e.g. `load curves`.
    pub figure: String,
    pub reason: String,
}

/// An SVG document of `size` (px) on a white ground, drawn by `draw`; its failure is a
/// [`DrawError`] of `figure`.
pub fn draw_svg(
    figure: &str,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> Result<(), String>,
) -> Result<String, DrawError> {
    let mut svg = String::new();
    let result = (|| {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        draw(&root)?;
        root.present().map_err(|e| e.to_string())
    })();
    result.map_err(|reason| DrawError {
        figure: figure.to_string(),
        reason,
    })?;
    Ok(svg)
}

/// Ten distinct colours (the "tab10" palette), for curves told apart by colour.
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
];

/// The `k`-th colour of [`PALETTE`], cycling.
pub fn palette(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// `#rrggbb` as a colour (black when it is not one).
pub fn rgb(hex: &str) -> RGBColor {
    let h = hex.trim_start_matches('#');
    let byte = |i: usize| {
        h.get(i..i + 2)
            .and_then(|b| u8::from_str_radix(b, 16).ok())
            .unwrap_or(0)
    };
    if h.len() == 6 {
        RGBColor(byte(0), byte(2), byte(4))
    } else {
        BLACK
    }
}

/// Draws `title` (bold) and `notes` as lines at the top of `root` and returns the area
/// below them.
pub fn captioned<'a>(
    root: &DrawingArea<SVGBackend<'a>, Shift>,
    title: &str,
    notes: &[String],
) -> Result<DrawingArea<SVGBackend<'a>, Shift>, String> {
    let lines = 1 + notes.len() as u32;
    let (top, rest) = root.split_vertically(CAPTION_LINE * lines + 8);
    top.draw(&Text::new(
        title.to_string(),
        (10, 4),
        (FONT, 15).into_font().style(FontStyle::Bold),
    ))
    .map_err(|e| e.to_string())?;
    for (i, n) in notes.iter().enumerate() {
        top.draw(&Text::new(
            n.clone(),
            (10, 4 + CAPTION_LINE as i32 * (i as i32 + 1)),
            (FONT, 12).into_font().color(&RGBColor(0x44, 0x44, 0x44)),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(rest)
}

/// Marker drawn at each point of a series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Style {
    /// Colour as `#rrggbb`.
    pub color: &'static str,
    pub marker: Marker,
}

/// A point of a series, in data units (both coordinates positive, or it is left out).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    /// Text beside the marker.
    pub label: String,
    /// Drawn as an outline: a value of another standing (e.g. an estimate).
    pub hollow: bool,
}

/// One line of a panel, its points joined in the order given.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<Point>,
    pub style: Style,
}

/// One log-log plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

const PANEL_W: u32 = 480;
const PANEL_H: u32 = 380;

/// Whole decades `[lo, hi]` (exponents) covering the positive finite values.
fn decades(values: impl Iterator<Item = f64>) -> Option<(i32, i32)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return None;
    }
    let (a, mut b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    if b <= a {
        b = a + 1;
    }
    Some((a, b))
}

/// A tick label of a log axis: `1e-3`, `2e-3`, …
fn log_tick(v: &f64) -> String {
    format!("{v:.0e}")
}

/// An SVG document: a title, note lines under it, then the panels side by side, each on
/// log-log axes. Points that are not positive and finite are left out; a panel without any
/// says "no data".
pub fn log_log_svg(title: &str, notes: &[String], panels: &[Panel]) -> Result<String, DrawError> {
    let width = PANEL_W * panels.len().max(1) as u32;
    let height = CAPTION_LINE * (1 + notes.len() as u32) + 8 + PANEL_H;
    draw_svg("work-precision chart", (width, height), |root| {
        let body = captioned(root, title, notes)?;
        let areas = body.split_evenly((1, panels.len().max(1)));
        for (p, area) in panels.iter().zip(&areas) {
            log_log_panel(area, p)?;
        }
        Ok(())
    })
}

fn log_log_panel(area: &DrawingArea<SVGBackend, Shift>, p: &Panel) -> Result<(), String> {
    let finite = |q: &&Point| q.x > 0.0 && q.y > 0.0 && q.x.is_finite() && q.y.is_finite();
    let points = || p.series.iter().flat_map(|s| s.points.iter()).filter(finite);
    let (Some(xd), Some(yd)) = (
        decades(points().map(|q| q.x)),
        decades(points().map(|q| q.y)),
    ) else {
        area.draw(&Text::new(
            format!("{}: no data", p.title),
            (60, PANEL_H as i32 / 2),
            (FONT, 13).into_font().color(&RGBColor(0x88, 0x88, 0x88)),
        ))
        .map_err(|e| e.to_string())?;
        return Ok(());
    };
    // a little beyond the decades, so that both end decades get their tick label
    let x = (0.8 * 10f64.powi(xd.0)..1.25 * 10f64.powi(xd.1)).log_scale();
    let y = (0.8 * 10f64.powi(yd.0)..1.25 * 10f64.powi(yd.1)).log_scale();
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .caption(&p.title, (FONT, 13).into_font().style(FontStyle::Bold))
        .x_label_area_size(44)
        .y_label_area_size(62)
        .build_cartesian_2d(x, y)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .x_label_formatter(&log_tick)
        .y_label_formatter(&log_tick)
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .light_line_style(RGBAColor(0xff, 0xff, 0xff, 0.0))
        .bold_line_style(RGBColor(0xdd, 0xdd, 0xdd))
        .draw()
        .map_err(|e| e.to_string())?;
    for series in &p.series {
        let color = rgb(series.style.color);
        let line = color.stroke_width(2);
        let pts: Vec<&Point> = series.points.iter().filter(finite).collect();
        let marker = series.style.marker;
        chart
            .draw_series(LineSeries::new(pts.iter().map(|q| (q.x, q.y)), line))
            .map_err(|e| e.to_string())?
            .label(&series.label)
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (22, 0)], line)
                    + marker_element(marker, (11, 0), 4, color, false)
            });
        for q in &pts {
            let label = Text::new(
                q.label.clone(),
                (7, -12),
                (FONT, 10).into_font().color(&color),
            );
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((q.x, q.y))
                        + marker_element(marker, (0, 0), 4, color, q.hollow)
                        + label,
                ))
                .map_err(|e| e.to_string())?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(0x99, 0x99, 0x99))
        .label_font((FONT, 11))
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// A marker centred on `at` (pixels relative to its anchor): filled, or an outline when
/// `hollow`.
fn marker_element<DB: DrawingBackend>(
    marker: Marker,
    at: (i32, i32),
    r: i32,
    color: RGBColor,
    hollow: bool,
) -> DynElement<'static, DB, (i32, i32)> {
    let style = if hollow {
        color.stroke_width(2)
    } else {
        color.filled()
    };
    match marker {
        Marker::Circle => Circle::new(at, r, style).into_dyn(),
        Marker::Square => {
            Rectangle::new([(at.0 - r, at.1 - r), (at.0 + r, at.1 + r)], style).into_dyn()
        }
    }
}

/// A curve of a [`LinePanel`]: points joined in the order given, in data units.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend text (none when empty).
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Drawn dashed (e.g. a reference or an unstable stretch) instead of solid.
    pub dashed: bool,
    /// Place in [`PALETTE`].
    pub color: usize,
}

/// One plot on linear axes: axis labels with their units, curves, and intervals of x
/// shaded behind them (with a legend text each).
#[derive(Clone, Debug, PartialEq)]
pub struct LinePanel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub curves: Vec<Curve>,
    /// `(from, to, label)` in x.
    pub shaded: Vec<(f64, f64, String)>,
}

/// An SVG document: a title, note lines under it (the case and the command), then the
/// panels side by side on linear axes — for comparisons such as a finite assembly's force
/// against a closed form. Points that are not finite are left out.
pub fn lines_svg(title: &str, notes: &[String], panels: &[LinePanel]) -> Result<String, DrawError> {
    let width = PANEL_W * panels.len().max(1) as u32;
    let height = CAPTION_LINE * (1 + notes.len() as u32) + 8 + PANEL_H;
    draw_svg(title, (width, height), |root| {
        let body = captioned(root, title, notes)?;
        let areas = body.split_evenly((1, panels.len().max(1)));
        for (p, area) in panels.iter().zip(&areas) {
            line_panel(area, p)?;
        }
        Ok(())
    })
}

/// `[lo, hi]` of the finite values with 5 % head room (a unit wide around a single value).
fn padded(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * (lo.abs() + hi.abs()) {
        return (lo - 0.5, hi + 0.5);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

fn line_panel(area: &DrawingArea<SVGBackend, Shift>, p: &LinePanel) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let finite = |q: &&(f64, f64)| q.0.is_finite() && q.1.is_finite();
    let pts = || p.curves.iter().flat_map(|c| c.points.iter()).filter(finite);
    let x = padded(pts().map(|q| q.0));
    let y = padded(pts().map(|q| q.1));
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .caption(&p.title, (FONT, 13).into_font().style(FontStyle::Bold))
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .light_line_style(RGBAColor(0xff, 0xff, 0xff, 0.0))
        .bold_line_style(RGBColor(0xdd, 0xdd, 0xdd))
        .draw()
        .map_err(e)?;
    let fill = RGBColor(0xff, 0xd7, 0x00).mix(0.25).filled();
    for (from, to, label) in &p.shaded {
        let a = chart
            .draw_series(std::iter::once(Rectangle::new(
                [(*from, y.0), (*to, y.1)],
                fill,
            )))
            .map_err(e)?;
        if !label.is_empty() {
            a.label(label.clone())
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 22, y + 5)], fill));
        }
    }
    for c in &p.curves {
        let line = palette(c.color).stroke_width(2);
        let points: Vec<(f64, f64)> = c.points.iter().filter(finite).copied().collect();
        let a = if c.dashed {
            chart
                .draw_series(DashedLineSeries::new(points, 7, 5, line))
                .map_err(e)?
        } else {
            chart
                .draw_series(LineSeries::new(points, line))
                .map_err(e)?
        };
        if c.label.is_empty() {
            continue;
        }
        let a = a.label(c.label.clone());
        if c.dashed {
            a.legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (8, 0)], line)
                    + PathElement::new(vec![(14, 0), (22, 0)], line)
            });
        } else {
            a.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], line));
        }
    }
    if p.curves.iter().any(|c| !c.label.is_empty()) || p.shaded.iter().any(|s| !s.2.is_empty()) {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(0x99, 0x99, 0x99))
            .label_font((FONT, 11))
            .draw()
            .map_err(e)?;
    }
    Ok(())
}
