//! The keys overlay (`?`), made from the key table the key handling reads.

use super::colours::DIM;
use super::overlay::draw_overlay;
use crate::tui::app::App;
use crate::tui::keys::BINDINGS;
use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::Frame;

/// The keys, in the help overlay: (keys, what they do), made from the key table
/// [`BINDINGS`] that the key handling reads.
pub const KEYS: [(&str, &str); BINDINGS.len()] = {
    let mut keys = [("", ""); BINDINGS.len()];
    let mut i = 0;
    while i < keys.len() {
        keys[i] = (BINDINGS[i].label, BINDINGS[i].help);
        i += 1;
    }
    keys
};

pub(super) fn draw_help(frame: &mut Frame, area: Rect, app: &App) {
    let mut lines: Vec<Line> = KEYS
        .iter()
        .map(|(k, what)| {
            Line::from(vec![
                Span::styled(format!(" {k:<6} "), Style::new().fg(Color::Yellow)),
                Span::raw(in_terms_of(what, app.symbol())),
            ])
        })
        .collect();
    lines.push(Line::from(Span::styled(
        if app.out_dir == std::path::Path::new(".") {
            " exports go to the current folder".to_string()
        } else {
            format!(" exports go to {}", app.out_dir.display())
        },
        Style::new().fg(DIM),
    )));
    draw_overlay(frame, area, lines, " keys ", " any key closes ");
}

/// A help text with the load parameter's `symbol` in place of `ε` (the key table is written
/// for displacement control).
fn in_terms_of(help: &str, symbol: &str) -> String {
    help.replace('ε', symbol)
}
