//! Charts drawn with `plotters` into SVG text: the pieces every figure shares (the caption
//! lines, the palette, the drawing error), a chart of curves on linear axes ([`lines_svg`],
//! e.g. a finite assembly against a closed form) and the log-log work-precision chart of
//! [`crate::output::precision`] — panels side by side, decades on both axes, one line with
//! markers per series, a label beside each point, a legend.
//!
//! SVG only: the text is set by whatever shows the file, so no font is bundled or needed.

use super::legend::{self, Entry, Sample};
use plotters::coord::Shift;
use plotters::prelude::*;

pub use super::legend::FONT;
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
/// below them. A line too long for the width is set smaller, so that it fits.
pub fn captioned<'a>(
    root: &DrawingArea<SVGBackend<'a>, Shift>,
    title: &str,
    notes: &[String],
) -> Result<DrawingArea<SVGBackend<'a>, Shift>, String> {
    let lines = 1 + notes.len() as u32;
    let (width, _) = root.dim_in_pixel();
    let (top, rest) = root.split_vertically(CAPTION_LINE * lines + 8);
    // bold text is about a tenth wider
    let size = fitting_size(title, 15, width, 1.1);
    top.draw(&Text::new(
        title.to_string(),
        (10, 4),
        (FONT, size).into_font().style(FontStyle::Bold),
    ))
    .map_err(|e| e.to_string())?;
    for (i, n) in notes.iter().enumerate() {
        let size = fitting_size(n, 12, width, 1.0);
        top.draw(&Text::new(
            n.clone(),
            (10, 4 + CAPTION_LINE as i32 * (i as i32 + 1)),
            (FONT, size).into_font().color(&RGBColor(0x44, 0x44, 0x44)),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(rest)
}

/// The font size (px, at most `size`, at least 7) at which `text` fits in `width` px
/// less the margins, `wider` the factor of the font's weight.
pub fn fitting_size(text: &str, size: u32, width: u32, wider: f64) -> u32 {
    let room = width.saturating_sub(20) as f64;
    let at = |s: u32| super::legend::text_width(text, s) as f64 * wider;
    (7..=size).rev().find(|&s| at(s) <= room).unwrap_or(7)
}

/// A tick label of a linear axis spanning `span`: as many decimals as the ticks' spacing
/// needs (about a tenth of the span), trailing zeros left out, and zero never signed (a
/// tick at `-1e-17` is `0`, not `-0.0`). Values beyond 1e5 or spacings below 1e-5 are
/// written in scientific notation.
pub fn tick_label(v: f64, span: f64) -> String {
    let step = (span / 10.0).abs();
    let zero = |s: String| {
        if s.parse::<f64>() == Ok(0.0) {
            "0".to_string()
        } else {
            s
        }
    };
    if !(step.is_finite() && step > 0.0 && v.is_finite()) {
        return zero(format!("{v}"));
    }
    if v.abs() >= 1e5 || step < 1e-5 {
        if v.abs() < step * 1e-6 {
            return "0".to_string();
        }
        return format!("{v:.2e}").replace(".00e", "e").replace("0e", "e");
    }
    let decimals = ((-step.log10()).ceil().max(0.0) as usize + 1).min(8);
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    zero(s)
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

/// The legend entries of the series of `panels`, each label once (panels share their
/// series).
fn series_entries(panels: &[Panel]) -> Vec<Entry> {
    let mut entries: Vec<Entry> = Vec::new();
    for series in panels.iter().flat_map(|p| &p.series) {
        if series.label.is_empty() || entries.iter().any(|e| e.label == series.label) {
            continue;
        }
        let color = rgb(series.style.color);
        let sample = match series.style.marker {
            Marker::Circle => Sample::LineCircle(color.stroke_width(2), color.filled(), 4),
            Marker::Square => Sample::LineSquare(color.stroke_width(2), color.filled(), 4),
        };
        entries.push(Entry::new(series.label.clone(), sample));
    }
    entries
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
    let entries = series_entries(panels);
    let height =
        CAPTION_LINE * (1 + notes.len() as u32) + 8 + legend::height(&entries, width) + PANEL_H;
    draw_svg("work-precision chart", (width, height), |root| {
        let body = captioned(root, title, notes)?;
        let body = legend::above(&body, &entries)?;
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
            .map_err(|e| e.to_string())?;
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
    /// A dot at every point (a curve of few points, such as a sweep's).
    pub marked: bool,
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
    let entries = curve_entries(panels);
    let height =
        CAPTION_LINE * (1 + notes.len() as u32) + 8 + legend::height(&entries, width) + PANEL_H;
    draw_svg(title, (width, height), |root| {
        let body = captioned(root, title, notes)?;
        let body = legend::above(&body, &entries)?;
        let areas = body.split_evenly((1, panels.len().max(1)));
        for (p, area) in panels.iter().zip(&areas) {
            line_panel(area, p)?;
        }
        Ok(())
    })
}

/// The legend entries of the curves and shaded intervals of `panels`, each label once.
fn curve_entries(panels: &[LinePanel]) -> Vec<Entry> {
    let mut entries: Vec<Entry> = Vec::new();
    let mut add = |label: &str, sample: Sample| {
        if !label.is_empty() && !entries.iter().any(|e| e.label == label) {
            entries.push(Entry::new(label, sample));
        }
    };
    for p in panels {
        for (_, _, label) in &p.shaded {
            add(label, Sample::Band(SHADE.mix(0.25).filled()));
        }
        for c in &p.curves {
            let line = palette(c.color).stroke_width(2);
            let dot = palette(c.color).filled();
            add(
                &c.label,
                match (c.dashed, c.marked) {
                    (true, _) => Sample::Dashed(line),
                    (false, true) => Sample::LineCircle(line, dot, 3),
                    (false, false) => Sample::Line(line),
                },
            );
        }
    }
    entries
}

/// Colour of shaded intervals.
const SHADE: RGBColor = RGBColor(0xff, 0xd7, 0x00);

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
        .x_label_formatter(&|v| tick_label(*v, x.1 - x.0))
        .y_label_formatter(&|v| tick_label(*v, y.1 - y.0))
        .axis_desc_style((FONT, 13))
        .label_style((FONT, 11))
        .light_line_style(RGBAColor(0xff, 0xff, 0xff, 0.0))
        .bold_line_style(RGBColor(0xdd, 0xdd, 0xdd))
        .draw()
        .map_err(e)?;
    let fill = SHADE.mix(0.25).filled();
    for (from, to, _) in &p.shaded {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(*from, y.0), (*to, y.1)],
                fill,
            )))
            .map_err(e)?;
    }
    for c in &p.curves {
        let line = palette(c.color).stroke_width(2);
        let points: Vec<(f64, f64)> = c.points.iter().filter(finite).copied().collect();
        if c.marked {
            let dot = palette(c.color).filled();
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, dot)))
                .map_err(e)?;
        }
        if c.dashed {
            chart
                .draw_series(DashedLineSeries::new(points, 7, 5, line))
                .map_err(e)?;
        } else {
            chart
                .draw_series(LineSeries::new(points, line))
                .map_err(e)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_have_the_decimals_of_their_spacing_and_no_signed_zero() {
        assert_eq!(tick_label(-1e-17, 0.85), "0");
        assert_eq!(tick_label(-0.0, 0.85), "0");
        assert_eq!(tick_label(0.05, 0.85), "0.05");
        assert_eq!(tick_label(0.1, 0.85), "0.1");
        assert_eq!(tick_label(-0.35, 0.85), "-0.35");
        assert_eq!(tick_label(-4.5, 5.2), "-4.5");
        assert_eq!(tick_label(20.0, 120.0), "20");
        assert_eq!(tick_label(1.5e-6, 1e-5), "1.5e-6");
        assert_eq!(tick_label(-1e-22, 1e-5), "0");
        assert_eq!(tick_label(2.0e5, 1e6), "2e5");
    }

    #[test]
    fn a_long_line_is_set_smaller_to_fit() {
        let long = "x".repeat(300);
        assert!(fitting_size(&long, 15, 480, 1.1) < 15);
        assert_eq!(fitting_size("short", 15, 480, 1.1), 15);
    }
}
