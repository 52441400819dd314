//! A box over the screen, for the lists and the help.

use ratatui::layout::{Alignment, Rect};
use ratatui::text::Line;
use ratatui::widgets::{Block, Borders, Clear, Paragraph};
use ratatui::Frame;

/// A box of `lines` centred over the screen, titled, with how to close it at the bottom
/// right (and `foot` at the bottom left).
pub(super) fn draw_overlay(
    frame: &mut Frame,
    area: Rect,
    lines: Vec<Line>,
    title: &str,
    (foot, close): (Option<Line>, &str),
) {
    let foot_width = foot.as_ref().map_or(0, |f| f.width() + 1) + close.chars().count();
    let width = (lines.iter().map(|l| l.width()).max().unwrap_or(0) as u16 + 3)
        .max(foot_width as u16 + 2)
        .min(area.width);
    let height = (lines.len() as u16 + 2).min(area.height);
    let rect = Rect {
        x: area.x + (area.width - width) / 2,
        y: area.y + (area.height - height) / 2,
        width,
        height,
    };
    frame.render_widget(Clear, rect);
    let mut block = Block::new()
        .borders(Borders::ALL)
        .title(title.to_string())
        .title_bottom(Line::from(close.to_string()).alignment(Alignment::Right));
    if let Some(foot) = foot {
        block = block.title_bottom(foot);
    }
    frame.render_widget(Paragraph::new(lines).block(block), rect);
}
