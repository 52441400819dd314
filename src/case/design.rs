//! The design keys a critical curve of an accepted case may be continued in without its
//! file (the explorer's curve of the scene on screen): the number of turns, the helix
//! radius, the rod length and the torsional stiffness. Each sets the case as the key of a
//! case file would, and is refused by the limits the case reader puts on that key.

use super::helices::{elements_message, joints_message, Refused};
use super::limits::{
    num, LENGTH_RANGE, PITCH_RATIO, STIFFNESS_RANGE, STIFFNESS_RATIO, TURNS_RANGE,
};
use super::settings::Geometry;
use crate::model::stiffness::Stiffness;
use std::f64::consts::PI;

/// A numeric key of the design, as a case file names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DesignKey {
    /// `geometry.turns`: turns `L/(2π c)` of every helix, its radius and pitch held (the
    /// rod length follows).
    Turns,
    /// `geometry.radius`: helix radius `a` (m), the turns and pitch held (the rod length
    /// follows), as in a case file that gives `turns`.
    Radius,
    /// `geometry.length`: rod length `L` (m), the radius and pitch held.
    Length,
    /// `stiffness.b3`: torsional stiffness `B3` (N m²), the bending stiffnesses held, so the
    /// ratio `B3/B1` varies with it.
    TorsionalStiffness,
}

impl DesignKey {
    /// The keys in the order the explorer cycles through them.
    pub const ALL: [DesignKey; 4] = [
        DesignKey::Turns,
        DesignKey::Radius,
        DesignKey::Length,
        DesignKey::TorsionalStiffness,
    ];

    /// The dotted key of a case file.
    pub fn key(self) -> &'static str {
        match self {
            DesignKey::Turns => "geometry.turns",
            DesignKey::Radius => "geometry.radius",
            DesignKey::Length => "geometry.length",
            DesignKey::TorsionalStiffness => "stiffness.b3",
        }
    }

    /// The quantity as a label says it, with its unit.
    pub fn label(self) -> &'static str {
        match self {
            DesignKey::Turns => "turns",
            DesignKey::Radius => "radius a (m)",
            DesignKey::Length => "length L (m)",
            DesignKey::TorsionalStiffness => "B3 (N m², B1 held)",
        }
    }

    /// The next key of [`DesignKey::ALL`], round.
    pub fn next(self) -> DesignKey {
        let k = DesignKey::ALL.iter().position(|&d| d == self).unwrap_or(0);
        DesignKey::ALL[(k + 1) % DesignKey::ALL.len()]
    }

    /// Whether `geometry` has this key to vary (a straight rod has no turns or radius).
    pub fn applies(self, geometry: &Geometry) -> bool {
        geometry.radius > 0.0 || !matches!(self, DesignKey::Turns | DesignKey::Radius)
    }

    /// The key's value in `geometry` and `stiffness`.
    pub fn value(self, geometry: &Geometry, stiffness: &Stiffness) -> f64 {
        match self {
            DesignKey::Turns => geometry.turns(),
            DesignKey::Radius => geometry.radius,
            DesignKey::Length => geometry.length,
            DesignKey::TorsionalStiffness => stiffness.b3,
        }
    }
}

/// Sets the design key `key` to `value` in `geometry` and `stiffness`, refused as the case
/// reader would refuse the key's value in a file, with `elements` per rod when the mesh is
/// given by its count (a straight rod has no turns or radius to vary).
pub(super) fn set_design(
    key: DesignKey,
    value: f64,
    geometry: &mut Geometry,
    stiffness: &mut Stiffness,
    elements: Option<usize>,
) -> Result<(), Refused> {
    {
        let refuse = |message: String| Refused {
            key: key.key(),
            message,
        };
        let g = &mut *geometry;
        let helix = g.radius > 0.0;
        if !helix && matches!(key, DesignKey::Turns | DesignKey::Radius) {
            return Err(refuse("a straight rod has no helix to vary".into()));
        }
        let within = |r: (f64, f64)| value.is_finite() && value >= r.0 && value <= r.1;
        let expected = |what: &str, r: (f64, f64)| {
            refuse(format!(
                "expected {what} from {} to {}, found {}",
                num(r.0),
                num(r.1),
                num(value)
            ))
        };
        match key {
            DesignKey::Turns if !within(TURNS_RANGE) => {
                return Err(expected("a number of turns", TURNS_RANGE))
            }
            DesignKey::Turns => g.length = 2.0 * PI * g.c() * value,
            DesignKey::Radius if !within(LENGTH_RANGE) || !within_ratio(g.pitch / value) => {
                return Err(refuse(format!(
                    "expected a radius in m from {} to {} with a pitch/radius ratio b/a from {} to {}, found {}",
                    num(LENGTH_RANGE.0),
                    num(LENGTH_RANGE.1),
                    PITCH_RATIO.0,
                    PITCH_RATIO.1,
                    num(value)
                )))
            }
            DesignKey::Radius => {
                let turns = g.turns();
                g.radius = value;
                g.length = 2.0 * PI * g.c() * turns;
            }
            DesignKey::Length if !within(LENGTH_RANGE) => {
                return Err(expected("a rod length in m", LENGTH_RANGE))
            }
            DesignKey::Length => g.length = value,
            DesignKey::TorsionalStiffness => {
                let ratio = value / stiffness.b1;
                if !within(STIFFNESS_RANGE)
                    || !(STIFFNESS_RATIO.0..=STIFFNESS_RATIO.1).contains(&ratio)
                {
                    return Err(expected("a torsional stiffness in N m²", STIFFNESS_RANGE));
                }
                stiffness.b3 = value;
            }
        }
        let g = &*geometry;
        if !(LENGTH_RANGE.0..=LENGTH_RANGE.1).contains(&g.length) {
            return Err(refuse(format!(
                "the rod length L would be {} m; expected L from {} to {} m",
                num(g.length),
                num(LENGTH_RANGE.0),
                num(LENGTH_RANGE.1)
            )));
        }
        if helix {
            if let Some(m) = joints_message(g) {
                return Err(refuse(m));
            }
            if let Some(m) = elements.and_then(|e| elements_message(g, e)) {
                return Err(refuse(m));
            }
        }
        Ok(())
    }
}

fn within_ratio(r: f64) -> bool {
    r.is_finite() && (PITCH_RATIO.0..=PITCH_RATIO.1).contains(&r)
}
