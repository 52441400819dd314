//! The explorer's state and its transitions: key presses and solver answers in, solver
//! requests and other effects out. No terminal and no solver here, so every transition can
//! be tested headless.

use super::keys::{self, Action};
use super::stability;
use crate::case::Case;
use crate::model::boundary::{BoundaryConditions, Rotation, Translation};
use crate::results::CriticalPoint;
use crate::results::{LoadPoint, Snapshot};
use crate::session::export::{self, SessionEvent};
use crate::session::script::Script;
use crate::session::worker::{Job, Part, Request, Solved, WorkerEvent};
use crate::solver::interrupt::Interruption;
use crate::study::{MeshChoice, Study};
use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The numbers of helices `n`/`N` step through (no wrap-around: they stop at the ends).
pub const HELICES: [usize; 5] = [1, 2, 4, 8, 16];
/// The user steps in `ε` that `+`/`-` choose from.
pub const STEPS: [f64; 5] = [0.005, 0.01, 0.02, 0.05, 0.1];
/// Largest and smallest user step in `ε`.
pub const MAX_STEP: f64 = STEPS[STEPS.len() - 1];
pub const MIN_STEP: f64 = STEPS[0];
/// A change of `n` that would discard a path of more converged points than this asks
/// first (the same key again confirms).
pub const CONFIRM_DISCARD: usize = 4;
/// The message while a cancel is on its way to the solver.
const CANCELLING: &str = "cancelling…";
/// Positions of the curvature plot's cursor along `s/L`: `0, 1/CURSOR_STEPS, …, 1`.
pub const CURSOR_STEPS: usize = 32;

/// How the left upper area is used: all three views, or one of them alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ViewMode {
    #[default]
    All,
    XY,
    ZY,
    ZX,
}

impl ViewMode {
    fn next(self) -> ViewMode {
        match self {
            ViewMode::All => ViewMode::XY,
            ViewMode::XY => ViewMode::ZY,
            ViewMode::ZY => ViewMode::ZX,
            ViewMode::ZX => ViewMode::All,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ViewMode::All => "all views",
            ViewMode::XY => "X-Y view",
            ViewMode::ZY => "Z-Y view",
            ViewMode::ZX => "Z-X view",
        }
    }
}

/// How far the solve in progress has got.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Load parameter of the last accepted internal step (`ε` under displacement control).
    pub parameter: f64,
    /// Internal steps accepted so far.
    pub steps: usize,
    /// Time since the job started.
    pub elapsed: Duration,
}

/// What a transition asks the outside world to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    /// Send this request to the solver thread.
    Solve(Request),
    /// Cancel every request up to this sequence number (the running solve stops at its
    /// last converged state).
    Cancel(u64),
    /// Save the session as a replayable script ([`App::save_session`]).
    SaveSession,
    /// Write the current state and load path to CSV ([`App::export`]).
    Export,
    /// Leave the explorer.
    Quit,
}

/// The explorer's work-precision study of the current case (issue 5).
#[derive(Clone, Debug, PartialEq)]
pub enum PrecisionView {
    /// None asked for since the case or its conditions last changed.
    None,
    /// Running: `done` of `total` meshes solved (`total` is 0 until the first is).
    Running {
        done: usize,
        total: usize,
    },
    Ready(Box<Study>),
    Failed(String),
}

/// A line for the user under the status line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Message {
    Info(String),
    Error(String),
}

/// What a new simulation replaces on screen, kept until its natural state arrives.
#[derive(Debug)]
struct Previous {
    generation: u64,
    helices: usize,
    boundary: BoundaryConditions,
    step: f64,
    requested_eps: f64,
    path: Vec<LoadPoint>,
    conditions: Vec<BoundaryConditions>,
    critical: Vec<CriticalPoint>,
    state: Option<Solved>,
    natural_k1: Option<f64>,
    mesh: Option<MeshChoice>,
    events: Vec<SessionEvent>,
    ran: usize,
}

/// The explorer's state.
#[derive(Debug)]
pub struct App {
    /// The case as loaded (its `n` and conditions are what `r` returns to).
    case: Case,
    /// Number of helices of the current simulation.
    pub helices: usize,
    /// Boundary conditions asked for (those in force are in [`App::state`]).
    pub boundary: BoundaryConditions,
    /// User step in `ε` (> 0).
    pub step: f64,
    /// `ε` the solver was last asked to reach (the current `ε` when idle).
    pub requested_eps: f64,
    /// Continuous loading towards the case's target is on.
    pub running: bool,
    pub selected_rod: usize,
    pub show_help: bool,
    /// Converged points in the order they were reached (step numbers 0, 1, ...).
    pub path: Vec<LoadPoint>,
    /// The last converged state, if any.
    pub state: Option<Solved>,
    pub message: Option<Message>,
    /// What the solver is doing now, if anything.
    pub solving: Option<String>,
    /// Mean κ1 (1/m) of the first state of this simulation (the natural state), the centre
    /// of the colour scale.
    pub natural_k1: Option<f64>,
    /// Where exports go.
    pub out_dir: PathBuf,
    /// The mesh chosen for the case's accuracy target, when it gives one.
    pub mesh: Option<MeshChoice>,
    /// The work-precision chart replaces the curvature and load plots.
    pub show_precision: bool,
    pub precision: PrecisionView,
    /// Sequence number of the last study asked for (answers to older ones are dropped).
    precision_seq: u64,
    generation: u64,
    next_seq: u64,
    /// Sequence number of the last request sent, and of the last one answered.
    last_sent: u64,
    last_done: u64,
    solver_lost: bool,
    /// The solve in progress: how far it got (from the solver's progress reports).
    pub progress: Option<Progress>,
    /// Time since the job in progress started (updated by [`App::tick`]).
    pub elapsed: Option<Duration>,
    started_at: Option<Instant>,
    /// A key that must be pressed again to confirm (a change of `n` discarding a path).
    pub confirm: Option<Action>,
    /// The key in hand is the confirmation [`App::confirm`] asked for.
    confirmed: bool,
    /// Critical points crossed on this simulation's path, in order (without state and mode).
    pub critical: Vec<CriticalPoint>,
    pub show_critical: bool,
    /// Cursor of the curvature plot, in steps of `1/CURSOR_STEPS` along `s/L`.
    pub cursor: usize,
    /// Cursor on the load path: an index into [`App::path`] (`None`: the current point).
    pub path_cursor: Option<usize>,
    pub view: ViewMode,
    /// What changed in this session, in order (conditions, `n`, step, control).
    pub events: Vec<SessionEvent>,
    /// The conditions of each point of [`App::path`].
    pub conditions: Vec<BoundaryConditions>,
    /// The jobs the solver ran for this session, in order, for a replay (by sequence).
    pub(crate) sent: Vec<(u64, Job)>,
    pub ran: Vec<Job>,
    /// The sequence number of each job of [`App::ran`].
    ran_seq: Vec<u64>,
    /// The simulation on screen before a new one was asked for, until the new one's
    /// natural state arrives: a cancelled natural state brings it back.
    previous: Option<Box<Previous>>,
    /// Sequence number of the new simulation's request while its natural state solves.
    start_seq: Option<u64>,
    /// Selected row of the critical-point list (`x`).
    pub critical_cursor: usize,
    /// Sequence number of the last branch switch asked for.
    switch_seq: Option<u64>,
    /// Where the case came from (`None`: the built-in case), for a saved session.
    pub case_file: Option<PathBuf>,
    /// The terminal is smaller than the screen needs: keys other than quit do nothing.
    pub too_small: bool,
    /// `NO_COLOR` is set: curves are told apart by their marks, not their colours.
    pub no_color: bool,
}

impl App {
    /// A new explorer on `case`, exporting into `out_dir`. Call [`App::start`] for the
    /// first solver request.
    pub fn new(case: Case, out_dir: PathBuf) -> App {
        let helices = case.geometry.helices;
        let boundary = case.boundary;
        let step = default_step(&case);
        App {
            case,
            helices,
            boundary,
            step,
            requested_eps: 0.0,
            running: false,
            selected_rod: 0,
            show_help: false,
            path: Vec::new(),
            state: None,
            message: None,
            solving: None,
            natural_k1: None,
            out_dir,
            mesh: None,
            show_precision: false,
            precision: PrecisionView::None,
            precision_seq: 0,
            generation: 0,
            next_seq: 0,
            last_sent: 0,
            last_done: 0,
            solver_lost: false,
            progress: None,
            elapsed: None,
            started_at: None,
            confirm: None,
            confirmed: false,
            critical: Vec::new(),
            show_critical: false,
            cursor: CURSOR_STEPS / 2,
            path_cursor: None,
            view: ViewMode::All,
            events: Vec::new(),
            conditions: Vec::new(),
            sent: Vec::new(),
            ran: Vec::new(),
            ran_seq: Vec::new(),
            previous: None,
            start_seq: None,
            critical_cursor: 0,
            switch_seq: None,
            case_file: None,
            too_small: false,
            no_color: false,
        }
    }

    /// Updates the elapsed time of the solve in progress (the event loop calls it).
    pub fn tick(&mut self, now: Instant) {
        self.elapsed = self.started_at.map(|t| now.saturating_duration_since(t));
    }

    fn record(&mut self, what: String) {
        self.events.push(SessionEvent {
            from_point: self.path.len(),
            eps: self.requested_eps,
            what,
        });
    }

    /// The case as loaded.
    pub fn case(&self) -> &Case {
        &self.case
    }

    /// Whether the explorer solves one symmetric pair for the current `n` (its Bloch blocks
    /// judging the whole assembly's stability), rather than the full assembly.
    pub fn solves_pair(&self) -> bool {
        // the model of the state on screen (a switch moves a pair's path onto the whole
        // assembly), else the one the case asks for
        if let Some(s) = &self.state {
            return s.pair;
        }
        self.case
            .with_helices(self.helices)
            .for_explorer()
            .discretisation
            .symmetric
    }

    /// The case's name, with the number of helices when it was changed from the case's.
    pub fn case_label(&self) -> String {
        if self.helices == self.case.geometry.helices {
            self.case.name.clone()
        } else {
            format!("{}-n{}", self.case.name, self.helices)
        }
    }

    /// Target of continuous loading (the case's `loading.target`).
    pub fn target(&self) -> f64 {
        self.case.loading.target
    }

    /// True while a request is unanswered.
    pub fn busy(&self) -> bool {
        self.last_done < self.last_sent
    }

    /// Number of rods of the state on screen.
    pub fn rods(&self) -> usize {
        self.state
            .as_ref()
            .map_or(self.helices, |s| s.snapshot.rods.len())
    }

    /// Current compression ratio (of the state on screen).
    pub fn eps(&self) -> Option<f64> {
        self.state.as_ref().map(|s| s.point.eps)
    }

    /// Stability of the state on screen.
    pub fn stability(&self) -> Option<bool> {
        self.state
            .as_ref()
            .and_then(|s| stability::is_unstable(&s.point))
    }

    fn request(&mut self, job: Job) -> Effect {
        if matches!(self.message, Some(Message::Error(_))) {
            self.message = None;
        }
        self.next_seq += 1;
        self.last_sent = self.next_seq;
        self.sent.push((self.next_seq, job.clone()));
        Effect::Solve(Request {
            generation: self.generation,
            seq: self.next_seq,
            job,
        })
    }

    /// A work-precision study of the case as it stands (its `n` and the conditions asked
    /// for), on the solver's precision thread; it does not make the app busy.
    fn request_precision(&mut self) -> Effect {
        self.next_seq += 1;
        self.precision_seq = self.next_seq;
        self.precision = PrecisionView::Running { done: 0, total: 0 };
        let mut case = self.case.with_helices(self.helices);
        case.boundary = self.boundary;
        Effect::Solve(Request {
            generation: self.generation,
            seq: self.next_seq,
            job: Job::Precision(Box::new(case)),
        })
    }

    /// The case or its conditions changed: the study on screen is of another problem. A new
    /// one is asked for when the chart is shown.
    fn precision_obsolete(&mut self) -> Vec<Effect> {
        self.precision = PrecisionView::None;
        if self.show_precision {
            vec![self.request_precision()]
        } else {
            vec![]
        }
    }

    /// The first request: solve the case's natural state.
    pub fn start(&mut self) -> Vec<Effect> {
        self.restart()
    }

    /// What is on screen now, for [`App::restart`] to bring back if the new simulation's
    /// natural state is cancelled (taken before the change of `n` or the reset).
    fn keep(&self) -> Box<Previous> {
        Box::new(Previous {
            generation: self.generation,
            helices: self.helices,
            boundary: self.boundary,
            step: self.step,
            requested_eps: self.requested_eps,
            path: self.path.clone(),
            conditions: self.conditions.clone(),
            critical: self.critical.clone(),
            state: self.state.clone(),
            natural_k1: self.natural_k1,
            mesh: self.mesh.clone(),
            events: self.events.clone(),
            ran: self.ran.len(),
        })
    }

    /// The simulation the cancelled natural state was to replace, back on screen.
    fn bring_back(&mut self, p: Box<Previous>) {
        self.generation = p.generation;
        self.helices = p.helices;
        self.boundary = p.boundary;
        self.step = p.step;
        self.requested_eps = p.requested_eps;
        self.path = p.path;
        self.conditions = p.conditions;
        self.critical = p.critical;
        self.state = p.state;
        self.natural_k1 = p.natural_k1;
        self.mesh = p.mesh;
        self.events = p.events;
        self.ran.truncate(p.ran);
        self.ran_seq.truncate(p.ran);
        self.selected_rod = self.selected_rod.min(self.rods().saturating_sub(1));
        self.critical_cursor = 0;
    }

    /// A new simulation with the current `n` and conditions, from `ε = 0`; `previous` is
    /// what was on screen (brought back if its natural state is cancelled).
    fn restart_from(&mut self, previous: Box<Previous>) -> Vec<Effect> {
        // a new simulation asked for while another's natural state solves replaces that
        // one: the simulation to come back to is still the one before
        if self.previous.is_none() && previous.state.is_some() {
            self.previous = Some(previous);
        }
        self.restart()
    }

    /// A new simulation with the current `n` and conditions, from `ε = 0`.
    fn restart(&mut self) -> Vec<Effect> {
        // a solve of the old simulation in progress is of no more use: stop it
        let cancel = self.busy().then_some(Effect::Cancel(self.last_sent));
        self.generation += 1;
        self.path.clear();
        self.conditions.clear();
        self.critical.clear();
        self.path_cursor = None;
        self.progress = None;
        self.state = None;
        self.natural_k1 = None;
        self.running = false;
        self.requested_eps = 0.0;
        self.solving = None;
        self.selected_rod = self.selected_rod.min(self.helices.saturating_sub(1));
        let mut case = self.case.with_helices(self.helices);
        case.boundary = self.boundary;
        self.mesh = None;
        self.critical_cursor = 0;
        // a large problem says so before it is solved, as `spira run` does
        let estimate = case.for_explorer().size_estimate();
        if estimate.is_large() {
            let said = match &self.message {
                Some(Message::Info(m)) => format!("{m}; "),
                _ => String::new(),
            };
            self.message = Some(Message::Info(format!(
                "{said}size estimate: {estimate}; c cancels"
            )));
        }
        let mut effects: Vec<Effect> = cancel.into_iter().collect();
        let start = self.request(Job::Start(Box::new(case)));
        if let Effect::Solve(r) = &start {
            self.start_seq = Some(r.seq);
        }
        effects.push(start);
        effects.extend(self.precision_obsolete());
        effects
    }

    /// Asks for `ε = eps` if the geometry admits it.
    fn advance(&mut self, eps: f64) -> Vec<Effect> {
        // round to 1e-12 so repeated steps land on the decimal values a user expects
        let eps = (eps * 1e12).round() / 1e12;
        if let Err(why) = self.case.check_target(eps) {
            self.running = false;
            self.message = Some(Message::Error(format!("ε = {eps:.5}: {why}")));
            return vec![];
        }
        self.requested_eps = eps;
        vec![self.request(Job::Advance(eps))]
    }

    /// Cancels the solve in progress (and what is queued behind it); the last converged
    /// state stays.
    fn cancel(&mut self) -> Vec<Effect> {
        self.running = false;
        if !self.busy() {
            self.message = Some(Message::Info(
                "nothing to cancel: the solver is idle".into(),
            ));
            return vec![];
        }
        self.message = Some(Message::Info(CANCELLING.into()));
        vec![Effect::Cancel(self.last_sent)]
    }

    /// Next request of continuous loading, if the target is not reached.
    fn run_on(&mut self) -> Vec<Effect> {
        let target = self.target();
        let gap = target - self.requested_eps;
        if gap.abs() < 1e-12 {
            self.running = false;
            self.message = Some(Message::Info(format!(
                "reached the target ε = {target}; r starts over"
            )));
            return vec![];
        }
        let next = self.requested_eps + gap.signum() * self.step.min(gap.abs());
        self.advance(next)
    }

    fn set_boundary(&mut self, bc: BoundaryConditions, what: String) -> Vec<Effect> {
        // the case reader's check: supports that leave a rigid motion free are refused
        if let Some(motion) = self.case.with_helices(self.helices).free_motion(&bc) {
            self.message = Some(Message::Error(format!(
                "{what} refused and undone: {}; the conditions stay {}",
                motion.message,
                self.boundary.label()
            )));
            return vec![];
        }
        self.boundary = bc;
        self.record(what.clone());
        self.message = Some(Message::Info(format!(
            "{what}; the path continues from ε = {:.5} under the new conditions",
            self.requested_eps
        )));
        let mut effects = vec![self.request(Job::SetBoundary(bc))];
        effects.extend(self.precision_obsolete());
        effects
    }

    /// Transition on a key press: Ctrl-C quits, a key closes the help (q still quits),
    /// else the key's [`Action`] from the key table ([`keys::BINDINGS`]).
    pub fn handle_key(&mut self, key: KeyEvent) -> Vec<Effect> {
        if key.kind == KeyEventKind::Release {
            return vec![];
        }
        let ctrl = key.modifiers.contains(KeyModifiers::CONTROL);
        if ctrl && matches!(key.code, KeyCode::Char('c') | KeyCode::Char('C')) {
            return vec![Effect::Quit];
        }
        if self.too_small {
            return match keys::action_for(key.code) {
                Some(Action::Quit) => vec![Effect::Quit],
                _ => vec![],
            };
        }
        if self.show_help {
            self.show_help = false;
            return match key.code {
                KeyCode::Char('q') => vec![Effect::Quit],
                _ => vec![],
            };
        }
        let action = keys::action_for(key.code);
        let confirm = self.confirm.take();
        if confirm.is_some() && action != confirm {
            self.message = Some(Message::Info("kept the path: n unchanged".into()));
            return vec![];
        }
        self.confirmed = confirm.is_some();
        if self.solver_lost && !action.is_some_and(Action::works_without_solver) {
            self.message = Some(Message::Error(
                "the solver thread has stopped; export with e or quit with q".into(),
            ));
            return vec![];
        }
        action.map_or_else(Vec::new, |a| self.perform(a))
    }

    /// Transition on a user action.
    pub fn perform(&mut self, action: Action) -> Vec<Effect> {
        match action {
            Action::Quit => vec![Effect::Quit],
            Action::Help => {
                self.show_help = true;
                vec![]
            }
            Action::StepForward => self.step_by(1.0),
            Action::StepBack => self.step_by(-1.0),
            Action::DoubleStep => self.scale_step(2.0),
            Action::HalveStep => self.scale_step(0.5),
            // in the critical-point list the rod keys choose a critical point
            Action::PreviousRod if self.show_critical => self.move_critical_cursor(-1),
            Action::NextRod if self.show_critical => self.move_critical_cursor(1),
            Action::PreviousRod => self.select_rod_by(-1),
            Action::NextRod => self.select_rod_by(1),
            Action::SwitchBranch => self.switch_branch(1.0),
            Action::SwitchBranchOther => self.switch_branch(-1.0),
            Action::RunPause => self.run_or_pause(),
            Action::BaseTranslation => self.cycle_base_translation(),
            Action::BaseRotation => self.cycle_base_rotation(),
            Action::TipTranslation => self.cycle_tip_translation(),
            Action::TipRotation => self.cycle_tip_rotation(),
            Action::PinJoints => self.toggle_joints(),
            Action::MoreHelices => self.change_helices(true, action),
            Action::FewerHelices => self.change_helices(false, action),
            Action::Cancel => self.cancel(),
            Action::CriticalPoints => {
                self.show_critical = !self.show_critical;
                if self.show_critical && self.critical.is_empty() {
                    self.message = Some(Message::Info(
                        "no critical point crossed on this path yet".into(),
                    ));
                }
                vec![]
            }
            Action::CursorBack => {
                self.cursor = self.cursor.saturating_sub(1);
                vec![]
            }
            Action::CursorForward => {
                self.cursor = (self.cursor + 1).min(CURSOR_STEPS);
                vec![]
            }
            Action::PathCursorBack => self.move_path_cursor(-1),
            Action::PathCursorForward => self.move_path_cursor(1),
            Action::SingleView => {
                self.view = self.view.next();
                self.message = Some(Message::Info(format!("{} (v cycles)", self.view.name())));
                vec![]
            }
            Action::SaveSession => vec![Effect::SaveSession],
            Action::Reset => self.reset(),
            Action::Export => vec![Effect::Export],
            Action::Precision => self.toggle_precision(),
        }
    }

    fn move_critical_cursor(&mut self, by: isize) -> Vec<Effect> {
        let n = self.critical.len();
        if n > 0 {
            self.critical_cursor =
                (self.critical_cursor as isize + by).clamp(0, n as isize - 1) as usize;
        }
        vec![]
    }

    /// Switches onto the branch of the bifurcation selected in the critical-point list, on
    /// the side `sign`, and follows it to the `ε` of the state on screen (as `spira run`
    /// with `branch = "switch"` does at its first bifurcation); stops continuous loading.
    fn switch_branch(&mut self, sign: f64) -> Vec<Effect> {
        use crate::results::CriticalKind;
        if !self.show_critical {
            self.message = Some(Message::Info(
                "x lists the critical points; choose one with ↑↓ and switch onto its branch there"
                    .into(),
            ));
            return vec![];
        }
        let Some(c) = self.critical.get(self.critical_cursor) else {
            self.message = Some(Message::Info(
                "no critical point crossed on this path yet".into(),
            ));
            return vec![];
        };
        if c.kind != CriticalKind::Bifurcation {
            self.message = Some(Message::Error(format!(
                "critical point {} is a {}, not a bifurcation: there is no other branch to switch onto",
                self.critical_cursor,
                c.kind.name()
            )));
            return vec![];
        }
        let (index, at) = (self.critical_cursor, c.eps);
        let eps = self.requested_eps;
        self.running = false;
        self.show_critical = false;
        self.record(format!(
            "switch onto the branch of critical point {index} (ε = {at:.5}, side {sign:+})"
        ));
        self.message = Some(Message::Info(format!(
            "switching onto the branch of critical point {index} at ε = {at:.5} (side {sign:+}), then along it to ε = {eps:.5}"
        )));
        let effect = self.request(Job::Switch {
            index,
            sign,
            eps,
            part: None,
        });
        if let Effect::Solve(r) = &effect {
            self.switch_seq = Some(r.seq);
        }
        let mut effects = vec![effect];
        effects.extend(self.precision_obsolete());
        effects
    }

    /// One user step forward (`sign` 1) or back (−1); stops continuous loading.
    fn step_by(&mut self, sign: f64) -> Vec<Effect> {
        self.running = false;
        let (from, target) = (self.requested_eps, self.target());
        let mut next = from + sign * self.step;
        // a step forward towards the target stops there; one beyond it is refused
        if target > 0.0 && sign > 0.0 {
            if from >= target - 1e-12 {
                self.message = Some(Message::Info(format!(
                    "at the target ε = {target}; ← steps back, r starts over"
                )));
                return vec![];
            }
            next = next.min(target);
        }
        self.advance(next)
    }

    /// Moves the load-path cursor by `by` points (from the current point when it is off).
    fn move_path_cursor(&mut self, by: isize) -> Vec<Effect> {
        if self.path.is_empty() {
            return vec![];
        }
        let last = self.path.len() - 1;
        let at = self.path_cursor.unwrap_or(last) as isize + by;
        let at = at.clamp(0, last as isize) as usize;
        self.path_cursor = (at != last || by < 0).then_some(at);
        vec![]
    }

    /// The user step times `factor`, within [`MIN_STEP`] and [`MAX_STEP`].
    fn scale_step(&mut self, factor: f64) -> Vec<Effect> {
        let next = if factor > 1.0 {
            STEPS.iter().copied().find(|&s| s > self.step + 1e-12)
        } else {
            STEPS.iter().rev().copied().find(|&s| s < self.step - 1e-12)
        };
        let Some(step) = next else {
            self.message = Some(Message::Info(format!(
                "Δε = {} is the {} step ({})",
                fmt_step(self.step),
                if factor > 1.0 { "largest" } else { "smallest" },
                STEPS.map(fmt_step).join(" ")
            )));
            return vec![];
        };
        self.step = step;
        self.message = Some(Message::Info(format!("step Δε = {}", fmt_step(self.step))));
        self.record(format!("step Δε = {}", fmt_step(self.step)));
        vec![]
    }

    /// Selects the rod `offset` places on, round the assembly.
    fn select_rod_by(&mut self, offset: isize) -> Vec<Effect> {
        let n = self.rods().max(1);
        let offset = offset.rem_euclid(n as isize) as usize;
        self.selected_rod = (self.selected_rod + offset) % n;
        vec![]
    }

    /// Starts continuous loading towards the target, or pauses it.
    fn run_or_pause(&mut self) -> Vec<Effect> {
        if self.running {
            self.running = false;
            self.message = Some(Message::Info("paused".into()));
            return vec![];
        }
        self.running = true;
        self.message = Some(Message::Info(format!(
            "loading to ε = {} in steps of {}",
            self.target(),
            fmt_step(self.step)
        )));
        if self.busy() {
            // the answer to the request in flight sends the next one
            vec![]
        } else {
            self.run_on()
        }
    }

    fn cycle_base_translation(&mut self) -> Vec<Effect> {
        let mut bc = self.boundary;
        bc.base.translation = next_translation(bc.base.translation);
        let what = format!("base translation {}", translation_name(bc.base.translation));
        self.set_boundary(bc, what)
    }

    fn cycle_base_rotation(&mut self) -> Vec<Effect> {
        let mut bc = self.boundary;
        bc.base.rotation = other_rotation(bc.base.rotation);
        let what = format!("base rotation {}", rotation_name(bc.base.rotation));
        self.set_boundary(bc, what)
    }

    fn cycle_tip_translation(&mut self) -> Vec<Effect> {
        let mut bc = self.boundary;
        bc.tip.translation = next_translation(bc.tip.translation);
        let what = format!("tip translation {}", translation_name(bc.tip.translation));
        self.set_boundary(bc, what)
    }

    fn cycle_tip_rotation(&mut self) -> Vec<Effect> {
        let mut bc = self.boundary;
        bc.tip.rotation = other_rotation(bc.tip.rotation);
        let what = format!("tip rotation {}", rotation_name(bc.tip.rotation));
        self.set_boundary(bc, what)
    }

    fn toggle_joints(&mut self) -> Vec<Effect> {
        let mut bc = self.boundary;
        bc.joints = !bc.joints;
        let what = format!("pin joints {}", if bc.joints { "on" } else { "off" });
        self.set_boundary(bc, what)
    }

    /// The next larger (`up`) or smaller number of helices of [`HELICES`], from `ε = 0`.
    fn change_helices(&mut self, up: bool, key: Action) -> Vec<Effect> {
        let Some(n) = next_helices(self.helices, up) else {
            self.message = Some(Message::Info(format!(
                "n = {} is the {} ({})",
                self.helices,
                if up { "largest" } else { "smallest" },
                HELICES.map(|n| n.to_string()).join(" ")
            )));
            return vec![];
        };
        if self.path.len() > CONFIRM_DISCARD && !std::mem::take(&mut self.confirmed) {
            self.confirm = Some(key);
            self.message = Some(Message::Info(format!(
                "n = {n} starts over and discards the path of {} points: press {} again to confirm, any other key keeps it",
                self.path.len(),
                if up { "n" } else { "N" }
            )));
            return vec![];
        }
        self.confirm = None;
        let previous = self.keep();
        self.helices = n;
        self.message = Some(Message::Info(format!(
            "n = {}: starting over from ε = 0",
            self.helices
        )));
        self.record(format!("n = {n}, start over"));
        self.restart_from(previous)
    }

    /// Back to `ε = 0` under the case's conditions and step.
    fn reset(&mut self) -> Vec<Effect> {
        let previous = self.keep();
        self.boundary = self.case.boundary;
        self.step = default_step(&self.case);
        self.message = Some(Message::Info(
            "reset: ε = 0 under the case's boundary conditions".into(),
        ));
        self.record("reset".into());
        self.restart_from(previous)
    }

    /// Shows or hides the work-precision chart; the first time, asks for the study.
    fn toggle_precision(&mut self) -> Vec<Effect> {
        self.show_precision = !self.show_precision;
        if self.show_precision && self.precision == PrecisionView::None {
            self.message = Some(Message::Info(
                "work-precision study of the path to the target started on its own thread; the explorer stays live".into(),
            ));
            vec![self.request_precision()]
        } else {
            vec![]
        }
    }

    /// Transition on an answer from the solver thread.
    pub fn on_worker_event(&mut self, event: WorkerEvent) -> Vec<Effect> {
        if event.generation() != self.generation {
            return vec![];
        }
        match event {
            WorkerEvent::Started { seq, job, .. } => {
                if seq > self.last_done {
                    self.solving = Some(job);
                    self.progress = None;
                    self.started_at = Some(Instant::now());
                    self.elapsed = Some(Duration::ZERO);
                }
                if let Some(j) = self
                    .sent
                    .iter()
                    .find(|(s, _)| *s == seq)
                    .map(|(_, j)| j.clone())
                {
                    self.ran.push(j);
                    self.ran_seq.push(seq);
                }
                vec![]
            }
            WorkerEvent::Stopped {
                seq,
                steps,
                step_length,
                ..
            } => {
                // the session records the part of the way the job got, for its replay
                if let Some(k) = self.ran_seq.iter().rposition(|&s| s == seq) {
                    match steps {
                        None => {
                            self.ran.remove(k);
                            self.ran_seq.remove(k);
                        }
                        Some(steps) => {
                            let part = Part { steps, step_length };
                            self.ran[k] = match self.ran[k].clone() {
                                Job::Advance(eps) | Job::AdvancePart { eps, .. } => {
                                    Job::AdvancePart { eps, part }
                                }
                                Job::Switch {
                                    index, sign, eps, ..
                                } => Job::Switch {
                                    index,
                                    sign,
                                    eps,
                                    part: Some(part),
                                },
                                other => other,
                            };
                        }
                    }
                }
                vec![]
            }
            WorkerEvent::Progress {
                seq,
                parameter,
                steps,
                elapsed,
                ..
            } => {
                if seq > self.last_done {
                    self.progress = Some(Progress {
                        parameter,
                        steps,
                        elapsed,
                    });
                    self.elapsed = Some(elapsed);
                }
                vec![]
            }
            WorkerEvent::Solved {
                seq, done, state, ..
            } => {
                if self.start_seq == Some(seq) {
                    self.start_seq = None;
                    self.previous = None;
                }
                if self.switch_seq == Some(seq) && seq >= self.last_sent {
                    // the steps that follow go on from where the branch was reached
                    self.requested_eps = state.point.parameter;
                    if done {
                        self.message = Some(Message::Info(format!(
                            "on the bifurcated branch at ε = {:.5}: fz/(n Pcrit) = {:.4}, {}; steps go on along it",
                            state.point.eps,
                            state.point.load[2],
                            state.point.stability.map_or("stability not computed".to_string(), |s| format!(
                                "unstable directions {}",
                                s.unstable_directions
                            ))
                        )));
                    }
                }
                self.path.push(state.point.clone());
                self.conditions.push(state.boundary);
                for c in &state.critical {
                    self.message = Some(Message::Info(format!(
                        "critical point: {} at ε = {:.5}, fz/(n Pcrit) = {:.4}, unstable directions {} → {} (x lists them)",
                        c.kind.name(),
                        c.eps,
                        c.load[2],
                        c.unstable_before,
                        c.unstable_after
                    )));
                }
                self.critical.extend(state.critical.iter().cloned());
                if self.natural_k1.is_none() {
                    self.natural_k1 = mean_k1(&state.snapshot);
                }
                self.boundary_settled(state.boundary, seq);
                self.selected_rod = self
                    .selected_rod
                    .min(state.snapshot.rods.len().saturating_sub(1));
                self.state = Some(*state);
                if done {
                    self.finish(seq)
                } else {
                    vec![]
                }
            }
            WorkerEvent::Unchanged { seq, .. } => self.finish(seq),
            WorkerEvent::MeshChosen { choice, .. } => {
                self.mesh = Some(*choice);
                vec![]
            }
            WorkerEvent::PrecisionProgress {
                seq, done, total, ..
            } => {
                if seq == self.precision_seq {
                    self.precision = PrecisionView::Running { done, total };
                }
                vec![]
            }
            WorkerEvent::Precision { seq, study, .. } => {
                if seq == self.precision_seq {
                    self.precision = match study {
                        Ok(s) => PrecisionView::Ready(s),
                        Err(e) => PrecisionView::Failed(e),
                    };
                }
                vec![]
            }
            WorkerEvent::Failed {
                seq,
                reason,
                boundary,
                interrupted,
                ..
            } => {
                self.running = false;
                if interrupted == Some(Interruption::Cancelled) {
                    // a cancel the user asked for is news, not an error
                    self.message = Some(Message::Info(reason));
                } else {
                    self.message = Some(Message::Error(reason));
                }
                if self.start_seq == Some(seq) {
                    self.start_seq = None;
                    let previous = self.previous.take();
                    // the solver keeps the simulation it had when a natural state is
                    // stopped from outside: so does the screen
                    if let (Some(p), Some(_)) = (previous, interrupted) {
                        self.bring_back(p);
                        let effects = self.precision_obsolete();
                        self.finish_failed(seq);
                        return effects;
                    }
                }
                if let Some(bc) = boundary {
                    self.boundary_settled(bc, seq);
                }
                self.finish_failed(seq);
                vec![]
            }
        }
    }

    /// After the failure of request `seq`: idle if nothing newer is asked for.
    fn finish_failed(&mut self, seq: u64) {
        self.last_done = self.last_done.max(seq);
        if !self.busy() {
            self.solving = None;
            self.progress = None;
            self.started_at = None;
            self.elapsed = None;
            // pending steps start again from the state on screen
            if let Some(eps) = self.eps() {
                self.requested_eps = eps;
            }
        }
    }

    /// After the answer to request `seq`: the conditions in force are `bc`; if nothing newer
    /// was asked for, what is asked for is what is in force.
    fn boundary_settled(&mut self, bc: BoundaryConditions, seq: u64) {
        if seq >= self.last_sent {
            self.boundary = bc;
        }
    }

    fn finish(&mut self, seq: u64) -> Vec<Effect> {
        self.last_done = self.last_done.max(seq);
        if self.busy() {
            return vec![];
        }
        if self.message == Some(Message::Info(CANCELLING.into())) {
            self.message = Some(Message::Info(
                "the solve had finished before the cancel reached it; its result is on screen"
                    .into(),
            ));
        }
        self.solving = None;
        self.progress = None;
        self.started_at = None;
        self.elapsed = None;
        if self.running {
            self.run_on()
        } else {
            vec![]
        }
    }

    /// The solver thread is gone (it never stops by itself while the app holds its channel).
    pub fn on_solver_lost(&mut self) {
        self.solver_lost = true;
        self.running = false;
        self.solving = None;
        self.last_done = self.last_sent;
        self.message = Some(Message::Error(
            "the solver thread has stopped; export with e or quit with q".into(),
        ));
    }

    /// File names of an export of the current state.
    pub fn export_names(&self) -> Option<[String; 3]> {
        let point = &self.state.as_ref()?.point;
        Some(export::names(&self.case_label(), point.step, point.eps))
    }

    fn place(&self) -> String {
        if self.out_dir == Path::new(".") {
            String::new()
        } else {
            format!(" in {}", self.out_dir.display())
        }
    }

    /// Writes the current state and the load path so far (with the conditions of each
    /// point and the session's events) into [`App::out_dir`], in the formats of
    /// `spira run`, and says so in the message line.
    pub fn export(&mut self) -> Vec<PathBuf> {
        let written = match self.state.as_ref() {
            Some(state) => export::write(
                &self.out_dir,
                &self.case_label(),
                &state.snapshot,
                &self.path,
                &self.conditions,
                &self.events,
            ),
            None => Err(std::io::Error::other("no converged state yet")),
        };
        match written {
            Ok(files) => {
                let names: Vec<String> = files
                    .iter()
                    .filter_map(|f| f.file_name())
                    .map(|f| f.to_string_lossy().into_owned())
                    .collect();
                self.message = Some(Message::Info(format!(
                    "wrote {}{}",
                    names.join(", "),
                    self.place()
                )));
                files
            }
            Err(e) => {
                self.message = Some(Message::Error(format!("export failed: {e}")));
                vec![]
            }
        }
    }

    /// The session so far as a replayable script.
    pub fn script(&self) -> Script {
        let case = self
            .case_file
            .as_ref()
            .map(|p| std::fs::canonicalize(p).unwrap_or_else(|_| p.clone()));
        let from = self
            .events
            .iter()
            .rposition(|e| e.from_point == 0 && (e.what.starts_with("n =") || e.what == "reset"))
            .unwrap_or(0);
        Script::of(
            case,
            self.case_label(),
            self.events[from..].to_vec(),
            &self.ran,
        )
    }

    /// Writes [`App::script`] to `<case>-session.toml` in [`App::out_dir`].
    pub fn save_session(&mut self) -> Option<PathBuf> {
        let name = format!("{}-session.toml", export::sanitise(&self.case_label()));
        let file = self.out_dir.join(name);
        let saved = std::fs::create_dir_all(&self.out_dir)
            .map_err(|e| e.to_string())
            .and_then(|()| self.script().write(&file).map_err(|e| e.to_string()));
        match saved {
            Ok(()) => {
                self.message = Some(Message::Info(format!(
                    "saved the session to {}; spira replay {} --out DIR writes its CSVs",
                    file.display(),
                    file.display()
                )));
                Some(file)
            }
            Err(e) => {
                self.message = Some(Message::Error(format!("saving the session failed: {e}")));
                None
            }
        }
    }
}

fn mean_k1(snapshot: &Snapshot) -> Option<f64> {
    let k1: Vec<f64> = snapshot
        .rods
        .iter()
        .flat_map(|r| r.nodes.iter().map(|n| n.curvature[0]))
        .filter(|k| k.is_finite())
        .collect();
    (!k1.is_empty()).then(|| k1.iter().sum::<f64>() / k1.len() as f64)
}

/// The step of [`STEPS`] nearest the case's output spacing `target / steps`.
fn default_step(case: &Case) -> f64 {
    let s = (case.loading.target / case.loading.steps as f64).abs();
    if !(s.is_finite() && s > 0.0) {
        return 0.05;
    }
    STEPS
        .iter()
        .copied()
        .min_by(|a, b| (a.ln() - s.ln()).abs().total_cmp(&(b.ln() - s.ln()).abs()))
        .unwrap_or(0.05)
}

/// A step in `ε` with the digits it needs.
pub fn fmt_step(step: f64) -> String {
    let s = format!("{step:.6}");
    let s = s.trim_end_matches('0');
    s.trim_end_matches('.').to_string()
}

/// The next larger (`up`) or smaller number of helices, none past the ends.
fn next_helices(n: usize, up: bool) -> Option<usize> {
    if up {
        HELICES.iter().copied().find(|&m| m > n)
    } else {
        HELICES.iter().rev().copied().find(|&m| m < n)
    }
}

fn next_translation(t: Translation) -> Translation {
    match t {
        Translation::Fixed => Translation::Slide,
        Translation::Slide => Translation::Radial,
        Translation::Radial => Translation::Fixed,
    }
}

fn other_rotation(r: Rotation) -> Rotation {
    match r {
        Rotation::Clamped => Rotation::Free,
        Rotation::Free => Rotation::Pinned,
        Rotation::Pinned => Rotation::Clamped,
    }
}

fn translation_name(t: Translation) -> &'static str {
    match t {
        Translation::Fixed => "fixed",
        Translation::Slide => "slide",
        Translation::Radial => "radial",
    }
}

fn rotation_name(r: Rotation) -> &'static str {
    match r {
        Rotation::Clamped => "clamped",
        Rotation::Free => "free",
        Rotation::Pinned => "pinned",
    }
}
