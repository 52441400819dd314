//! Numbers in a few characters, for the readouts and the axes.

/// A number in a few characters: 3 significant digits.
pub fn fmt_num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            format!("{v}")
        };
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = (2 - a.log10().floor() as i32).clamp(0, 5) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        s
    }
}

/// A short number for the readout: as [`fmt_num`], with one digit in scientific notation
/// and values below `1e-9` of `scale` shown as 0 (round-off of a symmetric state).
pub fn fmt_short(v: f64, scale: f64) -> String {
    if is_round_off(v, scale) {
        return "0".into();
    }
    let a = v.abs();
    if a.is_finite() && !(1e-3..1e4).contains(&a) {
        return format!("{v:.1e}");
    }
    fmt_num(v)
}

/// Whether `v` is below `1e-9` of `scale`: the round-off of a zero (a lateral force or a
/// curvature of a symmetric state).
fn is_round_off(v: f64, scale: f64) -> bool {
    v.abs() <= 1e-9 * scale.abs()
}

/// The largest magnitude among `v`: the scale of a vector's round-off.
pub(super) fn largest(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, c| m.max(c.abs()))
}

/// A component of a load as [`fmt_num`], 0 when it is the round-off of the load's largest.
pub(super) fn fmt_load(v: f64, load: &[f64; 3]) -> String {
    if is_round_off(v, largest(load)) {
        return "0".into();
    }
    fmt_num(v)
}

pub(super) fn fmt_duration(d: std::time::Duration) -> String {
    let ms = d.as_secs_f64() * 1e3;
    if ms < 10.0 {
        format!("{ms:.1} ms")
    } else if ms < 10_000.0 {
        format!("{ms:.0} ms")
    } else {
        format!("{:.1} s", ms / 1e3)
    }
}
