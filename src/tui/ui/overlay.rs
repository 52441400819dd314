//! A box over the screen, for the lists and the help.

use ratatui::layout::{Alignment, Rect};
use ratatui::text::Line;
use ratatui::widgets::{Block, Borders, Clear, Paragraph};
use ratatui::Frame;

/// A box of `lines` centred over the screen, titled, with how to close it at the bottom.
pub(super) fn draw_overlay(
    frame: &mut Frame,
    area: Rect,
    lines: Vec<Line>,
    title: &str,
    close: &str,
) {
    let width = (lines.iter().map(|l| l.width()).max().unwrap_or(0) as u16 + 3).min(area.width);
    let height = (lines.len() as u16 + 2).min(area.height);
    let rect = Rect {
        x: area.x + (area.width - width) / 2,
        y: area.y + (area.height - height) / 2,
        width,
        height,
    };
    frame.render_widget(Clear, rect);
    frame.render_widget(
        Paragraph::new(lines).block(
            Block::new()
                .borders(Borders::ALL)
                .title(title.to_string())
                .title_bottom(Line::from(close.to_string()).alignment(Alignment::Right)),
        ),
        rect,
    );
}
