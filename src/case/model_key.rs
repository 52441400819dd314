//! `discretisation.model`: which model stands for the assembly — `"auto"` (the default: the
//! symmetric pair wherever the assembly has the symmetry), `"pair"`, `"full"`, or `"cell"`,
//! the cell of the infinitely long tube of the case's helices (docs/theory.md §8). The older
//! key `symmetric` (`true`, `false`, `"auto"`) keeps its meaning; the two are not given
//! together.

use super::raw::{ModelKey, RawDiscretisation};
use super::settings::{Geometry, Loading};
use crate::model::loading::{AxialHeld, Branch, Component, Control};

/// The model a case's `[discretisation]` chooses: `(symmetric, symmetric_auto, cell)`, or
/// `None` when it gives no `model` (then `symmetric` decides); `Err` says what is wrong with
/// the `model` key.
pub(super) fn model_choice(
    d: &RawDiscretisation,
    geometry: &Geometry,
) -> Result<Option<(bool, bool, bool)>, String> {
    let Some(key) = &d.model else {
        return Ok(None);
    };
    if d.symmetric.is_some() {
        return Err("give either `model` or the older `symmetric`, not both".into());
    }
    if d.accuracy.is_some() && *key == ModelKey::Cell {
        return Err(
            "a cell takes `elements` (its default mesh when not given), not `accuracy`".into(),
        );
    }
    let n = geometry.helices;
    let has = n >= 4 && n % 2 == 0;
    match key {
        ModelKey::Auto => Ok(Some((has, true, false))),
        ModelKey::Full => Ok(Some((false, false, false))),
        ModelKey::Pair if has => Ok(Some((true, false, false))),
        ModelKey::Pair => Err(format!("expected \"full\", \"auto\" or \"cell\": {n} helix(es) have no rotational symmetry to reduce to a pair (it needs n = 2m helices with m ≥ 2)")),
        ModelKey::Cell if n % 2 == 0 && geometry.radius > 0.0 => Ok(Some((false, false, true))),
        ModelKey::Cell => Err(format!("expected \"full\", \"pair\" or \"auto\": the cell of an infinite tube needs n = 2m helices off the axis, found n = {n} and radius {} m", geometry.radius)),
    }
}

/// What a cell is loaded by: its axial strain `ε` (displacement control), its twist per
/// cell `φ` (the extra turn of its screw, rad), a radial pressure or its tilt per bending
/// cell (rad: the tube bent, docs/theory.md §8), one stepped and the others held, `ε` held
/// as a strain; no dead axial load or branch switch, and a tilt only on a tube of `m ≥ 2`
/// helices of each hand (`helices = 2m`), untwisted. `Some` says why the case's loading is not that.
pub(super) fn cell_loading_message(loading: &Loading, helices: usize) -> Option<&'static str> {
    let held_ratio = matches!(loading.hold.axial, AxialHeld::Ratio(_));
    let tilted = loading.parameter == Component::Tilt || loading.hold.tilt != 0.0;
    match loading.parameter {
        Component::Axial if loading.control == Control::Force => {
            Some("the cell's axial strain is prescribed (displacement control), not a dead load")
        }
        Component::Axial | Component::Twist | Component::Pressure | Component::Tilt
            if !held_ratio =>
        {
            Some("the cell's axial strain is held (hold.axial = eps), not a dead load")
        }
        _ if tilted && helices < 4 => Some(
            "a bent cell needs n = 2m helices with m >= 2 (its section's centre is the mean of its m crossings)",
        ),
        _ if tilted && (loading.parameter == Component::Twist || loading.hold.twist != 0.0) => {
            Some("a bent cell is not twisted: give the tilt with the twist at 0")
        }
        _ if loading.branch != Branch::Fundamental => {
            Some("the cell follows its fundamental path (branch = \"fundamental\")")
        }
        _ => None,
    }
}
