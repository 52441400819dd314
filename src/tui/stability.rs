//! Stability of the states on the load path, as the explorer shows it. The one place to wire
//! the core's stability analysis (docs/theory.md §5) into the screen: the status line and the
//! marking of unstable stretches of the load path both go through [`is_unstable`].

use crate::results::LoadPoint;
use std::ops::Range;

/// Whether the state at `point` is unstable: `Some(true)` unstable, `Some(false)` stable,
/// `None` unknown (stability not tracked, or not computable at that state).
pub fn is_unstable(point: &LoadPoint) -> Option<bool> {
    point.stability.map(|s| !s.is_stable())
}

/// Status-line label of a state's stability.
pub fn label(unstable: Option<bool>) -> &'static str {
    match unstable {
        None => "n/a",
        Some(false) => "stable",
        Some(true) => "UNSTABLE",
    }
}

/// A run of consecutive load-path points drawn alike: `points` indexes the path, and
/// consecutive stretches share their end point so the drawn path has no gaps.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Stretch {
    pub unstable: bool,
    pub points: Range<usize>,
}

/// Splits a path of `len` points into stretches; a segment between two points is unstable
/// when either end is. A single point is one stable stretch.
pub fn stretches(len: usize, unstable: impl Fn(usize) -> Option<bool>) -> Vec<Stretch> {
    if len == 0 {
        return Vec::new();
    }
    if len == 1 {
        return vec![Stretch {
            unstable: unstable(0) == Some(true),
            points: 0..1,
        }];
    }
    let flags: Vec<bool> = (0..len).map(|k| unstable(k) == Some(true)).collect();
    let mut out: Vec<Stretch> = Vec::new();
    for k in 0..len - 1 {
        let bad = flags[k] || flags[k + 1];
        match out.last_mut() {
            Some(s) if s.unstable == bad => s.points.end = k + 2,
            _ => out.push(Stretch {
                unstable: bad,
                points: k..k + 2,
            }),
        }
    }
    out
}
