//! Sliding joints against numbers that do not come from spira: central differences of the
//! discrete system, the work of the supports against the energy stored (composite Simpson),
//! the symmetry of the thesis geometry, Love's helix of a rod whose crossings all slide, and
//! the bulk of long tubes against the helix of radius a0.

use nalgebra::Vector3;
use spira::case::Case;
use spira::discretisation::system::System;
use spira::model::boundary::{BoundaryConditions, Joints};
use spira::model::helix::Helix;
use spira::model::loading::Control;
use spira::results::{CriticalPoint, LoadPoint};
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;

/// The thesis tube of `n` helices over `turns` turns, compressed to `target` in `steps`
/// output steps, with sliding joints and the extra case text `extra` (its own tables).
fn sliding_tube(n: usize, turns: f64, elements: usize, target: f64, steps: usize) -> Case {
    let text = format!(
        "[geometry]\nhelices = {n}\nturns = {turns}\n[boundary]\njoints = \"sliding\"\n[loading]\ntarget = {target}\nsteps = {steps}\n[discretisation]\nelements = {elements}\n"
    );
    Case::parse(&text, "sliding.toml", "sliding").unwrap_or_else(|e| panic!("{e}"))
}

/// The load points at the case's output steps, and the critical points found on the way.
fn path(case: &Case) -> (Vec<LoadPoint>, Vec<CriticalPoint>, Simulation) {
    let mut sim = Simulation::from_case_on(case, 1).unwrap_or_else(|e| panic!("{e}"));
    let mut points = vec![sim.load_point(0)];
    for k in 1..=case.loading.steps {
        let target = case.loading.target * k as f64 / case.loading.steps as f64;
        sim.advance_to(target).unwrap_or_else(|e| panic!("{e}"));
        points.push(sim.load_point(k));
    }
    let critical = sim.critical_points().to_vec();
    (points, critical, sim)
}

#[test]
fn sliding_terms_are_the_derivatives_of_the_contact() {
    let case = sliding_tube(2, 3.5, 8, 0.1, 1);
    let model = case.model();
    assert!(!model.slides.is_empty());
    let x0 = model.natural_state();
    let sys = System::new(&model, case.boundary, &x0, &case.loads(), 0.0);
    let mut x = x0;
    x.resize(sys.n, 0.0);
    let np = model.n_primal;
    for (i, v) in x.iter_mut().enumerate() {
        let noise = ((i * 7919 + 13) % 1009) as f64 / 1009.0 - 0.5;
        *v += if i < np { 0.01 * noise } else { 3.0 * noise };
    }
    let (worst, scale) = crate::kkt_against_differences(&sys, &model, &x, 0..sys.n);
    assert!(
        worst < 1e-6 * scale,
        "KKT against differences {worst:e} (scale {scale:e})"
    );
}

/// The slip of every joint of the snapshot's rod `rod`, by arc length.
fn slips(sim: &Simulation, rod: usize) -> Vec<(f64, f64)> {
    let snap = sim.snapshot();
    let shape = &snap.rods[rod];
    shape
        .joints
        .iter()
        .zip(&shape.joint_states)
        .map(|(&s, j)| (s, j.slip))
        .collect()
}

#[test]
fn thesis_n2_sliding_stores_the_work_of_its_supports_with_the_slips_its_symmetry_says() {
    // cases/thesis-n2.toml with sliding joints, to ε = 0.2 in 40 equal steps
    let mut case = Case::from_file(std::path::Path::new("cases/thesis-n2.toml")).unwrap();
    case.boundary.joints = Joints::Sliding;
    case.loading.target = 0.2;
    case.loading.steps = 40;
    let (points, _, sim) = path(&case);
    let (energy, work, rel) = crate::energy_and_tip_work(&points);
    assert!(rel < 1e-8, "energy {energy} J, work {work} J ({rel:e})");
    // the mirror that swaps the right and the left rod keeps arc lengths: equal slips on
    // both rods; the half-turn about a horizontal axis at mid-height maps each rod onto
    // itself with s → L − s: the slip is odd about the middle
    let (right, left) = (slips(&sim, 0), slips(&sim, 1));
    let length = case.geometry.length;
    let largest = right.iter().fold(0.0f64, |m, j| m.max(j.1.abs()));
    assert!(largest > 1e-3 * length, "the contacts slide: {right:?}");
    for (r, l) in right.iter().zip(&left) {
        assert!(
            (r.0 - l.0).abs() < 1e-12 && (r.1 - l.1).abs() < 1e-6 * largest,
            "{r:?} vs {l:?}"
        );
    }
    for (k, r) in right.iter().enumerate() {
        let opposite = right[right.len() - 1 - k];
        assert!((r.0 + opposite.0 - length).abs() < 1e-9 * length);
        assert!(
            (r.1 + opposite.1).abs() < 1e-6 * largest,
            "{r:?} vs {opposite:?}"
        );
    }
    // and the tube is softer than the pinned one
    case.boundary.joints = Joints::Pin;
    case.loading.steps = 2;
    let (pins, _, _) = path(&case);
    let (slide, pin) = (points.last().unwrap().load[2], pins.last().unwrap().load[2]);
    assert!(
        slide.abs() < 0.97 * pin.abs(),
        "sliding {slide} vs pin {pin}"
    );
}

/// Axial force F (tension positive) and axial couple M on the tip of a rod held as the
/// helix (a, b) whose natural helix is (a0, b0), B1 = B2 = `bend`, B3 = `twist`:
/// docs/theory.md §6 (Love), written out here from the balance laws.
fn love(a0: f64, b0: f64, a: f64, b: f64, bend: f64, twist: f64, chi: f64) -> (f64, f64) {
    let (c0, c) = (a0.hypot(b0), a.hypot(b));
    let (k0, t0) = (a0 / (c0 * c0), b0 / (c0 * c0));
    let (k, t) = (a / (c * c), b / (c * c));
    let f = (twist * (t - t0) * a - bend * (k - k0) * b) / (a * c);
    let m = chi * (bend * (k - k0) * a + twist * (t - t0) * b) / c;
    (f, m)
}

#[test]
fn rods_whose_crossings_slide_stay_loves_helices_of_another_arc_length_per_turn() {
    // the thesis pair (n = 2, 3.5 turns), both ends of both rods clamped on the helix
    // a = a0, b = b0/2: c ≠ c0, so the natural crossings are no longer crossings of the
    // held helices — pins could not hold them there, sliding contacts move to where the
    // helices cross, s = s0 c/c0, and carry no force (a helix and its mirror image meet on
    // the mirror's plane), so each rod is Love's helix
    let (a0, b0) = (0.06, 0.025);
    let (a, b) = (a0, b0 / 2.0);
    let mut case = Case::from_file(std::path::Path::new("cases/thesis-n2.toml")).unwrap();
    case.discretisation.elements = 192;
    let model = case.model();
    let targets: Vec<Helix> = model
        .rods
        .iter()
        .map(|r| Helix {
            radius: a,
            pitch: b,
            ..r.helix
        })
        .collect();
    let x = model.helix_state(&targets);
    let bc = BoundaryConditions {
        joints: Joints::Sliding,
        ..Default::default()
    };
    let settings = ContinuationSettings::default();
    let sim = Simulation::from_state(model, bc, Control::Displacement, x, settings)
        .unwrap_or_else(|e| panic!("{e}"));
    let length = case.geometry.length;
    let lp = sim.load_point(0);
    for (rod, target) in lp.reactions.iter().zip(&targets) {
        let chi = target.chirality.sign();
        let (f, m) = love(a0, b0, a, b, 1.0, 2.0, chi);
        let force = Vector3::from(rod.tip.force);
        let tip = target.position(length);
        // moment about the helix axis: the couple plus the moment of the tip force
        let moment =
            Vector3::from(rod.tip.moment) + Vector3::new(tip[0], tip[1], 0.0).cross(&force);
        assert!(
            (force[2] - f).abs() < 1e-5 * f.abs(),
            "{:?}: Fz = {} vs Love {f}",
            target.chirality,
            force[2]
        );
        assert!(
            (moment[2] - m).abs() < 1e-5 * m.abs(),
            "{:?}: Mz = {} vs Love {m}",
            target.chirality,
            moment[2]
        );
    }
    // the contacts sit where the held helices cross
    let c_ratio = a.hypot(b) / a0.hypot(b0);
    for rod in 0..2 {
        for (s, slip) in slips(&sim, rod) {
            if s > 1e-9 * length && s < (1.0 - 1e-9) * length {
                assert!(
                    (slip - s * (c_ratio - 1.0)).abs() < 1e-6 * length,
                    "rod {rod}, joint at {s}: slip {slip} vs {}",
                    s * (c_ratio - 1.0)
                );
            }
        }
    }
}

#[test]
fn the_bulk_of_a_clamped_sliding_tube_keeps_its_arc_length_per_turn() {
    // n = 8, 3.5 turns, clamped tips at their natural azimuth: each rod keeps its total turn,
    // so its uniform bulk keeps c = c0 and rises b = b0 (1 − ε) (docs/theory.md §7), the
    // pinned tube's helix a = √(c0² − b²) — not the radius a0
    let case = sliding_tube(8, 3.5, 48, 0.1, 2);
    let (a0, b0) = (case.geometry.radius, case.geometry.pitch);
    let c0 = a0.hypot(b0);
    let (points, _, sim) = path(&case);
    let point = points.last().unwrap();
    let step = spira::discretisation::bulk::step_bulk(sim.model(), &sim.snapshot(), point);
    assert_eq!(step.rods.len(), 8);
    let b = b0 * (1.0 - point.compression_ratio);
    let a = (c0 * c0 - b * b).sqrt();
    for rb in &step.rods {
        assert!(
            rb.end_over_l() - rb.start_over_l() > 0.9,
            "the bulk spans the rod: {} to {}",
            rb.start_over_l(),
            rb.end_over_l()
        );
        let c = rb.radius.hypot(rb.pitch);
        assert!((c - c0).abs() < 1e-4 * c0, "c = {c} vs c0 = {c0}");
        assert!((rb.radius - a).abs() < 2e-4 * a, "a = {} vs {a}", rb.radius);
        // the clamped ends' boundary layers take a little of the height: the bulk rises
        // 6e-4 more than the mean
        assert!((rb.pitch - b).abs() < 1e-3 * b, "b = {} vs {b}", rb.pitch);
    }
    // the joints carry no force on this symmetric path: a helix and its mirror image meet
    // on the mirror's plane
    let force = (0..sim.system().slides.len())
        .map(|k| {
            let row = sim.system().slide_row(k);
            Vector3::new(sim.state()[row], sim.state()[row + 1], sim.state()[row + 2]).norm()
        })
        .fold(0.0f64, f64::max);
    let tip = point.load[2].abs() * sim.pcrit();
    assert!(
        force < 1e-6 * tip,
        "largest joint force {force} N, tip load {tip} N"
    );
}

#[test]
fn a_compressed_sliding_tube_is_stable_with_the_same_path_at_two_meshes() {
    // n = 8 to ε = 0.3 (short of the fold near 0.338) on 24 and 48 elements per rod: stable
    // at every step, no critical point at either mesh, and the load converging
    let (coarse, coarse_critical, _) = path(&sliding_tube(8, 3.5, 24, 0.3, 3));
    let (fine, fine_critical, _) = path(&sliding_tube(8, 3.5, 48, 0.3, 3));
    assert!(coarse_critical.is_empty() && fine_critical.is_empty());
    for (c, f) in coarse.iter().zip(&fine).skip(1) {
        let counts = |p: &LoadPoint| p.stability.as_ref().map(|s| s.unstable_directions);
        assert_eq!(counts(c), Some(0), "step {}", c.step);
        assert_eq!(counts(f), Some(0), "step {}", f.step);
        assert!(
            (c.load[2] - f.load[2]).abs() <= 1e-3 * f.load[2].abs(),
            "step {}: {} vs {}",
            c.step,
            c.load[2],
            f.load[2]
        );
    }
}
