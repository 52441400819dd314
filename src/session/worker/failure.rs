//! A failed job's message in the user's terms: what was asked for, where the path stopped,
//! why.

use crate::simulation::SolveError;
use crate::solver::continuation::StopReason;
use crate::solver::interrupt::Interruption;
use std::time::Duration;

/// What a failed job asked for, for its message.
#[derive(Clone, Copy, Debug)]
pub(super) enum Asked {
    /// The path continued to this load parameter.
    Parameter(f64),
    Boundary,
    /// A new simulation of `n` helices.
    Start(usize),
    /// The branch of critical point `index`, followed to this load parameter.
    Switch(usize, f64),
}

/// Why a solve stopped, if it was stopped from outside.
pub(super) fn interruption(e: &SolveError) -> Option<Interruption> {
    match e.reason {
        StopReason::Interrupted(why) => Some(why),
        _ => None,
    }
}

/// A failure in the user's terms: what was asked for, where the path stopped, why; `symbol`
/// is the load parameter's.
pub(super) fn describe_failure(
    e: &SolveError,
    asked: Asked,
    symbol: &str,
    elapsed: Duration,
) -> String {
    let what = match asked {
        Asked::Parameter(parameter) => format!("{symbol} → {parameter:.5}"),
        Asked::Boundary => "the new boundary conditions".to_string(),
        Asked::Start(n) => format!("the natural state of n = {n}"),
        Asked::Switch(index, parameter) => {
            format!(
                "the switch onto the branch of critical point {index} ({symbol} → {parameter:.5})"
            )
        }
    };
    let kept = match asked {
        Asked::Start(_) => "the previous simulation is kept".to_string(),
        _ => format!(
            "the last converged state (ε = {:.5}) is kept",
            e.compression_ratio
        ),
    };
    match (interruption(e), asked) {
        (Some(Interruption::Cancelled), _) => {
            format!(
                "{what} cancelled after {:.1} s; {kept}",
                elapsed.as_secs_f64()
            )
        }
        (Some(Interruption::Deadline), _) => format!(
            "{what} stopped: its time budget of {:.0} s ran out; {kept}",
            elapsed.as_secs_f64().round()
        ),
        // no equilibrium near the state, and the new conditions' own path from rest
        // stopped short of its load parameter
        (None, Asked::Boundary) if e.reached != e.target => format!(
            "the new boundary conditions were refused and undone: their own path from rest stops at {symbol} = {:.5}, short of {:.5} ({}); {kept}",
            e.reached, e.target, e.reason
        ),
        (None, Asked::Boundary) => {
            format!(
                "the new boundary conditions were refused and undone ({}); {kept}",
                e.reason
            )
        }
        (None, _) => format!("{what} failed: {}; {kept}", e.reason),
    }
}
