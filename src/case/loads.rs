//! `[loading]`: which component of the tube's loading the load parameter steps (axial,
//! twist, tilt or radial pressure), to which target, the values the others are held at,
//! the control of the axial component, the output steps and the branch taken at the first
//! bifurcation.

use super::error::CaseError;
use super::limits::{num, MAX_STEPS};
use super::raw::{RawHold, RawLoading};
use super::settings::{Geometry, Loading};
use super::tables::Checker;
use super::target::{check_component_target, MAX_PRESSURE, MAX_TILT, MAX_TWIST};
use crate::model::boundary::{BoundaryConditions, Translation};
use crate::model::loading::{AxialHeld, Branch, Component, Control, Held};

/// `[loading]` checked against the geometry, the rods' bending stiffness `b1` (N m², the
/// scale of the pressure's range) and the supports.
pub(super) fn loading(
    l: &RawLoading,
    geometry: &Geometry,
    b1: f64,
    boundary: &BoundaryConditions,
    ck: &Checker,
) -> Result<Loading, CaseError> {
    let parameter = l.parameter.unwrap_or(Component::Axial);
    // an error about the parameter is reported on its line
    let at_parameter = |key: &str, message: String| CaseError::Invalid {
        file: ck.file.to_string(),
        line: ck.line_of_key("parameter"),
        key: key.to_string(),
        message,
    };
    let control = l.control.unwrap_or(Control::Displacement);
    if parameter != Component::Axial && control == Control::Force {
        let what = match parameter {
            Component::Twist => "a torque",
            Component::Tilt => "a bending moment",
            _ => "a force",
        };
        return Err(at_parameter(
            "loading.control",
            format!(
                "expected control = \"displacement\" with parameter = \"{}\": the {} is stepped by the support's motion ({what} on the support is not modelled)",
                parameter.name(),
                parameter.name()
            ),
        ));
    }
    let target = match &l.target {
        None if parameter == Component::Axial => 0.5,
        None => {
            return Err(at_parameter(
                "loading.target",
                format!(
                    "expected a target for parameter = \"{}\" ({})",
                    parameter.name(),
                    unit_of(parameter)
                ),
            ))
        }
        Some(t) => {
            let target = *t.get_ref();
            check_component_target(geometry, b1, parameter, control, target)
                .map_err(|why| ck.invalid("loading.target", t.span(), why))?;
            target
        }
    };
    let default = RawHold::default();
    let hold = held(l.hold.as_ref().unwrap_or(&default), geometry, b1, ck)?;
    check_combination(parameter, control, &hold, geometry, boundary, ck)?;
    let steps = ck.integer(
        "loading.steps",
        &l.steps,
        10,
        (1, MAX_STEPS as i64),
        "a number of output steps",
    )?;
    Ok(Loading {
        parameter,
        hold,
        control,
        target,
        steps,
        branch: l.branch.unwrap_or(Branch::Fundamental),
    })
}

/// The unit a component's target is given in.
fn unit_of(component: Component) -> &'static str {
    match component {
        Component::Axial => "ε or P/Pcrit",
        Component::Twist | Component::Tilt => "rad",
        Component::Pressure => "N/m",
    }
}

/// `hold = { … }`: each value finite and in its component's range.
fn held(h: &RawHold, geometry: &Geometry, b1: f64, ck: &Checker) -> Result<Held, CaseError> {
    let ranged = |key: &str, value, max: f64, what: &str| {
        ck.number(
            &format!("loading.hold.{key}"),
            value,
            0.0,
            |v| v.abs() <= max,
            &format!("a {what} from -{} to {}", num(max), num(max)),
        )
    };
    let axial = match (&h.axial, &h.axial_force) {
        (Some(_), Some(f)) => {
            return Err(ck.invalid(
                "loading.hold.axial_force",
                f.span(),
                "expected either hold.axial (a compression ratio held) or hold.axial_force (a dead load), not both",
            ))
        }
        (_, Some(_)) => AxialHeld::Load(ranged(
            "axial_force",
            &h.axial_force,
            super::limits::MAX_LOAD,
            "load P/Pcrit",
        )?),
        (Some(e), None) => {
            let eps = *e.get_ref();
            check_component_target(geometry, b1, Component::Axial, Control::Displacement, eps)
                .map_err(|why| ck.invalid("loading.hold.axial", e.span(), why))?;
            AxialHeld::Ratio(eps)
        }
        (None, None) => AxialHeld::Ratio(0.0),
    };
    let max_pressure = MAX_PRESSURE * b1 / geometry.length.powi(3);
    Ok(Held {
        axial,
        twist: ranged("twist", &h.twist, MAX_TWIST, "twist angle in rad")?,
        tilt: ranged("tilt", &h.tilt, MAX_TILT, "tilt angle in rad")?,
        pressure: ranged(
            "pressure",
            &h.pressure,
            max_pressure,
            "radial pressure in N/m",
        )?,
    })
}

/// What the supports cannot carry, as (key, message): a radial pressure on a rod on the
/// axis, and a tilted support that holds the tips' translations while its axial position
/// is free (the tips' heights would then have no common centre to turn about).
pub(super) fn combination_error(
    parameter: Component,
    control: Control,
    hold: &Held,
    geometry: &Geometry,
    boundary: &BoundaryConditions,
) -> Option<(&'static str, &'static str)> {
    let pressed = parameter == Component::Pressure || hold.pressure != 0.0;
    if pressed && geometry.radius == 0.0 {
        return Some((
            "loading.parameter",
            "a radial pressure needs rods off the axis (geometry.radius > 0), found radius 0",
        ));
    }
    let tilted = parameter == Component::Tilt || hold.tilt != 0.0;
    let axial_free = match parameter {
        Component::Axial => control == Control::Force,
        _ => matches!(hold.axial, AxialHeld::Load(_)),
    };
    if tilted && axial_free && boundary.tip.translation != Translation::Slide {
        return Some((
            "loading.hold.axial_force",
            "a tilted tip support with a free axial position needs boundary.tip.translation = \"slide\" (or hold.axial instead)",
        ));
    }
    None
}

fn check_combination(
    parameter: Component,
    control: Control,
    hold: &Held,
    geometry: &Geometry,
    boundary: &BoundaryConditions,
    ck: &Checker,
) -> Result<(), CaseError> {
    match combination_error(parameter, control, hold, geometry, boundary) {
        Some((key, message)) => Err(CaseError::Invalid {
            file: ck.file.to_string(),
            line: ck.line_of_key(key.rsplit('.').next().unwrap_or(key)),
            key: key.to_string(),
            message: message.to_string(),
        }),
        None => Ok(()),
    }
}
