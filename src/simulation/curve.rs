//! Critical curves: the first critical point of a case's path continued in a second
//! parameter, any numeric key of the case (docs/theory.md, "Critical curves"). The case is
//! rebuilt at every value of the key by the case reader (as `--set key=value` would), with
//! the same mesh, and the extended system of [`crate::solver::extended`] is continued by
//! the engine of [`crate::solver::continuation`].

use super::problem::{mean_tip_height, LoadedAssembly};
use super::{Simulation, SolveError};
use crate::case::{Case, CaseError, Setting};
use crate::discretisation::fields;
use crate::discretisation::system::System;
use crate::results::{CriticalKind, CriticalPoint};
use crate::solver::continuation::{Continuation, ContinuationSettings};
use crate::solver::extended::{CriticalStart, CriticalSystem, Family};
use crate::solver::interrupt::Interrupt;
use crate::solver::problem::Problem;
use toml::Value;

/// What to continue: the key varied, from where to where, and the rows written on the way.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveSpec {
    /// A dotted numeric key of the case file (`geometry.length`).
    pub key: String,
    pub from: f64,
    pub to: f64,
    /// Rows: equally spaced values of the key from `from` to `to`, both included (at
    /// least 2).
    pub rows: usize,
}

/// One point of a critical curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveRow {
    /// The key's value.
    pub value: f64,
    /// The load parameter at the critical point.
    pub parameter: f64,
    /// Compression ratio there.
    pub eps: f64,
    /// Axial tip force, the tip reactions summed over the rods (N; negative: compression).
    pub fz: f64,
    /// Torque about the axis the tip support applies to the rods, summed (N m).
    pub torque: f64,
    pub kind: CriticalKind,
    pub wavenumber: Option<usize>,
    pub multiplicity: usize,
}

/// A critical curve: its rows, and why it stopped short of the end, if it did.
#[derive(Debug)]
pub struct CriticalCurve {
    pub rows: Vec<CurveRow>,
    /// The load parameter's name and unit, as the faces label it.
    pub parameter_label: String,
    pub stopped: Option<CurveError>,
}

/// Why a critical curve could not be started, or stopped.
#[derive(Debug, thiserror::Error)]
pub enum CurveError {
    /// The key (or its value at the start) is not one the case accepts.
    #[error("--vary {key}: {cause}")]
    Key { key: String, cause: Box<CaseError> },
    #[error("--vary {key}: expected a numeric key of the case file (a number, such as geometry.length or stiffness.b3), but the case reads it as {found}")]
    NotNumeric { key: String, found: String },
    #[error("--vary {key}: the key sets the number of unknowns (the mesh, the helices), which must stay fixed along a critical curve")]
    Layout { key: String },
    #[error("expected --from and --to to be finite and different, found {from} and {to}")]
    Range { from: f64, to: f64 },
    #[error("the path of the case at {key} = {value} meets no critical point up to its target {target}{}", .reason.as_ref().map(|r| format!(" (it stopped: {r})")).unwrap_or_default())]
    NoCriticalPoint {
        key: String,
        value: f64,
        target: f64,
        reason: Option<String>,
    },
    #[error("the case at {key} = {value} does not start: {cause}")]
    Start {
        key: String,
        value: f64,
        cause: SolveError,
    },
    #[error("the first critical point at {key} = {value} is of the Bloch block of wavenumber {wavenumber} of a symmetric pair, not a singular point of the pair's own matrix: continue it on the full model (--set discretisation.symmetric=false)")]
    BlochBlock {
        key: String,
        value: f64,
        wavenumber: usize,
    },
    #[error("the critical point at {key} = {value} cannot be continued: {reason}")]
    Extended {
        key: String,
        value: f64,
        reason: String,
    },
    #[error("the critical curve stopped at {key} = {reached} (target {target}): {reason}")]
    Stopped {
        key: String,
        reached: f64,
        target: f64,
        reason: String,
    },
}

/// Keys whose value sets the layout of the state (never varied along a curve).
const LAYOUT_KEYS: [&str; 4] = [
    "geometry.helices",
    "discretisation.elements",
    "discretisation.order",
    "discretisation.accuracy",
];

/// The case rebuilt at every value of one key: a [`Family`] of loaded assemblies.
pub struct CaseFamily {
    text: String,
    file: String,
    stem: String,
    settings: Vec<Setting>,
    key: String,
    /// The scale of the key's central differences (the larger of its ends' sizes).
    scale: f64,
}

impl CaseFamily {
    /// The case of `text` (`file`, `stem` as for [`Case::parse_with`]) with `settings`,
    /// varied in `key`.
    pub fn new(text: &str, file: &str, stem: &str, settings: &[Setting], spec: &CurveSpec) -> Self {
        CaseFamily {
            text: text.to_string(),
            file: file.to_string(),
            stem: stem.to_string(),
            settings: settings.to_vec(),
            key: spec.key.clone(),
            scale: spec.from.abs().max(spec.to.abs()).max(1e-300),
        }
    }

    /// The case at `value` of the key.
    pub fn case(&self, value: f64) -> Result<Case, CaseError> {
        let mut settings = self.settings.clone();
        settings.retain(|s| s.key != self.key);
        settings.push(Setting {
            key: self.key.clone(),
            value: Value::Float(value),
        });
        Case::parse_with(&self.text, &self.file, &self.stem, &settings)
    }
}

/// The loaded assembly of `case` at its natural state, as its path starts.
fn assembly(case: &Case) -> LoadedAssembly {
    let model = case.model();
    let x0 = model.natural_state();
    let system = System::new(&model, case.boundary, &x0, &case.loads(), 0.0);
    LoadedAssembly::new(model, system).with_threads(1)
}

impl Family for CaseFamily {
    type Member = LoadedAssembly;

    fn member(&mut self, mu: f64) -> Result<LoadedAssembly, String> {
        self.case(mu)
            .map(|c| assembly(&c))
            .map_err(|e| e.to_string())
    }

    fn step(&self, mu: f64) -> f64 {
        1e-6 * self.scale.max(mu.abs())
    }
}

/// The critical curve of the case of `text` with `settings`: its first critical point at
/// `spec.from` (located by the case's own path), continued in `spec.key` to `spec.to`.
/// A curve that stops on the way keeps its rows and says why in
/// [`CriticalCurve::stopped`].
pub fn critical_curve(
    text: &str,
    file: &str,
    stem: &str,
    settings: &[Setting],
    spec: &CurveSpec,
) -> Result<CriticalCurve, CurveError> {
    check_spec(text, file, stem, settings, spec)?;
    let family = CaseFamily::new(text, file, stem, settings, spec);
    let case = family.case(spec.from).map_err(|e| key_error(spec, e))?;
    let critical = first_critical(&case, spec)?;
    let extended_error = |reason: String| CurveError::Extended {
        key: spec.key.clone(),
        value: spec.from,
        reason,
    };
    let start = CriticalStart {
        x: critical.state.clone(),
        lambda: critical.parameter,
        mu: spec.from,
        modes: start_modes(&critical),
        bifurcation: critical.kind == CriticalKind::Bifurcation,
    };
    let mut check = assembly(&case);
    check_holds(&mut check, &start).map_err(extended_error)?;
    let mut system = CriticalSystem::new(family, &start).map_err(extended_error)?;
    let stop = Interrupt::new();
    system.set_stop(Some(stop.clone()));
    let xe = system.extend(&start.x, start.lambda);
    let settings = curve_settings(&case.solver, spec);
    let mut path = Continuation::new(system, xe, spec.from, settings)
        .map_err(|e| extended_error(e.to_string()))?;
    path.set_interrupt(Some(stop));
    let multiplicity = path.problem().borders();
    let describe = |path: &mut Continuation<CriticalSystem<CaseFamily>>| {
        let (x, lambda) = path.problem().split(&path.state().x);
        let mu = path.state().lambda;
        let member = path.problem_mut().member_at(mu)?;
        Some(row(member, &x, lambda, mu, &critical, multiplicity))
    };
    let mut rows = Vec::new();
    let mut stopped = None;
    for k in 0..spec.rows {
        let value = spec.from + (spec.to - spec.from) * (k as f64 / (spec.rows - 1) as f64);
        let value = if k + 1 == spec.rows { spec.to } else { value };
        if let Err(e) = path.advance_to(value) {
            let reason = path
                .problem()
                .refusal()
                .map_or_else(|| e.reason.to_string(), str::to_string);
            stopped = Some(CurveError::Stopped {
                key: spec.key.clone(),
                reached: e.reached,
                target: spec.to,
                reason,
            });
            break;
        }
        rows.extend(describe(&mut path));
    }
    Ok(CriticalCurve {
        rows,
        parameter_label: case.load_parameter().label().to_string(),
        stopped,
    })
}

/// Refuses a range that is not one, a key that sets the layout, and a key the case does
/// not read as a number.
fn check_spec(
    text: &str,
    file: &str,
    stem: &str,
    settings: &[Setting],
    spec: &CurveSpec,
) -> Result<(), CurveError> {
    if !spec.from.is_finite() || !spec.to.is_finite() || spec.from == spec.to {
        return Err(CurveError::Range {
            from: spec.from,
            to: spec.to,
        });
    }
    if LAYOUT_KEYS.contains(&spec.key.as_str()) {
        return Err(CurveError::Layout {
            key: spec.key.clone(),
        });
    }
    Case::parse_with(text, file, stem, settings).map_err(|e| key_error(spec, e))?;
    let doc: toml::Table = text.parse().unwrap_or_default();
    let mut node = Some(&Value::Table(doc));
    for part in spec.key.split('.') {
        node = node.and_then(|v| v.as_table()).and_then(|t| t.get(part));
    }
    if let Some(found) = node.filter(|v| !(v.is_float() || v.is_integer())) {
        return Err(CurveError::NotNumeric {
            key: spec.key.clone(),
            found: format!("{} `{found}`", found.type_str()),
        });
    }
    Ok(())
}

fn key_error(spec: &CurveSpec, e: CaseError) -> CurveError {
    CurveError::Key {
        key: spec.key.clone(),
        cause: Box::new(e),
    }
}

/// The first critical point (not a neutral direction) of the case's path.
fn first_critical(case: &Case, spec: &CurveSpec) -> Result<CriticalPoint, CurveError> {
    let start_error = |cause| CurveError::Start {
        key: spec.key.clone(),
        value: spec.from,
        cause,
    };
    let mut sim = Simulation::from_case_on(case, 1).map_err(start_error)?;
    let mut reason = None;
    for target in case.output_parameters(case.loading.target, case.loading.steps) {
        let outcome = sim.advance_to(target);
        let found = sim
            .critical_points()
            .iter()
            .find(|c| c.kind != CriticalKind::Neutral);
        if let Some(c) = found {
            if let Some(p) = c.wavenumber.filter(|&p| p != 0) {
                return Err(CurveError::BlochBlock {
                    key: spec.key.clone(),
                    value: spec.from,
                    wavenumber: p,
                });
            }
            return Ok(c.clone());
        }
        if let Err(e) = outcome {
            reason = Some(e.to_string());
            break;
        }
    }
    Err(CurveError::NoCriticalPoint {
        key: spec.key.clone(),
        value: spec.from,
        target: case.loading.target,
        reason,
    })
}

/// The modes that border the extended system: the critical mode, and at a double point
/// of the model's own matrix the other mode of its plane.
fn start_modes(c: &CriticalPoint) -> Vec<Vec<f64>> {
    let mut modes = vec![c.mode.clone()];
    if c.multiplicity > 1 && c.wavenumber.is_none_or(|p| p == 0) {
        if let Some(second) = c.second_mode.as_ref().filter(|m| m.len() <= c.mode.len()) {
            modes.push(second.clone());
        }
    }
    modes
}

/// The assembly rebuilt at the start holds the located state (the same supports and
/// loads as the path's): else the curve would be of another problem.
fn check_holds(member: &mut LoadedAssembly, start: &CriticalStart) -> Result<(), String> {
    let n = member.unknowns();
    if start.x.len() != n {
        return Err(format!(
            "the path's state has {} unknowns, the case rebuilt {n}",
            start.x.len()
        ));
    }
    let mut r = vec![0.0; n];
    let mut w = vec![1.0; n];
    member.residual(&start.x, start.lambda, &mut r);
    member.residual_weights(&mut w);
    let worst = r
        .iter()
        .zip(&w)
        .map(|(a, b)| (a * b).abs())
        .fold(0.0, f64::max);
    if worst.is_finite() && worst <= 1e-6 {
        Ok(())
    } else {
        Err(format!("the case rebuilt from its natural state does not hold the path's critical state (weighted residual {worst:.2e}): its supports or held loads differ from the path's"))
    }
}

/// The continuation settings of a curve: steps in the key's own measure, no stability.
fn curve_settings(solver: &ContinuationSettings, spec: &CurveSpec) -> ContinuationSettings {
    let span = (spec.to - spec.from).abs();
    let interval = span / (spec.rows - 1).max(1) as f64;
    ContinuationSettings {
        initial_step: interval.min(span / 20.0),
        min_step: span * 1e-7,
        max_step: interval,
        target_iterations: 6,
        arclength_fallback: true,
        track_stability: false,
        lowest_eigenvalue: false,
        critical_tolerance: solver.critical_tolerance,
        newton: solver.newton,
    }
}

/// The row of the critical state `x` at `(λ, μ)` of `member`.
fn row(
    member: &mut LoadedAssembly,
    x: &[f64],
    lambda: f64,
    mu: f64,
    critical: &CriticalPoint,
    multiplicity: usize,
) -> CurveRow {
    let mut r = vec![0.0; member.unknowns()];
    member.residual(x, lambda, &mut r);
    let (model, system) = (&member.model, &member.system);
    let reactions = fields::reactions(model, system, x);
    let height = mean_tip_height(model, x);
    let support = fields::support_response(model, system, x, &reactions, height);
    CurveRow {
        value: mu,
        parameter: lambda,
        eps: 1.0 - height / model.height0(),
        fz: reactions.iter().map(|r| r.tip.force[2]).sum(),
        torque: support.torque,
        kind: critical.kind,
        wavenumber: critical.wavenumber,
        multiplicity: critical.multiplicity.max(multiplicity),
    }
}
