//! The explorer: a ratatui terminal UI around the continuation solver.
//!
//! [`app`] holds the state and its transitions (no terminal), the solver runs on its own
//! thread ([`crate::session`]), [`ui`] draws. This module owns the terminal: raw mode and the alternate
//! screen are set up here and undone on exit, on error and on panic.

pub mod app;
pub mod keys;
pub mod stability;
pub mod ui;

use crate::case::Case;
use crate::session::worker::{self, Worker, WorkerEvent};
use app::{App, Effect};
use crossterm::event::{self, Event, KeyCode, KeyEvent, KeyModifiers};
use crossterm::{cursor, execute, terminal};
use ratatui::backend::{Backend, CrosstermBackend, TestBackend};
use ratatui::Terminal;
use std::fmt;
use std::io::{self, IsTerminal};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::mpsc::{RecvTimeoutError, TryRecvError};
use std::sync::Arc;
use std::sync::Once;
use std::time::{Duration, Instant};

/// Why the explorer could not run, or stopped.
#[derive(Debug, thiserror::Error)]
pub enum TuiError {
    #[error("the explorer needs an interactive terminal; for a headless run use `spira run CASE`")]
    NotATerminal,
    #[error("the terminal (TERM={0}) cannot address the cursor, which the explorer needs; for a headless run use `spira run CASE` (or `spira replay SESSION.toml`)")]
    DumbTerminal(String),
    #[error("setting up the terminal")]
    Setup(#[source] io::Error),
    #[error("starting the solver thread")]
    SolverThread(#[source] io::Error),
    /// Reading input from or drawing to the terminal failed (or another I/O error, such as
    /// starting the threads of [`measure_responsiveness`]).
    #[error(transparent)]
    Terminal(#[from] io::Error),
    #[error("the solver thread stopped")]
    SolverStopped,
    #[error("the solver did not answer within 10 minutes")]
    Timeout,
    /// A step of [`measure_responsiveness`] failed, for this reason.
    #[error("step failed: {0}")]
    StepFailed(String),
}

/// How long the event loop waits for input before looking at the solver again.
const POLL: Duration = Duration::from_millis(40);

/// Opens the explorer on `case`, exporting into the current directory, and returns when the
/// user quits.
pub fn run(case: Case) -> Result<(), TuiError> {
    run_in(case, PathBuf::from("."))
}

/// Opens the explorer on `case`, exporting into `out_dir`.
pub fn run_in(case: Case, out_dir: PathBuf) -> Result<(), TuiError> {
    run_with(case, out_dir, None)
}

/// Opens the explorer on `case` read from `case_file` (`None`: the built-in case), exporting
/// into `out_dir`; a saved session names the case file.
pub fn run_with(case: Case, out_dir: PathBuf, case_file: Option<PathBuf>) -> Result<(), TuiError> {
    run_with_set(case, out_dir, case_file, Vec::new())
}

/// Opens the explorer as [`run_with`] on a case whose keys `set` (`key=value`) were
/// overridden on the command line; a saved session names them.
pub fn run_with_set(
    case: Case,
    out_dir: PathBuf,
    case_file: Option<PathBuf>,
    set: Vec<String>,
) -> Result<(), TuiError> {
    if !io::stdout().is_terminal() || !io::stdin().is_terminal() {
        return Err(TuiError::NotATerminal);
    }
    if let Some(term) = dumb_terminal() {
        return Err(TuiError::DumbTerminal(term));
    }
    install_panic_hook();
    // SIGTERM and SIGHUP (a dropped SSH connection) end the explorer through the event
    // loop, which restores the terminal on its way out
    let stop = Arc::new(AtomicBool::new(false));
    let done = Arc::new(AtomicBool::new(false));
    watch_signals(Arc::clone(&stop), Arc::clone(&done)).map_err(TuiError::Setup)?;
    let mut terminal = TerminalGuard::enter().map_err(TuiError::Setup)?;
    let worker = Worker::spawn().map_err(TuiError::SolverThread)?;
    let mut app = App::new(case, out_dir);
    app.case_file = case_file;
    app.case_set = set;
    app.view.no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
    let result = event_loop(&mut terminal.terminal, &mut app, &worker, &stop);
    drop(terminal);
    done.store(true, Ordering::Relaxed);
    // stop a solve in progress at its next check, then let the thread go
    worker.cancel(u64::MAX);
    drop(worker);
    result
}

/// How long after SIGTERM or SIGHUP the event loop has to end by itself before the signal
/// thread restores the terminal and ends the process.
const SIGNAL_GRACE: Duration = Duration::from_millis(500);

/// The signal that ended the explorer (0: none), for [`ended_by_signal`].
static ENDED_BY: AtomicI32 = AtomicI32::new(0);

/// The signal (SIGTERM or SIGHUP) that ended the last explorer, if one did: the command
/// then exits with 128 + its number, as a shell expects of a process a signal ended.
pub fn ended_by_signal() -> Option<i32> {
    Some(ENDED_BY.load(Ordering::Relaxed)).filter(|&s| s != 0)
}

/// SIGTERM and SIGHUP raise `stop`, which the event loop checks between polls. A hung-up
/// terminal can keep the loop from getting there: after a dropped connection every read
/// of the terminal fails, and crossterm's reader retries such a read for ever (a core
/// busy, seen after `tmux kill-session`). So a thread of its own waits for the signals and,
/// if the loop has not ended (`done`) within [`SIGNAL_GRACE`], restores the terminal as
/// far as it still can and exits the process (status 128 + the signal).
fn watch_signals(stop: Arc<AtomicBool>, done: Arc<AtomicBool>) -> io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("spira-signals".into())
        .spawn(move || {
            let Some(signal) = signals.forever().next() else {
                return;
            };
            ENDED_BY.store(signal, Ordering::Relaxed);
            stop.store(true, Ordering::Relaxed);
            let t0 = Instant::now();
            while t0.elapsed() < SIGNAL_GRACE {
                if done.load(Ordering::Relaxed) {
                    return;
                }
                std::thread::sleep(Duration::from_millis(10));
            }
            // not through `io::stdout()`, whose lock the stuck loop may hold
            let _ = terminal::disable_raw_mode();
            let restore = b"\x1b[?1049l\x1b[?25h";
            // SAFETY: writes a byte string of the given length to the standard output
            unsafe {
                libc::write(libc::STDOUT_FILENO, restore.as_ptr().cast(), restore.len());
            }
            std::process::exit(128 + signal);
        })?;
    Ok(())
}

/// The value of `TERM` when it names a terminal without cursor addressing.
fn dumb_terminal() -> Option<String> {
    let term = std::env::var("TERM").ok()?;
    matches!(term.as_str(), "dumb" | "unknown" | "").then_some(term)
}

/// Raw mode, alternate screen, hidden cursor while alive; restored when dropped.
struct TerminalGuard {
    terminal: Terminal<CrosstermBackend<io::Stdout>>,
}

impl TerminalGuard {
    fn enter() -> io::Result<TerminalGuard> {
        terminal::enable_raw_mode()?;
        let setup = execute!(io::stdout(), terminal::EnterAlternateScreen, cursor::Hide)
            .and_then(|()| Terminal::new(CrosstermBackend::new(io::stdout())));
        match setup {
            Ok(terminal) => Ok(TerminalGuard { terminal }),
            Err(e) => {
                restore_terminal();
                Err(e)
            }
        }
    }
}

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        restore_terminal();
    }
}

/// Undoes the terminal setup; safe to call more than once.
fn restore_terminal() {
    let _ = terminal::disable_raw_mode();
    let _ = execute!(io::stdout(), terminal::LeaveAlternateScreen, cursor::Show);
}

/// Restores the terminal before the default report of a panic on the UI thread. A panic on
/// the solver thread (or the thread of work-precision studies) is caught there and shown on
/// screen, so it leaves the terminal alone and prints nothing over the screen.
fn install_panic_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let name = std::thread::current().name().map(str::to_string);
            if matches!(
                name.as_deref(),
                Some(
                    worker::THREAD_NAME | worker::PRECISION_THREAD_NAME | worker::CURVE_THREAD_NAME
                )
            ) {
                return;
            }
            restore_terminal();
            previous(info);
        }));
    });
}

/// Sends `effects` out; returns false when the user quits.
fn apply(effects: Vec<Effect>, app: &mut App, worker: &Worker) -> bool {
    for effect in effects {
        match effect {
            Effect::Solve(request) => {
                if !worker.send(request) {
                    app.on_solver_lost();
                }
            }
            Effect::Cancel(through) => worker.cancel(through),
            Effect::CancelCurve(through) => worker.cancel_curve(through),
            Effect::Export => {
                app.export();
            }
            Effect::SaveSession => {
                app.save_session();
            }
            Effect::Quit => return false,
        }
    }
    true
}

/// Takes every answer the solver has ready; true if there was any.
fn drain_worker(app: &mut App, worker: &Worker) -> bool {
    let mut any = false;
    loop {
        match worker.events.try_recv() {
            Ok(event) => {
                any = true;
                let effects = app.on_worker_event(event);
                apply(effects, app, worker);
            }
            Err(TryRecvError::Empty) => return any,
            Err(TryRecvError::Disconnected) => {
                if !any {
                    app.on_solver_lost();
                }
                return true;
            }
        }
    }
}

fn event_loop<B: Backend>(
    terminal: &mut Terminal<B>,
    app: &mut App,
    worker: &Worker,
    stop: &AtomicBool,
) -> Result<(), TuiError>
where
    B::Error: Into<TuiError>,
{
    let effects = app.start();
    apply(effects, app, worker);
    let mut dirty = true;
    let mut lost = false;
    let mut last_tick = Instant::now();
    loop {
        if stop.load(Ordering::Relaxed) {
            return Ok(());
        }
        // the elapsed time of a long solve moves on screen about every 0.2 s
        if app.busy() && last_tick.elapsed() >= Duration::from_millis(200) {
            last_tick = Instant::now();
            app.tick(last_tick);
            dirty = true;
        }
        if dirty {
            let size = terminal.size().map_err(Into::into)?;
            app.view.too_small = size.width < ui::MIN_WIDTH || size.height < ui::MIN_HEIGHT;
            terminal.draw(|f| ui::draw(f, app)).map_err(Into::into)?;
            dirty = false;
        }
        if event::poll(POLL)? {
            // take everything typed so far before drawing again
            loop {
                match event::read()? {
                    Event::Key(key) => {
                        dirty = true;
                        let effects = app.handle_key(key);
                        if !apply(effects, app, worker) {
                            return Ok(());
                        }
                    }
                    Event::Resize(..) => dirty = true,
                    _ => {}
                }
                if !event::poll(Duration::ZERO)? {
                    break;
                }
            }
        }
        if !lost {
            if drain_worker(app, worker) {
                dirty = true;
            }
            if worker.is_finished() {
                drain_worker(app, worker);
                app.on_solver_lost();
                lost = true;
                dirty = true;
            }
        }
    }
}

/// Responsiveness of the explorer while the solver works, measured headless on a
/// [`TestBackend`] with the real [`App`], [`Worker`] and drawing code.
#[derive(Clone, Debug)]
pub struct Responsiveness {
    pub helices: usize,
    pub width: u16,
    pub height: u16,
    /// Key press (rod selection) to the redrawn frame, each measured while a step was
    /// being solved on the solver thread.
    pub key_to_frame: Vec<Duration>,
    /// Wall time of each measured step of `Δε` on the solver thread.
    pub step_times: Vec<Duration>,
    pub step: f64,
    /// Key press to redrawn frame during a long solve (a step of the case with internal
    /// steps of at most 1e-5), over its first second.
    pub key_to_frame_long: Vec<Duration>,
    /// The cancel key during that solve to an idle app (the answer received).
    pub cancel_to_idle: Option<Duration>,
}

fn median(v: &[Duration]) -> Duration {
    let mut v = v.to_vec();
    v.sort();
    v.get(v.len() / 2).copied().unwrap_or_default()
}

impl Responsiveness {
    pub fn key_to_frame_median(&self) -> Duration {
        median(&self.key_to_frame)
    }
    pub fn key_to_frame_max(&self) -> Duration {
        self.key_to_frame.iter().max().copied().unwrap_or_default()
    }
    pub fn step_median(&self) -> Duration {
        median(&self.step_times)
    }
}

impl fmt::Display for Responsiveness {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        writeln!(
            f,
            "explorer, n = {}, {}x{} frame: key press -> redrawn frame while a step solves: median {:.2} ms, max {:.2} ms ({} presses)",
            self.helices,
            self.width,
            self.height,
            ms(self.key_to_frame_median()),
            ms(self.key_to_frame_max()),
            self.key_to_frame.len()
        )?;
        if !self.key_to_frame_long.is_empty() {
            writeln!(
                f,
                "during a long solve (internal steps of 1e-5): key -> frame median {:.2} ms, max {:.2} ms ({} presses); cancel key -> idle {}",
                ms(median(&self.key_to_frame_long)),
                ms(self.key_to_frame_long.iter().max().copied().unwrap_or_default()),
                self.key_to_frame_long.len(),
                self.cancel_to_idle
                    .map_or("n/a (the step finished first)".to_string(), |d| format!("{:.1} ms", ms(d)))
            )?;
        }
        let all: Vec<String> = self
            .step_times
            .iter()
            .map(|d| format!("{:.0}", ms(*d)))
            .collect();
        write!(
            f,
            "one step of Δε = {} on the solver thread: median {:.1} ms (steps: {} ms)",
            app::fmt_step(self.step),
            ms(self.step_median()),
            all.join(", ")
        )
    }
}

/// Drives the explorer headless on `case`: solves the natural state, then takes `steps`
/// steps of the default `Δε`; while each is being solved, presses "next rod" every few
/// milliseconds and times key handling plus drawing a `width` x `height` frame.
pub fn measure_responsiveness(
    case: Case,
    steps: usize,
    width: u16,
    height: u16,
) -> Result<Responsiveness, TuiError> {
    let helices = case.geometry.helices;
    let worker = Worker::spawn()?;
    let Ok(mut terminal) = Terminal::new(TestBackend::new(width, height));
    let mut app = App::new(case, std::env::temp_dir());
    let mut result = Responsiveness {
        helices,
        width,
        height,
        key_to_frame: Vec::new(),
        step_times: Vec::new(),
        step: app.screen.step,
        key_to_frame_long: Vec::new(),
        cancel_to_idle: None,
    };
    let deadline = Instant::now() + Duration::from_secs(600);
    let effects = app.start();
    send_requests(effects, &worker);
    wait_idle(&mut app, &worker, deadline)?;
    for _ in 0..steps {
        measure_step(&mut app, &worker, &mut terminal, &mut result, deadline)?;
    }
    // a long solve: the same case with internal steps of at most 1e-5 in ε (a case with
    // both ends sliding would be refused as a free rigid motion)
    let mut slow = app.case().clone();
    slow.solver.initial_step = LONG_SOLVE_STEP;
    slow.solver.max_step = LONG_SOLVE_STEP;
    slow.solver.min_step = slow.solver.min_step.min(LONG_SOLVE_STEP);
    let mut app = App::new(slow, std::env::temp_dir());
    send_requests(app.start(), &worker);
    wait_idle(&mut app, &worker, deadline)?;
    measure_long_solve(&mut app, &worker, &mut terminal, &mut result, deadline)?;
    worker.cancel(u64::MAX);
    worker.join();
    Ok(result)
}

/// Largest internal step (in ε) of the long solve of [`measure_responsiveness`]: a step of
/// Δε takes thousands of them.
const LONG_SOLVE_STEP: f64 = 1e-5;

/// A step of a long solve (`app`'s case with tiny internal steps). Presses "next rod" for
/// a second while it solves, then the cancel key, and times the way to idle.
fn measure_long_solve(
    app: &mut App,
    worker: &Worker,
    terminal: &mut Terminal<TestBackend>,
    result: &mut Responsiveness,
    deadline: Instant,
) -> Result<(), TuiError> {
    let down = KeyEvent::new(KeyCode::Down, KeyModifiers::NONE);
    send_requests(app.perform(keys::Action::StepForward), worker);
    let t0 = Instant::now();
    while app.busy() && t0.elapsed() < Duration::from_secs(1) {
        while let Ok(e) = worker.events.try_recv() {
            app.on_worker_event(e);
        }
        let t = Instant::now();
        app.handle_key(down);
        let Ok(_) = terminal.draw(|f| ui::draw(f, app));
        result.key_to_frame_long.push(t.elapsed());
        std::thread::sleep(Duration::from_millis(5));
    }
    if app.busy() {
        let t = Instant::now();
        for e in app.perform(keys::Action::Cancel) {
            if let Effect::Cancel(through) = e {
                worker.cancel(through);
            }
        }
        wait_idle(app, worker, deadline)?;
        let Ok(_) = terminal.draw(|f| ui::draw(f, app));
        result.cancel_to_idle = Some(t.elapsed());
    }
    Ok(())
}

/// Sends the solver requests among `effects` (the headless driver does nothing else).
fn send_requests(effects: Vec<Effect>, worker: &Worker) {
    for effect in effects {
        if let Effect::Solve(r) = effect {
            worker.send(r);
        }
    }
}

/// Feeds the solver's answers to `app` until it is idle.
fn wait_idle(app: &mut App, worker: &Worker, deadline: Instant) -> Result<(), TuiError> {
    while app.busy() {
        if Instant::now() > deadline {
            return Err(TuiError::Timeout);
        }
        match worker.events.recv_timeout(Duration::from_millis(100)) {
            Ok(e) => send_requests(app.on_worker_event(e), worker),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return Err(TuiError::SolverStopped),
        }
    }
    Ok(())
}

/// One step of `Δε`: while it is being solved, presses "next rod" every few milliseconds
/// and times key handling plus drawing.
fn measure_step(
    app: &mut App,
    worker: &Worker,
    terminal: &mut Terminal<TestBackend>,
    result: &mut Responsiveness,
    deadline: Instant,
) -> Result<(), TuiError> {
    let down = KeyEvent::new(KeyCode::Down, KeyModifiers::NONE);
    let right = KeyEvent::new(KeyCode::Right, KeyModifiers::NONE);
    send_requests(app.handle_key(right), worker);
    while app.busy() {
        if Instant::now() > deadline {
            return Err(TuiError::Timeout);
        }
        match worker.events.try_recv() {
            Ok(e) => {
                if let WorkerEvent::Solved {
                    done: true, state, ..
                } = &e
                {
                    result.step_times.push(state.time);
                }
                app.on_worker_event(e);
                continue;
            }
            Err(TryRecvError::Disconnected) => return Err(TuiError::SolverStopped),
            Err(TryRecvError::Empty) => {}
        }
        let t = Instant::now();
        app.handle_key(down);
        let Ok(_) = terminal.draw(|f| ui::draw(f, app));
        result.key_to_frame.push(t.elapsed());
        std::thread::sleep(Duration::from_millis(5));
    }
    match &app.message {
        Some(app::Message::Error(e)) => Err(TuiError::StepFailed(e.clone())),
        _ => Ok(()),
    }
}
