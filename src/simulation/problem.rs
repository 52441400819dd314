//! The discrete assembly as a continuation problem: the KKT system of a discrete model under
//! boundary conditions, loaded through its tips by the load parameter (DESIGN.md §3, §5).
//!
//! Under displacement control `λ = ε`, the compression ratio, and the tips are held at
//! `h = h0 (1 − ε)`; under load control `λ = P / Pcrit`, a dead compressive load on every
//! tip over the Euler load. Stability is judged on the full assembly: for a symmetric pair,
//! by the Bloch blocks of its KKT matrix, one per wavenumber (a symmetric state can lose
//! stability to modes that break the symmetry; they live in the blocks `p ≠ 0`).

use crate::discretisation::model::{DiscreteModel, End};
use crate::discretisation::symmetry::BlochBlocks;
use crate::discretisation::system::System;
use crate::results::Stability;
use crate::solver::problem::Problem;
use crate::solver::stability::{InertiaError, KktStability, KktStructure, RoughLowest, WarmStart};
use faer::c64;
use faer::sparse::SymbolicSparseColMat;
use std::sync::Arc;

/// A discrete model under boundary conditions and a control of its tips.
pub struct RodProblem {
    pub(super) model: DiscreteModel,
    pub(super) system: System,
    /// Where stability is judged: this model, or the full model behind a symmetric pair.
    judge: Judge,
}

/// The model on which stability is judged, with its buffers.
enum Judge {
    Own {
        stability: KktStability,
        residual: Vec<f64>,
        values: Vec<f64>,
    },
    Blocks(Box<Blocks>),
}

/// The Bloch blocks of a symmetric pair, one per wavenumber (DESIGN.md §7), judged on two
/// threads (the blocks are independent).
struct Blocks {
    bloch: BlochBlocks,
    /// One workspace per thread.
    workers: [Worker; 2],
    /// The warm start of inverse iteration of each wavenumber `0 ..= m/2`.
    warm: Vec<BlockWarm>,
    residual: Vec<f64>,
    /// The pair's KKT values.
    pair: Vec<f64>,
    /// The wavenumber of the lowest eigenvalue found last.
    lowest_wavenumber: usize,
    /// The wavenumber a critical-point search looks at, when one is under way.
    focus: Option<usize>,
}

/// The warm starts of one wavenumber's eigenvalue searches: on its real block (`p = 0`,
/// `m/2`) or on its complex one.
#[derive(Default)]
struct BlockWarm {
    real: WarmStart,
    complex: WarmStart<c64>,
}

impl BlockWarm {
    fn has_history(&self) -> bool {
        self.real.has_history() || self.complex.has_history()
    }

    fn upper_estimate(&self) -> Option<f64> {
        self.real
            .upper_estimate()
            .or_else(|| self.complex.upper_estimate())
    }
}

/// What one thread needs to judge a block: the stability of the real blocks and of the
/// complex ones (`LDLᴴ`), both in the pair's pattern and sharing its symbolic analysis,
/// each built on first use, and the block's values.
struct Worker {
    real: KktStability,
    hermitian: KktStability<c64>,
    values: Vec<f64>,
    hermitian_values: Vec<c64>,
}

/// One Bloch block as a task on a worker sees it: a real block or a complex one, its
/// values assembled when first asked for.
struct BlockView<'a> {
    p: usize,
    bloch: &'a BlochBlocks,
    pattern: &'a SymbolicSparseColMat<usize>,
    pair: &'a [f64],
    worker: &'a mut Worker,
    real_ready: bool,
    hermitian_ready: bool,
}

/// `$body` on the block `$view` as its own kind: `$pat`, `$v`, `$s` its pattern, values and
/// stability, of real entries (`p = 0`, `m/2`) or complex ones.
macro_rules! on_block {
    ($view:expr, |$pat:ident, $v:ident, $s:ident| $body:expr) => {
        if $view.is_complex() {
            let ($pat, $v, $s) = $view.hermitian_form();
            $body
        } else {
            let ($pat, $v, $s) = $view.real_form();
            $body
        }
    };
}

impl BlockView<'_> {
    /// Whether the block is complex (`0 < p < m/2`).
    fn is_complex(&self) -> bool {
        !self.bloch.is_real(self.p)
    }

    /// A real block (`p = 0`, `m/2`): its pattern, values and stability.
    fn real_form(&mut self) -> (&SymbolicSparseColMat<usize>, &[f64], &mut KktStability) {
        debug_assert!(!self.is_complex());
        let w = &mut *self.worker;
        if self.p == 0 {
            return (self.pattern, self.pair, &mut w.real);
        }
        if !self.real_ready {
            w.values.resize(self.pair.len(), 0.0);
            self.bloch.real_block(self.p, self.pair, &mut w.values);
            self.real_ready = true;
        }
        (self.pattern, &w.values[..], &mut w.real)
    }

    /// A complex block itself: the pair's pattern, its values and stability.
    fn hermitian_form(&mut self) -> (&SymbolicSparseColMat<usize>, &[c64], &mut KktStability<c64>) {
        let w = &mut *self.worker;
        if !self.hermitian_ready {
            w.hermitian_values
                .resize(self.pair.len(), c64::new(0.0, 0.0));
            self.bloch
                .hermitian_block(self.p, self.pair, &mut w.hermitian_values);
            self.hermitian_ready = true;
        }
        (self.pattern, &w.hermitian_values[..], &mut w.hermitian)
    }

    fn unstable_directions(&mut self) -> Result<usize, InertiaError> {
        on_block!(self, |pat, v, s| s.unstable_directions(pat, v))
    }

    fn unstable_and_below(&mut self, sigma: f64) -> Result<(usize, usize), InertiaError> {
        on_block!(self, |pat, v, s| s.unstable_and_below(pat, v, sigma))
    }

    fn rounding_band(&mut self) -> Result<f64, InertiaError> {
        on_block!(self, |pat, v, s| s.rounding_band(pat, v))
    }

    /// The block's lowest eigenvalue, going on from a rough estimate of it at this state
    /// when there is one.
    fn lowest_eigenvalue(&mut self, rough: Option<RoughLowest>) -> Option<f64> {
        on_block!(self, |pat, v, s| s.lowest_eigenvalue_after(pat, v, rough))
    }

    fn rough_lowest(&mut self) -> Option<RoughLowest> {
        on_block!(self, |pat, v, s| s.rough_lowest(pat, v))
    }

    /// The eigenvalue nearest zero and its mode: over the pair's primal unknowns, for a
    /// complex block their real parts then their imaginary parts.
    fn nearest_zero(&mut self) -> Option<(f64, Vec<f64>)> {
        if self.is_complex() {
            let (pat, v, s) = self.hermitian_form();
            let mu = s.eigenvalue_nearest_zero(pat, v)?;
            let mode = s.nearest_zero_mode();
            let parts = mode.iter().map(|z| z.re).chain(mode.iter().map(|z| z.im));
            Some((mu, parts.collect()))
        } else {
            let (pat, v, s) = self.real_form();
            let mu = s.eigenvalue_nearest_zero(pat, v)?;
            Some((mu, s.nearest_zero_mode().to_vec()))
        }
    }
}

/// The stability of one Bloch block of a state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockStability {
    pub wavenumber: usize,
    /// How many wavenumbers the block stands for (`p` and `m − p`).
    pub multiplicity: usize,
    pub unstable_directions: usize,
    /// The block's lowest eigenvalue (J/m), when it was computed: the lowest of the state's
    /// blocks always is, a block known to have none below it is not.
    pub lowest_eigenvalue: Option<f64>,
}

/// Tributary arc length of every primal unknown: the metric of the eigenproblem
/// (quaternion unknowns weighted by their node's share of the rod, positions zero).
fn metric(model: &DiscreteModel) -> Vec<f64> {
    let mut m = vec![0.0; model.n_primal];
    let p = model.order.degree();
    for rod in &model.rods {
        for e in 0..rod.mesh.elements() {
            let h = rod.mesh.vertices[e + 1] - rod.mesh.vertices[e];
            for a in 0..=p {
                let w = if a == 0 || a == p {
                    h / (2.0 * p as f64)
                } else {
                    h / p as f64
                };
                for k in 0..4 {
                    m[rod.q_dof(e * p + a, k)] += w;
                }
            }
        }
    }
    m
}

/// Mean tip height over the rods of `model` in state `x` (m).
pub fn mean_tip_height(model: &DiscreteModel, x: &[f64]) -> f64 {
    let n = model.rods.len() as f64;
    model
        .rods
        .iter()
        .enumerate()
        .map(|(id, r)| model.vertex(x, id, r.end_vertex(End::Tip))[2])
        .sum::<f64>()
        / n
}

impl RodProblem {
    /// The problem of `system` (built on `model`, loaded by the system's loads).
    pub fn new(model: DiscreteModel, system: System) -> RodProblem {
        let judge = match BlochBlocks::new(&model, &system) {
            Some(bloch) => {
                // the blocks, real and complex, share the pair's symbolic analysis on both
                // threads
                let real: KktStability = KktStability::new(metric(&model), model.length());
                let worker = || Worker {
                    real: real.sharing(),
                    hermitian: real.sharing(),
                    values: Vec::new(),
                    hermitian_values: Vec::new(),
                };
                Judge::Blocks(Box::new(Blocks {
                    workers: [worker(), worker()],
                    warm: (0..=bloch.m / 2).map(|_| BlockWarm::default()).collect(),
                    bloch,
                    residual: vec![0.0; system.n],
                    pair: system.new_values(),
                    lowest_wavenumber: 0,
                    focus: None,
                }))
            }
            None => Judge::Own {
                stability: KktStability::new(metric(&model), model.length()),
                residual: vec![0.0; system.n],
                values: system.new_values(),
            },
        };
        RodProblem {
            model,
            system,
            judge,
        }
    }

    /// Whether this is a symmetric pair, its stability judged by Bloch blocks.
    pub fn is_symmetric_pair(&self) -> bool {
        matches!(self.judge, Judge::Blocks(_))
    }

    /// The stability of every distinct block at `x` (the KKT values do not depend on the
    /// load parameter: it enters the residual only), with the lowest eigenvalue over the
    /// blocks when `eigenvalue` is asked for; one block of wavenumber 0 for a model without
    /// the symmetry.
    ///
    /// For the lowest eigenvalue, only the block that had it last time is iterated on; every
    /// other block is asked, by one inertia count at that eigenvalue, whether it has one
    /// below (and the same factorisation counts its unstable directions when it has none).
    pub fn block_stability(
        &mut self,
        x: &[f64],
        eigenvalue: bool,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        let b = match &mut self.judge {
            Judge::Own {
                stability,
                residual,
                values,
            } => {
                self.system.evaluate(&self.model, x, residual, values);
                let pattern = self.system.pattern();
                let lowest_eigenvalue = if eigenvalue {
                    stability.lowest_eigenvalue(pattern, values)
                } else {
                    None
                };
                let unstable_directions =
                    if clearly_stable(lowest_eigenvalue, stability.rounding_band(pattern, values)?)
                    {
                        0
                    } else {
                        stability.unstable_directions(pattern, values)?
                    };
                return Ok(vec![BlockStability {
                    wavenumber: 0,
                    multiplicity: 1,
                    unstable_directions,
                    lowest_eigenvalue,
                }]);
            }
            Judge::Blocks(b) => b.as_mut(),
        };
        self.system
            .evaluate(&self.model, x, &mut b.residual, &mut b.pair);
        let pattern = self.system.pattern();
        let all: Vec<usize> = b.bloch.wavenumbers().collect();
        if !eigenvalue {
            return b
                .run(pattern, &all, |b| {
                    b.unstable_directions().map(|c| (c, None))
                })
                .into_iter()
                .map(|(p, r)| r.map(|(c, l)| b.stability_of(p, c, l)))
                .collect();
        }
        // without a lowest eigenvalue found before (the first state), the block likely to
        // hold it is picked by a rough estimate on every block (a cold search through a
        // block's cluster of eigenvalues costs tens of factorisations, and would be repeated
        // on every block found to have an eigenvalue below it), and that estimate, a
        // Rayleigh quotient, is an upper estimate of the lowest eigenvalue; along a path the
        // upper estimate is the extrapolation of the last ones
        // (each block's search goes on from its rough estimate)
        let mut rough: Vec<Option<RoughLowest>> = vec![None; all.len()];
        let upper = if b.warm.iter().all(|w| !w.has_history()) {
            for (p, r) in b.run(pattern, &all, |b| Ok(b.rough_lowest())) {
                rough[p] = r.ok().flatten();
            }
            let lowest = (0..all.len())
                .filter_map(|p| rough[p].map(|r| (p, r.estimate)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            lowest.map(|(p, mu)| {
                b.lowest_wavenumber = p;
                mu
            })
        } else {
            b.warm[b.lowest_wavenumber].upper_estimate()
        };
        let first = b.lowest_wavenumber;
        // every block at once (both threads busy): the block that holds (or held) the
        // lowest eigenvalue searches it, the others count below the upper estimate of it;
        // a block with an eigenvalue below the estimate searches its own, and when the
        // lowest comes out above the estimate the blocks that only counted are asked again
        // at it
        if let Some(upper) = upper {
            let below_or_lowest = |b: &mut BlockView, sigma: f64| -> Result<_, InertiaError> {
                let (count, below) = b.unstable_and_below(sigma)?;
                Ok((
                    count,
                    if below > 0 {
                        b.lowest_eigenvalue(rough[b.p])
                    } else {
                        None
                    },
                ))
            };
            let found = b.run(pattern, &all, |b| {
                if b.p != first {
                    return below_or_lowest(b, upper);
                }
                let lowest = b.lowest_eigenvalue(rough[b.p]);
                let count = if clearly_stable(lowest, b.rounding_band()?) {
                    0
                } else {
                    b.unstable_directions()?
                };
                Ok((count, lowest))
            });
            let mut out = Vec::with_capacity(found.len());
            for (p, r) in found {
                let (c, l) = r?;
                out.push(b.stability_of(p, c, l));
            }
            if let Some((best, _)) = lowest_of(&out).filter(|&(best, _)| best > upper) {
                let unsure: Vec<usize> = out
                    .iter()
                    .filter(|s| s.lowest_eigenvalue.is_none())
                    .map(|s| s.wavenumber)
                    .collect();
                for (p, r) in b.run(pattern, &unsure, |b| below_or_lowest(b, best)) {
                    let (c, l) = r?;
                    let again = b.stability_of(p, c, l);
                    if let Some(s) = out.iter_mut().find(|s| s.wavenumber == p) {
                        *s = again;
                    }
                }
            }
            if let Some((_, p)) = lowest_of(&out) {
                b.lowest_wavenumber = p;
            }
            out.sort_by_key(|s| s.wavenumber);
            return Ok(out);
        }
        // no upper estimate (one lowest eigenvalue known, or no rough estimate found): the
        // block that held the lowest searches it, then the others count below it
        let [(_, head)] = b
            .run(pattern, &[first], |b| {
                let lowest = b.lowest_eigenvalue(None);
                let count = if clearly_stable(lowest, b.rounding_band()?) {
                    0
                } else {
                    b.unstable_directions()?
                };
                Ok((count, lowest))
            })
            .try_into()
            .expect("one block asked, one answered");
        let (count, lowest) = head?;
        let mut out = vec![b.stability_of(first, count, lowest)];
        let others: Vec<usize> = all.into_iter().filter(|&p| p != first).collect();
        let Some(best) = lowest else {
            for (p, r) in b.run(pattern, &others, |b| {
                b.unstable_directions().map(|c| (c, None))
            }) {
                let (c, l) = r?;
                out.push(b.stability_of(p, c, l));
            }
            return Ok(out);
        };
        for (p, r) in b.run(pattern, &others, |b| {
            let (count, below) = b.unstable_and_below(best)?;
            let lowest = if below > 0 {
                b.lowest_eigenvalue(None)
            } else {
                None
            };
            Ok((count, lowest))
        }) {
            let (c, l) = r?;
            out.push(b.stability_of(p, c, l));
        }
        let lowest = out
            .iter()
            .filter_map(|s| s.lowest_eigenvalue.map(|l| (l, s.wavenumber)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, p)) = lowest {
            b.lowest_wavenumber = p;
        }
        out.sort_by_key(|s| s.wavenumber);
        Ok(out)
    }

    /// The lowest eigenvalue over the blocks at `x` and its wavenumber.
    pub fn lowest_eigenvalue_with_wavenumber(&mut self, x: &[f64]) -> Option<(f64, usize)> {
        lowest_of(&self.block_stability(x, true).ok()?)
    }

    /// The eigenvalue nearest zero at `x` of the block a critical-point search focuses on,
    /// or over every block, with its wavenumber and the block's mode (primal unknowns of
    /// the block: the pair's, or real then imaginary parts for a complex block).
    pub fn nearest_zero_with_mode(&mut self, x: &[f64]) -> Option<(f64, usize, Vec<f64>)> {
        let b = match &mut self.judge {
            Judge::Own {
                stability,
                residual,
                values,
            } => {
                self.system.evaluate(&self.model, x, residual, values);
                let mu = stability.eigenvalue_nearest_zero(self.system.pattern(), values)?;
                return Some((mu, 0, stability.nearest_zero_mode().to_vec()));
            }
            Judge::Blocks(b) => b.as_mut(),
        };
        self.system
            .evaluate(&self.model, x, &mut b.residual, &mut b.pair);
        let pattern = self.system.pattern();
        let ps: Vec<usize> = match b.focus {
            Some(p) => vec![p],
            None => b.bloch.wavenumbers().collect(),
        };
        let found = b.run(pattern, &ps, |b| Ok(b.nearest_zero()));
        let mut nearest: Option<(f64, usize, Vec<f64>)> = None;
        for (p, r) in found {
            let (mu, mode) = r.ok()??;
            if nearest.as_ref().is_none_or(|n| mu.abs() < n.0.abs()) {
                nearest = Some((mu, p, mode));
            }
        }
        nearest
    }

    /// At a double critical point of a model judged on itself (count change 2): the mode
    /// of the other eigenvalue nearest zero at `x`, orthogonal in the metric to `first`,
    /// scaled as `first` over the primal unknowns; `None` for the Bloch blocks (whose
    /// double modes are the two halves of one complex mode).
    pub fn second_mode(&mut self, x: &[f64], first: &[f64]) -> Option<Vec<f64>> {
        let Judge::Own {
            stability,
            residual,
            values,
        } = &mut self.judge
        else {
            return None;
        };
        self.system.evaluate(&self.model, x, residual, values);
        let (_, mut mode) =
            stability.nearest_zero_orthogonal_to(self.system.pattern(), values, first)?;
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let scale = norm(&first[..mode.len()]) / norm(&mode);
        if !scale.is_finite() {
            return None;
        }
        mode.iter_mut().for_each(|v| *v *= scale);
        Some(mode)
    }

    /// The eigenvector (primal unknowns of the block) of the eigenvalue nearest zero of
    /// block `p` at `x`: a critical mode of wavenumber `p`.
    pub fn block_mode(&mut self, x: &[f64], p: usize) -> Option<Vec<f64>> {
        if let Judge::Blocks(b) = &mut self.judge {
            b.focus = Some(p);
        }
        let found = self.nearest_zero_with_mode(x);
        self.clear_focus();
        found.map(|(_, _, mode)| mode)
    }

    /// Per block, the unstable directions at `x` (for the wavenumber whose count changes).
    fn counts(&mut self, x: &[f64]) -> Option<Vec<usize>> {
        self.block_stability(x, false)
            .ok()
            .map(|v| v.iter().map(|s| s.unstable_directions).collect())
    }

    /// The Bloch blocks' bookkeeping (`None` for a model without the symmetry).
    pub fn bloch(&self) -> Option<&BlochBlocks> {
        match &self.judge {
            Judge::Blocks(b) => Some(&b.bloch),
            Judge::Own { .. } => None,
        }
    }
}

/// Whether a state whose lowest eigenvalue is `lowest` has no unstable direction without
/// a count: the count is of the eigenvalues below `−τ` (`tau`, its rounding band), and none
/// is below the lowest. (Near a critical point the lowest eigenvalue, from unregularised
/// Rayleigh quotients, is the sharper of the two: the count's pivots round at about `τ`.)
fn clearly_stable(lowest: Option<f64>, tau: f64) -> bool {
    lowest.is_some_and(|l| l > -tau)
}

/// The lowest computed eigenvalue over `blocks`, with its wavenumber.
fn lowest_of(blocks: &[BlockStability]) -> Option<(f64, usize)> {
    blocks
        .iter()
        .filter_map(|s| s.lowest_eigenvalue.map(|l| (l, s.wavenumber)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// A task on one block: the wavenumber, the block's pattern and values, its stability.
type BlockTask<'a, T> = dyn Fn(&mut BlockView) -> Result<T, InertiaError> + Sync + 'a;

impl Blocks {
    fn stability_of(&self, p: usize, count: usize, lowest: Option<f64>) -> BlockStability {
        BlockStability {
            wavenumber: p,
            multiplicity: self.bloch.multiplicity(p),
            unstable_directions: count,
            lowest_eigenvalue: lowest,
        }
    }

    /// `task` on the blocks of wavenumbers `ps` at the pair's KKT values in `self.pair`,
    /// shared out between the two workers (the second on a thread of its own) by the
    /// parity of `p`: a block stays with the worker whose factorisation workspace it has
    /// built (the first use of a workspace costs what a few factorisations do), and the
    /// blocks of all wavenumbers are shared about evenly; results in the order of `ps`.
    fn run<T: Send>(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        ps: &[usize],
        task: impl Fn(&mut BlockView) -> Result<T, InertiaError> + Sync,
    ) -> Vec<(usize, Result<T, InertiaError>)> {
        let task: &BlockTask<T> = &task;
        let mut jobs: [Vec<(usize, BlockWarm)>; 2] = [Vec::new(), Vec::new()];
        for &p in ps {
            jobs[p % 2].push((p, std::mem::take(&mut self.warm[p])));
        }
        let (bloch, pair) = (&self.bloch, &self.pair);
        let [w0, w1] = &mut self.workers;
        let [j0, j1] = jobs;
        let (mut r0, r1) = if j1.is_empty() {
            (w0.run(bloch, pattern, pair, j0, task), Vec::new())
        } else if j0.is_empty() {
            (Vec::new(), w1.run(bloch, pattern, pair, j1, task))
        } else {
            std::thread::scope(|scope| {
                let other = scope.spawn(|| w1.run(bloch, pattern, pair, j1, task));
                let mine = w0.run(bloch, pattern, pair, j0, task);
                (mine, other.join().expect("a block's thread does not panic"))
            })
        };
        r0.extend(r1);
        let mut out = Vec::with_capacity(ps.len());
        for (p, warm, result) in r0 {
            self.warm[p] = warm;
            out.push((p, result));
        }
        out.sort_by_key(|(p, _)| ps.iter().position(|q| q == p));
        out
    }
}

impl Worker {
    /// `task` on each block of `jobs` (wavenumber and warm starts), the warm start put in
    /// place for the task and taken back after it.
    fn run<T>(
        &mut self,
        bloch: &BlochBlocks,
        pattern: &SymbolicSparseColMat<usize>,
        pair: &[f64],
        jobs: Vec<(usize, BlockWarm)>,
        task: &BlockTask<T>,
    ) -> Vec<(usize, BlockWarm, Result<T, InertiaError>)> {
        jobs.into_iter()
            .map(|(p, mut warm)| {
                let real = bloch.is_real(p);
                self.swap_warm_start(real, &mut warm);
                let mut view = BlockView {
                    p,
                    bloch,
                    pattern,
                    pair,
                    worker: self,
                    real_ready: false,
                    hermitian_ready: false,
                };
                let result = task(&mut view);
                self.swap_warm_start(real, &mut warm);
                (p, warm, result)
            })
            .collect()
    }

    /// Exchanges the warm start of the searches on a real (or complex) block with `warm`.
    fn swap_warm_start(&mut self, real: bool, warm: &mut BlockWarm) {
        if real {
            self.real.swap_warm_start(&mut warm.real);
        } else {
            self.hermitian.swap_warm_start(&mut warm.complex);
        }
    }
}

/// Euler load of the model's rods, `Pcrit = B1 (2π/L)²` (N): the unit of `λ` under load
/// control.
pub fn pcrit(model: &DiscreteModel) -> f64 {
    model.stiffness.euler_load(model.length())
}

impl Problem for RodProblem {
    fn unknowns(&self) -> usize {
        self.system.n
    }

    fn primal_unknowns(&self) -> usize {
        self.model.n_primal
    }

    fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        self.system.pattern()
    }

    fn residual(&mut self, x: &[f64], lambda: f64, residual: &mut [f64]) -> f64 {
        self.system.set_parameter(lambda);
        self.system.residual(&self.model, x, residual).energy
    }

    fn jacobian(
        &mut self,
        x: &[f64],
        lambda: f64,
        residual: &mut [f64],
        jacobian: &mut [f64],
    ) -> f64 {
        self.system.set_parameter(lambda);
        self.system
            .evaluate(&self.model, x, residual, jacobian)
            .energy
    }

    fn eigenvalue_scale(&self) -> f64 {
        self.model.stiffness.b1 / self.model.length().powi(2)
    }

    /// The structure of the stability's real blocks: the pair's (or the full model's)
    /// own pattern, metric and length.
    fn kkt_structure(&self) -> Option<Arc<KktStructure>> {
        let stability = match &self.judge {
            Judge::Own { stability, .. } => stability,
            Judge::Blocks(b) => &b.workers[0].real,
        };
        stability.structure_for(self.system.pattern()).ok()
    }

    fn residual_weights(&self, weights: &mut [f64]) {
        self.system.residual_weights(&self.model, weights);
    }

    /// From the loads at `lambda`.
    fn load_derivative(&mut self, x: &[f64], lambda: f64, out: &mut [f64]) {
        self.system.load_derivative(&self.model, x, lambda, out);
    }

    fn load_derivative_is_constant(&self) -> bool {
        self.system.load_derivative_is_constant()
    }

    fn unstable_directions(&mut self, x: &[f64], _lambda: f64) -> Result<usize, InertiaError> {
        Ok(self
            .block_stability(x, false)?
            .iter()
            .map(|s| s.multiplicity * s.unstable_directions)
            .sum())
    }

    fn lowest_eigenvalue(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        self.lowest_eigenvalue_with_wavenumber(x).map(|(l, _)| l)
    }

    fn stability(
        &mut self,
        x: &[f64],
        _lambda: f64,
        eigenvalue: bool,
    ) -> Result<Stability, InertiaError> {
        let blocks = self.block_stability(x, eigenvalue)?;
        let lowest = lowest_of(&blocks);
        Ok(Stability {
            unstable_directions: blocks
                .iter()
                .map(|s| s.multiplicity * s.unstable_directions)
                .sum(),
            lowest_eigenvalue: lowest.map(|(l, _)| l),
            lowest_wavenumber: lowest.filter(|_| self.is_symmetric_pair()).map(|(_, p)| p),
        })
    }

    /// The eigenvalue nearest zero of the focused block, or over the blocks.
    fn eigenvalue_nearest_zero(&mut self, x: &[f64], _lambda: f64) -> Option<f64> {
        self.nearest_zero_with_mode(x).map(|(mu, _, _)| mu)
    }

    /// The first wavenumber whose count differs between `x0` and `x1`.
    fn focus_on_crossing(&mut self, x0: &[f64], x1: &[f64]) -> usize {
        let (Some(a), Some(b)) = (self.counts(x0), self.counts(x1)) else {
            return 0;
        };
        let Judge::Blocks(blocks) = &mut self.judge else {
            return 0;
        };
        let p = a.iter().zip(&b).position(|(u, v)| u != v).unwrap_or(0);
        blocks.focus = Some(p);
        p
    }

    fn clear_focus(&mut self) {
        if let Judge::Blocks(b) = &mut self.judge {
            b.focus = None;
        }
    }

    /// The system keeps the tip load of the converged point (reactions are read from it).
    fn restore(&mut self, _x: &[f64], lambda: f64) {
        self.system.set_parameter(lambda);
    }
}
