//! `spira bench --sweep`: a built-in sweep on every core, then one case after another.

use anyhow::{bail, Result};
use spira::sweep::{run_sweep, workers, RunOptions, Shard, Sweep};
use std::path::Path;

/// The sweep of `spira bench --sweep`: 16 cases of similar cost (n = 2, 8 lengths, fixed
/// and sliding tips).
const BENCH_SWEEP: &str = r#"
name = "bench"
combine = "product"
[case]
geometry.helices = 2
discretisation.elements = 24
loading.target = 0.3
loading.steps = 6
[axes]
"geometry.turns" = [2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5]
"boundary.tip" = [{ translation = "fixed", rotation = "clamped" }, { translation = "slide", rotation = "clamped" }]
"#;

/// `spira bench --sweep`: the wall time of [`BENCH_SWEEP`] on every core and on one, and
/// their ratio.
pub fn bench_sweep() -> Result<()> {
    let sweep = Sweep::parse(
        BENCH_SWEEP,
        "bench sweep (built in)",
        "bench",
        Path::new("."),
    )?;
    let cores = workers(None, sweep.cases.len());
    println!(
        "spira bench --sweep: {} cases (n = 2, 24 quadratic elements per rod, eps 0 -> 0.3 in 6 steps, turns 2 ... 5.5, fixed and sliding tips), {cores} core(s)",
        sweep.cases.len()
    );
    let mut times = Vec::new();
    for jobs in [cores, 1] {
        let dir = tempfile::tempdir()?;
        let opts = RunOptions {
            out: dir.path().to_path_buf(),
            jobs: Some(jobs),
            shard: Shard::ALL,
            interrupt: None,
        };
        let report = run_sweep(&sweep, &opts, |_| std::ops::ControlFlow::Continue(()))?;
        if report.failed > 0 {
            bail!("{} bench cases failed", report.failed);
        }
        let t = report.wall.as_secs_f64();
        println!("{jobs} worker(s): {t:.2} s for {} cases", report.total);
        times.push(t);
    }
    println!(
        "parallel / one after another: {:.2} (the goal: at most 0.6)",
        times[0] / times[1]
    );
    Ok(())
}
