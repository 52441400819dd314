//! Bad input, bounded work: results that do not depend on the units of the
//! stiffness or of length, and no non-finite number written.

use spira::case::Case;
use spira::run::run_path;
use std::path::Path;

fn thesis_n1() -> Case {
    Case::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/thesis-n1.toml"))
        .expect("shipped case")
}

#[test]
fn every_stiffness_times_1e5_gives_the_thesis_n1_path_scaled_by_1e5() {
    let case = thesis_n1();
    let mut stiff = case.clone();
    let s = 1e5;
    stiff = Case {
        stiffness: spira::model::stiffness::Stiffness {
            b1: case.stiffness.b1 * s,
            b2: case.stiffness.b2 * s,
            b3: case.stiffness.b3 * s,
        },
        ..stiff
    };
    // the case file says the same
    let text = "[stiffness]\nb1 = 1e5\nb2 = 1e5\nb3 = 2e5\n";
    let parsed = Case::parse(text, "stiff.toml", "thesis-n1").expect("valid");
    assert_eq!(parsed.stiffness, stiff.stiffness);

    let eps = case.output_parameters(case.loading.target, case.loading.steps);
    let a = run_path(&case, &eps, |_, _| {}).expect("thesis n = 1");
    let b = run_path(&stiff, &eps, |_, _| {}).expect("thesis n = 1, stiffness x 1e5");
    assert!(
        a.error.is_none() && b.error.is_none(),
        "{:?} {:?}",
        a.error,
        b.error
    );
    assert_eq!(a.points.len(), b.points.len());
    let rel = |x: f64, y: f64, scale: f64| (x - y).abs() / scale;
    for (p, q) in a.points.iter().zip(&b.points) {
        assert_eq!(p.compression_ratio, q.compression_ratio);
        // normalised by n Pcrit: the same numbers
        for k in 0..3 {
            assert!(
                rel(p.load[k], q.load[k], 1.0) < 1e-7,
                "step {}: {:?} vs {:?}",
                p.step,
                p.load,
                q.load
            );
        }
        let e_scale = p.energy.abs().max(1e-6);
        assert!(
            rel(p.energy * s, q.energy, e_scale * s) < 1e-7,
            "energy {} vs {}",
            p.energy,
            q.energy
        );
        for (ra, rb) in p.reactions.iter().zip(&q.reactions) {
            for k in 0..3 {
                let f = ra.tip.force.iter().map(|v| v.abs()).fold(1e-3, f64::max);
                assert!(rel(ra.tip.force[k] * s, rb.tip.force[k], f * s) < 1e-7);
            }
        }
        assert_eq!(
            p.stability.map(|x| x.unstable_directions),
            q.stability.map(|x| x.unstable_directions)
        );
        // the lowest eigenvalue (J/m: energy per arc length) scales with the stiffness
        let lowest = |p: &spira::results::LoadPoint| {
            p.stability
                .and_then(|x| x.lowest_eigenvalue)
                .expect("computed")
        };
        let (la, lb) = (lowest(p), lowest(q));
        assert!(
            rel(la * s, lb, la.abs() * s) < 1e-8,
            "step {}: lowest eigenvalue {la} x 1e5 vs {lb}",
            p.step
        );
    }
    let (last_a, last_b) = (a.points.last().unwrap(), b.points.last().unwrap());
    assert!((last_a.load[2] - -3.082).abs() < 1e-3, "{}", last_a.load[2]);
    assert!((last_b.load[2] - last_a.load[2]).abs() < 1e-7);
}

#[test]
fn writers_refuse_non_finite_cells_naming_the_column() {
    use spira::output::check_finite;
    assert!(check_finite("# case\nstep,fz\n0,1.0e0\n").is_ok());
    for bad in ["NaN", "inf", "-inf"] {
        let e = check_finite(&format!(
            "# case\nstep,fz,energy\n0,1.0e0,2.0e0\n1,3.0e0,{bad}\n"
        ))
        .expect_err("a non-finite cell");
        assert_eq!(e.column, "energy");
        assert_eq!(e.row, 2);
        assert!(e.to_string().contains("column `energy`"), "{e}");
    }
    // names are not numbers
    assert!(check_finite("rod,kind\n0,information\n").is_ok());
}

/// The thesis n = 1 case with the tips free to slide (Haringx's ends): it bifurcates at
/// ε ≈ 0.135 (README, Findings), so the length test also compares a critical point.
fn sliding_tips(case: &str) -> String {
    case.replace(
        "tip = { translation = \"fixed\", rotation = \"clamped\" }",
        "tip = { translation = \"slide\", rotation = \"clamped\" }",
    )
}

/// The thesis n = 1 case written with every length ×s (s = 1e-3: the same spring in
/// kilometres, or a spring a thousand times smaller) and every stiffness ×s² (force in the
/// same unit) is the same problem in other units, and spira must find the same path.
///
/// Dimensional analysis. The data are lengths a, b, L (m) and stiffnesses B1, B2, B3
/// (N m²), the control ε = (h0 − h)/h0. The only force scale is B1/L², so by the Π
/// theorem every result is a function of the dimensionless groups a/L, b/L, B2/B1,
/// B3/B1 and ε, all unchanged by a → s a, b → s b, L → s L, Bi → s² Bi. Hence:
/// - ε, P/Pcrit and the normalised loads F/(n Pcrit), Pcrit = B1 (2π/L)², are unchanged,
///   and so is every critical point's ε and the count of unstable directions;
/// - forces F = (B1/L²) Φ scale by s²/s² = 1, moments M = (B1/L) Φ by s, the energy
///   E = (B1/L) Φ by s;
/// - positions and heights scale by s, curvatures by 1/s;
/// - the lowest eigenvalue of the constrained Hessian (J/m: energy per rotation² per arc
///   length, B1/L² Φ) by s²/s² = 1 (compared to 1e-8: the regularisation of its KKT
///   solves weighs constraints on positions by the rod length, src/solver/stability.rs;
///   with one penalty for all rows it was 11.27 J/m in metres and 11.40 scaled at ε = 0.5).
///
/// Compared to 1e-6 relative: far below the discretisation error of the thesis mesh (Fz
/// about 2e-4 relative at 48 elements, README), and above the Newton tolerance's 1e-9 in
/// the problem's own units, which is all a change of units may change.
#[test]
fn every_length_times_1e_3_gives_the_thesis_n1_path_in_other_units() {
    let s: f64 = 1e-3;
    let metres = include_str!("../../cases/thesis-n1.toml");
    let scaled = metres
        .replace("radius = 0.06 ", &format!("radius = {:e} ", 0.06 * s))
        .replace("pitch = 0.025 ", &format!("pitch = {:e} ", 0.025 * s))
        .replace("b1 = 1.0 ", &format!("b1 = {:e} ", s * s))
        .replace("b2 = 1.0 ", &format!("b2 = {:e} ", s * s))
        .replace("b3 = 2.0 ", &format!("b3 = {:e} ", 2.0 * s * s));
    assert_ne!(scaled, metres);
    for (label, a_text, b_text, target) in [
        ("clamped", metres.to_string(), scaled.clone(), None),
        (
            "tip slides",
            sliding_tips(metres),
            sliding_tips(&scaled),
            Some(0.2),
        ),
    ] {
        let a_case = Case::parse(&a_text, "m.toml", "thesis-n1").expect("valid");
        let b_case = Case::parse(&b_text, "km.toml", "thesis-n1").expect("valid");
        assert!((b_case.geometry.length - s * a_case.geometry.length).abs() < 1e-15);
        assert_eq!(b_case.geometry.helices, 1);
        let target = target.unwrap_or(a_case.loading.target);
        let steps = if target < 0.5 {
            4
        } else {
            a_case.loading.steps
        };
        let eps = a_case.output_parameters(target, steps);
        let a = run_path(&a_case, &eps, |_, _| {}).expect("metres");
        let b = run_path(&b_case, &eps, |_, _| {}).expect("lengths x 1e-3");
        assert!(
            a.error.is_none() && b.error.is_none(),
            "{label}: {:?} {:?}",
            a.error,
            b.error
        );
        assert_eq!(a.points.len(), b.points.len(), "{label}");
        let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= 1e-6 * scale;
        for (p, q) in a.points.iter().zip(&b.points) {
            assert!(
                close(p.compression_ratio, q.compression_ratio, 1.0),
                "{label}: eps {} vs {}",
                p.compression_ratio,
                q.compression_ratio
            );
            assert!(close(p.parameter, q.parameter, 1.0));
            assert!(close(p.height * s, q.height, p.height * s), "{label}: h");
            for k in 0..3 {
                assert!(
                    close(p.load[k], q.load[k], 1.0),
                    "{label}, step {}: {:?} vs {:?}",
                    p.step,
                    p.load,
                    q.load
                );
            }
            let e_scale = p.energy.abs().max(1e-6);
            assert!(
                close(p.energy * s, q.energy, e_scale * s),
                "{label}: energy {} vs {}",
                p.energy,
                q.energy
            );
            for (ra, rb) in p.reactions.iter().zip(&q.reactions) {
                let f = ra.tip.force.iter().map(|v| v.abs()).fold(1e-3, f64::max);
                let m = ra.tip.moment.iter().map(|v| v.abs()).fold(1e-3, f64::max);
                for k in 0..3 {
                    assert!(close(ra.tip.force[k], rb.tip.force[k], f), "{label}: force");
                    assert!(
                        close(ra.tip.moment[k] * s, rb.tip.moment[k], m * s),
                        "{label}: moment {:?} vs {:?}",
                        ra.tip.moment,
                        rb.tip.moment
                    );
                }
            }
            let (sa, sb) = (p.stability.expect("judged"), q.stability.expect("judged"));
            assert_eq!(sa.unstable_directions, sb.unstable_directions, "{label}");
            if let (Some(la), Some(lb)) = (sa.lowest_eigenvalue, sb.lowest_eigenvalue) {
                // relative to the spectrum's scale (past a bifurcation it is near zero)
                let scale = a.points[0]
                    .stability
                    .and_then(|x| x.lowest_eigenvalue)
                    .expect("at rest")
                    .max(la.abs());
                assert!(
                    (la - lb).abs() <= 1e-8 * scale,
                    "{label}, step {}: lowest eigenvalue {la} vs {lb}",
                    p.step
                );
            } else {
                assert_eq!(sa.lowest_eigenvalue, sb.lowest_eigenvalue, "{label}");
            }
        }
        // the final shape: positions scaled by s, curvatures by 1/s
        for (ra, rb) in a.snapshot.rods.iter().zip(&b.snapshot.rods) {
            assert_eq!(ra.nodes.len(), rb.nodes.len());
            for (na, nb) in ra.nodes.iter().zip(&rb.nodes) {
                assert!(close(na.s * s, nb.s, a_case.geometry.length * s));
                for k in 0..3 {
                    assert!(close(
                        na.position[k] * s,
                        nb.position[k],
                        a_case.geometry.length * s
                    ));
                    assert!(close(na.curvature[k] / s, nb.curvature[k], 100.0 / s));
                }
            }
        }
        // the same critical points at the same ε (none when clamped; the sliding tips'
        // bifurcation near ε = 0.135)
        assert_eq!(a.critical.len(), b.critical.len(), "{label}");
        for (ca, cb) in a.critical.iter().zip(&b.critical) {
            assert_eq!(ca.kind, cb.kind);
            assert_eq!(
                (ca.unstable_before, ca.unstable_after),
                (cb.unstable_before, cb.unstable_after)
            );
            assert!(
                close(ca.compression_ratio, cb.compression_ratio, 1.0),
                "{label}: {} vs {}",
                ca.compression_ratio,
                cb.compression_ratio
            );
            for k in 0..3 {
                assert!(close(ca.load[k], cb.load[k], 1.0));
            }
        }
        if label == "tip slides" {
            assert_eq!(a.critical.len(), 1, "the sliding tips' bifurcation");
            assert!(
                (a.critical[0].compression_ratio - 0.1353).abs() < 1e-3,
                "{}",
                a.critical[0].compression_ratio
            );
        } else {
            assert!(a.critical.is_empty());
            let last = b.points.last().expect("points");
            assert!((last.load[2] - -3.082).abs() < 1e-3, "{}", last.load[2]);
        }
    }
}

/// Four extension cases pass a limit point short of their target ε = −0.5 (the tube,
/// pulled, stiffens until it folds back): under displacement control each ends at its fold
/// — named as the reason, located, the last state written — and never writes a state with
/// ε outside [target, 0] or the tip at or below the base. The error quotes the case's
/// target, not the output step on the way.
#[test]
fn extension_paths_stop_at_their_folds_and_stay_physical() {
    use spira::results::CriticalKind;
    use spira::solver::continuation::StopReason;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/hypotheses");
    for (name, fold_eps) in [
        ("n8-straight-clamped-extension", -0.342795),
        ("n8-straight-slide-extension", -0.365177),
        ("n8-sadowsky-clamped-extension", -0.312967),
        ("n8-sadowsky-slide-extension", -0.236140),
    ] {
        let case = Case::from_file(&root.join(format!("{name}.toml"))).expect("shipped case");
        let target = case.loading.target;
        let eps = case.output_parameters(target, case.loading.steps);
        let out = run_path(&case, &eps, |_, _| {}).expect(name);
        let err = out
            .error
            .unwrap_or_else(|| panic!("{name}: reached its target"));
        let StopReason::Fold { parameter } = err.reason else {
            panic!("{name}: stopped for another reason: {err}");
        };
        assert_eq!(err.target, target, "{name}: {err}");
        assert!(
            err.to_string().contains("target -0.500000"),
            "{name}: {err}"
        );
        for p in &out.points {
            assert!(
                p.height > 0.0 && (target..=0.0).contains(&p.compression_ratio),
                "{name}: step {} at eps = {}, h = {}",
                p.step,
                p.compression_ratio,
                p.height
            );
        }
        let fold = out.critical.last().expect("the fold is listed");
        assert_eq!(fold.kind, CriticalKind::LimitPoint, "{name}");
        assert_eq!(fold.parameter, parameter, "{name}");
        assert!(
            (fold.compression_ratio - fold_eps).abs() < 1e-5,
            "{name}: fold at eps = {}",
            fold.compression_ratio
        );
        let last = out.points.last().expect("points");
        assert!(
            (last.compression_ratio - fold.compression_ratio).abs() < 1e-12,
            "{name}: the path ends at eps = {}, the fold is at {}",
            last.compression_ratio,
            fold.compression_ratio
        );
    }
}

/// Under a compressive dead load far past its limit point the spring of thesis n = 1 is
/// carried through flat: the path stops before a state with the tip at or below the base,
/// says why, and keeps the states above it.
#[test]
fn a_load_controlled_path_stops_before_the_tip_reaches_the_base() {
    use spira::solver::continuation::StopReason;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/thesis-n1.toml");
    let text = std::fs::read_to_string(&path)
        .expect("shipped case")
        .replace("target = 0.5 ", "control = \"force\"\ntarget = 40.0 ")
        .replace("elements = 48 ", "elements = 16 ");
    let case = Case::parse(&text, "force.toml", "force").expect("valid");
    let targets = case.output_parameters(40.0, 10);
    let out = run_path(&case, &targets, |_, _| {}).expect("path");
    let err = out.error.expect("short of its target");
    assert!(
        matches!(err.reason, StopReason::LeftDomain { why } if why.contains("base")),
        "{err}"
    );
    assert_eq!(err.target, 40.0, "{err}");
    let last = out.points.last().expect("points");
    assert!(last.compression_ratio > 0.9, "{}", last.compression_ratio);
    for p in &out.points {
        assert!(p.height > 0.0, "step {}: h = {}", p.step, p.height);
    }
}
