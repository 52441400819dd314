//! Tubular assemblies of helices and their pin joints (DESIGN.md §2).

use super::helix::{Chirality, Helix};
use std::f64::consts::PI;

/// Handle of a rod in an assembly (index into [`Assembly::rods`]).
pub type RodId = usize;

/// A pin joint: rod `right` at arc length `s` coincides with rod `left` at the same `s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    pub right: RodId,
    pub left: RodId,
    /// Arc length of the crossing on both rods (m).
    pub s: f64,
}

/// The natural (stress-free) geometry of an assembly of `n` helices of equal radius,
/// pitch and length, all based on the plane z = 0.
#[derive(Clone, Debug)]
pub struct Assembly {
    pub rods: Vec<Helix>,
    /// Rod length `L` (m).
    pub length: f64,
    pub joints: Vec<Joint>,
}

/// Relative tolerance on arc length when deciding that a crossing lies on a rod.
const ARC_TOL: f64 = 1e-9;

impl Assembly {
    /// `n = 1`: one right-handed helix at `t0 = 0`. `n = 2m`: `m` right- then `m`
    /// left-handed helices at `t0 = 2πk/m`, `k = 0..m`.
    pub fn new(n: usize, radius: f64, pitch: f64, length: f64) -> Assembly {
        let helix = |chirality, base_angle| Helix {
            radius,
            pitch,
            chirality,
            base_angle,
        };
        let rods: Vec<Helix> = if n == 1 {
            vec![helix(Chirality::Right, 0.0)]
        } else {
            let m = n / 2;
            let angle = |k: usize| 2.0 * PI * k as f64 / m as f64;
            (0..m)
                .map(|k| helix(Chirality::Right, angle(k)))
                .chain((0..m).map(|k| helix(Chirality::Left, angle(k))))
                .collect()
        };
        let joints = crossings(&rods, length);
        Assembly {
            rods,
            length,
            joints,
        }
    }

    /// The same assembly rotated rigidly by `angle` (rad) about the z axis: right-handed
    /// base angles grow by `angle`, left-handed ones shrink by it (their azimuth runs
    /// backwards). Joints are recomputed from the geometry.
    pub fn rotated(&self, angle: f64) -> Assembly {
        let rods: Vec<Helix> = self
            .rods
            .iter()
            .map(|h| Helix {
                base_angle: h.base_angle + h.chirality.sign() * angle,
                ..*h
            })
            .collect();
        let joints = crossings(&rods, self.length);
        Assembly {
            rods,
            length: self.length,
            joints,
        }
    }

    /// Initial height `h0` of the tips (m).
    pub fn height(&self) -> f64 {
        self.rods[0].position(self.length)[2]
    }

    /// Arc lengths of the joints on rod `id`, sorted, without duplicates.
    pub fn joint_arc_lengths(&self, id: RodId) -> Vec<f64> {
        let mut s: Vec<f64> = self
            .joints
            .iter()
            .filter(|j| j.right == id || j.left == id)
            .map(|j| j.s)
            .collect();
        s.sort_by(f64::total_cmp);
        s.dedup_by(|a, b| (*a - *b).abs() <= ARC_TOL * self.length);
        s
    }
}

/// All crossings of right- with left-handed rods on `[0, L]`: right rod `tR` meets left
/// rod `tL` at `s/c = −(tR + tL)/2 + kπ`. Same-chirality helices never cross.
pub fn crossings(rods: &[Helix], length: f64) -> Vec<Joint> {
    let mut joints = Vec::new();
    for (i, r) in rods.iter().enumerate() {
        if r.chirality != Chirality::Right {
            continue;
        }
        for (j, l) in rods.iter().enumerate() {
            if l.chirality != Chirality::Left {
                continue;
            }
            let c = r.c();
            let mut first = (-(r.base_angle + l.base_angle) / 2.0).rem_euclid(PI);
            if PI - first < 1e-12 {
                first = 0.0; // rounding of a crossing at s = 0
            }
            let tol = ARC_TOL * length;
            let mut k = 0;
            loop {
                let mut s = (first + k as f64 * PI) * c;
                if s > length + tol {
                    break;
                }
                // crossings within rounding of an end sit exactly on it
                if (s - length).abs() <= tol {
                    s = length;
                }
                if s.abs() <= tol {
                    s = 0.0;
                }
                joints.push(Joint {
                    right: i,
                    left: j,
                    s,
                });
                k += 1;
            }
        }
    }
    joints.sort_by(|a, b| a.s.total_cmp(&b.s).then(a.right.cmp(&b.right)));
    joints
}
