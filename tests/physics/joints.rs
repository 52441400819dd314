//! Welded and elastic joints against numbers that do not come from spira: central
//! differences of the discrete system, the limits of the springs (none: the pin; stiff: the
//! weld), the work of the supports against the energy stored (composite Simpson), the
//! balance of moments at a crossing, and the symmetric pair against the full model.

use nalgebra::Vector3;
use spira::case::Case;
use spira::discretisation::system::System;
use spira::model::boundary::{JointStiffness, Joints};
use spira::results::{CriticalPoint, LoadPoint};
use spira::simulation::Simulation;

/// The thesis tube of `n` helices over 3.5 turns on a coarse mesh, compressed to `target`
/// in `steps` output steps, with joints `joints`.
fn tube(n: usize, elements: usize, target: f64, steps: usize, joints: Joints) -> Case {
    let text = format!(
        "[geometry]\nhelices = {n}\n[loading]\ntarget = {target}\nsteps = {steps}\n[discretisation]\nelements = {elements}\n"
    );
    let mut case = Case::parse(&text, "joints.toml", "joints").unwrap_or_else(|e| panic!("{e}"));
    case.boundary.joints = joints;
    case
}

fn springs(k: f64) -> Joints {
    Joints::Elastic(JointStiffness {
        scissor: k,
        out_of_plane: k,
    })
}

/// The load points at the case's output steps, and the critical points found on the way.
fn path(case: &Case) -> (Vec<LoadPoint>, Vec<CriticalPoint>) {
    let mut sim = Simulation::from_case_on(case, 1).unwrap_or_else(|e| panic!("{e}"));
    let mut points = vec![sim.load_point(0)];
    for k in 1..=case.loading.steps {
        let target = case.loading.target * k as f64 / case.loading.steps as f64;
        sim.advance_to(target).unwrap_or_else(|e| panic!("{e}"));
        points.push(sim.load_point(k));
    }
    (points, sim.critical_points().to_vec())
}

/// Two paths agree to `tol` relative: load, energy, and critical points (same kinds and
/// counts, same load parameters).
fn same_paths(a: &Case, b: &Case, tol: f64, what: &str) {
    let ((pa, ca), (pb, cb)) = (path(a), path(b));
    for (x, y) in pa.iter().zip(&pb).skip(1) {
        let fz = x.load[2].abs();
        assert!(
            (x.load[2] - y.load[2]).abs() <= tol * fz,
            "{what}, step {}: fz {} vs {}",
            x.step,
            x.load[2],
            y.load[2]
        );
        assert!(
            (x.energy - y.energy).abs() <= tol * x.energy,
            "{what}, step {}: energy {} vs {}",
            x.step,
            x.energy,
            y.energy
        );
    }
    assert_eq!(ca.len(), cb.len(), "{what}: critical points");
    for (x, y) in ca.iter().zip(&cb) {
        assert_eq!(x.kind, y.kind, "{what}");
        assert_eq!(
            (x.unstable_before, x.unstable_after),
            (y.unstable_before, y.unstable_after)
        );
        assert!(
            (x.parameter - y.parameter).abs() <= tol * x.parameter,
            "{what}: critical point at {} vs {}",
            x.parameter,
            y.parameter
        );
    }
}

/// The KKT matrix against central differences of the residual, and the residual's primal
/// rows (multipliers zero) against central differences of the energy, at a perturbed state
/// with the joints `joints` on n = 2.
fn check_derivatives(joints: Joints) {
    let case = tube(2, 8, 0.1, 1, joints);
    let model = case.model();
    let x0 = model.natural_state();
    let sys = System::new(&model, case.boundary, &x0, &case.loads(), 0.0);
    assert!(!sys.rotations.is_empty());
    let mut x = x0;
    x.resize(sys.n, 0.0);
    let np = model.n_primal;
    for (i, v) in x.iter_mut().enumerate() {
        let noise = ((i * 7919 + 13) % 1009) as f64 / 1009.0 - 0.5;
        *v += if i < np { 0.05 * noise } else { 3.0 * noise };
    }
    // the joints' quaternions and the welds' multipliers
    let mut columns: Vec<usize> = Vec::new();
    for (i, rot) in sys.rotations.iter().enumerate() {
        columns.extend(rot.dofs);
        columns.extend(sys.rotation_row(i)..sys.rotation_row(i) + rot.rows());
    }
    let (worst, scale) = crate::kkt_against_differences(&sys, &model, &x, columns);
    let h = 1e-6;
    assert!(
        worst < 1e-6 * scale,
        "{joints:?}: KKT against differences {worst:e} (scale {scale:e})"
    );
    // the energy's gradient: the residual's primal rows with no multipliers
    let mut y = x.clone();
    y[np..].fill(0.0);
    let mut r = vec![0.0; sys.n];
    let energy_at = |z: &[f64]| {
        let mut out = vec![0.0; sys.n];
        sys.residual(&model, z, &mut out).energy
    };
    sys.residual(&model, &y, &mut r);
    let mut worst: f64 = 0.0;
    for rot in &sys.rotations {
        for &d in &rot.dofs {
            let (mut yp, mut ym) = (y.clone(), y.clone());
            yp[d] += h;
            ym[d] -= h;
            let fd = (energy_at(&yp) - energy_at(&ym)) / (2.0 * h);
            worst = worst.max((fd - r[d]).abs() / r[d].abs().max(1.0));
        }
    }
    assert!(
        worst < 1e-7,
        "{joints:?}: gradient against differences {worst:e}"
    );
}

#[test]
fn joint_terms_are_the_derivatives_of_springs_and_welds() {
    check_derivatives(Joints::Elastic(JointStiffness {
        scissor: 3.0,
        out_of_plane: 0.7,
    }));
    check_derivatives(Joints::Welded);
}

#[test]
fn elastic_joints_without_springs_are_pins() {
    for (n, elements, target, steps) in [(2, 24, 0.5, 10), (8, 24, 0.5, 5)] {
        same_paths(
            &tube(n, elements, target, steps, Joints::Pin),
            &tube(n, elements, target, steps, springs(0.0)),
            1e-9,
            &format!("n = {n}, no springs"),
        );
    }
}

/// Springs of `1e6 B1/L` about every axis give the welded path on n = 2. On n = 8 the
/// crossings are so close (rod segments of about `L/50` between them, bending stiffness
/// `B1/h ≈ 50 B1/L` on each side) that the springs' compliance `1/k` still shows at `1e-4`
/// there; stiffer springs are out of reach (their residual at rest is `k` times the rounding
/// of the relative rotation, above Newton's tolerance from about `1e6 B1/L`). So on n = 8 the
/// springs must approach the weld as `1/k`: the differences at `1e5` and `1e6 B1/L` are in
/// the ratio 10, and the limit extrapolated from them (Richardson) is the welded path to 1e-5.
#[test]
fn stiff_elastic_joints_are_welded() {
    let welded = tube(2, 24, 0.5, 10, Joints::Welded);
    let unit = welded.stiffness.b1 / welded.geometry.length;
    same_paths(
        &welded,
        &tube(2, 24, 0.5, 10, springs(1e6 * unit)),
        1e-5,
        "n = 2, springs of 1e6 B1/L",
    );
    let (target, steps) = (0.5, 5);
    let (pw, cw) = path(&tube(8, 24, target, steps, Joints::Welded));
    let (p5, c5) = path(&tube(8, 24, target, steps, springs(1e5 * unit)));
    let (p6, c6) = path(&tube(8, 24, target, steps, springs(1e6 * unit)));
    assert_eq!((cw.len(), c5.len()), (c6.len(), c6.len()));
    for ((w, a), b) in pw.iter().zip(&p5).zip(&p6).skip(1) {
        for (name, fw, f5, f6) in [
            ("fz", w.load[2], a.load[2], b.load[2]),
            ("energy", w.energy, a.energy, b.energy),
        ] {
            let ratio = (fw - f5) / (fw - f6);
            assert!(
                (ratio - 10.0).abs() < 0.1,
                "n = 8, step {}: {name} ratio {ratio}",
                w.step
            );
            let limit = f6 + (f6 - f5) / 9.0;
            assert!(
                (limit - fw).abs() < 1e-5 * fw.abs(),
                "n = 8, step {}: {name} {limit} vs welded {fw}",
                w.step
            );
        }
    }
}

#[test]
fn welded_joints_make_another_tube_than_pins() {
    let (pin, _) = path(&tube(8, 24, 0.2, 2, Joints::Pin));
    let (welded, _) = path(&tube(8, 24, 0.2, 2, Joints::Welded));
    let (p, w) = (pin[2].load[2], welded[2].load[2]);
    // the weld keeps the scissor angle: the rods must bend instead of turning at the crossings
    assert!(w < 2.0 * p && p < 0.0, "fz/(n Pcrit): pin {p}, welded {w}");
}

#[test]
fn energy_stored_is_the_work_of_the_supports_along_welded_and_elastic_paths() {
    for joints in [Joints::Welded, springs(0.3)] {
        let case = tube(8, 24, 0.1, 40, joints);
        let (points, _) = path(&case);
        let (energy, work, rel) = crate::energy_and_tip_work(&points);
        assert!(
            rel < 1e-8,
            "{joints:?}: energy {energy} J, work {work} J ({rel:e})"
        );
    }
}

#[test]
fn a_welded_pair_at_its_natural_state_carries_no_joint_moment() {
    let case = tube(2, 24, 0.1, 1, Joints::Welded);
    let sim = Simulation::from_case_on(&case, 1).unwrap();
    let unit = case.stiffness.b1 / case.geometry.length;
    let snapshot = sim.snapshot();
    let mut seen = 0;
    for rod in &snapshot.rods {
        for j in &rod.joint_states {
            let m = Vector3::from(j.moment).norm();
            assert!(m < 1e-12 * unit, "rod {} s = {}: {m} N m", rod.rod, j.s);
            assert!(Vector3::from(j.rotation).norm() < 1e-12);
            seen += 1;
        }
    }
    assert!(seen >= 8, "{seen} joint rows");
}

/// Under compression, at every crossing inside the rods: the rod's internal moments on
/// either side and the joint's moment balance, `m(s⁺) − m(s⁻) + M = 0`, and the joint's
/// moments on its two rods are opposite — all read from the joints' table.
#[test]
fn joint_moments_balance_the_rods_internal_moments_at_every_crossing() {
    for (n, joints) in [(2, Joints::Welded), (8, Joints::Welded), (8, springs(0.3))] {
        let case = tube(n, 24, 0.3, 3, joints);
        let mut sim = Simulation::from_case_on(&case, 1).unwrap();
        for k in 1..=3 {
            sim.advance_to(0.1 * k as f64).unwrap();
        }
        let snapshot = sim.snapshot();
        let text = spira::output::joints_csv("balance", &snapshot);
        let rows: Vec<Vec<f64>> = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .skip(1)
            .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
            .collect();
        let scale = rows
            .iter()
            .map(|r| Vector3::new(r[9], r[10], r[11]).norm())
            .fold(0.0, f64::max);
        let length = case.geometry.length;
        let mut checked = 0;
        for r in rows
            .iter()
            .filter(|r| r[1] > 1e-9 * length && r[1] < length * (1.0 - 1e-9))
        {
            let joint = Vector3::new(r[6], r[7], r[8]);
            let before = Vector3::new(r[9], r[10], r[11]);
            let after = Vector3::new(r[12], r[13], r[14]);
            let imbalance = (after - before + joint).norm();
            assert!(
                imbalance < 1e-8 * scale,
                "n = {n}, rod {} s = {}: {imbalance:e} N m (scale {scale:e})",
                r[0],
                r[1]
            );
            assert!(
                joint.norm() > 1e-6 * scale,
                "a joint moment under compression"
            );
            checked += 1;
        }
        assert!(checked >= 2 * n, "n = {n}: {checked} rows");
        // action and reaction: the two rows of a crossing at the same point in space
        let own = sim.model();
        if own.assembly.symmetry.is_none() {
            let sum: Vector3<f64> = rows
                .iter()
                .filter(|r| r[1] > 1e-9 * length && r[1] < length * (1.0 - 1e-9))
                .map(|r| Vector3::new(r[6], r[7], r[8]))
                .sum();
            assert!(sum.norm() < 1e-8 * scale, "n = {n}: Σ joint moments {sum}");
        }
    }
}

#[test]
fn symmetric_pair_reproduces_the_full_welded_assembly() {
    for joints in [Joints::Welded, springs(0.3)] {
        let mut full = tube(8, 24, 0.3, 3, joints);
        full.discretisation.symmetric = false;
        let mut pair = full.clone();
        pair.discretisation.symmetric = true;
        let ((pf, cf), (pp, cp)) = (path(&full), path(&pair));
        for (a, b) in pf.iter().zip(&pp).skip(1) {
            assert!((a.load[2] - b.load[2]).abs() < 1e-9 * a.load[2].abs());
            assert!((a.energy - b.energy).abs() < 1e-9 * a.energy);
            let (sa, sb) = (a.stability.unwrap(), b.stability.unwrap());
            assert_eq!(sa.unstable_directions, sb.unstable_directions);
            let (la, lb) = (sa.lowest_eigenvalue.unwrap(), sb.lowest_eigenvalue.unwrap());
            assert!(
                (la - lb).abs() < 1e-6 * la.abs(),
                "{joints:?}: {la} vs {lb}"
            );
        }
        assert_eq!(cf.len(), cp.len());
    }
}

/// The Bloch blocks of a welded or sprung pair against the full model at perturbed states
/// (multipliers too): the joints' couplings between the two quaternions carry the phases.
/// n = 8 with sliding tips, past the sway of the pins' tube.
#[test]
fn bloch_blocks_of_welded_and_elastic_pairs_count_the_full_models_unstable_directions() {
    for joints in [Joints::Welded, springs(0.3)] {
        let mut case = tube(8, 24, 0.3, 3, joints);
        case.discretisation.symmetric = true;
        case.boundary.tip.translation = spira::model::boundary::Translation::Slide;
        let mut sim = Simulation::from_case_on(&case, 1).unwrap();
        for k in 1..=3 {
            sim.advance_to(0.1 * k as f64).unwrap();
        }
        let x0 = sim.state().to_vec();
        let np = sim.model().n_primal;
        for (k, amplitude) in [0.0, 1e-3].into_iter().enumerate() {
            let x: Vec<f64> = x0
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let wiggle = ((i * 7919 + k * 104_729) % 1000) as f64 / 1000.0 - 0.5;
                    if i < np {
                        v + amplitude * wiggle
                    } else {
                        v * (1.0 + 10.0 * amplitude * wiggle)
                    }
                })
                .collect();
            let (counted, full_count, lowest, full_lowest) =
                super::symmetry::blocks_against_full(&case, &x);
            assert_eq!(counted, full_count, "{joints:?}, amplitude {amplitude}");
            assert!(
                (lowest - full_lowest).abs() < 1e-8 * full_lowest.abs(),
                "{joints:?}, amplitude {amplitude}: {lowest} vs {full_lowest}"
            );
        }
    }
}

/// The thesis n = 8 tube (48 elements per rod) compressed to ε = 0.5 in 10 steps with
/// joints `joints`: its simulation there.
fn compressed(joints: Joints) -> Simulation {
    let case = tube(8, 48, 0.5, 10, joints);
    let mut sim = Simulation::from_case_on(&case, 1).unwrap_or_else(|e| panic!("{e}"));
    for k in 1..=10 {
        sim.advance_to(0.05 * k as f64)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    sim
}

#[test]
fn crossings_changed_at_half_height_take_the_state_of_the_new_kinds_own_path() {
    // welded at ε = 0.5, loosened to springs of B1/L: Newton's method from the welded state
    // does not find the elastic equilibrium, so the simulation follows the elastic tube's
    // path from rest; its state is that of the elastic tube compressed from rest
    let length = tube(8, 48, 0.5, 10, Joints::Pin).geometry.length;
    let elastic = springs(1.0 / length);
    let mut changed = compressed(Joints::Welded);
    let welded = changed.load_point(0);
    changed
        .set_boundary_conditions(spira::model::boundary::BoundaryConditions {
            joints: elastic,
            ..changed.boundary_conditions()
        })
        .unwrap_or_else(|e| panic!("{e}"));
    let (got, want) = (changed.load_point(0), compressed(elastic).load_point(0));
    assert!((got.compression_ratio - 0.5).abs() < 1e-12);
    assert!(
        (got.load[2] - want.load[2]).abs() < 1e-9 * want.load[2].abs(),
        "fz {} vs {}",
        got.load[2],
        want.load[2]
    );
    assert!(
        (got.energy - want.energy).abs() < 1e-9 * want.energy,
        "energy {} vs {}",
        got.energy,
        want.energy
    );
    assert!(got.load[2].abs() < 0.2 * welded.load[2].abs());
    // sliding crossings' own path stops where two crossings of one rod meet, short of
    // ε = 0.5: the change is refused, the error says where, and the state stays the
    // elastic one
    let error = changed
        .set_boundary_conditions(spira::model::boundary::BoundaryConditions {
            joints: Joints::Sliding,
            ..changed.boundary_conditions()
        })
        .expect_err("the sliding tube does not reach ε = 0.5");
    assert!(
        (error.reached - 0.335824).abs() < 1e-5,
        "stopped at {}",
        error.reached
    );
    assert!((error.compression_ratio - 0.5).abs() < 1e-12);
    assert_eq!(changed.boundary_conditions().joints, elastic);
    let kept = changed.load_point(0);
    assert_eq!(kept.load, got.load);
    assert_eq!(kept.energy, got.energy);
}
