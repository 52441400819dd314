//! Critical curves against closed forms and against separate runs: Euler's clamped column
//! against its length, Greenhill's built-in shaft under an axial load, and the single
//! spring against its turns, each point of the curve the first critical point of a path
//! solved on its own.

use spira::case::{Case, Setting};
use spira::results::CriticalKind;
use spira::simulation::curve::{critical_curve, CriticalCurve, CurveSpec};
use spira::simulation::Simulation;
use std::f64::consts::PI;

/// The critical curve of the case file `file` with `settings`, `key` from `from` to `to`.
fn curve(
    file: &str,
    settings: &[&str],
    key: &str,
    from: f64,
    to: f64,
    rows: usize,
) -> CriticalCurve {
    let path = format!("{}/cases/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let settings: Vec<Setting> = settings
        .iter()
        .map(|s| s.parse().expect("a setting"))
        .collect();
    let spec = CurveSpec {
        key: key.to_string(),
        from,
        to,
        rows,
        at: Vec::new(),
    };
    let curve =
        critical_curve(&text, &path, "test", &settings, &spec).unwrap_or_else(|e| panic!("{e}"));
    if let Some(why) = &curve.stopped {
        panic!("the curve stopped: {why}");
    }
    curve
}

/// The shipped case `file` with `settings`.
fn shipped_with(file: &str, settings: &[String]) -> Case {
    let path = format!("{}/cases/{file}", env!("CARGO_MANIFEST_DIR"));
    let settings: Vec<Setting> = settings
        .iter()
        .map(|s| s.parse().expect("a setting"))
        .collect();
    Case::from_file_with(std::path::Path::new(&path), &settings).unwrap_or_else(|e| panic!("{e}"))
}

/// The first critical point's load parameter on the path of `file` with `settings`.
fn first_critical(file: &str, settings: &[String]) -> f64 {
    let case = shipped_with(file, settings);
    let mut sim = Simulation::from_case_on(&case, 1).unwrap_or_else(|e| panic!("{e}"));
    for target in case.output_parameters(case.loading.target, case.loading.steps) {
        sim.advance_to(target).unwrap_or_else(|e| panic!("{e}"));
        if let Some(c) = sim
            .critical_points()
            .iter()
            .find(|c| c.kind != CriticalKind::Neutral)
        {
            return c.parameter;
        }
    }
    panic!("no critical point on the path of {file} with {settings:?}");
}

/// Euler's clamped column, L from 0.5 to 2 m: |fz| L²/(4π² B) = 1 at every point.
#[test]
fn the_clamped_columns_critical_load_against_its_length_is_eulers() {
    let curve = curve("euler-clamped.toml", &[], "geometry.length", 0.5, 2.0, 16);
    assert!(curve.rows.len() >= 10, "{} rows", curve.rows.len());
    for r in &curve.rows {
        let euler = r.fz.abs() * r.value.powi(2) / (4.0 * PI * PI);
        assert!(
            (euler - 1.0).abs() < 1e-6,
            "L = {}: |fz| L²/(4π²B) = {euler}",
            r.value
        );
        assert_eq!(r.kind, CriticalKind::Bifurcation);
        assert_eq!(r.multiplicity, 2, "B1 = B2: a double point");
    }
}

/// Greenhill's built-in shaft (both ends clamped, free along the axis) twisted under a
/// compressive dead load P: the lateral deflection `w = u + i v` solves
/// `B w'''' − i T w''' + P w'' = 0`, `w = w' = 0` at both ends, whose determinant is
/// `2r (cos kL − cos rL) = L (P/B) sin rL`, `k = T/2B`, `r = √(k² + P/B)`.
fn greenhill_clamped(t: f64, p: f64, b: f64, l: f64) -> f64 {
    let k = t / (2.0 * b);
    let r = (k * k + p / b).sqrt();
    2.0 * r * ((k * l).cos() - (r * l).cos()) - l * (p / b) * (r * l).sin()
}

/// The root of Greenhill's determinant in T nearest `t0` (a secant).
fn greenhill_torque(t0: f64, p: f64, b: f64, l: f64) -> f64 {
    let (mut a, mut c) = (t0 * (1.0 - 1e-3), t0 * (1.0 + 1e-3));
    for _ in 0..60 {
        let (fa, fc) = (greenhill_clamped(a, p, b, l), greenhill_clamped(c, p, b, l));
        if fc == fa {
            break;
        }
        let next = c - fc * (c - a) / (fc - fa);
        (a, c) = (c, next);
        if (c - a).abs() <= 1e-15 * c.abs() {
            break;
        }
    }
    c
}

/// The twisted shaft's critical torque against the axial load held on it, P/Pcrit from
/// 0.05 to 0.5: Greenhill's determinant at every point, to 1e-6 in T.
#[test]
fn the_twisted_shafts_critical_torque_against_its_axial_load_is_greenhills() {
    let curve = curve(
        "straight-twist.toml",
        &[],
        "loading.hold.axial_force",
        0.05,
        0.5,
        6,
    );
    let (b, l) = (1.0, 1.0);
    for r in &curve.rows {
        let p = -r.fz;
        assert!(
            (p - r.value * 4.0 * PI * PI * b / (l * l)).abs() < 1e-9 * p,
            "P = {p} at P/Pcrit = {}",
            r.value
        );
        let t = r.torque.abs();
        let exact = greenhill_torque(t, p, b, l);
        assert!(
            (t - exact).abs() < 1e-6 * exact,
            "P/Pcrit = {}: critical T L/B = {t}, Greenhill's {exact}",
            r.value
        );
    }
}

/// The single spring (thesis n = 1, clamped) against its turns, 6 to 6.1: every point of
/// the curve is the first critical point of the path at that many turns to 1e-8.
#[test]
fn the_single_springs_curve_against_its_turns_agrees_with_separate_runs() {
    let curve = curve("thesis-n1.toml", &[], "geometry.turns", 6.0, 6.1, 5);
    assert_eq!(curve.rows.len(), 5);
    for r in &curve.rows {
        let eps = first_critical("thesis-n1.toml", &[format!("geometry.turns={}", r.value)]);
        assert!(
            (r.parameter - eps).abs() < 1e-8,
            "turns {}: curve ε = {}, run ε = {eps}",
            r.value,
            r.parameter
        );
        assert!((r.eps - eps).abs() < 1e-8);
    }
}

/// A sweep whose turns axis is continued as a critical curve (`continue`), for two
/// torsional stiffnesses: every row of `critical-curves.csv` is the first critical point of
/// a path solved on its own at that many turns and that B3, to 1e-8 in ε.
#[test]
fn a_sweep_axis_continued_as_a_curve_agrees_with_separate_runs() {
    use spira::sweep::{run_curves, Sweep, CURVES_CSV};
    let file = format!(
        "{}/cases/sweep-critical-turns.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let sweep = Sweep::from_file(std::path::Path::new(&file)).unwrap_or_else(|e| panic!("{e}"));
    let out = std::env::temp_dir().join(format!("spira-sweep-curve-{}", std::process::id()));
    let report = run_curves(&sweep, &out, |_| {}).unwrap_or_else(|e| panic!("{e}"));
    assert!(report.short().is_empty(), "{:?}", report.short());
    assert_eq!(report.curves.len(), 2, "one curve per B3");
    let table = std::fs::read_to_string(out.join(CURVES_CSV)).expect("the table");
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .collect();
    assert_eq!(rows.len(), 10, "{table}");
    for row in rows {
        let cells: Vec<&str> = row.split(',').collect();
        let (b3, turns, eps): (f64, f64, f64) = (
            cells[0].parse().expect("b3"),
            cells[1].parse().expect("turns"),
            cells[2].parse().expect("parameter"),
        );
        let run = first_critical(
            "thesis-n1.toml",
            &[
                format!("geometry.turns={turns}"),
                format!("stiffness.b3={b3}"),
            ],
        );
        assert!(
            (eps - run).abs() < 1e-8,
            "B3 {b3}, turns {turns}: curve ε = {eps}, separate run ε = {run}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The thesis geometry as a tube of 4 helices (16 elements per rod, the whole assembly) whose
/// tip slides sideways, with `more` settings.
fn sliding_tip_tube(more: &[String]) -> Vec<String> {
    let mut settings = vec![
        "geometry.helices=4".to_string(),
        "discretisation.elements=16".to_string(),
        "boundary.tip={translation=\"slide\",rotation=\"clamped\"}".to_string(),
        "discretisation.symmetric=false".to_string(),
    ];
    settings.extend_from_slice(more);
    settings
}

/// The sliding-tip tube against its turns, 3.5 to 3.65: every row is the first critical
/// point of a path solved on its own at that many turns, to 1e-8 in ε. Past 3.5 a crossing
/// enters the rods, and the curve is located afresh there.
#[test]
fn the_sliding_tip_tubes_curve_against_its_turns_agrees_with_separate_runs() {
    let settings = sliding_tip_tube(&[]);
    let settings: Vec<&str> = settings.iter().map(String::as_str).collect();
    let curve = curve("thesis-n8.toml", &settings, "geometry.turns", 3.5, 3.65, 5);
    assert_eq!(curve.rows.len(), 5);
    assert!(curve.relocated >= 1, "the layout changes past 3.5 turns");
    for r in &curve.rows {
        let eps = first_critical(
            "thesis-n8.toml",
            &sliding_tip_tube(&[format!("geometry.turns={}", r.value)]),
        );
        assert!(
            (r.parameter - eps).abs() < 1e-8,
            "turns {}: curve ε = {}, run ε = {eps}",
            r.value,
            r.parameter
        );
        assert_eq!(r.multiplicity, 1, "two simple points, not a double one");
    }
    // fewer turns, a longer tube: the critical compression falls
    assert!(curve
        .rows
        .windows(2)
        .all(|w| w[1].parameter < w[0].parameter));
}

/// Two simple critical points crossed by one output step of the n = 4 sliding-tip tube
/// (ε = 0.1 to 0.15) are located apart, 0 → 1 and 1 → 2, where a path of steps a tenth as
/// long finds them one by one, to 1e-8.
#[test]
fn two_points_in_one_step_are_located_apart() {
    let points = |steps: &str| {
        let case = shipped_with(
            "thesis-n8.toml",
            &sliding_tip_tube(&[
                format!("loading.steps={steps}"),
                "loading.target=0.15".to_string(),
            ]),
        );
        let mut sim = Simulation::from_case_on(&case, 1).unwrap_or_else(|e| panic!("{e}"));
        for target in case.output_parameters(case.loading.target, case.loading.steps) {
            sim.advance_to(target).unwrap_or_else(|e| panic!("{e}"));
        }
        sim.critical_points()
            .iter()
            .map(|c| (c.parameter, c.unstable_before, c.unstable_after))
            .collect::<Vec<_>>()
    };
    let (coarse, fine) = (points("3"), points("30"));
    assert_eq!(coarse.len(), 2, "{coarse:?}");
    assert_eq!(fine.len(), 2, "{fine:?}");
    for (c, f) in coarse.iter().zip(&fine) {
        assert!((c.0 - f.0).abs() < 1e-8, "{coarse:?} {fine:?}");
        assert_eq!((c.1, c.2), (f.1, f.2));
    }
    assert_eq!((coarse[0].1, coarse[0].2, coarse[1].2), (0, 1, 2));
    assert!(coarse[1].0 - coarse[0].0 > 1e-3, "{coarse:?}");
}
