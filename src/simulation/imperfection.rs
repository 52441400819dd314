//! Imperfect structures (docs/theory.md §9): the natural state flawed along a critical mode
//! of the perfect structure, found by following the perfect path to it, or along a named
//! shape.

use super::flaw::{
    bow_rotations, flaw_references, mode_rotations, mode_scale, perfect_point, Flaw,
};
use super::{Simulation, SolveError, Start};
use crate::case::{Case, Imperfection, ImperfectionShape};
use crate::discretisation::discrete_model::DiscreteModel;
use crate::results::CriticalPoint;
use crate::solver::continuation::{ContinuationError, StopReason};
use crate::solver::interrupt::Interrupt;

/// A critical mode on the model it lives on.
pub(super) struct ModeOnModel {
    pub model: DiscreteModel,
    /// The critical state (all unknowns of `model`'s system).
    pub state: Vec<f64>,
    /// The mode (primal unknowns at least, unit norm over them).
    pub mode: Vec<f64>,
    /// At a double point, the other mode of its plane.
    pub second: Option<Vec<f64>>,
    /// Whether `model` is the whole assembly standing in for the reduced model solved (a
    /// mode that breaks its symmetry).
    pub whole: bool,
}

impl Simulation {
    /// The flaw of the natural state of an imperfect case (`None`: a perfect structure).
    pub fn flaw(&self) -> Option<&Flaw> {
        self.flaw.as_ref()
    }

    /// The perfect structure of `case` (its imperfection removed) followed until critical
    /// point `index` is located, stopping there: the simulation, past the point.
    pub(super) fn perfect_until(
        case: &Case,
        index: usize,
        interrupt: &Option<Interrupt>,
        threads: usize,
    ) -> Result<Simulation, SolveError> {
        let mut perfect = case.clone();
        perfect.imperfection = None;
        let start = Start {
            interrupt: interrupt.clone(),
            threads,
            ..Start::plain(perfect.solver)
        };
        let mut sim = Simulation::start_case(&perfect, start)?;
        let targets = perfect.output_parameters(perfect.loading.target, perfect.loading.steps);
        for target in targets {
            if sim.critical_points().len() > index {
                break;
            }
            let outcome = sim.advance_to(target);
            if sim.critical_points().len() > index {
                break;
            }
            outcome?;
        }
        if sim.critical_points().len() <= index {
            let lambda = sim.parameter();
            return Err(sim.error(ContinuationError {
                reached: lambda,
                target: perfect.loading.target,
                step: 0.0,
                reason: StopReason::NoImperfectionMode {
                    index,
                    found: sim.critical_points().len(),
                },
            }));
        }
        Ok(sim)
    }

    /// The model of `case` with its flaw: the reference curvatures of the natural state
    /// displaced along the flaw's shape, and what the flaw was measured against.
    pub(super) fn flawed_model(
        case: &Case,
        imperfection: Imperfection,
        interrupt: &Option<Interrupt>,
        threads: usize,
    ) -> Result<(DiscreteModel, Flaw), SolveError> {
        match imperfection.shape {
            ImperfectionShape::Mode(index) => {
                let sim = Simulation::perfect_until(case, index, interrupt, threads)?;
                let cp = sim.critical_points()[index].clone();
                let ModeOnModel {
                    mut model,
                    state,
                    mode,
                    whole,
                    ..
                } = sim.mode_on_model(&cp);
                let Some(scale) = mode_scale(&model, &mode, imperfection.amplitude) else {
                    let lambda = sim.parameter();
                    return Err(sim.error(ContinuationError {
                        reached: lambda,
                        target: lambda,
                        step: 0.0,
                        reason: StopReason::FlatImperfectionMode { index },
                    }));
                };
                let rotations = mode_rotations(&model, &state, &mode, scale);
                flaw_references(&mut model, &rotations);
                let flaw = Flaw {
                    imperfection,
                    perfect: Some(perfect_point(index, &cp)),
                    whole_assembly: whole,
                };
                Ok((model, flaw))
            }
            ImperfectionShape::Bow => {
                // the perfect critical point the bow is measured against: the path's first
                let perfect = Simulation::perfect_until(case, 0, interrupt, threads)
                    .ok()
                    .map(|sim| perfect_point(0, &sim.critical_points()[0]));
                let mut model = case.model();
                let rotations = bow_rotations(&model, imperfection.amplitude);
                flaw_references(&mut model, &rotations);
                let flaw = Flaw {
                    imperfection,
                    perfect,
                    whole_assembly: false,
                };
                Ok((model, flaw))
            }
        }
    }

    /// The model a critical point's mode lives on, with the critical state and mode there.
    pub(super) fn mode_on_model(&self, cp: &CriticalPoint) -> ModeOnModel {
        let second = cp.second_mode.clone();
        if !self.reduction().keeps(cp) {
            if let (Some((full, _, x)), Some(mode)) =
                (self.on_whole_assembly(cp), &cp.assembly_mode)
            {
                return ModeOnModel {
                    model: full,
                    state: x,
                    mode: mode.clone(),
                    second,
                    whole: true,
                };
            }
        }
        ModeOnModel {
            model: self.model().clone(),
            state: cp.state.clone(),
            mode: cp.mode.clone(),
            second,
            whole: false,
        }
    }
}
