//! How a command ends on a signal (Ctrl-C, `kill`, a closed terminal): never while a file
//! or folder is being written.

use spira::solver::interrupt::Interrupt;

/// The signals that end a command: Ctrl-C, `kill` and a closed terminal.
const ENDING_SIGNALS: [i32; 3] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
];

/// Ends the process as `signal` would (status 128 + signal), once no file or folder is
/// being written: a write under way finishes first (it is bounded work), so the staging
/// folder of a run is never left behind and its target holds the old files or the whole
/// new set.
fn end_between_writes(signal: i32) -> ! {
    let _no_write = spira::output::files::hold_writes();
    std::process::exit(128 + signal)
}

/// For the commands that do not stop by themselves on a signal (`plot`, `precision`,
/// `replay`, `bench`): a signal ends them between writes ([`end_between_writes`]), with
/// the status a shell expects.
pub fn end_on_signal_between_writes() {
    if let Ok(mut signals) = signal_hook::iterator::Signals::new(ENDING_SIGNALS) {
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                end_between_writes(signal);
            }
        });
    }
}

/// For the commands that stop by themselves (`run`, `sweep`): the first signal says
/// `message` and raises the interrupt returned, the solves stop at their last converged
/// state and the command writes what it has; a second signal ends the process between
/// writes ([`end_between_writes`]).
pub fn stop_on_signal(message: &'static str) -> Interrupt {
    let interrupt = Interrupt::new();
    let raise = interrupt.clone();
    if let Ok(mut signals) = signal_hook::iterator::Signals::new(ENDING_SIGNALS) {
        std::thread::spawn(move || {
            let mut signals = signals.forever();
            if signals.next().is_some() {
                eprintln!("{message}");
                raise.raise();
            }
            if let Some(signal) = signals.next() {
                end_between_writes(signal);
            }
        });
    }
    interrupt
}
