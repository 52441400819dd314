//! The explorer's state as small values, one per concern: what is on screen ([`Screen`]),
//! how it is shown ([`View`]), the requests in flight ([`Requests`]) and the jobs the solver
//! ran for a replay ([`Replay`]).

use crate::case::DesignKey;
use crate::model::boundary::BoundaryConditions;
use crate::results::{CriticalPoint, LoadPoint};
use crate::session::export::SessionEvent;
use crate::session::worker::{CriticalMode, Job, Part, Solved};
use crate::study::MeshChoice;
use std::time::{Duration, Instant};

/// Positions of the curvature plot's cursor along `s/L`: `0, 1/CURSOR_STEPS, …, 1`.
pub const CURSOR_STEPS: usize = 32;

/// What is on screen: the simulation, its path and the session's changes. A new
/// simulation keeps a clone of it until its natural state arrives, to bring back if that
/// is cancelled.
#[derive(Clone, Debug)]
pub struct Screen {
    /// The simulation's generation (bumped by every new simulation; answers to an older
    /// one are dropped).
    pub(crate) generation: u64,
    /// Number of helices of the current simulation.
    pub helices: usize,
    /// Boundary conditions asked for (those in force are in [`Screen::state`]).
    pub boundary: BoundaryConditions,
    /// User step in the load parameter `λ` (> 0).
    pub step: f64,
    /// Load parameter `λ` the solver was last asked to reach (the current one when idle).
    pub requested_parameter: f64,
    /// Converged points in the order they were reached (step numbers 0, 1, ...).
    pub path: Vec<LoadPoint>,
    /// The conditions of each point of [`Screen::path`].
    pub conditions: Vec<BoundaryConditions>,
    /// Critical points crossed on this simulation's path, in order (without state and mode).
    pub critical: Vec<CriticalPoint>,
    /// The mode of each of [`Screen::critical`], in the same order.
    pub modes: Vec<CriticalMode>,
    /// The tip's sway at each point of [`Screen::path`] (m): how far the tip's offset from
    /// the base ([`Snapshot::tip_offset`](crate::results::Snapshot::tip_offset)) moved from
    /// the natural state's, the order parameter of the load panel.
    pub sway: Vec<f64>,
    /// The tip's offset from the base in the natural state of this simulation.
    pub natural_offset: Option<[f64; 2]>,
    /// The last converged state, if any.
    pub state: Option<Solved>,
    /// Mean κ1 (1/m) of the first state of this simulation (the natural state), the centre
    /// of the colour scale.
    pub natural_k1: Option<f64>,
    /// The mesh chosen for the case's accuracy target, when it gives one.
    pub mesh: Option<MeshChoice>,
    /// What changed on this path, in point order (conditions, step, a branch switch; first
    /// the start of the path: `n`, a reset, the load stepped), each at the first point
    /// solved after it.
    pub events: Vec<SessionEvent>,
    /// Changes that no point solved after them has reached yet, with the sequence number
    /// of the first request that applies them, and whether that request is the change
    /// itself (which goes if the request fails).
    pub(super) pending: Vec<(u64, bool, SessionEvent)>,
}

impl Screen {
    /// A first screen: no state yet, `helices` helices under `boundary`, user step `step`.
    pub(super) fn new(helices: usize, boundary: BoundaryConditions, step: f64) -> Screen {
        Screen {
            generation: 0,
            helices,
            boundary,
            step,
            requested_parameter: 0.0,
            path: Vec::new(),
            conditions: Vec::new(),
            critical: Vec::new(),
            modes: Vec::new(),
            sway: Vec::new(),
            natural_offset: None,
            state: None,
            natural_k1: None,
            mesh: None,
            events: Vec::new(),
            pending: Vec::new(),
        }
    }

    /// The screen of a new simulation (the next generation) from `λ = 0`: the same `n`,
    /// conditions asked for and step; the events of the discarded path go with it.
    pub(super) fn restart(&mut self) {
        self.events.clear();
        self.pending.clear();
        self.generation += 1;
        self.path.clear();
        self.conditions.clear();
        self.critical.clear();
        self.modes.clear();
        self.sway.clear();
        self.natural_offset = None;
        self.state = None;
        self.natural_k1 = None;
        self.requested_parameter = 0.0;
        self.mesh = None;
    }

    /// A point of request `seq` is about to join the path: the changes it is the first
    /// point after are placed at it.
    pub(super) fn place_events(&mut self, seq: u64) {
        let at = self.path.len();
        let (reached, waiting): (Vec<_>, Vec<_>) = self
            .pending
            .drain(..)
            .partition(|(from, _, _)| *from <= seq);
        self.pending = waiting;
        for (_, _, mut e) in reached {
            e.from_point = at;
            self.events.push(e);
        }
    }

    /// Request `seq` failed without a point: the change it was, and those folded into it
    /// (changes still waiting from earlier requests, which the scheduling dropped in its
    /// favour), are no changes of the path.
    pub(super) fn drop_failed_change(&mut self, seq: u64) {
        self.pending
            .retain(|(from, own, _)| !(*own && *from <= seq));
    }

    /// The changes of this path in point order, those no point has reached yet at the
    /// next point.
    pub fn session_events(&self) -> Vec<SessionEvent> {
        let next = self.path.len();
        let waiting = self.pending.iter().map(|(_, _, e)| SessionEvent {
            from_point: next,
            ..e.clone()
        });
        self.events.iter().cloned().chain(waiting).collect()
    }

    /// Number of rods of the state on screen (`n` before the first state).
    pub fn rods(&self) -> usize {
        self.state
            .as_ref()
            .map_or(self.helices, |s| s.snapshot.rods.len())
    }
}

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
    pub(super) fn next(self) -> ViewMode {
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

/// What the load panel plots against the load parameter's motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LoadSeries {
    /// The averaged normalised tip loads (or the stepped load's conjugate force).
    #[default]
    Loads,
    /// The lowest eigenvalue of each state's stability, with its sign.
    Stability,
    /// The tip's sway over the helix radius: the order parameter of a sway branch.
    Sway,
}

impl LoadSeries {
    pub(super) fn next(self) -> LoadSeries {
        match self {
            LoadSeries::Loads => LoadSeries::Stability,
            LoadSeries::Stability => LoadSeries::Sway,
            LoadSeries::Sway => LoadSeries::Loads,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            LoadSeries::Loads => "load panel: the tip loads",
            LoadSeries::Stability => "load panel: the lowest eigenvalue λmin of each state",
            LoadSeries::Sway => {
                "load panel: the tip's sway over the helix radius (0 on the fundamental path)"
            }
        }
    }
}

/// How the screen is shown: the overlays and panels chosen, the selections and cursors, and
/// what the terminal allows.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub show_help: bool,
    /// The work-precision chart replaces the curvature and load plots.
    pub show_precision: bool,
    /// The critical curve of the scene (`u`) replaces the curvature and load plots.
    pub show_curve: bool,
    /// The design key the critical curve is continued in (`U` cycles).
    pub curve_key: DesignKey,
    /// The critical-point list (`x`) is over the screen.
    pub show_critical: bool,
    pub mode: ViewMode,
    /// What the load panel plots.
    pub load_series: LoadSeries,
    pub selected_rod: usize,
    /// Cursor of the curvature plot, in steps of `1/CURSOR_STEPS` along `s/L`.
    pub cursor: usize,
    /// Cursor on the load path: an index into [`Screen::path`] (`None`: the current point).
    pub path_cursor: Option<usize>,
    /// Selected row of the critical-point list.
    pub critical_cursor: usize,
    /// The terminal is smaller than the screen needs: keys other than quit do nothing.
    pub too_small: bool,
    /// `NO_COLOR` is set: curves are told apart by their marks, not their colours.
    pub no_color: bool,
}

impl Default for View {
    fn default() -> View {
        View {
            show_help: false,
            show_precision: false,
            show_curve: false,
            curve_key: DesignKey::Turns,
            show_critical: false,
            mode: ViewMode::All,
            load_series: LoadSeries::Loads,
            selected_rod: 0,
            cursor: CURSOR_STEPS / 2,
            path_cursor: None,
            critical_cursor: 0,
            too_small: false,
            no_color: false,
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

/// The bookkeeping of the requests to the solver: their sequence numbers, the ones whose
/// answers matter, and the job in progress.
#[derive(Clone, Debug, Default)]
pub struct Requests {
    /// Continuous loading towards the case's target is on.
    pub running: bool,
    /// What the solver is doing now, if anything.
    pub solving: Option<String>,
    /// The solve in progress: how far it got (from the solver's progress reports).
    pub progress: Option<Progress>,
    /// Time since the job in progress started (updated by [`App::tick`](super::App::tick)).
    pub elapsed: Option<Duration>,
    pub(super) started_at: Option<Instant>,
    pub(super) next_seq: u64,
    /// Sequence number of the last request sent, and of the last one answered.
    pub(super) last_sent: u64,
    pub(super) last_done: u64,
    /// Sequence number of the last study asked for (answers to older ones are dropped).
    pub(super) precision_seq: u64,
    /// Sequence number of the last critical curve asked for.
    pub(super) curve_seq: u64,
    /// Sequence number of the new simulation's request while its natural state solves.
    pub(super) start_seq: Option<u64>,
    /// Sequence number of the last branch switch asked for.
    pub(super) switch_seq: Option<u64>,
    pub(super) solver_lost: bool,
}

impl Requests {
    /// True while a request is unanswered.
    pub fn busy(&self) -> bool {
        self.last_done < self.last_sent
    }

    /// The sequence number the next request will have.
    pub(super) fn upcoming(&self) -> u64 {
        self.next_seq + 1
    }

    /// The next sequence number.
    pub(super) fn next(&mut self) -> u64 {
        self.next_seq += 1;
        self.next_seq
    }

    /// The job of request `seq` started.
    pub(super) fn started(&mut self, seq: u64, job: String) {
        if seq > self.last_done {
            self.solving = Some(job);
            self.progress = None;
            self.started_at = Some(Instant::now());
            self.elapsed = Some(Duration::ZERO);
        }
    }

    /// Nothing is being solved any more.
    pub(super) fn idle(&mut self) {
        self.solving = None;
        self.progress = None;
        self.started_at = None;
        self.elapsed = None;
    }
}

/// The jobs sent to the solver and those it ran for this session, in order: what a saved
/// session replays.
#[derive(Clone, Debug, Default)]
pub struct Replay {
    /// Every job sent, by sequence number.
    sent: Vec<(u64, Job)>,
    /// The jobs the solver started, by sequence number (a job stopped part of the way as
    /// the part it ran).
    ran: Vec<(u64, Job)>,
}

impl Replay {
    /// The jobs the solver ran, in order.
    pub fn ran(&self) -> Vec<Job> {
        self.ran.iter().map(|(_, j)| j.clone()).collect()
    }

    /// How many jobs ran so far: a mark for [`Replay::rewind`].
    pub(super) fn mark(&self) -> usize {
        self.ran.len()
    }

    /// Forgets the jobs run after `mark`.
    pub(super) fn rewind(&mut self, mark: usize) {
        self.ran.truncate(mark);
    }

    /// Request `seq` of `job` was sent.
    pub(super) fn sent(&mut self, seq: u64, job: Job) {
        self.sent.push((seq, job));
    }

    /// The job of request `seq` started.
    pub(super) fn started(&mut self, seq: u64) {
        if let Some(j) = self
            .sent
            .iter()
            .find(|(s, _)| *s == seq)
            .map(|(_, j)| j.clone())
        {
            self.ran.push((seq, j));
        }
    }

    /// The job of request `seq` was stopped from outside after `steps` internal steps (with
    /// the next one `step_length` long), or before it changed anything (`None`): the part it
    /// ran replaces it, or it is forgotten.
    pub(super) fn stopped(&mut self, seq: u64, steps: Option<usize>, step_length: f64) {
        let Some(k) = self.ran.iter().rposition(|(s, _)| *s == seq) else {
            return;
        };
        let Some(steps) = steps else {
            self.ran.remove(k);
            return;
        };
        let part = Part { steps, step_length };
        let job = &mut self.ran[k].1;
        *job = match job.clone() {
            Job::Advance(parameter) | Job::AdvancePart { parameter, .. } => {
                Job::AdvancePart { parameter, part }
            }
            Job::Switch {
                index,
                sign,
                parameter,
                ..
            } => Job::Switch {
                index,
                sign,
                parameter,
                part: Some(part),
            },
            other => other,
        };
    }
}
