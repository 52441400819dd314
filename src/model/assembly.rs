//! Tubular assemblies of helices and their pin joints (docs/theory.md §2).

use super::cell::{Cell, CellError};
use super::helix::{Chirality, Helix};
use super::symmetry::{Symmetry, SymmetryError};
use std::f64::consts::PI;

/// Handle of a rod in an assembly (index into [`Assembly::rods`]).
pub type RodId = usize;

/// A pin joint: rod `right` at arc length `s` coincides with rod `left` at the same `s`,
/// turned by `left_turn` about z (zero in a full assembly; in a symmetry-reduced one the
/// partner is an image of `left`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    pub right: RodId,
    pub left: RodId,
    /// Arc length of the crossing on both rods (m).
    pub s: f64,
    /// Rotation (rad) about z of the left rod's image that the joint ties.
    pub left_turn: f64,
}

/// The natural (stress-free) geometry of an assembly of `n` helices of equal radius,
/// pitch and length, all based on the plane z = 0.
#[derive(Clone, Debug)]
pub struct Assembly {
    pub rods: Vec<Helix>,
    /// Rod length `L` (m).
    pub length: f64,
    pub joints: Vec<Joint>,
    /// Set when the rods are one right/left pair standing for a symmetric assembly.
    pub symmetry: Option<Symmetry>,
    /// Set when the rods are the cell of an infinitely long tube (docs/theory.md §8).
    pub cell: Option<Cell>,
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
            symmetry: None,
            cell: None,
        }
    }

    /// The symmetric pair standing for this assembly of `n = 2m` helices (`m ≥ 2`): rods
    /// `R_0` and `L_0`, and the joints of `R_0`, each tied to the image of `L_0` that is
    /// its partner (every other joint is an image of one of these).
    pub fn symmetric_pair(&self) -> Result<Assembly, SymmetryError> {
        let n = self.rods.len();
        if n < 4 || n % 2 == 1 || self.symmetry.is_some() || self.cell.is_some() {
            return Err(SymmetryError::TooFewHelices { n });
        }
        let m = n / 2;
        let joints = self
            .joints
            .iter()
            .filter(|j| j.right == 0)
            .map(|j| Joint {
                right: 0,
                left: 1,
                s: j.s,
                // L_j is L_0 turned by −t_j (left-handed azimuths run backwards)
                left_turn: -self.rods[j.left].base_angle,
            })
            .collect();
        Ok(Assembly {
            rods: vec![self.rods[0], self.rods[m]],
            length: self.length,
            joints,
            symmetry: Some(Symmetry { m }),
            cell: None,
        })
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
            symmetry: None,
            cell: None,
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
                    left_turn: 0.0,
                });
                k += 1;
            }
        }
    }
    joints.sort_by(|a, b| a.s.total_cmp(&b.s).then(a.right.cmp(&b.right)));
    joints
}

/// The cells of infinite tubes and rods (docs/theory.md §8).
impl Assembly {
    /// The cell of the infinite tube of `n = 2m` helices of radius `a` and pitch parameter
    /// `b` (m): rods `R_0` and `L_0` (base angle 0) over the arc length `π c/m`, crossing at
    /// their near ends (the crossing at their far ends is the screw image of that one).
    pub fn tube_cell(n: usize, radius: f64, pitch: f64) -> Result<Assembly, CellError> {
        Assembly::tube_cells(n, radius, pitch, 1)
    }

    /// `cells` cells of the infinite tube stacked along the screw and closed on themselves
    /// (the cell of the tube seen with `S^cells` as its screw): `R_0` and `L_0` over
    /// `cells · π c/m`, `R_0` crossing the image `L_{−l} = R^l L_0` at `s = l π c/m`.
    pub fn tube_cells(
        n: usize,
        radius: f64,
        pitch: f64,
        cells: usize,
    ) -> Result<Assembly, CellError> {
        if n < 2 || n % 2 == 1 || radius <= 0.0 || !radius.is_finite() || cells == 0 {
            return Err(CellError::NotATube { n, radius });
        }
        let m = n / 2;
        let helix = |chirality| Helix {
            radius,
            pitch,
            chirality,
            base_angle: 0.0,
        };
        let right = helix(Chirality::Right);
        let step = PI * right.c() / m as f64;
        let turn = PI / m as f64 * cells as f64;
        let joints = (0..cells)
            .map(|l| Joint {
                right: 0,
                left: 1,
                s: step * l as f64,
                left_turn: 2.0 * PI * (l % m) as f64 / m as f64,
            })
            .collect();
        Ok(Assembly {
            rods: vec![right, helix(Chirality::Left)],
            length: step * cells as f64,
            joints,
            symmetry: None,
            cell: Some(Cell {
                m,
                turns: vec![turn, -turn],
                far_sectors: vec![0, (m - cells % m) % m],
                partners: vec![0, 1],
                bending: false,
            }),
        })
    }

    /// The cell of one infinitely long helix (radius `radius`, pitch parameter `pitch`, m),
    /// alone: a right-handed segment turning by `turn` (rad, not a multiple of 2π, so that
    /// the screw holds the helix's axis) about the axis, its far end the screw image of its
    /// near end — the rod of a tube's cell without its partner, Love's helix when loaded.
    pub fn helix_cell(radius: f64, pitch: f64, turn: f64) -> Result<Assembly, CellError> {
        let whole = (turn / (2.0 * PI)).round() * 2.0 * PI;
        if radius <= 0.0 || !radius.is_finite() || !turn.is_finite() || (turn - whole).abs() < 1e-6
        {
            return Err(CellError::NotATube { n: 1, radius });
        }
        let helix = Helix {
            radius,
            pitch,
            chirality: Chirality::Right,
            base_angle: 0.0,
        };
        Ok(Assembly {
            length: turn.abs() * helix.c(),
            rods: vec![helix],
            joints: Vec::new(),
            symmetry: None,
            cell: Some(Cell {
                m: 1,
                turns: vec![turn.abs()],
                far_sectors: vec![0],
                partners: vec![0],
                bending: false,
            }),
        })
    }

    /// The cell of an infinitely long straight rod on the axis (radius 0): one rod of length
    /// `length` (m) whose far end is its near end translated along the axis, its frame
    /// turned by `turn` (rad) about it (the twist of the rod over the cell).
    pub fn straight_cell(length: f64, turn: f64) -> Result<Assembly, CellError> {
        if length <= 0.0 || !length.is_finite() || !turn.is_finite() {
            return Err(CellError::NotStraight {
                radius: 0.0,
                length,
            });
        }
        Ok(Assembly {
            rods: vec![Helix {
                radius: 0.0,
                pitch: 1.0,
                chirality: Chirality::Right,
                base_angle: 0.0,
            }],
            length,
            joints: Vec::new(),
            symmetry: None,
            cell: Some(Cell {
                m: 1,
                turns: vec![turn],
                far_sectors: vec![0],
                partners: vec![0],
                bending: true,
            }),
        })
    }

    /// The bending cell of the infinite tube of `n = 2m` helices (`m ≥ 2`) of radius `a` and
    /// pitch parameter `b` (m): all `n` rods (base angles `2πk/m`) over the arc length
    /// `2π c/m`, the tube's axial period `2π b/m` (the screw `S` twice, turned back by
    /// `2π/m`: a pure translation). It holds the crossings at `s = 0` and `π c/m` (those at
    /// its far ends are their images); right rod `R_j`'s far end is the image of `R_{j+1}`'s
    /// near end, left rod `L_j`'s of `L_{j+1}`'s.
    pub fn bending_cell(n: usize, radius: f64, pitch: f64) -> Result<Assembly, CellError> {
        if n < 4 || n % 2 == 1 || radius <= 0.0 || !radius.is_finite() {
            return Err(CellError::NotABendingTube { n, radius });
        }
        let m = n / 2;
        let c = (radius * radius + pitch * pitch).sqrt();
        let length = 2.0 * PI * c / m as f64;
        let mut assembly = Assembly::new(n, radius, pitch, length);
        assembly.joints.retain(|j| j.s < length * (1.0 - ARC_TOL));
        let partners = (0..n)
            .map(|id| {
                if id < m {
                    (id + 1) % m
                } else {
                    m + (id - m + 1) % m
                }
            })
            .collect();
        assembly.cell = Some(Cell {
            m,
            turns: vec![0.0; n],
            far_sectors: vec![0; n],
            partners,
            bending: true,
        });
        Ok(assembly)
    }

    /// The rise of the cell (m): the axial distance from a rod's near end to its far end.
    pub fn cell_rise(&self) -> Option<f64> {
        self.cell.as_ref()?;
        let h = &self.rods[0];
        Some(if h.is_straight() {
            self.length
        } else {
            h.position(self.length)[2]
        })
    }
}
