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
    let lines: Vec<Line> = KEYS
        .iter()
        .map(|(k, what)| {
            Line::from(vec![
                Span::styled(format!(" {k:<6} "), Style::new().fg(Color::Yellow)),
                Span::raw(in_terms_of(what, app.symbol())),
            ])
        })
        .collect();
    // the export folder on the bottom border, its head shortened when the box is narrow
    let close = " any key closes ";
    let room = (area.width as usize).saturating_sub(close.len() + 4 + "exports to ".len());
    let folder = fit_path(&export_folder(app), room);
    let foot = Line::from(vec![
        Span::styled(" exports to ", Style::new().fg(DIM)),
        Span::raw(format!("{folder} ")),
    ]);
    draw_overlay(frame, area, lines, " keys ", (Some(foot), close));
}

/// The absolute path of the export folder (as given when it cannot be made absolute).
fn export_folder(app: &App) -> String {
    let absolute = std::path::absolute(&app.out_dir).unwrap_or_else(|_| app.out_dir.clone());
    // `.` and `..` parts as the user's shell would resolve them
    let mut clean = std::path::PathBuf::new();
    for part in absolute.components() {
        match part {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                clean.pop();
            }
            other => clean.push(other),
        }
    }
    clean.display().to_string()
}

/// `path` in at most `room` columns: whole, or its tail after `…`.
fn fit_path(path: &str, room: usize) -> String {
    let n = path.chars().count();
    if n <= room {
        return path.to_string();
    }
    let tail: String = path.chars().skip(n + 1 - room.max(1)).collect();
    format!("…{tail}")
}

/// A help text with the load parameter's `symbol` in place of `ε` (the key table is written
/// for displacement control).
fn in_terms_of(help: &str, symbol: &str) -> String {
    help.replace('ε', symbol)
}
