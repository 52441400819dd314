//! The reductions of an assembly: which rods are modelled, and how they stand for the whole
//! assembly. The whole assembly is modelled as it is ([`WholeAssembly`]); an assembly of
//! `n = 2m` helices under boundary conditions shared by all rods is modelled by one
//! right/left pair, each of whose rods stands for `m` rods turned about the axis
//! ([`CyclicPair`], docs/theory.md §7). Each reduction owns what differs between them: the
//! images of a modelled rod, the expansion of a state and of a critical mode to the whole
//! assembly, how stability is judged there ([`StabilityJudge`]), and its label on the faces.

use super::blocks::JudgeByBlocks;
use super::cell::{phase_grid, CellJudge, PATH_PHASES};
use super::judge::{JudgeOnItself, StabilityJudge};
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::symmetry::{assembly_mode, expand_state};
use crate::discretisation::system::System;
use crate::results::{CriticalKind, CriticalPoint};
use crate::solver::continuation::Critical;

/// How the modelled rods stand for the whole assembly.
pub trait Reduction: Send + Sync {
    /// What the model solved is, as the faces name it ("full model", "symmetric pair").
    fn label(&self) -> &'static str;

    /// Whether fewer rods than the whole assembly's are modelled.
    fn is_reduced(&self) -> bool {
        true
    }

    /// Number of rods of the whole assembly each rod of `model` stands for.
    fn images(&self, model: &DiscreteModel) -> f64;

    /// The whole assembly `model` stands for (same meshes and hypotheses), when `model` is
    /// reduced.
    fn whole(&self, model: &DiscreteModel) -> Option<DiscreteModel>;

    /// Expands the state `x` of `model` (in `system`'s layout) to the state of the whole
    /// assembly `whole` in `whole_system`'s layout (`out`, of the length of its unknowns):
    /// support and joint multipliers are zero (they do not enter the Hessian).
    fn expand_state(
        &self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        whole: &DiscreteModel,
        whole_system: &System,
        out: &mut [f64],
    );

    /// The judge of the stability of `model`'s states on the whole assembly, its block
    /// work shared out on `threads` threads where it has independent blocks.
    fn judge(
        &self,
        model: &DiscreteModel,
        system: &System,
        threads: usize,
    ) -> Box<dyn StabilityJudge>;

    /// The modes of the critical point `critical` of `model` (found by `judge`), described
    /// on the whole assembly.
    fn critical_modes(
        &self,
        model: &DiscreteModel,
        system: &System,
        judge: &mut dyn StabilityJudge,
        critical: &Critical,
    ) -> CriticalModes;

    /// Whether the branches leaving `critical` keep to the model solved (else a switch
    /// moves the path onto the whole assembly).
    fn keeps(&self, critical: &CriticalPoint) -> bool;
}

/// The reduction `model` is solved in.
pub fn of(model: &DiscreteModel) -> Box<dyn Reduction> {
    if model.assembly.cell.is_some() {
        return Box::new(TubeCell);
    }
    match model.assembly.symmetry {
        Some(_) => Box::new(CyclicPair),
        None => Box::new(WholeAssembly),
    }
}

/// The modes of a critical point, as [`crate::results::CriticalPoint`] reports them.
#[derive(Clone, Debug, Default)]
pub struct CriticalModes {
    /// The wavenumber of the mode, when the blocks judged are of distinct wavenumbers.
    pub wavenumber: Option<usize>,
    /// The axial Bloch phase of the mode (rad per cell), for a cell.
    pub bloch_phase: Option<f64>,
    /// Modes crossing together.
    pub multiplicity: usize,
    /// For a reduced model: the critical mode on the whole assembly (its primal unknowns).
    pub assembly_mode: Option<Vec<f64>>,
    /// The other mode of the plane of a double point, when there is one (on the whole
    /// assembly for a reduced model).
    pub second_mode: Option<Vec<f64>>,
}

/// Every rod of the assembly modelled, its stability judged on its own KKT matrix.
#[derive(Clone, Copy, Debug)]
pub struct WholeAssembly;

impl Reduction for WholeAssembly {
    fn label(&self) -> &'static str {
        "full model"
    }

    fn is_reduced(&self) -> bool {
        false
    }

    fn images(&self, _model: &DiscreteModel) -> f64 {
        1.0
    }

    fn whole(&self, _model: &DiscreteModel) -> Option<DiscreteModel> {
        None
    }

    /// The state itself.
    fn expand_state(
        &self,
        _model: &DiscreteModel,
        _system: &System,
        x: &[f64],
        _whole: &DiscreteModel,
        _whole_system: &System,
        out: &mut [f64],
    ) {
        out.copy_from_slice(&x[..out.len()]);
    }

    fn judge(
        &self,
        model: &DiscreteModel,
        system: &System,
        _threads: usize,
    ) -> Box<dyn StabilityJudge> {
        Box::new(JudgeOnItself::new(model, system))
    }

    /// At a double point (two eigenvalues crossing together) the plane's other mode; the
    /// multiplicity is the jump of the count of unstable directions, as the blocks give
    /// theirs (a neutral direction, which crosses nothing, one).
    fn critical_modes(
        &self,
        model: &DiscreteModel,
        system: &System,
        judge: &mut dyn StabilityJudge,
        critical: &Critical,
    ) -> CriticalModes {
        let jump = critical.unstable_after.abs_diff(critical.unstable_before);
        let double = jump == 2;
        let second = double
            .then(|| judge.second_mode(model, system, &critical.state, &critical.mode))
            .flatten();
        CriticalModes {
            wavenumber: None,
            bloch_phase: None,
            multiplicity: match critical.kind {
                CriticalKind::Neutral => 1,
                _ => jump.max(1),
            },
            assembly_mode: None,
            second_mode: second,
        }
    }

    fn keeps(&self, _critical: &CriticalPoint) -> bool {
        true
    }
}

/// One right/left pair standing for the `n = 2m` rods of a cyclically symmetric assembly,
/// its stability judged by the Bloch blocks of its KKT matrix, one per wavenumber.
#[derive(Clone, Copy, Debug)]
pub struct CyclicPair;

impl Reduction for CyclicPair {
    fn label(&self) -> &'static str {
        "symmetric pair"
    }

    fn images(&self, model: &DiscreteModel) -> f64 {
        model
            .assembly
            .symmetry
            .map_or(1.0, |s| s.full_rods() as f64 / model.rods.len() as f64)
    }

    fn whole(&self, model: &DiscreteModel) -> Option<DiscreteModel> {
        model.full_model()
    }

    /// Every rod is the image of one rod of the pair turned about z.
    fn expand_state(
        &self,
        model: &DiscreteModel,
        system: &System,
        x: &[f64],
        whole: &DiscreteModel,
        whole_system: &System,
        out: &mut [f64],
    ) {
        expand_state(model, system, x, whole, whole_system, out);
    }

    fn judge(
        &self,
        model: &DiscreteModel,
        system: &System,
        threads: usize,
    ) -> Box<dyn StabilityJudge> {
        match JudgeByBlocks::new(model, system, threads) {
            Some(blocks) => Box::new(blocks),
            None => WholeAssembly.judge(model, system, threads),
        }
    }

    /// The mode of the block whose count changed, rebuilt on the whole assembly; for a
    /// complex block (`0 < p < m/2`: a double point of wavenumbers `p` and `m − p`) also
    /// the mode `i v`, the other of the plane.
    fn critical_modes(
        &self,
        model: &DiscreteModel,
        system: &System,
        judge: &mut dyn StabilityJudge,
        critical: &Critical,
    ) -> CriticalModes {
        let Some(full) = self.whole(model) else {
            return WholeAssembly.critical_modes(model, system, judge, critical);
        };
        let p = critical.block;
        let v = judge.block_mode(model, system, &critical.state, p);
        let rebuilt = |v: &[f64]| assembly_mode(model, p, v, &full);
        let first = v.as_deref().map(rebuilt);
        // i v: (re, im) → (−im, re)
        let second = v.filter(|_| judge.multiplicity(p) > 1).map(|v| {
            let half = v.len() / 2;
            let turned: Vec<f64> = v[half..]
                .iter()
                .map(|x| -x)
                .chain(v[..half].iter().copied())
                .collect();
            rebuilt(&turned)
        });
        CriticalModes {
            wavenumber: Some(p),
            bloch_phase: None,
            multiplicity: judge.multiplicity(p),
            assembly_mode: first,
            second_mode: second,
        }
    }

    /// A mode of wavenumber 0 keeps the symmetry.
    fn keeps(&self, critical: &CriticalPoint) -> bool {
        critical.wavenumber == Some(0)
    }
}

/// The cell of an infinite tube standing for the whole tube: each of its rods for the `m`
/// rods of its chirality over one rise of the cell, its stability judged by the blocks
/// `H(p, k)`.
#[derive(Clone, Copy, Debug)]
pub struct TubeCell;

impl Reduction for TubeCell {
    fn label(&self) -> &'static str {
        "tube cell"
    }

    fn images(&self, model: &DiscreteModel) -> f64 {
        model.assembly.cell.as_ref().map_or(1.0, |c| c.sectors())
    }

    /// An infinite tube is not modelled whole.
    fn whole(&self, _model: &DiscreteModel) -> Option<DiscreteModel> {
        None
    }

    fn expand_state(
        &self,
        _model: &DiscreteModel,
        _system: &System,
        x: &[f64],
        _whole: &DiscreteModel,
        _whole_system: &System,
        out: &mut [f64],
    ) {
        out.copy_from_slice(&x[..out.len()]);
    }

    fn judge(
        &self,
        model: &DiscreteModel,
        system: &System,
        threads: usize,
    ) -> Box<dyn StabilityJudge> {
        match CellJudge::new(model, system, PATH_PHASES) {
            Some(judge) => Box::new(judge),
            None => WholeAssembly.judge(model, system, threads),
        }
    }

    /// The block whose count changed: its wavenumber `p` and phase `k`.
    fn critical_modes(
        &self,
        _model: &DiscreteModel,
        _system: &System,
        judge: &mut dyn StabilityJudge,
        critical: &Critical,
    ) -> CriticalModes {
        let b = critical.block;
        let grid = phase_grid(PATH_PHASES);
        CriticalModes {
            wavenumber: Some(b / grid.len()),
            bloch_phase: grid.get(b % grid.len()).copied(),
            multiplicity: judge.multiplicity(b),
            assembly_mode: None,
            second_mode: None,
        }
    }

    /// A mode of the block `(0, 0)` keeps the cell's periodicity.
    fn keeps(&self, critical: &CriticalPoint) -> bool {
        critical.wavenumber == Some(0) && critical.bloch_phase.is_none_or(|k| k == 0.0)
    }
}
