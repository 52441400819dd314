//! Stability, critical points and branch switching, checked against Euler's column and the
//! elastica (closed forms computed here, independently of spira), and the behaviour of the
//! continuation where Newton fails.

use spira::case::Case;
use spira::discretisation::discrete_model::DiscreteModel;
use spira::model::boundary::BoundaryConditions;
use spira::model::loading::Control;
use spira::results::CriticalKind;
use spira::run::run_path;
use spira::simulation::Simulation;
use spira::solver::continuation::{ContinuationSettings, StopReason};
use spira::solver::linear::LinearError;
use spira::solver::newton::NewtonError;
use std::f64::consts::PI;
use std::path::Path;

fn case(name: &str) -> Case {
    Case::from_file(Path::new(&format!("cases/{name}.toml"))).unwrap()
}

/// Complete elliptic integrals `K(m)`, `E(m)` (parameter `m = k²`) by the arithmetic–
/// geometric mean (Abramowitz & Stegun 17.6).
fn elliptic_ke(m: f64) -> (f64, f64) {
    let (mut a, mut g) = (1.0f64, (1.0 - m).sqrt());
    let mut c2_sum = m / 2.0; // Σ 2^(n−1) c_n², c_0² = m
    let mut pow = 0.5;
    for _ in 0..60 {
        let c = (a - g) / 2.0;
        pow *= 2.0;
        c2_sum += pow * c * c;
        let an = (a + g) / 2.0;
        g = (a * g).sqrt();
        a = an;
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - c2_sum))
}

/// Clamped–clamped elastica (docs/theory.md §6): `P/Pcr = (2K(m)/π)²` at end-shortening
/// `δ/L = 2 (1 − E(m)/K(m))`; solved for `m` by bisection.
fn elastica_load(shortening: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 0.9999);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let (k, e) = elliptic_ke(mid);
        if 2.0 * (1.0 - e / k) < shortening {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (k, _) = elliptic_ke(0.5 * (lo + hi));
    (2.0 * k / PI).powi(2)
}

#[test]
fn elliptic_integrals_match_tabulated_values() {
    // A&S table 17.1: K(0.5) = 1.854074677, E(0.5) = 1.350643881
    let (k, e) = elliptic_ke(0.5);
    assert!((k - 1.854_074_677_301_372).abs() < 1e-12);
    assert!((e - 1.350_643_881_047_675).abs() < 1e-12);
    assert!((elastica_load(0.0) - 1.0).abs() < 1e-9);
}

fn run_to_target(case: &Case) -> Simulation {
    let mut sim = Simulation::from_case(case).expect("start");
    let targets = case.output_parameters(case.loading.target, case.loading.steps);
    for t in targets {
        sim.advance_to(t).expect("fundamental path");
    }
    sim
}

#[test]
fn clamped_euler_column_bifurcates_at_four_pi_squared_b_over_l_squared() {
    let c = case("euler-clamped");
    let sim = run_to_target(&c);
    let cps = sim.critical_points();
    // P/Pcrit with Pcrit = 4π²B/L²: the first critical load is 1
    let first = &cps[0];
    assert!(
        (first.parameter - 1.0).abs() < 1e-5,
        "P/Pcr = {}",
        first.parameter
    );
    assert_eq!(first.kind, CriticalKind::Bifurcation);
    // B1 = B2: the mode is double, which the count of unstable directions sees
    assert_eq!((first.unstable_before, first.unstable_after), (0, 2));
    // clamped–clamped mode: lateral deflection ∝ 1 − cos(2π s/L)
    let model = &sim.model();
    let rod = &model.rods[0];
    let l = model.length();
    let lateral: Vec<(f64, [f64; 2])> = rod
        .mesh
        .vertices
        .iter()
        .enumerate()
        .map(|(v, &s)| {
            (
                s,
                [first.mode[rod.r_dof(v, 0)], first.mode[rod.r_dof(v, 1)]],
            )
        })
        .collect();
    let (_, peak) = lateral
        .iter()
        .max_by(|a, b| a.1[0].hypot(a.1[1]).total_cmp(&b.1[0].hypot(b.1[1])))
        .unwrap();
    let amplitude = peak[0].hypot(peak[1]);
    let dir = [peak[0] / amplitude, peak[1] / amplitude];
    for (s, d) in &lateral {
        let w = (d[0] * dir[0] + d[1] * dir[1]) / amplitude;
        let exact = (1.0 - (2.0 * PI * s / l).cos()) / 2.0;
        assert!((w - exact).abs() < 1e-3, "mode at s = {s}: {w} vs {exact}");
        // and in one plane
        assert!((d[0] * dir[1] - d[1] * dir[0]).abs() < 1e-6 * amplitude);
    }
}

#[test]
fn on_the_fundamental_branch_the_next_critical_load_is_the_antisymmetric_one() {
    // antisymmetric clamped–clamped mode: tan(x) = x, P = 4x²B/L² (8.183 π² B/L²)
    let mut x: f64 = 4.49;
    for _ in 0..50 {
        x -= (x.tan() - x) / (1.0 / x.cos().powi(2) - 1.0);
    }
    let exact = 4.0 * x * x / (4.0 * PI * PI);
    assert!((exact * 4.0 - 8.183).abs() < 1e-3);
    let sim = run_to_target(&case("euler-clamped"));
    let second = &sim.critical_points()[1];
    assert_eq!(second.kind, CriticalKind::Bifurcation);
    assert_eq!((second.unstable_before, second.unstable_after), (2, 4));
    assert!(
        (second.parameter - exact).abs() < 1e-5 * exact,
        "{} vs {exact}",
        second.parameter
    );
}

#[test]
fn pinned_euler_column_bifurcates_at_pi_squared_b_over_l_squared() {
    let sim = run_to_target(&case("euler-pinned"));
    let first = &sim.critical_points()[0];
    // π²B/L² over Pcrit = 4π²B/L²
    assert!(
        (first.parameter - 0.25).abs() < 1e-5 * 0.25,
        "{}",
        first.parameter
    );
    assert_eq!(first.kind, CriticalKind::Bifurcation);
    assert_eq!(first.unstable_after, 2);
    // the second pinned–pinned load is 4π²B/L²
    assert!((sim.critical_points()[1].parameter - 1.0).abs() < 1e-5);
}

#[test]
fn after_branch_switching_the_column_follows_the_elastica() {
    let c = case("elastica");
    let targets = c.output_parameters(c.loading.target, c.loading.steps);
    let out = run_path(&c, &targets, |_, _| {}).expect("path");
    assert!(out.error.is_none(), "{:?}", out.error);
    assert_eq!(out.switched_at, Some(0));
    let mut checked = 0;
    let mut furthest: f64 = 0.0;
    for p in &out.points {
        let shortening = p.compression_ratio; // h0 = L for a straight rod
        if shortening < 1e-3 {
            continue; // still on (or at) the straight branch
        }
        let expected = elastica_load(shortening);
        let load = -p.load[2];
        assert!(
            (load - expected).abs() < 1e-3 * expected,
            "δ/L = {shortening}: P/Pcr = {load} vs elastica {expected}"
        );
        // the first post-buckled branch is stable
        assert_eq!(p.stability.map(|s| s.unstable_directions), Some(0));
        checked += 1;
        furthest = furthest.max(shortening);
    }
    assert!(
        checked >= 5 && furthest >= 0.2,
        "{checked} points up to δ/L = {furthest}"
    );
}

#[test]
fn thesis_assemblies_of_one_four_and_eight_helices_stay_stable_to_half_height() {
    for n in [1, 4, 8] {
        let c = case(&format!("thesis-n{n}"));
        let targets = c.output_parameters(c.loading.target, c.loading.steps);
        let out = run_path(&c, &targets, |_, _| {}).expect("path");
        assert!(out.error.is_none());
        assert!(
            out.critical.is_empty(),
            "n = {n}: {:?}",
            out.critical
                .iter()
                .map(|c| c.compression_ratio)
                .collect::<Vec<_>>()
        );
        for p in &out.points {
            let st = p.stability.expect("stability tracked");
            assert!(st.is_stable(), "n = {n} at eps = {}", p.compression_ratio);
            assert!(st.lowest_eigenvalue.is_some_and(|l| l > 0.0));
        }
    }
}

#[test]
fn two_helices_leave_the_symmetric_path_at_a_bifurcation_onto_a_stable_softer_branch() {
    let fundamental = case("thesis-n2");
    let targets = fundamental.output_parameters(0.5, 10);
    let stay = run_path(&fundamental, &targets, |_, _| {}).unwrap();
    let first = &stay.critical[0];
    assert_eq!(first.kind, CriticalKind::Bifurcation);
    assert_eq!((first.unstable_before, first.unstable_after), (0, 1));
    assert!(
        first.compression_ratio > 0.3 && first.compression_ratio < 0.4,
        "{}",
        first.compression_ratio
    );
    let end = stay.points.last().unwrap();
    assert!(!end.stability.unwrap().is_stable());
    // switching in either direction gives mirror-image states of equal energy and load
    let mut switch = fundamental.clone();
    switch.loading.branch = spira::model::loading::Branch::Switch;
    let plus = run_path(&switch, &targets, |_, _| {}).unwrap();
    switch.loading.branch = spira::model::loading::Branch::SwitchNegative;
    let minus = run_path(&switch, &targets, |_, _| {}).unwrap();
    let (p, m) = (plus.points.last().unwrap(), minus.points.last().unwrap());
    assert!(p.stability.unwrap().is_stable() && m.stability.unwrap().is_stable());
    assert!((p.energy - m.energy).abs() < 1e-6 * p.energy);
    assert!((p.load[2] - m.load[2]).abs() < 1e-6 * p.load[2].abs());
    // at the same compression the stable branch stores less energy and carries less load
    assert!(p.energy < end.energy, "{} vs {}", p.energy, end.energy);
    assert!(p.load[2].abs() < end.load[2].abs());
}

#[test]
fn a_step_far_too_long_is_cut_and_the_path_recovers() {
    let reference = run_to_target(&case("thesis-n1"));
    let mut c = case("thesis-n1");
    c.solver.initial_step = 0.5;
    c.solver.max_step = 0.5;
    c.solver.newton.max_iterations = 6;
    let mut sim = Simulation::from_case(&c).unwrap();
    sim.advance_to(0.5).expect("recovers by cutting the step");
    assert!(sim.statistics().rejected > 0, "{:?}", sim.statistics());
    let (a, b) = (sim.load_point(1), reference.load_point(1));
    for k in 0..3 {
        assert!(
            (a.load[k] - b.load[k]).abs() < 1e-7,
            "{:?} vs {:?}",
            a.load,
            b.load
        );
    }
}

#[test]
fn a_duplicated_joint_is_reported_as_a_singular_system() {
    let mut c = case("thesis-n2");
    // the continuum's reference curvatures, so that the natural state is not already an
    // equilibrium and Newton must factorise the matrix (with the discrete ones it is one
    // exactly, and is accepted before any solve)
    c.discretisation.reference = spira::discretisation::discrete_model::Reference::Continuum;
    let mut model: DiscreteModel = c.model();
    // an interior joint tied twice: two identical constraint rows
    let j = model.assembly.joints[3];
    model.assembly.joints.push(j);
    let x0 = model.natural_state();
    let err = Simulation::from_state(
        model,
        BoundaryConditions::default(),
        Control::Displacement,
        x0,
        ContinuationSettings::default(),
    )
    .err()
    .expect("a singular system cannot be solved");
    match err.reason {
        StopReason::Newton {
            cause:
                NewtonError::Linear {
                    source: LinearError::Singular { .. },
                    ..
                },
            ..
        } => {}
        other => panic!("expected a singular KKT matrix, got {other:?}"),
    }
    assert!(err.to_string().contains("singular"), "{err}");
}

/// Pinned elastica, end-shortening at a load: `P/(π²B/L²) = (2K(m)/π)²` solved for `m` by
/// bisection, then `δ/L = 2(1 − E(m)/K(m))`. `load` is over spira's `Pcrit = 4π²B/L²`.
fn pinned_elastica_shortening(load: f64) -> f64 {
    let k_wanted = PI * load.sqrt(); // 2K/π = √(P/Pe), P/Pe = 4 load
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if elliptic_ke(mid).0 < k_wanted {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (k, e) = elliptic_ke(0.5 * (lo + hi));
    2.0 * (1.0 - e / k)
}

/// The critical points of a run: kind and load parameter.
fn kinds_and_loads(out: &spira::run::PathOutcome) -> Vec<(CriticalKind, f64)> {
    out.critical.iter().map(|c| (c.kind, c.parameter)).collect()
}

/// Euler's pinned column as shipped, switched onto its buckled branch: with B1 = B2 the
/// buckled plane may turn about the axis at no cost, a neutral direction at every state of
/// the branch, which once made the path crawl (thousands of steps, most rejected) or count
/// it as critical at every step. A phase condition holds the plane: the path follows the
/// pinned elastica to 1e-6 in δ/L through the loop (the ends meet at δ = L and pass each
/// other) to P/Pcrit = 2.5 with no step rejected, and no neutral direction is left.
#[test]
fn the_pinned_isotropic_elastica_is_followed_with_its_plane_held() {
    let c = case("euler-pinned");
    let targets = c.output_parameters(c.loading.target, c.loading.steps);
    let out = run_path(&c, &targets, |_, _| {}).expect("path");
    assert!(out.error.is_none(), "{:?}", out.error);
    assert_eq!(out.switched_at, Some(0));
    let last = out.points.last().expect("points");
    assert!((last.parameter - 2.5).abs() < 1e-12, "{}", last.parameter);
    assert_eq!(out.stats.rejected, 0, "{:?}", out.stats);
    let mut checked = 0;
    for p in out.points.iter().filter(|p| p.parameter > 0.25) {
        let expected = pinned_elastica_shortening(p.parameter);
        assert!(
            (p.compression_ratio - expected).abs() < 1e-6,
            "P/Pcrit = {}: δ/L = {} vs the pinned elastica's {expected}",
            p.parameter,
            p.compression_ratio
        );
        // stable in its plane and out of it until the ends meet
        if p.compression_ratio < 1.0 {
            assert_eq!(p.stability.map(|s| s.unstable_directions), Some(0));
        }
        checked += 1;
    }
    assert!(checked >= 20, "{checked}");
    assert!(last.compression_ratio > 1.5, "{}", last.compression_ratio);
    // the double Euler point, then the point where the loop's ends meet (δ = L: E/K = ½,
    // m = 0.826115, P/Pe = 2.18338), where the loop may turn about the meeting point at no
    // cost and loses stability out of its plane; no neutral entry
    let critical = kinds_and_loads(&out);
    assert!(critical
        .iter()
        .all(|(kind, _)| *kind == CriticalKind::Bifurcation));
    assert!((critical[0].1 - 0.25).abs() < 1e-6, "{critical:?}");
    assert_eq!(out.critical[0].unstable_after, 2);
    let meet = &out.critical[1];
    assert!((meet.compression_ratio - 1.0).abs() < 1e-6, "{critical:?}");
    let expected = 0.25 * 2.183_380;
    assert!(
        (meet.parameter - expected).abs() < 1e-5 * expected,
        "{critical:?}"
    );
    assert_eq!((meet.unstable_before, meet.unstable_after), (0, 1));
    // critical.csv lists the points of the path followed whatever the output steps: two
    // output steps pass 0.25 and the straight rod's next point, 1.0, before the switch
    let coarse = run_path(&c, &c.output_parameters(2.5, 2), |_, _| {}).expect("path");
    assert!(coarse.error.is_none(), "{:?}", coarse.error);
    let again = kinds_and_loads(&coarse);
    assert_eq!(again.len(), critical.len(), "{again:?} vs {critical:?}");
    for (a, b) in again.iter().zip(&critical) {
        assert_eq!(a.0, b.0);
        assert!((a.1 - b.1).abs() < 1e-7 * b.1, "{again:?} vs {critical:?}");
    }
}

/// The lowest eigenvalue of the constrained pencil at the simulation's state by a dense
/// solve: `Zᵀ H Z v = μ Zᵀ M Z v` with `Z` an orthonormal basis of the constraints' null
/// space (nalgebra; no regularisation, no iteration).
fn dense_lowest_eigenvalue(sim: &Simulation) -> f64 {
    use nalgebra::{DMatrix, DVector};
    let model = sim.model();
    let system = sim.system();
    let (n, np) = (system.n, model.n_primal);
    let mut residual = vec![0.0; n];
    let mut values = system.new_values();
    system.evaluate(model, sim.state(), &mut residual, &mut values);
    let kkt = system.matrix(&values);
    let mut k_dense = DMatrix::<f64>::zeros(n, n);
    let (cp, ri) = (kkt.symbolic().col_ptr(), kkt.symbolic().row_idx());
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            k_dense[(ri[p], j)] += kkt.val()[p];
        }
    }
    // the metric: each node's quaternion weighted by its tributary arc length
    let metric = crate::rotation_metric(model);
    let h = k_dense.view((0, 0), (np, np)).into_owned();
    let j = k_dense.view((np, 0), (n - np, np)).into_owned();
    let gram = (j.transpose() * &j).symmetric_eigen();
    let top = gram.eigenvalues.max();
    let null: Vec<_> = (0..np)
        .filter(|&i| gram.eigenvalues[i] < 1e-12 * top)
        .map(|i| gram.eigenvectors.column(i).into_owned())
        .collect();
    let z = DMatrix::from_columns(&null);
    let m = DMatrix::from_diagonal(&DVector::from_vec(metric));
    let zmz = (z.transpose() * m * &z).cholesky().expect("ZᵀMZ positive");
    let l_inv = zmz.l().try_inverse().expect("invertible");
    let reduced = &l_inv * (z.transpose() * &h * &z) * l_inv.transpose();
    reduced.symmetric_eigen().eigenvalues.min()
}

/// The lowest eigenvalue that inverse iteration on the regularised KKT matrix reports,
/// against a dense solve of the constrained pencil itself, along the thesis n = 1 path
/// (where the lowest two eigenvalues come within 5 % of each other at ε = 0.3 and then
/// part) from its natural state (the first eigenvalue, found without a history), and at
/// the natural state of the two-helix assembly (full model).
#[test]
fn the_lowest_eigenvalue_is_that_of_a_dense_solve_of_the_constrained_pencil() {
    let mut sim = Simulation::from_case(&case("thesis-n1")).expect("natural state");
    for k in 0..=10 {
        let eps = 0.05 * k as f64;
        if k > 0 {
            sim.advance_to(eps).expect("path");
        }
        let lowest = sim
            .stability()
            .and_then(|s| s.lowest_eigenvalue)
            .expect("computed at an output step");
        let dense = dense_lowest_eigenvalue(&sim);
        assert!(
            (lowest - dense).abs() < 1e-9 * dense.abs(),
            "n = 1, ε = {eps}: {lowest} vs dense {dense}"
        );
    }
    let mut two = case("thesis-n2");
    two.discretisation.symmetric = false;
    let sim = Simulation::from_case(&two).expect("natural state");
    let lowest = sim
        .stability()
        .and_then(|s| s.lowest_eigenvalue)
        .expect("computed at the natural state");
    let dense = dense_lowest_eigenvalue(&sim);
    assert!(
        (lowest - dense).abs() < 1e-9 * dense.abs(),
        "n = 2 at rest: {lowest} vs dense {dense}"
    );
}

/// Greenhill's built-in shaft (B1 = B2) buckles in a plane of any orientation: two
/// eigenvalues cross zero together. The full model reports the point with the count
/// jumping by 2 and multiplicity 2, as the Bloch blocks report theirs.
#[test]
fn the_full_model_reports_a_double_point_with_multiplicity_two() {
    let c = case("straight-twist");
    let targets = c.output_parameters(c.loading.target, c.loading.steps);
    let out = run_path(&c, &targets, |_, _| {}).expect("path");
    assert!(out.error.is_none(), "{:?}", out.error);
    let first = out.critical.first().expect("Greenhill's point");
    assert_eq!(first.kind, CriticalKind::Bifurcation);
    assert_eq!((first.unstable_before, first.unstable_after), (0, 2));
    assert_eq!(first.wavenumber, None, "the full model");
    assert_eq!(first.multiplicity, 2);
    // T L/B = 8.9868 at B3 = 2: phi = 8.9868 / 2
    assert!(
        (first.parameter - 4.4934).abs() < 1e-3,
        "{}",
        first.parameter
    );
}

/// A path does not jump between branches, whatever its steps: n = 2 with sliding tips,
/// compressed under displacement control, turns smoothly near ε ≈ 0.08 from the nearly
/// linear path onto one that bulges (the sliding tip breaks the symmetry that makes the
/// clamped pair's point at 0.342 a pitchfork, so here the branches do not meet): its lowest
/// eigenvalue dips to a seventh of its value at ε = 0.058 and rises again, and the count of
/// unstable directions never changes. Output steps of Δε = 0.05 once let the corrector land
/// on the other, disconnected branch (fz/(n Pcrit) = −1.034 at ε = 0.1 instead of −0.849,
/// one unstable direction, and a "bifurcation" at 0.0842 whose kind changed with the mesh).
#[test]
fn a_path_does_not_jump_branches_whatever_its_steps() {
    for elements in [24, 48, 96] {
        let mut c = Case::from_file(Path::new("cases/thesis-n8.toml"))
            .unwrap()
            .with_helices(2);
        c.boundary.tip.translation = spira::model::boundary::Translation::Slide;
        c.discretisation.elements = elements;
        let mut ends = Vec::new();
        for steps in [2, 20] {
            let out = run_path(&c, &c.output_parameters(0.1, steps), |_, _| {}).expect("path");
            assert!(out.error.is_none(), "{:?}", out.error);
            assert!(out.critical.is_empty(), "{elements}: {:?}", out.critical);
            for p in &out.points {
                let stability = p.stability.expect("stability tracked");
                assert!(stability.is_stable(), "{elements} elements, {steps} steps");
            }
            ends.push(out.points.last().expect("points").load[2]);
        }
        // the same state at ε = 0.1, on the bulging branch: the load has levelled off
        assert!((ends[0] - ends[1]).abs() < 1e-8, "{elements}: {ends:?}");
        assert!((ends[1] + 0.849).abs() < 2e-3, "{elements}: {ends:?}");
    }
}

/// The same point has the same kind at every mesh: the clamped pair's pitchfork (exact by
/// the half-turn that swaps its ends) is a bifurcation 0 → 1 at 24, 48 and 96 elements,
/// converging with the mesh, on a path passed in output steps of Δε = 0.175.
#[test]
fn the_same_point_has_the_same_kind_at_24_48_and_96_elements() {
    let mut found = Vec::new();
    for elements in [24, 48, 96] {
        let mut c = Case::from_file(Path::new("cases/thesis-n2.toml")).unwrap();
        c.discretisation.elements = elements;
        let out = run_path(&c, &c.output_parameters(0.35, 2), |_, _| {}).expect("path");
        assert!(out.error.is_none(), "{:?}", out.error);
        let first = out.critical.first().expect("a critical point").clone();
        assert_eq!(first.kind, CriticalKind::Bifurcation, "{elements} elements");
        assert_eq!((first.unstable_before, first.unstable_after), (0, 1));
        found.push(first.compression_ratio);
    }
    // the same point, converging with the mesh
    assert!((found[0] - found[2]).abs() < 1e-3, "{found:?}");
    assert!(
        (found[1] - found[2]).abs() < (found[0] - found[2]).abs(),
        "{found:?}"
    );
}
