//! The free-motion check of the case reader is exact: for every combination of
//! the supports (base and tip translation × rotation), with and without joints (pinned,
//! welded, with a scissor spring, sliding), under
//! displacement and load control, on 1, 2 and 8 helices, `free_motion_of` names a motion
//! exactly when the natural state has a zero-energy mode (its lowest stability eigenvalue
//! vanishes, the first step meets a singular matrix, or, with sliding joints, the lowest
//! eigenvalue with every unknown in the metric vanishes); when it names none, a short solve
//! (one small step) succeeds.

use rayon::prelude::*;
use spira::case::{free_motion_of, Case};
use spira::model::boundary::{
    BoundaryConditions, EndCondition, JointStiffness, Joints, Rotation, Translation,
};
use spira::model::loading::Control;

const TRANSLATIONS: [Translation; 3] =
    [Translation::Fixed, Translation::Slide, Translation::Radial];
const ROTATIONS: [Rotation; 3] = [Rotation::Clamped, Rotation::Free, Rotation::Pinned];

/// A tiny case: `n` helices of 1.3 turns, 6 elements per rod, the full model, one output
/// step to `target` (ε, or P/Pcrit under load control).
fn tiny(n: usize, control: &str, target: f64) -> Case {
    let text = format!(
        "[geometry]\nhelices = {n}\nturns = 1.3\n[loading]\ncontrol = \"{control}\"\ntarget = {target}\nsteps = 1\n[discretisation]\nelements = 6\nsymmetric = false\n"
    );
    let mut case = Case::parse(&text, "tiny.toml", "tiny").unwrap_or_else(|e| panic!("{e}"));
    case.solver.track_stability = true;
    case.solver.lowest_eigenvalue = true;
    case
}

fn ends() -> impl Iterator<Item = EndCondition> {
    TRANSLATIONS.into_iter().flat_map(|translation| {
        ROTATIONS.into_iter().map(move |rotation| EndCondition {
            translation,
            rotation,
        })
    })
}

/// The lowest stability eigenvalue of the natural state, and the error of one small step
/// (if any).
fn natural_state(case: &Case, step: bool) -> (f64, Option<String>) {
    let targets = if step {
        case.output_parameters(case.loading.target, 1)
    } else {
        vec![0.0]
    };
    match spira::run::run_path(case, &targets, |_, _| {}) {
        Ok(o) => {
            let lowest = o.points[0]
                .stability
                .and_then(|s| s.lowest_eigenvalue)
                .expect("the lowest eigenvalue at eps = 0");
            (lowest, o.error.map(|e| e.to_string()))
        }
        Err(e) => (0.0, Some(format!("no natural state: {e}"))),
    }
}

/// The lowest eigenvalue of the natural state's constrained Hessian with every primal
/// unknown in the metric (unit weight: positions and the contacts' arc lengths too), so
/// that a rigid translation, which the rotations' metric does not see, shows as a zero
/// eigenvalue.
fn lowest_with_every_unknown_weighted(case: &Case) -> Option<f64> {
    use spira::discretisation::system::System;
    use spira::solver::stability::KktStability;
    let model = case.model();
    let x0 = model.natural_state();
    let system = System::new(&model, case.boundary, &x0, &case.loads(), 0.0);
    let mut x = x0;
    x.resize(system.n, 0.0);
    let mut residual = vec![0.0; system.n];
    let mut values = system.new_values();
    system.evaluate(&model, &x, &mut residual, &mut values);
    let mut stability: KktStability = KktStability::new(vec![1.0; model.n_primal], model.length());
    stability.lowest_eigenvalue(system.pattern(), &values)
}

#[test]
fn the_free_motion_check_names_a_motion_exactly_when_one_is_free() {
    let mut named = 0;
    let mut accepted = 0;
    for (control, target) in [(Control::Displacement, 0.01), (Control::Force, 0.01)] {
        let name = match control {
            Control::Displacement => "displacement",
            Control::Force => "force",
        };
        for n in [1usize, 2, 8] {
            let case = tiny(n, name, target);
            // the scale of the stiffness: the lowest eigenvalue with both ends clamped
            let (reference, e) = natural_state(&case, false);
            assert!(e.is_none() && reference > 0.0, "{e:?}");
            // and with every unknown in the metric, sliding crossings and clamped ends
            let mut clamped = case.clone();
            clamped.boundary.joints = Joints::Sliding;
            let weighted_reference = lowest_with_every_unknown_weighted(&clamped).expect("clamped");
            assert!(weighted_reference > 0.0);
            // welded joints tie the rods' rotations, a scissor spring alone the rotation
            // about the surface normal only
            let scissor = Joints::Elastic(JointStiffness {
                scissor: 1.0,
                out_of_plane: 0.0,
            });
            // sliding crossings on two helices: on eight, each sliding scene's solve costs
            // seconds (the 162 of them five minutes), and the motion they free there has
            // its own test below
            let joints: &[Joints] = match n {
                1 => &[Joints::Pin],
                2 => &[
                    Joints::Pin,
                    Joints::None,
                    Joints::Welded,
                    scissor,
                    Joints::Sliding,
                ],
                _ => &[Joints::Pin, Joints::None, Joints::Welded, scissor],
            };
            let scenes: Vec<BoundaryConditions> = joints
                .iter()
                .flat_map(|&joints| {
                    ends().flat_map(move |base| {
                        ends().map(move |tip| BoundaryConditions { base, tip, joints })
                    })
                })
                .collect();
            // true: named
            let verdicts: Vec<bool> = scenes
                .par_iter()
                .map(|&bc| {
                    let what = format!("{name} control, n = {n}, {}", bc.label());
                    let mut c = case.clone();
                    c.boundary = bc;
                    let motion = free_motion_of(&bc, &c.geometry, control == Control::Displacement);
                    assert_eq!(motion, c.free_motion(&bc), "{what}");
                    // a named motion: the natural state's stability first (a rotation
                    // shows there), the step only when it does not
                    let (mut lowest, mut error) = natural_state(&c, motion.is_none());
                    if motion.is_some() && lowest.abs() > 1e-8 * reference {
                        (lowest, error) = natural_state(&c, true);
                    }
                    // sliding crossings free translations of rods relative to one
                    // another that a solve need not meet as a singular matrix: every
                    // unknown weighted shows them
                    let weighted = (bc.joints == Joints::Sliding)
                        .then(|| lowest_with_every_unknown_weighted(&c).unwrap_or(0.0));
                    match motion {
                        Some(m) => {
                            // a zero-energy mode, no refusal of a solvable scene: a
                            // rotation shows in the stability (its metric is of the
                            // rotations), a translation as a singular matrix
                            let singular = error.as_deref().is_some_and(|e| e.contains("singular"));
                            let neutral = weighted.is_some_and(|w| w.abs() <= 1e-8 * weighted_reference);
                            assert!(
                                lowest.abs() <= 1e-8 * reference || singular || neutral,
                                "{what}: named `{}` but the lowest eigenvalue is {lowest:e} (clamped {reference:e}) and the step gave {error:?}",
                                m.message
                            );
                            assert!(m.message.contains("a free rigid motion"), "{}", m.message);
                            assert!(["translation", "rotation"].contains(&m.half));
                            true
                        }
                        None => {
                            assert!(error.is_none(), "{what}: accepted, but the solve failed: {error:?}");
                            assert!(
                                lowest > 1e-3 * reference,
                                "{what}: accepted, but the lowest eigenvalue is {lowest:e} (clamped {reference:e})"
                            );
                            if let Some(w) = weighted {
                                assert!(
                                    w > 1e-3 * weighted_reference,
                                    "{what}: accepted, but with every unknown weighted the lowest eigenvalue is {w:e} (clamped {weighted_reference:e})"
                                );
                            }
                            false
                        }
                    }
                })
                .collect();
            named += verdicts.iter().filter(|&&v| v).count();
            accepted += verdicts.iter().filter(|&&v| !v).count();
        }
    }
    // 2 controls × (81 + 5 × 81 + 4 × 81) combinations
    assert_eq!(named + accepted, 1620);
    println!("{named} named, {accepted} accepted");
}

/// The check reads the geometry, not only the names of the supports: two radially sliding
/// ends leave a translation free when their radii are parallel (a whole number of half
/// turns), and two rods hinged at both ends turn together about the line through the
/// points where they meet when their tips meet (the thesis's 3.5 turns), not otherwise.
/// The solver does not always see the first: radii parallel to rounding make a matrix
/// singular to rounding, which its factorisation does not flag; the motion named is then
/// checked to be along the radii.
#[test]
fn the_free_motion_check_follows_the_geometry() {
    let end = |translation, rotation| EndCondition {
        translation,
        rotation,
    };
    let radial = BoundaryConditions {
        base: end(Translation::Radial, Rotation::Clamped),
        tip: end(Translation::Radial, Rotation::Clamped),
        joints: Joints::Pin,
    };
    let hinged = BoundaryConditions {
        base: end(Translation::Fixed, Rotation::Free),
        tip: end(Translation::Fixed, Rotation::Free),
        joints: Joints::Pin,
    };
    for (n, bc, turns, free) in [
        (1, radial, 1.5, true),
        (1, radial, 2.0, true),
        (1, radial, 1.3, false),
        (1, radial, 1.75, false),
        (2, hinged, 3.5, true),
        (2, hinged, 2.0, true),
        (2, hinged, 1.3, false),
        (2, hinged, 1.75, false),
    ] {
        let mut case = tiny(n, "displacement", 0.01);
        let reference = natural_state(&case, false).0;
        case = Case::parse(
            &format!(
                "[geometry]\nhelices = {n}\nturns = {turns}\n[loading]\ntarget = 0.01\nsteps = 1\n[discretisation]\nelements = 8\nsymmetric = false\n"
            ),
            "g.toml",
            "g",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        case.solver.track_stability = true;
        case.solver.lowest_eigenvalue = true;
        case.boundary = bc;
        let motion = case.free_motion(&bc);
        let (lowest, error) = natural_state(&case, true);
        let what = format!("n = {n}, {turns} turns, {}", bc.label());
        let zero_mode = lowest.abs() <= 1e-8 * reference
            || error.as_deref().is_some_and(|e| e.contains("singular"));
        assert_eq!(motion.is_some(), free, "{what}: {motion:?}");
        match &motion {
            // base and tip radii along x
            Some(m) if bc == radial => {
                assert_eq!(m.half, "translation");
                assert!(
                    m.message.contains("along parallel radii")
                        && (m.message.contains("along (1.000, 0.000, 0)")
                            || m.message.contains("along (-1.000, 0.000, 0)")),
                    "{what}: {}",
                    m.message
                );
            }
            Some(m) => {
                assert!(zero_mode, "{what}: lowest {lowest:e}, step {error:?}");
                assert!(m
                    .message
                    .contains("the assembly may turn as a whole about its chord"));
            }
            None => {
                assert!(!zero_mode, "{what}: lowest {lowest:e}, step {error:?}");
                assert!(error.is_none(), "{what}: {error:?}");
            }
        }
    }
}

/// Sliding crossings free what pins hold: n = 8 helices whose bases slide along their radii
/// and whose tips slide in their plane (both clamped in rotation) keep no rod from
/// translating along its base's radius when the crossings slide. A crossing of `R_i` and
/// `L_j` lies midway in azimuth between their bases, so the same radial speed on every rod
/// moves its two rods apart along the tube's surface only, which the contacts follow by
/// sliding. The check names the motion, and the natural state's KKT matrix has it as a
/// zero-energy mode: every rod translated along its base radius, the contacts' arc lengths
/// moved along both tangents, keeps every constraint and stores no energy. With pins the
/// same motion tears the joints, and the check names nothing.
#[test]
fn sliding_crossings_let_every_rod_translate_along_its_base_radius() {
    use nalgebra::{Matrix3x2, Vector3};
    use spira::discretisation::system::System;
    let clamped = |translation| EndCondition {
        translation,
        rotation: Rotation::Clamped,
    };
    let mut case = tiny(8, "displacement", 0.01);
    for joints in [Joints::Sliding, Joints::Pin] {
        let bc = BoundaryConditions {
            base: clamped(Translation::Radial),
            tip: clamped(Translation::Slide),
            joints,
        };
        case.boundary = bc;
        let motion = free_motion_of(&bc, &case.geometry, true);
        let model = case.model();
        let x0 = model.natural_state();
        let system = System::new(&model, bc, &x0, &case.loads(), 0.0);
        let mut x = x0.clone();
        x.resize(system.n, 0.0);
        // every rod translated by its base's radial unit vector
        let mut u = vec![0.0; model.n_primal];
        let radial = |rod: usize| {
            let r = model.vertex(&x0, rod, 0);
            Vector3::new(r[0], r[1], 0.0).normalize()
        };
        for (k, rod) in model.rods.iter().enumerate() {
            let e = radial(k);
            for v in 0..=rod.mesh.elements() {
                for c in 0..3 {
                    u[rod.r_dof(v, c)] = e[c];
                }
            }
        }
        // the contacts follow: t_R δs_R − t_L δs_L = δr_L − δr_R (least squares)
        let mut off_surface = 0.0f64;
        for (k, &j) in model.slides.iter().enumerate() {
            let joint = &model.assembly.joints[j];
            let tangent = |rod: usize| {
                model.assembly.rods[rod]
                    .directors(joint.s)
                    .column(2)
                    .into_owned()
            };
            let a = Matrix3x2::from_columns(&[tangent(joint.right), -tangent(joint.left)]);
            let b = radial(joint.left) - radial(joint.right);
            let ds = (a.transpose() * a).try_inverse().expect("two tangents") * a.transpose() * b;
            off_surface = off_surface.max((a * ds - b).norm());
            u[model.slide_dof(k, 0)] = ds[0];
            u[model.slide_dof(k, 1)] = ds[1];
        }
        let (hu, cu) = crate::symmetry::kkt_action(&model, &system, &x, &u);
        let kept = cu.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        let energy = hu.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        eprintln!("{}: named {:?}; constraints {kept:e}, energy rows {energy:e}, contacts off the surface {off_surface:e}", joints.name(), motion.as_ref().map(|m| &m.message));
        match joints {
            Joints::Sliding => {
                let m = motion.expect("a free motion named");
                assert_eq!(m.half, "translation");
                assert!(m.message.contains("a free rigid motion"), "{}", m.message);
                assert!(
                    m.message.contains("the crossings slide")
                        && m.message.contains("pinned, they would hold it"),
                    "{}",
                    m.message
                );
                assert!(off_surface < 1e-12, "{off_surface:e}");
                assert!(kept < 1e-12, "the motion breaks a constraint by {kept:e}");
                assert!(energy < 1e-9, "the motion stores energy: {energy:e}");
            }
            _ => {
                assert!(motion.is_none(), "{motion:?}");
                assert!(kept > 1e-3, "pins hold the motion: {kept:e}");
            }
        }
    }
}
