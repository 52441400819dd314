//! Critical curves: the first critical point of a case's path continued in a second
//! parameter, any numeric key of the case (docs/theory.md, "Critical curves"). The case is
//! rebuilt at every value of the key by the case reader (as `--set key=value` would), with
//! the same mesh, and the extended system of [`crate::solver::extended`] is continued by
//! the engine of [`crate::solver::continuation`].

use super::problem::{mean_tip_height, LoadedAssembly};
use super::{Simulation, SolveError};
use crate::case::{Case, CaseError, DesignKey, Refused, Setting};
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
    /// The rows' values when they are given (a sweep's axis, from `from` to `to` in order);
    /// empty: `rows` equally spaced values.
    pub at: Vec<f64>,
}

impl CurveSpec {
    /// The curve in `key` through `values` (at least 2, in increasing or decreasing order),
    /// a row at each.
    pub fn through(key: &str, values: &[f64]) -> CurveSpec {
        CurveSpec {
            key: key.to_string(),
            from: values.first().copied().unwrap_or(f64::NAN),
            to: values.last().copied().unwrap_or(f64::NAN),
            rows: values.len(),
            at: values.to_vec(),
        }
    }

    /// The values of the key where the rows are.
    pub fn values(&self) -> Vec<f64> {
        if !self.at.is_empty() {
            return self.at.clone();
        }
        let last = self.rows.max(2) - 1;
        (0..=last)
            .map(|k| match k {
                k if k == last => self.to,
                k => self.from + (self.to - self.from) * (k as f64 / last as f64),
            })
            .collect()
    }
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
    /// Times the point was located afresh by the case's path where the layout of the
    /// state changed between rows ([`follow`]).
    pub relocated: usize,
}

/// Why a critical curve could not be started, or stopped.
#[derive(Debug, thiserror::Error)]
pub enum CurveError {
    /// The key (or its value at the start) is not one the case accepts.
    #[error("--vary {key}: {cause}")]
    Key { key: String, cause: Box<CaseError> },
    /// A design key's value the case reader would refuse.
    #[error("{cause} (at {value})")]
    Refused { value: f64, cause: Refused },
    #[error("--vary {key}: expected a numeric key of the case file (a number, such as geometry.length or stiffness.b3), but the case reads it as {found}")]
    NotNumeric { key: String, found: String },
    #[error("--vary {key}: the key sets the number of unknowns (the mesh, the helices), which must stay fixed along a critical curve")]
    Layout { key: String },
    #[error("expected --from and --to to be finite and different, found {from} and {to}")]
    Range { from: f64, to: f64 },
    #[error("{key}: expected the values of the rows in order from the first to the last")]
    Order { key: String },
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
    #[error("the critical curve stopped at {key} = {} (target {}): {reason}", short(*.reached), short(*.target))]
    Stopped {
        key: String,
        reached: f64,
        target: f64,
        reason: String,
    },
}

/// A value reached by continuation for a message, to ten significant digits (so that
/// 1.8800000000000001 reads 1.88).
fn short(x: f64) -> String {
    let rounded = format!("{x:.9e}").parse::<f64>().unwrap_or(x);
    crate::case::num(rounded)
}

/// Keys whose value sets the layout of the state (never varied along a curve).
const LAYOUT_KEYS: [&str; 4] = [
    "geometry.helices",
    "discretisation.elements",
    "discretisation.order",
    "discretisation.accuracy",
];

/// Where the members of a [`CaseFamily`] come from.
#[derive(Clone)]
enum Source {
    /// The case text read again at every value of the key, with the settings (the route
    /// of `--set`).
    Text {
        text: String,
        file: String,
        stem: String,
        settings: Vec<Setting>,
    },
    /// An accepted case with one design key set ([`Case::with_design`]): the explorer's
    /// scene, which has no file of its own.
    Design { case: Box<Case>, key: DesignKey },
}

/// The case rebuilt at every value of one key: a [`Family`] of loaded assemblies.
#[derive(Clone)]
pub struct CaseFamily {
    source: Source,
    key: String,
    /// The scale of the key's central differences (the larger of its ends' sizes).
    scale: f64,
}

impl CaseFamily {
    /// The case of `text` (`file`, `stem` as for [`Case::parse_with`]) with `settings`,
    /// varied in `key`.
    pub fn new(text: &str, file: &str, stem: &str, settings: &[Setting], spec: &CurveSpec) -> Self {
        let source = Source::Text {
            text: text.to_string(),
            file: file.to_string(),
            stem: stem.to_string(),
            settings: settings.to_vec(),
        };
        CaseFamily::of(source, spec)
    }

    /// `case` varied in its design key `key` (`spec.key` is that key's name).
    pub fn design(case: &Case, key: DesignKey, spec: &CurveSpec) -> Self {
        let source = Source::Design {
            case: Box::new(case.clone()),
            key,
        };
        CaseFamily::of(source, spec)
    }

    fn of(source: Source, spec: &CurveSpec) -> Self {
        CaseFamily {
            source,
            key: spec.key.clone(),
            scale: spec.from.abs().max(spec.to.abs()).max(1e-300),
        }
    }

    /// The case at `value` of the key.
    pub fn case(&self, value: f64) -> Result<Case, CurveError> {
        match &self.source {
            Source::Text {
                text,
                file,
                stem,
                settings,
            } => {
                let mut settings = settings.clone();
                settings.retain(|s| s.key != self.key);
                settings.push(Setting {
                    key: self.key.clone(),
                    value: Value::Float(value),
                });
                Case::parse_with(text, file, stem, &settings).map_err(|e| CurveError::Key {
                    key: self.key.clone(),
                    cause: Box::new(e),
                })
            }
            Source::Design { case, key } => case
                .with_design(*key, value)
                .map_err(|cause| CurveError::Refused { value, cause }),
        }
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

/// How far a critical curve has got, as it goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CurveProgress {
    /// The case's own path, which locates the critical point to continue, has reached
    /// load parameter `parameter`.
    Locating { parameter: f64 },
    /// Row `done` of `total` is found.
    Row {
        row: CurveRow,
        done: usize,
        total: usize,
    },
}

/// What the caller of a long curve sees and can do: `interrupt` stops it at its last
/// converged point (the rows found so far are kept), and `progress` hears of each step.
pub struct Watch<'a> {
    pub interrupt: Interrupt,
    pub progress: &'a mut dyn FnMut(CurveProgress),
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
    let mut quiet = |_: CurveProgress| {};
    let mut watch = Watch {
        interrupt: Interrupt::new(),
        progress: &mut quiet,
    };
    follow(family, spec, &mut watch)
}

/// The critical curve of the accepted case `case` (the explorer's scene, which has no file)
/// in its design key `key` from `from` to `to` in `rows` rows, watched by `watch`.
pub fn design_curve(
    case: &Case,
    key: DesignKey,
    from: f64,
    to: f64,
    rows: usize,
    watch: &mut Watch,
) -> Result<CriticalCurve, CurveError> {
    let spec = CurveSpec {
        key: key.key().to_string(),
        from,
        to,
        rows: rows.max(2),
        at: Vec::new(),
    };
    if !from.is_finite() || !to.is_finite() || from == to {
        return Err(CurveError::Range { from, to });
    }
    follow(CaseFamily::design(case, key, &spec), &spec, watch)
}

/// One stretch of a curve: the extended system continued from a critical point located by
/// the case's path at one value of the key, over which the layout of the state holds.
struct Stretch {
    path: Continuation<CriticalSystem<CaseFamily>>,
    critical: CriticalPoint,
    multiplicity: usize,
}

impl Stretch {
    /// The first critical point of the case's path at `value`, bordered and ready to be
    /// continued.
    fn locate(
        family: &CaseFamily,
        value: f64,
        spec: &CurveSpec,
        watch: &mut Watch,
    ) -> Result<(Stretch, Case), CurveError> {
        let case = family.case(value)?;
        let critical = first_critical(&case, spec, value, watch)?;
        let extended_error = |reason: String| CurveError::Extended {
            key: spec.key.clone(),
            value,
            reason,
        };
        let start = CriticalStart {
            x: critical.state.clone(),
            lambda: critical.parameter,
            mu: value,
            modes: start_modes(&critical),
            bifurcation: critical.kind == CriticalKind::Bifurcation,
        };
        let mut check = assembly(&case);
        check_holds(&mut check, &start).map_err(extended_error)?;
        let mut system = CriticalSystem::new(family.clone(), &start).map_err(extended_error)?;
        system.set_stop(Some(watch.interrupt.clone()));
        let xe = system.extend(&start.x, start.lambda);
        let settings = curve_settings(&case.solver, spec);
        let mut path = Continuation::new(system, xe, value, settings)
            .map_err(|e| extended_error(e.to_string()))?;
        path.set_interrupt(Some(watch.interrupt.clone()));
        let multiplicity = path.problem().borders();
        let stretch = Stretch {
            path,
            critical,
            multiplicity,
        };
        Ok((stretch, case))
    }

    /// The row of the stretch's current point.
    fn row(&mut self) -> Option<CurveRow> {
        let (x, lambda) = self.path.problem().split(&self.path.state().x);
        let mu = self.path.state().lambda;
        let member = self.path.problem_mut().member_at(mu)?;
        Some(row(
            member,
            &x,
            lambda,
            mu,
            &self.critical,
            self.multiplicity,
        ))
    }
}

/// The curve of `family` from its first critical point at `spec.from`. Where the layout of
/// the state changes on the way (a vertex or a crossing enters the mesh as a length or a
/// number of turns grows), the extended system of one layout cannot be continued into the
/// next: the point is located afresh by the case's path at the next row's value, and the
/// curve goes on from there.
fn follow(
    family: CaseFamily,
    spec: &CurveSpec,
    watch: &mut Watch,
) -> Result<CriticalCurve, CurveError> {
    let (mut stretch, case) = Stretch::locate(&family, spec.from, spec, watch)?;
    let mut rows = Vec::new();
    let mut stopped = None;
    let mut relocated = 0;
    let values = spec.values();
    for (k, &value) in values.iter().enumerate() {
        if let Err(e) = stretch.path.advance_to(value) {
            let problem = stretch.path.problem();
            if problem.layout_changed() {
                // the system raised the stop at the refusal: lowered, the next stretch goes on
                watch.interrupt.clear();
                match Stretch::locate(&family, value, spec, watch) {
                    Ok((next, _)) => {
                        stretch = next;
                        relocated += 1;
                    }
                    Err(why) => {
                        stopped = Some(why);
                        break;
                    }
                }
            } else {
                let reason = problem
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
        }
        if let Some(row) = stretch.row() {
            rows.push(row);
            (watch.progress)(CurveProgress::Row {
                row,
                done: k + 1,
                total: values.len(),
            });
        }
    }
    Ok(CriticalCurve {
        rows,
        parameter_label: case.load_parameter().label().to_string(),
        stopped,
        relocated,
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
    let forward = (spec.to - spec.from).signum();
    let in_order = |w: &[f64]| (w[1] - w[0]) * forward > 0.0;
    if spec.at.len() == 1 || !spec.at.windows(2).all(in_order) {
        return Err(CurveError::Order {
            key: spec.key.clone(),
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
fn first_critical(
    case: &Case,
    spec: &CurveSpec,
    value: f64,
    watch: &mut Watch,
) -> Result<CriticalPoint, CurveError> {
    let start_error = |cause| CurveError::Start {
        key: spec.key.clone(),
        value,
        cause,
    };
    let mut sim = Simulation::from_case_on(case, 1).map_err(start_error)?;
    sim.set_interrupt(Some(watch.interrupt.clone()));
    let mut reason = None;
    for target in case.output_parameters(case.loading.target, case.loading.steps) {
        let outcome = sim.advance_to(target);
        (watch.progress)(CurveProgress::Locating { parameter: target });
        let found = sim
            .critical_points()
            .iter()
            .find(|c| c.kind != CriticalKind::Neutral);
        if let Some(c) = found {
            if let Some(p) = c.wavenumber.filter(|&p| p != 0) {
                return Err(CurveError::BlochBlock {
                    key: spec.key.clone(),
                    value,
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
        value,
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

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn values_reached_by_continuation_read_to_ten_digits() {
        assert_eq!(short(1.8800000000000001), "1.88");
        assert_eq!(short(6.025), "6.025");
        assert_eq!(short(-0.1 - 0.2), "-0.3");
        assert_eq!(short(2.5e-7), "2.5e-7");
    }
}
