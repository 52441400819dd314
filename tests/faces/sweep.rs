//! Sweeps: shards, restarts, Slurm, validation before anything runs, failing
//! cases. Tiny cases (n = 1 and 2, 8 elements, 2 output steps) so that it runs in seconds.
//! No physics here, and no wall-clock assertions.

use spira::sweep::{
    merge_dirs, run_sweep, RunOptions, Shard, Sweep, SweepError, SweepTable, MARKER,
};
use std::collections::HashMap;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::Command;

const BASE: &str = r#"
[geometry]
helices = 1
turns = 1.5

[loading]
target = 0.2
steps = 2

[discretisation]
elements = 8
"#;

const SWEEP: &str = r#"
base = "base.toml"
combine = "product"

[axes]
"geometry.helices" = [1, 2]
"loading.target" = [0.1, 0.2, 0.3]
"#;

/// A scratch folder with the base case and `sweep` as `sweep.toml`.
fn scratch(sweep: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("scratch folder");
    std::fs::write(dir.path().join("base.toml"), BASE).expect("base");
    let file = dir.path().join("sweep.toml");
    std::fs::write(&file, sweep).expect("sweep");
    (dir, file)
}

fn opts(out: &Path, jobs: usize, shard: Shard) -> RunOptions {
    RunOptions {
        out: out.to_path_buf(),
        jobs: Some(jobs),
        shard,
        interrupt: None,
    }
}

fn run_all(sweep: &Sweep, out: &Path, jobs: usize, shard: Shard) -> spira::sweep::SweepReport {
    run_sweep(
        sweep,
        &opts(out, jobs, shard),
        |_| ControlFlow::Continue(()),
    )
    .expect("sweep")
}

/// The table without its wall-time column (the only one that differs between runs).
fn without_wall(t: &SweepTable) -> Vec<Vec<String>> {
    let wall = t.column("wall_s").expect("wall_s column");
    t.rows
        .iter()
        .map(|r| {
            r.iter()
                .enumerate()
                .filter(|(i, _)| *i != wall)
                .map(|(_, c)| c.clone())
                .collect()
        })
        .collect()
}

fn read_table(path: &Path) -> SweepTable {
    let text = std::fs::read_to_string(path).expect("table");
    SweepTable::from_csv(&text, &path.display().to_string()).expect("a sweep table")
}

fn spira() -> Command {
    Command::new(env!("CARGO_BIN_EXE_spira"))
}

/// Runs the sweep `file` into `out` on two jobs to its end (the same command a stopped
/// sweep is resumed with), and returns what it printed.
fn sweep_to_the_end(file: &Path, out: &Path) -> String {
    let output = spira()
        .args([
            "sweep",
            file.to_str().expect("path"),
            "--jobs",
            "2",
            "--out",
        ])
        .arg(out)
        .output()
        .expect("spira sweep");
    assert!(output.status.success(), "{output:?}");
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[test]
fn the_table_has_the_columns_of_the_issue_and_a_row_per_case() {
    let (dir, file) = scratch(SWEEP);
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    assert_eq!(sweep.cases.len(), 6);
    let out = dir.path().join("out");
    let report = run_all(&sweep, &out, 2, Shard::ALL);
    assert_eq!((report.ran, report.skipped, report.failed), (6, 0, 0));
    let t = read_table(&out.join("sweep.csv"));
    assert_eq!(t, report.table);
    for c in [
        "case",
        "status",
        "geometry.helices",
        "loading.target",
        "model",
        "elements",
        "fz",
        "energy",
        "critical_eps",
        "stable",
        "iterations",
        "wall_s",
        "reason",
    ] {
        assert!(t.column(c).is_some(), "column {c} in {:?}", t.headers);
    }
    assert_eq!(
        &t.headers[..4],
        ["case", "status", "geometry.helices", "loading.target"]
    );
    assert_eq!(t.rows.len(), 6);
    for (i, c) in sweep.cases.iter().enumerate() {
        assert_eq!(t.get(i, "case"), Some(c.id.as_str()));
        assert_eq!(t.get(i, "status"), Some("done"));
        let fz: f64 = t.get(i, "fz").expect("fz").parse().expect("a number");
        assert!(fz < 0.0, "compressed: fz = {fz}");
        assert!(out.join(&c.id).join("load.csv").is_file());
        assert!(out.join(&c.id).join(MARKER).is_file());
        assert!(out.join(&c.id).join("case.toml").is_file());
    }
    assert_eq!(t.get(0, "geometry.helices"), Some("1"));
    assert_eq!(t.get(5, "geometry.helices"), Some("2"));
    assert_eq!(t.get(5, "loading.target"), Some("0.3"));
    // nothing but the case folders and the table (no temporary folders left)
    let names: Vec<String> = std::fs::read_dir(&out)
        .expect("out")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 7, "{names:?}");
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
}

#[test]
fn the_union_of_the_shards_equals_the_unsharded_table() {
    let (dir, file) = scratch(SWEEP);
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    let whole = run_all(&sweep, &dir.path().join("whole"), 2, Shard::ALL).table;
    // shards in folders of their own, merged
    let mut folders = Vec::new();
    let mut rows = 0;
    for k in 1..=3 {
        let f = dir.path().join(format!("shard-{k}"));
        let r = run_all(&sweep, &f, 1, Shard::new(k, 3).expect("shard"));
        assert_eq!(r.total, 2);
        assert!(f.join(format!("sweep-shard-{k}-of-3.csv")).is_file());
        rows += r.table.rows.len();
        folders.push(f);
    }
    assert_eq!(rows, 6);
    let merged_dir = dir.path().join("merged");
    let (merged, path) = merge_dirs(&folders, &merged_dir).expect("merge");
    assert_eq!(path, merged_dir.join("sweep.csv"));
    assert_eq!(merged.headers, whole.headers);
    assert_eq!(without_wall(&merged), without_wall(&whole));
    assert_eq!(read_table(&path), merged);
    // shards sharing one folder, merged in place
    let shared = dir.path().join("shared");
    for k in 1..=3 {
        run_all(&sweep, &shared, 1, Shard::new(k, 3).expect("shard"));
    }
    let (in_place, _) = merge_dirs(std::slice::from_ref(&shared), &shared).expect("merge");
    assert_eq!(without_wall(&in_place), without_wall(&whole));
}

#[test]
fn a_stopped_sweep_resumes_without_recomputing_finished_cases() {
    let (dir, file) = scratch(SWEEP);
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    let reference = run_all(&sweep, &dir.path().join("reference"), 2, Shard::ALL).table;
    let out = dir.path().join("out");
    // stopped after two cases (one worker, so in order)
    let mut seen = 0;
    let first = run_sweep(&sweep, &opts(&out, 1, Shard::ALL), |_| {
        seen += 1;
        if seen == 2 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .expect("sweep");
    assert_eq!((first.ran, first.pending), (2, 4));
    assert_eq!(first.table.rows.len(), 2);
    // what a kill could leave: a temporary folder, and a case folder without its marker
    std::fs::create_dir(out.join(".spira-003-killed")).expect("temporary folder");
    let stale = out.join(&sweep.cases[3].id);
    std::fs::create_dir(&stale).expect("incomplete folder");
    std::fs::write(stale.join("load.csv"), "half").expect("half a file");
    let markers: Vec<String> = sweep.cases[..2]
        .iter()
        .map(|c| std::fs::read_to_string(out.join(&c.id).join(MARKER)).expect("marker"))
        .collect();
    let second = run_all(&sweep, &out, 2, Shard::ALL);
    assert_eq!((second.skipped, second.ran, second.pending), (2, 4, 0));
    // the finished cases were not recomputed: their rows (wall time included) are the old
    for (i, c) in sweep.cases[..2].iter().enumerate() {
        let now = std::fs::read_to_string(out.join(&c.id).join(MARKER)).expect("marker");
        assert_eq!(now, markers[i]);
        assert_eq!(second.table.rows[i], first.table.rows[i]);
    }
    assert_eq!(without_wall(&second.table), without_wall(&reference));
    let redone = std::fs::read_to_string(stale.join("load.csv")).expect("load.csv");
    assert!(redone.starts_with('#'), "the incomplete folder was redone");
    // a third run finds everything complete
    let third = run_all(&sweep, &out, 2, Shard::ALL);
    assert_eq!((third.skipped, third.ran), (6, 0));
    assert_eq!(third.table, second.table);
}

#[test]
fn a_killed_sweep_process_resumes_where_it_stopped() {
    let (dir, file) = scratch(SWEEP);
    let out = dir.path().join("out");
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    let mut child = spira()
        .args([
            "sweep",
            file.to_str().expect("path"),
            "--jobs",
            "1",
            "--out",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("spira sweep");
    let complete = |out: &Path| {
        sweep
            .cases
            .iter()
            .filter(|c| out.join(&c.id).join(MARKER).is_file())
            .count()
    };
    // killed (SIGKILL) as soon as the first case is complete
    let t = std::time::Instant::now();
    while complete(&out) == 0 && t.elapsed().as_secs() < 120 {
        if child.try_wait().expect("child").is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let _ = child.kill();
    child.wait().expect("killed");
    let before = complete(&out);
    assert!(before >= 1);
    let stdout = sweep_to_the_end(&file, &out);
    assert_eq!(
        stdout.matches("complete already, skipped").count(),
        before,
        "finished cases skipped, the others run:\n{stdout}"
    );
    assert_eq!(stdout.matches(" done in ").count(), 6 - before, "{stdout}");
    let reference = run_all(&sweep, &dir.path().join("reference"), 2, Shard::ALL).table;
    assert_eq!(
        without_wall(&read_table(&out.join("sweep.csv"))),
        without_wall(&reference)
    );
}

/// Sixteen cases of some tenths of a second each: a sweep that is still running when the
/// first case is done.
const SLOW_SWEEP: &str = r#"
combine = "product"
[case]
geometry.helices = 2
discretisation.elements = 24
loading.target = 0.3
loading.steps = 6
[axes]
"geometry.turns" = [2.0, 2.25, 2.5, 2.75, 3.0, 3.25, 3.5, 3.75, 4.0, 4.25, 4.5, 4.75, 5.0, 5.25, 5.5, 5.75]
"#;

/// Starts `spira sweep` on `file` into `out` with two workers, sends `signals` (SIGTERM)
/// once its first case is done, and returns its exit status, stdout and stderr.
fn sweep_signalled(
    file: &Path,
    out: &Path,
    signals: usize,
) -> (std::process::ExitStatus, String, String) {
    use std::io::{BufRead as _, BufReader, Read as _};
    let mut child = spira()
        .args([
            "sweep",
            file.to_str().expect("path"),
            "--jobs",
            "2",
            "--out",
        ])
        .arg(out)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spira sweep");
    let mut stdout = String::new();
    let mut lines = BufReader::new(child.stdout.take().expect("stdout"));
    loop {
        let mut line = String::new();
        if lines.read_line(&mut line).expect("a line") == 0 {
            break;
        }
        stdout.push_str(&line);
        if line.contains(" done in ") {
            break;
        }
    }
    let pid = child.id() as libc::pid_t;
    for _ in 0..signals {
        // SAFETY: kill(2) on the child's pid, which is not reaped before `wait` below
        unsafe { libc::kill(pid, libc::SIGTERM) };
    }
    lines.read_to_string(&mut stdout).expect("stdout");
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut stderr)
        .expect("stderr");
    let status = child.wait().expect("spira sweep ends");
    (status, stdout, stderr)
}

/// What a sweep's folder holds: its entries, and the number of complete case folders
/// (every case folder must be complete).
fn whole_folder(out: &Path, sweep: &Sweep) -> (Vec<String>, usize) {
    let mut names: Vec<String> = std::fs::read_dir(out)
        .expect("out")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut complete = 0;
    for n in &names {
        if n == "sweep.csv" {
            continue;
        }
        assert!(
            sweep.cases.iter().any(|c| &c.id == n),
            "only case folders and the table: {n} in {names:?}"
        );
        assert!(out.join(n).join(MARKER).is_file(), "{n} is complete");
        assert!(
            out.join(n).join("load.csv").is_file(),
            "{n} has its results"
        );
        complete += 1;
    }
    (names, complete)
}

/// SIGTERM during a sweep: the cases under way stop and are not written, no case
/// starts, the table of the finished ones is written, the exit status is not 0 and the
/// message says what was done. Nothing temporary is left, after one signal or two (the
/// second ends the process, between writes), and a case folder a killed sweep left half
/// written (`kill -9`) is removed by the next sweep.
#[test]
fn a_terminated_sweep_leaves_only_complete_case_folders_and_its_table() {
    let (dir, file) = scratch(SLOW_SWEEP);
    let out = dir.path().join("out");
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    let total = sweep.cases.len();
    let (status, stdout, stderr) = sweep_signalled(&file, &out, 1);
    assert_eq!(status.code(), Some(1), "{stdout}\n{stderr}");
    let (names, complete) = whole_folder(&out, &sweep);
    assert!(complete >= 1 && complete < total, "{names:?}");
    for fragment in [
        "spira sweep: interrupted; the cases under way stop",
        &format!("{complete} of {total} cases complete"),
        &format!("{} not done", total - complete),
        "the same command goes on with the rest",
    ] {
        assert!(stderr.contains(fragment), "`{fragment}` missing: {stderr}");
    }
    assert_eq!(stdout.matches(" done in ").count(), complete, "{stdout}");
    let table = read_table(&out.join("sweep.csv"));
    assert_eq!(table.rows.len(), complete);
    assert!((0..complete).all(|i| table.get(i, "status") == Some("done")));

    // a case folder a killed sweep was writing, with its owner gone; and one of a live
    // process (this test's), which stays
    let mut gone = std::process::Command::new("true").spawn().expect("true");
    let dead = gone.id();
    gone.wait().expect("true ends");
    let killed = out.join(format!(".spira-{}-AbCdEf", sweep.cases[total - 1].id));
    let live = out.join(format!(".spira-{}-GhIjKl", sweep.cases[total - 1].id));
    for (folder, pid) in [(&killed, dead), (&live, std::process::id())] {
        std::fs::create_dir(folder).expect("folder");
        std::fs::write(folder.join("load.csv"), "half").expect("write");
        std::fs::write(
            folder.join(spira::output::staging::OWNER_FILE),
            spira::output::staging::owner_record(pid),
        )
        .expect("owner");
    }
    let (status, stdout, stderr) = sweep_signalled(&file, &out, 2);
    assert!(!status.success(), "{stdout}\n{stderr}");
    assert!(!killed.exists(), "the killed sweep's folder is removed");
    std::fs::remove_dir_all(&live).expect("the live one is kept");
    let (_, again) = whole_folder(&out, &sweep);
    assert!(again > complete, "{stdout}");

    // and the same command finishes the rest
    let stdout = sweep_to_the_end(&file, &out);
    assert_eq!(stdout.matches("complete already, skipped").count(), again);
    let (_, all) = whole_folder(&out, &sweep);
    assert_eq!(all, total);
    assert_eq!(read_table(&out.join("sweep.csv")).rows.len(), total);
}

#[test]
fn slurm_variables_select_the_shard_of_the_task() {
    let vars = |pairs: &[(&str, &str)]| {
        let m: HashMap<String, String> = pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        move |name: &str| m.get(name).cloned()
    };
    let slurm = |pairs: &[(&str, &str)]| Shard::from_slurm(vars(pairs)).expect("slurm shard");
    assert_eq!(slurm(&[]), None, "outside a job array");
    // sbatch --array=1-3
    let one_based = [
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_MAX", "3"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    assert_eq!(slurm(&one_based), Some(Shard::new(2, 3).expect("shard")));
    // sbatch --array=0-2, without COUNT
    let zero_based = [
        ("SLURM_ARRAY_TASK_ID", "1"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "2"),
    ];
    assert_eq!(slurm(&zero_based), Some(Shard::new(2, 3).expect("shard")));
    // sbatch --array=1-5:2 (tasks 1, 3, 5)
    let stepped = [
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_MAX", "5"),
        ("SLURM_ARRAY_TASK_STEP", "2"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    assert_eq!(slurm(&stepped), Some(Shard::new(2, 3).expect("shard")));
    // an array with gaps, or no size
    assert!(Shard::from_slurm(vars(&[
        ("SLURM_ARRAY_TASK_ID", "4"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_MAX", "9"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ]))
    .is_err());
    assert!(Shard::from_slurm(vars(&[("SLURM_ARRAY_TASK_ID", "1")])).is_err());

    // the binary: the same cases and rows as --shard 2/3
    let (dir, file) = scratch(SWEEP);
    let (a, b) = (dir.path().join("slurm"), dir.path().join("flag"));
    let mut cmd = spira();
    cmd.args(["sweep", file.to_str().expect("path"), "--out"])
        .arg(&a);
    for (k, v) in one_based {
        cmd.env(k, v);
    }
    let slurm_run = cmd.output().expect("spira sweep");
    assert!(slurm_run.status.success(), "{slurm_run:?}");
    let flag_run = spira()
        .args([
            "sweep",
            file.to_str().expect("path"),
            "--shard",
            "2/3",
            "--out",
        ])
        .arg(&b)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .output()
        .expect("spira sweep");
    assert!(flag_run.status.success(), "{flag_run:?}");
    let name = "sweep-shard-2-of-3.csv";
    let (ta, tb) = (read_table(&a.join(name)), read_table(&b.join(name)));
    assert_eq!(ta.rows.len(), 2);
    assert_eq!(without_wall(&ta), without_wall(&tb));
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    let ids: Vec<&str> = ta.rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        ids,
        [sweep.cases[1].id.as_str(), sweep.cases[4].id.as_str()]
    );
}

/// The error of a sweep file, its file, line and key.
fn refused(sweep: &str) -> (SweepError, String) {
    let (dir, file) = scratch(sweep);
    let err = Sweep::from_file(&file).expect_err("refused");
    // the binary refuses it before any case runs: no output folder at all
    let out = dir.path().join("out");
    let run = spira()
        .args(["sweep", file.to_str().expect("path"), "--out"])
        .arg(&out)
        .output()
        .expect("spira sweep");
    assert!(!run.status.success());
    assert!(!out.exists(), "nothing ran");
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(stderr.contains(&err.to_string()), "{stderr}");
    assert_eq!(err.file(), Some(file.to_str().expect("path")));
    (err, stderr)
}

#[test]
fn invalid_axes_and_invalid_generated_cases_are_refused_before_anything_runs() {
    // an invalid value: n = 3 is neither 1 nor even
    let (e, msg) = refused(
        "base = \"base.toml\"\n\n[axes]\n\"loading.target\" = [0.1, 0.2]\n\"geometry.helices\" = [1, 3]\n",
    );
    assert!(matches!(e, SweepError::Generated(_)), "{e:?}");
    assert_eq!((e.line(), e.key()), (Some(5), Some("geometry.helices")));
    assert!(
        msg.contains("sweep.toml:5: axis `geometry.helices` = 3"),
        "{msg}"
    );

    // a key that is not a case key, written bare and dotted
    let (e, msg) = refused("base = \"base.toml\"\n[axes]\ngeometry.helix = [1, 2]\n");
    assert_eq!((e.line(), e.key()), (Some(3), Some("geometry.helix")));
    assert!(msg.contains("unknown field"), "{msg}");

    // a value of the wrong type
    let (e, _) =
        refused("[case]\ngeometry.helices = 2\n[axes]\n\"stiffness.b3\" = [1.0, \"stiff\"]\n");
    assert_eq!((e.line(), e.key()), (Some(4), Some("stiffness.b3")));

    // a key whose parent is not a table in the base
    let (e, _) = refused("base = \"base.toml\"\n[axes]\n\"geometry.helices.x\" = [1]\n");
    assert_eq!((e.line(), e.key()), (Some(3), Some("geometry.helices.x")));

    // an axis that is not an array, an empty one, zipped axes of two lengths
    let (e, _) = refused("base = \"base.toml\"\n[axes]\n\"geometry.helices\" = 2\n");
    assert_eq!((e.line(), e.key()), (Some(3), Some("geometry.helices")));
    let (e, _) = refused("base = \"base.toml\"\n[axes]\n\"geometry.helices\" = []\n");
    assert_eq!((e.line(), e.key()), (Some(3), Some("geometry.helices")));
    let (e, msg) = refused(
        "base = \"base.toml\"\ncombine = \"zip\"\n[axes]\n\"geometry.helices\" = [1, 2]\n\"loading.target\" = [0.1, 0.2, 0.3]\n",
    );
    assert_eq!((e.line(), e.key()), (Some(5), Some("loading.target")));
    assert!(msg.contains("zip"), "{msg}");

    // sweep-file keys: combine, unknown keys, a missing base
    let (e, _) =
        refused("base = \"base.toml\"\ncombine = \"cross\"\n[axes]\n\"geometry.helices\" = [1]\n");
    assert_eq!((e.line(), e.key()), (Some(2), Some("combine")));
    let (e, _) = refused("base = \"base.toml\"\naxis = 1\n[axes]\n\"geometry.helices\" = [1]\n");
    assert_eq!((e.line(), e.key()), (Some(2), Some("axis")));
    let (e, _) = refused("base = \"missing.toml\"\n[axes]\n\"geometry.helices\" = [1]\n");
    assert_eq!((e.line(), e.key()), (Some(1), Some("base")));

    // a generated case invalid through the combination: a target the geometry refuses
    let (e, msg) = refused(
        "base = \"base.toml\"\n[axes]\n\"geometry.helices\" = [1, 2]\n\"loading.target\" = [0.5, 1.5]\n",
    );
    assert_eq!((e.line(), e.key()), (Some(4), Some("loading.target")));
    assert!(msg.contains("= 1.5"), "{msg}");
}

#[test]
fn a_failing_case_is_recorded_with_its_reason_and_the_others_run() {
    // one Newton iteration per step and no room to cut back: the path cannot start
    let (dir, file) = scratch(
        "base = \"base.toml\"\n[case.solver]\nmin_step = 0.05\ninitial_step = 0.05\n[axes]\n\"geometry.helices\" = [1, 2]\n\"solver.max_iterations\" = [12, 1]\n",
    );
    let sweep = Sweep::from_file(&file).expect("valid sweep");
    let out = dir.path().join("out");
    let report = run_all(&sweep, &out, 2, Shard::ALL);
    assert_eq!((report.ran, report.failed), (4, 2));
    let t = &report.table;
    for i in 0..4 {
        let iterations = t.get(i, "solver.max_iterations").expect("axis column");
        let (status, reason) = (
            t.get(i, "status").expect("status"),
            t.get(i, "reason").expect("reason"),
        );
        if iterations == "1" {
            assert_eq!(status, "failed");
            assert!(!reason.is_empty());
        } else {
            assert_eq!(status, "done", "{reason}");
            assert!(reason.is_empty());
        }
        // every case folder is complete, a failed one included
        assert!(out.join(&sweep.cases[i].id).join(MARKER).is_file());
    }
    // the failed cases count as finished: a rerun skips them
    let again = run_all(&sweep, &out, 2, Shard::ALL);
    assert_eq!((again.skipped, again.ran), (4, 0));
    // and the binary says so in its exit status, with the table written
    let run = spira()
        .args(["sweep", file.to_str().expect("path"), "--out"])
        .arg(&out)
        .output()
        .expect("spira sweep");
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("2 of 4 cases failed"));
}

#[test]
fn an_inline_case_sweeps_nested_keys_and_turns_replace_the_length() {
    let sweep = Sweep::parse(
        "name = \"inline\"\ncombine = \"zip\"\n[case]\ngeometry = { helices = 1, length = 1.0, radius = 0.06, pitch = 0.025 }\n[axes]\n\"geometry.turns\" = [1.5, 2.0]\n\"boundary.tip.translation\" = [\"fixed\", \"slide\"]\n",
        "inline.toml",
        "inline",
        Path::new("."),
    )
    .expect("valid sweep");
    assert_eq!(sweep.name, "inline");
    assert_eq!(sweep.cases.len(), 2);
    let c = &sweep.cases[1];
    assert!((c.case.geometry.turns() - 2.0).abs() < 1e-12);
    assert_eq!(c.id, "002_turns-2.0_tip.translation-slide");
    assert_eq!(c.case.name, c.id);
    assert_ne!(sweep.cases[0].case.boundary, c.case.boundary);
}

#[test]
fn a_sweep_over_the_flaw_amplitude_reports_koiters_fit_or_that_no_path_turned() {
    // the shipped sweep: Euler's column, stable symmetric, whose flawed paths never turn
    let dir = tempfile::tempdir().expect("scratch folder");
    let out = dir.path().join("out");
    let printed = sweep_to_the_end(Path::new("cases/sweep-imperfection.toml"), &out);
    assert!(
        printed.contains("Koiter: fewer than two imperfect paths turned"),
        "{printed}"
    );
    // the normal form measured on the perfect column's branch: the elastica's b = π²/8
    let line = printed
        .lines()
        .find(|l| l.starts_with("normal form of the perfect point 0"))
        .unwrap_or_else(|| panic!("{printed}"));
    assert!(line.contains("stable-symmetric, no drop"), "{line}");
    let b: f64 = line
        .split("b = ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    let eighth = std::f64::consts::PI.powi(2) / 8.0;
    assert!((b / eighth - 1.0).abs() < 1e-3, "{line}");
    let table = read_table(&out.join("sweep.csv"));
    assert_eq!(table.rows.len(), 4);
    for row in 0..4 {
        assert_eq!(table.get(row, "status"), Some("done"));
        assert_eq!(table.get(row, "limit_parameter"), Some(""));
        assert_eq!(table.get(row, "drop"), Some(""));
    }
    assert!(table.koiter().is_none());
    // drops that follow δ^(2/3) over three decades: the fit finds the exponent
    let mut text = String::from("case,status,imperfection.amplitude,drop\n");
    for (k, d) in [1e-5f64, 1e-4, 1e-3, 1e-2].iter().enumerate() {
        text.push_str(&format!("{k:03},done,{d},{}\n", 0.3 * d.powf(2.0 / 3.0)));
    }
    let synthetic = SweepTable::from_csv(&text, "koiter.csv").expect("a table");
    let fit = synthetic.koiter().expect("a fit");
    assert!((fit.exponent - 2.0 / 3.0).abs() < 1e-9, "{fit:?}");
    assert!((fit.decades - 3.0).abs() < 1e-9);
}

#[test]
fn a_continued_axis_must_be_an_ordered_axis_of_numbers_of_a_product() {
    let parse = |head: &str, axes: &str| {
        Sweep::parse(
            &format!("{head}\n[case]\ngeometry = {{ helices = 1 }}\n[axes]\n{axes}\n"),
            "curve.toml",
            "curve",
            Path::new("."),
        )
    };
    let ok = parse(
        "continue = \"geometry.turns\"",
        "\"stiffness.b3\" = [2.0, 2.5]\n\"geometry.turns\" = [6.0, 6.1]",
    )
    .expect("valid sweep");
    assert_eq!(ok.continued, Some(1));
    for (head, axes, says) in [
        (
            "continue = \"geometry.radius\"",
            "\"geometry.turns\" = [6.0, 6.1]",
            "`geometry.radius` is not an axis; the axes are geometry.turns",
        ),
        (
            "continue = \"geometry.turns\"\ncombine = \"zip\"",
            "\"stiffness.b3\" = [2.0, 2.5]\n\"geometry.turns\" = [6.0, 6.1]",
            "needs `combine = \"product\"`",
        ),
        (
            "continue = \"geometry.turns\"",
            "\"geometry.turns\" = [6.0, 6.2, 6.1]",
            "at least two numbers in increasing or decreasing order",
        ),
        (
            "continue = \"geometry.turns\"",
            "\"geometry.turns\" = [6.0]",
            "at least two numbers",
        ),
        (
            "continue = 3",
            "\"geometry.turns\" = [6.0, 6.1]",
            "expected the key of an axis",
        ),
    ] {
        let e = parse(head, axes).expect_err(head).to_string();
        assert!(
            e.starts_with("curve.toml:1: key `continue`:") && e.contains(says),
            "{head}: {e}"
        );
    }
}
