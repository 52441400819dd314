//! Long waits are cancellable and say so: a signal during the mesh choice of `spira run`
//! (an accuracy target on a long assembly) or during `spira precision` ends the command
//! part of the way, saying "interrupted" and that nothing was written (within a second,
//! measured by hand: the tests hold no clock); and numbers in the messages stay short.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// Thesis helices of 50 turns whose mesh is chosen for an accuracy of 1e-3: the pilot
/// solves alone take tens of seconds.
const LONG_ACCURACY: &str =
    "name = \"long\"\n[geometry]\nhelices = 8\nturns = 50\n[discretisation]\naccuracy = 1e-3\n";

/// Thesis helices of 20 turns: a work-precision study of tens of seconds.
const LONG_STUDY: &str = "name = \"study\"\n[geometry]\nhelices = 8\nturns = 20\n";

/// `spira ARGS` in `dir`, sent `signal` after `after`; its output.
#[cfg(unix)]
fn signalled(
    dir: &Path,
    args: &[&str],
    after: Duration,
    signal: rustix::process::Signal,
) -> Output {
    use rustix::process::{kill_process, Pid};
    let child = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spira");
    std::thread::sleep(after);
    let pid = Pid::from_raw(child.id() as i32).expect("pid");
    kill_process(pid, signal).expect("signal");
    child.wait_with_output().expect("wait")
}

#[cfg(unix)]
#[test]
fn a_signal_during_the_mesh_choice_ends_run_part_of_the_way_saying_so() {
    use rustix::process::Signal;
    let dir = tempfile::tempdir().expect("scratch");
    std::fs::write(dir.path().join("long.toml"), LONG_ACCURACY).unwrap();
    for signal in [Signal::TERM, Signal::INT] {
        let out = signalled(
            dir.path(),
            &["run", "long.toml", "--out", "out"],
            Duration::from_secs(3),
            signal,
        );
        let said = String::from_utf8_lossy(&out.stdout);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            said.contains("choosing the mesh for accuracy 1e-3"),
            "{said}"
        );
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("spira run: interrupted"), "{err}");
        assert!(
            err.contains("the mesh choice for accuracy 1e-3 was cancelled after")
                && err.ends_with("no mesh was chosen; nothing was solved or written\n"),
            "{err}"
        );
        // ended by the signal, mid-way (how soon is measured by hand: tests hold no clock)
        assert!(err.contains("with the pilot solves of 0 of 2"), "{err}");
        assert!(!dir.path().join("out").exists(), "nothing written");
    }
}

#[cfg(unix)]
#[test]
fn a_signal_during_precision_ends_it_part_of_the_way_saying_so() {
    use rustix::process::Signal;
    let dir = tempfile::tempdir().expect("scratch");
    std::fs::write(dir.path().join("study.toml"), LONG_STUDY).unwrap();
    let out = signalled(
        dir.path(),
        &["precision", "study.toml", "--out", "out"],
        Duration::from_secs(3),
        Signal::TERM,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("spira precision: interrupted"), "{err}");
    assert!(
        err.contains("the study was cancelled after ")
            && err.contains(" of 9 meshes")
            && err.contains("nothing was written"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists(), "nothing written");
}

#[test]
fn a_tiny_target_is_said_in_a_few_digits() {
    let dir = tempfile::tempdir().expect("scratch");
    let case = "name = \"t\"\n[geometry]\nhelices = 2\n[loading]\ntarget = 5e-324\nsteps = 1\n[discretisation]\nelements = 6\n";
    std::fs::write(dir.path().join("t.toml"), case).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(["run", "t.toml", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .expect("spira");
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("displacement control 0 -> 5e-324 in 1 steps"),
        "{said}"
    );
    let longest = said
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest <= 20, "a long number: {said}");
    let parsed = spira::case::Case::parse(case, "t.toml", "t").expect("valid");
    let subject = spira::study::Subject::Path(Box::new(parsed));
    assert_eq!(subject.response_label(), "Fz/(n Pcrit) at ε = 5e-324");
    assert!(
        subject.describe().contains("0 → 5e-324 in 1 steps"),
        "{}",
        subject.describe()
    );
}
