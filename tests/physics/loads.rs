//! Twist, tilt and radial pressure against numbers that do not come from spira: the exact
//! derivatives of the discrete system (central differences), the straight rod in pure
//! bending and pure torsion (closed forms, Greenhill's shaft), the work of the supports
//! against the energy stored, and the pressurised tube against the pantograph's closed form.

use spira::case::Case;
use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::system::System;
use spira::results::LoadPoint;
use spira::simulation::Simulation;
use std::f64::consts::PI;

/// A case from TOML text.
fn case(text: &str) -> Case {
    Case::parse(text, "test.toml", "test").unwrap_or_else(|e| panic!("{e}"))
}

/// The straight rod of the closed forms: n = 1, radius 0, L = 1 m, B1 = B2 = 1, B3 = 2.
fn straight(loading: &str, boundary: &str) -> Case {
    case(&format!(
        "[geometry]\nhelices = 1\nradius = 0.0\nlength = 1.0\n[stiffness]\nb1 = 1.0\nb2 = 1.0\nb3 = 2.0\n[boundary]\n{boundary}\n[loading]\n{loading}\n[discretisation]\nelements = 48\n"
    ))
}

/// The thesis tube of `n` helices over `turns` turns, under `loading`.
fn tube(n: usize, turns: f64, elements: usize, loading: &str) -> Case {
    case(&format!(
        "[geometry]\nhelices = {n}\nradius = 0.06\npitch = 0.025\nturns = {turns}\n[loading]\n{loading}\n[discretisation]\nelements = {elements}\n"
    ))
}

/// `∂R/∂λ` of the system against central differences of the residual in `λ`, and the KKT
/// matrix against central differences of the residual in every unknown, at a state `x`
/// away from equilibrium (multipliers not zero) and at `λ`.
fn check_derivatives(case: &Case, lambda: f64) {
    let model: DiscreteModel = case.model();
    let x0 = model.natural_state();
    let mut sys = System::new(&model, case.boundary, &x0, &case.loads(), 0.0);
    sys.set_parameter(lambda);
    let mut x = x0;
    x.resize(sys.n, 0.0);
    for (i, v) in x.iter_mut().enumerate() {
        let noise = ((i * 7919 + 13) % 1009) as f64 / 1009.0 - 0.5;
        *v += if i < model.n_primal {
            0.01 * noise
        } else {
            3.0 * noise
        };
    }
    let residual_at = |sys: &System, y: &[f64]| {
        let mut r = vec![0.0; sys.n];
        sys.residual(&model, y, &mut r);
        r
    };
    // ∂R/∂λ
    let h = 1e-6;
    let mut analytic = vec![0.0; sys.n];
    sys.load_derivative(&model, &x, lambda, &mut analytic);
    let (mut plus, mut minus) = (sys.clone(), sys.clone());
    plus.set_parameter(lambda + h);
    minus.set_parameter(lambda - h);
    let (rp, rm) = (residual_at(&plus, &x), residual_at(&minus, &x));
    for i in 0..sys.n {
        let fd = (rp[i] - rm[i]) / (2.0 * h);
        assert!(
            (fd - analytic[i]).abs() < 1e-6 * (1.0 + fd.abs()),
            "{}: dR/dλ[{i}] = {} vs finite difference {fd}",
            case.loading.parameter.name(),
            analytic[i]
        );
    }
    // the KKT matrix
    let mut r = vec![0.0; sys.n];
    let mut values = sys.new_values();
    sys.evaluate(&model, &x, &mut r, &mut values);
    let m = sys.matrix(&values);
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    for j in 0..sys.n {
        let (mut xp, mut xm) = (x.clone(), x.clone());
        xp[j] += h;
        xm[j] -= h;
        let (rp, rm) = (residual_at(&sys, &xp), residual_at(&sys, &xm));
        let mut column = vec![0.0; sys.n];
        for p in cp[j]..cp[j + 1] {
            column[ri[p]] += m.val()[p];
        }
        for i in 0..sys.n {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            assert!(
                (fd - column[i]).abs() < 1e-5 * (1.0 + fd.abs()),
                "{}: K[{i}][{j}] = {} vs finite difference {fd}",
                case.loading.parameter.name(),
                column[i]
            );
        }
    }
}

#[test]
fn turning_supports_and_pressure_have_exact_derivatives() {
    let few = |text: &str| text.replace("elements = 48", "elements = 8");
    // twist of a clamped pair, of radially sliding pinned tips, and a tilt of both
    check_derivatives(&tube(2, 1.0, 8, "parameter = \"twist\"\ntarget = 1.0"), 0.7);
    check_derivatives(
        &case(&few(
            "[geometry]\nhelices = 2\nturns = 1.0\n[boundary]\ntip = { translation = \"radial\", rotation = \"pinned\" }\n[loading]\nparameter = \"twist\"\ntarget = 1.0\nhold = { axial = 0.1, tilt = 0.2 }\n[discretisation]\nelements = 48\n",
        )),
        -0.4,
    );
    check_derivatives(
        &tube(
            2,
            1.0,
            8,
            "parameter = \"tilt\"\ntarget = 1.0\nhold = { twist = 0.3 }",
        ),
        0.5,
    );
    // the pressure, with the tips free along the axis and a held twist
    check_derivatives(
        &tube(
            2,
            1.0,
            8,
            "parameter = \"pressure\"\ntarget = 100.0\nhold = { axial_force = 0, twist = 0.2 }",
        ),
        300.0,
    );
}

/// Steps a case's path to each of `values` in turn, with the load point at each.
fn path(case: &Case, values: &[f64]) -> Vec<LoadPoint> {
    let mut sim = Simulation::from_case_on(case, 1).unwrap_or_else(|e| panic!("{e}"));
    values
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            sim.advance_to(v).unwrap_or_else(|e| panic!("{e}"));
            sim.load_point(k + 1)
        })
        .collect()
}

/// Pure bending: base clamped, tip turned by θ about x with its position free. The rod is
/// the circular arc of curvature θ/L, held by the moment B θ/L alone.
#[test]
fn a_straight_rod_turned_at_its_tip_bends_into_an_arc_held_by_b_theta_over_l() {
    let case = straight(
        "parameter = \"tilt\"\ntarget = 3.0\nhold = { axial_force = 0 }",
        "tip = { translation = \"slide\", rotation = \"clamped\" }",
    );
    let thetas = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0];
    let mut sim = Simulation::from_case_on(&case, 1).unwrap();
    for theta in thetas {
        sim.advance_to(theta).unwrap();
        let p = sim.load_point(1);
        let moment = p.support.bending_moment;
        assert!(
            (moment - theta).abs() < 1e-6 * theta,
            "θ = {theta}: M = {moment}, expected B θ/L = {theta}"
        );
        let force: f64 = p.reactions[0].tip.force.iter().map(|f| f * f).sum::<f64>();
        assert!(force.sqrt() < 1e-6, "θ = {theta}: a tip force {force:e}");
        // the arc: a bending curvature θ/L everywhere (about the director that the tilt's
        // axis is), no twist
        let snapshot = sim.snapshot();
        for node in &snapshot.rods[0].nodes {
            let [k1, k2, omega] = node.curvature;
            assert!(
                (k1.hypot(k2) - theta).abs() < 1e-6 * theta && omega.abs() < 1e-6,
                "θ = {theta}: curvature {:?} at s = {}",
                node.curvature,
                node.s
            );
        }
    }
}

/// Pure torsion: both ends clamped, the tip turned by φ about the axis, free along it. The
/// torque is B3 φ/L, and the straight shaft buckles at T L/B = 8.9868, the first root of
/// tan(x/2) = x/2 (Greenhill's built-in shaft), as a double critical point (B1 = B2).
#[test]
fn a_twisted_straight_shaft_carries_b3_phi_over_l_and_buckles_at_greenhills_torque() {
    let case = straight(
        "parameter = \"twist\"\ntarget = 5.0\nsteps = 10\nhold = { axial_force = 0 }",
        "tip = { translation = \"fixed\", rotation = \"clamped\" }",
    );
    let phis: Vec<f64> = (1..=10).map(|k| 0.5 * k as f64).collect();
    let points = path(&case, &phis);
    for (p, phi) in points.iter().zip(&phis) {
        let expected = 2.0 * phi;
        assert!(
            (p.support.torque - expected).abs() < 1e-6 * expected,
            "φ = {phi}: T = {}, expected B3 φ/L = {expected}",
            p.support.torque
        );
    }
    // the critical point: x/2 = 4.4934094579 solves tan(y) = y
    let mut y: f64 = 4.49;
    for _ in 0..50 {
        y -= (y.tan() - y) / (1.0 / y.cos().powi(2) - 1.0);
    }
    let greenhill = 2.0 * y;
    let mut sim = Simulation::from_case_on(&case, 1).unwrap();
    sim.advance_to(5.0).unwrap();
    let c = &sim.critical_points()[0];
    let torque_at = 2.0 * c.parameter;
    assert!(
        (torque_at - greenhill).abs() < 1e-6 * greenhill,
        "critical T L/B = {torque_at}, Greenhill's {greenhill}"
    );
    assert_eq!(
        (c.unstable_before, c.unstable_after),
        (0, 2),
        "a double point"
    );
}

/// The energy stored against the work of the loads along a path of `steps` equal steps to
/// `target`: `∫ T dφ`, `∫ M dθ` or `−n L ∫ q d(radius)`, by composite Simpson.
fn energy_is_work(case: &Case, target: f64, steps: usize) {
    let values: Vec<f64> = (1..=steps)
        .map(|k| target * k as f64 / steps as f64)
        .collect();
    let mut sim = Simulation::from_case_on(case, 1).unwrap();
    let mut points = vec![sim.load_point(0)];
    for &v in &values {
        sim.advance_to(v).unwrap_or_else(|e| panic!("{e}"));
        points.push(sim.load_point(0));
    }
    let n = case.geometry.helices as f64;
    let length = case.geometry.length;
    let h = target / steps as f64;
    let work = match case.loading.parameter {
        spira::model::loading::Component::Twist => crate::simpson(
            &points.iter().map(|p| p.support.torque).collect::<Vec<_>>(),
            h,
        ),
        spira::model::loading::Component::Tilt => crate::simpson(
            &points
                .iter()
                .map(|p| p.support.bending_moment)
                .collect::<Vec<_>>(),
            h,
        ),
        // −n L ∫ q (d radius/dq) dq, d radius/dq by Simpson's partner: integrate by parts,
        // −n L [q radius − ∫ radius dq]
        _ => {
            let last = points.last().unwrap();
            let integral = crate::simpson(
                &points.iter().map(|p| p.support.radius).collect::<Vec<_>>(),
                h,
            );
            -n * length * (last.support.pressure * last.support.radius - integral)
        }
    };
    let energy = points.last().unwrap().energy - points[0].energy;
    assert!(
        (energy - work).abs() < 1e-8 * energy.abs(),
        "{}: energy {energy} vs work {work} (relative {:e})",
        case.loading.parameter.name(),
        (energy - work).abs() / energy.abs()
    );
}

#[test]
fn the_energy_stored_is_the_work_of_twist_tilt_and_pressure() {
    energy_is_work(
        &tube(8, 3.5, 48, "parameter = \"twist\"\ntarget = 0.1"),
        0.1,
        40,
    );
    energy_is_work(
        &tube(8, 3.5, 48, "parameter = \"tilt\"\ntarget = 0.2"),
        0.2,
        40,
    );
    energy_is_work(
        &tube(
            8,
            3.5,
            48,
            "parameter = \"pressure\"\ntarget = 1000.0\nhold = { axial_force = 0 }",
        ),
        1000.0,
        40,
    );
}

/// The pantograph's closed form: uniform helices of c = c0 (pins at fixed material points)
/// with no axial force need the inward line pressure q = [C(τ − τ0) a/b − B(K − K0)]/c² to
/// hold radius a (K = a/c², τ = b/c²). Its check value: a = 0.05 m needs q = 2790.21 N/m.
fn pantograph_pressure(a: f64) -> f64 {
    let (a0, b0): (f64, f64) = (0.06, 0.025);
    let c = a0.hypot(b0);
    let b = (c * c - a * a).sqrt();
    let (k, k0, t, t0) = (a / (c * c), a0 / (c * c), b / (c * c), b0 / (c * c));
    (2.0 * (t - t0) * a / b - (k - k0)) / (c * c)
}

#[test]
fn the_pantographs_closed_form_gives_the_check_value() {
    assert!((pantograph_pressure(0.05) - 2790.21).abs() < 0.01);
    // the library's, against this file's own derivation
    let natural = spira::model::assembly::Assembly::new(8, 0.06, 0.025, 1.0).rods[0];
    let stiffness = spira::model::stiffness::Stiffness {
        b1: 1.0,
        b2: 1.0,
        b3: 2.0,
    };
    use spira::model::pantograph::{pantograph_pressure as library, pantograph_radius};
    for a in [0.055, 0.05, 0.045] {
        assert!((library(&natural, &stiffness, a) - pantograph_pressure(a)).abs() < 1e-9);
    }
    let a = pantograph_radius(&natural, &stiffness, 2790.21).unwrap();
    assert!((a - 0.05).abs() < 1e-7, "{a}");
    // past the branch's largest pressure no radius carries it
    assert!(pantograph_radius(&natural, &stiffness, 4000.0).is_none());
}

/// The mean bulk helix `(a, b)` (m) of the rods at the case's path end, stepped to
/// `target` in `steps` steps.
fn bulk_helix(case: &Case, target: f64, steps: usize) -> (f64, LoadPoint) {
    let mut sim = Simulation::from_case_on(case, 1).unwrap();
    for k in 1..=steps {
        sim.advance_to(target * k as f64 / steps as f64)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let point = sim.load_point(steps);
    let bulk = spira::discretisation::bulk::step_bulk(sim.model(), &sim.snapshot(), &point);
    let a = bulk.rods.iter().map(|r| r.radius).sum::<f64>() / bulk.rods.len() as f64;
    (a, point)
}

/// The closed form's radius at pressure `q`: the root of `pantograph_pressure(a) = q` in
/// (0.03, 0.06) m, where the pressure rises as the radius falls.
fn pantograph_radius(q: f64) -> f64 {
    let (mut lo, mut hi) = (0.03, 0.06);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if pantograph_pressure(mid) > q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The bulk of long pressurised tubes (n = 8, clamped ends free along the axis) tends to
/// the pantograph's uniform helices as 1/L: at 14 and 28 turns, q = 1000 N/m, the error of
/// the bulk radius halves with the length, and at 28 turns the pressure that the closed
/// form gives for the bulk's radius is the applied one within 2 %.
#[test]
fn the_bulk_of_a_long_pressurised_tube_is_the_pantographs_helix() {
    let q = 1000.0;
    let exact = pantograph_radius(q);
    let error = |turns: usize| {
        let case = tube(
            8,
            turns as f64,
            14 * turns,
            &format!("parameter = \"pressure\"\ntarget = {q}\nhold = {{ axial_force = 0 }}"),
        );
        let (a, point) = bulk_helix(&case, q, 4);
        assert!((point.support.pressure - q).abs() < 1e-9 * q);
        (a - exact).abs() / exact
    };
    let (e14, e28) = (error(14), error(28));
    assert!(e28 < 1e-3, "28 turns: bulk radius off by {e28:e}");
    assert!(
        e28 < 0.6 * e14,
        "the error does not fall as 1/L: {e14:e} at 14 turns, {e28:e} at 28"
    );
    let tube28 = tube(
        8,
        28.0,
        392,
        &format!("parameter = \"pressure\"\ntarget = {q}\nhold = {{ axial_force = 0 }}"),
    );
    let (a, point) = bulk_helix(&tube28, q, 4);
    let needed = pantograph_pressure(a);
    assert!((point.support.pressure - q).abs() < 1e-9 * q);
    assert!(
        (needed - q).abs() < 0.02 * q,
        "bulk radius {a} m needs q = {needed} N/m, applied {q}"
    );
}

/// Love's helix of a spring (natural helix (0.06, 0.025), B = 1, C = 2, right-handed)
/// twisted by `per_turn` rad per turn with no axial force: the turns' angle grows by the
/// twist, so `c = c0 / (1 + per_turn/2π)`; `F(a, b) = 0` (docs/theory.md §6) fixes `a` on that
/// `c`; the couple it carries is `M(a, b)`.
fn love_twisted(per_turn: f64) -> f64 {
    let (a0, b0): (f64, f64) = (0.06, 0.025);
    let c0 = a0.hypot(b0);
    let c = c0 / (1.0 + per_turn / (2.0 * PI));
    let (k0, t0) = (a0 / (c0 * c0), b0 / (c0 * c0));
    let wrench = |a: f64| {
        let b = (c * c - a * a).sqrt();
        let (k, t) = (a / (c * c), b / (c * c));
        let f = (2.0 * (t - t0) * a - (k - k0) * b) / (a * c);
        let m = ((k - k0) * a + 2.0 * (t - t0) * b) / c;
        (f, m)
    };
    // F changes sign between a small radius and one close to c
    let (mut lo, mut hi) = (0.5 * c, 0.999 * c);
    let sign_lo = wrench(lo).0.signum();
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if wrench(mid).0.signum() == sign_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    wrench(0.5 * (lo + hi)).1
}

/// A single spring (n = 1; 14, 28 and 56 turns, 40 elements per turn) twisted by 0.05 rad
/// per turn, free along its axis: the torque it carries tends to that of Love's helix, its
/// error at least halving as the length doubles (measured: 7.7e-5, 1.4e-5, 8.4e-7 — the
/// clamped ends' boundary layers are of fixed length and take a share of the twist that
/// falls faster than 1/L).
#[test]
fn a_twisted_spring_tends_to_loves_helix_as_its_length_grows() {
    let per_turn = 0.05;
    let love = love_twisted(per_turn);
    let error = |turns: usize| {
        let twist = per_turn * turns as f64;
        let case = tube(
            1,
            turns as f64,
            40 * turns,
            &format!("parameter = \"twist\"\ntarget = {twist}\nhold = {{ axial_force = 0 }}"),
        );
        let point = path(&case, &[0.5 * twist, twist]).pop().unwrap();
        (point.support.torque - love) / love
    };
    let (e14, e28, e56) = (error(14), error(28), error(56));
    assert!(e56.abs() < 1e-5, "56 turns: torque off Love's by {e56:e}");
    for (short, long) in [(e14, e28), (e28, e56)] {
        // at least as fast as 1/L (the layers' share of the twist falls faster)
        assert!(
            long.abs() < 0.5 * short.abs(),
            "the error does not fall with the length: {e14:e}, {e28:e}, {e56:e}"
        );
    }
}
