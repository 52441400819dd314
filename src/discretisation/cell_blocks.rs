//! The Bloch blocks `H(p, k)` of the KKT matrix of a cell of an infinite tube
//! (docs/theory.md §8), built on the rows of [`super::cell`].

use super::constraints::Role;
use super::discrete_model::{DiscreteModel, End};
use super::system::System;
use crate::model::cell::Cell;
use faer::c64;
use std::f64::consts::PI;

/// What a stored entry of the cell's KKT pattern becomes in a Bloch block.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Entry {
    /// The same in every block.
    Plain,
    /// A periodic row's coupling to rod `rod`'s near end: times `e^{±iθ}`, `θ` that rod's
    /// far-end phase (`+` on the row, `−` on its transpose).
    Phased { rod: usize, sign: f64 },
    /// A joint row's coupling to the image of its left rod turned by `turn` about z:
    /// times `e^{±2πipr/m}`, `r` the image's sector.
    Sector { turn: f64, sign: f64 },
    /// A gauge row's coupling: kept in the block of the rigid motions (`p = 0`, `k = 0`),
    /// and, for the azimuthal row, in that of the translation across the axis.
    Gauge { translation: bool },
    /// A row holding the contacts' arc lengths on the rods of one hand: kept in the blocks
    /// where a rod moves at no cost between uniform helices, turning about the axis and
    /// rising along it alone, its contacts sliding along it and the rods it crosses (a right
    /// rod lies in the cells of one sector, `k = 0`; a left rod passes to the next sector
    /// back in every cell, `k = 2πp/m`): two motions a rod, which the two rows hold.
    Conveyor,
}

/// The Bloch blocks `H(p, k)` of a cell's KKT matrix (docs/theory.md §8): a perturbation
/// of circumferential wavenumber `p` (`0 … m − 1`) and axial Bloch phase `k` (rad per cell)
/// is `e^{i(2πpj/m + kl)} U` in cell `(j, l)` (in its own frame); the block is the cell's KKT
/// matrix with each periodic row's coupling to its rod's near end times `e^{iθ}`, `θ` the
/// phase of the cell the far end begins, and the conjugate on the transposes. The gauge
/// rows are kept only where the motions they hold are perturbations of the block.
#[derive(Clone, Debug)]
pub struct CellBlocks {
    cell: Cell,
    entries: Vec<Entry>,
    /// Whether the cell's crossings slide (rows on the contacts among its gauge).
    sliding: bool,
}

impl CellBlocks {
    /// The blocks of a cell's system (`None` for a model that is not a cell).
    pub fn new(model: &DiscreteModel, system: &System) -> Option<CellBlocks> {
        let cell = model.assembly.cell.clone()?;
        // a bending cell of several rods, or a cell under a tilt, has no blocks of this form
        let own = cell.partners.iter().enumerate().all(|(i, &p)| i == p);
        if !own || system.loads().tilts() {
            return None;
        }
        let entry = |row: usize, col: usize| system.entry(row, col);
        let mut entries = vec![Entry::Plain; system.nnz()];
        for (i, c) in system.linear.iter().enumerate() {
            let r = system.linear_row(i);
            let mark = match c.role {
                Role::Support { rod, end: End::Tip } | Role::TipHeight { rod } => Some(rod),
                Role::Support { end: End::Base, .. } => {
                    let azimuth = c.terms.len() == 1 && c.terms[0].0 == model.rods[0].r_dof(0, 1);
                    let side_of = |d: usize| {
                        (0..model.slides.len())
                            .flat_map(|k| [0, 1].map(|side| (k, side)))
                            .find(|&(k, side)| model.slide_dof(k, side) == d)
                            .map(|(_, side)| side)
                    };
                    let g = match c.terms.first().and_then(|&(d, _)| side_of(d)) {
                        Some(_) => Entry::Conveyor,
                        None => Entry::Gauge {
                            translation: azimuth,
                        },
                    };
                    for &(d, _) in &c.terms {
                        entries[entry(r, d)] = g;
                        entries[entry(d, r)] = g;
                    }
                    None
                }
                Role::Joint(j) => {
                    let joint = model.assembly.joints[j];
                    let left = &model.rods[joint.left];
                    let dofs = left.q_offset..left.r_offset + 3 * (left.mesh.elements() + 1);
                    for &(d, _) in c.terms.iter().filter(|(d, _)| dofs.contains(d)) {
                        let turn = joint.left_turn;
                        entries[entry(r, d)] = Entry::Sector { turn, sign: 1.0 };
                        entries[entry(d, r)] = Entry::Sector { turn, sign: -1.0 };
                    }
                    None
                }
                _ => None,
            };
            let Some(rod) = mark else { continue };
            let near = &model.rods[rod];
            let near_dofs = [
                near.q_dof(0, 0),
                near.q_dof(0, 1),
                near.q_dof(0, 2),
                near.q_dof(0, 3),
            ]
            .into_iter()
            .chain((0..3).map(|k| near.r_dof(0, k)))
            .collect::<Vec<_>>();
            for &(d, _) in c.terms.iter().filter(|(d, _)| near_dofs.contains(d)) {
                entries[entry(r, d)] = Entry::Phased { rod, sign: 1.0 };
                entries[entry(d, r)] = Entry::Phased { rod, sign: -1.0 };
            }
        }
        // a sliding joint's multipliers and both contacts' arc lengths are unknowns of the
        // cell: its rows and the left contact's arc length couple to the positions and
        // quaternions of the left rod's image in the window (`ν · ∂r_L`, `ν · ∂²r_L/∂s∂q`),
        // which take the image's sector phase; the terms `ν · ∂²r_L/∂q∂q` are of the image
        // alone and take none
        for (k, slide) in system.slides.iter().enumerate() {
            let turn = slide.turn;
            for (row, d) in slide.image_entries(model, system.slide_row(k)) {
                entries[entry(row, d)] = Entry::Sector { turn, sign: 1.0 };
                entries[entry(d, row)] = Entry::Sector { turn, sign: -1.0 };
            }
        }
        let sliding = entries.contains(&Entry::Conveyor);
        Some(CellBlocks {
            cell,
            entries,
            sliding,
        })
    }

    /// The cell's periodicity.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }

    /// Whether block `(p, k)` is real: every phase `0` or `π` (`k = 0` or `π`, `2p = 0 mod m`).
    pub fn is_real(&self, p: usize, k: f64) -> bool {
        let on_axis = k == 0.0 || (k - PI).abs() < 1e-14;
        on_axis && (2 * p) % self.cell.m == 0
    }

    /// Whether block `(p, k)` holds the tube's rigid translation across its axis, or with
    /// sliding crossings the rods' translations along the tube's surface (`p = 0`,
    /// `k = ψ`): motions of no energy and no metric, which its azimuthal gauge row holds.
    pub fn holds_translation(&self, p: usize, k: f64) -> bool {
        self.keeps_gauge(p, k, true) && !self.keeps_gauge(p, k, false)
    }

    /// The neutral modes of block `(p, k)` that turn frames and that its gauge rows hold at
    /// points, each as the rods of the cell that turn together about the axis
    /// ([`super::cell::turning_mode`]): the cell's rigid rotation in the block of rigid
    /// motions (`p = 0`, `k = 0`); with sliding crossings each rod turning alone instead,
    /// in the blocks where it moves alone ([`CellBlocks::moves_alone`]) and the rows on the
    /// contacts are kept. (The rigid rise and a rod rising alone turn no frame: held
    /// at a point, they shift nothing.)
    pub fn turning_rods(&self, p: usize, k: f64) -> Vec<Vec<usize>> {
        let rods = self.cell.turns.len();
        if !self.sliding {
            return if self.keeps_gauge(p, k, false) {
                vec![(0..rods).collect()]
            } else {
                Vec::new()
            };
        }
        (0..rods)
            .filter(|&rod| self.moves_alone(rod, p, k))
            .map(|rod| vec![rod])
            .collect()
    }

    /// Whether the gauge rows of kind `translation` are kept in block `(p, k)`.
    fn keeps_gauge(&self, p: usize, k: f64, translation: bool) -> bool {
        let same = |a: f64, b: f64| {
            let d = (a - b).rem_euclid(2.0 * PI);
            d.min(2.0 * PI - d) < 1e-9
        };
        let rigid = p == 0 && same(k, 0.0);
        // the translation across the axis: (1, ψ) and its conjugate (m − 1, −ψ)
        let (m, psi) = (self.cell.m, self.cell.translation_phase());
        let across =
            translation && ((p == 1 % m && same(k, psi)) || (p == (m - 1) % m && same(k, -psi)));
        // with sliding crossings, the rods translating along the tube's surface: at (0, ±ψ)
        // every rod translates rigidly (in the cell's frame, one circular polarisation for
        // the right rods, the other for the left), the two rods' difference at every
        // crossing azimuthal, in the tube's tangent plane, so that the contacts slide: no
        // energy, no frame turned (its value written 0, as the translation's)
        let along = translation && self.sliding && p == 0 && (same(k, psi) || same(k, -psi));
        rigid || across || along
    }

    /// Whether the rows holding the contacts are kept in block `(p, k)`: where a rod's own
    /// motions live ([`CellBlocks::moves_alone`]).
    fn keeps_conveyor(&self, p: usize, k: f64) -> bool {
        (0..self.cell.turns.len()).any(|rod| self.moves_alone(rod, p, k))
    }

    /// Whether rod `rod` moving alone (turning about the axis and rising, its contacts
    /// sliding: the same in every cell along it) is a perturbation of block `(p, k)`: its
    /// far end's phase is 0 (a right rod of the cell at `k = 0`, a left one, whose far end
    /// begins the sector behind, at `k = 2πp/m`).
    fn moves_alone(&self, rod: usize, p: usize, k: f64) -> bool {
        let d = self.cell.far_phase(rod, p, k).rem_euclid(2.0 * PI);
        d.min(2.0 * PI - d) < 1e-9
    }

    /// The complex Hermitian block `(p, k)` from the cell's KKT values `kkt`, in the cell's
    /// pattern.
    pub fn hermitian_block(&self, p: usize, k: f64, kkt: &[f64], out: &mut [c64]) {
        let phases: Vec<(f64, f64)> = (0..self.cell.turns.len())
            .map(|rod| {
                let (s, c) = self.cell.far_phase(rod, p, k).sin_cos();
                (c, s)
            })
            .collect();
        for ((o, &v), e) in out.iter_mut().zip(kkt).zip(&self.entries) {
            *o = match *e {
                Entry::Plain => c64::new(v, 0.0),
                Entry::Phased { rod, sign } => {
                    let (c, s) = phases[rod];
                    c64::new(v * c, sign * v * s)
                }
                Entry::Sector { turn, sign } => {
                    let (s, c) = self.cell.sector_phase(turn, p).sin_cos();
                    c64::new(v * c, sign * v * s)
                }
                Entry::Conveyor => {
                    if self.keeps_conveyor(p, k) {
                        c64::new(v, 0.0)
                    } else {
                        c64::new(0.0, 0.0)
                    }
                }
                Entry::Gauge { translation } => {
                    if self.keeps_gauge(p, k, translation) {
                        c64::new(v, 0.0)
                    } else {
                        c64::new(0.0, 0.0)
                    }
                }
            };
        }
    }

    /// The real block `(p, k)` (see [`CellBlocks::is_real`]) from the cell's KKT values.
    pub fn real_block(&self, p: usize, k: f64, kkt: &[f64], out: &mut [f64]) {
        let mut complex = vec![c64::new(0.0, 0.0); kkt.len()];
        self.hermitian_block(p, k, kkt, &mut complex);
        for (o, z) in out.iter_mut().zip(&complex) {
            *o = z.re;
        }
    }
}
