//! The stability of a cyclic pair judged on the whole assembly by the Bloch blocks of its
//! KKT matrix, one per wavenumber (docs/theory.md §7): a symmetric state can lose stability to
//! modes that break the symmetry, and they live in the blocks `p ≠ 0`. The blocks are
//! independent, and are judged on a number of threads given by the caller.

use super::judge::{clearly_stable, lowest_of, metric, BlockStability, StabilityJudge};
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::symmetry::BlochBlocks;
use crate::discretisation::system::System;
use crate::solver::stability::{InertiaError, KktStability, KktStructure, RoughLowest, WarmStart};
use faer::c64;
use faer::sparse::SymbolicSparseColMat;
use std::sync::Arc;

/// The Bloch blocks of a symmetric pair, one per wavenumber, judged on `workers.len()`
/// threads.
pub struct JudgeByBlocks {
    bloch: BlochBlocks,
    /// One workspace per thread (at least one).
    workers: Vec<Worker>,
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

impl Worker {
    /// A workspace sharing the symbolic analysis of `real`.
    fn sharing(real: &KktStability) -> Worker {
        Worker {
            real: real.sharing(),
            hermitian: real.sharing(),
            values: Vec::new(),
            hermitian_values: Vec::new(),
        }
    }
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

    /// The block's unstable directions, and its lowest eigenvalue searched for (from a rough
    /// estimate of it when there is one): the count is skipped when that eigenvalue shows
    /// the block clearly stable.
    fn lowest_and_count(
        &mut self,
        rough: Option<RoughLowest>,
    ) -> Result<(usize, Option<f64>), InertiaError> {
        let lowest = self.lowest_eigenvalue(rough);
        let count = if clearly_stable(lowest, self.rounding_band()?) {
            0
        } else {
            self.unstable_directions()?
        };
        Ok((count, lowest))
    }

    /// The block's unstable directions, and its lowest eigenvalue when it has one below
    /// `sigma` (searched for from a rough estimate of it when there is one).
    fn count_and_lowest_below(
        &mut self,
        sigma: f64,
        rough: Option<RoughLowest>,
    ) -> Result<(usize, Option<f64>), InertiaError> {
        let (count, below) = self.unstable_and_below(sigma)?;
        Ok((
            count,
            if below > 0 {
                self.lowest_eigenvalue(rough)
            } else {
                None
            },
        ))
    }
}

impl JudgeByBlocks {
    /// The blocks of the symmetric pair `model` under `system` (`None` for a model without
    /// the symmetry), judged on `threads` threads (at least one).
    pub fn new(model: &DiscreteModel, system: &System, threads: usize) -> Option<JudgeByBlocks> {
        let bloch = BlochBlocks::new(model, system)?;
        // the blocks, real and complex, share the pair's symbolic analysis on every thread
        let real: KktStability = KktStability::new(metric(model), model.length());
        Some(JudgeByBlocks {
            workers: (0..threads.max(1))
                .map(|_| Worker::sharing(&real))
                .collect(),
            warm: (0..=bloch.m / 2).map(|_| BlockWarm::default()).collect(),
            bloch,
            residual: vec![0.0; system.n],
            pair: system.new_values(),
            lowest_wavenumber: 0,
            focus: None,
        })
    }

    fn stability_of(&self, p: usize, count: usize, lowest: Option<f64>) -> BlockStability {
        BlockStability {
            wavenumber: p,
            multiplicity: self.bloch.multiplicity(p),
            unstable_directions: count,
            lowest_eigenvalue: lowest,
        }
    }

    /// `task` on the blocks of wavenumbers `ps` for the answers `(count, lowest)` of their
    /// stability, in the order of `ps`.
    fn stabilities(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        ps: &[usize],
        task: impl Fn(&mut BlockView) -> Result<(usize, Option<f64>), InertiaError> + Sync,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        let found = self.run(pattern, ps, task);
        let mut out = Vec::with_capacity(found.len());
        for (p, r) in found {
            let (c, l) = r?;
            out.push(self.stability_of(p, c, l));
        }
        Ok(out)
    }

    /// Without a lowest eigenvalue found before (the first state), the block likely to
    /// hold it is picked by a rough estimate on every block (a cold search through a
    /// block's cluster of eigenvalues costs tens of factorisations, and would be repeated
    /// on every block found to have an eigenvalue below it), and that estimate, a
    /// Rayleigh quotient, is an upper estimate of the lowest eigenvalue; along a path the
    /// upper estimate is the extrapolation of the last ones. Returns each block's rough
    /// estimate (from which its search goes on) and the upper estimate.
    fn upper_estimate(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        all: &[usize],
    ) -> (Vec<Option<RoughLowest>>, Option<f64>) {
        let mut rough: Vec<Option<RoughLowest>> = vec![None; all.len()];
        let upper = if self.warm.iter().all(|w| !w.has_history()) {
            for (p, r) in self.run(pattern, all, |b| Ok(b.rough_lowest())) {
                rough[p] = r.ok().flatten();
            }
            let lowest = (0..all.len())
                .filter_map(|p| rough[p].map(|r| (p, r.estimate)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            lowest.map(|(p, mu)| {
                self.lowest_wavenumber = p;
                mu
            })
        } else {
            self.warm[self.lowest_wavenumber].upper_estimate()
        };
        (rough, upper)
    }

    /// Every block at once (every thread busy): the block that holds (or held) the lowest
    /// eigenvalue searches it, the others count below its upper estimate `upper`; a block
    /// with an eigenvalue below the estimate searches its own, and when the lowest comes
    /// out above the estimate the blocks that only counted are asked again at it.
    fn below_estimate(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        all: &[usize],
        rough: &[Option<RoughLowest>],
        upper: f64,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        let first = self.lowest_wavenumber;
        let mut out = self.stabilities(pattern, all, |b| {
            if b.p != first {
                return b.count_and_lowest_below(upper, rough[b.p]);
            }
            b.lowest_and_count(rough[b.p])
        })?;
        if let Some((best, _)) = lowest_of(&out).filter(|&(best, _)| best > upper) {
            let unsure: Vec<usize> = out
                .iter()
                .filter(|s| s.lowest_eigenvalue.is_none())
                .map(|s| s.wavenumber)
                .collect();
            let again = self.stabilities(pattern, &unsure, |b| {
                b.count_and_lowest_below(best, rough[b.p])
            })?;
            for again in again {
                if let Some(s) = out.iter_mut().find(|s| s.wavenumber == again.wavenumber) {
                    *s = again;
                }
            }
        }
        if let Some((_, p)) = lowest_of(&out) {
            self.lowest_wavenumber = p;
        }
        out.sort_by_key(|s| s.wavenumber);
        Ok(out)
    }

    /// Without an upper estimate (one lowest eigenvalue known, or no rough estimate found):
    /// the block that held the lowest searches it, then the others count below it.
    fn lowest_first(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        all: Vec<usize>,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        let first = self.lowest_wavenumber;
        let [head] = self
            .stabilities(pattern, &[first], |b| b.lowest_and_count(None))?
            .try_into()
            .expect("one block asked, one answered");
        let mut out = vec![head];
        let others: Vec<usize> = all.into_iter().filter(|&p| p != first).collect();
        let Some(best) = head.lowest_eigenvalue else {
            out.extend(self.stabilities(pattern, &others, |b| {
                b.unstable_directions().map(|c| (c, None))
            })?);
            return Ok(out);
        };
        out.extend(self.stabilities(pattern, &others, |b| b.count_and_lowest_below(best, None))?);
        if let Some((_, p)) = lowest_of(&out) {
            self.lowest_wavenumber = p;
        }
        out.sort_by_key(|s| s.wavenumber);
        Ok(out)
    }

    /// `task` on the blocks of wavenumbers `ps` at the pair's KKT values in `self.pair`,
    /// shared out between the workers by `p` modulo their number (the first worker on this
    /// thread, each other one with blocks to judge on a thread of its own): a block stays
    /// with the worker whose factorisation workspace it has built (the first use of a
    /// workspace costs what a few factorisations do), and the blocks of all wavenumbers
    /// are shared about evenly; results in the order of `ps`.
    fn run<T: Send>(
        &mut self,
        pattern: &SymbolicSparseColMat<usize>,
        ps: &[usize],
        task: impl Fn(&mut BlockView) -> Result<T, InertiaError> + Sync,
    ) -> Vec<(usize, Result<T, InertiaError>)> {
        let task: &BlockTask<T> = &task;
        let threads = self.workers.len();
        let mut jobs: Vec<Vec<(usize, BlockWarm)>> = (0..threads).map(|_| Vec::new()).collect();
        for &p in ps {
            jobs[p % threads].push((p, std::mem::take(&mut self.warm[p])));
        }
        let (bloch, pair) = (&self.bloch, &self.pair);
        let mut busy = self
            .workers
            .iter_mut()
            .zip(jobs)
            .filter(|(_, jobs)| !jobs.is_empty());
        let done: Vec<_> = match busy.next() {
            None => Vec::new(),
            Some((w0, j0)) => std::thread::scope(|scope| {
                let others: Vec<_> = busy
                    .map(|(w, j)| scope.spawn(move || w.run(bloch, pattern, pair, j, task)))
                    .collect();
                let mut done = w0.run(bloch, pattern, pair, j0, task);
                for other in others {
                    done.extend(other.join().expect("a block's thread does not panic"));
                }
                done
            }),
        };
        let mut out = Vec::with_capacity(ps.len());
        for (p, warm, result) in done {
            self.warm[p] = warm;
            out.push((p, result));
        }
        out.sort_by_key(|(p, _)| ps.iter().position(|q| q == p));
        out
    }
}

/// A task on one block: the wavenumber, the block's pattern and values, its stability.
type BlockTask<'a, T> = dyn Fn(&mut BlockView) -> Result<T, InertiaError> + Sync + 'a;

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

impl StabilityJudge for JudgeByBlocks {
    /// For the lowest eigenvalue, only the block that had it last time is iterated on; every
    /// other block is asked, by one inertia count at that eigenvalue, whether it has one
    /// below (and the same factorisation counts its unstable directions when it has none).
    fn blocks(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        eigenvalue: bool,
    ) -> Result<Vec<BlockStability>, InertiaError> {
        system.evaluate(model, x, &mut self.residual, &mut self.pair);
        let pattern = system.pattern();
        let all: Vec<usize> = self.bloch.wavenumbers().collect();
        if !eigenvalue {
            return self
                .run(pattern, &all, |b| {
                    b.unstable_directions().map(|c| (c, None))
                })
                .into_iter()
                .map(|(p, r)| r.map(|(c, l)| self.stability_of(p, c, l)))
                .collect();
        }
        let (rough, upper) = self.upper_estimate(pattern, &all);
        match upper {
            Some(upper) => self.below_estimate(pattern, &all, &rough, upper),
            None => self.lowest_first(pattern, all),
        }
    }

    fn nearest_zero_with_mode(
        &mut self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
    ) -> Option<(f64, usize, Vec<f64>)> {
        system.evaluate(model, x, &mut self.residual, &mut self.pair);
        let pattern = system.pattern();
        let ps: Vec<usize> = match self.focus {
            Some(p) => vec![p],
            None => self.bloch.wavenumbers().collect(),
        };
        let found = self.run(pattern, &ps, |b| Ok(b.nearest_zero()));
        let mut nearest: Option<(f64, usize, Vec<f64>)> = None;
        for (p, r) in found {
            let (mu, mode) = r.ok()??;
            if nearest.as_ref().is_none_or(|n| mu.abs() < n.0.abs()) {
                nearest = Some((mu, p, mode));
            }
        }
        nearest
    }

    fn has_wavenumbers(&self) -> bool {
        true
    }

    fn multiplicity(&self, p: usize) -> usize {
        self.bloch.multiplicity(p)
    }

    fn focus(&mut self, p: Option<usize>) {
        self.focus = p;
    }

    /// The structure of the real blocks: the pair's own pattern, metric and length.
    fn kkt_structure(&self, pattern: &SymbolicSparseColMat<usize>) -> Option<Arc<KktStructure>> {
        self.workers[0].real.structure_for(pattern).ok()
    }

    fn set_threads(&mut self, threads: usize) {
        let threads = threads.max(1);
        if threads < self.workers.len() {
            self.workers.truncate(threads);
        }
        while self.workers.len() < threads {
            let worker = Worker::sharing(&self.workers[0].real);
            self.workers.push(worker);
        }
    }
}
