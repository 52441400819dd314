//! The solver's answers: each moves the requests' bookkeeping on, and a converged state or
//! a failure changes what is on screen.

use super::explorer::{App, CurveView, Effect, Message, PrecisionView, CANCELLING, STUDY_STARTED};
use super::state::Progress;
use crate::model::boundary::BoundaryConditions;
use crate::model::loading::Component;
use crate::results::Snapshot;
use crate::session::worker::{CurveDone, Solved, WorkerEvent};
use crate::simulation::curve::CurveProgress;
use crate::solver::interrupt::Interruption;

impl App {
    /// Transition on an answer from the solver thread (answers of an older simulation are
    /// dropped).
    pub fn on_worker_event(&mut self, event: WorkerEvent) -> Vec<Effect> {
        // a curve is of the scene, not of one simulation: its sequence number says if it
        // is the one asked for last
        if let WorkerEvent::CurveProgress { seq, progress, .. } = event {
            self.on_curve_progress(seq, progress);
            return vec![];
        }
        if let WorkerEvent::Curve { seq, outcome, .. } = event {
            self.on_curve(seq, outcome);
            return vec![];
        }
        if event.generation() != self.screen.generation {
            return vec![];
        }
        match event {
            WorkerEvent::Started { seq, job, .. } => {
                self.requests.started(seq, job);
                self.replay.started(seq);
                vec![]
            }
            WorkerEvent::Stopped {
                seq,
                steps,
                step_length,
                ..
            } => {
                // the session records the part of the way the job got, for its replay
                self.replay.stopped(seq, steps, step_length);
                vec![]
            }
            WorkerEvent::Progress {
                seq,
                parameter,
                steps,
                elapsed,
                ..
            } => {
                if seq > self.requests.last_done {
                    self.requests.progress = Some(Progress {
                        parameter,
                        steps,
                        elapsed,
                    });
                    self.requests.elapsed = Some(elapsed);
                }
                vec![]
            }
            WorkerEvent::Solved {
                seq, done, state, ..
            } => self.on_solved(seq, done, *state),
            WorkerEvent::Unchanged { seq, .. } => self.finish(seq),
            WorkerEvent::MeshChosen { choice, .. } => {
                self.screen.mesh = Some(*choice);
                vec![]
            }
            WorkerEvent::PrecisionProgress {
                seq, done, total, ..
            } => {
                if seq == self.requests.precision_seq {
                    self.precision = PrecisionView::Running { done, total };
                }
                vec![]
            }
            WorkerEvent::Precision { seq, study, .. } => {
                if seq == self.requests.precision_seq {
                    // the news that it started is old news now
                    if self.message == Some(Message::Info(STUDY_STARTED.into())) {
                        self.message = None;
                    }
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
            } => self.on_failed(seq, reason, boundary, interrupted),
            WorkerEvent::CurveProgress { .. } | WorkerEvent::Curve { .. } => vec![],
        }
    }

    /// A row of the critical curve asked for last, or how far its locating path got.
    fn on_curve_progress(&mut self, seq: u64, progress: CurveProgress) {
        if seq != self.requests.curve_seq {
            return;
        }
        if let CurveView::Running {
            rows,
            done,
            total,
            locating,
            ..
        } = &mut self.curve
        {
            match progress {
                CurveProgress::Locating { parameter } => *locating = Some(parameter),
                CurveProgress::Row {
                    row,
                    done: d,
                    total: t,
                } => {
                    rows.push(row);
                    (*done, *total, *locating) = (d, t, None);
                }
            }
        }
    }

    /// The critical curve asked for last is finished, stopped or cancelled, or has failed.
    fn on_curve(&mut self, seq: u64, outcome: Result<CurveDone, String>) {
        if seq != self.requests.curve_seq {
            return;
        }
        match &outcome {
            Ok(d) if d.cancelled => {
                self.message = Some(Message::Info(format!(
                    "critical curve cancelled: the {} rows found stay",
                    d.rows.len()
                )));
            }
            Ok(d) => {
                if let Some(why) = d.stopped.first() {
                    self.message = Some(Message::Info(format!(
                        "the critical curve stopped short: {why}"
                    )));
                }
            }
            Err(_) => {}
        }
        self.curve = match outcome {
            Ok(done) => CurveView::Ready(Box::new(done)),
            Err(e) => CurveView::Failed(e),
        };
    }

    /// A converged state of request `seq` (`done`: the job's last).
    fn on_solved(&mut self, seq: u64, done: bool, state: Solved) -> Vec<Effect> {
        self.refused_joints = None;
        if self.requests.start_seq == Some(seq) {
            self.requests.start_seq = None;
            self.previous = None;
        }
        if self.requests.switch_seq == Some(seq) && seq >= self.requests.last_sent {
            // the steps that follow go on from where the branch was reached
            self.screen.requested_parameter = state.point.parameter;
            if done {
                self.message = Some(Message::Info(format!(
                    "on the bifurcated branch at ε = {:.5}: fz/(n Pcrit) = {:.4}, {}; steps go on along it",
                    state.point.compression_ratio,
                    state.point.load[2],
                    state.point.stability.map_or("stability not computed".to_string(), |s| format!(
                        "unstable directions {}",
                        s.unstable_directions
                    ))
                )));
            }
        }
        self.screen.place_events(seq);
        self.screen.path.push(state.point.clone());
        self.screen.conditions.push(state.boundary);
        let offset = state.snapshot.tip_offset();
        let natural = *self.screen.natural_offset.get_or_insert(offset);
        self.screen
            .sway
            .push((offset[0] - natural[0]).hypot(offset[1] - natural[1]));
        for c in &state.critical {
            // where: ε and the axial load, or the stepped load's own parameter
            let at = if self.case.loading.parameter == Component::Axial {
                format!(
                    "ε = {:.5}, fz/(n Pcrit) = {:.4}",
                    c.compression_ratio, c.load[2]
                )
            } else {
                let p = self.load_parameter();
                format!("{} = {:.5} {}", p.symbol(), c.parameter, p.unit())
            };
            self.message = Some(Message::Info(format!(
                "critical point: {} at {at}, unstable directions {} (x lists them)",
                c.kind.name(),
                c.count_change("→")
            )));
        }
        self.screen.critical.extend(state.critical.iter().cloned());
        self.screen.modes.extend(state.modes.iter().cloned());
        if self.screen.natural_k1.is_none() {
            self.screen.natural_k1 = mean_k1(&state.snapshot);
        }
        self.boundary_settled(state.boundary, seq);
        self.view.selected_rod = self
            .view
            .selected_rod
            .min(state.snapshot.rods.len().saturating_sub(1));
        self.screen.state = Some(state);
        if done {
            self.finish(seq)
        } else {
            vec![]
        }
    }

    /// Request `seq` failed for `reason`; the conditions in force are `boundary` (when the
    /// solver has a simulation); `interrupted` when it was stopped from outside.
    fn on_failed(
        &mut self,
        seq: u64,
        reason: String,
        boundary: Option<BoundaryConditions>,
        interrupted: Option<Interruption>,
    ) -> Vec<Effect> {
        self.requests.running = false;
        self.screen.drop_failed_change(seq);
        if interrupted == Some(Interruption::Cancelled) {
            // a cancel the user asked for is news, not an error
            self.message = Some(Message::Info(reason));
        } else {
            self.message = Some(Message::Error(reason));
        }
        if self.requests.start_seq == Some(seq) {
            self.requests.start_seq = None;
            let previous = self.previous.take();
            // the solver keeps the simulation it had when a natural state is stopped from
            // outside: so does the screen
            if let (Some(p), Some(_)) = (previous, interrupted) {
                self.bring_back(p);
                let effects = self.precision_obsolete();
                self.finish_failed(seq);
                return effects;
            }
        }
        if let Some(bc) = boundary {
            let asked = self.screen.boundary.joints;
            self.refused_joints = (asked != bc.joints).then_some(asked);
            self.boundary_settled(bc, seq);
        }
        self.finish_failed(seq);
        vec![]
    }

    /// After the failure of request `seq`: idle if nothing newer is asked for.
    fn finish_failed(&mut self, seq: u64) {
        self.requests.last_done = self.requests.last_done.max(seq);
        if !self.busy() {
            self.requests.idle();
            // pending steps start again from the state on screen
            if let Some(parameter) = self.parameter() {
                self.screen.requested_parameter = parameter;
            }
        }
    }

    /// After the answer to request `seq`: the conditions in force are `bc`; if nothing newer
    /// was asked for, what is asked for is what is in force.
    fn boundary_settled(&mut self, bc: BoundaryConditions, seq: u64) {
        if seq >= self.requests.last_sent {
            self.screen.boundary = bc;
        }
    }

    /// After the answer to request `seq`: idle if nothing newer is asked for, and the next
    /// step of continuous loading.
    fn finish(&mut self, seq: u64) -> Vec<Effect> {
        self.requests.last_done = self.requests.last_done.max(seq);
        if self.busy() {
            return vec![];
        }
        if self.message == Some(Message::Info(CANCELLING.into())) {
            self.message = Some(Message::Info(
                "the solve had finished before the cancel reached it; its result is on screen"
                    .into(),
            ));
        }
        self.requests.idle();
        if self.requests.running {
            self.run_on()
        } else {
            vec![]
        }
    }

    /// The solver thread is gone (it never stops by itself while the app holds its channel).
    pub fn on_solver_lost(&mut self) {
        self.requests.solver_lost = true;
        self.requests.running = false;
        self.requests.solving = None;
        self.requests.last_done = self.requests.last_sent;
        self.message = Some(Message::Error(
            "the solver thread has stopped; export with e or quit with q".into(),
        ));
    }
}

/// Mean κ1 (1/m) over the nodes of `snapshot`.
fn mean_k1(snapshot: &Snapshot) -> Option<f64> {
    let k1: Vec<f64> = snapshot
        .rods
        .iter()
        .flat_map(|r| r.nodes.iter().map(|n| n.curvature[0]))
        .filter(|k| k.is_finite())
        .collect();
    (!k1.is_empty()).then(|| k1.iter().sum::<f64>() / k1.len() as f64)
}
