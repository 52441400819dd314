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

/// The block work on one thread: the tests run in parallel.
const THREADS: usize = 1;

fn solve(case: &Case, eps: f64) -> Simulation {
    let mut sim = Simulation::from_case_on(case, THREADS).unwrap();
    for k in 1..=6 {
        sim.advance_to(eps * k as f64 / 6.0).unwrap();
    }
    sim
}

#[test]
fn symmetric_pair_reproduces_the_full_assembly() {
    for n in [4, 8] {
        compare_pair_and_full(thesis(n), n);
    }
}

/// The element kernels of the other hypotheses in the pair and its Bloch blocks:
/// rods stress-free when straight and Sadowsky ribbons, n = 4 and 8 (straight rods start
/// unstable at ε = 0: the counts are compared where they are not zero).
#[test]
fn symmetric_pair_reproduces_the_full_assembly_for_every_elastic_hypothesis() {
    use spira::model::elasticity::{Elasticity, Energy, Ribbon, StressFree};
    for n in [4, 8] {
        for energy in [
            Energy::Kirchhoff,
            Energy::Sadowsky(Ribbon {
                width: 0.02,
                thickness: 2e-4,
            }),
        ] {
            let mut case = thesis(n);
            case.rod = Elasticity {
                stress_free: StressFree::Straight,
                energy,
            };
            compare_pair_and_full(case, n);
        }
    }
}

fn compare_pair_and_full(mut full_case: Case, n: usize) {
    full_case.discretisation.symmetric = false;
    {
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
    // and a pair that has crossed no critical point has no branch to switch to
    let mut c = thesis(4);
    c.discretisation.symmetric = true;
    let mut sim = Simulation::from_case_on(&c, THREADS).unwrap();
    assert!(sim.switch_branch(0, 1.0, 0.05).is_err());
}

/// At a state of the pair (not an equilibrium: perturbed), the unstable directions of the
/// Bloch blocks — each block `0 < p < m/2` counted twice, for `p` and `m − p` — and their
/// lowest eigenvalue, against those of the full model at the expanded state.
pub(crate) fn blocks_against_full(case: &Case, x: &[f64]) -> (usize, usize, f64, f64) {
    use spira::discretisation::symmetry::expand_state;
    use spira::discretisation::system::System;
    use spira::model::loading::{Control, Loads};
    use spira::simulation::problem::LoadedAssembly;
    use spira::solver::problem::Problem;
    let pair = case.model();
    let np = pair.n_primal;
    let tip = &Loads::axial(Control::Displacement);
    let pair_system = System::new(&pair, case.boundary, &x[..np], tip, 0.0);
    let full = pair.full_model().expect("a symmetric pair");
    let full_system0 = System::new(&full, case.boundary, &full.natural_state(), tip, 0.0);
    let mut xf = vec![0.0; full_system0.n];
    expand_state(&pair, &pair_system, x, &full, &full_system0, &mut xf);
    // the supports hold what they hold at the expanded state, as the pair's at its own
    let full_system = System::new(&full, case.boundary, &xf[..full.n_primal], tip, 0.0);
    let mut blocks = LoadedAssembly::new(pair.clone(), pair_system).with_threads(THREADS);
    let mut whole = LoadedAssembly::new(full, full_system);
    let per_block = blocks.block_stability(x, false).unwrap();
    let counted: usize = per_block
        .iter()
        .map(|b| b.multiplicity * b.unstable_directions)
        .sum();
    let (lowest, _) = blocks.lowest_eigenvalue_with_wavenumber(x).unwrap();
    let full_count = whole.unstable_directions(&xf, 0.0).unwrap();
    let full_lowest = whole.lowest_eigenvalue(&xf, 0.0).unwrap();
    (counted, full_count, lowest, full_lowest)
}

#[test]
fn bloch_blocks_count_the_full_models_unstable_directions_at_perturbed_states() {
    for n in [4, 8, 16] {
        let mut case = thesis(8);
        case.geometry.helices = n;
        case.discretisation.symmetric = true;
        // the sliding tip (Haringx) loses stability to sideways sway, a wavenumber-1 mode:
        // solve to ε = 0.25, beyond the bifurcation, then perturb the state
        case.boundary.tip.translation = spira::model::boundary::Translation::Slide;
        let sim = solve(&case, 0.25);
        let x0 = sim.state().to_vec();
        for (k, amplitude) in [0.0, 1e-3, 3e-3].into_iter().enumerate() {
            let np = sim.model().n_primal;
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
            let (counted, full_count, lowest, full_lowest) = blocks_against_full(&case, &x);
            assert_eq!(counted, full_count, "n = {n}, amplitude {amplitude}");
            assert!(
                (lowest - full_lowest).abs() < 1e-8 * full_lowest.abs(),
                "n = {n}, amplitude {amplitude}: {lowest} vs {full_lowest}"
            );
            if amplitude == 0.0 {
                // past the sway bifurcation: a double (p, m − p) wavenumber-1 mode, or the
                // real p = 1 block of n = 4 (m = 2) counted once
                assert!(full_count >= 1, "n = {n}: {full_count}");
            }
        }
    }
}

/// `K [u; 0]` for the KKT values of `system` at `x`: `(H u, C u)`, the Hessian's and the
/// constraints' action on a primal direction `u`.
pub(crate) fn kkt_action(
    model: &spira::discretisation::discrete_model::DiscreteModel,
    system: &spira::discretisation::system::System,
    x: &[f64],
    u: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let mut residual = vec![0.0; system.n];
    let mut values = system.new_values();
    system.evaluate(model, x, &mut residual, &mut values);
    let pattern = system.pattern();
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let mut y = vec![0.0; system.n];
    for (col, &uc) in u.iter().enumerate() {
        for p in cp[col]..cp[col + 1] {
            y[ri[p]] += values[p] * uc;
        }
    }
    let np = model.n_primal;
    (y[..np].to_vec(), y[np..].to_vec())
}

/// The sliding tip (Haringx) of n = 8 sways sideways: judged by its Bloch blocks, the pair
/// finds the full model's critical point as a double mode of wavenumber 1, and the mode it
/// rebuilds on the whole assembly is a zero-energy direction of the full model there — it
/// keeps every constraint of the full model, the joints between sectors included (a wrong
/// phase would tear them), and its energy vanishes at the critical state but not before.
#[test]
fn the_sliding_tip_sways_at_a_double_wavenumber_one_mode_rebuilt_on_the_whole_assembly() {
    use spira::discretisation::symmetry::expand_state;
    use spira::discretisation::system::System;
    use spira::model::loading::{Control, Loads};
    let mut full_case = thesis(8);
    full_case.boundary.tip.translation = spira::model::boundary::Translation::Slide;
    full_case.discretisation.symmetric = false;
    let mut pair_case = full_case.clone();
    pair_case.discretisation.symmetric = true;
    let (full, pair) = (solve(&full_case, 0.2), solve(&pair_case, 0.2));
    let (cf, cp) = (&full.critical_points()[0], &pair.critical_points()[0]);
    assert_eq!(full.critical_points().len(), 1);
    assert_eq!(pair.critical_points().len(), 1);
    assert_eq!((cp.wavenumber, cp.multiplicity), (Some(1), 2));
    // the full model counts the double point as the blocks do
    assert_eq!((cf.wavenumber, cf.multiplicity), (None, 2));
    assert_eq!(
        (cp.unstable_before, cp.unstable_after),
        (cf.unstable_before, cf.unstable_after)
    );
    assert_eq!(cf.unstable_after - cf.unstable_before, 2);
    // the eigenvalue nearest zero of a double mode places the point to about 3e-7 in both
    // models (its noise floor, 3e-5 J/m, over a slope of 210 J/m per unit ε)
    assert!(
        (cp.compression_ratio - cf.compression_ratio).abs() < 1e-6 * cf.compression_ratio,
        "{} vs {}",
        cp.compression_ratio,
        cf.compression_ratio
    );
    // the rebuilt mode on the full model at the expanded critical state
    let model = pair.model();
    let whole = model.full_model().unwrap();
    let tip = &Loads::axial(Control::Displacement);
    let at = |x: &[f64]| {
        let s0 = System::new(&whole, full_case.boundary, &whole.natural_state(), tip, 0.0);
        let mut xf = vec![0.0; s0.n];
        let ps = System::new(model, full_case.boundary, &x[..model.n_primal], tip, 0.0);
        expand_state(model, &ps, x, &whole, &s0, &mut xf);
        let s = System::new(&whole, full_case.boundary, &xf[..whole.n_primal], tip, 0.0);
        (s, xf)
    };
    let u = cp
        .assembly_mode
        .as_ref()
        .expect("a mode on the whole assembly");
    assert_eq!(u.len(), whole.n_primal);
    let (system, xf) = at(&cp.state);
    let (hu, cu) = kkt_action(&whole, &system, &xf, u);
    let torn = cu.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(torn < 1e-6, "constraints violated by {torn}");
    let energy_at_critical: f64 = u.iter().zip(&hu).map(|(a, b)| a * b).sum();
    // the same direction at the stable state ε = 0.1 stores energy
    let mut early = Simulation::from_case_on(&pair_case, THREADS).unwrap();
    early.advance_to(0.1).unwrap();
    let (system, xf) = at(early.state());
    let (hu, _) = kkt_action(&whole, &system, &xf, u);
    let energy_before: f64 = u.iter().zip(&hu).map(|(a, b)| a * b).sum();
    assert!(energy_before > 0.0);
    assert!(
        energy_at_critical.abs() < 1e-5 * energy_before,
        "{energy_at_critical} vs {energy_before}"
    );
}

/// Past the sway of the sliding tip, switching branch from the pair (a wavenumber-1 mode:
/// the path moves onto the full model) and from the full model follow the same branch:
/// the same axial force, energy, lateral force magnitude and stability at the same ε (the
/// two start along different directions of the double mode's plane, so the sway may point
/// another way).
#[test]
fn switching_onto_the_sway_from_the_pair_follows_the_full_models_branch() {
    let mut full_case = thesis(8);
    full_case.boundary.tip.translation = spira::model::boundary::Translation::Slide;
    full_case.discretisation.symmetric = false;
    let mut pair_case = full_case.clone();
    pair_case.discretisation.symmetric = true;
    let (mut full, mut pair) = (solve(&full_case, 0.16), solve(&pair_case, 0.16));
    assert_eq!(pair.critical_points()[0].wavenumber, Some(1));
    for sim in [&mut full, &mut pair] {
        sim.switch_branch(0, 1.0, 0.02).expect("switches");
        sim.advance_to(0.2).expect("follows the branch");
    }
    assert_eq!(
        pair.model().rods.len(),
        8,
        "the pair moved onto the full model"
    );
    let (a, b) = (full.load_point(1), pair.load_point(1));
    // the sliding tips carry no lateral force: the sway is their mean lateral offset
    let sway = |sim: &Simulation| {
        let shot = sim.snapshot();
        let n = shot.rods.len() as f64;
        let (mut x, mut y) = (0.0, 0.0);
        for r in &shot.rods {
            let tip = r.nodes.last().unwrap().position;
            x += tip[0] / n;
            y += tip[1] / n;
        }
        f64::hypot(x, y)
    };
    let (sa, sb) = (sway(&full), sway(&pair));
    assert!(sa > 1e-4, "the branch sways: {sa} m");
    assert!((sa - sb).abs() < 1e-5 * sa, "{sa} vs {sb}");
    assert!(
        (a.load[2] - b.load[2]).abs() < 1e-6 * a.load[2].abs(),
        "{:?} vs {:?}",
        a.load,
        b.load
    );
    assert!((a.energy - b.energy).abs() < 1e-6 * a.energy);
    assert_eq!(
        a.stability.map(|s| s.unstable_directions),
        b.stability.map(|s| s.unstable_directions)
    );
}
