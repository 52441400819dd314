//! The symmetry-reduced model (one right/left pair standing for n = 2m helices) against the
//! full model: same forces, shapes, energy and stability; refused where there is no symmetry.

use nalgebra::Vector3;
use spira::case::{Case, CaseError};
use spira::model::assembly::Assembly;
use spira::simulation::Simulation;
use std::path::Path;

fn thesis(n: usize) -> Case {
    Case::from_file(Path::new(&format!("cases/thesis-n{n}.toml"))).unwrap()
}

fn solve(case: &Case, eps: f64) -> Simulation {
    let mut sim = Simulation::from_case(case).unwrap();
    for k in 1..=6 {
        sim.advance_to(eps * k as f64 / 6.0).unwrap();
    }
    sim
}

#[test]
fn symmetric_pair_reproduces_the_full_assembly() {
    for n in [4, 8] {
        let full_case = thesis(n);
        let mut pair_case = full_case.clone();
        pair_case.discretisation.symmetric = true;
        let (full, pair) = (solve(&full_case, 0.3), solve(&pair_case, 0.3));
        assert_eq!(pair.model().rods.len(), 2);
        assert!(pair.system().n * (n / 2) <= full.system().n + 10 * n);
        let (a, b) = (full.load_point(1), pair.load_point(1));
        assert_eq!(a.reactions.len(), b.reactions.len());
        let scale = Vector3::from(a.reactions[0].tip.force).norm();
        for (ra, rb) in a.reactions.iter().zip(&b.reactions) {
            assert_eq!(ra.chirality, rb.chirality);
            for k in 0..3 {
                assert!(
                    (ra.tip.force[k] - rb.tip.force[k]).abs() < 1e-9 * scale,
                    "n = {n} rod {}",
                    ra.rod
                );
                assert!((ra.base.force[k] - rb.base.force[k]).abs() < 1e-9 * scale);
                assert!((ra.tip.moment[k] - rb.tip.moment[k]).abs() < 1e-9 * scale);
            }
        }
        for k in 0..3 {
            assert!((a.load[k] - b.load[k]).abs() < 1e-9 * a.load[2].abs());
        }
        assert!((a.energy - b.energy).abs() < 1e-9 * a.energy);
        // shapes of all rods, the images included
        let (sa, sb) = (full.snapshot(), pair.snapshot());
        assert_eq!(sa.rods.len(), sb.rods.len());
        for (ra, rb) in sa.rods.iter().zip(&sb.rods) {
            for (na, nb) in ra.nodes.iter().zip(&rb.nodes) {
                for k in 0..3 {
                    assert!((na.position[k] - nb.position[k]).abs() < 1e-9);
                    assert!((na.curvature[k] - nb.curvature[k]).abs() < 1e-7);
                }
                let qa = nalgebra::Vector4::from(na.quaternion);
                let qb = nalgebra::Vector4::from(nb.quaternion);
                assert!((qa - qb).norm().min((qa + qb).norm()) < 1e-9);
            }
        }
        // stability is judged on the full model, non-symmetric modes included
        let (st_a, st_b) = (a.stability.unwrap(), b.stability.unwrap());
        assert_eq!(st_a.unstable_directions, st_b.unstable_directions);
        let (la, lb) = (
            st_a.lowest_eigenvalue.unwrap(),
            st_b.lowest_eigenvalue.unwrap(),
        );
        assert!((la - lb).abs() < 1e-6 * la.abs(), "n = {n}: {la} vs {lb}");
    }
}

#[test]
fn assemblies_without_the_symmetry_are_refused_the_reduction() {
    for n in [1, 2] {
        let asm = Assembly::new(n, 0.06, 0.025, 1.0);
        assert!(asm.symmetric_pair().is_err(), "n = {n}");
        let text = format!("[geometry]\nhelices = {n}\n[discretisation]\nsymmetric = true\n");
        match Case::parse(&text, "sym.toml", "sym") {
            Err(CaseError::Invalid {
                key, line, message, ..
            }) => {
                assert_eq!(key, "discretisation.symmetric");
                assert_eq!(line, 4);
                assert!(message.contains("symmetry"), "{message}");
            }
            other => panic!("n = {n}: expected a refusal, got {other:?}"),
        }
    }
    // and a symmetric pair cannot switch to a branch that breaks its symmetry
    let mut c = thesis(4);
    c.discretisation.symmetric = true;
    let mut sim = Simulation::from_case(&c).unwrap();
    assert!(sim.switch_branch(0, 1.0, 0.05).is_err());
}
