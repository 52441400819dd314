//! The explorer's state and its transitions: key presses and solver answers in, solver
//! requests and other effects out. No terminal and no solver here, so every transition can
//! be tested headless.
//!
//! The state is a few small values, one per concern ([`state`]): what is on screen, the
//! view, the requests in flight and the replay log. The transitions are the user's
//! (`actions`) and the solver's answers (`answers`); `files` writes exports and saved
//! sessions.

mod actions;
mod answers;
mod explorer;
mod files;
pub mod state;

pub use actions::fmt_step;
pub use explorer::{
    App, CurveView, Effect, Message, PrecisionView, CONFIRM_DISCARD, CURVE_ROWS_EACH, CURVE_WIDTH,
    HELICES, MAX_STEP, MIN_STEP, STEPS,
};
pub use state::{LoadSeries, Progress, Replay, Requests, Screen, View, ViewMode, CURSOR_STEPS};
