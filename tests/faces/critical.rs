//! `spira critical` end to end: the real binary writes the critical curve's table and
//! figure, and refuses a key it cannot vary with a message that says which and why, exit
//! status 1 and nothing written.

use crate::cli::spira;
use std::path::{Path, PathBuf};

/// A scratch folder under the system's temporary folder, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(test: &str) -> Scratch {
        let dir =
            std::env::temp_dir().join(format!("spira-critical-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch folder");
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn case(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(name)
        .display()
        .to_string()
}

/// The curve of Euler's clamped column against its length: a table of the documented
/// columns, one row per value asked for, and an SVG figure.
#[test]
fn critical_writes_the_curve_table_and_its_figure() {
    let dir = Scratch::new("writes");
    let out = dir.0.join("curve");
    let c = case("euler-clamped.toml");
    let o = out.display().to_string();
    let args = [
        "critical",
        &c,
        "--vary",
        "geometry.length",
        "--from",
        "1",
        "--to",
        "1.5",
        "--rows",
        "4",
        "--out",
        &o,
    ];
    let run = spira(&dir.0, &args);
    assert!(
        run.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let table = std::fs::read_to_string(out.join("critical-curve.csv")).expect("the table");
    let mut lines = table.lines().filter(|l| !l.starts_with('#'));
    assert_eq!(
        lines.next(),
        Some("value,parameter,eps,fz,kind,wavenumber,multiplicity")
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 4, "{table}");
    for (row, length) in rows.iter().zip([1.0, 7.0 / 6.0, 4.0 / 3.0, 1.5]) {
        let cells: Vec<&str> = row.split(',').collect();
        let value: f64 = cells[0].parse().expect("a number");
        let fz: f64 = cells[3].parse().expect("a number");
        assert!((value - length).abs() < 1e-12, "{row}");
        let euler = fz.abs() * value * value / (4.0 * std::f64::consts::PI.powi(2));
        assert!((euler - 1.0).abs() < 1e-6, "{row}");
        assert_eq!(cells[4], "bifurcation");
    }
    let svg = std::fs::read_to_string(out.join("critical-curve.svg")).expect("the figure");
    assert!(svg.starts_with("<svg") || svg.contains("<svg"), "an SVG");
    assert!(svg.contains("geometry.length"));
}

/// Keys that cannot be varied: not a key of a case, not a number, or one that sets the
/// layout of the unknowns. Each is refused before anything is solved, the message names
/// the key and what was expected, and the output folder is not created.
#[test]
fn critical_refuses_a_bad_key_and_writes_nothing() {
    let dir = Scratch::new("refuses");
    let c = case("euler-clamped.toml");
    let cases = [
        ("geometry.lenght", "geometry.lenght"),
        ("boundary.tip.translation", "expected a numeric key"),
        ("discretisation.elements", "number of unknowns"),
    ];
    for (key, says) in cases {
        let out = dir.0.join("never");
        let o = out.display().to_string();
        let args = [
            "critical", &c, "--vary", key, "--from", "1", "--to", "2", "--out", &o,
        ];
        let run = spira(&dir.0, &args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{key}: {stderr}");
        assert!(stderr.contains(key), "{key}: {stderr}");
        assert!(stderr.contains(says), "{key}: {stderr}");
        assert!(!out.exists(), "{key}: nothing is written");
    }
}
