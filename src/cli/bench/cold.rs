//! `spira bench --cold` and `--scaling`: whole `spira run` processes of this binary, timed
//! from outside, with the unknowns and peak memory they report.

use anyhow::{bail, Context, Result};
use std::path::Path;
use std::time::Instant;

/// One cold `spira run` process of this binary on the case `text` (written into `dir` as
/// `name.toml`, its output folder beside it): its wall time (s), and the unknowns and peak
/// memory (MB) it reports.
struct ColdRun {
    wall: f64,
    unknowns: String,
    memory: String,
}

fn cold_run(dir: &Path, name: &str, text: &str) -> Result<ColdRun> {
    let exe = std::env::current_exe().context("finding the spira binary")?;
    let case = dir.join(format!("{name}.toml"));
    std::fs::write(&case, text)?;
    let out = dir.join(format!("out-{name}"));
    let t = Instant::now();
    let output = std::process::Command::new(&exe)
        .args(["run", &case.to_string_lossy(), "--force", "--out"])
        .arg(&out)
        .output()
        .context("running spira run")?;
    let wall = t.elapsed().as_secs_f64();
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    if !output.status.success() {
        bail!(
            "{name}: spira run failed: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let unknowns = text
        .split(" unknowns;")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .unwrap_or("?")
        .to_string();
    let memory = text
        .lines()
        .find_map(|l| l.strip_prefix("peak memory "))
        .map_or("?".into(), |m| m.trim_end_matches(" MB").to_string());
    // the next run writes a folder of its own: a removed one leaves no trace to reuse
    std::fs::remove_dir_all(&out).ok();
    Ok(ColdRun {
        wall,
        unknowns,
        memory,
    })
}

/// `spira bench --cold`: what a user waits for, a whole `spira run` process, for the
/// thesis assembly of n = 8 helices (solved as the symmetric pair, its stability by Bloch
/// blocks) and of one helix, alternately so that both see the same load of the machine;
/// the best and median times of each and their ratios.
pub fn bench_cold(repeats: usize) -> Result<()> {
    let dir = tempfile::tempdir()?;
    println!(
        "spira bench --cold: thesis geometry (48 quadratic elements per rod), eps 0 -> 0.5 in 10 output steps, stability at every step, lowest eigenvalue at every output step; cold `spira run` processes, n = 8 and n = 1 alternately, {repeats} each"
    );
    let cases = [
        ("n8", "[geometry]\nhelices = 8\n"),
        ("n1", "[geometry]\nhelices = 1\n"),
    ];
    let mut times = [Vec::new(), Vec::new()];
    let mut memory = [String::new(), String::new()];
    for _ in 0..repeats {
        for (k, (name, text)) in cases.iter().enumerate() {
            let r = cold_run(dir.path(), name, text)?;
            times[k].push(r.wall);
            memory[k] = r.memory;
        }
    }
    let stats = |t: &mut Vec<f64>| {
        t.sort_by(f64::total_cmp);
        (t[0], t[t.len() / 2])
    };
    let (best8, median8) = stats(&mut times[0]);
    let (best1, median1) = stats(&mut times[1]);
    println!(
        "{:>6} {:>10} {:>12} {:>12}",
        "n", "best (ms)", "median (ms)", "memory (MB)"
    );
    for (n, best, median, mem) in [
        (8, best8, median8, &memory[0]),
        (1, best1, median1, &memory[1]),
    ] {
        println!(
            "{n:>6} {:>10.1} {:>12.1} {mem:>12}",
            best * 1e3,
            median * 1e3
        );
    }
    println!(
        "n = 8 / n = 1: {:.2} best, {:.2} median (the goals: n = 8 at most 250 ms, at most 2 times n = 1)",
        best8 / best1,
        median8 / median1
    );
    Ok(())
}

/// `spira bench --scaling`: cold `spira run` processes of this binary on the thesis
/// geometry (56 quadratic elements per rod, ε 0 → 0.5 in 10 output steps, stability of every
/// step, lowest eigenvalue at every output step) for n = 8 … 64, pair and full model side by
/// side, each process's wall time and peak memory (as it reports it).
pub fn bench_scaling(full_max: usize) -> Result<()> {
    let dir = tempfile::tempdir()?;
    println!(
        "spira bench --scaling: thesis geometry, 56 quadratic elements per rod, eps 0 -> 0.5 in 10 output steps, stability at every step, lowest eigenvalue at every output step; cold `spira run` processes"
    );
    println!(
        "{:>4} {:>6} {:>10} {:>10} {:>12}",
        "n", "model", "unknowns", "time (s)", "memory (MB)"
    );
    for n in [8usize, 16, 32, 64] {
        for pair in [true, false] {
            if !pair && n > full_max {
                continue;
            }
            let text = format!(
                "[geometry]\nhelices = {n}\n[discretisation]\nelements = 56\nsymmetric = {pair}\n"
            );
            let r = cold_run(dir.path(), &format!("n{n}-{pair}"), &text)?;
            println!(
                "{n:>4} {:>6} {:>10} {:>10.2} {:>12}",
                if pair { "pair" } else { "full" },
                r.unknowns,
                r.wall,
                r.memory
            );
        }
    }
    Ok(())
}
