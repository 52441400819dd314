//! Drawing the explorer: [`draw`] lays out the screen and each panel has a file of its
//! own, drawn by one function taking the [`App`] read-only: the three projections of the
//! assembly ([`shapes`]), the curvature of the selected rod (`curvature`), the load path
//! (`load`), the work-precision chart (`precision`), the critical curve of the scene (`curve`), the status lines (`status`), and
//! the overlays of the critical points (`critical`) and the keys (`help`). Only the 16
//! ANSI colours are used ([`colours`]), so the screen reads the same on any terminal and
//! over SSH.

mod chart;
pub mod colours;
mod critical;
mod curvature;
mod curve;
mod help;
mod load;
mod numbers;
mod overlay;
mod precision;
pub mod shapes;
mod status;

pub use colours::K1_PALETTE;
pub use help::KEYS;
pub use numbers::{fmt_num, fmt_short};
pub use shapes::{dot_size, fit_aspect, fit_scale, K1Scale, View};

use super::app::App;
use ratatui::layout::{Alignment, Constraint, Layout, Rect};
use ratatui::style::{Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Wrap};
use ratatui::Frame;

/// Smallest usable terminal.
pub const MIN_WIDTH: u16 = 80;
pub const MIN_HEIGHT: u16 = 24;

/// Draws the whole screen (or the too-small message): the projections over the plots (or
/// the work-precision chart), the status lines below, the overlays on top.
pub fn draw(frame: &mut Frame, app: &App) {
    let area = frame.area();
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        draw_too_small(frame, area);
        return;
    }
    let [main, status] = Layout::vertical([
        Constraint::Min(0),
        Constraint::Length(4 + status::message_lines(app, area.width)),
    ])
    .areas(area);
    // on a short screen the views take a row more than half, for four rows of each side view
    let views_rows = if main.height < 30 {
        main.height.div_ceil(2) + 1
    } else {
        main.height.div_ceil(2)
    };
    let [views, plots] =
        Layout::vertical([Constraint::Length(views_rows), Constraint::Min(0)]).areas(main);
    let [curvature, load] =
        Layout::horizontal([Constraint::Ratio(1, 2), Constraint::Ratio(1, 2)]).areas(plots);
    shapes::draw_views(frame, views, app);
    if app.view.show_precision {
        precision::draw_precision(frame, plots, app);
    } else if app.view.show_curve {
        curve::draw_curve(frame, plots, app);
    } else {
        curvature::draw_curvature(frame, curvature, app);
        load::draw_load_path(frame, load, app);
    }
    status::draw_status(frame, status, app);
    if app.view.show_critical {
        // below the views, which show the chosen point's mode
        let below = Rect {
            y: plots.y,
            height: area.bottom() - plots.y,
            ..area
        };
        critical::draw_critical(frame, below, app);
    }
    if app.view.show_help {
        help::draw_help(frame, area, app);
    }
}

/// The message for a terminal below [`MIN_WIDTH`] x [`MIN_HEIGHT`].
pub fn draw_too_small(frame: &mut Frame, area: Rect) {
    let text = vec![
        Line::from(Span::styled(
            "terminal too small",
            Style::new().add_modifier(Modifier::BOLD),
        )),
        Line::from(format!(
            "spira needs {MIN_WIDTH}x{MIN_HEIGHT}, this one is {}x{}.",
            area.width, area.height
        )),
        Line::from("Enlarge the window, or press q to quit."),
    ];
    let top = area.height.saturating_sub(text.len() as u16) / 2;
    let rect = Rect {
        y: area.y + top,
        height: area.height - top,
        ..area
    };
    frame.render_widget(
        Paragraph::new(text)
            .alignment(Alignment::Center)
            .wrap(Wrap { trim: true }),
        rect,
    );
}
