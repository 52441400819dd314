//! Imperfections (docs/theory.md §9): the normal form of a perfect bifurcation measured on
//! its branch, and what a flaw along its mode does to the path. Koiter: the maximum load
//! drops as δ^(1/2) at an asymmetric point, as δ^(2/3) at an unstable symmetric one, and not
//! at all at a stable symmetric one. The Euler column, the thesis pair's pitchfork and the
//! sliding-tip tube's lateral point all measure stable symmetric: their imperfect paths
//! pass the perfect critical load without turning, over three decades of δ.

use spira::case::{Case, ImperfectionShape};
use spira::results::Snapshot;
use spira::run::{run_path, PathOutcome};
use spira::simulation::normal_form::{koiter_fit, normal_form, BifurcationType, NormalForm};
use spira::simulation::Simulation;
use std::f64::consts::PI;
use std::path::Path;

/// Three decades of flaw amplitudes (in rod lengths).
const DECADES: [f64; 4] = [1e-5, 1e-4, 1e-3, 1e-2];

fn case(name: &str) -> Case {
    Case::from_file(Path::new(&format!("cases/{name}.toml"))).unwrap()
}

/// The case with its flaw's amplitude `delta`.
fn with_amplitude(case: &Case, delta: f64) -> Case {
    let mut c = case.clone();
    c.imperfection
        .as_mut()
        .expect("an imperfect case")
        .amplitude = delta;
    c
}

fn run(case: &Case) -> PathOutcome {
    let targets = case.output_parameters(case.loading.target, case.loading.steps);
    run_path(case, &targets, |_, _| {}).expect("the path starts")
}

/// The largest distance of the centreline from the z axis, over the rod length.
fn deflection(shape: &Snapshot, length: f64) -> f64 {
    shape
        .rods
        .iter()
        .flat_map(|r| r.nodes.iter())
        .map(|n| n.position[0].hypot(n.position[1]))
        .fold(0.0, f64::max)
        / length
}

/// A stable symmetric normal form: no slope (`|a| ξ` below a thousandth of `b ξ²` at the
/// sampled amplitudes), the branch rising with the load.
fn assert_stable_symmetric(nf: &NormalForm, xi: f64) {
    assert_eq!(nf.kind, BifurcationType::StableSymmetric, "{nf:?}");
    assert!(nf.b > 0.0, "{nf:?}");
    assert!(nf.a.abs() * xi < 1e-3 * nf.b * xi * xi, "{nf:?}");
    assert_eq!(nf.kind.koiter_exponent(), None);
}

/// Every imperfect path of the case over the amplitudes `deltas` passes the perfect
/// critical load without turning: no limit point, no drop, the target load reached.
fn assert_no_drop(imperfect: &Case, perfect_parameter: f64, deltas: &[f64]) -> Vec<PathOutcome> {
    assert!(imperfect.loading.target > perfect_parameter);
    deltas
        .iter()
        .map(|&delta| {
            let outcome = run(&with_amplitude(imperfect, delta));
            assert!(outcome.error.is_none(), "δ = {delta}: {:?}", outcome.error);
            let path = outcome.imperfection.as_ref().expect("an imperfect path");
            let perfect = path.flaw.perfect.as_ref().expect("the perfect point");
            assert!((perfect.parameter - perfect_parameter).abs() < 1e-9);
            assert_eq!(
                path.limit_parameter,
                None,
                "δ = {delta}: {}",
                path.summary()
            );
            assert_eq!(path.drop, None);
            assert!((path.max_load - imperfect.loading.target).abs() < 1e-9);
            outcome
        })
        .collect()
}

#[test]
fn euler_column_is_stable_symmetric_with_b_pi_squared_over_8_and_its_flaws_do_not_drop_the_load() {
    let imperfect = case("euler-clamped-imperfect");
    let xi = 1e-3;
    let nf = normal_form(&imperfect, 0, xi).expect("the normal form");
    assert!((nf.parameter - 1.0).abs() < 1e-6);
    assert_stable_symmetric(&nf, xi);
    // the elastica: P/Pcrit = (2K(k)/π)², w/L = k/K(k), so P/Pcrit = 1 + (π²/8) (w/L)² + …
    assert!((nf.b / (PI * PI / 8.0) - 1.0).abs() < 1e-4, "b = {}", nf.b);
    // the perfect post-buckled branch at the target load, which the flawed paths approach
    let mut perfect = imperfect.clone();
    perfect.imperfection = None;
    perfect.loading.branch = spira::model::loading::Branch::Switch;
    let buckled = deflection(&run(&perfect).snapshot, 1.0);
    let outcomes = assert_no_drop(&imperfect, nf.parameter, &DECADES);
    let gaps: Vec<f64> = outcomes
        .iter()
        .zip(DECADES)
        .map(|(o, delta)| (deflection(&o.snapshot, 1.0) - buckled) / delta)
        .collect();
    // above the critical load the flawed rod is the buckled one plus a deflection in
    // proportion to δ, at most δ P/(2 (P − Pc)) to first order (10.5 δ at P = 1.05 Pc)
    for g in &gaps[..3] {
        assert!(*g > 0.0 && *g < 10.5, "{gaps:?}");
        assert!((g / gaps[0] - 1.0).abs() < 0.1, "{gaps:?}");
    }
}

#[test]
fn a_flaw_along_the_mode_is_the_unloaded_shape_and_a_bow_bows_the_pinned_column() {
    // clamped: the mode fits the supports, so the unloaded flawed rod takes it, deflected δ
    let clamped = with_amplitude(&case("euler-clamped-imperfect"), 1e-3);
    let sim = Simulation::from_case(&clamped).expect("the natural state");
    let w = deflection(&sim.snapshot(), 1.0);
    assert!((w - 1e-3).abs() < 1e-8, "w = {w}");
    // pinned: the half sine bow is stress-free there
    let text = std::fs::read_to_string("cases/euler-pinned.toml").unwrap()
        + "[imperfection]\nshape = \"bow\"\namplitude = 2e-3\n";
    let pinned = Case::parse(&text, "pinned-bow.toml", "pinned-bow").expect("the case");
    assert_eq!(
        pinned.imperfection.map(|i| i.shape),
        Some(ImperfectionShape::Bow)
    );
    let sim = Simulation::from_case(&pinned).expect("the natural state");
    let w = deflection(&sim.snapshot(), 1.0);
    assert!((w - 2e-3).abs() < 1e-8, "w = {w}");
    let shape = sim.snapshot();
    for n in &shape.rods[0].nodes {
        let bow = 2e-3 * (PI * n.s_over_l).sin();
        assert!(
            (n.position[0] - bow).abs() < 1e-8,
            "{} {}",
            n.position[0],
            bow
        );
    }
}

#[test]
fn thesis_pair_pitchfork_is_stable_symmetric_and_its_flaws_do_not_drop_the_load() {
    let imperfect = case("thesis-n2-imperfect");
    let xi = 1e-3;
    let nf = normal_form(&imperfect, 0, xi).expect("the normal form");
    assert!((nf.parameter - 3.409821772).abs() < 1e-8, "{nf:?}");
    assert_stable_symmetric(&nf, xi);
    assert_no_drop(&imperfect, nf.parameter, &DECADES);
}

#[test]
fn sliding_tip_tube_lateral_point_is_stable_symmetric_and_its_flaws_do_not_drop_the_load() {
    let imperfect = case("thesis-n8-slide-imperfect");
    let xi = 1e-3;
    let nf = normal_form(&imperfect, 0, xi).expect("the normal form");
    assert_stable_symmetric(&nf, xi);
    // the whole tube solved for each flaw: the ends of the three decades
    let outcomes = assert_no_drop(&imperfect, nf.parameter, &[DECADES[0], DECADES[3]]);
    // the wavenumber-1 flaw breaks the pair's symmetry: the whole tube was solved
    for o in &outcomes {
        let path = o.imperfection.as_ref().unwrap();
        assert!(path.flaw.whole_assembly);
        assert_eq!(path.flaw.perfect.as_ref().unwrap().wavenumber, Some(1));
    }
}

#[test]
fn koiter_fit_recovers_the_exponent_of_a_power_law_over_three_decades() {
    let samples: Vec<(f64, f64)> = DECADES
        .iter()
        .map(|&d| (d, 0.7 * d.powf(2.0 / 3.0)))
        .collect();
    let fit = koiter_fit(&samples).expect("a fit");
    assert!((fit.exponent - 2.0 / 3.0).abs() < 1e-12);
    assert!((fit.coefficient - 0.7).abs() < 1e-12);
    assert!((fit.decades - 3.0).abs() < 1e-12);
    // no drop: nothing to fit
    assert!(koiter_fit(&[(1e-3, 0.0), (1e-2, 0.0)]).is_none());
}
