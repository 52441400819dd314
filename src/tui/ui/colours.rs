//! The colours of the screen, all among the 16 ANSI colours.

use ratatui::style::Color;

/// κ1 colour scale, most negative to most positive (bins of equal width over the state's
/// range).
pub const K1_PALETTE: [Color; 5] = [
    Color::Blue,
    Color::Cyan,
    Color::Green,
    Color::Yellow,
    Color::Red,
];

pub(super) const SELECTED: Color = Color::White;

pub(super) const JOINT: Color = Color::Gray;

/// The bar over the bulk of the rod on the curvature plot.
pub(super) const BULK: Color = Color::Cyan;

pub(super) const K1_LINE: Color = Color::LightYellow;

pub(super) const K2_LINE: Color = Color::LightCyan;

pub(super) const OMEGA_LINE: Color = Color::LightMagenta;

pub(super) const FX_LINE: Color = Color::LightRed;

pub(super) const FY_LINE: Color = Color::LightGreen;

pub(super) const FZ_LINE: Color = Color::LightBlue;

pub(super) const DIM: Color = Color::DarkGray;

/// A critical mode's preview over the views.
pub(super) const MODE: Color = Color::Magenta;
