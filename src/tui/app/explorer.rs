//! The explorer's state ([`App`]) and what every transition shares: its requests to the
//! solver, and a new simulation that keeps the screen it replaces.

use super::state::{Replay, Requests, Screen, View};
use crate::case::Case;
use crate::model::boundary::Joints;
use crate::model::loading::{Control, LoadParameter};
use crate::session::worker::{CurveDone, CurveJob, Job, Request};
use crate::simulation::curve::CurveRow;
use crate::study::Study;
use crate::tui::keys::Action;
use crate::tui::stability;
use std::path::PathBuf;
use std::time::Instant;

/// The numbers of helices `n`/`N` step through (no wrap-around: they stop at the ends).
pub const HELICES: [usize; 5] = [1, 2, 4, 8, 16];
/// The user steps in the load parameter that `+`/`-` choose from.
pub const STEPS: [f64; 5] = [0.005, 0.01, 0.02, 0.05, 0.1];
/// Largest and smallest user step in the load parameter.
pub const MAX_STEP: f64 = STEPS[STEPS.len() - 1];
pub const MIN_STEP: f64 = STEPS[0];
/// A change of `n` that would discard a path of more converged points than this asks
/// first (the same key again confirms).
pub const CONFIRM_DISCARD: usize = 4;
/// The message while a cancel is on its way to the solver.
pub(super) const CANCELLING: &str = "cancelling…";

/// The message of a work-precision study asked for, until it is finished.
pub(super) const STUDY_STARTED: &str =
    "work-precision study of the path to the target started on its own thread; the explorer stays live";

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
    /// Cancel the critical curves asked for up to this sequence number (the one in
    /// progress stops at its last converged point).
    CancelCurve(u64),
    /// Leave the explorer.
    Quit,
}

/// The explorer's work-precision study of the current case.
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

/// How far on each side of the design key's value the explorer's critical curve goes, as
/// a fraction of the value: ±10 %, a designer's neighbourhood of the scene.
pub const CURVE_WIDTH: f64 = 0.1;
/// Rows of the explorer's critical curve on each side of the value (the value included).
pub const CURVE_ROWS_EACH: usize = 6;

/// The explorer's critical curve of the scene.
#[derive(Clone, Debug, PartialEq)]
pub enum CurveView {
    /// None asked for since the scene last changed.
    None,
    /// Running: the rows found so far (in the order found), `done` of `total`, and the
    /// load parameter the path that locates the critical point has reached.
    Running {
        rows: Vec<CurveRow>,
        done: usize,
        total: usize,
        locating: Option<f64>,
        cancelling: bool,
    },
    Ready(Box<CurveDone>),
    Failed(String),
}

/// A line for the user under the status line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Message {
    Info(String),
    Error(String),
}

/// What a new simulation replaces, kept until its natural state arrives: the screen, and
/// how far the replay log went.
#[derive(Debug)]
pub(super) struct Kept {
    screen: Screen,
    ran: usize,
}

/// The explorer's state.
#[derive(Debug)]
pub struct App {
    /// The case as loaded (its `n` and conditions are what `r` returns to).
    pub(super) case: Case,
    /// Where the case came from (`None`: the built-in case), for a saved session.
    pub case_file: Option<PathBuf>,
    /// The case keys overridden on the command line (`key=value`), for a saved session.
    pub case_set: Vec<String>,
    /// Where exports go.
    pub out_dir: PathBuf,
    /// What is on screen.
    pub screen: Screen,
    /// How it is shown.
    pub view: View,
    /// The requests to the solver in flight.
    pub requests: Requests,
    /// The jobs the solver ran for this session, for a replay.
    pub replay: Replay,
    pub message: Option<Message>,
    pub precision: PrecisionView,
    pub curve: CurveView,
    /// The scene the curve on screen (or in progress) is of.
    pub(super) curve_scene: Option<Box<Case>>,
    /// A key that must be pressed again to confirm (a change of `n` discarding a path).
    pub confirm: Option<Action>,
    /// The key in hand is the confirmation [`App::confirm`] asked for.
    pub(super) confirmed: bool,
    /// The screen before a new simulation was asked for, until the new one's natural state
    /// arrives: a cancelled natural state brings it back.
    pub(super) previous: Option<Box<Kept>>,
    /// The kind of crossing the solver refused last (the conditions stayed as they were):
    /// `p` goes on from it, so that the cycle passes a kind the state cannot take.
    pub(super) refused_joints: Option<Joints>,
}

impl App {
    /// A new explorer on `case`, exporting into `out_dir`. Call [`App::start`] for the
    /// first solver request.
    pub fn new(case: Case, out_dir: PathBuf) -> App {
        let screen = Screen::new(case.geometry.helices, case.boundary, default_step(&case));
        App {
            case,
            case_file: None,
            case_set: Vec::new(),
            out_dir,
            screen,
            view: View::default(),
            requests: Requests::default(),
            replay: Replay::default(),
            message: None,
            precision: PrecisionView::None,
            curve: CurveView::None,
            curve_scene: None,
            confirm: None,
            confirmed: false,
            previous: None,
            refused_joints: None,
        }
    }

    /// Updates the elapsed time of the solve in progress (the event loop calls it).
    pub fn tick(&mut self, now: Instant) {
        self.requests.elapsed = self
            .requests
            .started_at
            .map(|t| now.saturating_duration_since(t));
    }

    /// The case as loaded.
    pub fn case(&self) -> &Case {
        &self.case
    }

    /// The model solved, for the status line: the cell of the infinite tube, the pair, or
    /// the full assembly.
    pub fn model_name(&self) -> &'static str {
        if self.case.discretisation.cell {
            "cell"
        } else if self.solves_pair() {
            "pair"
        } else {
            "full"
        }
    }

    /// Whether the explorer solves one symmetric pair for the current `n` (its Bloch blocks
    /// judging the whole assembly's stability), rather than the full assembly.
    pub fn solves_pair(&self) -> bool {
        // the model of the state on screen (a switch moves a pair's path onto the whole
        // assembly), else the one the case asks for
        if let Some(s) = &self.screen.state {
            return s.pair;
        }
        self.case
            .with_helices(self.screen.helices)
            .for_explorer()
            .discretisation
            .symmetric
    }

    /// The case's name, with the number of helices when it was changed from the case's.
    pub fn case_label(&self) -> String {
        if self.screen.helices == self.case.geometry.helices {
            self.case.name.clone()
        } else {
            format!("{}-n{}", self.case.name, self.screen.helices)
        }
    }

    /// Target of continuous loading (the case's `loading.target`).
    /// The user's step in the load parameter, in its own measure (the step chosen among
    /// [`STEPS`] times the parameter's natural scale).
    pub fn user_step(&self) -> f64 {
        self.screen.step * self.case.parameter_unit()
    }

    pub fn target(&self) -> f64 {
        self.case.loading.target
    }

    /// True while a request is unanswered.
    pub fn busy(&self) -> bool {
        self.requests.busy()
    }

    /// Number of rods of the state on screen.
    pub fn rods(&self) -> usize {
        self.screen.rods()
    }

    /// Compression ratio `ε` of the state on screen.
    pub fn compression_ratio(&self) -> Option<f64> {
        self.screen
            .state
            .as_ref()
            .map(|s| s.point.compression_ratio)
    }

    /// Load parameter `λ` of the state on screen.
    pub fn parameter(&self) -> Option<f64> {
        self.screen.state.as_ref().map(|s| s.point.parameter)
    }

    /// What the case's load parameter `λ` is.
    pub fn load_parameter(&self) -> LoadParameter {
        self.case.load_parameter()
    }

    /// The load parameter's symbol as the screen and the messages print it: `ε` under
    /// displacement control, `P/Pcrit` under load control.
    pub fn symbol(&self) -> &'static str {
        self.load_parameter().symbol()
    }

    /// The load parameter of a point as the screen shows it: under displacement control
    /// the compression ratio `ratio` measured at the tip (the prescribed `λ` up to
    /// round-off), under load control `λ = parameter` (`P/Pcrit`).
    pub fn shown_parameter(&self, ratio: f64, parameter: f64) -> f64 {
        if self.load_parameter() == LoadParameter::axial(Control::Displacement) {
            ratio
        } else {
            parameter
        }
    }

    /// Stability of the state on screen.
    pub fn stability(&self) -> Option<bool> {
        self.screen
            .state
            .as_ref()
            .and_then(|s| stability::is_unstable(&s.point))
    }

    pub(super) fn request(&mut self, job: Job) -> Effect {
        if matches!(self.message, Some(Message::Error(_))) {
            self.message = None;
        }
        let seq = self.requests.next();
        self.requests.last_sent = seq;
        self.replay.sent(seq, job.clone());
        Effect::Solve(Request {
            generation: self.screen.generation,
            seq,
            job,
        })
    }

    /// A work-precision study of the case as it stands (its `n` and the conditions asked
    /// for), on the solver's precision thread; it does not make the app busy.
    pub(super) fn request_precision(&mut self) -> Effect {
        let seq = self.requests.next();
        self.requests.precision_seq = seq;
        self.precision = PrecisionView::Running { done: 0, total: 0 };
        Effect::Solve(Request {
            generation: self.screen.generation,
            seq,
            job: Job::Precision(Box::new(self.scene())),
        })
    }

    /// The case or its conditions changed: the study and the curve on screen are of another
    /// problem. New ones are asked for when they are shown.
    pub(super) fn precision_obsolete(&mut self) -> Vec<Effect> {
        self.precision = PrecisionView::None;
        let mut effects = Vec::new();
        if self.view.show_precision {
            effects.push(self.request_precision());
        }
        // a curve is of the scene: a branch switch or a new path leaves it as it is
        if self
            .curve_scene
            .as_deref()
            .is_some_and(|c| *c != self.scene())
        {
            effects.extend(self.curve_obsolete());
        }
        effects
    }

    /// The scene as a case: the case with the current `n` and conditions.
    pub(super) fn scene(&self) -> Case {
        let mut case = self.case.with_helices(self.screen.helices);
        case.boundary = self.screen.boundary;
        case
    }

    /// The critical curve of the scene in the chosen design key, on the curve thread; it
    /// does not make the app busy.
    pub(super) fn request_curve(&mut self) -> Effect {
        let seq = self.requests.next();
        self.requests.curve_seq = seq;
        let scene = self.scene();
        self.curve_scene = Some(Box::new(scene.clone()));
        self.curve = CurveView::Running {
            rows: Vec::new(),
            done: 0,
            total: 2 * CURVE_ROWS_EACH - 1,
            locating: None,
            cancelling: false,
        };
        Effect::Solve(Request {
            generation: self.screen.generation,
            seq,
            job: Job::Curve(Box::new(CurveJob {
                case: scene,
                key: self.view.curve_key,
                width: CURVE_WIDTH,
                rows_each: CURVE_ROWS_EACH,
            })),
        })
    }

    /// The scene changed: a curve in progress is stopped, and a new one asked for when the
    /// panel is shown.
    pub(super) fn curve_obsolete(&mut self) -> Vec<Effect> {
        let mut effects = Vec::new();
        if matches!(self.curve, CurveView::Running { .. }) {
            effects.push(Effect::CancelCurve(self.requests.curve_seq));
        }
        self.curve = CurveView::None;
        self.curve_scene = None;
        if self.view.show_curve {
            effects.push(self.request_curve());
        }
        effects
    }

    /// The first request: solve the case's natural state.
    pub fn start(&mut self) -> Vec<Effect> {
        self.restart()
    }

    /// What is on screen now, for [`App::restart`] to bring back if the new simulation's
    /// natural state is cancelled (taken before the change of `n` or the reset).
    pub(super) fn keep(&self) -> Box<Kept> {
        Box::new(Kept {
            screen: self.screen.clone(),
            ran: self.replay.mark(),
        })
    }

    /// The simulation the cancelled natural state was to replace, back on screen.
    pub(super) fn bring_back(&mut self, kept: Box<Kept>) {
        self.screen = kept.screen;
        self.replay.rewind(kept.ran);
        self.view.selected_rod = self.view.selected_rod.min(self.rods().saturating_sub(1));
        self.view.critical_cursor = 0;
    }

    /// A new simulation with the current `n` and conditions, from `λ = 0`, for the reason
    /// `what` (the first event of its path); `previous` is what was on screen (brought back
    /// if its natural state is cancelled).
    pub(super) fn restart_from(&mut self, previous: Box<Kept>, what: String) -> Vec<Effect> {
        // a new simulation asked for while another's natural state solves replaces that
        // one: the simulation to come back to is still the one before
        if self.previous.is_none() && previous.screen.state.is_some() {
            self.previous = Some(previous);
        }
        self.restart_with(Some(what))
    }

    /// A new simulation with the current `n` and conditions, from `λ = 0`.
    pub(super) fn restart(&mut self) -> Vec<Effect> {
        self.restart_with(None)
    }

    /// [`App::restart`], recording `what` as the first event of the new path.
    fn restart_with(&mut self, what: Option<String>) -> Vec<Effect> {
        // a solve of the old simulation in progress is of no more use: stop it
        let cancel = self
            .busy()
            .then_some(Effect::Cancel(self.requests.last_sent));
        self.screen.restart();
        self.view.path_cursor = None;
        self.view.critical_cursor = 0;
        self.view.selected_rod = self
            .view
            .selected_rod
            .min(self.screen.helices.saturating_sub(1));
        self.requests.progress = None;
        self.requests.running = false;
        self.requests.solving = None;
        if let Some(what) = what {
            self.record(what, false);
        }
        let mut case = self.case.with_helices(self.screen.helices);
        case.boundary = self.screen.boundary;
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
            self.requests.start_seq = Some(r.seq);
        }
        effects.push(start);
        effects.extend(self.precision_obsolete());
        effects
    }
}

/// The step of [`STEPS`] nearest the case's output spacing `target / steps`.
pub(super) fn default_step(case: &Case) -> f64 {
    let s = (case.loading.target / case.loading.steps as f64 / case.parameter_unit()).abs();
    if !(s.is_finite() && s > 0.0) {
        return 0.05;
    }
    STEPS
        .iter()
        .copied()
        .min_by(|a, b| (a.ln() - s.ln()).abs().total_cmp(&(b.ln() - s.ln()).abs()))
        .unwrap_or(0.05)
}
