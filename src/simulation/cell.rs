//! The stability of a cell of the infinite tube judged by its Bloch blocks `H(p, k)`
//! (docs/theory.md §8): every circumferential wavenumber `p = 0 … m − 1` and axial Bloch
//! phases `k` on a grid of `[0, π]` (rad per cell); `(p, k)` and `(m − p, −k)` are
//! conjugate, so the grid covers every perturbation. The lowest eigenvalue over the
//! blocks, the unstable band in `k` of every `p`, and the dispersion table come from it.

use super::judge::{clearly_stable, metric, BlockStability, StabilityJudge};
use crate::discretisation::cell::turning_mode;
use crate::discretisation::cell_blocks::CellBlocks;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::mirror::Mirror;
use crate::discretisation::system::System;
use crate::solver::stability::{InertiaError, KktStability, KktStructure, Scalar, WarmStart};
use faer::c64;
use faer::sparse::SymbolicSparseColMat;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Arc;

/// Axial Bloch phases of the dispersion table: `k = iπ/64`, `i = 0 … 64`.
pub const PHASES: usize = 65;

/// Axial Bloch phases on which the stability of every state along a path is judged:
/// `k = iπ/8`, `i = 0 … 8` (the dispersion of the output states takes [`PHASES`]).
pub const PATH_PHASES: usize = 9;

/// The lowest eigenvalue of every Bloch block of a cell's state: `lowest[p][i]` (J/m, in
/// the metric of nodal rotations) at circumferential wavenumber `p` and axial Bloch phase
/// `phases[i]` (rad per cell); `None` where the search did not converge.
#[derive(Clone, Debug, PartialEq)]
pub struct Dispersion {
    pub phases: Vec<f64>,
    pub lowest: Vec<Vec<Option<f64>>>,
    /// The `(p, i)` whose block holds the tube's rigid translation across its axis (or,
    /// with sliding crossings, the rods' translations along its surface), its value written
    /// 0: neither a lowest eigenvalue nor the end of a band (the column's band of long
    /// waves lies on both sides of it).
    pub translation: Vec<(usize, usize)>,
}

/// The dispersion of a cell at one output step of a path.
#[derive(Clone, Debug, PartialEq)]
pub struct StepDispersion {
    pub step: usize,
    /// The tube's axial strain `ε` there.
    pub eps: f64,
    pub dispersion: Dispersion,
}

/// Where a band of unstable perturbations of one wavenumber opens or closes, between two
/// phases of the grid: the phase where the lowest eigenvalue, linear between them, is zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandEdge {
    pub p: usize,
    pub k: f64,
}

impl Dispersion {
    /// The lowest eigenvalue over the blocks, with its `(p, k)`.
    pub fn lowest(&self) -> Option<(f64, usize, f64)> {
        let mut best: Option<(f64, usize, f64)> = None;
        for (p, row) in self.lowest.iter().enumerate() {
            for (i, (&k, mu)) in self.phases.iter().zip(row).enumerate() {
                let Some(mu) = *mu else { continue };
                if self.translation.contains(&(p, i)) {
                    continue;
                }
                if best.is_none_or(|b| mu < b.0) {
                    best = Some((mu, p, k));
                }
            }
        }
        best
    }

    /// The unstable bands of wavenumber `p`: the intervals of `k` where its lowest
    /// eigenvalue is negative, their ends placed linearly between the grid's phases.
    pub fn unstable_bands(&self, p: usize) -> Vec<(f64, f64)> {
        let row = &self.lowest[p];
        let mut bands = Vec::new();
        let mut open: Option<f64> = None;
        for i in 0..row.len() {
            if self.translation.contains(&(p, i)) {
                continue;
            }
            let mu = row[i].unwrap_or(f64::INFINITY);
            let k = self.phases[i];
            if mu < 0.0 && open.is_none() {
                open = Some(if i == 0 { k } else { self.edge(p, i - 1) });
            }
            if mu >= 0.0 {
                if let Some(start) = open.take() {
                    bands.push((start, self.edge(p, i - 1)));
                }
            }
        }
        if let Some(start) = open {
            bands.push((start, *self.phases.last().unwrap_or(&PI)));
        }
        bands
    }

    /// The phase between grid points `i` and `i + 1` where wavenumber `p`'s lowest
    /// eigenvalue, linear between them, is zero.
    fn edge(&self, p: usize, i: usize) -> f64 {
        let (k0, k1) = (self.phases[i], self.phases[i + 1]);
        match (self.lowest[p][i], self.lowest[p][i + 1]) {
            (Some(a), Some(b)) if a != b => k0 + (k1 - k0) * a / (a - b),
            _ => k1,
        }
    }
}

/// The phases `k = iπ/(count − 1)`, `i = 0 … count − 1` (rad per cell).
pub fn phase_grid(count: usize) -> Vec<f64> {
    let n = count.max(2) - 1;
    (0..=n).map(|i| PI * i as f64 / n as f64).collect()
}

/// The Bloch blocks of a cell, judged one after the other on a grid of axial phases.
pub struct CellJudge {
    blocks: CellBlocks,
    phases: Vec<f64>,
    real: KktStability,
    complex: KktStability<c64>,
    /// The map's searches: regularised with [`DiscreteModel::stability_length`], a turn of
    /// the helices, whose counts resolve the map's eigenvalues (the path's solves keep the
    /// cell's own length).
    map: KktStability,
    /// Each rod of the cell turning about the axis at the state last evaluated: the neutral
    /// modes held out of the metric of the blocks that hold them at points
    /// ([`CellBlocks::turning_rods`]).
    rod_turns: Vec<Vec<f64>>,
    warm_real: Vec<WarmStart>,
    warm_complex: Vec<WarmStart<c64>>,
    residual: Vec<f64>,
    kkt: Vec<f64>,
    real_values: Vec<f64>,
    complex_values: Vec<c64>,
    /// The block (index `p · phases + i`) of the lowest eigenvalue found last.
    lowest_block: usize,
    focus: Option<usize>,
}

impl CellJudge {
    /// The judge of a cell's states under `system` on `phases` axial phases in `[0, π]`
    /// (`None` for a model that is not a cell).
    pub fn new(model: &DiscreteModel, system: &System, phases: usize) -> Option<CellJudge> {
        let blocks = CellBlocks::new(model, system)?;
        let phases = phase_grid(phases);
        let count = blocks.cell().m * phases.len();
        let real: KktStability = KktStability::new(metric(model), model.length());
        let complex = real.sharing();
        let map = KktStability::new(metric(model), model.stability_length());
        Some(CellJudge {
            blocks,
            phases,
            real,
            complex,
            map,
            rod_turns: Vec::new(),
            warm_real: (0..count).map(|_| WarmStart::default()).collect(),
            warm_complex: (0..count).map(|_| WarmStart::default()).collect(),
            residual: vec![0.0; system.n],
            kkt: system.new_values(),
            real_values: Vec::new(),
            complex_values: Vec::new(),
            lowest_block: 0,
            focus: None,
        })
    }

    /// The cell's KKT values at the state `x`, and its rods turning about the axis there.
    fn evaluate(&mut self, model: &DiscreteModel, system: &System, x: &[f64]) {
        system.evaluate(model, x, &mut self.residual, &mut self.kkt);
        self.rod_turns = (0..model.rods.len())
            .map(|rod| turning_mode(model, x, rod))
            .collect();
    }

    /// Blocks judged: `m` wavenumbers times the phases.
    fn count(&self) -> usize {
        self.blocks.cell().m * self.phases.len()
    }

    /// The wavenumber and phase of block `b`.
    pub fn block(&self, b: usize) -> (usize, f64) {
        (b / self.phases.len(), self.phases[b % self.phases.len()])
    }

    /// `task` on block `b` at the KKT values in `self.kkt`, as a real or complex matrix,
    /// with the block's own warm start.
    fn on_block<T>(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        b: usize,
        real: impl FnOnce(&mut KktStability, &SymbolicSparseColMat<usize>, &[f64]) -> T,
        complex: impl FnOnce(&mut KktStability<c64>, &SymbolicSparseColMat<usize>, &[c64]) -> T,
    ) -> T {
        let (p, k) = self.block(b);
        if self.blocks.is_real(p, k) {
            self.real_values.resize(self.kkt.len(), 0.0);
            self.blocks
                .real_block(p, k, &self.kkt, &mut self.real_values);
            self.real.swap_warm_start(&mut self.warm_real[b]);
            let held = held_modes(&self.blocks, &self.rod_turns, p, k);
            let out = holding(&mut self.real, pattern, held.as_deref(), |s| {
                real(s, pattern, &self.real_values)
            });
            self.real.swap_warm_start(&mut self.warm_real[b]);
            out
        } else {
            self.complex_values
                .resize(self.kkt.len(), c64::new(0.0, 0.0));
            self.blocks
                .hermitian_block(p, k, &self.kkt, &mut self.complex_values);
            self.complex.swap_warm_start(&mut self.warm_complex[b]);
            let held = held_modes(&self.blocks, &self.rod_turns, p, k);
            let out = holding(&mut self.complex, pattern, held.as_deref(), |s| {
                complex(s, pattern, &self.complex_values)
            });
            self.complex.swap_warm_start(&mut self.warm_complex[b]);
            out
        }
    }

    fn lowest_of_block(&mut self, pattern: &SymbolicSparseColMat<usize>, b: usize) -> Option<f64> {
        self.on_block(
            pattern,
            b,
            |s, pat, v| s.lowest_eigenvalue(pat, v),
            |s, pat, v| s.lowest_eigenvalue(pat, v),
        )
    }

    fn count_of_block(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        b: usize,
        sigma: Option<f64>,
    ) -> Result<(usize, usize), InertiaError> {
        self.on_block(
            pattern,
            b,
            |s, pat, v| match sigma {
                Some(sigma) => s.unstable_and_below(pat, v, sigma),
                None => Ok((s.unstable_directions(pat, v)?, 0)),
            },
            |s, pat, v| match sigma {
                Some(sigma) => s.unstable_and_below(pat, v, sigma),
                None => Ok((s.unstable_directions(pat, v)?, 0)),
            },
        )
    }

    fn rounding_band(&mut self, pattern: &SymbolicSparseColMat<usize>, b: usize) -> f64 {
        self.on_block(
            pattern,
            b,
            |s, pat, v| s.rounding_band(pat, v),
            |s, pat, v| s.rounding_band(pat, v),
        )
        .unwrap_or(0.0)
    }

    fn stability_of(&self, b: usize, count: usize, lowest: Option<f64>) -> BlockStability {
        let (p, _) = self.block(b);
        BlockStability {
            wavenumber: p,
            multiplicity: StabilityJudge::multiplicity(self, b),
            unstable_directions: count,
            lowest_eigenvalue: lowest,
        }
    }

    /// The lowest eigenvalue of block `(p, k)` at the state `x`, at any phase `k` (rad per
    /// cell), searched cold as the dispersion searches its blocks (regularised on one turn
    /// of the helices, [`DiscreteModel::stability_length`]).
    pub fn lowest_at(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        p: usize,
        k: f64,
    ) -> Option<f64> {
        self.evaluate(model, system, x);
        let pattern = system.pattern();
        let held = held_modes(&self.blocks, &self.rod_turns, p, k);
        if self.blocks.is_real(p, k) {
            let mut values = vec![0.0; self.kkt.len()];
            self.blocks.real_block(p, k, &self.kkt, &mut values);
            let mut search: KktStability = self.map.sharing();
            holding(&mut search, pattern, held.as_deref(), |s| {
                s.lowest_eigenvalue(pattern, &values)
            })
        } else {
            let mut values = vec![c64::new(0.0, 0.0); self.kkt.len()];
            self.blocks.hermitian_block(p, k, &self.kkt, &mut values);
            let mut search: KktStability<c64> = self.map.sharing();
            holding(&mut search, pattern, held.as_deref(), |s| {
                s.lowest_eigenvalue(pattern, &values)
            })
        }
    }

    /// The number of eigenvalues of block `(p, k)` below `sigma` at the state `x`, counted
    /// as [`CellJudge::lowest_at`] searches.
    pub fn count_below_at(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        (p, k): (usize, f64),
        sigma: f64,
    ) -> Result<usize, InertiaError> {
        self.evaluate(model, system, x);
        let pattern = system.pattern();
        let held = held_modes(&self.blocks, &self.rod_turns, p, k);
        if self.blocks.is_real(p, k) {
            let mut values = vec![0.0; self.kkt.len()];
            self.blocks.real_block(p, k, &self.kkt, &mut values);
            let mut count: KktStability = self.map.sharing();
            holding(&mut count, pattern, held.as_deref(), |s| {
                s.count_below(pattern, &values, sigma)
            })
        } else {
            let mut values = vec![c64::new(0.0, 0.0); self.kkt.len()];
            self.blocks.hermitian_block(p, k, &self.kkt, &mut values);
            let mut count: KktStability<c64> = self.map.sharing();
            holding(&mut count, pattern, held.as_deref(), |s| {
                s.count_below(pattern, &values, sigma)
            })
        }
    }

    /// The lowest eigenvalue of every block at the state `x`: the dispersion of the cell.
    ///
    /// Each wavenumber's blocks are searched in order of the phase, every search starting
    /// from the last phase's mode with the last phases' eigenvalues extrapolated (as along
    /// a path): the dispersion is smooth in `k`, so most blocks take one factorisation. The
    /// wavenumbers are searched in parallel, each with its own factorisations on the
    /// shared symbolic structure.
    pub fn dispersion(&mut self, model: &DiscreteModel, system: &System, x: &[f64]) -> Dispersion {
        self.evaluate(model, system, x);
        let pattern = system.pattern();
        // the symbolic analysis once, before the searches share it
        let _ = self.map.structure_for(pattern);
        let (blocks, phases, kkt) = (&self.blocks, &self.phases, &self.kkt);
        let rod_turns = &self.rod_turns;
        let partners = mirror_partners(model, x, blocks, phases);
        let count = phases.len();
        // the blocks searched: one of each mirror pair, every block without the mirror
        let searched = |p: usize, i: usize| {
            partners
                .as_ref()
                .is_none_or(|partner| partner[p * count + i] >= p * count + i)
        };
        let real = &self.map;
        let lowest = (0..blocks.cell().m)
            .into_par_iter()
            .map(|p| {
                let mut chain = PhaseChain {
                    real: real.sharing(),
                    complex: real.sharing(),
                    real_values: vec![0.0; kkt.len()],
                    complex_values: vec![c64::new(0.0, 0.0); kkt.len()],
                };
                phases
                    .iter()
                    .enumerate()
                    .map(|(i, &k)| {
                        if !searched(p, i) {
                            return None;
                        }
                        let held = held_modes(blocks, rod_turns, p, k);
                        chain.lowest(blocks, pattern, kkt, (p, k), held.as_deref())
                    })
                    .collect()
            })
            .collect::<Vec<Vec<Option<f64>>>>();
        let mut lowest = lowest;
        if let Some(partner) = &partners {
            for (b, &other) in partner.iter().enumerate() {
                if other < b {
                    lowest[b / count][b % count] = lowest[other / count][other % count];
                }
            }
        }
        let translation = (0..blocks.cell().m)
            .flat_map(|p| (0..phases.len()).map(move |i| (p, i)))
            .filter(|&(p, i)| blocks.holds_translation(p, phases[i]))
            .collect();
        Dispersion {
            phases: self.phases.clone(),
            lowest,
            translation,
        }
    }
}

/// The block (index `p · phases + i`) of the same spectrum as each block under the mirror
/// `y ↦ −y` of a cell whose state `x` is its own mirror image; `None` for a state (or a
/// phase grid) without it.
///
/// The mirror maps the right rod onto the left one and sector `j` onto `−j`: a
/// perturbation `e^{i(2πpj/m + kl)}` in cell `(j, l)`, whose left rod's far end begins cell
/// `(j_L, 1)`, becomes one of wavenumber `−p` and phase `k + 2πp j_L/m` — the conjugate of
/// block `(p, −k − 2πp j_L/m)` (`(p, 2πp/m − k)` for `j_L = −1`), a block of the same
/// spectrum, on the grid when `2πp/m` is a multiple of its step.
fn mirror_partners(
    model: &DiscreteModel,
    x: &[f64],
    blocks: &CellBlocks,
    phases: &[f64],
) -> Option<Vec<usize>> {
    let cell = blocks.cell();
    if cell.turns.len() != 2 || phases.len() < 2 {
        return None;
    }
    let mirror = Mirror::of(model)?;
    if !mirror.keeps(model, x) {
        return None;
    }
    let step = phases[1] - phases[0];
    let count = phases.len();
    let grid = |k: f64| {
        let i = (k / step).round();
        ((k - i * step).abs() <= 1e-9 * step && i >= 0.0 && (i as usize) < count)
            .then_some(i as usize)
    };
    let m = cell.m;
    let mut partner = Vec::with_capacity(m * count);
    for p in 0..m {
        for &k in phases {
            let image = (-k - cell.far_phase(1, p, 0.0)).rem_euclid(2.0 * PI);
            let (q, at) = if image <= PI + 1e-12 {
                (p, image.min(PI))
            } else {
                ((m - p) % m, 2.0 * PI - image)
            };
            partner.push(q * count + grid(at)?);
        }
    }
    Some(partner)
}

/// The searches of one wavenumber's blocks along the phases, each kind of block (real at
/// `k = 0` or `π`, Hermitian between) starting from the last one's mode and eigenvalues.
struct PhaseChain {
    real: KktStability,
    complex: KktStability<c64>,
    real_values: Vec<f64>,
    complex_values: Vec<c64>,
}

impl PhaseChain {
    /// The lowest eigenvalue of block `(p, k)` (0 where it holds the rigid translation
    /// across the axis).
    fn lowest(
        &mut self,
        blocks: &CellBlocks,
        pattern: &SymbolicSparseColMat<usize>,
        kkt: &[f64],
        (p, k): (usize, f64),
        held: Option<&[Vec<f64>]>,
    ) -> Option<f64> {
        if blocks.holds_translation(p, k) {
            return Some(0.0);
        }
        if blocks.is_real(p, k) {
            blocks.real_block(p, k, kkt, &mut self.real_values);
            let values = &self.real_values;
            holding(&mut self.real, pattern, held, |s| {
                s.lowest_eigenvalue(pattern, values)
            })
        } else {
            blocks.hermitian_block(p, k, kkt, &mut self.complex_values);
            let values = &self.complex_values;
            holding(&mut self.complex, pattern, held, |s| {
                s.lowest_eigenvalue(pattern, values)
            })
        }
    }
}

/// The neutral modes of block `(p, k)` held out of its metric ([`CellBlocks::turning_rods`]),
/// from each rod turning alone, `rod_turns`; `None` for none.
fn held_modes(
    blocks: &CellBlocks,
    rod_turns: &[Vec<f64>],
    p: usize,
    k: f64,
) -> Option<Vec<Vec<f64>>> {
    let sets = blocks.turning_rods(p, k);
    (!sets.is_empty()).then(|| {
        sets.iter()
            .map(|rods| {
                let mut t = vec![0.0; rod_turns.first().map_or(0, Vec::len)];
                for &r in rods {
                    t.iter_mut().zip(&rod_turns[r]).for_each(|(a, b)| *a += b);
                }
                t
            })
            .collect()
    })
}

/// `task` on `stability` with the neutral modes `held` (if any) held out of its metric
/// ([`KktStability::hold_modes`]), restored after.
fn holding<T: Scalar, R>(
    stability: &mut KktStability<T>,
    pattern: &SymbolicSparseColMat<usize>,
    held: Option<&[Vec<f64>]>,
    task: impl FnOnce(&mut KktStability<T>) -> R,
) -> R {
    let Some(modes) = held else {
        return task(stability);
    };
    // a pattern whose counter cannot be built fails the task itself
    let _ = stability.hold_modes(pattern, modes);
    let out = task(stability);
    let _ = stability.hold_modes(pattern, &[]);
    out
}

impl StabilityJudge for CellJudge {
    /// The count is of sampled phases k: a band that widens past the next one adds to it
    /// with no new critical point.
    fn counts_points(&self) -> bool {
        false
    }

    /// The block that held the lowest eigenvalue last searches it; every other block counts
    /// its eigenvalues below it by one factorisation and searches its own when it has some.
    fn blocks(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        eigenvalue: bool,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        self.evaluate(model, system, x);
        let pattern = system.pattern();
        let count = self.count();
        if !eigenvalue {
            return (0..count)
                .map(|b| {
                    let (unstable, _) = self.count_of_block(pattern, b, None)?;
                    Ok(self.stability_of(b, unstable, None))
                })
                .collect();
        }
        let first = self.lowest_block.min(count - 1);
        let own = self.lowest_of_block(pattern, first);
        let mut best = own;
        let mut out = Vec::with_capacity(count);
        for b in 0..count {
            let (unstable, lowest) = if b == first {
                let band = self.rounding_band(pattern, b);
                let unstable = if clearly_stable(own, band) {
                    0
                } else {
                    self.count_of_block(pattern, b, None)?.0
                };
                (unstable, own)
            } else {
                let (unstable, below) = match best {
                    Some(best) => self.count_of_block(pattern, b, Some(best))?,
                    None => (self.count_of_block(pattern, b, None)?.0, 0),
                };
                let lowest = (below > 0)
                    .then(|| self.lowest_of_block(pattern, b))
                    .flatten();
                if let Some(l) = lowest.filter(|&l| best.is_none_or(|b| l < b)) {
                    best = Some(l);
                }
                (unstable, lowest)
            };
            out.push(self.stability_of(b, unstable, lowest));
        }
        if let Some(b) = out
            .iter()
            .enumerate()
            .filter_map(|(b, s)| s.lowest_eigenvalue.map(|l| (b, l)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(b, _)| b)
        {
            self.lowest_block = b;
        }
        Ok(out)
    }

    fn nearest_zero_with_mode(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
    ) -> Option<(f64, usize, Vec<f64>)> {
        self.evaluate(model, system, x);
        let pattern = system.pattern();
        let candidates: Vec<usize> = match self.focus {
            Some(b) => vec![b],
            None => (0..self.count()).collect(),
        };
        let mut nearest: Option<(f64, usize, Vec<f64>)> = None;
        for b in candidates {
            let found = self.on_block(
                pattern,
                b,
                |s, pat, v| {
                    let mu = s.eigenvalue_nearest_zero(pat, v)?;
                    Some((mu, s.nearest_zero_mode().to_vec()))
                },
                |s, pat, v| {
                    let mu = s.eigenvalue_nearest_zero(pat, v)?;
                    let mode = s.nearest_zero_mode();
                    let parts = mode.iter().map(|z| z.re).chain(mode.iter().map(|z| z.im));
                    Some((mu, parts.collect()))
                },
            );
            let Some((mu, mode)) = found else { continue };
            if nearest.as_ref().is_none_or(|n| mu.abs() < n.0.abs()) {
                nearest = Some((mu, b, mode));
            }
        }
        nearest
    }

    fn has_wavenumbers(&self) -> bool {
        true
    }

    /// 1 for a block conjugate to itself (`k = 0` or `π` with `2p = 0 mod m`), else 2: the
    /// block and its conjugate `(m − p, −k)`.
    fn multiplicity(&self, b: usize) -> usize {
        let (p, k) = self.block(b);
        if self.blocks.is_real(p, k) {
            1
        } else {
            2
        }
    }

    fn focus(&mut self, b: Option<usize>) {
        self.focus = b;
    }

    fn kkt_structure(&self, pattern: &SymbolicSparseColMat<usize>) -> Option<Arc<KktStructure>> {
        self.real.structure_for(pattern).ok()
    }
}
