//! Hand-written SVG charts on log-log axes (the work-precision chart of
//! [`crate::output::precision`]): panels side by side, decade ticks labelled `10^k` with minor ticks
//! at 2..9, one polyline with markers per series, a legend, a title and notes.

use std::fmt::Write as _;

/// Marker drawn at each point of a series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Style {
    /// SVG colour, e.g. `#1f77b4`.
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

const PANEL_W: f64 = 480.0;
const PANEL_H: f64 = 380.0;
/// Plot area inside a panel: margins left, right, top, bottom.
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 34.0;
const BOTTOM: f64 = 52.0;
const HEADER_LINE: f64 = 18.0;

/// Escapes text for SVG.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

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

/// `10^k` as SVG text content, the exponent raised.
fn power_of_ten(k: i32) -> String {
    let exp = if k < 0 {
        format!("\u{2212}{}", -k)
    } else {
        k.to_string()
    };
    format!("10<tspan dy=\"-6\" font-size=\"9\">{exp}</tspan>")
}

/// An SVG document: a title, note lines under it, then the panels side by side.
pub fn log_log_svg(title: &str, notes: &[String], panels: &[Panel]) -> String {
    let header = HEADER_LINE * (1 + notes.len()) as f64 + 10.0;
    let width = PANEL_W * panels.len().max(1) as f64;
    let height = header + PANEL_H;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\" font-family=\"sans-serif\" font-size=\"11\">"
    );
    let _ = writeln!(s, "<title>{}</title>", escape(title));
    let _ = writeln!(
        s,
        "<rect x=\"0\" y=\"0\" width=\"{width}\" height=\"{height}\" fill=\"white\"/>"
    );
    let _ = writeln!(
        s,
        "<text class=\"title\" x=\"10\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{}</text>",
        HEADER_LINE,
        escape(title)
    );
    for (i, n) in notes.iter().enumerate() {
        let _ = writeln!(
            s,
            "<text class=\"note\" x=\"10\" y=\"{}\" fill=\"#444\">{}</text>",
            HEADER_LINE * (i + 2) as f64,
            escape(n)
        );
    }
    for (i, p) in panels.iter().enumerate() {
        panel(&mut s, p, PANEL_W * i as f64, header);
    }
    s.push_str("</svg>\n");
    s
}

fn panel(s: &mut String, p: &Panel, x0: f64, y0: f64) {
    let (px, py) = (x0 + LEFT, y0 + TOP);
    let (pw, ph) = (PANEL_W - LEFT - RIGHT, PANEL_H - TOP - BOTTOM);
    let _ = writeln!(s, "<g class=\"panel\">");
    let _ = writeln!(
        s,
        "<text class=\"panel-title\" x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-weight=\"bold\">{}</text>",
        px + pw / 2.0,
        y0 + 16.0,
        escape(&p.title)
    );
    let points = || p.series.iter().flat_map(|s| s.points.iter());
    let (Some(xd), Some(yd)) = (
        decades(points().map(|q| q.x)),
        decades(points().map(|q| q.y)),
    ) else {
        let _ = writeln!(
            s,
            "<rect x=\"{px}\" y=\"{py}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"black\"/>"
        );
        let _ = writeln!(
            s,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"#888\">no data</text>",
            px + pw / 2.0,
            py + ph / 2.0
        );
        s.push_str("</g>\n");
        return;
    };
    let map_x = |x: f64| px + (x.log10() - xd.0 as f64) / (xd.1 - xd.0) as f64 * pw;
    let map_y = |y: f64| py + ph - (y.log10() - yd.0 as f64) / (yd.1 - yd.0) as f64 * ph;
    // grid and ticks
    let _ = writeln!(s, "<g class=\"axes\" stroke=\"black\">");
    for k in xd.0..=xd.1 {
        let x = map_x(10f64.powi(k));
        let _ = writeln!(
            s,
            "<line x1=\"{x:.2}\" y1=\"{py}\" x2=\"{x:.2}\" y2=\"{}\" stroke=\"#ddd\"/>",
            py + ph
        );
        let _ = writeln!(
            s,
            "<line x1=\"{x:.2}\" y1=\"{}\" x2=\"{x:.2}\" y2=\"{}\"/>",
            py + ph,
            py + ph + 6.0
        );
        if k < xd.1 {
            for m in 2..10 {
                let xm = map_x(m as f64 * 10f64.powi(k));
                let _ = writeln!(
                    s,
                    "<line x1=\"{xm:.2}\" y1=\"{}\" x2=\"{xm:.2}\" y2=\"{}\"/>",
                    py + ph,
                    py + ph + 3.0
                );
            }
        }
    }
    for k in yd.0..=yd.1 {
        let y = map_y(10f64.powi(k));
        let _ = writeln!(
            s,
            "<line x1=\"{px}\" y1=\"{y:.2}\" x2=\"{}\" y2=\"{y:.2}\" stroke=\"#ddd\"/>",
            px + pw
        );
        let _ = writeln!(
            s,
            "<line x1=\"{}\" y1=\"{y:.2}\" x2=\"{px}\" y2=\"{y:.2}\"/>",
            px - 6.0
        );
        if k < yd.1 {
            for m in 2..10 {
                let ym = map_y(m as f64 * 10f64.powi(k));
                let _ = writeln!(
                    s,
                    "<line x1=\"{}\" y1=\"{ym:.2}\" x2=\"{px}\" y2=\"{ym:.2}\"/>",
                    px - 3.0
                );
            }
        }
    }
    let _ = writeln!(
        s,
        "<rect x=\"{px}\" y=\"{py}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\"/>"
    );
    s.push_str("</g>\n");
    for k in xd.0..=xd.1 {
        let _ = writeln!(
            s,
            "<text class=\"tick\" x=\"{:.2}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
            map_x(10f64.powi(k)),
            py + ph + 20.0,
            power_of_ten(k)
        );
    }
    for k in yd.0..=yd.1 {
        let _ = writeln!(
            s,
            "<text class=\"tick\" x=\"{}\" y=\"{:.2}\" text-anchor=\"end\">{}</text>",
            px - 9.0,
            map_y(10f64.powi(k)) + 4.0,
            power_of_ten(k)
        );
    }
    let _ = writeln!(
        s,
        "<text class=\"axis-label\" x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
        px + pw / 2.0,
        py + ph + 40.0,
        escape(&p.x_label)
    );
    let (lx, ly) = (x0 + 16.0, py + ph / 2.0);
    let _ = writeln!(
        s,
        "<text class=\"axis-label\" x=\"{lx}\" y=\"{ly}\" text-anchor=\"middle\" transform=\"rotate(-90 {lx} {ly})\">{}</text>",
        escape(&p.y_label)
    );
    // the series
    for series in &p.series {
        let pts: Vec<(f64, f64, &Point)> = series
            .points
            .iter()
            .filter(|q| q.x > 0.0 && q.y > 0.0 && q.x.is_finite() && q.y.is_finite())
            .map(|q| (map_x(q.x), map_y(q.y), q))
            .collect();
        let color = series.style.color;
        let _ = writeln!(
            s,
            "<g class=\"series\" data-label=\"{}\">",
            escape(&series.label)
        );
        let coords: Vec<String> = pts
            .iter()
            .map(|(x, y, _)| format!("{x:.2},{y:.2}"))
            .collect();
        let _ = writeln!(
            s,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{color}\" stroke-width=\"1.8\"/>",
            coords.join(" ")
        );
        for (x, y, q) in &pts {
            marker(s, series.style, *x, *y, 4.0, q.hollow);
            let _ = writeln!(
                s,
                "<text class=\"point-label\" x=\"{:.2}\" y=\"{:.2}\" font-size=\"9\" fill=\"{color}\">{}</text>",
                x + 6.0,
                y - 5.0,
                escape(&q.label)
            );
        }
        s.push_str("</g>\n");
    }
    // legend in the corner of the plot that hides least of the lines (tried in the order
    // bottom left, top right, bottom right, top left: work-precision lines run from the top
    // left, cheap and inaccurate, to the bottom right)
    let drawn: Vec<Vec<(f64, f64)>> = p
        .series
        .iter()
        .map(|series| {
            series
                .points
                .iter()
                .filter(|q| q.x > 0.0 && q.y > 0.0 && q.x.is_finite() && q.y.is_finite())
                .map(|q| (map_x(q.x), map_y(q.y)))
                .collect()
        })
        .collect();
    let widest = p
        .series
        .iter()
        .map(|s| s.label.chars().count())
        .max()
        .unwrap_or(0) as f64;
    let lw = 36.0 + 6.2 * widest;
    let lh = 8.0 + 16.0 * p.series.len() as f64;
    let corners = [
        (px + 6.0, py + ph - lh - 6.0),
        (px + pw - lw - 6.0, py + 6.0),
        (px + pw - lw - 6.0, py + ph - lh - 6.0),
        (px + 6.0, py + 6.0),
    ];
    let (lx, ly) = corners
        .into_iter()
        .min_by_key(|&(x, y)| covered(&drawn, x - 4.0, y - 4.0, lw + 8.0, lh + 8.0))
        .expect("four corners");
    let _ = writeln!(s, "<g class=\"legend\">");
    let _ = writeln!(
        s,
        "<rect x=\"{lx:.2}\" y=\"{ly:.2}\" width=\"{lw:.2}\" height=\"{lh:.2}\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#999\"/>"
    );
    for (i, series) in p.series.iter().enumerate() {
        let y = ly + 14.0 + 16.0 * i as f64;
        let _ = writeln!(
            s,
            "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{}\" stroke-width=\"1.8\"/>",
            lx + 6.0,
            y - 4.0,
            lx + 28.0,
            y - 4.0,
            series.style.color
        );
        marker(s, series.style, lx + 17.0, y - 4.0, 3.5, false);
        let _ = writeln!(
            s,
            "<text x=\"{:.2}\" y=\"{y:.2}\">{}</text>",
            lx + 33.0,
            escape(&series.label)
        );
    }
    s.push_str("</g>\n</g>\n");
}

/// How much of the polylines `lines` lies in the rectangle `(x, y, w, h)`: the number of
/// samples (20 per segment, and the vertices) inside it.
fn covered(lines: &[Vec<(f64, f64)>], x: f64, y: f64, w: f64, h: f64) -> usize {
    let inside = |(a, b): (f64, f64)| a >= x && a <= x + w && b >= y && b <= y + h;
    lines
        .iter()
        .map(|l| {
            let vertices = l.iter().filter(|&&q| inside(q)).count();
            let along: usize = l
                .windows(2)
                .map(|w2| {
                    (1..20)
                        .filter(|&k| {
                            let t = k as f64 / 20.0;
                            inside((
                                w2[0].0 + t * (w2[1].0 - w2[0].0),
                                w2[0].1 + t * (w2[1].1 - w2[0].1),
                            ))
                        })
                        .count()
                })
                .sum();
            // a marker and its label weigh more than a stretch of line
            5 * vertices + along
        })
        .sum()
}

fn marker(s: &mut String, style: Style, x: f64, y: f64, r: f64, hollow: bool) {
    let color = style.color;
    let paint = if hollow {
        format!("fill=\"white\" stroke=\"{color}\" stroke-width=\"1.5\"")
    } else {
        format!("fill=\"{color}\"")
    };
    let _ = match style.marker {
        Marker::Circle => writeln!(s, "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"{r}\" {paint}/>"),
        Marker::Square => writeln!(
            s,
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{}\" height=\"{}\" {paint}/>",
            x - r,
            y - r,
            2.0 * r,
            2.0 * r
        ),
    };
}
