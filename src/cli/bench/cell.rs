//! `spira bench --cell`: the stability map of one state of the infinite tube's cell — the
//! lowest eigenvalue of every Bloch block `H(p, k)`, `p = 0 … m − 1`, on 65 axial phases in
//! `[0, π]` (a 64-interval grid) — beside the stability of one state of the finite pair of
//! the same n (every Bloch block of the thesis tube, 3.5 turns, clamped).

use anyhow::{anyhow, Result};
use spira::case::Case;
use spira::simulation::blocks::JudgeByBlocks;
use spira::simulation::cell::PHASES;
use spira::simulation::judge::StabilityJudge;
use spira::simulation::Simulation;
use std::time::Instant;

/// The axial strain of the states judged: half way along the cell's shipped path.
const EPS: f64 = 0.25;

/// The thesis tube of `n` helices with the `[discretisation]` lines `discretisation`.
fn thesis(n: usize, discretisation: &str) -> Result<Case> {
    let text = format!("[geometry]\nhelices = {n}\n[discretisation]\n{discretisation}\n");
    Ok(Case::parse(
        &text,
        "spira bench --cell",
        &format!("bench-n{n}"),
    )?)
}

/// The best and mean of `repeats` timings (s) of `f`, after one untimed run.
fn time(repeats: usize, mut f: impl FnMut() -> Result<()>) -> Result<(f64, f64)> {
    f()?;
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed().as_secs_f64());
    }
    let best = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok((best, times.iter().sum::<f64>() / times.len() as f64))
}

/// `spira bench --cell`: for n = 8 and 64, the cell's full (p, k) map and the finite pair's
/// blocks at ε = 0.25, best and mean of `repeats` timed runs each (the first untimed).
pub fn bench_cell(repeats: usize) -> Result<()> {
    println!(
        "spira bench --cell: one state at eps = {EPS} of the thesis tube; the cell: the lowest eigenvalue of every block H(p, k) on {PHASES} phases k in [0, pi] (cold: a new judge each time); the finite pair (3.5 turns, clamped, 56 elements per rod): every Bloch block judged with its lowest eigenvalue; best (mean) of {} timed runs",
        repeats.max(1)
    );
    println!(
        "{:>4} {:>6} {:>9} {:>7} {:>22} {:>14}",
        "n", "model", "unknowns", "blocks", "time per state (ms)", "lowest (J/m)"
    );
    for n in [8usize, 64] {
        let cell = thesis(n, "model = \"cell\"")?;
        let mut sim = Simulation::from_case(&cell)?;
        sim.advance_to(EPS)?;
        let mut lowest = None;
        let (best, mean) = time(repeats, || {
            let d = sim
                .dispersion(PHASES)
                .ok_or_else(|| anyhow!("the cell has no dispersion"))?;
            lowest = d.lowest().map(|l| l.0);
            Ok(())
        })?;
        let m = n / 2;
        row(n, "cell", sim.system().n, m * PHASES, best, mean, lowest);
        let pair = thesis(n, "model = \"pair\"\nelements = 56")?;
        let mut sim = Simulation::from_case(&pair)?;
        sim.advance_to(EPS)?;
        let (best, mean) = time(repeats, || {
            let mut judge = JudgeByBlocks::new(sim.model(), sim.system(), 1)
                .ok_or_else(|| anyhow!("the pair has no Bloch blocks"))?;
            let blocks = judge.blocks(sim.model(), sim.system(), sim.state(), true)?;
            lowest = blocks
                .iter()
                .filter_map(|b| b.lowest_eigenvalue)
                .min_by(f64::total_cmp);
            Ok(())
        })?;
        row(n, "pair", sim.system().n, m / 2 + 1, best, mean, lowest);
    }
    Ok(())
}

fn row(
    n: usize,
    model: &str,
    unknowns: usize,
    blocks: usize,
    best: f64,
    mean: f64,
    lowest: Option<f64>,
) {
    let lowest = lowest.map_or("-".to_string(), |l| format!("{l:.6}"));
    println!(
        "{n:>4} {model:>6} {unknowns:>9} {blocks:>7} {:>13.1} ({:>6.1}) {lowest:>14}",
        best * 1e3,
        mean * 1e3
    );
}
