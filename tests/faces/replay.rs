//! `spira replay` on bad sessions: the real binary on a tiny case. Every action is checked
//! before anything runs, by the case reader's limits and the explorer's rules; an action
//! that cannot be done is refused with exit 1, one paragraph naming the file, the line and
//! the action, and nothing is written.

use crate::common;

use std::path::PathBuf;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A scratch folder holding the tiny case, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(test: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("spira-replay-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch folder");
        std::fs::write(dir.join("tiny.toml"), common::TINY_CASE).expect("write case");
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The supports of the thesis, as the explorer writes them.
const THESIS_BOUNDARY: &str = "joints = true
base = { translation = \"fixed\", rotation = \"clamped\" }
tip = { translation = \"fixed\", rotation = \"clamped\" }
";

/// A session on the tiny case: one event saying `what`, a start of `helices` helices
/// under the thesis supports (at line 10), then `rest`.
fn session(what: &str, helices: &str, rest: &str) -> String {
    format!(
        "version = 2\ncase = \"tiny.toml\"\nlabel = \"tiny\"\n\n[[events]]\nfrom_point = 1\nparameter = 0.05\nwhat = {what}\n\n\
         [[actions]]\ndo = \"start\"\nhelices = {helices}\n\n[actions.boundary]\n{THESIS_BOUNDARY}{rest}"
    )
}

/// An advance to `parameter`, as the explorer writes it.
fn advance(parameter: &str) -> String {
    format!("\n[[actions]]\ndo = \"advance\"\nparameter = {parameter}\n")
}

/// `spira replay` of the session `text` (written as `s.toml`) into `out` inside the
/// scratch folder; the output and how long it took.
fn replay(dir: &Scratch, text: &str) -> (Output, Duration) {
    std::fs::write(dir.0.join("s.toml"), text).expect("write session");
    let t0 = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(["replay", "s.toml", "--out", "out"])
        .current_dir(&dir.0)
        .output()
        .expect("run the spira binary");
    (out, t0.elapsed())
}

/// A refusal: exit 1, one paragraph on stderr starting with `s.toml:LINE: action K`,
/// nothing written; returns the paragraph.
fn assert_refused(dir: &Scratch, out: &Output, line: usize, action: usize) -> String {
    let err = String::from_utf8_lossy(&out.stderr).trim().to_string();
    assert_eq!(out.status.code(), Some(1), "exit 1: {err}");
    let head = format!("spira: error: s.toml:{line}: action {action} (");
    assert!(err.starts_with(&head), "expected `{head}…`, found: {err}");
    assert!(!err.contains('\n'), "one paragraph: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        common::listing(&dir.0.join("out")).is_empty(),
        "nothing written: {err}"
    );
    err
}

#[test]
fn a_start_of_zero_or_three_or_1024_helices_is_refused_by_the_case_readers_limits() {
    let dir = Scratch::new("helices");
    for (helices, says) in [
        ("0", "expected a number of helices from 1 to 1024, found 0"),
        ("3", "expected 1 or an even number"),
        ("1024", "pin joints; expected at most 1000000"),
    ] {
        let (out, _) = replay(&dir, &session("\"x\"", helices, &advance("0.05")));
        let err = assert_refused(&dir, &out, 10, 1);
        assert!(
            err.contains(&format!("refused: helices = {helices}: ")),
            "{err}"
        );
        assert!(err.contains(says), "{err}");
    }
}

#[test]
fn a_load_parameter_the_case_does_not_admit_is_refused_before_anything_runs() {
    let dir = Scratch::new("parameter");
    for bad in ["nan", "inf", "-inf", "1e300", "1.0", "-5.0"] {
        // a good first step: the refusal comes before it runs
        let rest = advance("0.05") + &advance(bad);
        let (out, _) = replay(&dir, &session("\"x\"", "2", &rest));
        let err = assert_refused(&dir, &out, 23, 3);
        assert!(
            err.contains("(do = \"advance\") refused: parameter: expected a compression ratio"),
            "{bad}: {err}"
        );
        assert!(!err.contains("1000000000"), "numbers short: {err}");
    }
}

#[test]
fn a_switch_to_a_critical_point_not_found_is_refused() {
    let dir = Scratch::new("switch");
    let rest = advance("0.05")
        + "\n[[actions]]\ndo = \"switch\"\nindex = 99\nsign = 1.0\nparameter = 0.06\n";
    let (out, _) = replay(&dir, &session("\"x\"", "2", &rest));
    let err = assert_refused(&dir, &out, 23, 3);
    assert!(
        err.contains("(do = \"switch\") refused: index: the path has found no critical point to switch at, found index 99"),
        "{err}"
    );
}

#[test]
fn a_side_other_than_plus_or_minus_one_is_refused() {
    let dir = Scratch::new("sign");
    for sign in ["nan", "0.5", "0.0", "-2.0"] {
        let rest =
            format!("\n[[actions]]\ndo = \"switch\"\nindex = 0\nsign = {sign}\nparameter = 0.06\n");
        let (out, _) = replay(&dir, &session("\"x\"", "2", &rest));
        let err = assert_refused(&dir, &out, 19, 2);
        assert!(
            err.contains("sign: expected the side of the branch, 1 or -1"),
            "{sign}: {err}"
        );
    }
}

#[test]
fn supports_that_free_a_rigid_motion_are_refused_in_a_start_or_a_change() {
    let dir = Scratch::new("boundary");
    let free = "joints = true
base = { translation = \"slide\", rotation = \"free\" }
tip = { translation = \"slide\", rotation = \"free\" }
";
    let change = format!("\n[[actions]]\ndo = \"boundary\"\n\n[actions.boundary]\n{free}");
    let (out, _) = replay(&dir, &session("\"x\"", "2", &change));
    let err = assert_refused(&dir, &out, 19, 2);
    assert!(
        err.contains("(do = \"boundary\") refused: boundary: ")
            && err.contains("free rigid motion"),
        "{err}"
    );
    let start = session("\"x\"", "2", "").replace(THESIS_BOUNDARY, free);
    let (out, _) = replay(&dir, &start);
    let err = assert_refused(&dir, &out, 10, 1);
    assert!(err.contains("free rigid motion"), "{err}");
}

#[test]
fn an_event_text_with_line_breaks_stays_in_its_comment_line() {
    let dir = Scratch::new("event");
    let what = "\"tip slide\\n1,2,3\\r\\nstep,eps\"";
    let (out, _) = replay(&dir, &session(what, "2", &advance("0.05")));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files = common::listing(&dir.0.join("out"));
    let load = files
        .iter()
        .find(|f| f.ends_with("-load.csv"))
        .expect("a load table");
    let text = std::fs::read_to_string(dir.0.join("out").join(load)).unwrap();
    let first_data = text.lines().position(|l| !l.starts_with('#')).unwrap();
    let header = text.lines().nth(first_data).unwrap();
    assert!(header.starts_with("step,eps,"), "the header first: {text}");
    assert!(
        text.contains("# event: from point 1 (eps asked 0.050000): tip slide 1,2,3  step,eps\n"),
        "{text}"
    );
}

#[test]
fn a_malformed_session_is_said_once_naming_its_action_and_line() {
    let dir = Scratch::new("malformed");
    let rest = advance("0.05") + &advance("\"x\"");
    let (out, _) = replay(&dir, &session("\"x\"", "2", &rest));
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.matches("invalid type").count(), 1, "said once: {err}");
    assert!(
        err.starts_with("spira: error: s.toml:23: not a valid session: action 3: invalid type: string \"x\", expected a number"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "no caret diagram: {err}");
    // a key no action has
    let (out, _) = replay(
        &dir,
        &session("\"x\"", "2", &(advance("0.05") + "stpes = 3\n")),
    );
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        err.starts_with(
            "spira: error: s.toml:19: not a valid session: action 2: unknown field `stpes`"
        ),
        "{err}"
    );
}

#[test]
fn a_good_session_replays_every_action() {
    let dir = Scratch::new("good");
    let rest = advance("0.05") + &advance("0.1");
    let (out, _) = replay(&dir, &session("\"x\"", "2", &rest));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        said.starts_with("spira replay: 3 actions of s.toml; wrote "),
        "{said}"
    );
    let files = common::listing(&dir.0.join("out"));
    assert_eq!(
        files,
        [
            "tiny-step2-eps0.1000-load.csv",
            "tiny-step2-eps0.1000-reactions.csv",
            "tiny-step2-eps0.1000-state.csv"
        ]
    );
}
