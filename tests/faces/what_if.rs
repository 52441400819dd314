//! What-ifs from the command line: `--set key=value` on `spira run`, `precision` and `tui`,
//! overriding a key of the case file, checked as the case reader checks the file, said in
//! the summary and recorded in the `#` lines of every table.

use super::cli::spira;
use std::path::PathBuf;

/// The shipped case with 8 helices.
fn thesis_n8() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cases/thesis-n8.toml")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn set_overrides_the_helices_solves_sixteen_rods_and_records_it() {
    let dir = tempfile::tempdir().expect("scratch folder");
    let case = thesis_n8();
    let out = spira(
        dir.path(),
        &[
            "run",
            case.to_str().unwrap(),
            "--set",
            "geometry.helices=16",
            "--set",
            "loading.target=0.02",
            "--steps",
            "1",
            "--out",
            "o",
        ],
    );
    let said = text(&out.stdout);
    assert!(out.status.success(), "{said}\n{}", text(&out.stderr));
    let set_line =
        "case keys set on the command line (--set): geometry.helices = 16, loading.target = 0.02";
    assert!(said.contains("(n = 16, "), "{said}");
    assert!(said.contains("0 -> 0.02 in 1 steps"), "{said}");
    assert!(said.lines().any(|l| l == set_line), "{said}");
    assert!(
        said.lines()
            .any(|l| l.starts_with("wrote 5 files to o: load.csv, reactions.csv")),
        "{said}"
    );
    for table in [
        "load.csv",
        "reactions.csv",
        "state.csv",
        "joints.csv",
        "bulk.csv",
    ] {
        let csv = std::fs::read_to_string(dir.path().join("o").join(table)).expect("table");
        let header: Vec<&str> = csv.lines().take_while(|l| l.starts_with('#')).collect();
        assert!(
            header.contains(&format!("# {set_line}").as_str()),
            "{table}: {header:?}"
        );
        assert!(
            header
                .iter()
                .any(|l| l.starts_with("# model: ") && l.contains("standing for all 16 rods")),
            "{table}: {header:?}"
        );
    }
}

#[test]
fn a_bad_set_is_refused_naming_the_key_and_nothing_is_written() {
    let dir = tempfile::tempdir().expect("scratch folder");
    let case = thesis_n8();
    let case = case.to_str().unwrap();
    for (command, set, said) in [
        (
            "run",
            "geometry.helices=3",
            "--set geometry.helices=3: expected 1 or an even number",
        ),
        (
            "run",
            "geometry.helix=16",
            "--set geometry.helix=16: unknown field `helix`",
        ),
        (
            "run",
            "loading.target=fast",
            "--set loading.target=\"fast\": ",
        ),
        (
            "run",
            "boundary.tip.translation=slid",
            "expected one of `fixed`, `slide`, `radial`",
        ),
        (
            "run",
            "geometry.helices.n=3",
            "`geometry.helices` is integer in the case, not a table",
        ),
        (
            "precision",
            "stiffness.b1=-1",
            "--set stiffness.b1=-1: expected",
        ),
        (
            "tui",
            "geometry.helices=3",
            "--set geometry.helices=3: expected",
        ),
    ] {
        let out = spira(dir.path(), &[command, case, "--set", set, "--out", "o"]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{command} --set {set}: {err}");
        assert!(err.contains(said), "{command} --set {set}: {err}");
        assert!(
            !dir.path().join("o").exists(),
            "{command} --set {set} wrote o/"
        );
    }
    // not a setting at all: a usage error naming the flag
    let out = spira(
        dir.path(),
        &["run", case, "--set", "geometry.helices", "--out", "o"],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--set <KEY=VALUE>") && err.contains("expected key=value"),
        "{err}"
    );
    assert!(!dir.path().join("o").exists());
}

#[test]
fn a_set_taken_from_the_file_alone_says_the_files_own_error() {
    let dir = tempfile::tempdir().expect("scratch folder");
    std::fs::write(dir.path().join("bad.toml"), "[geometry]\nhelices = 5\n").expect("case");
    let out = spira(
        dir.path(),
        &[
            "run",
            "bad.toml",
            "--set",
            "loading.target=0.1",
            "--out",
            "o",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("bad.toml:2: key `geometry.helices`"), "{err}");
    assert!(!dir.path().join("o").exists());
}

/// A session of the explorer started with `--set`: `set` holds the overrides, and the
/// replay applies them to the case file (a bad one refused as on the command line).
#[test]
fn a_replayed_session_applies_its_settings() {
    let dir = tempfile::tempdir().expect("scratch folder");
    let case = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cases/thesis-n2.toml");
    let session = |set: &str| {
        format!(
            "version = 2\ncase = {:?}\nset = [{set}]\nlabel = \"n2\"\n\n[[actions]]\ndo = \"start\"\nhelices = 2\nboundary = {{ base = {{ translation = \"fixed\", rotation = \"clamped\" }}, tip = {{ translation = \"fixed\", rotation = \"clamped\" }}, joints = true }}\n\n[[actions]]\ndo = \"advance\"\nparameter = 0.02\n",
            case.display().to_string()
        )
    };
    std::fs::write(dir.path().join("bad.toml"), session("\"stiffness.b1=-1\"")).expect("session");
    let out = spira(dir.path(), &["replay", "bad.toml", "--out", "o"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("--set stiffness.b1=-1: expected"), "{err}");
    assert!(!dir.path().join("o").exists());
    // a stiffer torsion (b3 = 4 for the file's 2): the same compression takes another load
    let fz = |set: &str, name: &str| -> f64 {
        std::fs::write(dir.path().join(name), session(set)).expect("session");
        let out = spira(
            dir.path(),
            &["replay", name, "--out", name.trim_end_matches(".toml")],
        );
        assert!(out.status.success(), "{}", text(&out.stderr));
        let folder = dir.path().join(name.trim_end_matches(".toml"));
        let load = std::fs::read_dir(&folder)
            .expect("replay folder")
            .map(|e| e.expect("entry").path())
            .find(|p| p.to_string_lossy().ends_with("-load.csv"))
            .expect("a load table");
        let csv = std::fs::read_to_string(load).expect("load table");
        let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
        let header: Vec<&str> = lines.next().expect("header").split(',').collect();
        let k = header.iter().position(|h| *h == "fz").expect("fz column");
        let last = lines.next_back().expect("a row");
        last.split(',')
            .nth(k)
            .expect("fz")
            .parse()
            .expect("a number")
    };
    let plain = fz("", "plain.toml");
    let stiff = fz("\"stiffness.b3=4\"", "stiff.toml");
    assert!(plain < 0.0, "{plain}");
    assert!(
        (stiff / plain - 1.0).abs() > 1e-3,
        "{stiff} against {plain}: the setting was not applied"
    );
}
