//! The cell of the infinite tube (docs/theory.md §8) against numbers that do not come from
//! it: the uniform helix of the pinned lattice (Love's force, and the pantograph's under
//! pressure), Euler's and Greenhill's bands of an infinite straight rod, and a ring of
//! cells closed on itself.

use spira::discretisation::cell::default_elements;
use spira::discretisation::discrete_model::{DiscreteModel, End};
use spira::discretisation::shape::Order;
use spira::discretisation::system::System;
use spira::model::assembly::Assembly;
use spira::model::boundary::{BoundaryConditions, Joints};
use spira::model::elasticity::Reference;
use spira::model::loading::{AxialHeld, Component, Control, Held, Loads};
use spira::model::love::LoveHelix;
use spira::model::quaternion::{self, Quat};
use spira::model::stiffness::Stiffness;
use spira::simulation::cell::CellJudge;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;

use crate::{A0, B0, STIFFNESS};

/// The cell of the thesis tube of `n` helices at its default mesh, solved under `loads`
/// from the natural state up to `target`.
fn solved_cell(n: usize, cells: usize, loads: Loads, target: f64) -> Simulation {
    let joints = BoundaryConditions::default().joints;
    solved_cells(
        n,
        cells,
        joints,
        loads,
        target,
        ContinuationSettings::default(),
    )
}

/// The cell (`cells` cells closed on themselves) of the thesis tube of `n` helices at its
/// default mesh, its crossings `joints`, solved under `loads` from the natural state up to
/// `target`.
pub(crate) fn solved_cells(
    n: usize,
    cells: usize,
    joints: Joints,
    loads: Loads,
    target: f64,
    settings: ContinuationSettings,
) -> Simulation {
    let assembly = Assembly::tube_cells(n, A0, B0, cells).expect("a tube cell");
    let elements = cells * default_elements(n);
    let model = DiscreteModel::new(assembly, STIFFNESS, elements, Order::Quadratic);
    let x = model.natural_state();
    let bc = BoundaryConditions {
        joints,
        ..BoundaryConditions::default()
    };
    let mut sim =
        Simulation::with_loads(model, bc, loads, x, settings).expect("the natural state solves");
    sim.advance_to(target).expect("the cell follows the load");
    sim
}

/// Love's helix of the thesis tube's rods of length `length` (m) compressed by `eps`.
pub(crate) fn love(length: f64, eps: f64) -> LoveHelix {
    LoveHelix {
        radius0: A0,
        pitch0: B0,
        length,
        stiffness: STIFFNESS,
        pitch: B0 * (1.0 - eps),
        elasticity: Default::default(),
        reference: Reference::Discrete,
    }
}

/// Compressed by ε, every rod of the cell is Love's helix with c = c0, b = b0 (1 − ε): the
/// axial force each carries is Love's to 1e-8 at the default mesh, for n = 2, 8 and 64.
#[test]
fn the_compressed_cell_carries_loves_force() {
    for n in [2, 8, 64] {
        for eps in [0.25, 0.5, -0.3] {
            let sim = solved_cell(n, 1, Loads::axial(Control::Displacement), eps);
            assert!((sim.compression_ratio() - eps).abs() < 1e-12);
            let f = love(sim.model().length(), eps).force();
            for rod in 0..2 {
                let (force, _) = sim
                    .system()
                    .reaction(sim.model(), sim.state(), rod, End::Tip);
                let rel = (force[2] - f).abs() / f.abs();
                println!(
                    "n = {n}, eps = {eps}, rod {rod}: fz {:.12} Love {f:.12} rel {rel:.2e}",
                    force[2]
                );
                assert!(
                    rel < 1e-8,
                    "n = {n}, eps = {eps}, rod {rod}: {} vs {f}",
                    force[2]
                );
                assert!(force[0].abs() + force[1].abs() < 1e-8 * f.abs());
            }
        }
    }
}

/// Pressed by q at a held ε, the cell stays on the pantograph (its radius fixed by c = c0
/// and b) and the axial force changes by the pressure's share: F = F_Love − q b c0/a.
#[test]
fn the_pressed_cell_carries_the_pantographs_force() {
    let (eps, q) = (0.3, 1500.0);
    for n in [2, 8, 64] {
        let held = Held {
            axial: AxialHeld::Ratio(eps),
            ..Held::NATURAL
        };
        let loads = Loads::compose(Component::Pressure, Control::Force, held);
        let sim = solved_cell(n, 1, loads, q);
        let love = love(sim.model().length(), eps);
        let (a, b, c0) = (love.radius(), love.pitch, love.c0());
        let f = love.force() - q * b * c0 / a;
        for rod in 0..2 {
            let (force, _) = sim
                .system()
                .reaction(sim.model(), sim.state(), rod, End::Tip);
            let rel = (force[2] - f).abs() / f.abs();
            println!(
                "n = {n}, q = {q}, rod {rod}: fz {:.12} closed form {f:.12} rel {rel:.2e}",
                force[2]
            );
            assert!(rel < 1e-8, "n = {n}, rod {rod}: {} vs {f}", force[2]);
        }
    }
}

/// A straight rod on the axis (B1 = B2 = `b`, B3 = `c`) as a one-rod cell of length 1 m,
/// twisted by the torque `t` and compressed by `p` (N): the state by hand (positions on
/// the axis, frames turned about it at the rate t/c, every element's force −p e_z, the
/// unit-norm multipliers balancing the rest) and the judge of its Bloch blocks.
pub(crate) fn straight_rod(
    b: f64,
    c: f64,
    p: f64,
    t: f64,
) -> (DiscreteModel, System, Vec<f64>, CellJudge) {
    let rate = t / c;
    let assembly = Assembly::straight_cell(1.0, rate).expect("a straight cell");
    let stiffness = Stiffness {
        b1: b,
        b2: b,
        b3: c,
    };
    let model = DiscreteModel::new(assembly, stiffness, 64, Order::Quadratic);
    let mut x = model.natural_state();
    let rod = &model.rods[0];
    for node in 0..rod.mesh.quaternion_nodes() {
        let q = model.quaternion(&x, 0, node);
        let turned = quaternion::mul(
            &quaternion::about_z(rate * rod.mesh.node_arc_length(node)),
            &q,
        );
        for k in 0..4 {
            x[rod.q_dof(node, k)] = turned[k];
        }
    }
    let loads = Loads::axial(Control::Displacement);
    let system = System::new(&model, BoundaryConditions::default(), &x, &loads, 0.0);
    x.resize(system.n, 0.0);
    for e in 0..rod.mesh.elements() {
        x[system.compat_row(0, e) + 2] = -p;
    }
    let mut residual = vec![0.0; system.n];
    system.residual(&model, &x, &mut residual);
    for node in 0..rod.mesh.quaternion_nodes() {
        let q: Quat = model.quaternion(&x, 0, node);
        let g = Quat::from_fn(|k, _| residual[rod.q_dof(node, k)]);
        x[system.unit_row(0, node)] = -g.dot(&q) / (2.0 * q.norm_squared());
    }
    let judge = CellJudge::new(&model, &system, 9).expect("a cell");
    (model, system, x, judge)
}

/// The phase (rad per cell) in `(lo, hi)` where the lowest eigenvalue of block `(0, k)`
/// changes sign, by bisection.
fn band_edge(rod: &mut (DiscreteModel, System, Vec<f64>, CellJudge), lo: f64, hi: f64) -> f64 {
    let (model, system, x, judge) = rod;
    let sign = |k: f64| judge.lowest_at(model, system, x, 0, k).expect("converges") < 0.0;
    crate::bisect_change(sign, lo, hi, 1e-10)
}

/// Helical perturbations e^{iks} of an infinite straight rod under compression P and torque
/// T are unstable between the roots of B k² − T k − P = 0 (k > 0 a right-handed helix). In
/// the cell of length ℓ whose far frame is turned by ψ = T ℓ/B3, the helix k lives in the
/// block of phase |k ℓ − ψ|: Euler's band |k| < √(P/B) at T = 0, and under torque alone
/// 0 < k < T/B, to 1e-6.
#[test]
fn a_straight_rod_cell_is_unstable_in_eulers_and_greenhills_bands() {
    let root =
        |b: f64, t: f64, p: f64, sign: f64| (t + sign * (t * t + 4.0 * b * p).sqrt()) / (2.0 * b);
    // (B, B3, P, T): Euler; compression and torque; torque alone
    for (b, c, p, t) in [
        (1.0, 2.0, 1.0, 0.0),
        (1.0, 1.0, 1.0, 1.0),
        (1.0, 4.0, 0.0, 1.0),
    ] {
        let psi = t / c;
        let (k_minus, k_plus) = (root(b, t, p, -1.0), root(b, t, p, 1.0));
        // the band of phases: |k ℓ − ψ| over (k−, k+), which holds 0 for these loads
        let expected = (k_minus - psi).abs().max((k_plus - psi).abs());
        let mut rod = straight_rod(b, c, p, t);
        let edge = band_edge(&mut rod, 0.5 * expected, (1.5 * expected).min(3.0));
        let (model, system, x, judge) = &mut rod;
        let inside = judge
            .lowest_at(model, system, x, 0, 0.5 * expected)
            .expect("converges");
        println!("B {b} B3 {c} P {p} T {t}: edge {edge:.10} expected {expected:.10} error {:.2e}; lowest inside {inside:.4e}", (edge - expected).abs());
        assert!(inside < 0.0, "unstable inside the band");
        assert!(
            (edge - expected).abs() < 1e-6 * expected,
            "edge {edge} vs {expected}"
        );
    }
}

/// At k = 2πj/N the cell's spectrum is that of N cells closed on themselves: block (p, 0) of
/// the N-cell ring has the lowest eigenvalue of the cell's blocks (p, 2πj/N), j = 0 … N − 1,
/// to 1e-8, and as many eigenvalues below any level as they have together.
#[test]
fn the_cells_spectrum_at_k_2pi_j_over_n_is_that_of_a_ring_of_n_cells() {
    let (n, eps) = (8, 0.3);
    let cell = solved_cell(n, 1, Loads::axial(Control::Displacement), eps);
    let mut on_cell = CellJudge::new(cell.model(), cell.system(), 9).expect("a cell");
    for cells in [4, 8] {
        let ring = solved_cell(n, cells, Loads::axial(Control::Displacement), eps);
        ring_against_cell(&cell, &mut on_cell, &ring, cells);
    }
}

/// The ring check of the ring `ring` of `cells` cells against the cell `cell` (see above).
pub(crate) fn ring_against_cell(
    cell: &Simulation,
    on_cell: &mut CellJudge,
    ring: &Simulation,
    cells: usize,
) {
    let m = cell.model().assembly.cell.as_ref().expect("a cell").m;
    let mut on_ring = CellJudge::new(ring.model(), ring.system(), 9).expect("a cell");
    let phases: Vec<f64> = (0..cells)
        .map(|j| 2.0 * std::f64::consts::PI * j as f64 / cells as f64)
        .collect();
    for p in 0..m {
        let ring_lowest = on_ring
            .lowest_at(ring.model(), ring.system(), ring.state(), p, 0.0)
            .expect("converges");
        let cell_lowest = phases
            .iter()
            .map(|&k| {
                on_cell
                    .lowest_at(cell.model(), cell.system(), cell.state(), p, k)
                    .expect("converges")
            })
            .fold(f64::INFINITY, f64::min);
        let rel = (ring_lowest - cell_lowest).abs() / cell_lowest.abs();
        println!(
            "{cells} cells, p = {p}: ring {ring_lowest:.12} cell {cell_lowest:.12} rel {rel:.2e}"
        );
        assert!(rel < 1e-8, "p = {p}: {ring_lowest} vs {cell_lowest}");
        for sigma in [2.0, 4.0, 8.0].map(|f| f * cell_lowest.abs()) {
            let ring_count = on_ring
                .count_below_at(ring.model(), ring.system(), ring.state(), (p, 0.0), sigma)
                .expect("factorises");
            let counts: Vec<usize> = phases
                .iter()
                .map(|&k| {
                    on_cell
                        .count_below_at(cell.model(), cell.system(), cell.state(), (p, k), sigma)
                        .expect("factorises")
                })
                .collect();
            let cell_count: usize = counts.iter().sum();
            println!("  below {sigma:.3}: ring {ring_count} cells {cell_count}");
            assert_eq!(ring_count, cell_count, "p = {p}, below {sigma}");
        }
    }
}

/// `cases/cell-n8.toml` as a run: every output step's rods carry Love's force, the
/// dispersion covers every wavenumber on 65 phases, and the compressed tube's column band
/// of p = 1 lies about k = π/m, the phase of its rigid translation.
#[test]
fn the_shipped_cell_case_runs_to_loves_force_with_its_column_band() {
    let case = spira::case::Case::from_file(std::path::Path::new("cases/cell-n8.toml"))
        .expect("the shipped case reads");
    assert!(case.discretisation.cell);
    let targets = case.output_parameters(case.loading.target, case.loading.steps);
    let outcome = spira::run::run_path(&case, &targets, |_, _| {}).expect("the path runs");
    assert!(outcome.error.is_none());
    assert_eq!(outcome.dispersion.len(), outcome.points.len());
    for (point, d) in outcome.points.iter().zip(&outcome.dispersion) {
        let eps = point.compression_ratio;
        let f = love(outcome.model.length(), eps).force();
        for r in &point.reactions {
            let fz = r.tip.force[2];
            assert!(
                (fz - f).abs() <= 1e-8 * f.abs().max(1.0),
                "eps = {eps}: {fz} vs {f}"
            );
        }
        assert_eq!(d.dispersion.lowest.len(), 4);
        assert!(d.dispersion.lowest.iter().all(|row| row.len() == 65));
    }
    let last = &outcome.dispersion.last().expect("points").dispersion;
    let quarter = std::f64::consts::FRAC_PI_4;
    let bands = last.unstable_bands(1);
    // one band of the column's long waves on both sides of the translation's phase π/4,
    // where the block holds the rigid translation (its value written 0)
    assert_eq!(bands.len(), 1, "{bands:?}");
    assert!(bands[0].0 < quarter && quarter < bands[0].1, "{bands:?}");
    for (from, to) in bands {
        assert!(
            from < to && from >= quarter - 0.5 && to <= quarter + 0.5,
            "({from}, {to})"
        );
    }
}

/// A tilt makes the cell the tube's bending cell (n = 2m, m ≥ 2); a tube of two helices
/// is refused it, saying so.
#[test]
fn a_cell_is_bent_only_with_two_helices_of_each_hand() {
    let text = std::fs::read_to_string("cases/cell-n8.toml").expect("the shipped case");
    let tilted = text.replace(
        "[loading]",
        "[loading]\nparameter = \"tilt\"\nhold = { axial = 0.0 }",
    );
    let case = spira::case::Case::parse(&tilted, "tilted.toml", "tilted")
        .expect("a tilted cell of 8 helices");
    assert!(case.bends_cell());
    let model = case.model();
    assert_eq!(model.rods.len(), 8);
    let two = tilted.replace("helices = 8", "helices = 2");
    let err = spira::case::Case::parse(&two, "tilted.toml", "tilted")
        .expect_err("a tilted cell of 2 helices is refused");
    let message = err.to_string();
    assert!(message.contains("discretisation.model"), "{message}");
    assert!(message.contains("m >= 2"), "{message}");
}

/// The loads of a cell twisted by `phi` (rad per cell, stepped) at the held strain `eps`.
fn twist_at(eps: f64) -> Loads {
    let held = Held {
        axial: AxialHeld::Ratio(eps),
        ..Held::NATURAL
    };
    Loads::compose(Component::Twist, Control::Displacement, held)
}

/// Continuation settings without the stability of the path (the twisted lattice buckles
/// early; these checks are of the equilibrium).
fn equilibrium_only() -> ContinuationSettings {
    ContinuationSettings {
        track_stability: false,
        lowest_eigenvalue: false,
        ..ContinuationSettings::default()
    }
}

/// One helix alone as a cell (the rod of the tube's cell of `n` helices without its
/// partner: 1/n of a turn), twisted by φ per cell at a held strain ε: it stays the uniform
/// helix through its near end and the screw image of it, turning by ψ = 2π/n + φ over the
/// arc ℓ with the rise h = h0 (1 − ε), so a = √(ℓ² − h²)/ψ and b = h/ψ, and carries Love's
/// axial force and couple there, to 1e-8, for n = 2, 8, 64.
#[test]
fn a_twisted_helix_cell_carries_loves_force_and_couple() {
    use spira::model::helix::Chirality;
    use spira::model::love::axial_wrench;
    for n in [2, 8, 64] {
        let turn = 2.0 * std::f64::consts::PI / n as f64;
        for (eps, phi) in [(0.3, 0.2 * turn), (0.0, -0.1 * turn), (-0.2, 0.05 * turn)] {
            let assembly = Assembly::helix_cell(A0, B0, turn).expect("a helix cell");
            let model =
                DiscreteModel::new(assembly, STIFFNESS, default_elements(n), Order::Quadratic);
            let x = model.natural_state();
            let (length, h0) = (model.length(), model.height0());
            let mut sim = Simulation::with_loads(
                model,
                BoundaryConditions::default(),
                twist_at(eps),
                x,
                equilibrium_only(),
            )
            .expect("the natural state solves");
            sim.advance_to(phi).expect("the cell follows the twist");
            let psi = turn + phi;
            let h = h0 * (1.0 - eps);
            let (a, b) = ((length * length - h * h).sqrt() / psi, h / psi);
            let (f, m) =
                axial_wrench((A0, B0), (a, b), &STIFFNESS, Chirality::Right).expect("a helix");
            let point = sim.load_point(0);
            let fz = point.reactions[0].tip.force[2];
            let torque = point.support.torque;
            let (ef, em) = ((fz - f).abs() / f.abs(), (torque - m).abs() / m.abs());
            println!("n = {n}, eps = {eps}, phi = {phi:.5}: fz {fz:.12} Love {f:.12} ({ef:.1e}), T {torque:.12} Love {m:.12} ({em:.1e})");
            assert!(ef < 1e-8 && em < 1e-8, "n = {n}, eps = {eps}, phi = {phi}");
        }
    }
}

/// The tube's cell twisted at a held strain, for n = 2, 8, 64: the pinned lattice cannot
/// shear, so its rods leave the helices and no uniform helix is a closed form; what holds
/// instead is that the torque is the energy's rate, ∫ T dφ = energy of the m cells of one
/// rise (Simpson on 64 steps, to 1e-8 of the energy), and the mirror image of the tube (right
/// and left helices exchanged) carries T(−φ) = −T(φ), its left rod the axial force of the
/// right rod under φ, to 1e-9.
#[test]
fn the_twisted_tube_cell_stores_the_work_of_its_torque_and_is_mirror_symmetric() {
    let steps = 64;
    for (n, target) in [(2, 0.2), (8, 0.01), (64, 1e-5)] {
        let eps = 0.2;
        let path = |sign: f64| {
            let assembly = Assembly::tube_cell(n, A0, B0).expect("a tube cell");
            let model =
                DiscreteModel::new(assembly, STIFFNESS, default_elements(n), Order::Quadratic);
            let x = model.natural_state();
            let mut sim = Simulation::with_loads(
                model,
                BoundaryConditions::default(),
                twist_at(eps),
                x,
                equilibrium_only(),
            )
            .expect("the natural state solves");
            let start = sim.load_point(0).energy;
            let points: Vec<_> = (0..=steps)
                .map(|i| {
                    let phi = sign * target * i as f64 / steps as f64;
                    sim.advance_to(phi).expect("the cell follows the twist");
                    let p = sim.load_point(i);
                    (
                        p.support.torque,
                        p.energy - start,
                        [0, 1].map(|r| p.reactions[r].tip.force[2]),
                    )
                })
                .collect();
            points
        };
        let (plus, minus) = (path(1.0), path(-1.0));
        let d = target / steps as f64;
        let work: f64 = (0..steps / 2)
            .map(|j| d / 3.0 * (plus[2 * j].0 + 4.0 * plus[2 * j + 1].0 + plus[2 * j + 2].0))
            .sum();
        let energy = plus[steps].1;
        let rel = (work - energy).abs() / energy;
        // the mirror exchanges the right rod (0) and the left one (1)
        let (t, f) = (plus[steps].0, plus[steps].2);
        let (tm, fm) = (minus[steps].0, minus[steps].2);
        let mirror = ((t + tm).abs() / t.abs())
            .max((f[0] - fm[1]).abs() / f[0].abs())
            .max((f[1] - fm[0]).abs() / f[1].abs());
        println!("n = {n}: phi {target}, T {t:.9} N m, work {work:.12} energy {energy:.12} ({rel:.1e}); mirror T {tm:.9}, fz {f:.9?} / {fm:.9?} ({mirror:.1e})");
        assert!(rel < 1e-8, "n = {n}: work {work} vs energy {energy}");
        assert!(mirror < 1e-9, "n = {n}: T {t} / {tm}, fz {f:?} / {fm:?}");
    }
}

/// Welded and elastic crossings on the cell (the weld's rows kept although the cell's rods
/// end at crossings, where a finite tube's clamped supports would already hold them): the
/// energy stored by the m cells of one rise is m times the work of one cell's axial forces
/// over its rise, m Σ ∫ F dh
/// (Simpson on 32 steps of ε to 0.2, to 1e-8 of the energy), for n = 2, 8, 64; the weld
/// keeps the angle between the rods, so the welded cell is stiffer than the elastic one,
/// which is stiffer than the pinned one (whose rods stay Love's helices).
#[test]
fn welded_and_elastic_cells_store_the_work_of_their_axial_forces() {
    use spira::model::boundary::{JointStiffness, Joints};
    let steps = 32;
    for n in [2usize, 8, 64] {
        let mut forces = Vec::new();
        let springs = JointStiffness {
            scissor: 0.1,
            out_of_plane: 0.1,
        };
        for joints in [Joints::Pin, Joints::Elastic(springs), Joints::Welded] {
            let assembly = Assembly::tube_cell(n, A0, B0).expect("a tube cell");
            let model =
                DiscreteModel::new(assembly, STIFFNESS, default_elements(n), Order::Quadratic);
            let x = model.natural_state();
            let bc = BoundaryConditions {
                joints,
                ..BoundaryConditions::default()
            };
            let mut sim = Simulation::with_loads(
                model,
                bc,
                Loads::axial(Control::Displacement),
                x,
                equilibrium_only(),
            )
            .expect("the natural state solves");
            let points: Vec<_> = (0..=steps)
                .map(|i| {
                    sim.advance_to(0.2 * i as f64 / steps as f64)
                        .expect("the cell follows the compression");
                    sim.load_point(i)
                })
                .collect();
            let fz: Vec<f64> = points
                .iter()
                .map(|p| p.reactions.iter().map(|r| r.tip.force[2]).sum())
                .collect();
            let dh = points[1].height - points[0].height;
            let d = |j: usize| dh / 3.0 * (fz[2 * j] + 4.0 * fz[2 * j + 1] + fz[2 * j + 2]);
            // the energy is of the m cells of one rise, around the axis
            let work = (n / 2) as f64 * (0..steps / 2).map(d).sum::<f64>();
            let energy = points[steps].energy - points[0].energy;
            let rel = (work - energy).abs() / energy;
            println!("n = {n}, {joints:?}: energy {energy:.12} J, work {work:.12} J ({rel:.1e}), fz {:.6} N", fz[steps]);
            assert!(
                rel < 1e-8,
                "n = {n}, {joints:?}: work {work} vs energy {energy}"
            );
            forces.push(fz[steps]);
        }
        // compressive forces: the welded cell carries the most, the pinned one the least
        assert!(
            forces[2] < forces[1] && forces[1] < forces[0] && forces[0] < 0.0,
            "n = {n}: pin, elastic, welded {forces:?}"
        );
    }
}

/// The lowest eigenvalue of a Hermitian KKT block `[[H, Jᴴ], [J, 0]]` (values `block` in
/// the pattern of `system`) on its constraints, by dense linear algebra: the null space `Z`
/// of `J` from a singular value decomposition (zero rows dropped), then `Zᴴ H Z v = λ Zᴴ M Z v`
/// with `Zᴴ M Z` positive definite (positions follow the rotations through the constraints),
/// reduced to a standard problem by its eigenvectors.
fn dense_lowest(system: &System, block: &[faer::c64], metric: &[f64]) -> f64 {
    use nalgebra::{Complex, DMatrix};
    let n_primal = metric.len();
    let pattern = system.pattern();
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let mut h = DMatrix::<Complex<f64>>::zeros(n_primal, n_primal);
    let mut j_rows: Vec<Vec<(usize, Complex<f64>)>> = vec![Vec::new(); system.n - n_primal];
    for col in 0..n_primal {
        for q in cp[col]..cp[col + 1] {
            let v = Complex::new(block[q].re, block[q].im);
            if ri[q] < n_primal {
                h[(ri[q], col)] = v;
            } else if v.norm() > 0.0 {
                j_rows[ri[q] - n_primal].push((col, v));
            }
        }
    }
    // J padded with zero rows to a square matrix: its V is then complete
    let mut j = DMatrix::<Complex<f64>>::zeros(n_primal, n_primal);
    for (r, row) in j_rows.iter().filter(|r| !r.is_empty()).enumerate() {
        for &(col, v) in row {
            j[(r, col)] = v;
        }
    }
    let svd = j.svd(false, true);
    let v_t = svd.v_t.expect("V requested");
    let largest = svd.singular_values.max();
    let null: Vec<usize> = (0..n_primal)
        .filter(|&i| svd.singular_values[i] <= 1e-12 * largest)
        .collect();
    let z = DMatrix::from_fn(n_primal, null.len(), |r, c| v_t[(null[c], r)].conj());
    let m = DMatrix::from_fn(n_primal, n_primal, |r, c| {
        Complex::new(if r == c { metric[r] } else { 0.0 }, 0.0)
    });
    let a = z.adjoint() * &h * &z;
    let b = (z.adjoint() * &m * &z).symmetric_eigen();
    assert!(b.eigenvalues.min() > 1e-12 * b.eigenvalues.max());
    let scale = b.eigenvalues.map(|e| 1.0 / e.sqrt());
    let u = &b.eigenvectors;
    let reduced = u.adjoint() * a * u;
    let c = DMatrix::from_fn(reduced.nrows(), reduced.ncols(), |r, k| {
        reduced[(r, k)] * scale[r] * scale[k]
    });
    c.symmetric_eigen().eigenvalues.min()
}

/// The lowest eigenvalue of the Hermitian block `(p, k)` of the cell `sim` at its state, by
/// [`dense_lowest`].
fn dense_blocks(sim: &Simulation) -> impl FnMut(usize, f64) -> f64 + '_ {
    use spira::discretisation::cell_blocks::CellBlocks;
    let (model, system, x) = (sim.model(), sim.system(), sim.state());
    let mut residual = vec![0.0; system.n];
    let mut kkt = system.new_values();
    system.evaluate(model, x, &mut residual, &mut kkt);
    let blocks = CellBlocks::new(model, system).expect("a cell");
    let metric = crate::rotation_metric(model);
    let mut block = vec![faer::c64::new(0.0, 0.0); kkt.len()];
    move |p, k| {
        blocks.hermitian_block(p, k, &kkt, &mut block);
        dense_lowest(system, &block, &metric)
    }
}

/// The n = 8 cell compressed to ε = 0.25: the map's lowest eigenvalue of the blocks where
/// the count and the iteration disagreed when the regularisation weighed the constraints on
/// positions by the cell's own length (p = 1 about k = π/4, the map's minimum; p = 0 at
/// small k) equals a dense constrained solve of the same block to 1e-8, and wavenumber 1's
/// map is symmetric about k = π/4 (its blocks at k and π/2 − k have equal spectra, which
/// the dense solves show to 1e-10) to 1e-8.
#[test]
fn the_cell_map_matches_dense_constrained_solves() {
    use std::f64::consts::PI;
    let sim = solved_cell(8, 1, Loads::axial(Control::Displacement), 0.25);
    let map = sim.dispersion(65).expect("a cell");
    let mut dense_at = dense_blocks(&sim);
    let mut dense = |p: usize, i: usize| dense_at(p, map.phases[i]);
    for (p, i) in [(1, 14), (1, 15), (1, 17), (1, 18), (0, 1), (0, 3), (0, 6)] {
        let reference = dense(p, i);
        let found = map.lowest[p][i].expect("a lowest eigenvalue");
        let rel = (found - reference).abs() / reference.abs();
        println!(
            "p = {p}, k = {:.4}: map {found:.10} dense {reference:.10} rel {rel:.2e}",
            map.phases[i]
        );
        assert!(rel < 1e-8, "p = {p}, i = {i}: {found} vs {reference}");
    }
    let (below, above) = (dense(1, 15), dense(1, 17));
    assert!(
        (below - above).abs() < 1e-10 * below.abs(),
        "{below} vs {above}"
    );
    assert!((map.phases[16] - PI / 4.0).abs() < 1e-15);
    // k = π/4 itself holds the tube's translation across its axis (reported as 0)
    for i in 0..16 {
        let (a, b) = (map.lowest[1][i], map.lowest[1][32 - i]);
        let (a, b) = (a.expect("an eigenvalue"), b.expect("an eigenvalue"));
        let rel = (a - b).abs() / a.abs().max(b.abs());
        println!(
            "p = 1, k = {:.4} and {:.4}: {a:.10} {b:.10} rel {rel:.2e}",
            map.phases[i],
            map.phases[32 - i]
        );
        assert!(rel < 1e-8, "k index {i}: {a} vs {b}");
    }
}

/// The mirror `y ↦ −y` of a compressed cell (n = 8, m = 4) carries block `(p, k)` onto the
/// conjugate of `(p, 2πp/m − k)`: the dispersion, which searches one block of each such
/// pair, gives at the other one the value of that block searched by itself, to 1e-8; a
/// twisted cell, which the mirror does not keep, has its blocks searched one by one, and
/// they agree with the dispersion too.
#[test]
fn the_dispersion_takes_the_mirror_images_of_its_blocks_only_where_the_mirror_holds() {
    let n = 8;
    let compressed = solved_cell(n, 1, Loads::axial(Control::Displacement), 0.25);
    let twisted = {
        let assembly = Assembly::tube_cell(n, A0, B0).expect("a tube cell");
        let model = DiscreteModel::new(assembly, STIFFNESS, default_elements(n), Order::Quadratic);
        let x = model.natural_state();
        let mut sim = Simulation::with_loads(
            model,
            BoundaryConditions::default(),
            twist_at(0.1),
            x,
            equilibrium_only(),
        )
        .expect("the natural state solves");
        sim.advance_to(0.02).expect("the cell twists");
        sim
    };
    // (p, i) on the 65 phases k = iπ/64: each the mirror image of a block the dispersion
    // of the compressed cell searches, (2, 64 − i), (1, 32 − i), (1, i + 32) for (3, i)
    let images = [(2, 40), (2, 64), (1, 30), (3, 10), (3, 60), (1, 20)];
    for (name, sim) in [("compressed", &compressed), ("twisted", &twisted)] {
        let mut judge = CellJudge::new(sim.model(), sim.system(), 65).expect("a cell");
        let map = judge.dispersion(sim.model(), sim.system(), sim.state());
        for (p, i) in images {
            let k = map.phases[i];
            let own = judge
                .lowest_at(sim.model(), sim.system(), sim.state(), p, k)
                .expect("converges");
            let mapped = map.lowest[p][i].expect("found");
            let rel = (own - mapped).abs() / own.abs();
            println!("{name}: p = {p}, k = {k:.4}: by itself {own:.10}, in the map {mapped:.10}, rel {rel:.1e}");
            assert!(rel < 1e-8, "{name} ({p}, {k}): {own} vs {mapped}");
        }
        // the twist breaks the mirror: a pair's two blocks part, so copying one onto the
        // other would have been seen above
        let (a, b) = (map.lowest[2][40], map.lowest[2][24]);
        let (a, b) = (a.expect("found"), b.expect("found"));
        let parted = (a - b).abs() / a.abs();
        println!("{name}: (2, k) and (2, π − k) at k = 40π/64: {a:.10} and {b:.10}");
        if name == "twisted" {
            assert!(parted > 1e-3, "{a} vs {b}");
        } else {
            assert!(parted < 1e-9, "{a} vs {b}");
        }
    }
}

/// Close to the phase ψ = π/m where the block holds a rigid translation (the tube's across
/// its axis in (1, ψ); with sliding crossings the rods' along the surface in (0, ψ)), the
/// bending wave's energy and metric both vanish as (k − ψ)². The block search at any phase,
/// regularised as the dispersion's, still finds its eigenvalue: against a dense constrained
/// solve at ε = 0.3 (n = 8) to 1e-6 down to |k − ψ| = 3e-3 rad with pins and 1e-2 with
/// sliding crossings (the map's grid comes no closer than π/64 ≈ 0.049; closer still the
/// count loses the wave to the regularisation: docs/joints.md).
#[test]
fn the_block_search_follows_the_bending_wave_close_to_the_held_translation() {
    use spira::simulation::cell::CellJudge;
    use std::f64::consts::PI;
    for (joints, p, closest) in [(Joints::Pin, 1, 3e-3), (Joints::Sliding, 0, 1e-2)] {
        let sim = solved_cells(
            8,
            1,
            joints,
            Loads::axial(Control::Displacement),
            0.3,
            ContinuationSettings::default(),
        );
        let (model, system, x) = (sim.model(), sim.system(), sim.state());
        let mut dense_at = dense_blocks(&sim);
        let mut judge = CellJudge::new(model, system, 2).expect("a cell");
        for d in [1e-1, 3e-2, 1e-2, 3e-3]
            .into_iter()
            .filter(|&d| d >= closest)
        {
            let k = PI / 4.0 - d;
            let dense = dense_at(p, k);
            let sparse = judge
                .lowest_at(model, system, x, p, k)
                .expect("the search converges");
            let rel = (sparse - dense).abs() / dense.abs();
            println!("{joints:?}, p = {p}, ψ − {d:e}: search {sparse:.10} dense {dense:.10} rel {rel:.1e}");
            assert!(
                rel < 1e-6,
                "{joints:?}, p = {p}, ψ − {d}: {sparse} vs {dense}"
            );
        }
    }
}
