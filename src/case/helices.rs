//! The checks of a case that depend on its number of helices, shared by the case reader (a
//! file's `geometry.helices`) and by what changes the number of an accepted case (a
//! session's start action): the number itself, the straight rod, the pin joints the number
//! makes and the elements per turn they leave.

use super::limits::{
    estimated_joints, num, MAX_ELEMENTS_PER_TURN, MAX_JOINTS, MIN_ELEMENTS_PER_TURN,
};
use super::settings::Geometry;

/// The numbers of helices a case may have: 1, or an even number in this range.
pub const HELICES_RANGE: (i64, i64) = (1, 1024);

/// A value the case reader refuses: the key of a case file it belongs to and what was
/// expected and found.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("key `{key}`: {message}")]
pub struct Refused {
    pub key: &'static str,
    pub message: String,
}

/// Why `n` is not a number of helices: out of [`HELICES_RANGE`], or odd above 1.
pub(super) fn helices_message(n: i64) -> Option<String> {
    let (min, max) = HELICES_RANGE;
    if !(min..=max).contains(&n) {
        Some(format!(
            "expected a number of helices from {min} to {max}, found {n}"
        ))
    } else if n > 1 && n % 2 == 1 {
        Some(format!(
            "expected 1 or an even number (pairs of right- and left-handed helices), found {n}"
        ))
    } else {
        None
    }
}

/// Why the geometry's helices cannot be straight rods (radius 0 needs one helix).
pub(super) fn straight_rod_message(geometry: &Geometry) -> Option<String> {
    (geometry.radius == 0.0 && geometry.helices > 1).then(|| {
        format!(
            "a straight rod (radius 0) needs helices = 1, found {}",
            geometry.helices
        )
    })
}

/// Why the geometry has too many pin joints (more than [`MAX_JOINTS`]).
pub(super) fn joints_message(geometry: &Geometry) -> Option<String> {
    let joints = estimated_joints(geometry);
    (joints > MAX_JOINTS as f64).then(|| {
        format!(
            "{} helices of {} turns would have about {} pin joints; expected at most {MAX_JOINTS} (fewer helices or turns)",
            geometry.helices,
            num(geometry.turns()),
            num(joints.round())
        )
    })
}

/// Why `elements` per rod (and a vertex at every joint) make too few or too many elements
/// per turn of the geometry's helices.
pub(super) fn elements_message(geometry: &Geometry, elements: usize) -> Option<String> {
    if geometry.radius <= 0.0 {
        return None;
    }
    let per_rod =
        elements as f64 + estimated_joints(geometry) / (geometry.helices / 2).max(1) as f64;
    let per_turn = per_rod / geometry.turns();
    (!(MIN_ELEMENTS_PER_TURN..=MAX_ELEMENTS_PER_TURN).contains(&per_turn)).then(|| {
        format!(
            "expected from {MIN_ELEMENTS_PER_TURN} to {MAX_ELEMENTS_PER_TURN} elements per turn of helix, found {} ({elements} elements per rod over {} turns)",
            num(per_turn),
            num(geometry.turns())
        )
    })
}
