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
fn a_tube_whose_crossings_slide_is_n_lone_helices_on_its_symmetric_path() {
    // A helix and its mirror images meet on the mirror planes with no force: on the tube's
    // symmetric path every rod of the sliding tube is the lone clamped helix (n = 1, no
    // joints), rotated. The rods do not stay on a cylinder: each bows as the lone helix
    // does, towards the axis over part of a turn. With 56 elements per rod the crossings,
    // L/28 apart, are on element vertices, so both meshes are the same.
    let tube = sliding_tube(8, 3.5, 56, 0.3, 6);
    let text = "[geometry]\nhelices = 1\nturns = 3.5\n[boundary]\njoints = \"none\"\n[loading]\ntarget = 0.3\nsteps = 6\n[discretisation]\nelements = 56\n";
    let lone = Case::parse(text, "lone.toml", "lone").unwrap_or_else(|e| panic!("{e}"));
    let (tube_points, _, tube_sim) = path(&tube);
    let (lone_points, _, lone_sim) = path(&lone);
    for (t, l) in tube_points.iter().zip(&lone_points).skip(1) {
        // Σ Fz/(n Pcrit) is the load per rod; the energy is n times the lone rod's
        assert!(
            (t.load[2] - l.load[2]).abs() < 1e-8 * l.load[2].abs(),
            "ε = {}: {} vs {}",
            t.compression_ratio,
            t.load[2],
            l.load[2]
        );
        assert!(
            (t.energy - 8.0 * l.energy).abs() < 1e-8 * t.energy,
            "ε = {}: {} J vs 8 × {} J",
            t.compression_ratio,
            t.energy,
            l.energy
        );
    }
    let (tube_rod, lone_rod) = (&tube_sim.snapshot().rods[0], &lone_sim.snapshot().rods[0]);
    assert_eq!(tube_rod.nodes.len(), lone_rod.nodes.len(), "the same mesh");
    let length = tube.geometry.length;
    let mut radii = (f64::INFINITY, 0.0f64);
    for (a, b) in tube_rod.nodes.iter().zip(&lone_rod.nodes) {
        let gap = Vector3::from(a.position) - Vector3::from(b.position);
        assert!(gap.norm() < 1e-8 * length, "s = {}: {gap:?}", a.s);
        let r = a.position[0].hypot(a.position[1]);
        radii = (radii.0.min(r), radii.1.max(r));
    }
    // at ε = 0.3 the rods pass within 0.014 m of the axis and 0.118 m from it (a0 = 0.06 m)
    assert!(
        radii.0 < 0.5 * 0.06 && radii.1 > 1.5 * 0.06,
        "radii {radii:?}"
    );
}

#[test]
fn a_compressed_sliding_tube_is_stable_with_the_same_path_at_two_meshes() {
    // n = 8 to ε = 0.3 (short of where two crossings meet, near 0.336) on 24 and 48 elements per rod: stable
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

/// `cases/thesis-n8-sliding.toml` solved as the symmetric pair (`pair`) or as the whole
/// assembly.
fn thesis_n8_sliding(pair: bool) -> Case {
    let mut case = Case::from_file(std::path::Path::new("cases/thesis-n8-sliding.toml")).unwrap();
    case.discretisation.symmetric = pair;
    case
}

/// The Bloch blocks of the sliding pair (n = 8, m = 4) at ε = 0.2 against the whole
/// assembly's KKT matrix at the expanded state: each block's lowest eigenvalue and mode,
/// rebuilt on the eight rods (the contacts' arc lengths included), is a direction that keeps
/// every constraint of the whole tube — the sliding joints between sectors included — with
/// the block's eigenvalue as its Rayleigh quotient; the lowest over the blocks is the whole
/// tube's lowest, and the counts agree.
#[test]
fn bloch_blocks_of_the_sliding_pair_are_the_whole_tubes_constrained_hessian() {
    use spira::discretisation::symmetry::{assembly_mode, expand_state};
    use spira::model::loading::Loads;
    use spira::simulation::problem::LoadedAssembly;
    use spira::solver::problem::Problem;
    let case = thesis_n8_sliding(true);
    let mut sim = Simulation::from_case_on(&case, 1).unwrap();
    for k in 1..=4 {
        sim.advance_to(0.05 * k as f64).unwrap();
    }
    let x = sim.state().to_vec();
    let pair = sim.model().clone();
    assert_eq!(pair.rods.len(), 2);
    assert!(!pair.slides.is_empty());
    let np = pair.n_primal;
    let eps = sim.compression_ratio();
    let tip = &Loads::axial(Control::Displacement);
    let pair_system = System::new(&pair, case.boundary, &x[..np], tip, eps);
    let full = pair.full_model().expect("a symmetric pair");
    assert_eq!(full.slides.len(), 4 * pair.slides.len());
    let layout = System::new(&full, case.boundary, &full.natural_state(), tip, 0.0);
    let mut xf = vec![0.0; layout.n];
    expand_state(&pair, &pair_system, &x, &full, &layout, &mut xf);
    let full_system = System::new(&full, case.boundary, &xf[..full.n_primal], tip, eps);
    // the expanded state keeps every constraint of the whole tube, its sliding joints'
    // between sectors included (the multipliers of supports and pins, which do not enter
    // the Hessian, are not expanded: the primal rows are not compared)
    let mut residual = vec![0.0; full_system.n];
    full_system.residual(&full, &xf, &mut residual);
    let worst = residual[full.n_primal..]
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    assert!(worst < 1e-10, "constraints at the expanded state {worst:e}");
    let metric = crate::rotation_metric(&full);
    let mut blocks = LoadedAssembly::new(pair.clone(), pair_system).with_threads(1);
    let mut whole = LoadedAssembly::new(full.clone(), full_system.clone());
    let mut lowest = f64::INFINITY;
    for p in 0..=2 {
        let (mu, v) = blocks.block_nearest_zero(&x, p).expect("an eigenvalue");
        assert!(mu > 0.0, "p = {p}: the compressed tube is stable ({mu})");
        lowest = lowest.min(mu);
        // a complex block's mode v and i v: the two of the wavenumbers p and m − p
        let mut modes = vec![v.clone()];
        if p == 1 {
            let half = v.len() / 2;
            modes.push(
                v[half..]
                    .iter()
                    .map(|a| -a)
                    .chain(v[..half].iter().copied())
                    .collect(),
            );
        }
        for v in modes {
            let u = assembly_mode(&pair, p, &v, &full);
            let (hu, cu) = crate::symmetry::kkt_action(&full, &full_system, &xf, &u);
            let kept = cu.iter().fold(0.0f64, |m, c| m.max(c.abs()));
            let uhu: f64 = u.iter().zip(&hu).map(|(a, b)| a * b).sum();
            let umu: f64 = u.iter().zip(&metric).map(|(a, w)| w * a * a).sum();
            let rayleigh = uhu / umu;
            eprintln!("p = {p}: block {mu:.12e}, whole tube's Rayleigh quotient {rayleigh:.12e}, constraints {kept:e}");
            assert!(
                kept < 1e-9,
                "p = {p}: the mode breaks the whole tube's constraints by {kept:e}"
            );
            assert!(
                (rayleigh - mu).abs() < 1e-9 * mu,
                "p = {p}: block {mu} vs whole tube {rayleigh}"
            );
        }
    }
    let full_lowest = whole.lowest_eigenvalue(&xf, 0.0).unwrap();
    eprintln!("lowest over the blocks {lowest:.12e}, whole tube {full_lowest:.12e}");
    assert!((lowest - full_lowest).abs() < 1e-9 * full_lowest);
    assert_eq!(whole.unstable_directions(&xf, 0.0).unwrap(), 0);
}

/// The symmetric pair with sliding joints is the whole tube: `cases/thesis-n8-sliding.toml`
/// compressed by ε = 0.02 a step until two crossings of a rod meet, load, energy, stability and the contacts'
/// slips of every rod the same on both, and the stop at the same ε. Every crossing lies on
/// a mirror plane of the tube (its azimuth is a multiple of π/m), and the mirror swaps its
/// two rods: both slide by the same amount.
#[test]
fn the_symmetric_pair_with_sliding_joints_is_the_whole_tube_to_its_stop() {
    let run = |pair: bool| {
        let case = thesis_n8_sliding(pair);
        let mut sim = Simulation::from_case_on(&case, 1).unwrap();
        let mut points = vec![sim.load_point(0)];
        let mut stop = None;
        for k in 1..=17 {
            let done = sim.advance_to(0.02 * k as f64);
            points.push(sim.load_point(k));
            if let Err(e) = done {
                stop = Some(e);
                break;
            }
        }
        (
            points,
            stop.expect("the path stops where two crossings meet"),
            sim,
        )
    };
    let (full, full_stop, full_sim) = run(false);
    let (pair, pair_stop, pair_sim) = run(true);
    assert_eq!(pair_sim.model().rods.len(), 2);
    assert_eq!(full_sim.model().rods.len(), 8);
    assert_eq!(full.len(), pair.len());
    let (mut load_gap, mut energy_gap) = (0.0f64, 0.0f64);
    for (a, b) in full.iter().zip(&pair) {
        load_gap = load_gap.max((a.load[2] - b.load[2]).abs() / a.load[2].abs().max(1e-3));
        energy_gap = energy_gap.max((a.energy - b.energy).abs() / a.energy.max(1e-3));
        assert!((a.compression_ratio - b.compression_ratio).abs() < 1e-9);
        let scale = a.load[2].abs().max(1e-3);
        assert!(
            (a.load[2] - b.load[2]).abs() < 1e-9 * scale,
            "ε = {}: {} vs {}",
            a.compression_ratio,
            a.load[2],
            b.load[2]
        );
        assert!(
            (a.energy - b.energy).abs() < 1e-9 * a.energy.max(1e-3),
            "ε = {}: {} vs {}",
            a.compression_ratio,
            a.energy,
            b.energy
        );
        let (sa, sb) = (a.stability.unwrap(), b.stability.unwrap());
        assert_eq!(sa.unstable_directions, 0);
        assert_eq!(sb.unstable_directions, 0);
    }
    let (a, b) = (full.last().unwrap(), pair.last().unwrap());
    eprintln!("largest relative gaps, pair to full: load {load_gap:e}, energy {energy_gap:e}");
    eprintln!(
        "stop: full ε = {:.9} ({full_stop}), pair ε = {:.9}; Σ Fz/(n Pcrit) {:.10} vs {:.10}, energy {:.10} vs {:.10} J",
        a.compression_ratio, b.compression_ratio, a.load[2], b.load[2], a.energy, b.energy
    );
    use spira::solver::continuation::StopReason;
    // two crossings of one rod meet short of ε = 0.3379, where the steps find no equilibrium
    for stop in [&full_stop, &pair_stop] {
        assert!(
            matches!(stop.reason, StopReason::LeftDomain { why } if why.contains("crossings")),
            "{stop}"
        );
    }
    assert!(
        a.compression_ratio > 0.33 && a.compression_ratio < 0.3379,
        "{}",
        a.compression_ratio
    );
    // the path stops on the edge of its domain, whatever its steps: two contacts of a rod
    // at the stop are closer than a thousandth of the crossings' natural spacing (0.0503 m),
    // and steps of 0.05 stop at the same ε as steps of 0.02
    let length = thesis_n8_sliding(false).geometry.length;
    let closest = (0..8)
        .map(|rod| {
            let mut at: Vec<f64> = slips(&full_sim, rod).iter().map(|(s, d)| s + d).collect();
            at.sort_by(f64::total_cmp);
            at.windows(2).fold(f64::INFINITY, |m, w| m.min(w[1] - w[0]))
        })
        .fold(f64::INFINITY, f64::min);
    eprintln!("closest contacts of one rod at the stop: {closest:e} m");
    assert!((0.0..5e-5).contains(&closest), "{closest}");
    let coarse = {
        let mut sim = Simulation::from_case_on(&thesis_n8_sliding(true), 1).unwrap();
        let mut k = 0;
        while sim.advance_to(0.05 * (k + 1) as f64).is_ok() {
            k += 1;
        }
        sim.load_point(k).compression_ratio
    };
    assert!(
        (coarse - a.compression_ratio).abs() < 1e-5,
        "{coarse} vs {}",
        a.compression_ratio
    );
    // the slips of every rod: the pair's images as the whole tube's rods
    let largest = slips(&full_sim, 0)
        .iter()
        .fold(0.0f64, |m, j| m.max(j.1.abs()));
    assert!(largest > 1e-3 * length, "the contacts slide");
    for rod in 0..8 {
        for (f, p) in slips(&full_sim, rod).iter().zip(&slips(&pair_sim, rod)) {
            assert!((f.0 - p.0).abs() < 1e-12);
            assert!(
                (f.1 - p.1).abs() < 1e-9 * length,
                "rod {rod}: {f:?} vs {p:?}"
            );
        }
    }
    // both rods of a crossing slide alike: at each arc length s, R_0's contact is the right
    // side and L_0's the left side of crossings of one orbit of the rotation
    for (r, l) in slips(&pair_sim, 0).iter().zip(&slips(&pair_sim, 4)) {
        assert!((r.0 - l.0).abs() < 1e-12);
        assert!((r.1 - l.1).abs() < 1e-9 * length, "{r:?} vs {l:?}");
    }
}
