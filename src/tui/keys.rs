//! The explorer's keys: one table of which keys do what, read both by the key handling
//! ([`App::handle_key`](super::app::App::handle_key)) and by the help overlay
//! ([`ui::KEYS`](super::ui::KEYS)), so the two cannot drift apart.

use crossterm::event::KeyCode::{self, Char, Down, Enter, Esc, Left, Right, Up};

/// What a key asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    StepForward,
    StepBack,
    DoubleStep,
    HalveStep,
    RunPause,
    PreviousRod,
    NextRod,
    BaseTranslation,
    BaseRotation,
    TipTranslation,
    TipRotation,
    PinJoints,
    MoreHelices,
    FewerHelices,
    NextLoad,
    Reset,
    Export,
    Precision,
    CriticalCurve,
    CurveKey,
    Cancel,
    CriticalPoints,
    SwitchBranch,
    SwitchBranchOther,
    CursorBack,
    CursorForward,
    PathCursorBack,
    PathCursorForward,
    SingleView,
    LoadSeries,
    SaveSession,
    Help,
    Quit,
}

impl Action {
    /// The actions left once the solver thread has stopped.
    pub fn works_without_solver(self) -> bool {
        matches!(
            self,
            Action::Quit
                | Action::Help
                | Action::Export
                | Action::CriticalPoints
                | Action::CursorBack
                | Action::CursorForward
                | Action::PathCursorBack
                | Action::PathCursorForward
                | Action::SingleView
                | Action::LoadSeries
                | Action::SaveSession
        )
    }
}

/// One line of the help: the keys as it shows them, what each key does, and the text.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    pub label: &'static str,
    pub keys: &'static [(KeyCode, Action)],
    pub help: &'static str,
}

/// Every key of the explorer, in the order of the help (Ctrl-C quits too, and while the
/// help is shown any key closes it).
pub const BINDINGS: [Binding; 22] = {
    use Action::*;
    [
        Binding {
            label: "→l ←h",
            keys: &[
                (Right, StepForward),
                (Char('l'), StepForward),
                (Left, StepBack),
                (Char('h'), StepBack),
            ],
            help: "step compression forward / back by Δε (stops at the target)",
        },
        Binding {
            label: "+= -_",
            keys: &[
                (Char('+'), DoubleStep),
                (Char('='), DoubleStep),
                (Char('-'), HalveStep),
                (Char('_'), HalveStep),
            ],
            help: "larger / smaller Δε: 0.005 0.01 0.02 0.05 0.1",
        },
        Binding {
            label: "space",
            keys: &[(Char(' '), RunPause)],
            help: "run / pause continuous loading to the target",
        },
        Binding {
            label: "↑k ↓j",
            keys: &[
                (Up, PreviousRod),
                (Char('k'), PreviousRod),
                (Down, NextRod),
                (Char('j'), NextRod),
            ],
            help: "select the previous / next rod (in the x list: critical point)",
        },
        Binding {
            label: "b",
            keys: &[(Char('b'), BaseTranslation)],
            help: "base translation: fixed → slide → radial",
        },
        Binding {
            label: "B",
            keys: &[(Char('B'), BaseRotation)],
            help: "base rotation: clamped → free → pinned",
        },
        Binding {
            label: "t",
            keys: &[(Char('t'), TipTranslation)],
            help: "tip translation: fixed → slide → radial",
        },
        Binding {
            label: "T",
            keys: &[(Char('T'), TipRotation)],
            help: "tip rotation: clamped → free → pinned",
        },
        Binding {
            label: "p",
            keys: &[(Char('p'), PinJoints)],
            help: "joints: pin → welded → elastic → sliding → none",
        },
        Binding {
            label: "n N",
            keys: &[(Char('n'), MoreHelices), (Char('N'), FewerHelices)],
            help: "more / fewer helices (1 2 4 8 16), start over (asks first)",
        },
        Binding {
            label: "L",
            keys: &[(Char('L'), NextLoad)],
            help: "load stepped: axial → twist → pressure → tilt, start over (asks first)",
        },
        Binding {
            label: "r",
            keys: &[(Char('r'), Reset)],
            help: "reset: ε = 0, the case's conditions",
        },
        Binding {
            label: "e",
            keys: &[(Char('e'), Export)],
            help: "export state and load path to CSV",
        },
        Binding {
            label: "w u U",
            keys: &[
                (Char('w'), Precision),
                (Char('u'), CriticalCurve),
                (Char('U'), CurveKey),
            ],
            help: "work-precision chart / critical curve of the scene (on/off); U its key",
        },
        Binding {
            label: "c",
            keys: &[(Char('c'), Cancel)],
            help: "cancel the solve (keeps the last converged state) and the curve",
        },
        Binding {
            label: "x",
            keys: &[(Char('x'), CriticalPoints)],
            help: "critical points crossed so far (on/off)",
        },
        Binding {
            label: "⏎g G",
            keys: &[
                (Enter, SwitchBranch),
                (Char('g'), SwitchBranch),
                (Char('G'), SwitchBranchOther),
            ],
            help: "in the x list: onto the chosen bifurcation's branch (G: other side)",
        },
        Binding {
            label: ", . <>",
            keys: &[
                (Char(','), CursorBack),
                (Char('.'), CursorForward),
                (Char('<'), PathCursorBack),
                (Char('>'), PathCursorForward),
            ],
            help: "move the cursor of the curvature (, .) / of the load path (< >)",
        },
        Binding {
            label: "v o",
            keys: &[(Char('v'), SingleView), (Char('o'), LoadSeries)],
            help: "views: all → X-Y → Z-Y → Z-X alone / load panel: loads → λmin → sway",
        },
        Binding {
            label: "s",
            keys: &[(Char('s'), SaveSession)],
            help: "save the session (replay: spira replay FILE)",
        },
        Binding {
            label: "?",
            keys: &[(Char('?'), Help)],
            help: "this help (any key closes it)",
        },
        Binding {
            label: "q Esc",
            keys: &[(Char('q'), Quit), (Esc, Quit)],
            help: "quit (also Ctrl-C)",
        },
    ]
};

/// The action of key `code`, if it has one.
pub fn action_for(code: KeyCode) -> Option<Action> {
    BINDINGS
        .iter()
        .flat_map(|b| b.keys)
        .find(|(k, _)| *k == code)
        .map(|&(_, action)| action)
}
