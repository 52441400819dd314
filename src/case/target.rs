//! The target load parameter a case admits.
//!
//! Under displacement control the target is a compression ratio `ε = (h0 − h)/h0`: the tip
//! height `h = h0 (1 − ε)` must stay above the base (`h > 0`, `ε < 1`) and below the length
//! of the rod pulled straight (`h < L`, `ε > 1 − L/h0`); both limits are singular states.
//! Under load control the target `P / Pcrit` only has to be a finite number.

use super::limits::{num, MAX_LOAD};
use super::settings::Geometry;
use crate::model::loading::{Component, Control};
use std::fmt;

/// The largest twist a case may step to (rad): sixteen turns of the support.
pub const MAX_TWIST: f64 = 32.0 * std::f64::consts::PI;
/// The largest tilt a case may step to (rad): a full turn of the support.
pub const MAX_TILT: f64 = 2.0 * std::f64::consts::PI;
/// The largest radial pressure a case may step to, in units of `B1/L³` (N/m).
pub const MAX_PRESSURE: f64 = 1e9;

/// A target load parameter the case cannot reach; the message says which limit is crossed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum TargetError {
    /// An angle or a pressure that is NaN or infinite; `what` names it with its symbol.
    NotFinite { what: &'static str, value: f64 },
    /// An angle or a pressure beyond `max` in magnitude (in `unit`).
    OutOfRange {
        what: &'static str,
        value: f64,
        max: f64,
        unit: &'static str,
    },
    /// Load control: `P / Pcrit` is NaN or infinite.
    LoadNotFinite { load: f64 },
    /// Load control: `|P / Pcrit|` beyond [`MAX_LOAD`] (a path of more than
    /// `MAX_LOAD / max_step` steps, far past every critical load of a rod).
    LoadOutOfRange { load: f64 },
    /// Displacement control: `ε` is NaN or infinite. `min_eps = 1 − L/h0` is the lower
    /// limit of the admissible `ε`.
    RatioNotFinite { eps: f64, min_eps: f64 },
    /// `ε ≥ 1`: the tip, at height `h = h0 (1 − ε)` (m), would be on or below the base.
    TipOnOrBelowBase { eps: f64, min_eps: f64, height: f64 },
    /// `ε ≤ 1 − L/h0`: the tip, at height `h` (m), would be at or beyond the rod length `L`
    /// (m), the rod pulled straight; `height0` is `h0` (m).
    TipAtOrBeyondRodLength {
        eps: f64,
        min_eps: f64,
        height: f64,
        length: f64,
        height0: f64,
    },
}

impl fmt::Display for TargetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TargetError::NotFinite { what, value } => {
                write!(f, "expected a finite {what}, found {value}")
            }
            TargetError::OutOfRange {
                what,
                value,
                max,
                unit,
            } => write!(
                f,
                "expected a {what} from -{} to {} {unit}, found {}",
                short(max),
                short(max),
                num(value)
            ),
            TargetError::LoadNotFinite { load } => {
                write!(f, "expected a finite load P/Pcrit, found {load}")
            }
            TargetError::LoadOutOfRange { load } => {
                let max = MAX_LOAD;
                write!(
                    f,
                    "expected a load P/Pcrit from -{max} to {max}, found {}",
                    num(load)
                )
            }
            TargetError::RatioNotFinite { eps, min_eps } => {
                write!(f, "{}, found {}", admissible_ratios(min_eps), num(eps))
            }
            TargetError::TipOnOrBelowBase {
                eps,
                min_eps,
                height,
            } => {
                let place = if eps == 1.0 { "on" } else { "below" };
                write!(
                    f,
                    "{}, found {}: {}, {place} the base",
                    admissible_ratios(min_eps),
                    num(eps),
                    tip_height(height)
                )
            }
            TargetError::TipAtOrBeyondRodLength {
                eps,
                min_eps,
                height,
                length,
                height0,
            } => {
                let place = if eps == min_eps { "equal to" } else { "beyond" };
                write!(
                    f,
                    "{}, found {}: {}, {place} the rod length L = {} m (the rod pulled straight; h0 = {} m)",
                    admissible_ratios(min_eps),
                    num(eps),
                    tip_height(height),
                    short(length),
                    short(height0)
                )
            }
        }
    }
}

/// "expected a compression ratio in (1 − L/h0, 1)".
fn admissible_ratios(min_eps: f64) -> String {
    format!(
        "expected a compression ratio ε = (h0 − h)/h0 in ({}, 1)",
        short(min_eps)
    )
}

/// "the tip would be at height h".
fn tip_height(height: f64) -> String {
    format!(
        "the tip would be at height h = h0 (1 − ε) = {} m",
        short(height)
    )
}

/// Checks `target` as the target of `component`: under [`check_target`] for the axial one,
/// a finite angle or pressure within its range for the others (the pressure's range in
/// units of `b1/L³`, `b1` in N m²).
pub(super) fn check_component_target(
    geometry: &Geometry,
    b1: f64,
    component: Component,
    control: Control,
    target: f64,
) -> Result<(), TargetError> {
    let (what, max, unit) = match component {
        Component::Axial => return check_target(geometry, control, target),
        Component::Twist => ("twist angle φ", MAX_TWIST, "rad"),
        Component::Tilt => ("tilt angle θ", MAX_TILT, "rad"),
        Component::Pressure => (
            "radial pressure q",
            MAX_PRESSURE * b1 / geometry.length.powi(3),
            "N/m",
        ),
    };
    if !target.is_finite() {
        Err(TargetError::NotFinite {
            what,
            value: target,
        })
    } else if target.abs() > max {
        Err(TargetError::OutOfRange {
            what,
            value: target,
            max,
            unit,
        })
    } else {
        Ok(())
    }
}

/// Checks `target` as the target load parameter of `geometry` under `control`.
pub(super) fn check_target(
    geometry: &Geometry,
    control: Control,
    target: f64,
) -> Result<(), TargetError> {
    if control == Control::Force {
        return if !target.is_finite() {
            Err(TargetError::LoadNotFinite { load: target })
        } else if target.abs() > MAX_LOAD {
            Err(TargetError::LoadOutOfRange { load: target })
        } else {
            Ok(())
        };
    }
    let eps = target;
    let height0 = geometry.height0();
    let length = geometry.length;
    let min_eps = 1.0 - length / height0;
    if !eps.is_finite() {
        return Err(TargetError::RatioNotFinite { eps, min_eps });
    }
    let height = height0 * (1.0 - eps);
    if eps >= 1.0 {
        Err(TargetError::TipOnOrBelowBase {
            eps,
            min_eps,
            height,
        })
    } else if eps <= min_eps {
        Err(TargetError::TipAtOrBeyondRodLength {
            eps,
            min_eps,
            height,
            length,
            height0,
        })
    } else {
        Ok(())
    }
}

/// A number to 6 significant figures without trailing zeros, for messages.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-4..1e6).contains(&x.abs()) {
        // no 309-digit numbers: 6 significant figures in scientific notation
        let s = format!("{x:.5e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exponent}");
    }
    let decimals = (5 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}
