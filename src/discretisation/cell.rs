//! The cell of an infinite tube discretised (docs/theory.md §8): its helically periodic
//! conditions as linear constraints, the gauge that fixes its rigid motions, its natural
//! state centred on the axis, and the Bloch blocks `H(p, k)` of its KKT matrix.
//!
//! Each rod of the cell keeps its far-end vertex and quaternion node as unknowns, tied to
//! the screw image of its near end: `r_far = R_ψ r_near + h e_z` (three rows: x and y held
//! at zero, z at the cell's rise `h`, the axial motion the load parameter drives) and
//! `Im(w̄ ∘ (q_far − σ q_ψ ∘ q_near)) = 0` with `w = q_ψ ∘ q_near` at the state the rows are
//! built at (three rows, linear: with both unit norms they hold `q_far = σ q_ψ ∘ q_near`
//! exactly, as a clamp holds a frame). The rows are the far end's "support": their
//! multipliers are the force and moment the next cell applies to the rod.

use super::constraints::{LinearConstraint, Role};
use super::discrete_model::{DiscreteModel, End};
use super::system::System;
use crate::model::cell::Cell;
use crate::model::quaternion::{self, Quat};
use crate::model::symmetry::TurnZ;
use faer::c64;
use std::f64::consts::PI;

/// Quadratic elements per rod of the cell of a tube of `n` helices by default: `128/n`, at
/// least 8 — 64 per turn of the helix for n ≤ 16 (the cell's rods are `1/n` of a turn), so
/// that the cell's axial force is Love's to 1e-9 and below.
pub fn default_elements(n: usize) -> usize {
    (128 / n.max(1)).max(8)
}

/// `rows[i][k] = ∂ Im(w̄ ∘ q)_i / ∂q_k`: the rows by which a frame near `w` is held.
fn held_rows(w: &Quat) -> [[f64; 4]; 3] {
    let conj = quaternion::conj(w);
    std::array::from_fn(|i| {
        std::array::from_fn(|k| {
            let mut ek = Quat::zeros();
            ek[k] = 1.0;
            quaternion::mul(&conj, &ek)[i]
        })
    })
}

/// A constraint of the given terms (zero coefficients dropped).
fn row(terms: Vec<(usize, f64)>, value: f64, role: Role) -> LinearConstraint {
    LinearConstraint {
        terms: terms.into_iter().filter(|t| t.1.abs() > 1e-15).collect(),
        value,
        role,
        moving: None,
    }
}

/// The constraints of a cell in the state `x`: the gauge of its rigid motions, the pin
/// joints inside it and the periodic conditions of every rod, its rise held at `height`
/// (m; at its value in `x` when `None`).
pub(super) fn cell_constraints(
    model: &DiscreteModel,
    x: &[f64],
    cell: &Cell,
    height: Option<f64>,
    out: &mut Vec<LinearConstraint>,
) {
    gauge(model, x, out);
    for (j, joint) in model.assembly.joints.iter().enumerate() {
        let (ri, rj) = (&model.rods[joint.right], &model.rods[joint.left]);
        let (Some(vi), Some(vj)) = (ri.mesh.vertex_at(joint.s), rj.mesh.vertex_at(joint.s)) else {
            continue;
        };
        // r_right − Rot(turn) r_left = 0, held at its value in `x`
        let turn = TurnZ::new(joint.left_turn);
        let a = model.vertex(x, joint.right, vi);
        let b = model.vertex(x, joint.left, vj);
        let b = turn.apply([b[0], b[1], b[2]]);
        for i in 0..3 {
            let mut terms = vec![(ri.r_dof(vi, i), 1.0)];
            for k in 0..3 {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                terms.push((rj.r_dof(vj, k), -turn.apply(e)[i]));
            }
            out.push(row(terms, a[i] - b[i], Role::Joint(j)));
        }
    }
    for (id, rod) in model.rods.iter().enumerate() {
        let turn = TurnZ::new(cell.turns[id]);
        let (v, node) = (rod.end_vertex(End::Tip), rod.end_node(End::Tip));
        let tip = Role::Support {
            rod: id,
            end: End::Tip,
        };
        for i in 0..2 {
            let mut terms = vec![(rod.r_dof(v, i), 1.0)];
            for j in 0..2 {
                let mut e = [0.0; 3];
                e[j] = 1.0;
                terms.push((rod.r_dof(0, j), -turn.apply(e)[i]));
            }
            out.push(row(terms, 0.0, tip));
        }
        let terms = vec![(rod.r_dof(v, 2), 1.0), (rod.r_dof(0, 2), -1.0)];
        match height {
            Some(h) => out.push(row(terms, h, Role::TipHeight { rod: id })),
            None => {
                let rise = model.vertex(x, id, v)[2] - model.vertex(x, id, 0)[2];
                out.push(row(terms, rise, tip));
            }
        }
        let near = model.quaternion(x, id, 0);
        let far = model.quaternion(x, id, node);
        let w = turn.rotate(&near);
        let w = w / w.norm();
        let sigma = if far.dot(&w) < 0.0 { -1.0 } else { 1.0 };
        let rows = held_rows(&w);
        let turned: [Quat; 4] = std::array::from_fn(|k| {
            let mut ek = Quat::zeros();
            ek[k] = 1.0;
            turn.rotate(&ek)
        });
        for held in rows {
            let mut terms: Vec<(usize, f64)> =
                (0..4).map(|k| (rod.q_dof(node, k), held[k])).collect();
            for (k, tk) in turned.iter().enumerate() {
                let c: f64 = (0..4).map(|l| held[l] * tk[l]).sum();
                terms.push((rod.q_dof(0, k), -sigma * c));
            }
            out.push(row(terms, 0.0, tip));
        }
    }
}

/// The gauge of a cell's rigid motions, on rod 0's near end: its height, and its azimuth
/// (y, the vertex being at azimuth 0) off the axis; on the axis x, y and the twist of its
/// frame about the axis.
fn gauge(model: &DiscreteModel, x: &[f64], out: &mut Vec<LinearConstraint>) {
    let rod = &model.rods[0];
    let r = model.vertex(x, 0, 0);
    let base = Role::Support {
        rod: 0,
        end: End::Base,
    };
    out.push(row(vec![(rod.r_dof(0, 2), 1.0)], r[2], base));
    out.push(row(vec![(rod.r_dof(0, 1), 1.0)], r[1], base));
    if rod.helix.is_straight() {
        out.push(row(vec![(rod.r_dof(0, 0), 1.0)], r[0], base));
        let held = model.quaternion(x, 0, 0);
        let held = held / held.norm();
        let rh = quaternion::rotation(&held);
        let rows = held_rows(&held);
        let twist: Vec<(usize, f64)> = (0..4)
            .map(|k| {
                (
                    rod.q_dof(0, k),
                    (0..3).map(|i| rh[(2, i)] * rows[i][k]).sum(),
                )
            })
            .collect();
        out.push(row(twist, 0.0, base));
    }
}

/// Moves every helical rod of a cell's primal state `x` across the axis so that its far
/// vertex is the screw image of its near one: the discrete helix, whose vertices its chords
/// place, is a regular polygon about an axis a rounding away from z.
pub(super) fn centre_on_axis(model: &DiscreteModel, cell: &Cell, x: &mut [f64]) {
    for (id, rod) in model.rods.iter().enumerate() {
        if rod.helix.is_straight() {
            continue;
        }
        let turn = TurnZ::new(cell.turns[id]);
        let (v0, ve) = (
            model.vertex(x, id, 0),
            model.vertex(x, id, rod.mesh.elements()),
        );
        let image = turn.apply([v0[0], v0[1], 0.0]);
        // (I − R) c = v_far − R v_near in x–y
        let (b0, b1) = (ve[0] - image[0], ve[1] - image[1]);
        let (cos, sin) = (cell.turns[id].cos(), cell.turns[id].sin());
        let (a00, a01, a10, a11) = (1.0 - cos, sin, -sin, 1.0 - cos);
        let det = a00 * a11 - a01 * a10;
        if det.abs() < 1e-12 {
            continue;
        }
        let c = [(a11 * b0 - a01 * b1) / det, (a00 * b1 - a10 * b0) / det];
        for v in 0..=rod.mesh.elements() {
            for k in 0..2 {
                x[rod.r_dof(v, k)] -= c[k];
            }
        }
    }
}

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
}

impl CellBlocks {
    /// The blocks of a cell's system (`None` for a model that is not a cell).
    pub fn new(model: &DiscreteModel, system: &System) -> Option<CellBlocks> {
        let cell = model.assembly.cell.clone()?;
        let pattern = system.pattern();
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        let entry = |row: usize, col: usize| {
            let rows = &ri[cp[col]..cp[col + 1]];
            cp[col]
                + rows
                    .binary_search(&row)
                    .expect("cell entry in the KKT pattern")
        };
        let mut entries = vec![Entry::Plain; ri.len()];
        for (i, c) in system.linear.iter().enumerate() {
            let r = system.linear_row(i);
            let mark = match c.role {
                Role::Support { rod, end: End::Tip } | Role::TipHeight { rod } => Some(rod),
                Role::Support { end: End::Base, .. } => {
                    let azimuth = c.terms.len() == 1 && c.terms[0].0 == model.rods[0].r_dof(0, 1);
                    let g = Entry::Gauge {
                        translation: azimuth,
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
        Some(CellBlocks { cell, entries })
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

    /// Whether block `(p, k)` holds the tube's rigid translation across its axis (a zero
    /// eigenvalue, which its gauge row removes).
    pub fn holds_translation(&self, p: usize, k: f64) -> bool {
        self.keeps_gauge(p, k, true) && !self.keeps_gauge(p, k, false)
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
        rigid || across
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
