//! The critical-point list (`x`): the critical points crossed so far, over the screen.

use super::colours::DIM;
use super::overlay::draw_overlay;
use crate::model::loading::Component;
use crate::tui::app::App;
use ratatui::layout::Rect;
use ratatui::style::{Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::Frame;

/// The critical points crossed so far, as a list over the screen, the chosen one
/// highlighted (a bifurcation's branch is switched onto from here).
pub(super) fn draw_critical(frame: &mut Frame, area: Rect, app: &App) {
    // the axial load's critical points by ε and fz, the others' by their own parameter
    let axial = app.case().loading.parameter == Component::Axial;
    let head = if axial {
        "  #  kind           ε         fz/(n Pcrit)  unstable  p".to_string()
    } else {
        let p = app.load_parameter();
        format!(
            "  #  kind           {:<9} fz/(n Pcrit)  unstable  p",
            format!("{} ({})", p.symbol(), p.unit())
        )
    };
    let mut lines = vec![Line::from(Span::styled(head, Style::new().fg(DIM)))];
    if app.screen.critical.is_empty() {
        lines.push(Line::from(" none crossed on this path yet"));
    }
    for (i, c) in app.screen.critical.iter().enumerate() {
        let text = format!(
            "{} {i:>2}  {:<13} {:>9.5}  {:>12.5}  {}{}",
            if i == app.view.critical_cursor {
                '▸'
            } else {
                ' '
            },
            c.kind.name(),
            if axial {
                c.compression_ratio
            } else {
                c.parameter
            },
            c.load[2],
            c.count_change("→"),
            c.wavenumber.map_or(String::new(), |p| format!("     {p}"))
        );
        let style = if i == app.view.critical_cursor {
            Style::new().add_modifier(Modifier::REVERSED)
        } else {
            Style::new()
        };
        lines.push(Line::from(Span::styled(text, style)));
    }
    if !app.screen.critical.is_empty() {
        lines.push(Line::from(Span::styled(
            " ↑↓ choose · ⏎/g switch onto its branch (G: other side)",
            Style::new().fg(DIM),
        )));
    }
    draw_overlay(
        frame,
        area,
        lines,
        " critical points ",
        (None, " x closes "),
    );
}
