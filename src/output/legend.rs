//! The legend of a figure, drawn once and outside the data: a framed strip of entries in
//! rows above the panels, each a sample of how its series is drawn and its text. Figures
//! whose panels share their series get one legend, and no legend covers a curve.

use plotters::coord::Shift;
use plotters::prelude::*;

/// Font family of every text of the figures.
pub const FONT: &str = "sans-serif";

/// How an entry's series is drawn, as its sample shows it.
#[derive(Clone, Copy, Debug)]
pub enum Sample {
    /// A solid line.
    Line(ShapeStyle),
    /// A dashed line.
    Dashed(ShapeStyle),
    /// A circle of radius `r` (px).
    Circle(ShapeStyle, i32),
    /// A square of half side `r` (px).
    Square(ShapeStyle, i32),
    /// A line with a circle of radius `r` on it.
    LineCircle(ShapeStyle, ShapeStyle, i32),
    /// A line with a square of half side `r` on it.
    LineSquare(ShapeStyle, ShapeStyle, i32),
    /// A shaded band.
    Band(ShapeStyle),
}

/// One entry: its sample and its text.
#[derive(Clone, Debug)]
pub struct Entry {
    pub label: String,
    pub sample: Sample,
}

impl Entry {
    pub fn new(label: impl Into<String>, sample: Sample) -> Entry {
        Entry {
            label: label.into(),
            sample,
        }
    }
}

/// Colour of the legend's frame (the tests find the legend by it).
pub const FRAME: RGBColor = RGBColor(0x99, 0x99, 0x99);
/// Font size of the entries (px).
const SIZE: u32 = 11;
/// Height of a row of entries (px).
const ROW: u32 = 18;
/// Width of a sample (px) and the gaps around it.
const SAMPLE_W: u32 = 22;
const GAP: u32 = 8;
const SPACING: u32 = 18;
/// Inset of the frame from the strip's left edge, and of the entries from the frame.
const INSET: u32 = 10;
const PAD: u32 = 6;

/// The width (px) a text of `SIZE` px takes, estimated generously for a sans-serif font
/// (the viewer sets the text).
pub fn text_width(text: &str, size: u32) -> u32 {
    let em: f64 = text
        .chars()
        .map(|c| match c {
            'i' | 'j' | 'l' | '.' | ',' | ':' | ';' | '\'' | '|' | '!' | ' ' | '(' | ')' => 0.32,
            'm' | 'w' | 'M' | 'W' => 0.9,
            c if c.is_uppercase() => 0.7,
            _ => 0.58,
        })
        .sum();
    (em * size as f64).ceil() as u32
}

/// The width of an entry (px).
fn entry_width(e: &Entry) -> u32 {
    SAMPLE_W + GAP + text_width(&e.label, SIZE)
}

/// The entries in rows that fit in `width` px: the index ranges of each row.
fn rows(entries: &[Entry], width: u32) -> Vec<std::ops::Range<usize>> {
    let room = width.saturating_sub(2 * INSET + 2 * PAD).max(1);
    let mut out = Vec::new();
    let (mut start, mut used) = (0, 0);
    for (i, e) in entries.iter().enumerate() {
        let w = entry_width(e);
        if i > start && used + SPACING + w > room {
            out.push(start..i);
            start = i;
            used = 0;
        }
        used += if i == start { w } else { SPACING + w };
    }
    if start < entries.len() {
        out.push(start..entries.len());
    }
    out
}

/// The height (px) of the strip [`draw`] needs for `entries` across `width` px (0 without
/// entries).
pub fn height(entries: &[Entry], width: u32) -> u32 {
    if entries.is_empty() {
        return 0;
    }
    rows(entries, width).len() as u32 * ROW + 2 * PAD + 6
}

/// Draws the legend of `entries` on `strip` (of [`height`]): a white box framed in
/// [`FRAME`], the entries in rows.
pub fn draw(strip: &DrawingArea<SVGBackend, Shift>, entries: &[Entry]) -> Result<(), String> {
    if entries.is_empty() {
        return Ok(());
    }
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let (width, _) = strip.dim_in_pixel();
    let rows = rows(entries, width);
    let row_width = |r: &std::ops::Range<usize>| -> u32 {
        entries[r.clone()].iter().map(entry_width).sum::<u32>()
            + SPACING * (r.len() as u32).saturating_sub(1)
    };
    let inner = rows.iter().map(row_width).max().unwrap_or(0);
    let (x0, y0) = (INSET as i32, 2);
    let (x1, y1) = (
        x0 + (inner + 2 * PAD) as i32,
        y0 + (rows.len() as u32 * ROW + 2 * PAD) as i32,
    );
    strip
        .draw(&Rectangle::new([(x0, y0), (x1, y1)], WHITE.filled()))
        .map_err(e)?;
    strip
        .draw(&Rectangle::new([(x0, y0), (x1, y1)], FRAME.stroke_width(1)))
        .map_err(e)?;
    for (k, r) in rows.iter().enumerate() {
        let mut x = x0 + PAD as i32;
        let y = y0 + PAD as i32 + (k as u32 * ROW + ROW / 2) as i32;
        for entry in &entries[r.clone()] {
            sample(strip, entry.sample, (x, y))?;
            strip
                .draw(&Text::new(
                    entry.label.clone(),
                    (x + (SAMPLE_W + GAP) as i32, y - SIZE as i32 / 2 - 1),
                    (FONT, SIZE),
                ))
                .map_err(e)?;
            x += (entry_width(entry) + SPACING) as i32;
        }
    }
    Ok(())
}

/// The sample of an entry, its left end at `(x, y)`.
fn sample(
    strip: &DrawingArea<SVGBackend, Shift>,
    sample: Sample,
    (x, y): (i32, i32),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let w = SAMPLE_W as i32;
    let mid = (x + w / 2, y);
    let line = |style: ShapeStyle| PathElement::new(vec![(x, y), (x + w, y)], style);
    let square =
        |style: ShapeStyle, r: i32| Rectangle::new([(mid.0 - r, y - r), (mid.0 + r, y + r)], style);
    match sample {
        Sample::Line(s) => strip.draw(&line(s)).map_err(e),
        Sample::Dashed(s) => {
            strip
                .draw(&PathElement::new(vec![(x, y), (x + 8, y)], s))
                .map_err(e)?;
            strip
                .draw(&PathElement::new(vec![(x + 14, y), (x + w, y)], s))
                .map_err(e)
        }
        Sample::Circle(s, r) => strip.draw(&Circle::new(mid, r, s)).map_err(e),
        Sample::Square(s, r) => strip.draw(&square(s, r)).map_err(e),
        Sample::LineCircle(l, m, r) => {
            strip.draw(&line(l)).map_err(e)?;
            strip.draw(&Circle::new(mid, r, m)).map_err(e)
        }
        Sample::LineSquare(l, m, r) => {
            strip.draw(&line(l)).map_err(e)?;
            strip.draw(&square(m, r)).map_err(e)
        }
        Sample::Band(s) => strip
            .draw(&Rectangle::new([(x, y - 5), (x + w, y + 5)], s))
            .map_err(e),
    }
}

/// `area` split into the strip of the legend of `entries` (drawn) and the rest, returned.
pub fn above<'a>(
    area: &DrawingArea<SVGBackend<'a>, Shift>,
    entries: &[Entry],
) -> Result<DrawingArea<SVGBackend<'a>, Shift>, String> {
    let (w, _) = area.dim_in_pixel();
    let h = height(entries, w);
    if h == 0 {
        return Ok(area.clone());
    }
    let (strip, rest) = area.split_vertically(h);
    draw(&strip, entries)?;
    Ok(rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(n: usize) -> Vec<Entry> {
        (0..n)
            .map(|i| Entry::new(format!("rod {i}"), Sample::Line(BLACK.stroke_width(2))))
            .collect()
    }

    #[test]
    fn entries_wrap_into_rows_that_fit_the_width() {
        let many = entries(40);
        let rows = rows(&many, 400);
        assert!(rows.len() > 1);
        assert_eq!(rows.iter().map(|r| r.len()).sum::<usize>(), 40);
        for r in &rows {
            let w: u32 = many[r.clone()].iter().map(entry_width).sum::<u32>()
                + SPACING * (r.len() as u32 - 1);
            assert!(w <= 400 - 2 * INSET - 2 * PAD, "{w}");
        }
        assert_eq!(height(&[], 400), 0);
        assert_eq!(super::rows(&entries(2), 400).len(), 1);
    }
}
