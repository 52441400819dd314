//! `discretisation.model`: which model stands for the assembly — `"auto"` (the default: the
//! symmetric pair wherever the assembly has the symmetry), `"pair"`, `"full"`, or `"cell"`,
//! the cell of the infinitely long tube of the case's helices (docs/theory.md §8). The older
//! key `symmetric` (`true`, `false`, `"auto"`) keeps its meaning; the two are not given
//! together.

use super::raw::RawDiscretisation;
use super::settings::{Geometry, Loading};
use super::tables::{span, Checker};
use super::CaseError;
use crate::model::loading::{AxialHeld, Branch, Component, Control};

/// The model a case's `[discretisation]` chooses: `(symmetric, symmetric_auto, cell)`, or
/// `None` when it gives no `model` (then `symmetric` decides).
pub(super) fn model_choice(
    d: &RawDiscretisation,
    geometry: &Geometry,
    ck: &Checker,
) -> Result<Option<(bool, bool, bool)>, CaseError> {
    let Some(key) = &d.model else {
        return Ok(None);
    };
    if d.symmetric.is_some() {
        return Err(ck.invalid(
            "discretisation.model",
            key.span(),
            "give either `model` or the older `symmetric`, not both",
        ));
    }
    let n = geometry.helices;
    let has = n >= 4 && n % 2 == 0;
    match key.get_ref().as_str() {
        "auto" => Ok(Some((has, true, false))),
        "full" => Ok(Some((false, false, false))),
        "pair" if has => Ok(Some((true, false, false))),
        "pair" => Err(ck.invalid(
            "discretisation.model",
            key.span(),
            format!("expected \"full\", \"auto\" or \"cell\": {n} helix(es) have no rotational symmetry to reduce to a pair (it needs n = 2m helices with m ≥ 2)"),
        )),
        "cell" if n % 2 == 0 && geometry.radius > 0.0 => Ok(Some((false, false, true))),
        "cell" => Err(ck.invalid(
            "discretisation.model",
            key.span(),
            format!("expected \"full\", \"pair\" or \"auto\": the cell of an infinite tube needs n = 2m helices off the axis, found n = {n} and radius {} m", geometry.radius),
        )),
        other => Err(ck.invalid(
            "discretisation.model",
            key.span(),
            format!("expected \"auto\", \"pair\", \"full\" or \"cell\", found \"{other}\""),
        )),
    }
}

/// What a cell is loaded by: its axial strain `ε` (displacement control) stepped, or a
/// radial pressure stepped at a held `ε`; no twist, tilt, dead axial load or branch switch.
pub(super) fn check_cell_loading(
    d: &RawDiscretisation,
    loading: &Loading,
    ck: &Checker,
) -> Result<(), CaseError> {
    let held_ratio = matches!(loading.hold.axial, AxialHeld::Ratio(_));
    if d.accuracy.is_some() {
        return Err(ck.invalid(
            "discretisation.model",
            span(&d.model),
            "a cell takes `elements` (its default mesh when not given), not `accuracy`",
        ));
    }
    let why = match loading.parameter {
        Component::Axial if loading.control == Control::Force => {
            Some("the cell's axial strain is prescribed (displacement control), not a dead load")
        }
        Component::Axial | Component::Pressure if !held_ratio => {
            Some("the cell's axial strain is held (hold.axial = eps), not a dead load")
        }
        Component::Twist | Component::Tilt => {
            Some("the cell is loaded by its axial strain and a radial pressure only")
        }
        _ if loading.hold.twist != 0.0 || loading.hold.tilt != 0.0 => {
            Some("the cell holds no twist or tilt")
        }
        _ if loading.branch != Branch::Fundamental => {
            Some("the cell follows its fundamental path (branch = \"fundamental\")")
        }
        _ => None,
    };
    match why {
        Some(why) => Err(ck.invalid("discretisation.model", span(&d.model), why)),
        None => Ok(()),
    }
}
