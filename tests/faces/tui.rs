//! The explorer without a terminal: key events -> state -> solver requests (app), the solver
//! thread's scheduling (worker), and the screen drawn on ratatui's `TestBackend` compared with
//! committed snapshots in `tests/snapshots/tui/` (`SPIRA_UPDATE_SNAPSHOTS=1` rewrites them
//! after an intended change; review the diff before committing).

use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::style::Color;
use ratatui::Terminal;
use spira::case::Case;
use spira::discretisation::shape::Order;
use spira::model::boundary::{BoundaryConditions, Joints, Rotation, Translation};
use spira::output;
use spira::session::export::SessionEvent;
use spira::session::script::{Action as ScriptAction, Script};
use spira::session::worker::{coalesce, Job, Request, Solved, Worker, WorkerEvent};
use spira::simulation::Simulation;
use spira::study::{Reference, Rung, RungResult, Study, Values};
use spira::tui::app::{App, Effect, Message, PrecisionView};
use spira::tui::stability::{stretches, Stretch};
use spira::tui::ui::{self, K1Scale, K1_PALETTE};
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

// ---- helpers ----

/// A cheap case: `n` thesis helices, 8 quadratic elements per rod.
fn small_case(n: usize) -> Case {
    let text =
        format!("name = \"small\"\n[geometry]\nhelices = {n}\n[discretisation]\nelements = 8\n");
    Case::parse(&text, "small.toml", "small").expect("valid case")
}

fn key(code: KeyCode) -> KeyEvent {
    KeyEvent::new(code, KeyModifiers::NONE)
}

fn ch(c: char) -> KeyEvent {
    key(KeyCode::Char(c))
}

fn requests(effects: &[Effect]) -> Vec<&Request> {
    effects
        .iter()
        .filter_map(|e| match e {
            Effect::Solve(r) => Some(r),
            _ => None,
        })
        .collect()
}

/// The one request in `effects`.
fn only_request(effects: &[Effect]) -> Request {
    let r = requests(effects);
    assert_eq!(r.len(), 1, "expected one request, got {effects:?}");
    r[0].clone()
}

/// A converged state of `sim` as the solver thread reports it, with the solve's figures
/// fixed so that drawings do not depend on timing.
fn solved(sim: &Simulation, step: usize) -> Box<Solved> {
    let mut point = sim.load_point(step);
    point.iterations = 3;
    point.residual = 1.5e-11;
    let snapshot = sim.snapshot();
    Box::new(Solved {
        bulk: spira::discretisation::bulk::step_bulk(sim.model(), &snapshot, &point),
        point,
        snapshot,
        boundary: sim.boundary_conditions(),
        step_length: sim.step_length(),
        time: Duration::from_millis(42),
        critical: Vec::new(),
        modes: Vec::new(),
        pair: sim.solves_pair(),
    })
}

fn answer(request: &Request, state: Box<Solved>) -> WorkerEvent {
    WorkerEvent::Solved {
        generation: request.generation,
        seq: request.seq,
        done: true,
        state,
    }
}

/// An app on `case` whose natural state has arrived; returns the simulation behind it.
fn started(case: Case) -> (App, Simulation) {
    // exports go to the current folder: tests that export set their own
    let mut app = App::new(case.clone(), PathBuf::from("."));
    let start = only_request(&app.start());
    assert!(matches!(start.job, Job::Start(_)));
    let sim = Simulation::from_case(&case).expect("natural state");
    let effects = app.on_worker_event(answer(&start, solved(&sim, 0)));
    assert!(effects.is_empty());
    assert!(!app.busy());
    (app, sim)
}

/// Sends `effects` to the real solver thread and feeds its answers back until the app has
/// nothing outstanding.
fn settle(app: &mut App, worker: &Worker, effects: Vec<Effect>) {
    let mut effects = effects;
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        for e in effects.drain(..) {
            if let Effect::Solve(r) = e {
                assert!(worker.send(r), "solver thread gone");
            }
        }
        if !app.busy() {
            return;
        }
        assert!(Instant::now() < deadline, "solver did not answer");
        if let Ok(ev) = worker.events.recv_timeout(Duration::from_millis(200)) {
            effects = app.on_worker_event(ev);
        }
    }
}

/// The solver's word that request `r` (a step to ε = 0.05) has started and is under way:
/// 7 inner steps, at ε = 0.0321, 2.5 s in.
fn under_way(app: &mut App, r: &Request) {
    app.on_worker_event(WorkerEvent::Started {
        generation: r.generation,
        seq: r.seq,
        job: Job::Advance(0.05).describe("ε"),
    });
    app.on_worker_event(WorkerEvent::Progress {
        generation: r.generation,
        seq: r.seq,
        parameter: 0.0321,
        steps: 7,
        elapsed: Duration::from_millis(2500),
    });
}

/// How many files an export of `app` writes: state, load path and reactions, and with
/// critical points their table and one mode file each.
fn exported_files(app: &App) -> usize {
    match app.screen.critical.len() {
        0 => 3,
        n => 4 + n,
    }
}

/// The saved `session`, read back and replayed headless (on the two-helix small case) into
/// `dir`, writes the explorer's exported `files` byte for byte.
fn assert_replays_exactly(session: &Path, files: &[PathBuf], dir: &Path) {
    let script = spira::session::script::Session::read(session).expect("readable");
    let replayed =
        spira::session::replay::replay_into(&script, &small_case(2), dir).expect("replays");
    assert_eq!(files.len(), replayed.len());
    for (ours, theirs) in files.iter().zip(&replayed) {
        assert_eq!(ours.file_name(), theirs.file_name());
        assert_eq!(
            std::fs::read_to_string(ours).unwrap(),
            std::fs::read_to_string(theirs).unwrap(),
            "{} replays exactly",
            ours.display()
        );
    }
}

/// The solver reports ε from the tip height it reached: equal to what was asked up to
/// rounding.
fn assert_close(eps: Option<f64>, expected: f64) {
    let eps = eps.expect("a converged state");
    assert!(
        (eps - expected).abs() < 1e-12,
        "ε = {eps}, expected {expected}"
    );
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spira-tui-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

// ---- app: keys -> state -> requests ----

#[test]
fn start_asks_for_the_natural_state_of_the_case() {
    let case = small_case(2);
    let mut app = App::new(case.clone(), PathBuf::from("."));
    let r = only_request(&app.start());
    match r.job {
        Job::Start(c) => {
            assert_eq!(c.geometry.helices, 2);
            assert_eq!(c.boundary, case.boundary);
        }
        other => panic!("expected Start, got {other:?}"),
    }
    assert!(app.busy());
    assert!(app.screen.state.is_none());
}

#[test]
fn arrows_and_vim_keys_step_compression_by_the_user_step() {
    let (mut app, _sim) = started(small_case(1));
    assert_eq!(
        app.screen.step, 0.05,
        "default step is target / steps of the case"
    );
    let r = only_request(&app.handle_key(key(KeyCode::Right)));
    assert_eq!(r.job, Job::Advance(0.05));
    // a second press while the first is solving goes on from the requested ε
    let r = only_request(&app.handle_key(ch('l')));
    assert_eq!(r.job, Job::Advance(0.1));
    let r = only_request(&app.handle_key(key(KeyCode::Left)));
    assert_eq!(r.job, Job::Advance(0.05));
    let r = only_request(&app.handle_key(ch('h')));
    assert_eq!(r.job, Job::Advance(0.0));
    let r = only_request(&app.handle_key(ch('h')));
    assert_eq!(r.job, Job::Advance(-0.05), "extension is allowed");
}

#[test]
fn plus_and_minus_choose_the_step_from_the_list_and_stop_at_its_ends() {
    // Δε from a fixed list, so that 0.05 can always be returned to
    let (mut app, _sim) = started(small_case(1));
    assert!(app.handle_key(ch('+')).is_empty());
    assert_eq!(app.screen.step, 0.1);
    app.handle_key(ch('-'));
    app.handle_key(ch('-'));
    assert_eq!(app.screen.step, 0.02);
    app.handle_key(ch('+'));
    assert_eq!(app.screen.step, 0.05, "back to 0.05");
    for _ in 0..20 {
        app.handle_key(ch('-'));
    }
    assert_eq!(app.screen.step, spira::tui::app::MIN_STEP);
    assert_eq!(app.screen.step, 0.005);
    for _ in 0..20 {
        app.handle_key(ch('='));
    }
    assert_eq!(app.screen.step, spira::tui::app::MAX_STEP);
    assert_eq!(app.screen.step, 0.1);
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("largest")));
    let r = only_request(&app.handle_key(ch('l')));
    assert_eq!(r.job, Job::Advance(0.1));
}

#[test]
fn stepping_stops_at_the_target() {
    let mut case = small_case(1);
    case.loading.target = 0.12;
    case.loading.steps = 1;
    let (mut app, _sim) = started(case);
    assert_eq!(
        app.screen.step, 0.1,
        "the listed step nearest target / steps"
    );
    assert_eq!(
        only_request(&app.handle_key(ch('l'))).job,
        Job::Advance(0.1)
    );
    assert_eq!(
        only_request(&app.handle_key(ch('l'))).job,
        Job::Advance(0.12),
        "the step is cut at the target"
    );
    assert!(app.handle_key(ch('l')).is_empty(), "no step beyond it");
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("target")));
    assert_eq!(
        only_request(&app.handle_key(ch('h'))).job,
        Job::Advance(0.02)
    );
}

#[test]
fn a_step_outside_the_geometry_is_refused_with_a_message() {
    let mut case = small_case(1);
    case.loading.target = 1.0;
    let (mut app, _sim) = started(case);
    for _ in 0..20 {
        app.handle_key(ch('+'));
    }
    for _ in 0..9 {
        only_request(&app.handle_key(ch('l'))); // up to 0.9
    }
    assert!(app.handle_key(ch('l')).is_empty(), "ε = 1 is the base");
    match &app.message {
        Some(Message::Error(m)) => assert!(m.contains("ε = 1.00000"), "{m}"),
        other => panic!("expected an error message, got {other:?}"),
    }
    assert!((app.screen.requested_parameter - 0.9).abs() < 1e-12);
}

#[test]
fn up_down_j_k_select_the_rod_and_wrap() {
    let (mut app, _sim) = started(small_case(4));
    assert_eq!(app.rods(), 4);
    assert_eq!(app.view.selected_rod, 0);
    app.handle_key(key(KeyCode::Up));
    assert_eq!(app.view.selected_rod, 3);
    app.handle_key(ch('j'));
    assert_eq!(app.view.selected_rod, 0);
    app.handle_key(key(KeyCode::Down));
    app.handle_key(ch('j'));
    assert_eq!(app.view.selected_rod, 2);
    let effects = app.handle_key(ch('k'));
    assert!(effects.is_empty(), "selection needs no solve");
    assert_eq!(app.view.selected_rod, 1);
}

#[test]
fn condition_keys_toggle_each_condition_and_ask_for_a_resolve() {
    let (mut app, _sim) = started(small_case(2));
    let bc = |r: Request| match r.job {
        Job::SetBoundary(bc) => bc,
        other => panic!("expected SetBoundary, got {other:?}"),
    };
    let b1 = bc(only_request(&app.handle_key(ch('b'))));
    assert_eq!(b1.base.translation, Translation::Slide);
    let b2 = bc(only_request(&app.handle_key(ch('b'))));
    assert_eq!(b2.base.translation, Translation::Radial);
    let b3 = bc(only_request(&app.handle_key(ch('b'))));
    assert_eq!(b3.base.translation, Translation::Fixed);
    let b4 = bc(only_request(&app.handle_key(ch('B'))));
    assert_eq!(b4.base.rotation, Rotation::Free);
    let b5 = bc(only_request(&app.handle_key(ch('t'))));
    assert_eq!(b5.tip.translation, Translation::Slide);
    // a base hinge with a sliding, hinged tip: the rods may turn about a horizontal axis
    // through the base (a free rigid motion): refused, nothing asked
    assert!(app.handle_key(ch('T')).is_empty());
    assert!(
        matches!(&app.message, Some(Message::Error(m)) if m.contains("free to turn about a horizontal axis") && m.contains("undone")),
        "{:?}",
        app.message
    );
    assert_eq!(app.screen.boundary, b5, "undone");
    let b7 = bc(only_request(&app.handle_key(ch('p'))));
    assert_eq!(b7.joints, Joints::Welded, "pin → welded");
    // each toggle builds on the last asked-for conditions
    assert_eq!(b7.base.rotation, Rotation::Free);
    assert_eq!(b7.tip.translation, Translation::Slide);
    assert_eq!(b7.tip.rotation, Rotation::Clamped);
    assert_eq!(app.screen.boundary, b7);
}

#[test]
fn n_changes_the_helices_and_starts_over_ignoring_old_answers() {
    let (mut app, sim) = started(small_case(8));
    let step = only_request(&app.handle_key(ch('l')));
    let r = only_request(&app.handle_key(ch('n')));
    match &r.job {
        Job::Start(c) => assert_eq!(c.geometry.helices, 16),
        other => panic!("expected Start, got {other:?}"),
    }
    assert_eq!(app.screen.helices, 16);
    assert!(app.screen.path.is_empty() && app.screen.state.is_none());
    assert_eq!(app.screen.requested_parameter, 0.0);
    // the answer to the step asked before the restart belongs to the old simulation
    assert!(app
        .on_worker_event(answer(&step, solved(&sim, 1)))
        .is_empty());
    assert!(app.screen.path.is_empty(), "stale answer ignored");
    assert!(app.busy());
    // no wrap-around, n stops at 16 (and N at 1)
    assert!(app.handle_key(ch('n')).is_empty(), "no wrap 16 -> 1");
    assert_eq!(app.screen.helices, 16);
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("largest")));
    let r = only_request(&app.handle_key(ch('N')));
    assert!(matches!(&r.job, Job::Start(c) if c.geometry.helices == 8));
    for _ in 0..5 {
        app.handle_key(ch('N'));
    }
    assert_eq!(app.screen.helices, 1, "no wrap 1 -> 16");
    assert_eq!(app.case_label(), "small-n1");
}

#[test]
fn a_change_of_n_asks_before_it_discards_a_long_path() {
    let (mut app, mut sim) = started(small_case(1));
    for k in 1..=5 {
        let r = only_request(&app.handle_key(ch('l')));
        sim.advance_to(0.05 * k as f64).expect("converges");
        app.on_worker_event(answer(&r, solved(&sim, k)));
    }
    assert_eq!(app.screen.path.len(), 6);
    assert!(app.handle_key(ch('n')).is_empty(), "asks first");
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("again to confirm")));
    // another key keeps the path
    assert!(app.handle_key(ch('j')).is_empty());
    assert_eq!(app.screen.path.len(), 6);
    assert_eq!(app.screen.helices, 1);
    app.handle_key(ch('n'));
    let r = only_request(&app.handle_key(ch('n')));
    assert!(matches!(&r.job, Job::Start(c) if c.geometry.helices == 2));
    assert!(app.screen.path.is_empty());
}

#[test]
fn reset_returns_to_the_case_conditions_and_step() {
    let (mut app, _sim) = started(small_case(2));
    app.handle_key(ch('t'));
    app.handle_key(ch('p'));
    app.handle_key(ch('+'));
    app.handle_key(ch('l'));
    let r = only_request(&app.handle_key(ch('r')));
    match &r.job {
        Job::Start(c) => {
            assert_eq!(c.boundary, BoundaryConditions::default());
            assert_eq!(c.geometry.helices, 2);
        }
        other => panic!("expected Start, got {other:?}"),
    }
    assert_eq!(app.screen.boundary, BoundaryConditions::default());
    assert_eq!(app.screen.step, 0.05);
    assert_eq!(app.screen.requested_parameter, 0.0);
    assert!(app.screen.path.is_empty());
}

#[test]
fn space_runs_step_by_step_to_the_target_and_pauses() {
    let mut case = small_case(1);
    case.loading.target = 0.15;
    case.loading.steps = 3;
    let (mut app, mut sim) = started(case);
    let mut r = only_request(&app.handle_key(ch(' ')));
    assert!(app.requests.running);
    let mut reached = vec![];
    loop {
        let Job::Advance(eps) = r.job else {
            panic!("expected Advance, got {:?}", r.job)
        };
        sim.advance_to(eps).expect("converges");
        reached.push(eps);
        let effects = app.on_worker_event(answer(&r, solved(&sim, reached.len())));
        match requests(&effects).first() {
            Some(next) => r = (*next).clone(),
            None => break,
        }
    }
    assert_eq!(reached, vec![0.05, 0.1, 0.15]);
    assert!(!app.requests.running, "stops at the target");
    assert_eq!(app.screen.path.len(), 4);
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("target")));
}

#[test]
fn space_while_running_pauses_and_the_answer_in_flight_asks_no_more() {
    let (mut app, mut sim) = started(small_case(1));
    let r = only_request(&app.handle_key(ch(' ')));
    assert!(app.handle_key(ch(' ')).is_empty());
    assert!(!app.requests.running);
    let Job::Advance(eps) = r.job else {
        panic!("expected Advance")
    };
    sim.advance_to(eps).expect("converges");
    assert!(app.on_worker_event(answer(&r, solved(&sim, 1))).is_empty());
    assert!(!app.busy());
    assert_close(app.compression_ratio(), 0.05);
}

#[test]
fn a_failed_step_shows_the_reason_and_keeps_the_last_state() {
    let (mut app, _sim) = started(small_case(1));
    app.handle_key(ch(' '));
    let r = only_request(&app.handle_key(ch('l')));
    let reason = "continuation stopped at eps = 0.000000 (target 0.050000): Newton diverged";
    let effects = app.on_worker_event(WorkerEvent::Failed {
        generation: r.generation,
        seq: r.seq,
        reason: reason.into(),
        boundary: Some(BoundaryConditions::default()),
        interrupted: None,
    });
    assert!(effects.is_empty());
    assert_eq!(app.message, Some(Message::Error(reason.into())));
    assert!(!app.requests.running && !app.busy());
    assert_eq!(
        app.compression_ratio(),
        Some(0.0),
        "last converged state stays"
    );
    assert_eq!(
        app.screen.requested_parameter, 0.0,
        "the next step starts from it"
    );
    assert_eq!(app.screen.path.len(), 1);
    // a new request clears the error
    only_request(&app.handle_key(ch('l')));
    assert_eq!(app.message, None);
}

#[test]
fn a_refused_condition_change_shows_the_conditions_in_force() {
    let (mut app, _sim) = started(small_case(2));
    let r = only_request(&app.handle_key(ch('p')));
    assert_eq!(app.screen.boundary.joints, Joints::Welded);
    app.on_worker_event(WorkerEvent::Failed {
        generation: r.generation,
        seq: r.seq,
        reason: "singular".into(),
        boundary: Some(BoundaryConditions::default()),
        interrupted: None,
    });
    assert_eq!(
        app.screen.boundary.joints,
        Joints::Pin,
        "back to what the solver holds"
    );
}

#[test]
fn the_joints_cycle_passes_a_kind_the_solver_refused() {
    // pin → welded asked and refused: the conditions stay pins, and the next `p` asks for
    // the kind after the refused one (elastic), not welded again; an answer ends that
    let (mut app, sim) = started(small_case(2));
    let r = only_request(&app.handle_key(ch('p')));
    app.on_worker_event(WorkerEvent::Failed {
        generation: r.generation,
        seq: r.seq,
        reason: "their own path from rest stops short".into(),
        boundary: Some(BoundaryConditions::default()),
        interrupted: None,
    });
    assert_eq!(app.screen.boundary.joints, Joints::Pin);
    let r = only_request(&app.handle_key(ch('p')));
    assert!(
        matches!(app.screen.boundary.joints, Joints::Elastic(_)),
        "{:?}",
        app.screen.boundary.joints
    );
    app.on_worker_event(answer(&r, solved(&sim, 0)));
    let on_screen = app.screen.boundary.joints;
    let _ = only_request(&app.handle_key(ch('p')));
    assert_eq!(
        app.screen.boundary.joints,
        on_screen.next(app.case().joint_springs()),
        "after an answer the cycle goes on from the conditions on screen"
    );
}

#[test]
fn quit_keys_and_help_overlay() {
    let (mut app, _sim) = started(small_case(1));
    assert_eq!(app.handle_key(ch('q')), vec![Effect::Quit]);
    assert_eq!(app.handle_key(key(KeyCode::Esc)), vec![Effect::Quit]);
    let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
    assert_eq!(app.handle_key(ctrl_c), vec![Effect::Quit]);
    assert!(app.handle_key(ch('?')).is_empty());
    assert!(app.view.show_help);
    // any key closes the help and does nothing else
    assert!(app.handle_key(ch('l')).is_empty());
    assert!(!app.view.show_help);
    app.handle_key(ch('?'));
    assert_eq!(
        app.handle_key(ch('q')),
        vec![Effect::Quit],
        "q quits from the help"
    );
    app.handle_key(ch('?'));
    assert_eq!(app.handle_key(ctrl_c), vec![Effect::Quit]);
}

#[test]
fn key_releases_are_ignored() {
    let (mut app, _sim) = started(small_case(1));
    let mut release = key(KeyCode::Right);
    release.kind = KeyEventKind::Release;
    assert!(app.handle_key(release).is_empty());
    assert_eq!(app.screen.requested_parameter, 0.0);
}

#[test]
fn e_exports_state_load_path_and_reactions_in_the_run_formats() {
    let (mut app, mut sim) = started(small_case(2));
    assert_eq!(app.handle_key(ch('e')), vec![Effect::Export]);
    let r = only_request(&app.handle_key(ch('l')));
    sim.advance_to(0.05).expect("converges");
    app.on_worker_event(answer(&r, solved(&sim, 1)));
    let dir = temp_dir("export");
    app.out_dir = dir.clone();
    let files = app.export();
    let names: Vec<String> = files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "small-step1-eps0.0500-state.csv",
            "small-step1-eps0.0500-load.csv",
            "small-step1-eps0.0500-reactions.csv"
        ]
    );
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).expect("written");
    let state = app.screen.state.as_ref().unwrap();
    assert_eq!(
        read("small-step1-eps0.0500-state.csv"),
        output::state_csv("small", &state.snapshot)
    );
    // the load table of `spira run` with the conditions of each row
    let load = read("small-step1-eps0.0500-load.csv");
    assert_eq!(
        load,
        spira::session::export::load_csv(
            "small",
            &app.screen.path,
            &app.screen.conditions,
            &app.screen.events
        )
    );
    let run_format = output::load_csv("small", &app.screen.path);
    let data = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| !l.starts_with('#'))
            .map(String::from)
            .collect()
    };
    for (ours, run) in data(&load).iter().zip(data(&run_format)) {
        assert!(ours.starts_with(&run), "{ours} extends {run}");
    }
    assert!(data(&load)[0].ends_with(",conditions"));
    assert!(data(&load)[1].ends_with("base fixed/clamped tip fixed/clamped joints on"));
    assert_eq!(
        read("small-step1-eps0.0500-reactions.csv"),
        output::reactions_csv("small", &app.screen.path)
    );
    match &app.message {
        Some(Message::Info(m)) => {
            for n in &names {
                assert!(m.contains(n.as_str()), "{m} names {n}");
            }
        }
        other => panic!("expected the file names on screen, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn export_failure_is_a_message_not_a_crash() {
    let (mut app, _sim) = started(small_case(1));
    let file = temp_dir("export-fail").join("a-file");
    std::fs::write(&file, "x").unwrap();
    app.out_dir = file.join("sub");
    assert!(app.export().is_empty());
    assert!(matches!(&app.message, Some(Message::Error(m)) if m.starts_with("export failed")));
}

// ---- worker: scheduling and the real solver ----

fn req(seq: u64, job: Job) -> Request {
    Request {
        generation: 1,
        seq,
        job,
    }
}

#[test]
fn coalescing_keeps_every_step_and_the_last_of_a_run_of_changes() {
    let bc = BoundaryConditions::default();
    let mut q: VecDeque<Request> = [
        req(1, Job::Advance(0.05)),
        req(2, Job::SetBoundary(bc)),
        req(3, Job::SetBoundary(bc)),
        req(4, Job::Advance(0.1)),
        req(5, Job::Advance(0.15)),
        req(6, Job::SetBoundary(bc)),
    ]
    .into();
    coalesce(&mut q);
    let seqs: Vec<u64> = q.iter().map(|r| r.seq).collect();
    assert_eq!(
        seqs,
        [1, 3, 4, 5, 6],
        "every step stays; of two changes in a row the later"
    );

    let mut q: VecDeque<Request> = [
        req(1, Job::Advance(0.05)),
        req(2, Job::Start(Box::new(small_case(1)))),
        req(3, Job::Advance(0.1)),
        req(4, Job::Start(Box::new(small_case(2)))),
        req(5, Job::SetBoundary(bc)),
    ]
    .into();
    coalesce(&mut q);
    let seqs: Vec<u64> = q.iter().map(|r| r.seq).collect();
    assert_eq!(seqs, [4, 5], "a Start drops everything before it");
}

#[test]
fn the_solver_thread_answers_every_step_and_coalesces_toggles() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(2), std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    assert_eq!(app.compression_ratio(), Some(0.0));
    // three presses in a row: three points
    let mut effects = app.handle_key(ch('l'));
    effects.extend(app.handle_key(ch('l')));
    effects.extend(app.handle_key(ch('l')));
    settle(&mut app, &worker, effects);
    assert_close(app.compression_ratio(), 0.15);
    assert_eq!(app.screen.path.len(), 4);
    let steps: Vec<usize> = app.screen.path.iter().map(|p| p.step).collect();
    assert_eq!(steps, [0, 1, 2, 3]);
    // a condition change re-solves at the same ε
    let effects = app.handle_key(ch('p'));
    settle(&mut app, &worker, effects);
    let state = app.screen.state.as_ref().unwrap();
    assert_eq!(state.boundary.joints, Joints::Welded);
    assert_close(Some(state.point.compression_ratio), 0.15);
    // the status line says the kind, within 80 columns
    let screen = text(&draw(&app, 80, 24));
    assert!(
        screen.lines().any(|l| l.contains("│ joints welded")),
        "{screen}"
    );
    // asking again for what is in force needs no solve and adds no point
    let n = app.screen.path.len();
    let effects = app.handle_key(ch('p'));
    let effects2 = app.handle_key(ch('p'));
    let mut all = effects;
    all.extend(effects2);
    settle(&mut app, &worker, all);
    assert!(!app.busy());
    assert!(
        app.screen.path.len() <= n + 1,
        "the toggle back and forth coalesces"
    );
    // welded → elastic → sliding
    assert_eq!(
        app.screen.state.as_ref().unwrap().boundary.joints,
        Joints::Sliding
    );
    worker.join();
}

/// Sliding crossings are carried by the symmetric pair: on n = 4, which the explorer solves
/// as a symmetric pair, `p` up to sliding re-solves at the same ε on the pair, and the path
/// then steps under sliding joints.
#[test]
fn sliding_joints_keep_the_symmetric_pair_and_its_path() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(4), std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    assert_eq!(app.model_name(), "pair");
    let effects = app.handle_key(ch('l'));
    settle(&mut app, &worker, effects);
    assert_close(app.compression_ratio(), 0.05);
    // pin → welded → elastic → sliding
    for _ in 0..3 {
        let effects = app.handle_key(ch('p'));
        settle(&mut app, &worker, effects);
    }
    let state = app.screen.state.as_ref().expect("a state");
    assert_eq!(state.boundary.joints, Joints::Sliding);
    assert_eq!(app.model_name(), "pair");
    assert_close(app.compression_ratio(), 0.05);
    let effects = app.handle_key(ch('l'));
    settle(&mut app, &worker, effects);
    assert_close(app.compression_ratio(), 0.1);
    assert_eq!(
        app.screen.state.as_ref().unwrap().boundary.joints,
        Joints::Sliding
    );
    assert_eq!(app.model_name(), "pair");
    worker.join();
}

#[test]
fn quick_key_presses_give_a_point_each_on_screen_in_the_export_and_the_session() {
    let worker = Worker::spawn().expect("thread");
    let dir = temp_dir("quick-keys");
    let mut app = App::new(small_case(2), dir.join("explorer"));
    let start = app.start();
    settle(&mut app, &worker, start);
    // four → presses before any answer arrives
    let mut effects = Vec::new();
    for _ in 0..4 {
        effects.extend(app.handle_key(key(KeyCode::Right)));
    }
    assert_eq!(requests(&effects).len(), 4, "{effects:?}");
    settle(&mut app, &worker, effects);
    let eps: Vec<f64> = app
        .screen
        .path
        .iter()
        .map(|p| p.compression_ratio)
        .collect();
    let expected = [0.0, 0.05, 0.1, 0.15, 0.2];
    assert_eq!(eps.len(), expected.len(), "{eps:?}");
    for (got, want) in eps.iter().zip(expected) {
        assert!((got - want).abs() < 1e-12, "{eps:?}");
    }
    // the export: one row per point
    let files = app.export();
    assert_eq!(files.len(), exported_files(&app), "{:?}", app.message);
    let load = std::fs::read_to_string(&files[1]).unwrap();
    let rows = load.lines().filter(|l| !l.starts_with('#')).skip(1).count();
    assert_eq!(rows, 5, "{load}");
    // the session: one step per press, replayed to the same table
    let session = app.save_session().expect("saved");
    let script = spira::session::script::Session::read(&session).expect("readable");
    let asked: Vec<f64> = app
        .script()
        .actions
        .iter()
        .filter_map(|a| match a {
            ScriptAction::Advance { parameter, .. } => Some(*parameter),
            _ => None,
        })
        .collect();
    assert_eq!(asked, [0.05, 0.1, 0.15, 0.2]);
    let replayed =
        spira::session::replay::replay_into(&script, &small_case(2), &dir.join("replay"))
            .expect("replays");
    assert_eq!(
        std::fs::read_to_string(&files[1]).unwrap(),
        std::fs::read_to_string(&replayed[1]).unwrap()
    );
    worker.join();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_cancel_drops_the_queued_steps() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(2), std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    let mut effects = Vec::new();
    for _ in 0..4 {
        effects.extend(app.handle_key(key(KeyCode::Right)));
    }
    effects.extend(app.handle_key(ch('c')));
    send_all(&worker, effects);
    settle(&mut app, &worker, Vec::new());
    assert!(!app.busy());
    // the cancel reached the solver before any step ended: none of them, or at most the
    // one it was solving, is on the path
    assert!(app.screen.path.len() <= 2, "{}", app.screen.path.len());
}

#[test]
fn the_solver_thread_reports_failures_and_keeps_the_state() {
    let worker = Worker::spawn().expect("thread");
    // the continuum's reference curvatures, so that the natural state carries reactions
    // and releasing the supports leaves a residual for Newton to solve (with the discrete
    // ones the unloaded natural state is still an equilibrium once they are released, and
    // the singular system is met only at the next step)
    let mut case = small_case(1);
    case.discretisation.reference = spira::discretisation::discrete_model::Reference::Continuum;
    let mut app = App::new(case, std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    // the tip sliding radially (along x, for a helix of 3.5 turns), then the base sliding:
    // a rigid translation along x makes the system singular (a free motion the case
    // reader's check does not know; both ends sliding freely it refuses up front)
    let mut effects = app.handle_key(ch('t'));
    effects.extend(app.handle_key(ch('t')));
    effects.extend(app.handle_key(ch('b')));
    settle(&mut app, &worker, effects);
    assert_eq!(
        app.compression_ratio(),
        Some(0.0),
        "the last converged state stays"
    );
    match &app.message {
        Some(Message::Error(m)) => assert!(!m.is_empty()),
        other => panic!("expected the failure on screen, got {other:?}"),
    }
    assert_eq!(
        app.screen.boundary,
        app.screen.state.as_ref().unwrap().boundary,
        "what is asked for falls back to what is in force"
    );
    let events = app.screen.session_events();
    assert!(
        !events
            .iter()
            .any(|e| e.what.starts_with("base translation")),
        "a change that failed is no event of the path: {events:?}"
    );
    assert!(
        events.iter().all(|e| e.from_point < app.screen.path.len()),
        "the changes that stay are placed at points solved under them: {events:?}"
    );
    worker.join();
}

#[test]
fn a_request_after_a_failed_start_is_answered_with_a_reason() {
    let worker = Worker::spawn().expect("thread");
    let events = &worker.events;
    assert!(worker.send(req(1, Job::Advance(0.1))));
    let mut failed = None;
    while failed.is_none() {
        match events
            .recv_timeout(Duration::from_secs(60))
            .expect("answer")
        {
            WorkerEvent::Failed { reason, .. } => failed = Some(reason),
            WorkerEvent::Started { .. } => {}
            other => panic!("unexpected {other:?}"),
        }
    }
    assert!(failed.unwrap().contains("no converged state"));
    worker.join();
}

// ---- stability marking ----

#[test]
fn unstable_stretches_share_their_end_points() {
    let flags = [false, false, true, true, false, false];
    let s = stretches(flags.len(), |k| Some(flags[k]));
    assert_eq!(
        s,
        vec![
            Stretch {
                unstable: false,
                points: 0..2
            },
            Stretch {
                unstable: true,
                points: 1..5
            },
            Stretch {
                unstable: false,
                points: 4..6
            },
        ]
    );
    assert_eq!(
        stretches(3, |_| None),
        vec![Stretch {
            unstable: false,
            points: 0..3
        }]
    );
    assert!(stretches(0, |_| None).is_empty());
    assert_eq!(stretches(1, |_| Some(true))[0].points, 0..1);
}

// ---- drawing ----

fn draw(app: &App, width: u16, height: u16) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
    terminal.draw(|f| ui::draw(f, app)).unwrap();
    terminal
}

fn text(terminal: &Terminal<TestBackend>) -> String {
    let buf = terminal.backend().buffer();
    let mut s = String::new();
    for y in 0..buf.area.height {
        for x in 0..buf.area.width {
            s.push_str(buf[(x, y)].symbol());
        }
        s.push('\n');
    }
    s
}

/// Compares the screen with `tests/snapshots/tui/NAME.txt`.
fn assert_snapshot(name: &str, screen: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots/tui")
        .join(format!("{name}.txt"));
    if std::env::var_os("SPIRA_UPDATE_SNAPSHOTS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, screen).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|_| {
        panic!(
            "no snapshot {}; run with SPIRA_UPDATE_SNAPSHOTS=1 to write it",
            path.display()
        )
    });
    if expected != screen {
        let diff: Vec<String> = expected
            .lines()
            .zip(screen.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .map(|(k, (a, b))| format!("line {}:\n  expected {a}\n  found    {b}", k + 1))
            .collect();
        panic!(
            "screen differs from {} (SPIRA_UPDATE_SNAPSHOTS=1 rewrites it):\n{}\n\nscreen:\n{screen}",
            path.display(),
            diff.join("\n")
        );
    }
}

fn braille_cells(screen: &str) -> usize {
    screen
        .chars()
        .filter(|c| ('\u{2801}'..='\u{28ff}').contains(c))
        .count()
}

/// The n = 2 small case compressed to ε = 0.1 in two steps, rod 2 selected.
fn compressed_app() -> App {
    let (mut app, mut sim) = started(small_case(2));
    for k in 1..=2 {
        let r = only_request(&app.handle_key(ch('l')));
        let Job::Advance(eps) = r.job else {
            panic!("expected Advance")
        };
        sim.advance_to(eps).expect("converges");
        app.on_worker_event(answer(&r, solved(&sim, k)));
    }
    app.handle_key(ch('j'));
    app
}

#[test]
fn screen_natural_state_80x24() {
    let (app, _sim) = started(small_case(2));
    let t = draw(&app, 80, 24);
    let screen = text(&t);
    for label in [
        "X-Y",
        "Z-Y",
        "Z-X",
        "κ1 (1/m)",
        "s/L",
        "ε",
        "stability stable",
        "n 2",
    ] {
        assert!(screen.contains(label), "missing {label}:\n{screen}");
    }
    assert!(braille_cells(&screen) > 100, "canvases drawn:\n{screen}");
    assert_snapshot("natural_80x24", &screen);
}

#[test]
fn screen_compressed_state_100x30() {
    let app = compressed_app();
    let t = draw(&app, 100, 30);
    let screen = text(&t);
    for label in [
        "rod 1 (left)",
        "joints",
        "bulk",
        "fx",
        "fy",
        "fz",
        "ε 0.10000",
        "Δε 0.05",
    ] {
        assert!(screen.contains(label), "missing {label}:\n{screen}");
    }
    assert!(braille_cells(&screen) > 200);
    assert_snapshot("compressed_100x30", &screen);
}

#[test]
fn screen_colours_k1_bins_selected_rod_and_joints() {
    let app = compressed_app();
    let t = draw(&app, 100, 30);
    let buf = t.backend().buffer();
    let braille_fg = |color: Color| {
        buf.content()
            .iter()
            .filter(|c| {
                c.fg == color
                    && c.symbol()
                        .chars()
                        .all(|ch| ('\u{2801}'..='\u{28ff}').contains(&ch))
            })
            .count()
    };
    assert!(braille_fg(Color::White) > 10, "selected rod in white");
    assert!(braille_fg(Color::LightMagenta) > 0, "joints marked");
    let k1: usize = K1_PALETTE.iter().map(|&c| braille_fg(c)).sum();
    assert!(k1 > 10, "other rods coloured by κ1");
    // no true colour anywhere
    assert!(buf
        .content()
        .iter()
        .all(|c| !matches!(c.fg, Color::Rgb(..) | Color::Indexed(_))));
}

#[test]
fn k1_scale_bins_and_legend() {
    let case = small_case(1);
    let sim = Simulation::from_case(&case).unwrap();
    let snap = sim.snapshot();
    let k = snap.rods[0].nodes[3].curvature[0];
    let scale = K1Scale::of(&snap, Some(k));
    assert_eq!(
        scale.color(k),
        Color::Green,
        "the natural state is the middle bin"
    );
    assert_eq!(scale.color(scale.lo), K1_PALETTE[0]);
    assert_eq!(scale.color(scale.hi), K1_PALETTE[4]);
    let legend: String = scale
        .legend()
        .spans
        .iter()
        .map(|s| s.content.as_ref())
        .collect();
    assert!(
        legend.contains("κ1 (1/m)") && legend.contains("█████"),
        "{legend}"
    );
}

#[test]
fn screen_help_overlay_80x24() {
    let (mut app, _sim) = started(small_case(2));
    app.out_dir = PathBuf::from("/data/runs/./spira");
    app.handle_key(ch('?'));
    let screen = text(&draw(&app, 80, 24));
    for (k, _) in ui::KEYS {
        assert!(screen.contains(k), "help lists {k}:\n{screen}");
    }
    // every key and the export folder's absolute path fit 80x24
    assert!(screen.contains("exports to /data/runs/spira "), "{screen}");
    assert!(screen.contains("q Esc"), "{screen}");
    assert_snapshot("help_80x24", &screen);
}

#[test]
fn screen_too_small_gets_a_message() {
    let (app, _sim) = started(small_case(2));
    let screen = text(&draw(&app, 79, 24));
    assert!(screen.contains("terminal too small"));
    assert!(screen.contains("this one is 79x24"));
    assert_eq!(braille_cells(&screen), 0);
    assert_snapshot("too_small_60x20", &text(&draw(&app, 60, 20)));
    let tiny = text(&draw(&app, 10, 3));
    assert!(!tiny.trim().is_empty(), "something readable even at 10x3");
}

#[test]
fn screen_while_solving_the_natural_state() {
    let mut app = App::new(small_case(8), PathBuf::from("."));
    let r = only_request(&app.start());
    app.on_worker_event(WorkerEvent::Started {
        generation: r.generation,
        seq: r.seq,
        job: r.job.describe("ε"),
    });
    let screen = text(&draw(&app, 80, 24));
    assert!(screen.contains("solving the natural state"));
    // the n is on the line already; the cancel key fits 80 columns
    assert!(
        screen.contains("natural state… 0.0 s · c cancels"),
        "{screen}"
    );
    assert_snapshot("solving_80x24", &screen);
}

#[test]
fn screen_uses_the_room_of_a_large_terminal() {
    let app = compressed_app();
    let small = braille_cells(&text(&draw(&app, 80, 24)));
    let large = braille_cells(&text(&draw(&app, 200, 60)));
    assert!(large > 3 * small, "{large} vs {small} braille cells");
}

// ---- work-precision chart and accuracy-driven meshes ----

/// The one work-precision request in `effects`.
fn precision_request(effects: &[Effect]) -> Request {
    let r: Vec<&Request> = requests(effects)
        .into_iter()
        .filter(|r| matches!(r.job, Job::Precision(_)))
        .collect();
    assert_eq!(r.len(), 1, "expected one study request, got {effects:?}");
    r[0].clone()
}

/// A study with fixed times and errors, so that its drawing does not depend on the machine:
/// linear errors fall as h², quadratic as h⁴, each rung taking twice the time of the last.
fn synthetic_study() -> Study {
    let rung =
        |order, elements: usize, ms: u64, fz: f64, k: f64, observed, by_construction| RungResult {
            rung: Rung { order, elements },
            time: Duration::from_millis(ms),
            values: Ok(Values {
                response: -3.08,
                curvature: vec![],
                critical: None,
                unknowns: 11 * elements,
                elements,
            }),
            errors: [Some(fz), Some(k), None],
            observed,
            by_construction,
        };
    let rungs = vec![
        rung(Order::Linear, 32, 20, 5e-2, 5e-2, [None; 3], false),
        rung(
            Order::Linear,
            64,
            40,
            1.25e-2,
            2.5e-2,
            [Some(2.0), Some(1.0), None],
            false,
        ),
        rung(
            Order::Linear,
            128,
            80,
            3.125e-3,
            1.25e-2,
            [Some(2.0), Some(1.0), None],
            false,
        ),
        rung(Order::Quadratic, 16, 15, 1e-2, 6e-2, [None; 3], false),
        rung(
            Order::Quadratic,
            32,
            30,
            6.25e-4,
            1.5e-2,
            [Some(4.0), Some(2.0), None],
            false,
        ),
        rung(
            Order::Quadratic,
            64,
            60,
            3.9e-5,
            3.75e-3,
            [Some(4.0), Some(2.0), None],
            true,
        ),
    ];
    Study {
        name: "small".into(),
        description: "n = 2, displacement control 0 → 0.5 in 10 steps".into(),
        response_label: "Fz/(n Pcrit) at ε = 0.5".into(),
        reference: Reference::Richardson {
            order: Order::Quadratic,
            elements: [32, 64],
            exponents: [4.0, 2.0, 4.0],
            check: [None; 3],
        },
        reference_values: Values {
            response: -3.08,
            curvature: vec![],
            critical: None,
            unknowns: 0,
            elements: 0,
        },
        rungs,
        repeats: 1,
        uniform_curvature: false,
    }
}

#[test]
fn w_shows_the_work_precision_chart_and_asks_for_one_study() {
    let (mut app, _sim) = started(small_case(2));
    let r = precision_request(&app.handle_key(ch('w')));
    assert!(app.view.show_precision);
    match &r.job {
        Job::Precision(case) => {
            assert_eq!(case.geometry.helices, 2);
            assert_eq!(case.boundary, app.screen.boundary);
        }
        other => panic!("{other:?}"),
    }
    // the study runs beside the solver: stepping goes on
    assert!(!app.busy(), "a study does not make the explorer busy");
    assert!(matches!(
        only_request(&app.handle_key(ch('l'))).job,
        Job::Advance(_)
    ));
    // hiding and showing again asks for nothing new while the study is under way
    assert!(app.handle_key(ch('w')).is_empty());
    assert!(!app.view.show_precision);
    assert!(app.handle_key(ch('w')).is_empty());
    assert!(app.view.show_precision);
}

#[test]
fn study_answers_fill_the_chart_and_stale_ones_are_dropped() {
    let (mut app, _sim) = started(small_case(2));
    let r = precision_request(&app.handle_key(ch('w')));
    let started = app.message.clone();
    assert!(matches!(&started, Some(Message::Info(m)) if m.contains("its own thread")));
    app.on_worker_event(WorkerEvent::PrecisionProgress {
        generation: r.generation,
        seq: r.seq,
        done: 3,
        total: 9,
    });
    assert_eq!(app.precision, PrecisionView::Running { done: 3, total: 9 });
    assert_eq!(app.message, started, "said while the study runs");
    // an answer to an older request is of another problem
    app.on_worker_event(WorkerEvent::Precision {
        generation: r.generation,
        seq: r.seq - 1,
        study: Err("old".into()),
    });
    assert_eq!(app.precision, PrecisionView::Running { done: 3, total: 9 });
    app.on_worker_event(WorkerEvent::Precision {
        generation: r.generation,
        seq: r.seq,
        study: Ok(Box::new(synthetic_study())),
    });
    assert!(matches!(app.precision, PrecisionView::Ready(_)));
    assert!(!app.busy());
    assert_eq!(
        app.message, None,
        "the study has finished: no word of its start"
    );
    // new conditions make the study obsolete: a new one is asked for while shown
    let effects = app.handle_key(ch('p'));
    precision_request(&effects);
    assert_eq!(app.precision, PrecisionView::Running { done: 0, total: 0 });
    // and n too
    let effects = app.handle_key(ch('n'));
    let r = precision_request(&effects);
    match r.job {
        Job::Precision(case) => assert_eq!(case.geometry.helices, 4),
        other => panic!("{other:?}"),
    }
    // hidden, a change only forgets the study
    app.handle_key(ch('w'));
    assert!(precision_request_count(&app.handle_key(ch('p'))) == 0);
    assert_eq!(app.precision, PrecisionView::None);
}

fn precision_request_count(effects: &[Effect]) -> usize {
    requests(effects)
        .into_iter()
        .filter(|r| matches!(r.job, Job::Precision(_)))
        .count()
}

#[test]
fn the_precision_thread_answers_with_a_study_of_the_case() {
    let worker = Worker::spawn().expect("threads");
    let source = "name = \"short\"\n[loading]\ntarget = 0.05\nsteps = 1\n";
    let case = Case::parse(source, "short.toml", "short").expect("valid case");
    let mut app = App::new(case, std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    let effects = app.handle_key(ch('w'));
    for e in effects {
        if let Effect::Solve(r) = e {
            assert!(worker.send(r));
        }
    }
    let deadline = Instant::now() + Duration::from_secs(300);
    let mut progress = 0;
    while !matches!(
        app.precision,
        PrecisionView::Ready(_) | PrecisionView::Failed(_)
    ) {
        assert!(Instant::now() < deadline, "no study");
        if let Ok(ev) = worker.events.recv_timeout(Duration::from_millis(200)) {
            if matches!(ev, WorkerEvent::PrecisionProgress { .. }) {
                progress += 1;
            }
            app.on_worker_event(ev);
        }
    }
    let PrecisionView::Ready(study) = &app.precision else {
        panic!("{:?}", app.precision)
    };
    assert_eq!(progress, study.rungs.len(), "a progress report per mesh");
    assert_eq!(study.rungs.len(), 9);
    assert!(study.rungs.iter().all(|r| r.values.is_ok()));
    // drawn from a real study: both panels with their lines and the reference used
    app.message = None;
    let screen = text(&draw(&app, 80, 24));
    let panels: String = screen.lines().skip(11).take(8).collect();
    assert!(
        panels.contains("Fz error") && panels.contains("κ error"),
        "{screen}"
    );
    assert!(
        panels.contains("ref: Richardson quadratic 64/128"),
        "{screen}"
    );
    // the lines (braille) and the meshes' points (blocks)
    let points = panels.chars().filter(|&c| c == '█').count();
    assert!(points >= 9, "points drawn:\n{screen}");
    assert!(
        braille_cells(&panels) + points > 20,
        "lines drawn:\n{screen}"
    );
    worker.join();
}

#[test]
fn screen_work_precision_chart_80x24() {
    let (mut app, _sim) = started(small_case(2));
    let r = precision_request(&app.handle_key(ch('w')));
    let running = text(&draw(&app, 80, 24));
    assert!(
        running.contains("work-precision study: starting"),
        "{running}"
    );
    app.on_worker_event(WorkerEvent::Precision {
        generation: r.generation,
        seq: r.seq,
        study: Ok(Box::new(synthetic_study())),
    });
    app.message = None;
    let screen = text(&draw(&app, 80, 24));
    for want in [
        "work-precision",
        "Fz error",
        "κ error",
        "linear",
        "quadratic",
        "1e-2",
        "ref: Richardson quadratic 32/64",
    ] {
        assert!(screen.contains(want), "`{want}` missing:\n{screen}");
    }
    // the orders observed between the two finest meshes of each order (not the one that
    // defines the reference)
    assert!(
        screen.contains("linear 2.0") && screen.contains("quadratic 4.0"),
        "{screen}"
    );
    // the chart panels only: the views above belong to other snapshots
    let panels: String = screen
        .lines()
        .skip(10)
        .take(10)
        .map(|l| format!("{l}\n"))
        .collect();
    assert_snapshot("precision_80x24", &panels);
}

#[test]
fn the_mesh_chosen_for_an_accuracy_is_on_the_status_line() {
    let worker = Worker::spawn().expect("threads");
    let text_case =
        "name = \"acc\"\n[loading]\ntarget = 0.1\nsteps = 2\n[discretisation]\naccuracy = 1e-3\n";
    let case = Case::parse(text_case, "acc.toml", "acc").expect("valid case");
    let mut app = App::new(case, std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    let mesh = app
        .screen
        .mesh
        .clone()
        .expect("a mesh chosen for the accuracy");
    assert!(mesh.estimated_error <= 1e-3);
    assert_eq!(app.compression_ratio(), Some(0.0));
    let screen = text(&draw(&app, 80, 24));
    let want = format!(
        "mesh {} {}, err {:.0e}",
        mesh.elements,
        mesh.order.name(),
        mesh.estimated_error
    );
    assert!(screen.contains(&want), "`{want}` missing:\n{screen}");
    // the state on screen is of that mesh
    let nodes = app.screen.state.as_ref().unwrap().snapshot.rods[0]
        .nodes
        .len();
    assert_eq!(nodes, mesh.order.degree() * mesh.elements + 1);
    worker.join();
}

// ---- long solves, numbers on screen, recorded what-ifs, terminals ----

#[test]
fn c_cancels_the_solve_and_the_answer_keeps_the_last_state() {
    let (mut app, _sim) = started(small_case(1));
    assert!(
        app.handle_key(ch('c')).is_empty(),
        "nothing to cancel when idle"
    );
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("nothing to cancel")));
    app.handle_key(ch(' '));
    let r = only_request(&app.handle_key(ch('l')));
    assert_eq!(app.handle_key(ch('c')), vec![Effect::Cancel(r.seq)]);
    assert!(!app.requests.running, "cancelling stops continuous loading");
    let effects = app.on_worker_event(WorkerEvent::Failed {
        generation: r.generation,
        seq: r.seq,
        reason: "ε → 0.05000 cancelled after 0.3 s; the last converged state (ε = 0.00000) is kept"
            .into(),
        boundary: Some(BoundaryConditions::default()),
        interrupted: Some(spira::solver::interrupt::Interruption::Cancelled),
    });
    assert!(effects.is_empty());
    assert!(!app.busy() && app.requests.solving.is_none());
    assert!(matches!(&app.message, Some(Message::Info(m)) if m.contains("cancelled")));
    assert_eq!(
        app.compression_ratio(),
        Some(0.0),
        "last converged state stays"
    );
}

#[test]
fn the_worker_answers_cancelled_requests_without_solving_and_stops_at_its_budget() {
    // cancelled before it started: answered at once, no solve
    let worker = Worker::spawn().expect("thread");
    worker.cancel(5);
    assert!(worker.send(req(3, Job::Advance(0.1))));
    match worker
        .events
        .recv_timeout(Duration::from_secs(60))
        .expect("answer")
    {
        WorkerEvent::Failed {
            interrupted,
            reason,
            ..
        } => {
            assert_eq!(
                interrupted,
                Some(spira::solver::interrupt::Interruption::Cancelled)
            );
            assert!(reason.contains("cancelled"), "{reason}");
        }
        other => panic!("expected a cancelled answer, got {other:?}"),
    }
    worker.join();
    // a budget of zero stops every step at once, keeping the natural state
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(1), PathBuf::from("."));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    assert_eq!(app.compression_ratio(), Some(0.0));
    worker.set_budget(Duration::ZERO);
    let effects = app.handle_key(ch('l'));
    settle(&mut app, &worker, effects);
    match &app.message {
        Some(Message::Error(m)) => {
            assert!(m.contains("time budget"), "{m}");
            assert!(m.contains("ε → 0.05000"), "says what was asked: {m}");
        }
        other => panic!("expected the budget's message, got {other:?}"),
    }
    assert_eq!(app.compression_ratio(), Some(0.0));
    // and the natural state of a new simulation too: the one on screen stays
    let effects = app.handle_key(ch('n'));
    settle(&mut app, &worker, effects);
    match &app.message {
        Some(Message::Error(m)) => {
            assert!(m.contains("time budget"), "{m}");
            assert!(m.contains("natural state of n = 2"), "{m}");
            assert!(m.contains("previous simulation is kept"), "{m}");
        }
        other => panic!("expected the budget's message, got {other:?}"),
    }
    assert_eq!(
        (app.screen.helices, app.compression_ratio()),
        (1, Some(0.0))
    );
    worker.join();
}

#[test]
fn the_status_line_shows_elapsed_time_and_progress_of_a_solve() {
    let (mut app, _sim) = started(small_case(1));
    let r = only_request(&app.handle_key(ch('l')));
    under_way(&mut app, &r);
    let screen = text(&draw(&app, 160, 48));
    assert!(
        screen.contains("ε → 0.05000… 2.5 s · c cancels · at 0.03210 (7 steps)"),
        "{screen}"
    );
    assert_snapshot("progress_160x48", &screen);
}

fn critical_point() -> spira::results::CriticalPoint {
    spira::results::CriticalPoint {
        kind: spira::results::CriticalKind::Bifurcation,
        control: spira::model::loading::Control::Displacement,
        parameter: 0.05,
        compression_ratio: 0.05,
        load: [0.0, 0.0, -1.25],
        unstable_before: 0,
        unstable_after: 1,
        wavenumber: None,
        bloch_phase: None,
        multiplicity: 1,
        state: vec![],
        mode: vec![],
        assembly_mode: None,
        second_mode: None,
    }
}

#[test]
fn a_critical_point_crossed_is_announced_marked_and_listed() {
    let (mut app, mut sim) = started(small_case(2));
    let r = only_request(&app.handle_key(ch('l')));
    sim.advance_to(0.05).expect("converges");
    let mut state = solved(&sim, 1);
    state.critical = vec![critical_point()];
    app.on_worker_event(answer(&r, state));
    match &app.message {
        Some(Message::Info(m)) => {
            assert!(m.contains("bifurcation at ε = 0.05000"), "{m}");
            assert!(m.contains("0 → 1"), "{m}");
        }
        other => panic!("expected the announcement, got {other:?}"),
    }
    assert_eq!(app.screen.critical.len(), 1);
    let screen = text(&draw(&app, 80, 24));
    assert!(
        screen.contains("×critical 1 (x lists)"),
        "marked on the load plot:\n{screen}"
    );
    assert_snapshot("critical_announced_80x24", &screen);
    app.handle_key(ch('x'));
    let screen = text(&draw(&app, 80, 24));
    assert!(screen.contains("critical points"), "{screen}");
    assert!(screen.contains("bifurcation"), "{screen}");
    assert_snapshot("critical_list_80x24", &screen);
    // a restart forgets them
    app.handle_key(ch('r'));
    assert!(app.screen.critical.is_empty());
}

/// A neutral direction (a buckled isotropic rod turning about its axis) flips the count by
/// rounding and counts as stable: announced and listed as neutral with the count it keeps,
/// not as a change of the count.
#[test]
fn a_neutral_entry_is_announced_and_listed_as_neutral() {
    let (mut app, mut sim) = started(small_case(2));
    let r = only_request(&app.handle_key(ch('l')));
    sim.advance_to(0.05).expect("converges");
    let mut state = solved(&sim, 1);
    state.critical = vec![spira::results::CriticalPoint {
        kind: spira::results::CriticalKind::Neutral,
        ..critical_point()
    }];
    app.on_worker_event(answer(&r, state));
    match &app.message {
        Some(Message::Info(m)) => {
            assert!(m.contains("neutral at ε = 0.05000"), "{m}");
            assert!(m.contains("unstable directions 0, neutral"), "{m}");
            assert!(!m.contains("0 → 1"), "{m}");
        }
        other => panic!("expected the announcement, got {other:?}"),
    }
    app.handle_key(ch('x'));
    let screen = text(&draw(&app, 80, 24));
    let row = screen
        .lines()
        .find(|l| l.contains("neutral"))
        .unwrap_or_else(|| panic!("no neutral row:\n{screen}"));
    assert!(row.contains("0, neutral"), "{row}");
    assert!(!row.contains('→'), "{row}");
}

#[test]
fn the_readout_and_the_cursors_give_the_numbers() {
    let mut app = compressed_app();
    let screen = text(&draw(&app, 160, 48));
    for label in ["h 0.", "fz/nPc", "E ", "unstable", "λmin", "rod 1 tip F ("] {
        assert!(screen.contains(label), "readout has {label}:\n{screen}");
    }
    assert!(
        screen.contains("s/L 0.50 κ1"),
        "curvature cursor:\n{screen}"
    );
    for _ in 0..40 {
        app.handle_key(ch('.'));
    }
    assert_eq!(
        app.view.cursor,
        spira::tui::app::CURSOR_STEPS,
        "stops at s/L = 1"
    );
    app.handle_key(ch('<'));
    let screen = text(&draw(&app, 160, 48));
    assert!(screen.contains("s/L 1.00 κ1"), "{screen}");
    let k = app.view.path_cursor.expect("on the path");
    assert_eq!(k, app.screen.path.len() - 2);
    assert!(
        screen.contains(&format!("◆ step {} ε", app.screen.path[k].step)),
        "load-path cursor:\n{screen}"
    );
    assert_snapshot("cursors_160x48", &screen);
}

#[test]
fn v_gives_one_view_the_whole_left_area() {
    let mut app = compressed_app();
    app.handle_key(ch('v'));
    let screen = text(&draw(&app, 80, 24));
    assert!(
        screen.contains("X-Y") && !screen.contains("Z-Y"),
        "{screen}"
    );
    app.handle_key(ch('v'));
    let screen = text(&draw(&app, 80, 24));
    assert!(
        screen.contains("Z-Y") && !screen.contains("X-Y"),
        "{screen}"
    );
    assert_snapshot("single_view_zy_80x24", &screen);
    app.handle_key(ch('v'));
    app.handle_key(ch('v'));
    let screen = text(&draw(&app, 80, 24));
    assert!(
        screen.contains("X-Y") && screen.contains("Z-X"),
        "back to all"
    );
}

#[test]
fn no_color_legends_tell_the_curves_apart_by_their_marks() {
    let mut app = compressed_app();
    app.view.no_color = true;
    let screen = text(&draw(&app, 100, 30));
    for label in ["━κ1", "•κ2", "+Ω", "━fx", "•fy", "+fz"] {
        assert!(screen.contains(label), "legend {label}:\n{screen}");
    }
    assert_snapshot("no_color_100x30", &screen);
}

#[test]
fn keys_do_nothing_behind_the_too_small_screen() {
    let (mut app, _sim) = started(small_case(1));
    app.view.too_small = true;
    for c in ['l', 'n', 'b', ' ', 'e', '?'] {
        assert!(
            app.handle_key(ch(c)).is_empty(),
            "{c} acts behind the message"
        );
    }
    assert!(!app.view.show_help);
    assert_eq!(app.handle_key(ch('q')), vec![Effect::Quit]);
}

#[test]
fn a_saved_session_replays_to_the_explorers_csvs() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(2), PathBuf::from("."));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    // (one step back, not two: the tips freed at ε = 0.1 leave the pair on a branch that
    // folds back at ε = 0.085, where a second step back would end)
    for c in ['l', 'l', 't', 'l', 'h', '+', 'l'] {
        let effects = app.handle_key(ch(c));
        settle(&mut app, &worker, effects);
    }
    worker.join();
    assert!(app
        .screen
        .events
        .iter()
        .any(|e| e.what.contains("tip translation slide")));
    let dir = temp_dir("replay");
    app.out_dir = dir.join("explorer");
    let files = app.export();
    assert_eq!(files.len(), exported_files(&app), "{:?}", app.message);
    let load = std::fs::read_to_string(&files[1]).unwrap();
    assert!(load.contains("# event: from point 3"), "{load}");
    assert!(load.contains("tip fixed/clamped") && load.contains("tip slide/clamped"));
    let session = app.save_session().expect("saved");
    // the session file as written, read back and replayed headless
    assert_replays_exactly(&session, &files, &dir.join("replay"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn starting_over_during_a_solve_cancels_it() {
    let (mut app, _sim) = started(small_case(1));
    let step = only_request(&app.handle_key(ch('l')));
    let effects = app.handle_key(ch('r'));
    assert_eq!(effects[0], Effect::Cancel(step.seq), "{effects:?}");
    assert!(matches!(&only_request(&effects).job, Job::Start(_)));
}

// ---- branch switching, free motions, cancellable starts, partial steps ----

/// Sends `effects` to the solver thread, cancels included (what the event loop does).
fn send_all(worker: &Worker, effects: Vec<Effect>) {
    for e in effects {
        match e {
            Effect::Solve(r) => assert!(worker.send(r), "solver thread gone"),
            Effect::Cancel(through) => worker.cancel(through),
            _ => {}
        }
    }
}

/// Feeds the solver's answers to `app` until it is idle; `on_event` sees each one first.
fn settle_with(app: &mut App, worker: &Worker, mut on_event: impl FnMut(&mut App, &WorkerEvent)) {
    let deadline = Instant::now() + Duration::from_secs(300);
    while app.busy() {
        assert!(Instant::now() < deadline, "solver did not answer");
        if let Ok(ev) = worker.events.recv_timeout(Duration::from_millis(200)) {
            on_event(app, &ev);
            let effects = app.on_worker_event(ev);
            send_all(worker, effects);
        }
    }
}

#[test]
fn a_toggle_into_a_free_rigid_motion_is_refused_naming_it_and_undone() {
    // both ends sliding: a sideways translation of the whole assembly
    let (mut app, _sim) = started(small_case(8));
    let base = only_request(&app.handle_key(ch('b')));
    assert!(matches!(base.job, Job::SetBoundary(bc) if bc.base.translation == Translation::Slide));
    assert!(
        app.handle_key(ch('t')).is_empty(),
        "no solve for a refused toggle"
    );
    assert_eq!(
        app.screen.boundary.tip.translation,
        Translation::Fixed,
        "undone"
    );
    assert_eq!(app.screen.boundary.base.translation, Translation::Slide);
    // the message is the case reader's, for the same conditions in a file
    let file = Case::parse(
        "[geometry]\nhelices = 8\n[boundary]\nbase = { translation = \"slide\" }\ntip = { translation = \"slide\" }\n",
        "slide.toml",
        "slide",
    )
    .expect_err("the case reader refuses both ends sliding")
    .to_string();
    match &app.message {
        Some(Message::Error(m)) => {
            assert!(m.contains("translate sideways"), "{m}");
            assert!(m.contains("undone"), "{m}");
            let reader = "both ends slide: the assembly may translate sideways as a whole";
            assert!(m.contains(reader) && file.contains(reader), "{m}\n{file}");
        }
        other => panic!("expected the refusal, got {other:?}"),
    }
    assert!(
        !app.screen
            .events
            .iter()
            .any(|e| e.what.contains("tip translation")),
        "a refused toggle is no event of the session"
    );
    // one helix, both ends spherical hinges: it may turn about its chord
    let (mut app, _sim) = started(small_case(1));
    only_request(&app.handle_key(ch('B')));
    assert!(app.handle_key(ch('T')).is_empty());
    assert_eq!(
        app.screen.boundary.tip.rotation,
        Rotation::Clamped,
        "undone"
    );
    assert!(
        matches!(&app.message, Some(Message::Error(m)) if m.contains("turn about its chord") && m.contains("undone")),
        "{:?}",
        app.message
    );
    // the same hinges with the joints of 8 helices tying the rods: allowed
    let (mut app, _sim) = started(small_case(8));
    only_request(&app.handle_key(ch('B')));
    only_request(&app.handle_key(ch('T')));
    assert_eq!(app.screen.boundary.tip.rotation, Rotation::Free);
}

#[test]
fn a_raised_interrupt_stops_the_natural_state_solve() {
    let interrupt = spira::solver::interrupt::Interrupt::new();
    interrupt.raise();
    let e = Simulation::from_case_with(&small_case(2), Some(interrupt), None)
        .err()
        .expect("the natural state's solve is interrupted");
    assert_eq!(
        e.reason,
        spira::solver::continuation::StopReason::Interrupted(
            spira::solver::interrupt::Interruption::Cancelled
        )
    );
    // without one it converges
    assert!(Simulation::from_case_with(&small_case(2), None, None).is_ok());
}

#[test]
fn a_cancelled_natural_state_keeps_the_previous_simulation() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(1), PathBuf::from("."));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    let effects = app.handle_key(ch('l'));
    settle(&mut app, &worker, effects);
    assert_close(app.compression_ratio(), 0.05);
    let before = app.screen.path.clone();
    // n = 2 asked for, and cancelled before the solver takes it (the cancel reaches the
    // solver first, so the test does not depend on timing)
    let start = app.handle_key(ch('n'));
    assert!(matches!(&only_request(&start).job, Job::Start(c) if c.geometry.helices == 2));
    assert!(
        app.screen.state.is_none(),
        "the new simulation is being solved"
    );
    let cancel = app.handle_key(ch('c'));
    assert!(
        matches!(cancel.as_slice(), [Effect::Cancel(_)]),
        "{cancel:?}"
    );
    send_all(&worker, cancel);
    send_all(&worker, start);
    settle_with(&mut app, &worker, |_, _| {});
    assert_eq!(app.screen.helices, 1, "back to the previous n");
    assert_eq!(app.screen.path, before, "the previous path is back");
    assert_close(app.compression_ratio(), 0.05);
    match &app.message {
        Some(Message::Info(m)) => assert!(m.contains("cancelled"), "{m}"),
        other => panic!("expected the cancellation, got {other:?}"),
    }
    assert!(
        !app.screen.events.iter().any(|e| e.what.starts_with("n =")),
        "{:?}",
        app.screen.events
    );
    // the solver kept it too: the next step continues the previous path
    let effects = app.handle_key(ch('l'));
    settle(&mut app, &worker, effects);
    assert_close(app.compression_ratio(), 0.1);
    assert_eq!(app.screen.path.len(), 3);
    assert!(
        !matches!(
            app.script().actions.first(),
            Some(spira::session::script::Action::Start { helices: 2, .. })
        ),
        "the cancelled start is not in the session"
    );
    worker.join();
}

#[test]
fn a_large_new_simulation_shows_its_size_estimate_first() {
    let text = "name = \"big\"\n[geometry]\nhelices = 1\n[discretisation]\nelements = 6000\n";
    let case = Case::parse(text, "big.toml", "big").expect("valid case");
    let estimate = case.for_explorer().size_estimate();
    assert!(estimate.is_large(), "{estimate}");
    let mut app = App::new(case, PathBuf::from("."));
    app.start();
    match &app.message {
        Some(Message::Info(m)) => {
            assert!(m.contains(&format!("size estimate: {estimate}")), "{m}");
            assert!(m.contains("c cancels"), "{m}");
        }
        other => panic!("expected the estimate, got {other:?}"),
    }
    // a small one says nothing of its size
    let mut app = App::new(small_case(2), PathBuf::from("."));
    app.start();
    assert!(app.message.is_none(), "{:?}", app.message);
}

/// Two CSV texts agree: the same lines, every number within 1e-12 of the other, the
/// rest the same text.
fn assert_csv_equal(ours: &Path, theirs: &Path) {
    let (a, b) = (
        std::fs::read_to_string(ours).unwrap(),
        std::fs::read_to_string(theirs).unwrap(),
    );
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    assert_eq!(la.len(), lb.len(), "{} lines", ours.display());
    for (x, y) in la.iter().zip(&lb) {
        if x.starts_with('#') {
            assert_eq!(x, y, "{}", ours.display());
            continue;
        }
        let (fx, fy): (Vec<&str>, Vec<&str>) = (x.split(',').collect(), y.split(',').collect());
        assert_eq!(fx.len(), fy.len(), "{}: {x} / {y}", ours.display());
        for (u, v) in fx.iter().zip(&fy) {
            match (u.parse::<f64>(), v.parse::<f64>()) {
                (Ok(u), Ok(v)) => assert!(
                    (u - v).abs() <= 1e-12,
                    "{}: {u} against {v} in\n{x}\n{y}",
                    ours.display()
                ),
                _ => assert_eq!(u, v, "{}", ours.display()),
            }
        }
    }
}

/// `small_case(1)` with internal steps of at most 1e-4: a step of Δε = 0.05 takes 500.
fn slow_case() -> Case {
    let text = "name = \"slow\"\n[geometry]\nhelices = 1\n[discretisation]\nelements = 8\n[solver]\ninitial_step = 1e-4\nmax_step = 1e-4\n";
    Case::parse(text, "slow.toml", "slow").expect("valid case")
}

#[test]
fn a_step_cancelled_part_of_the_way_replays_to_the_same_state() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(slow_case(), PathBuf::from("."));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    let effects = app.handle_key(ch('l'));
    settle(&mut app, &worker, effects);
    // the next step is cancelled at its first progress report
    let effects = app.handle_key(ch('l'));
    send_all(&worker, effects);
    settle_with(&mut app, &worker, |app, ev| {
        if matches!(ev, WorkerEvent::Progress { .. }) && app.message.is_none() {
            let cancel = app.handle_key(ch('c'));
            send_all(&worker, cancel);
        }
    });
    let eps = app.compression_ratio().expect("a state");
    assert!(
        eps > 0.05 && eps < 0.1,
        "stopped part of the way: ε = {eps} ({:?})",
        app.message
    );
    // and the session goes on from there
    for c in ['l', 'h'] {
        let effects = app.handle_key(ch(c));
        settle(&mut app, &worker, effects);
    }
    worker.join();
    let script = app.script();
    assert!(
        script.actions.iter().any(|a| matches!(
            a,
            spira::session::script::Action::Advance { steps: Some(_), .. }
        )),
        "the part of the way is recorded: {script:?}"
    );
    let dir = temp_dir("partial");
    app.out_dir = dir.join("explorer");
    let files = app.export();
    assert_eq!(files.len(), exported_files(&app), "{:?}", app.message);
    let session = app.save_session().expect("saved");
    let script = spira::session::script::Session::read(&session).expect("readable");
    let replayed = spira::session::replay::replay_into(&script, &slow_case(), &dir.join("replay"))
        .expect("replays");
    assert_eq!(replayed.len(), files.len());
    for (ours, theirs) in files.iter().zip(&replayed) {
        assert_eq!(ours.file_name(), theirs.file_name());
        assert_csv_equal(ours, theirs);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two thesis helices, 8 elements per rod: a bifurcation at ε ≈ 0.349 (`spira run`).
fn pair_case(branch: &str, target: f64, steps: usize) -> Case {
    let text = format!(
        "name = \"two\"\n[geometry]\nhelices = 2\n[discretisation]\nelements = 8\n[loading]\ntarget = {target}\nsteps = {steps}\nbranch = \"{branch}\"\n"
    );
    Case::parse(&text, "two.toml", "two").expect("valid case")
}

#[test]
fn the_branch_switched_onto_from_the_list_is_spira_runs_switched_branch() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(pair_case("fundamental", 0.5, 10), PathBuf::from("."));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    for _ in 0..7 {
        let effects = app.handle_key(ch('l'));
        settle(&mut app, &worker, effects);
    }
    assert_close(app.compression_ratio(), 0.35);
    assert_eq!(
        app.screen.critical.len(),
        1,
        "one bifurcation crossed by ε = 0.35"
    );
    let fundamental = app.screen.path.last().unwrap().clone();
    // the key does nothing outside the list
    assert!(app.handle_key(key(KeyCode::Enter)).is_empty());
    app.handle_key(ch('x'));
    let screen = text(&draw(&app, 80, 24));
    assert!(screen.contains("▸  0  bifurcation"), "{screen}");
    assert!(screen.contains("switch onto its branch"), "{screen}");
    let effects = app.handle_key(key(KeyCode::Enter));
    let r = only_request(&effects);
    assert!(
        matches!(r.job, Job::Switch { index: 0, sign, parameter, part: None } if sign == 1.0 && (parameter - 0.35).abs() < 1e-12),
        "{:?}",
        r.job
    );
    settle(&mut app, &worker, effects);
    assert!(!app.view.show_critical, "the list closes");
    assert_close(app.compression_ratio(), 0.35);
    let switched = app.screen.path.last().unwrap().clone();
    // `spira run` of the same case with branch = "switch", to the same ε in the same steps
    let run = spira::run::run_path(
        &pair_case("switch", 0.35, 7).for_explorer(),
        &pair_case("switch", 0.35, 7).output_parameters(0.35, 7),
        |_, _| {},
    )
    .expect("runs");
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(run.switched_at, Some(0));
    let theirs = run.points.last().unwrap();
    for k in 0..3 {
        assert!(
            (switched.load[k] - theirs.load[k]).abs() < 1e-8,
            "load {k}: explorer {} against spira run {}",
            switched.load[k],
            theirs.load[k]
        );
    }
    // another branch than the fundamental one at the same ε
    let apart = (0..3)
        .map(|k| (switched.load[k] - fundamental.load[k]).abs())
        .fold(0.0, f64::max);
    assert!(apart > 1e-6, "the switched branch is another one: {apart}");
    assert!(app
        .screen
        .events
        .iter()
        .any(|e| e.what.contains("switch onto the branch")));
    // replayed by the session to the same CSVs
    let dir = temp_dir("switch");
    app.out_dir = dir.join("explorer");
    let files = app.export();
    assert_eq!(files.len(), exported_files(&app), "{:?}", app.message);
    let load = std::fs::read_to_string(&files[1]).unwrap();
    assert!(load.contains("# event: from point 8"), "{load}");
    let session = app.save_session().expect("saved");
    let script = spira::session::script::Session::read(&session).expect("readable");
    let replayed = spira::session::replay::replay_into(
        &script,
        &pair_case("fundamental", 0.5, 10),
        &dir.join("replay"),
    )
    .expect("replays");
    assert_eq!(replayed.len(), files.len());
    for (ours, theirs) in files.iter().zip(&replayed) {
        assert_eq!(ours.file_name(), theirs.file_name());
        assert_csv_equal(ours, theirs);
    }
    worker.join();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_help_lists_the_switch_key_from_the_key_table() {
    let mut app = App::new(small_case(1), PathBuf::from("."));
    app.handle_key(ch('?'));
    let screen = text(&draw(&app, 160, 48));
    assert!(
        screen.contains("in the x list: onto the chosen bifurcation's branch"),
        "{screen}"
    );
    assert_eq!(
        spira::tui::keys::action_for(KeyCode::Enter),
        Some(spira::tui::keys::Action::SwitchBranch)
    );
    assert_eq!(
        spira::tui::keys::action_for(KeyCode::Char('G')),
        Some(spira::tui::keys::Action::SwitchBranchOther)
    );
}

#[test]
fn the_readout_fits_80_columns_with_the_lowest_eigenvalue() {
    let app = compressed_app();
    for width in [80u16, 100, 160] {
        let screen = text(&draw(&app, width, 24.max(width / 3)));
        let line = screen
            .lines()
            .find(|l| l.contains("fz/nPc"))
            .unwrap_or_else(|| panic!("no readout at {width}:\n{screen}"));
        assert!(line.contains("λmin"), "{width} columns: {line}");
        assert!(line.contains("unstable"), "{width} columns: {line}");
    }
}

/// The model named on the status line is the one of the state on screen: a symmetric
/// pair's path that a branch switch moved onto the whole assembly is labelled `full`, not
/// what the case asks for.
#[test]
fn the_model_named_is_the_one_of_the_state_on_screen() {
    let case = small_case(8);
    let (mut app, sim) = started(case.clone());
    assert!(sim.solves_pair(), "n = 8 is solved as the pair by default");
    assert!(app.solves_pair());
    // the same case's state on the whole assembly, as a switch onto a mode of wavenumber
    // p ≠ 0 leaves it
    let mut full_case = case.clone();
    full_case.discretisation.symmetric = false;
    let full = Simulation::from_case(&full_case).expect("natural state");
    assert!(!full.solves_pair());
    let step = only_request(&app.handle_key(key(KeyCode::Right)));
    app.on_worker_event(answer(&step, solved(&full, 1)));
    assert!(!app.solves_pair());
}

/// A session of every kind of action, with an event, as the explorer saves it.
fn every_action_session() -> Script {
    let bc = BoundaryConditions::default();
    let mut slide = bc;
    slide.tip.translation = Translation::Slide;
    Script {
        version: spira::session::script::VERSION,
        case: Some(PathBuf::from("cases/thesis.toml")),
        set: Vec::new(),
        label: "thesis".into(),
        events: vec![SessionEvent {
            from_point: 2,
            parameter: 0.05,
            what: "tip translation slide".into(),
        }],
        actions: vec![
            ScriptAction::Start {
                helices: 2,
                boundary: bc,
                load: spira::model::loading::Component::Axial,
            },
            ScriptAction::Advance {
                parameter: 0.05,
                steps: None,
                step_length: None,
            },
            ScriptAction::Boundary { boundary: slide },
            ScriptAction::Advance {
                parameter: 0.1,
                steps: Some(3),
                step_length: Some(0.0025),
            },
            ScriptAction::Switch {
                index: 0,
                sign: -1.0,
                parameter: 0.15,
                steps: None,
                step_length: None,
            },
        ],
    }
}

/// A version-1 session file (no `version` key; the load parameter called `eps`), as the
/// explorer saved it before the format named the load parameter.
const VERSION_1_SESSION: &str = r#"# spira session: replay with `spira replay FILE --out DIR`
case = "cases/thesis.toml"
label = "thesis"

[[events]]
from_point = 2
eps = 0.05
what = "tip translation slide"

[[actions]]
do = "start"
helices = 2

[actions.boundary]
joints = true

[actions.boundary.base]
translation = "fixed"
rotation = "clamped"

[actions.boundary.tip]
translation = "fixed"
rotation = "clamped"

[[actions]]
do = "advance"
eps = 0.05

[[actions]]
do = "boundary"

[actions.boundary]
joints = true

[actions.boundary.base]
translation = "fixed"
rotation = "clamped"

[actions.boundary.tip]
translation = "slide"
rotation = "clamped"

[[actions]]
do = "advance"
eps = 0.1
steps = 3
step_length = 0.0025

[[actions]]
do = "switch"
index = 0
sign = -1.0
eps = 0.15
"#;

#[test]
fn a_version_1_session_file_is_still_read() {
    let read = Script::parse(VERSION_1_SESSION, Path::new("old-session.toml")).expect("reads");
    assert_eq!(
        read.version, 1,
        "a file without a version key is of version 1"
    );
    let mut want = every_action_session();
    want.version = 1;
    assert_eq!(read, want, "eps is read as the load parameter");
}

#[test]
fn a_version_2_session_round_trips() {
    let session = every_action_session();
    let text = session.to_toml().expect("writes");
    assert!(text.contains("\nversion = 2\n"), "{text}");
    assert!(text.contains("\nparameter = 0.15\n"), "{text}");
    assert!(!text.contains("\neps ="), "{text}");
    let dir = temp_dir("session-v2");
    let file = dir.join("thesis-session.toml");
    session.write(&file).expect("saved");
    assert_eq!(Script::read(&file).expect("reads"), session);
    let newer = text.replace("version = 2", "version = 3");
    assert!(
        Script::parse(&newer, &file).is_err(),
        "a version this spira does not know is refused"
    );
}

/// `L` steps the twist from the natural state: the load panel plots the torque against the
/// twist, the readout gives both, the torque is that of the state solved headless, and the
/// saved session replays to the same CSVs. A pressure on a straight rod is skipped with the
/// reason.
#[test]
fn l_steps_the_twist_and_the_screen_and_session_follow() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(small_case(2), PathBuf::from("."));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    let effects = app.handle_key(ch('L'));
    assert!(matches!(
        requests(&effects)[0].job,
        Job::Start(ref c) if c.loading.parameter == spira::model::loading::Component::Twist
    ));
    settle(&mut app, &worker, effects);
    assert_eq!(app.symbol(), "φ");
    for _ in 0..2 {
        let effects = app.handle_key(ch('l'));
        settle(&mut app, &worker, effects);
    }
    worker.join();
    let point = &app.screen.state.as_ref().expect("a state").point;
    let phi = point.support.twist;
    assert!((phi - 2.0 * app.user_step()).abs() < 1e-12, "φ = {phi}");
    // the same path headless
    let case = small_case(2)
        .with_stepped(spira::model::loading::Component::Twist)
        .unwrap();
    let mut sim = Simulation::from_case(&case).unwrap();
    sim.advance_to(phi).unwrap();
    let torque = sim.load_point(0).support.torque;
    assert!((point.support.torque - torque).abs() < 1e-9 * torque.abs());
    let screen = text(&draw(&app, 120, 40));
    assert!(screen.contains("twist T (N m)"), "{screen}");
    assert!(
        screen.contains("phi/rad") && screen.contains("T/N m"),
        "{screen}"
    );
    // saved and replayed
    let dir = temp_dir("twist-session");
    app.out_dir = dir.join("explorer");
    let files = app.export();
    let session = app.save_session().expect("saved");
    let text_of = std::fs::read_to_string(&session).unwrap();
    assert!(text_of.contains("load = \"twist\""), "{text_of}");
    assert_replays_exactly(&session, &files, &dir.join("replay"));
    let _ = std::fs::remove_dir_all(&dir);
    // a straight rod cannot be pressed: L goes from the twist on to the tilt
    let straight = Case::parse(
        "[geometry]\nhelices = 1\nradius = 0.0\nlength = 1.0\n[boundary]\ntip = { translation = \"slide\", rotation = \"clamped\" }\n[loading]\nparameter = \"twist\"\ntarget = 1.0\n[discretisation]\nelements = 8\n",
        "straight.toml",
        "straight",
    )
    .unwrap();
    let (mut app, _sim) = started(straight);
    let r = only_request(&app.handle_key(ch('L')));
    assert!(matches!(
        r.job,
        Job::Start(ref c) if c.loading.parameter == spira::model::loading::Component::Tilt
    ));
}

/// The `# event:` lines of a load table: (point, what).
fn event_lines(load: &str) -> Vec<(usize, String)> {
    load.lines()
        .filter_map(|l| l.strip_prefix("# event: from point "))
        .map(|rest| {
            let (point, tail) = rest.split_once(' ').expect("point then text");
            let what = tail.split_once("): ").expect("asked, then what").1;
            (point.parse().expect("a point number"), what.to_string())
        })
        .collect()
}

#[test]
fn the_exported_events_are_those_of_the_path_kept_in_point_order() {
    let worker = Worker::spawn().expect("thread");
    let dir = temp_dir("events");
    let mut app = App::new(pair_case("fundamental", 0.5, 10), dir.join("explorer"));
    let effects = app.start();
    settle(&mut app, &worker, effects);
    // a path that a reset discards, with a change of the tip on it
    for c in ['l', 'l', 'l', 't', 'l', 'l'] {
        let effects = app.handle_key(ch(c));
        settle(&mut app, &worker, effects);
    }
    assert_eq!(
        app.screen.path.len(),
        7,
        "five steps and the re-solve under the new tip"
    );
    let effects = app.handle_key(ch('r'));
    settle(&mut app, &worker, effects);
    // steps and step changes pressed faster than they are solved: each change is placed
    // at the first point solved after it
    let mut effects = Vec::new();
    for c in "lll-lllll+ll".chars() {
        effects.extend(app.handle_key(ch(c)));
    }
    settle(&mut app, &worker, effects);
    assert_eq!(app.screen.path.len(), 11);
    assert_close(app.compression_ratio(), 0.35);
    assert!(
        !app.screen.critical.is_empty(),
        "the bifurcation is crossed"
    );
    app.handle_key(ch('x'));
    let effects = app.handle_key(key(KeyCode::Enter));
    settle(&mut app, &worker, effects);
    let files = app.export();
    assert_eq!(files.len(), exported_files(&app), "{:?}", app.message);
    let load = std::fs::read_to_string(&files[1]).unwrap();
    let events = event_lines(&load);
    let points: Vec<usize> = events.iter().map(|(p, _)| *p).collect();
    assert_eq!(points, [0, 4, 9, 11], "{load}");
    assert_eq!(events[0].1, "reset");
    assert!(events[1].1.starts_with("step Δε = 0.02"), "{load}");
    assert!(events[2].1.starts_with("step Δε = 0.05"), "{load}");
    assert!(events[3].1.starts_with("switch onto the branch"), "{load}");
    let rows = load.lines().filter(|l| !l.starts_with('#')).skip(1).count();
    assert!(rows > 11, "the switch added points: {rows}");
    // the saved session holds the same events
    let session = app.save_session().expect("saved");
    let script = spira::session::script::Session::read(&session).expect("readable");
    assert_eq!(
        script.script.events,
        app.screen.session_events(),
        "the session's events"
    );
    worker.join();
    let _ = std::fs::remove_dir_all(&dir);
}

/// The n = 2 small case stepped to ε = 0.15, unstable from ε = 0.1 on past a bifurcation at
/// ε = 0.05, with the path cursor on the bifurcation's step.
fn unstable_app() -> App {
    let (mut app, mut sim) = started(small_case(2));
    for k in 1..=3 {
        let r = only_request(&app.handle_key(ch('l')));
        let Job::Advance(eps) = r.job else {
            panic!("expected Advance")
        };
        sim.advance_to(eps).expect("converges");
        let mut state = solved(&sim, k);
        state.point.stability = Some(spira::results::Stability {
            unstable_directions: usize::from(k >= 2),
            lowest_eigenvalue: Some(if k >= 2 { -1.0 } else { 1.0 }),
            lowest_wavenumber: None,
        });
        if k == 1 {
            state.critical = vec![critical_point()];
        }
        app.on_worker_event(answer(&r, state));
    }
    app
}

#[test]
fn no_color_marks_every_series_and_point_apart_at_80x24() {
    let mut app = unstable_app();
    app.view.no_color = true;
    let screen = text(&draw(&app, 80, 24));
    // the load panel's legend: one mark per series, none shared
    let legend = ["━fx", "•fy", "+fz", "░unstable", "█now", "×critical"];
    for label in legend {
        assert!(screen.contains(label), "legend {label}:\n{screen}");
    }
    let marks: std::collections::BTreeSet<char> = legend
        .iter()
        .map(|l| l.chars().next().unwrap())
        .chain(['◆'])
        .collect();
    assert_eq!(marks.len(), legend.len() + 1, "{marks:?}");
    // the path cursor on the bifurcation's step: its readout whole, the critical key in
    // what is left
    app.handle_key(ch('<'));
    app.handle_key(ch('<'));
    let screen = text(&draw(&app, 80, 24));
    let foot = screen
        .lines()
        .find(|l| l.starts_with('└') && l.contains('◆'))
        .expect("the cursor's readout");
    assert!(foot.contains("×critical 1"), "{screen}");
    assert!(foot.ends_with(" ┘"), "readout cut:\n{screen}");
    assert!(foot.contains("◆1 ε 0.0500"), "{screen}");
    // the marks drawn: the unstable stretch as a line, the critical point, now, the cursor
    let plot: String = screen
        .lines()
        .skip_while(|l| !l.contains("now"))
        .map(|l| l.split_once("││").map_or(l, |(_, right)| right))
        .collect::<Vec<_>>()
        .join("\n");
    for mark in ['░', '×', '█', '◆'] {
        assert!(plot.contains(mark), "{mark} drawn:\n{screen}");
    }
    assert!(
        plot.matches('░').count() >= 4,
        "the unstable stretch is a line, not isolated points:\n{screen}"
    );
    // the rods are all drawn alike: no colour scale
    assert!(!screen.contains("κ1 (1/m)"), "{screen}");
    assert_snapshot("no_color_unstable_80x24", &screen);
}

#[test]
fn the_cancel_key_stays_whole_on_the_status_line_at_80_columns() {
    let (mut app, _sim) = started(small_case(1));
    // continuous loading, a step under way with its progress reported
    let r = only_request(&app.handle_key(ch(' ')));
    under_way(&mut app, &r);
    let screen = text(&draw(&app, 80, 24));
    let line = screen
        .lines()
        .find(|l| l.starts_with("small │"))
        .expect("status line 1");
    assert!(line.contains("· c cancels"), "{screen}");
    assert!(line.contains("▶"), "running shown:\n{screen}");
    // at 160 columns the progress is there too
    let screen = text(&draw(&app, 160, 48));
    assert!(
        screen.contains("▶ running · ε → 0.05000… 2.5 s · c cancels · at 0.03210 (7 steps)"),
        "{screen}"
    );
}

// ---- stability on screen and in the exports ----

/// The number after `λmin ` on the readout line of `screen`.
fn readout_lowest(screen: &str) -> Option<f64> {
    let line = screen.lines().find(|l| l.contains("fz/nPc"))?;
    let after = line.split("λmin ").nth(1)?;
    after.split_whitespace().next()?.parse().ok()
}

/// Runs `app` continuously (space) to its case's target on the real solver thread.
fn run_to_target(app: &mut App, worker: &Worker) {
    let effects = app.start();
    settle(app, worker, effects);
    let effects = app.handle_key(ch(' '));
    settle(app, worker, effects);
    assert_close(app.compression_ratio(), app.target());
}

#[test]
fn the_readout_shows_the_lowest_eigenvalue_after_running_the_default_case() {
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(Case::default_case(), PathBuf::from("."));
    run_to_target(&mut app, &worker);
    worker.join();
    // every state of the path has its lowest eigenvalue, of the whole assembly's blocks
    for p in &app.screen.path {
        let st = p.stability.expect("stability tracked");
        assert!(st.lowest_eigenvalue.is_some_and(f64::is_finite), "{p:?}");
        assert!(st.lowest_wavenumber.is_some(), "a pair's blocks name p");
    }
    let last = app.screen.path.last().unwrap().stability.unwrap();
    let lowest = last.lowest_eigenvalue.unwrap();
    for (width, height) in [(80, 24), (120, 40)] {
        let screen = text(&draw(&app, width, height));
        let shown = readout_lowest(&screen)
            .unwrap_or_else(|| panic!("no λmin number at {width}x{height}:\n{screen}"));
        // three significant digits (fmt_num)
        assert!(
            (shown - lowest).abs() <= 5e-3 * lowest.abs(),
            "{shown} for {lowest}:\n{screen}"
        );
        let p = last.lowest_wavenumber.unwrap();
        assert!(screen.contains(&format!(" p{p}")), "{screen}");
    }
}

/// The n = 8 helices with sliding tips (fx = fy ≡ 0) run to their target: a bifurcation
/// with p = 1, the sway, on the way.
fn sliding_app(out: &Path) -> App {
    let (app, worker) = sliding_app_live(out);
    worker.join();
    app
}

/// [`sliding_app`] with its solver thread still running.
fn sliding_app_live(out: &Path) -> (App, Worker) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/hypotheses/n8-helix-slide-compression.toml");
    let case = Case::from_file(&file).expect("valid case");
    assert_eq!(case.boundary.tip.translation, Translation::Slide);
    let worker = Worker::spawn().expect("thread");
    let mut app = App::new(case, out.to_path_buf());
    run_to_target(&mut app, &worker);
    assert!(!app.screen.critical.is_empty(), "a critical point crossed");
    assert_eq!(app.screen.modes.len(), app.screen.critical.len());
    (app, worker)
}

/// The column `name` of a CSV table's data rows.
fn column(csv: &str, name: &str) -> Vec<String> {
    let mut rows = csv.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = rows.next().expect("a header").split(',').collect();
    let k = head.iter().position(|h| *h == name).expect("the column");
    rows.map(|r| r.split(',').nth(k).unwrap_or("").to_string())
        .collect()
}

#[test]
fn e_exports_the_critical_points_their_modes_and_a_filled_lowest_eigenvalue() {
    let dir = temp_dir("export-critical");
    let mut app = sliding_app(&dir);
    let files = app.export();
    assert_eq!(files.len(), exported_files(&app), "{:?}", app.message);
    let name = |f: &PathBuf| f.file_name().unwrap().to_string_lossy().into_owned();
    let read = |suffix: &str| {
        let f = files
            .iter()
            .find(|f| name(f).ends_with(suffix))
            .unwrap_or_else(|| panic!("no {suffix} in {files:?}"));
        std::fs::read_to_string(f).unwrap()
    };
    // λmin in every row of the load table, a number
    let load = read("-load.csv");
    let lowest = column(&load, "lowest_eig");
    assert_eq!(lowest.len(), app.screen.path.len());
    for (cell, p) in lowest.iter().zip(&app.screen.path) {
        let v: f64 = cell
            .parse()
            .unwrap_or_else(|_| panic!("{cell:?} in\n{load}"));
        let want = p.stability.unwrap().lowest_eigenvalue.unwrap();
        // written to 7 significant digits
        assert!((v - want).abs() <= 5e-7 * want.abs(), "{v} {want}");
    }
    // the critical points as `spira run` writes them, and a mode on the whole assembly
    let label = app.case_label();
    assert_eq!(
        read("-critical.csv"),
        output::critical_csv(&label, &app.screen.critical)
    );
    let mode = read("-mode-0.csv");
    let rods: std::collections::BTreeSet<String> = column(&mode, "rod").into_iter().collect();
    assert_eq!(rods.len(), 8, "the mode of all 8 rods");
    let largest = ["dx", "dy", "dz"]
        .iter()
        .flat_map(|c| column(&mode, c))
        .map(|v| v.parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    assert!(largest > 1e-6, "a mode that moves the rods: {largest}");
    match &app.message {
        Some(Message::Info(m)) => assert!(m.contains("-critical.csv") && m.contains("-mode-0")),
        other => panic!("expected the files named, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Cells of `terminal` drawn in `color` within rows `rows`.
fn cells_in(terminal: &Terminal<TestBackend>, color: Color, rows: std::ops::Range<u16>) -> usize {
    let buffer = terminal.backend().buffer();
    rows.flat_map(|y| (0..buffer.area.width).map(move |x| (x, y)))
        .filter(|&(x, y)| buffer[(x, y)].fg == color)
        .count()
}

#[test]
fn the_x_list_previews_the_chosen_mode_in_the_views_before_any_switch() {
    let dir = temp_dir("preview");
    let mut app = sliding_app(&dir);
    // the solve's wall time, fixed so that the drawing does not depend on it
    app.screen.state.as_mut().unwrap().time = Duration::from_millis(42);
    let before = draw(&app, 120, 40);
    let views_rows = 0..18;
    assert_eq!(cells_in(&before, Color::Magenta, views_rows.clone()), 0);
    let path = app.screen.path.len();
    let effects = app.handle_key(ch('x'));
    assert!(
        requests(&effects).is_empty(),
        "opening the list solves nothing"
    );
    let after = draw(&app, 120, 40);
    let screen = text(&after);
    assert!(screen.contains("mode of critical point 0"), "{screen}");
    assert!(
        cells_in(&after, Color::Magenta, views_rows.clone()) > 20,
        "the mode drawn over the state:\n{screen}"
    );
    // the list is below the views
    assert!(screen.lines().skip(18).any(|l| l.contains("bifurcation")));
    assert!(!screen.lines().take(18).any(|l| l.contains("bifurcation")));
    assert_eq!(app.screen.path.len(), path, "no switch yet");
    assert_snapshot("mode_preview_120x40", &screen);
    // without colour the preview has a mark of its own
    app.view.no_color = true;
    let plain = text(&draw(&app, 120, 40));
    let marks = plain
        .lines()
        .take(18)
        .map(|l| l.matches('∘').count())
        .sum::<usize>();
    assert!(marks > 10, "{plain}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn o_plots_the_lowest_eigenvalue_and_the_sway_that_tells_the_branches_apart() {
    let dir = temp_dir("series");
    let (mut app, worker) = sliding_app_live(&dir);
    // on the fundamental path the tip does not sway
    let radius = app.case().geometry.radius;
    assert!(app.screen.sway.iter().all(|w| w.abs() < 1e-6 * radius));
    app.handle_key(ch('o'));
    let screen = text(&draw(&app, 80, 24));
    assert!(screen.contains("λmin"), "{screen}");
    app.handle_key(ch('o'));
    let screen = text(&draw(&app, 120, 40));
    assert!(screen.contains("tip sway / helix radius"), "{screen}");
    // onto the sway branch: the tip moves off the axis
    app.handle_key(ch('x'));
    let effects = app.handle_key(key(KeyCode::Enter));
    settle(&mut app, &worker, effects);
    worker.join();
    let sway = *app.screen.sway.last().unwrap();
    assert!(sway > 0.1 * radius, "the sway branch sways: {sway}");
    let screen = text(&draw(&app, 120, 40));
    let plot: String = screen.lines().skip(19).take(15).collect();
    assert!(braille_cells(&plot) > 0 || plot.contains('•'), "{screen}");
    app.handle_key(ch('o'));
    assert!(text(&draw(&app, 120, 40)).contains("load Σf/(n Pcrit)"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn nothing_that_carries_meaning_is_cut_at_80x24() {
    let dir = temp_dir("uncut");
    let mut app = sliding_app(&dir);
    for _ in 0..3 {
        app.handle_key(ch('<'));
    }
    let k = app.view.path_cursor.expect("the path cursor");
    for series in ["Σf/nPc", "λmin", "sway/a"] {
        let screen = text(&draw(&app, 80, 24));
        let lines: Vec<&str> = screen.lines().collect();
        let title = lines.iter().find(|l| l.contains(series)).expect(series);
        assert!(title.contains("now"), "the legend whole: {title}");
        assert!(title.contains("unstable"), "the legend whole: {title}");
        // the feet of the two plots: the curvature cursor's readout, the load cursor's
        let foot = lines
            .iter()
            .find(|l| l.starts_with('└') && l.contains('◆'))
            .unwrap_or_else(|| panic!("the load cursor's readout:\n{screen}"));
        assert!(foot.contains("s/L 0.50"), "{foot}");
        let step = [format!("◆ step {k} ε 0."), format!("◆{k} ε 0.")];
        assert!(step.iter().any(|s| foot.contains(s.as_str())), "{foot}");
        assert!(foot.contains("×1 "), "the critical points' key: {foot}");
        let curvature = lines.iter().find(|l| l.contains("━κ1")).unwrap();
        assert!(curvature.contains("▄bulk"), "{curvature}");
        app.handle_key(ch('o'));
    }
    // a branch switch under way: its cancel key and how far it got, whole or not at all
    app.handle_key(ch('x'));
    let switch = only_request(&app.handle_key(key(KeyCode::Enter)));
    app.on_worker_event(WorkerEvent::Started {
        generation: switch.generation,
        seq: switch.seq,
        job: switch.job.describe("ε"),
    });
    app.on_worker_event(WorkerEvent::Progress {
        generation: switch.generation,
        seq: switch.seq,
        parameter: 0.15619,
        steps: 2,
        elapsed: Duration::from_millis(1300),
    });
    for width in [80, 120, 200] {
        let screen = text(&draw(&app, width, 40.min(width / 3)));
        let status = screen.lines().find(|l| l.contains("│ n 8 pair")).unwrap();
        assert!(status.trim_end().ends_with("c cancels") || status.contains("c cancels ·"));
        if status.contains("at 0.15") {
            assert!(status.contains("at 0.15619 (2 steps)"), "{status}");
        }
        if width >= 120 {
            let named = ["branch 0,", "branch of critical point 0,"];
            assert!(named.iter().any(|n| status.contains(n)), "{status}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---- critical curve of the scene ----

/// The one critical-curve request in `effects`, and its job.
fn curve_request(effects: &[Effect]) -> (Request, spira::session::worker::CurveJob) {
    let r: Vec<&Request> = requests(effects)
        .into_iter()
        .filter(|r| matches!(r.job, Job::Curve(_)))
        .collect();
    assert_eq!(r.len(), 1, "expected one curve request, got {effects:?}");
    match &r[0].job {
        Job::Curve(job) => (r[0].clone(), (**job).clone()),
        _ => unreachable!(),
    }
}

#[test]
fn u_asks_for_the_curve_of_the_scene_and_capital_u_changes_its_key() {
    use spira::case::DesignKey;
    use spira::simulation::curve::{CurveProgress, CurveRow};
    use spira::tui::app::CurveView;
    let mut app = App::new(small_case(2), PathBuf::from("."));
    app.start();
    let (first, job) = curve_request(&app.handle_key(ch('u')));
    assert!(app.view.show_curve && !app.view.show_precision);
    assert_eq!((job.key, job.case.geometry.helices), (DesignKey::Turns, 2));
    assert!(
        !app.busy() || app.requests.solving.is_none(),
        "the curve does not hold the solver"
    );
    // U: the next key, the curve in progress stopped, a new one asked for
    let effects = app.handle_key(ch('U'));
    assert!(
        effects.contains(&Effect::CancelCurve(first.seq)),
        "{effects:?}"
    );
    let (second, job) = curve_request(&effects);
    assert_eq!(job.key, DesignKey::Radius);
    // a row of the stopped curve is not drawn; one of the new curve is
    let row = CurveRow {
        value: 0.06,
        parameter: 0.3,
        eps: 0.3,
        fz: -100.0,
        torque: 0.0,
        kind: spira::results::CriticalKind::Bifurcation,
        wavenumber: None,
        multiplicity: 1,
    };
    for (seq, expect) in [(first.seq, 0), (second.seq, 1)] {
        app.on_worker_event(WorkerEvent::CurveProgress {
            generation: 0,
            seq,
            progress: CurveProgress::Row {
                row,
                done: 1,
                total: 11,
            },
        });
        let CurveView::Running { rows, .. } = &app.curve else {
            panic!("{:?}", app.curve)
        };
        assert_eq!(rows.len(), expect);
    }
    // c stops it
    assert!(app
        .handle_key(ch('c'))
        .contains(&Effect::CancelCurve(second.seq)));
    // the work-precision chart takes the panel's place
    app.handle_key(ch('w'));
    assert!(app.view.show_precision && !app.view.show_curve);
}

/// The explorer's curve of Euler's clamped column against its length, on the curve thread:
/// every row arrives as it is found and is Euler's, |fz| L²/(4π² B) = 1 to 1e-6 (the
/// 48-element mesh's error is 4e-7); then a curve cancelled at once says so.
#[test]
fn the_curve_thread_draws_eulers_column_against_its_length_and_cancels() {
    use spira::case::DesignKey;
    use spira::tui::app::CurveView;
    let source = include_str!("../../cases/euler-clamped.toml");
    let case = Case::parse(source, "euler-clamped.toml", "euler-clamped").expect("valid case");
    let worker = Worker::spawn().expect("threads");
    let mut app = App::new(case, std::env::temp_dir());
    let start = app.start();
    settle(&mut app, &worker, start);
    let t0 = Instant::now();
    let (r, job) = curve_request(&app.handle_key(ch('u')));
    // a straight rod has no turns or radius: the curve goes to its length
    assert_eq!(job.key, DesignKey::Length);
    assert!(worker.send(r));
    let mut rows_heard = 0;
    let deadline = Instant::now() + Duration::from_secs(300);
    while matches!(app.curve, CurveView::Running { .. }) {
        assert!(Instant::now() < deadline, "no curve");
        if let Ok(ev) = worker.events.recv_timeout(Duration::from_millis(200)) {
            if let WorkerEvent::CurveProgress {
                progress: spira::simulation::curve::CurveProgress::Row { .. },
                ..
            } = ev
            {
                rows_heard += 1;
            }
            app.on_worker_event(ev);
        }
    }
    let CurveView::Ready(done) = &app.curve else {
        panic!("{:?}", app.curve)
    };
    eprintln!("curve of 11 rows in {:.2} s", t0.elapsed().as_secs_f64());
    assert!(!done.cancelled && done.stopped.is_empty(), "{done:?}");
    assert_eq!(done.rows.len(), 11);
    assert_eq!(rows_heard, 11, "a progress report per row");
    let (lo, hi) = (done.rows[0].value, done.rows[10].value);
    assert!(
        (lo - 0.9).abs() < 1e-12 && (hi - 1.1).abs() < 1e-12,
        "{lo} … {hi}"
    );
    for row in &done.rows {
        let euler = row.fz.abs() * row.value.powi(2) / (4.0 * std::f64::consts::PI.powi(2));
        assert!((euler - 1.0).abs() < 1e-6, "L = {}: {euler}", row.value);
    }
    app.message = None;
    let screen = text(&draw(&app, 80, 24));
    let panels: String = screen.lines().skip(9).take(10).collect();
    assert!(panels.contains("critical P/Pcrit"), "{screen}");
    assert!(panels.contains("11 points"), "{screen}");
    assert!(panels.contains("against length L (m), ±10 %"), "{screen}");
    assert!(
        panels
            .chars()
            .any(|c| ('\u{2801}'..='\u{28ff}').contains(&c)),
        "braille:\n{screen}"
    );
    // another key, cancelled at once: the curve stops and says so
    let effects = app.handle_key(ch('U'));
    let (r, job) = curve_request(&effects);
    assert_eq!(job.key, DesignKey::TorsionalStiffness);
    let seq = r.seq;
    assert!(worker.send(r));
    let effects = app.handle_key(ch('c'));
    assert!(effects.contains(&Effect::CancelCurve(seq)));
    worker.cancel_curve(seq);
    let deadline = Instant::now() + Duration::from_secs(60);
    while matches!(app.curve, CurveView::Running { .. }) {
        assert!(Instant::now() < deadline, "the cancel was not heard");
        if let Ok(ev) = worker.events.recv_timeout(Duration::from_millis(200)) {
            app.on_worker_event(ev);
        }
    }
    match &app.curve {
        CurveView::Ready(d) => assert!(d.cancelled && d.rows.len() < 11, "{d:?}"),
        CurveView::Failed(e) => assert!(e.starts_with("cancelled"), "{e}"),
        other => panic!("{other:?}"),
    }
}
