//! The tube's mirror (`y ↦ −y`, right-handed helices onto left-handed ones) and the sway
//! of tubes whose cyclic symmetry is of high order: there the branch of a wavenumber-1
//! double point could turn in the plane of its modes at almost no cost, and it is held on
//! the mirror's line by a phase condition that must put no force on the tube.

use spira::case::Case;
use spira::discretisation::mirror::Mirror;
use spira::model::boundary::Translation;
use spira::results::CriticalKind;
use spira::simulation::Simulation;
use std::path::Path;

fn thesis(n: usize) -> Case {
    Case::from_file(Path::new("cases/thesis-n8.toml"))
        .unwrap()
        .with_helices(n)
}

#[test]
fn the_mirror_maps_every_tube_onto_itself_and_is_an_involution() {
    for n in [2, 8, 10] {
        let mut case = thesis(n);
        case.discretisation.symmetric = false;
        let model = case.model();
        let mirror = Mirror::of(&model).unwrap_or_else(|| panic!("n = {n} has its mirror"));
        let x = model.natural_state();
        let image = mirror.apply(&model, &x);
        for (k, rod) in model.rods.iter().enumerate() {
            for node in 0..rod.mesh.quaternion_nodes() {
                let (a, b) = (
                    model.quaternion(&x, k, node),
                    model.quaternion(&image, k, node),
                );
                // q and −q are the same frame
                let d = (a - b).norm().min((a + b).norm());
                assert!(d < 1e-9, "n = {n}, rod {k}, node {node}: {d}");
            }
            for v in 0..=rod.mesh.elements() {
                let d = (model.vertex(&x, k, v) - model.vertex(&image, k, v)).norm();
                assert!(
                    d < 1e-9 * model.length(),
                    "n = {n}, rod {k}, vertex {v}: {d}"
                );
            }
        }
        let v: Vec<f64> = (0..model.n_primal).map(|i| (i as f64).sin()).collect();
        let back = mirror.apply(&model, &mirror.apply(&model, &v));
        let err = v
            .iter()
            .zip(&back)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "n = {n}: σσv ≠ v by {err}");
    }
    // one helix has no mirror image among the rods
    assert!(Mirror::of(&thesis(1).model()).is_none());
}

/// n = 10 (cyclic symmetry of order 5) with sliding tips sways at a double wavenumber-1
/// point; switched there, the branch is held on its mirror's line. The phase condition's
/// multiplier vanishes (the state is an equilibrium of the tube without it), no spurious
/// critical point follows the switch, and the tips sway.
#[test]
fn the_ten_helix_sway_is_held_on_its_mirror_line_with_no_force() {
    let mut case = thesis(10);
    case.boundary.tip.translation = Translation::Slide;
    case.discretisation.symmetric = false;
    case.discretisation.elements = 24;
    let mut sim = Simulation::from_case_on(&case, 1).unwrap();
    let mut eps = 0.0;
    while sim.critical_points().is_empty() {
        eps += 0.05;
        assert!(eps < 0.3, "no sway up to ε = 0.3");
        sim.advance_to(eps).unwrap();
    }
    let cp = &sim.critical_points()[0];
    assert_eq!(cp.kind, CriticalKind::Bifurcation);
    assert_eq!((cp.unstable_before, cp.unstable_after), (0, 2));
    sim.switch_branch(0, 1.0, 0.02).expect("switches");
    assert!(sim.system().phase().is_some(), "the branch is held");
    sim.advance_to(eps + 0.05).expect("follows the sway");
    assert_eq!(
        sim.critical_points().len(),
        1,
        "{:?}",
        sim.critical_points()
    );
    let nu = sim.system().phase_multiplier(sim.state()).unwrap();
    assert!(nu.abs() < 1e-8 * sim.pcrit(), "phase force {nu} N");
    let shot = sim.snapshot();
    let n = shot.rods.len() as f64;
    let (mut x, mut y) = (0.0, 0.0);
    for r in &shot.rods {
        let tip = r.nodes.last().unwrap().position;
        x += tip[0] / n;
        y += tip[1] / n;
    }
    assert!(f64::hypot(x, y) > 1e-3, "the tips sway: {x}, {y}");
}
