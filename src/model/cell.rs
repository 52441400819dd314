//! The cell of an infinitely long tube (docs/theory.md §8): an infinite assembly of `n = 2m`
//! helices is invariant under the rotation `R` by `2π/m` about the axis and under the screw
//! `S` (a turn by `π/m` with a rise `π b/m`) that carries a crossing onto the next one
//! along a rod. One right and one left rod segment from a crossing to its image under the
//! screw, arc length `π c/m` each, make a cell: cell `(j, l)` of the tube is `R^j S^l`
//! applied to it. The right segment's far end is the near end of cell `(0, 1)`, the left
//! segment's that of cell `(−1, 1)` (`S` maps left rod `L_j` to `L_{j−1}`).

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
    /// Per rod: the rod of the cell whose near end its far end is the image of (itself,
    /// except in a bending cell).
    pub partners: Vec<usize>,
    /// A bending cell: the whole pattern over its axial period, periodic under a pure
    /// translation along the axis (a turn of its frames about the axis for a straight rod),
    /// which a tilt turns into a rotation about a transverse axis (docs/theory.md §8).
    pub bending: bool,
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

    /// The number of cells that make one rise of the whole tube's section (N m per cell to
    /// the tube's): `m` for a cell of one right and one left rod (one sector of `m`), 1 for
    /// a bending cell (all the rods) and a one-rod cell.
    pub fn sectors(&self) -> f64 {
        if self.bending {
            1.0
        } else {
            self.m as f64
        }
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
    #[error("a bending cell needs n = 2m helices with m ≥ 2 off the axis (its section's centre is the mean of its m crossings), found n = {n} and radius {radius} m")]
    NotABendingTube { n: usize, radius: f64 },
    #[error("a one-rod cell needs a straight rod (radius 0) of positive length, found radius {radius} m and length {length} m")]
    NotStraight { radius: f64, length: f64 },
}
