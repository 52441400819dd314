//! Sliding joints against numbers that do not come from spira: central differences of the
//! discrete system, the work of the supports against the energy stored (composite Simpson),
//! the symmetry of the thesis geometry, Love's helix of a rod whose crossings all slide, and
//! the bulk of long tubes against the helix of radius a0.

use spira::case::Case;
use spira::discretisation::system::System;
use spira::model::boundary::Joints;
use spira::results::{CriticalPoint, LoadPoint};
use spira::simulation::Simulation;

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
    let mut values = sys.new_values();
    let mut r0 = vec![0.0; sys.n];
    sys.evaluate(&model, &x, &mut r0, &mut values);
    let m = sys.matrix(&values);
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    let h = 1e-6;
    let (mut rp, mut rm) = (vec![0.0; sys.n], vec![0.0; sys.n]);
    let mut worst: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for j in 0..sys.n {
        let (mut xp, mut xm) = (x.clone(), x.clone());
        xp[j] += h;
        xm[j] -= h;
        sys.residual(&model, &xp, &mut rp);
        sys.residual(&model, &xm, &mut rm);
        let mut column = vec![0.0; sys.n];
        for p in cp[j]..cp[j + 1] {
            column[ri[p]] += m.val()[p];
        }
        for i in 0..sys.n {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            worst = worst.max((fd - column[i]).abs());
            scale = scale.max(fd.abs());
        }
    }
    assert!(
        worst < 1e-6 * scale,
        "KKT against differences {worst:e} (scale {scale:e})"
    );
}

/// Composite Simpson's rule over equally spaced samples `f` (an even number of intervals).
fn simpson(f: &[f64], step: f64) -> f64 {
    let n = f.len() - 1;
    assert!(n % 2 == 0);
    let inner: f64 = (1..n)
        .map(|k| if k % 2 == 1 { 4.0 * f[k] } else { 2.0 * f[k] })
        .sum();
    step / 3.0 * (f[0] + inner + f[n])
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
    // Σ_rods ∫ Fz dh: the tips move by equal steps of h
    let fz: Vec<f64> = points
        .iter()
        .map(|p| p.reactions.iter().map(|r| r.tip.force[2]).sum())
        .collect();
    let dh = points[1].height - points[0].height;
    let work = simpson(&fz, dh);
    let energy = points.last().unwrap().energy - points[0].energy;
    let rel = (energy - work).abs() / energy;
    assert!(rel < 1e-8, "energy {energy} J, work {work} J ({rel:e})");
    // the mirror that swaps the right and the left rod keeps arc lengths: equal slips on
    // both rods; the half-turn about a horizontal axis at mid-height maps each rod onto
    // itself with s → L − s: the slip is odd about the middle
    let (right, left) = (slips(&sim, 0), slips(&sim, 1));
    let length = case.geometry.length;
    let largest = right.iter().fold(0.0f64, |m, j| m.max(j.1.abs()));
    assert!(largest > 1e-3 * length, "the contacts slide: {right:?}");
    for (r, l) in right.iter().zip(&left) {
        assert!((r.0 - l.0).abs() < 1e-12 && (r.1 - l.1).abs() < 1e-6 * largest, "{r:?} vs {l:?}");
    }
    for (k, r) in right.iter().enumerate() {
        let opposite = right[right.len() - 1 - k];
        assert!((r.0 + opposite.0 - length).abs() < 1e-9 * length);
        assert!((r.1 + opposite.1).abs() < 1e-6 * largest, "{r:?} vs {opposite:?}");
    }
    // and the tube is softer than the pinned one
    case.boundary.joints = Joints::Pin;
    case.loading.steps = 2;
    let (pins, _, _) = path(&case);
    let (slide, pin) = (points.last().unwrap().load[2], pins.last().unwrap().load[2]);
    assert!(slide.abs() < 0.97 * pin.abs(), "sliding {slide} vs pin {pin}");
}
