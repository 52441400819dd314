//! `spira run` on the cell of the infinite tube: the summary names the unstable bands that
//! the step-by-step count (judged on a coarser grid of phases) can miss.

use super::cli::spira;
use std::path::Path;

/// The thesis tube compressed as a cell opens the band of p = 1 around the translation of
/// its cells, k = π/4 (one cell turns by π/4 from the next) — an infinitely long column
/// buckles at any compression — and the summary says so, where `bands.csv` has it.
#[test]
fn a_cell_run_names_the_bands_that_opened() {
    let dir = std::env::temp_dir().join(format!("spira-faces-cell-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch");
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/cell-n8.toml");
    let out = dir.join("out");
    let run = spira(
        &dir,
        &[
            "run",
            case.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--set",
            "loading.target=0.1",
            "--set",
            "loading.steps=2",
        ],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("unstable bands of the infinite tube"))
        .unwrap_or_else(|| panic!("no bands line in\n{stdout}"));
    assert!(
        line.contains("p = 1 opens between eps = 0.000000 and 0.050000"),
        "{line}"
    );
    // the band around k = π/4, read back from the line
    let at_end = line
        .split("at eps = 0.100000: p = 1 k ")
        .nth(1)
        .expect(line);
    let (from, to) = at_end.split_once('–').expect(line);
    let (from, to): (f64, f64) = (from.parse().unwrap(), to.parse().unwrap());
    let quarter = std::f64::consts::FRAC_PI_4;
    assert!(from < quarter && quarter < to, "{line}");
    // only p = 1 opens
    assert!(!line.contains("p = 0") && !line.contains("p = 2") && !line.contains("p = 3"));
    let bands = std::fs::read_to_string(out.join("bands.csv")).expect("bands.csv");
    assert!(bands
        .lines()
        .any(|l| l.starts_with("2,") && l.contains(",1,")));
    let _ = std::fs::remove_dir_all(&dir);
}
