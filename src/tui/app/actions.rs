//! The user's transitions: a key press, its action, and what each action asks of the
//! solver.

use super::explorer::{
    default_step, App, CurveView, Effect, Message, PrecisionView, CANCELLING, CONFIRM_DISCARD,
    HELICES, STEPS, STUDY_STARTED,
};
use super::state::CURSOR_STEPS;
use crate::case::DesignKey;
use crate::model::boundary::{BoundaryConditions, Rotation, Translation};
use crate::model::loading::Component;
use crate::session::export::SessionEvent;
use crate::session::worker::Job;
use crate::tui::keys::{self, Action};
use crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

impl App {
    /// Records a change of the session: it applies from the next request on, and is placed
    /// at the first point that request (or a later one) adds to the path; `own`: that
    /// request is the change itself, and if it fails the change is not recorded.
    pub(super) fn record(&mut self, what: String, own: bool) {
        let event = SessionEvent {
            from_point: self.screen.path.len(),
            parameter: self.screen.requested_parameter,
            what,
        };
        let from = self.requests.upcoming();
        self.screen.pending.push((from, own, event));
    }

    /// Asks for load parameter `parameter` if the geometry admits it.
    fn advance(&mut self, parameter: f64) -> Vec<Effect> {
        // round to 1e-12 so repeated steps land on the decimal values a user expects
        let parameter = (parameter * 1e12).round() / 1e12;
        if let Err(why) = self.case().check_target(parameter) {
            self.requests.running = false;
            self.message = Some(Message::Error(format!(
                "{} = {parameter:.5}: {why}",
                self.symbol()
            )));
            return vec![];
        }
        self.screen.requested_parameter = parameter;
        vec![self.request(Job::Advance(parameter))]
    }

    /// Cancels the solve in progress (and what is queued behind it); the last converged
    /// state stays.
    fn cancel(&mut self) -> Vec<Effect> {
        self.requests.running = false;
        let mut effects = Vec::new();
        if let CurveView::Running { cancelling, .. } = &mut self.curve {
            *cancelling = true;
            effects.push(Effect::CancelCurve(self.requests.curve_seq));
        }
        if !self.busy() {
            if !effects.is_empty() {
                self.message = Some(Message::Info(CANCELLING.into()));
                return effects;
            }
            self.message = Some(Message::Info(
                "nothing to cancel: the solver is idle".into(),
            ));
            return vec![];
        }
        self.message = Some(Message::Info(CANCELLING.into()));
        effects.push(Effect::Cancel(self.requests.last_sent));
        effects
    }

    /// Next request of continuous loading, if the target is not reached.
    pub(super) fn run_on(&mut self) -> Vec<Effect> {
        let target = self.target();
        let gap = target - self.screen.requested_parameter;
        if gap.abs() < 1e-12 {
            self.requests.running = false;
            self.message = Some(Message::Info(format!(
                "reached the target {} = {}; r starts over",
                self.symbol(),
                crate::case::num(target)
            )));
            return vec![];
        }
        let next = self.screen.requested_parameter + gap.signum() * self.user_step().min(gap.abs());
        self.advance(next)
    }

    fn set_boundary(&mut self, bc: BoundaryConditions, what: String) -> Vec<Effect> {
        // the case reader's check: supports that leave a rigid motion free are refused
        if let Some(motion) = self.case.with_helices(self.screen.helices).free_motion(&bc) {
            self.message = Some(Message::Error(format!(
                "{what} refused and undone: {}; the conditions stay {}",
                motion.message,
                self.screen.boundary.label()
            )));
            return vec![];
        }
        self.screen.boundary = bc;
        self.record(what.clone(), true);
        self.message = Some(Message::Info(format!(
            "{what}; the path continues from {} = {:.5} under the new conditions",
            self.symbol(),
            self.screen.requested_parameter
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
        if self.view.too_small {
            return match keys::action_for(key.code) {
                Some(Action::Quit) => vec![Effect::Quit],
                _ => vec![],
            };
        }
        if self.view.show_help {
            self.view.show_help = false;
            return match key.code {
                KeyCode::Char('q') => vec![Effect::Quit],
                _ => vec![],
            };
        }
        let action = keys::action_for(key.code);
        let confirm = self.confirm.take();
        if confirm.is_some() && action != confirm {
            self.message = Some(Message::Info("kept the path: nothing changed".into()));
            return vec![];
        }
        self.confirmed = confirm.is_some();
        if self.requests.solver_lost && !action.is_some_and(Action::works_without_solver) {
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
                self.view.show_help = true;
                vec![]
            }
            Action::StepForward => self.step_by(1.0),
            Action::StepBack => self.step_by(-1.0),
            Action::DoubleStep => self.scale_step(2.0),
            Action::HalveStep => self.scale_step(0.5),
            // in the critical-point list the rod keys choose a critical point
            Action::PreviousRod if self.view.show_critical => self.move_critical_cursor(-1),
            Action::NextRod if self.view.show_critical => self.move_critical_cursor(1),
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
            Action::NextLoad => self.change_load(action),
            Action::MoreHelices => self.change_helices(true, action),
            Action::FewerHelices => self.change_helices(false, action),
            Action::Cancel => self.cancel(),
            Action::CriticalPoints => {
                self.view.show_critical = !self.view.show_critical;
                if self.view.show_critical && self.screen.critical.is_empty() {
                    self.message = Some(Message::Info(
                        "no critical point crossed on this path yet".into(),
                    ));
                }
                vec![]
            }
            Action::CursorBack => {
                self.view.cursor = self.view.cursor.saturating_sub(1);
                vec![]
            }
            Action::CursorForward => {
                self.view.cursor = (self.view.cursor + 1).min(CURSOR_STEPS);
                vec![]
            }
            Action::PathCursorBack => self.move_path_cursor(-1),
            Action::PathCursorForward => self.move_path_cursor(1),
            Action::LoadSeries => {
                self.view.load_series = self.view.load_series.next();
                self.message = Some(Message::Info(format!(
                    "{} (o cycles)",
                    self.view.load_series.name()
                )));
                vec![]
            }
            Action::SingleView => {
                self.view.mode = self.view.mode.next();
                self.message = Some(Message::Info(format!(
                    "{} (v cycles)",
                    self.view.mode.name()
                )));
                vec![]
            }
            Action::SaveSession => vec![Effect::SaveSession],
            Action::Reset => self.reset(),
            Action::Export => vec![Effect::Export],
            Action::Precision => self.toggle_precision(),
            Action::CriticalCurve => self.toggle_curve(),
            Action::CurveKey => self.next_curve_key(),
        }
    }

    fn move_critical_cursor(&mut self, by: isize) -> Vec<Effect> {
        let n = self.screen.critical.len();
        if n > 0 {
            self.view.critical_cursor =
                (self.view.critical_cursor as isize + by).clamp(0, n as isize - 1) as usize;
        }
        vec![]
    }

    /// Switches onto the branch of the bifurcation selected in the critical-point list, on
    /// the side `sign`, and follows it to the load parameter asked for (as `spira run`
    /// with `branch = "switch"` does at its first bifurcation); stops continuous loading.
    fn switch_branch(&mut self, sign: f64) -> Vec<Effect> {
        use crate::results::CriticalKind;
        if !self.view.show_critical {
            self.message = Some(Message::Info(
                "x lists the critical points; choose one with ↑↓ and switch onto its branch there"
                    .into(),
            ));
            return vec![];
        }
        let Some(c) = self.screen.critical.get(self.view.critical_cursor) else {
            self.message = Some(Message::Info(
                "no critical point crossed on this path yet".into(),
            ));
            return vec![];
        };
        if c.kind != CriticalKind::Bifurcation {
            self.message = Some(Message::Error(format!(
                "critical point {} is a {}, not a bifurcation: there is no other branch to switch onto",
                self.view.critical_cursor,
                c.kind.name()
            )));
            return vec![];
        }
        let (index, at) = (self.view.critical_cursor, c.compression_ratio);
        let (symbol, parameter) = (self.symbol(), self.screen.requested_parameter);
        self.requests.running = false;
        self.view.show_critical = false;
        self.record(
            format!(
                "switch onto the branch of critical point {index} (ε = {at:.5}, side {sign:+})"
            ),
            true,
        );
        self.message = Some(Message::Info(format!(
            "switching onto the branch of critical point {index} at ε = {at:.5} (side {sign:+}), then along it to {symbol} = {parameter:.5}"
        )));
        let effect = self.request(Job::Switch {
            index,
            sign,
            parameter,
            part: None,
        });
        if let Effect::Solve(r) = &effect {
            self.requests.switch_seq = Some(r.seq);
        }
        let mut effects = vec![effect];
        effects.extend(self.precision_obsolete());
        effects
    }

    /// One user step forward (`sign` 1) or back (−1); stops continuous loading.
    fn step_by(&mut self, sign: f64) -> Vec<Effect> {
        self.requests.running = false;
        let (from, target) = (self.screen.requested_parameter, self.target());
        let mut next = from + sign * self.user_step();
        // a step forward towards the target stops there; one beyond it is refused
        if target > 0.0 && sign > 0.0 {
            if from >= target - 1e-12 {
                self.message = Some(Message::Info(format!(
                    "at the target {} = {}; ← steps back, r starts over",
                    self.symbol(),
                    crate::case::num(target)
                )));
                return vec![];
            }
            next = next.min(target);
        }
        self.advance(next)
    }

    /// Moves the load-path cursor by `by` points (from the current point when it is off).
    fn move_path_cursor(&mut self, by: isize) -> Vec<Effect> {
        if self.screen.path.is_empty() {
            return vec![];
        }
        let last = self.screen.path.len() - 1;
        let at = self.view.path_cursor.unwrap_or(last) as isize + by;
        let at = at.clamp(0, last as isize) as usize;
        self.view.path_cursor = (at != last || by < 0).then_some(at);
        vec![]
    }

    /// The user step times `factor`, within [`MIN_STEP`] and [`MAX_STEP`].
    fn scale_step(&mut self, factor: f64) -> Vec<Effect> {
        let next = if factor > 1.0 {
            STEPS
                .iter()
                .copied()
                .find(|&s| s > self.screen.step + 1e-12)
        } else {
            STEPS
                .iter()
                .rev()
                .copied()
                .find(|&s| s < self.screen.step - 1e-12)
        };
        let Some(step) = next else {
            self.message = Some(Message::Info(format!(
                "Δ{} = {} is the {} step ({})",
                self.symbol(),
                fmt_step(self.user_step()),
                if factor > 1.0 { "largest" } else { "smallest" },
                STEPS
                    .map(|s| fmt_step(s * self.case.parameter_unit()))
                    .join(" ")
            )));
            return vec![];
        };
        self.screen.step = step;
        let what = format!("step Δ{} = {}", self.symbol(), fmt_step(self.user_step()));
        self.message = Some(Message::Info(what.clone()));
        self.record(what, false);
        vec![]
    }

    /// Selects the rod `offset` places on, round the assembly.
    fn select_rod_by(&mut self, offset: isize) -> Vec<Effect> {
        let n = self.rods().max(1);
        let offset = offset.rem_euclid(n as isize) as usize;
        self.view.selected_rod = (self.view.selected_rod + offset) % n;
        vec![]
    }

    /// Starts continuous loading towards the target, or pauses it.
    fn run_or_pause(&mut self) -> Vec<Effect> {
        if self.requests.running {
            self.requests.running = false;
            self.message = Some(Message::Info("paused".into()));
            return vec![];
        }
        self.requests.running = true;
        self.message = Some(Message::Info(format!(
            "loading to {} = {} in steps of {}",
            self.symbol(),
            self.target(),
            fmt_step(self.user_step())
        )));
        if self.busy() {
            // the answer to the request in flight sends the next one
            vec![]
        } else {
            self.run_on()
        }
    }

    fn cycle_base_translation(&mut self) -> Vec<Effect> {
        let mut bc = self.screen.boundary;
        bc.base.translation = next_translation(bc.base.translation);
        let what = format!("base translation {}", translation_name(bc.base.translation));
        self.set_boundary(bc, what)
    }

    fn cycle_base_rotation(&mut self) -> Vec<Effect> {
        let mut bc = self.screen.boundary;
        bc.base.rotation = other_rotation(bc.base.rotation);
        let what = format!("base rotation {}", rotation_name(bc.base.rotation));
        self.set_boundary(bc, what)
    }

    fn cycle_tip_translation(&mut self) -> Vec<Effect> {
        let mut bc = self.screen.boundary;
        bc.tip.translation = next_translation(bc.tip.translation);
        let what = format!("tip translation {}", translation_name(bc.tip.translation));
        self.set_boundary(bc, what)
    }

    fn cycle_tip_rotation(&mut self) -> Vec<Effect> {
        let mut bc = self.screen.boundary;
        bc.tip.rotation = other_rotation(bc.tip.rotation);
        let what = format!("tip rotation {}", rotation_name(bc.tip.rotation));
        self.set_boundary(bc, what)
    }

    fn toggle_joints(&mut self) -> Vec<Effect> {
        let mut bc = self.screen.boundary;
        let from = self.refused_joints.take().unwrap_or(bc.joints);
        bc.joints = from.next(self.case.joint_springs());
        let what = format!("joints {}", bc.joints.name());
        self.set_boundary(bc, what)
    }

    /// The next larger (`up`) or smaller number of helices of [`HELICES`], from `λ = 0`.
    fn change_helices(&mut self, up: bool, key: Action) -> Vec<Effect> {
        let Some(n) = next_helices(self.screen.helices, up) else {
            self.message = Some(Message::Info(format!(
                "n = {} is the {} ({})",
                self.screen.helices,
                if up { "largest" } else { "smallest" },
                HELICES.map(|n| n.to_string()).join(" ")
            )));
            return vec![];
        };
        if self.screen.path.len() > CONFIRM_DISCARD && !std::mem::take(&mut self.confirmed) {
            self.confirm = Some(key);
            self.message = Some(Message::Info(format!(
                "n = {n} starts over and discards the path of {} points: press {} again to confirm, any other key keeps it",
                self.screen.path.len(),
                if up { "n" } else { "N" }
            )));
            return vec![];
        }
        self.confirm = None;
        let previous = self.keep();
        self.screen.helices = n;
        self.message = Some(Message::Info(format!(
            "n = {}: starting over from {} = 0",
            self.screen.helices,
            self.symbol()
        )));
        self.restart_from(previous, format!("n = {n}, start over"))
    }

    /// The next load component of [`Component::ALL`] that the supports can carry, stepped
    /// from `λ = 0` (the others held as the case holds them).
    fn change_load(&mut self, key: Action) -> Vec<Effect> {
        let now = self.case.loading.parameter;
        let at = Component::ALL.iter().position(|&c| c == now).unwrap_or(0);
        let mut refused = Vec::new();
        let mut next = None;
        for k in 1..Component::ALL.len() {
            let c = Component::ALL[(at + k) % Component::ALL.len()];
            match self.case.with_stepped(c) {
                Ok(case) => {
                    next = Some(case);
                    break;
                }
                Err(why) => refused.push(format!("{}: {why}", c.name())),
            }
        }
        let Some(case) = next else {
            self.message = Some(Message::Info(format!(
                "no other load on this scene ({})",
                refused.join("; ")
            )));
            return vec![];
        };
        let name = case.loading.parameter.name();
        if self.screen.path.len() > CONFIRM_DISCARD && !std::mem::take(&mut self.confirmed) {
            self.confirm = Some(key);
            self.message = Some(Message::Info(format!(
                "stepping the {name} starts over and discards the path of {} points: press L again to confirm, any other key keeps it",
                self.screen.path.len()
            )));
            return vec![];
        }
        self.confirm = None;
        let previous = self.keep();
        self.case = case;
        self.screen.step = default_step(&self.case);
        self.message = Some(Message::Info(format!(
            "stepping the {name} ({} = 0 → {} {}): starting over",
            self.symbol(),
            crate::case::num(self.target()),
            self.load_parameter().unit()
        )));
        self.restart_from(previous, format!("load {name}, start over"))
    }

    /// Back to `λ = 0` under the case's conditions and step.
    fn reset(&mut self) -> Vec<Effect> {
        let previous = self.keep();
        self.screen.boundary = self.case.boundary;
        self.screen.step = default_step(&self.case);
        self.message = Some(Message::Info(format!(
            "reset: {} = 0 under the case's boundary conditions",
            self.symbol()
        )));
        self.restart_from(previous, "reset".into())
    }

    /// Shows or hides the critical curve of the scene (in place of the work-precision
    /// chart); the first time, asks for the curve.
    fn toggle_curve(&mut self) -> Vec<Effect> {
        self.view.show_curve = !self.view.show_curve;
        if !self.view.curve_key.applies(&self.scene().geometry) {
            self.view.curve_key = self.next_applying_key();
        }
        self.view.show_precision &= !self.view.show_curve;
        if self.view.show_curve && self.curve == CurveView::None {
            self.message = Some(Message::Info(format!(
                "critical curve of the scene in {} started on its own thread; c cancels, U changes the key",
                self.view.curve_key.key()
            )));
            vec![self.request_curve()]
        } else {
            vec![]
        }
    }

    /// The next design key of the critical curve; a new curve when the panel is shown.
    fn next_curve_key(&mut self) -> Vec<Effect> {
        self.view.curve_key = self.next_applying_key();
        self.message = Some(Message::Info(format!(
            "critical curve in {} (U cycles){}",
            self.view.curve_key.key(),
            if self.view.show_curve {
                ""
            } else {
                "; u shows it"
            }
        )));
        self.curve_obsolete()
    }

    /// The design key after the current one that the scene has (a straight rod has no
    /// turns or radius).
    fn next_applying_key(&self) -> DesignKey {
        let scene = self.scene();
        let mut key = self.view.curve_key.next();
        while !key.applies(&scene.geometry) && key != self.view.curve_key {
            key = key.next();
        }
        key
    }

    /// Shows or hides the work-precision chart; the first time, asks for the study.
    fn toggle_precision(&mut self) -> Vec<Effect> {
        self.view.show_precision = !self.view.show_precision;
        self.view.show_curve &= !self.view.show_precision;
        if self.view.show_precision && self.precision == PrecisionView::None {
            self.message = Some(Message::Info(STUDY_STARTED.into()));
            vec![self.request_precision()]
        } else {
            vec![]
        }
    }
}

/// A step in the load parameter with the digits it needs.
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
