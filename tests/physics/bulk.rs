//! The bulk of the rods and the curvature profiles it reads (recovered from the
//! Barlow points of the elements): against closed forms only — Love's helical equilibria
//! (docs/theory.md §6) and the infinite tube of docs/theory.md §7 — never against the program itself.

use spira::case::Case;
use spira::discretisation::bulk;
use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::fields;
use spira::discretisation::shape::Order;
use spira::model::assembly::Assembly;
use spira::model::helix::Chirality;
use spira::model::love::LoveHelix;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;
use std::f64::consts::PI;
use std::path::Path;

use crate::{A0, B0, STIFFNESS};

fn c0() -> f64 {
    A0.hypot(B0)
}

/// A right- and a left-handed rod (no joints) of 3.5 turns held at both ends on the helix
/// of pitch parameter `b` and the same arc length per turn: the Love set-up of
/// tests/physics/rods.rs.
fn held_pair(b: f64, elements: usize, order: Order) -> (Simulation, f64) {
    let length = 7.0 * PI * c0();
    let model = DiscreteModel::new(Assembly::new(2, A0, B0, length), STIFFNESS, elements, order);
    let a = (c0() * c0() - b * b).sqrt();
    let sim = Simulation::held_on_helices(model, a, b, ContinuationSettings::default())
        .expect("perfect helix equilibrium converges");
    (sim, a)
}

// ---------------------------------------------------------------- the bulk of a helix

/// A rod held on a perfect helix is bulk from end to end, and the helix fitted to its
/// curvatures is the one it is held on, with Love's wrench, which the rod's tip reaction
/// is too (docs/theory.md §6: b = 0.0125 gives a = 0.0637868 m, F = −93.73536 N).
#[test]
fn the_bulk_of_a_rod_held_on_a_perfect_helix_is_the_whole_rod_and_that_helix() {
    for b in [0.0125, 0.04] {
        let (sim, a) = held_pair(b, 384, Order::Quadratic);
        let point = sim.load_point(0);
        let step = bulk::step_bulk(sim.model(), &sim.snapshot(), &point);
        assert_eq!(step.rods.len(), 2);
        for rb in &step.rods {
            assert_eq!(rb.start_over_l(), 0.0, "b = {b}: bulk starts at the base");
            assert_eq!(rb.end_over_l(), 1.0, "b = {b}: bulk ends at the tip");
            assert!(
                (rb.radius - a).abs() < 1e-8,
                "b = {b}: fitted radius {} vs {a}",
                rb.radius
            );
            assert!(
                (rb.pitch - b).abs() < 1e-8,
                "b = {b}: fitted pitch {} vs {b}",
                rb.pitch
            );
            let love = LoveHelix {
                radius0: A0,
                pitch0: B0,
                length: 7.0 * PI * c0(),
                stiffness: STIFFNESS,
                pitch: b,
                elasticity: Default::default(),
                reference: spira::model::elasticity::Reference::Discrete,
            };
            let (f, m) = (love.force(), love.moment(rb.chirality));
            let lf = rb.love_force.expect("a helix has Love's force");
            let lm = rb.love_moment.expect("and couple");
            assert!((lf - f).abs() < 1e-6 * f.abs(), "Love F {lf} vs {f}");
            assert!((lm - m).abs() < 1e-6 * m.abs(), "Love M {lm} vs {m}");
            // the rod's own reactions are Love's (to the discretisation error at 384
            // elements, 2e-7 relative in the couple: tests/physics/rods.rs)
            assert!((rb.axial_force - f).abs() < 1e-6 * f.abs());
            assert!((rb.axial_moment - m).abs() < 1e-6 * m.abs());
        }
        if b == 0.0125 {
            assert!((a - 0.0637868).abs() < 5e-8);
            assert!((step.rods[0].love_force.unwrap() - -93.73536).abs() < 1e-4);
        }
    }
}

/// The longest uniform stretch on a made-up profile: a plateau between two slopes, and the
/// spread allowed is `2 tol` per component.
#[test]
fn the_longest_uniform_stretch_is_the_plateau_within_the_tolerance() {
    let s: Vec<f64> = (0..=20).map(|k| k as f64 * 0.1).collect();
    let k: Vec<[f64; 3]> = s
        .iter()
        .map(|&x| {
            let v = if x < 0.5 {
                1.0 + (0.5 - x)
            } else if x > 1.5 {
                1.0 + 2.0 * (x - 1.5)
            } else {
                1.0 + 0.01 * (x - 1.0)
            };
            [v, 0.0, -v]
        })
        .collect();
    // plateau: s in [0.5, 1.5] (spread 0.01); the slopes add 0.1 and 0.2 per node
    assert_eq!(bulk::longest_uniform_stretch(&s, &k, 0.006), (5, 15));
    // a looser tolerance (spread 0.106 allowed) takes in one node of the gentler slope at
    // the base (1.1 against the plateau's least 0.995)
    assert_eq!(bulk::longest_uniform_stretch(&s, &k, 0.053), (4, 15));
}

// ---------------------------------------------------------------- curvature orders

/// Max relative error of the recovered nodal curvatures and of the Barlow-point samples of
/// the right-handed rod held on Love's helix b = 0.0125, against the closed form
/// `(−a/c², 0, b/c²)`.
fn love_curvature_errors(elements: usize, order: Order) -> (f64, f64) {
    let b = 0.0125;
    let (sim, a) = held_pair(b, elements, order);
    let c2 = a * a + b * b;
    let exact = [-a / c2, 0.0, b / c2];
    let scale = a / c2;
    let err = |k: [f64; 3]| (0..3).map(|i| (k[i] - exact[i]).abs()).fold(0.0, f64::max);
    let snap = sim.snapshot();
    let recovered = snap.rods[0]
        .nodes
        .iter()
        .map(|n| err(n.curvature))
        .fold(0.0, f64::max);
    let x = sim.state();
    let rod = &sim.model().rods[0];
    assert_eq!(rod.helix.chirality, Chirality::Right);
    let barlow = fields::gauss_curvatures(sim.model(), 0, |k| {
        std::array::from_fn(|c| x[rod.q_dof(k, c)])
    })
    .iter()
    .map(|g| err(g.curvature))
    .fold(0.0, f64::max);
    (recovered / scale, barlow / scale)
}

/// Curvature at the Barlow points, and recovered from them at the nodes, converges at order
/// `p + 1` (quadratic 3, linear 2: `Measure::theoretical_order`), measured against Love's
/// closed form on doubling meshes (observed within 0.3 of the theory, as
/// tests/physics/precision.rs).
#[test]
fn curvature_at_the_barlow_points_converges_at_order_p_plus_one_against_love() {
    for (order, meshes, theory) in [
        (Order::Quadratic, [48usize, 96, 192, 384], 3.0),
        (Order::Linear, [48, 96, 192, 384], 2.0),
    ] {
        let errors: Vec<(f64, f64)> = meshes
            .iter()
            .map(|&n| love_curvature_errors(n, order))
            .collect();
        for w in errors.windows(2) {
            for (name, e0, e1) in [("recovered", w[0].0, w[1].0), ("barlow", w[0].1, w[1].1)] {
                let k = (e0 / e1).log2();
                assert!(
                    (k - theory).abs() <= 0.3,
                    "{order:?} {name}: observed order {k:.3} ({e0:.3e} -> {e1:.3e}), theory {theory}; all {errors:?}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------- the infinite tube

/// The thesis n = 8 tube (clamped ends, pin joints; solved as its symmetric pair) of 3.5, 7
/// and 14 turns, the mesh refined with the length, compressed to ε = 0.25: with more turns
/// the bulk curvatures approach Love's family for the infinite tube (c = c0,
/// b = b0 (1 − ε), docs/theory.md §7), and the finite tube's force approaches the infinite one's.
#[test]
fn longer_tubes_approach_the_infinite_tube_of_loves_family() {
    let eps = 0.25;
    let base = Case::from_file(Path::new("cases/thesis-n8.toml")).expect("shipped case");
    let infinite = LoveHelix {
        radius0: A0,
        pitch0: B0,
        length: 7.0 * PI * c0(),
        stiffness: STIFFNESS,
        pitch: B0 * (1.0 - eps),
        elasticity: Default::default(),
        reference: spira::model::elasticity::Reference::Discrete,
    };
    let mut last: Option<(f64, f64)> = None;
    for turns in [3.5, 7.0, 14.0] {
        let text = std::fs::read_to_string("cases/thesis-n8.toml")
            .expect("shipped case")
            .replace("turns = 3.5 ", &format!("turns = {turns} "))
            .replace(
                "elements = 48 ",
                &format!("elements = {} ", (48.0 * turns / 3.5) as usize),
            )
            .replace(
                "order = \"quadratic\"",
                "order = \"quadratic\"\nsymmetric = true",
            );
        let mut case = Case::parse(&text, "tube.toml", "tube").expect("valid case");
        assert_eq!(case.geometry.helices, base.geometry.helices);
        case.loading.target = eps;
        case.loading.steps = 2;
        let targets = case.output_parameters(eps, 2);
        let out = spira::run::run_path(&case, &targets, |_, _| {}).expect("path");
        assert!(out.error.is_none(), "{turns} turns: {:?}", out.error);
        let step = out.bulk.last().expect("a bulk per point");
        assert!((step.compression_ratio - eps).abs() < 1e-9);
        let ratio = step.tube_ratio.expect("ratio at eps > 0");
        let tube = step.tube_force.expect("helical rods");
        assert!((tube - infinite.force()).abs() < 1e-9 * tube.abs());
        // the bulk curvature of every rod against the infinite tube's, relative to 1/c0
        let deviation = step
            .rods
            .iter()
            .map(|r| {
                let k = infinite.curvature(r.chirality);
                (0..3)
                    .map(|i| (r.curvature[i] - k[i]).abs())
                    .fold(0.0, f64::max)
                    * c0()
            })
            .fold(0.0, f64::max);
        println!("{turns} turns: finite/infinite force {ratio:.6}, bulk curvature off Love's family by {deviation:.3e} (x 1/c0)");
        if let Some((r0, d0)) = last {
            assert!(
                (ratio - 1.0).abs() < (r0 - 1.0).abs(),
                "{turns} turns: |ratio - 1| = {} did not fall from {}",
                (ratio - 1.0).abs(),
                (r0 - 1.0).abs()
            );
            assert!(
                deviation < d0,
                "{turns} turns: bulk curvature deviation {deviation} did not fall from {d0}"
            );
        }
        last = Some((ratio, deviation));
    }
}
