//! What every figure of a run shares: the caption lines, the grid, the colour of marks, and
//! the ranges of the axes.

use plotters::prelude::*;

/// Dashes of unstable stretches: dash and gap lengths (px).
pub(super) const DASH: (u32, u32) = (7, 5);
/// Colour of joints and other marks that are not a curve.
pub(super) const MARK: RGBColor = RGBColor(0x40, 0x40, 0x40);
pub(super) const GRID_BOLD: RGBColor = RGBColor(0xdd, 0xdd, 0xdd);
/// Minor grid lines are left out (transparent: plotters writes nothing for them), which
/// keeps the files small.
pub(super) const GRID_LIGHT: RGBAColor = RGBAColor(0xff, 0xff, 0xff, 0.0);

/// The lines under a figure's title: the case and the command that drew it, e.g.
/// `["case thesis-n8", "command: spira plot out/n8"]`.
pub type Caption = [String];

/// `[lo, hi]` of the finite values, padded by 5 % and at least `min_span` wide.
pub(super) fn range(values: impl Iterator<Item = f64>, min_span: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (-0.5 * min_span, 0.5 * min_span);
    }
    let pad = 0.05 * (hi - lo);
    let (mut lo, mut hi) = (lo - pad, hi + pad);
    if hi - lo < min_span {
        let mid = 0.5 * (lo + hi);
        lo = mid - 0.5 * min_span;
        hi = mid + 0.5 * min_span;
    }
    (lo, hi)
}
