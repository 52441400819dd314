//! The cell of an infinitely long tube (docs/theory.md §8): an infinite assembly of `n = 2m`
//! helices is invariant under the rotation `R` by `2π/m` about the axis and under the screw
//! `S` (a turn by `π/m` with a rise `π b/m`) that carries a crossing onto the next one
//! along a rod. One right and one left rod segment from a crossing to its image under the
//! screw, arc length `π c/m` each, make a cell: cell `(j, l)` of the tube is `R^j S^l`
//! applied to it. The right segment's far end is the near end of cell `(0, 1)`, the left
//! segment's that of cell `(−1, 1)` (`S` maps left rod `L_j` to `L_{j−1}`).

use super::assembly::{Assembly, Joint};
use super::helix::{Chirality, Helix};
use std::f64::consts::PI;

/// The helical periodicity of a cell: per rod, the screw that carries its near end onto
/// its far end (a turn about z and the cell's rise, the same for every rod), and the
/// sector of the cell whose near end that far end is.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// Sectors `m` of the rotational symmetry (1 for a one-rod cell).
    pub m: usize,
    /// Per rod: the turn (rad) about z of the screw carrying its near end onto its far end.
    pub turns: Vec<f64>,
    /// Per rod: the sector `j` (`0 … m − 1`) of the cell `(j, 1)` its far end begins.
    pub far_sectors: Vec<usize>,
}

impl Cell {
    /// The Bloch phase (rad) of rod `rod`'s far end in the perturbation of circumferential
    /// wavenumber `p` and axial Bloch phase `k` (rad per cell): `k + 2π p j/m`, `j` the
    /// sector of the cell the far end begins.
    pub fn far_phase(&self, rod: usize, p: usize, k: f64) -> f64 {
        let j = (p * self.far_sectors[rod]) % self.m;
        k + 2.0 * PI * j as f64 / self.m as f64
    }

    /// The axial Bloch phase (rad per cell, in `[0, 2π)`) at which the tube's rigid
    /// translation across its axis lives (with `p = 1 mod m`): the turn of the screw.
    pub fn translation_phase(&self) -> f64 {
        self.turns[0].rem_euclid(2.0 * PI)
    }

    /// The phase (rad) of a joint tying the cell to the image of a rod turned by `turn`
    /// about z, in the perturbation of wavenumber `p`: `2π p r/m`, `r` the image's sector.
    pub fn sector_phase(&self, turn: f64, p: usize) -> f64 {
        let m = self.m as f64;
        let r = (turn * m / (2.0 * PI)).round().rem_euclid(m) as usize;
        2.0 * PI * ((p * r) % self.m) as f64 / m
    }

    /// The circumferential wavenumber of the rigid translation across the axis.
    pub fn translation_wavenumber(&self) -> usize {
        1 % self.m
    }
}

/// Why a cell cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum CellError {
    #[error("a tube cell needs n = 2m helices (m ≥ 1) off the axis, found n = {n} and radius {radius} m")]
    NotATube { n: usize, radius: f64 },
    #[error("a one-rod cell needs a straight rod (radius 0) of positive length, found radius {radius} m and length {length} m")]
    NotStraight { radius: f64, length: f64 },
}

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
            }),
        })
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
