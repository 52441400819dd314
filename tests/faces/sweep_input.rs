//! Sweeps and `plot` on bad input, the real binary on tiny cases: the workers bounded by
//! the cores and the cases, a sweep's name kept a folder under `out/`, tables with a cell
//! that is not a number refused with file, line and column, OS errors said once, a FIFO
//! in place of a table refused, Slurm variables past the whole numbers refused, and sweeps
//! of more than 10,000 cases read only with `--force`.

use crate::common;

use spira::sweep::{Shard, Sweep, SweepError, SweepTable};
use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const BASE: &str = "[geometry]\nhelices = 1\nturns = 1.5\n[loading]\ntarget = 0.1\nsteps = 1\n[discretisation]\nelements = 8\n";

/// A scratch folder with the base case and `sweep` as `sweep.toml`.
fn scratch(sweep: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("scratch folder");
    std::fs::write(dir.path().join("base.toml"), BASE).expect("base");
    std::fs::write(dir.path().join("sweep.toml"), sweep).expect("sweep");
    dir
}

/// `spira ARGS` inside `dir`; its output and how long it took.
fn spira(dir: &Path, args: &[&str]) -> (Output, Duration) {
    let t0 = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(args)
        .current_dir(dir)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .output()
        .expect("run spira");
    (out, t0.elapsed())
}

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn jobs_are_capped_at_the_cases_and_the_cores() {
    let dir = scratch("base = \"base.toml\"\n[axes]\n\"loading.target\" = [0.05, 0.1]\n");
    let (out, took) = spira(
        dir.path(),
        &["sweep", "sweep.toml", "--jobs", "1000000", "--out", "o"],
    );
    let (said, err) = text(&out);
    assert!(out.status.success(), "{said}{err}");
    let workers = spira::sweep::workers(None, 2);
    assert!(said.contains("--jobs 1000000: "), "{said}");
    assert!(said.contains(&format!("on {workers} worker(s)")), "{said}");
    // a guard against a hang (a million threads), not a measure of speed
    assert!(took < Duration::from_secs(120), "{took:?}");
    assert_eq!(
        spira::sweep::workers(Some(1_000_000), 2),
        spira::sweep::workers(None, 2)
    );
    assert_eq!(spira::sweep::workers(Some(1_000_000), 1), 1);
    assert_eq!(spira::sweep::workers(Some(3), 0), 1);
}

#[test]
fn a_sweep_name_is_a_folder_under_out() {
    let dir = scratch(
        "name = \"../../x\\ny\"\nbase = \"base.toml\"\n[axes]\n\"loading.target\" = [0.05]\n",
    );
    std::fs::create_dir_all(dir.path().join("work")).unwrap();
    std::fs::rename(
        dir.path().join("sweep.toml"),
        dir.path().join("work/sweep.toml"),
    )
    .unwrap();
    std::fs::rename(
        dir.path().join("base.toml"),
        dir.path().join("work/base.toml"),
    )
    .unwrap();
    let work = dir.path().join("work");
    let (out, _) = spira(&work, &["sweep", "sweep.toml"]);
    let (said, err) = text(&out);
    assert!(out.status.success(), "{said}{err}");
    assert_eq!(common::listing(&work), ["base.toml", "out", "sweep.toml"]);
    let folders = common::listing(&work.join("out"));
    assert_eq!(folders, ["_.._x_y"], "{said}");
    assert!(
        common::listing(dir.path()).iter().all(|f| f == "work"),
        "nothing outside"
    );
    for (name, folder) in [
        ("..", "sweep"),
        ("", "sweep"),
        ("a/b", "a_b"),
        (".hidden", "hidden"),
    ] {
        assert_eq!(spira::sweep::folder_name(name), folder);
    }
}

#[test]
fn a_table_with_a_word_where_a_number_belongs_is_refused_by_merge_and_plot() {
    let dir = scratch("base = \"base.toml\"\n[axes]\n\"loading.target\" = [0.05, 0.1]\n");
    let (out, _) = spira(
        dir.path(),
        &["sweep", "sweep.toml", "--jobs", "1", "--out", "o"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let table = dir.path().join("o/sweep.csv");
    let good = std::fs::read_to_string(&table).unwrap();
    let header: Vec<&str> = good.lines().next().unwrap().split(',').collect();
    let fz = header.iter().position(|h| *h == "fz").unwrap();
    for bad in ["NaN", "abc", "inf"] {
        let mut lines: Vec<String> = good.lines().map(String::from).collect();
        let mut cells: Vec<String> = lines[2].split(',').map(String::from).collect();
        cells[fz] = bad.into();
        lines[2] = cells.join(",");
        std::fs::write(&table, lines.join("\n") + "\n").unwrap();
        let (out, _) = spira(dir.path(), &["sweep", "--merge", "o", "--out", "m"]);
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert_eq!(
            err.trim(),
            format!("spira: error: o/sweep.csv:3: column `fz`: expected a finite number or an empty cell, found `{bad}`"),
        );
        assert!(!dir.path().join("m/sweep.csv").exists());
    }
    let e = SweepTable::from_csv("case,status\n001,maybe\n", "t.csv").expect_err("refused");
    assert!(matches!(e, SweepError::Cell { line: 2, .. }), "{e}");
    // a run folder's joints table with a word in a column plot does not draw
    std::fs::write(dir.path().join("tiny.toml"), common::TINY_CASE).unwrap();
    let (out, _) = spira(dir.path(), &["run", "tiny.toml", "--out", "run"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let joints = dir.path().join("run/joints.csv");
    let t = std::fs::read_to_string(&joints).unwrap();
    let header = t.lines().position(|l| l.starts_with("rod,")).unwrap();
    let mut lines: Vec<String> = t.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[header + 1].split(',').map(String::from).collect();
    cells[1] = "abc".into();
    lines[header + 1] = cells.join(",");
    std::fs::write(&joints, lines.join("\n") + "\n").unwrap();
    let (out, _) = spira(dir.path(), &["plot", "run", "--out", "figs"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(
        err.trim(),
        format!(
            "spira: error: run/joints.csv:{}: column `s`: expected a finite number or an empty cell, found `abc`",
            header + 2
        )
    );
}

#[test]
fn an_os_error_is_said_once_and_a_fifo_is_not_a_table() {
    let dir = scratch("");
    let (out, _) = spira(dir.path(), &["plot", "nowhere"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    let fifo_dir = dir.path().join("fifo");
    std::fs::create_dir_all(&fifo_dir).unwrap();
    let status = Command::new("mkfifo")
        .arg(fifo_dir.join("load.csv"))
        .status()
        .expect("mkfifo");
    assert!(status.success());
    let (out, took) = spira(dir.path(), &["plot", "fifo"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("fifo/load.csv: not a regular file (a FIFO)"),
        "{err}"
    );
    // a guard against blocking on the FIFO, not a measure of speed
    assert!(took < Duration::from_secs(120));
}

#[test]
fn slurm_variables_past_the_whole_numbers_are_refused_clearly() {
    let max = u64::MAX.to_string();
    let vars = |pairs: Vec<(&'static str, String)>| {
        let map: HashMap<&str, String> = pairs.into_iter().collect();
        move |k: &str| map.get(k).cloned()
    };
    let e = Shard::from_slurm(vars(vec![
        ("SLURM_ARRAY_TASK_ID", "0".into()),
        ("SLURM_ARRAY_TASK_MIN", "0".into()),
        ("SLURM_ARRAY_TASK_MAX", max.clone()),
    ]))
    .expect_err("refused");
    let said = e.to_string();
    assert!(
        said.contains(&format!("SLURM_ARRAY_TASK_MAX = {max}")) && !said.contains("0/0"),
        "{said}"
    );
    let e = Shard::from_slurm(vars(vec![
        ("SLURM_ARRAY_TASK_ID", max.clone()),
        ("SLURM_ARRAY_TASK_MIN", "0".into()),
        ("SLURM_ARRAY_TASK_COUNT", "4".into()),
    ]))
    .expect_err("refused");
    assert!(e.to_string().contains("SLURM_ARRAY_TASK_ID"), "{e}");
    let e = Shard::from_slurm(vars(vec![
        ("SLURM_ARRAY_TASK_ID", "3".into()),
        ("SLURM_ARRAY_TASK_COUNT", "0".into()),
    ]))
    .expect_err("refused");
    assert!(!e.to_string().contains("0/0"), "{e}");
}

#[test]
fn a_sweep_of_more_than_ten_thousand_cases_asks_for_force() {
    let values = |n: usize| {
        (0..n)
            .map(|k| format!("{}", 0.01 + 0.1 * k as f64 / n as f64))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let huge = format!(
        "base = \"base.toml\"\n[axes]\n\"loading.target\" = [{}]\n\"solver.max_step\" = [{}]\n",
        values(2000),
        values(2000)
    );
    let dir = scratch(&huge);
    let (out, took) = spira(dir.path(), &["sweep", "sweep.toml", "--check"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("sweep.toml:2: key `axes`: the axes make 4000000 cases (2000 × 2000); a sweep of more than 10000 cases is read, checked and listed only with --force"),
        "{err}"
    );
    // a guard against an unbounded check, not a measure of speed
    assert!(took < Duration::from_secs(120), "at once: {took:?}");
    let file = dir.path().join("sweep.toml");
    assert!(Sweep::from_file(&file).is_err());
    let small = "base = \"base.toml\"\n[axes]\n\"loading.target\" = [0.05, 0.1]\n";
    std::fs::write(&file, small).unwrap();
    assert!(Sweep::from_file_with(&file, 1).is_err());
    assert_eq!(
        Sweep::from_file_with(&file, 2)
            .expect("two cases")
            .cases
            .len(),
        2
    );
}
