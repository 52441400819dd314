//! The infinite tube as a beam (docs/theory.md §8): the stiffnesses of its cell, exact
//! from the constrained tangent, against Love's helix in closed form and against finite
//! differences of whole solves; the bending stiffness's Bloch branch against the tube's
//! axial force.

use spira::discretisation::cell::default_elements;
use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::shape::Order;
use spira::model::assembly::Assembly;
use spira::model::boundary::BoundaryConditions;
use spira::model::loading::{AxialHeld, Component, Control, Held, Loads};
use spira::simulation::beam::{
    beam_stiffness, bending_energy, bending_of, bending_stiffness, column_turns, BeamStiffness,
    StepBeam,
};
use spira::simulation::cell::CellJudge;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;
use std::f64::consts::PI;

use crate::{A0, B0, STIFFNESS};

/// Continuation settings without the stability of the path.
fn equilibrium_only() -> ContinuationSettings {
    ContinuationSettings {
        track_stability: false,
        lowest_eigenvalue: false,
        ..ContinuationSettings::default()
    }
}

/// `assembly` at the default mesh of a tube of `n` helices, solved from the natural state
/// under `stepped` (the others held at `held`) to `target`.
fn solved(assembly: Assembly, n: usize, stepped: Component, held: Held, target: f64) -> Simulation {
    let model = DiscreteModel::new(assembly, STIFFNESS, default_elements(n), Order::Quadratic);
    let x = model.natural_state();
    let loads = Loads::compose(stepped, Control::Displacement, held);
    let mut sim = Simulation::with_loads(
        model,
        BoundaryConditions::default(),
        loads,
        x,
        equilibrium_only(),
    )
    .expect("the natural state solves");
    sim.advance_to(target).expect("the cell follows its load");
    sim
}

fn held(eps: f64, twist: f64) -> Held {
    Held {
        axial: AxialHeld::Ratio(eps),
        twist,
        ..Held::NATURAL
    }
}

fn stiffness_of(sim: &Simulation) -> BeamStiffness {
    beam_stiffness(sim.model(), sim.system(), sim.state()).expect("the stiffnesses")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The tube's axial force (N, all n rods) and torque (N m) of a cell's state.
fn force_and_torque(sim: &Simulation) -> (f64, f64) {
    let point = sim.load_point(0);
    let m = sim.model().assembly.cell.as_ref().expect("a cell").m as f64;
    let f: f64 = point.reactions.iter().map(|r| r.tip.force[2]).sum();
    (m * f, point.support.torque)
}

/// At rest (ε = 0) the tube's cell has Love's stiffnesses (docs/theory.md §8), with
/// c0 = √(a0² + b0²): per helix EA = b0 (C a0² + B b0²)/(a0² c0³), the tube's n times
/// that; the pantograph's radial stiffness (C a0² + B b0²)/(b0² c0⁴) and radius coupling
/// −b0²/a0; no extension–twist coupling (the tube is its own mirror image). One helix
/// alone as a cell has GJ = b0 (B a0² + C b0²)/c0³ and the coupling b0² (C − B)/c0³.
/// All to 1e-8, for n = 2, 8, 64.
#[test]
fn the_stiffnesses_at_rest_are_loves() {
    let (a, b, bb, cc) = (A0, B0, STIFFNESS.b1, STIFFNESS.b3);
    let c0 = a.hypot(b);
    let ea = b * (cc * a * a + bb * b * b) / (a * a * c0.powi(3));
    let gj = b * (bb * a * a + cc * b * b) / c0.powi(3);
    let coupling = b * b * (cc - bb) / c0.powi(3);
    let radial = (cc * a * a + bb * b * b) / (b * b * c0.powi(4));
    let radius_coupling = -b * b / a;
    for n in [2, 8, 64] {
        let tube = solved(
            Assembly::tube_cell(n, A0, B0).expect("a tube cell"),
            n,
            Component::Axial,
            Held::NATURAL,
            0.0,
        );
        let s = stiffness_of(&tube);
        let turn = 2.0 * PI / n as f64;
        let helix = solved(
            Assembly::helix_cell(A0, B0, turn).expect("a helix cell"),
            n,
            Component::Axial,
            Held::NATURAL,
            0.0,
        );
        let one = stiffness_of(&helix);
        let errors = [
            rel(s.axial, n as f64 * ea),
            rel(s.radial, radial),
            rel(s.radius_coupling, radius_coupling),
            s.twist_coupling.abs() / (s.axial * s.torsional).sqrt(),
            rel(one.axial, ea),
            rel(one.torsional, gj),
            rel(one.twist_coupling, coupling),
        ];
        println!("n = {n}: tube EA {:.10} GJ {:.6} radial {:.6} radius coupling {:.10} twist coupling {:.2e}; helix EA {:.10} GJ {:.10} coupling {:.10}; errors {errors:?}", s.axial, s.torsional, s.radial, s.radius_coupling, s.twist_coupling, one.axial, one.torsional, one.twist_coupling);
        assert!(errors.iter().all(|&e| e < 1e-8), "n = {n}: {errors:?}");
    }
}

/// At ε = 0.5 (n = 8) and at a twisted state, the stiffnesses equal central differences
/// of whole solves: EA = −(h/h0) dF/dε, GJ = h dT/dφ, and the extension–twist coupling
/// both as −(h/h0) dT/dε and as h dF/dφ (Maxwell), to 1e-6.
#[test]
fn the_stiffnesses_are_the_derivatives_of_whole_solves() {
    let n = 8;
    let cell = || Assembly::tube_cell(n, A0, B0).expect("a tube cell");
    let (eps, phi) = (0.5, 2e-4);
    for twist in [0.0, phi] {
        let at = |e: f64, p: f64| {
            if twist == 0.0 && p == 0.0 {
                solved(cell(), n, Component::Axial, held(0.0, 0.0), e)
            } else {
                solved(cell(), n, Component::Twist, held(e, 0.0), p)
            }
        };
        let state = at(eps, twist);
        let s = stiffness_of(&state);
        let h0 = state.model().height0();
        let h = h0 * (1.0 - eps);
        let (de, dp) = (1e-5, 1e-8);
        let (fe, te) = force_and_torque(&at(eps + de, twist));
        let (fw, tw) = force_and_torque(&at(eps - de, twist));
        let (fp, tp) = force_and_torque(&at(eps, twist + dp));
        let (fm, tm) = force_and_torque(&at(eps, twist - dp));
        let ea = -(h / h0) * (fe - fw) / (2.0 * de);
        let gj = h * (tp - tm) / (2.0 * dp);
        let by_eps = -(h / h0) * (te - tw) / (2.0 * de);
        let by_phi = h * (fp - fm) / (2.0 * dp);
        let scale = (s.axial * s.torsional).sqrt();
        let errors = [
            rel(s.axial, ea),
            rel(s.torsional, gj),
            (s.twist_coupling - by_eps).abs() / scale,
            (s.twist_coupling - by_phi).abs() / scale,
        ];
        println!("phi = {twist}: EA {:.9} ({ea:.9}), GJ {:.6} ({gj:.6}), coupling {:.9} ({by_eps:.9}, {by_phi:.9}); errors {errors:?}", s.axial, s.torsional, s.twist_coupling);
        assert!(
            errors.iter().all(|&e| e < 1e-6),
            "phi = {twist}: {errors:?}"
        );
    }
}

/// The phase (rad per cell) in `(lo, hi)` where the lowest eigenvalue of block `(p, k)` of
/// the state changes sign, by bisection.
fn band_edge(sim: &Simulation, p: usize, lo: f64, hi: f64) -> f64 {
    let mut judge = CellJudge::new(sim.model(), sim.system(), 2).expect("a cell");
    let unstable = |k: f64| {
        judge
            .lowest_at(sim.model(), sim.system(), sim.state(), p, k)
            .expect("converges")
            < 0.0
    };
    crate::bisect_change(unstable, lo, hi, 1e-9)
}

/// The bending wave's energy per cell is `E(q) = (2h/m)(EI q⁴ + F q²) + O(q⁶)`: its fit
/// gives the tube's axial force `F` of the cell's own state (its conjugate load) to 1e-8,
/// for n = 2 and 8, at rest and compressed; `EI` from fits of phase steps δ = 0.02 and
/// 0.01 (`q h` up to 0.1 and 0.05) agree to 1e-8 for n = 8 and 1e-7 for n = 2 (the fit's
/// truncation, O(δ¹⁰), and rounding), and [`bending_of`] gives the finer one, for n = 2 too.
#[test]
fn the_bending_waves_energy_gives_the_axial_force_and_ei() {
    for (n, eps) in [(8, 0.0), (8, 0.25), (8, 0.5), (2, 0.05), (2, 0.25)] {
        let tube = solved(
            Assembly::tube_cell(n, A0, B0).expect("a tube cell"),
            n,
            Component::Axial,
            Held::NATURAL,
            eps,
        );
        let s = stiffness_of(&tube);
        let fit = |step: f64| {
            bending_stiffness(tube.model(), tube.system(), tube.state(), step).expect("the fit")
        };
        let ((ei, force), (finer, _)) = (fit(0.02), fit(0.01));
        let chosen = bending_of(tube.model(), tube.system(), tube.state()).expect("EI");
        // at rest F = 0: measured against the bending term at q h = 1, EI/h²
        let h = s.turn_rise / n as f64;
        let scale = if eps == 0.0 {
            ei / (h * h)
        } else {
            s.force.abs()
        };
        let force_error = (force - s.force).abs() / scale;
        println!("n = {n}, eps = {eps}: EI {ei:.10} (δ/2: {finer:.10}, {:.1e}), bending_of {chosen:.10}; F {force:.10} vs the cell's {:.10} ({force_error:.1e})", rel(finer, ei), s.force);
        assert!(
            force_error < 1e-8,
            "n = {n}, eps = {eps}: F {force} vs {}",
            s.force
        );
        let agreement = if n == 2 { 1e-7 } else { 1e-8 };
        assert!(
            rel(finer, ei) < agreement,
            "n = {n}, eps = {eps}: EI {ei} vs {finer}"
        );
        assert!(
            rel(chosen, finer) < 1e-12 && ei > 0.0,
            "n = {n}, eps = {eps}"
        );
    }
}

/// A straight rod (B1 = B2 = B) as a one-rod cell of 1 m: its bending wave's fit (δ = 0.04,
/// q ≤ 0.2 /m) gives EI = B and F = −P to 1e-9, compressed and under a torque (Greenhill's odd term `−T q` in `g(q)`
/// drops out of the even part the fit takes).
#[test]
fn a_straight_rods_bending_stiffness_is_b() {
    for (b, c, p, t) in [
        (1.0, 2.0, 1.0, 0.0),
        (1.0, 1.0, 1.0, 1.0),
        (2.0, 4.0, 0.0, 1.0),
    ] {
        let (model, system, x, _) = crate::cell::straight_rod(b, c, p, t);
        let (ei, force) = bending_stiffness(&model, &system, &x, 0.04).expect("the fit");
        let force_error = (force + p).abs() / b;
        println!(
            "B {b} B3 {c} P {p} T {t}: EI {ei:.12} ({:.1e}), F {force:.12} ({force_error:.1e})",
            rel(ei, b)
        );
        assert!(rel(ei, b) < 1e-9, "EI {ei} vs {b}");
        assert!(force_error < 1e-9, "F {force} vs {}", -p);
    }
}

/// The compressed tube (n = 8) is an Euler column of bending stiffness EI: the band of
/// unstable bending waves of its Bloch branch (p = 1 about the translation's phase ψ) ends
/// where the wave's energy E(q) changes sign, at `q_e² = P/EI + O(P²)`: the root of E(q)
/// against √(P/EI) at ε = 0.0005, 0.001 and 0.002, `rel = e + c P + d P²`, has `e` (half
/// EI's error) below 1e-8. At ε = 0.25 the root is the band edge of the block's lowest
/// eigenvalue to 1e-7 (an independent search, on the block without the amplitude), and
/// √(P/EI) is 2.5 % above it (the q⁴ term of the branch at `q h = 0.15`).
#[test]
fn the_bending_branch_is_an_euler_column() {
    let n = 8;
    let tube_at = |eps: f64| {
        solved(
            Assembly::tube_cell(n, A0, B0).expect("a tube cell"),
            n,
            Component::Axial,
            Held::NATURAL,
            eps,
        )
    };
    let root = |tube: &Simulation, q: f64| {
        let energy = |k: f64| {
            bending_energy(tube.model(), tube.system(), tube.state(), k).expect("the energy")
        };
        crate::bisect_change(|k| energy(k) < 0.0, 0.5 * q, 2.0 * q, 1e-12 * q)
    };
    let mut rows = Vec::new();
    for eps in [0.0005, 0.001, 0.002] {
        let tube = tube_at(eps);
        let ei = bending_of(tube.model(), tube.system(), tube.state()).expect("EI");
        let p = -stiffness_of(&tube).force;
        let q = (p / ei).sqrt();
        let edge = root(&tube, q);
        println!(
            "eps = {eps}: P {p:.9} EI {ei:.10}; root of E {edge:.10}, sqrt(P/EI) {q:.10} ({:.4e})",
            rel(edge, q)
        );
        rows.push((p, (edge - q) / q));
    }
    // e + c P + d P² through the three points: e by Lagrange interpolation at P = 0
    let e: f64 = (0..3)
        .map(|i| {
            let others = (0..3).filter(|&j| j != i);
            let weight: f64 = others
                .map(|j| rows[j].0 / (rows[j].0 - rows[i].0))
                .product();
            weight * rows[i].1
        })
        .sum();
    println!("the root's gap at P = 0: {e:.2e}");
    assert!(e.abs() < 1e-8, "{e}");
    let tube = tube_at(0.25);
    let s = stiffness_of(&tube);
    let ei = bending_of(tube.model(), tube.system(), tube.state()).expect("EI");
    let q = (-s.force / ei).sqrt();
    let edge = root(&tube, q);
    let cell = tube.model().assembly.cell.clone().expect("a cell");
    let (psi, h) = (cell.translation_phase(), s.turn_rise / n as f64);
    let band = (band_edge(&tube, 1, psi + 0.5 * q * h, psi + 2.0 * q * h) - psi) / h;
    println!(
        "eps = 0.25: root of E {edge:.10}, band edge {band:.10} ({:.1e}), sqrt(P/EI) {q:.10}",
        rel(band, edge)
    );
    assert!(rel(band, edge) < 1e-7, "{band} vs {edge}");
}

/// The cell's prediction of the first column buckling of a clamped tube of `turns` turns
/// (n = 8, K = 0.5): the ε where `euler_turns/K` is the tube's length, by bisection.
fn predicted_column_strain(turns: f64) -> f64 {
    let n = 8;
    let excess = |eps: f64| {
        let tube = solved(
            Assembly::tube_cell(n, A0, B0).expect("a tube cell"),
            n,
            Component::Axial,
            Held::NATURAL,
            eps,
        );
        let stiffness = stiffness_of(&tube);
        let beam = StepBeam {
            step: 0,
            stiffness,
            bending: bending_of(tube.model(), tube.system(), tube.state()),
            bending_curvature: None,
            bending_curvature_refused: None,
        };
        column_turns(&beam, 0.5).expect("a compressed column") - turns
    };
    let (mut lo, mut hi) = (0.005, 0.3);
    assert!(excess(lo) > 0.0 && excess(hi) < 0.0);
    while hi - lo > 1e-7 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The first bifurcation of the thesis tube (n = 8, clamped) of `turns` turns.
fn finite_column_strain(turns: f64) -> f64 {
    let text = std::fs::read_to_string("cases/thesis-n8.toml").expect("the shipped case");
    let text = text
        .replace("turns = 3.5", &format!("turns = {turns}"))
        .replace(
            "elements = 48",
            &format!("elements = {}", (14.0 * turns) as usize),
        )
        .replace("target = 0.5", "target = 0.15")
        .replace("steps = 10", "steps = 20");
    let case = spira::case::Case::parse(&text, "column.toml", "column").expect("the case");
    let mut sim = Simulation::from_case(&case).expect("the natural state");
    sim.advance_to(0.15).expect("the path");
    sim.critical_points()
        .first()
        .expect("a column buckles")
        .compression_ratio
}

/// The cell predicts the column buckling of finite tubes, P = π² EI/(K L)² with K = 0.5 for
/// clamped ends: the thesis tube (n = 8) of 7 and 14 turns buckles first within 14 % and
/// 5 % of the prediction, the gap closing as the length grows (README §4c: 2.1 % at 28
/// turns, 1.0 % at 56). EI is the long-wave limit of the bending branch; at 7 turns the
/// clamped column's wave, q h ≈ 0.1, also feels the branch's q⁴ term.
#[test]
fn the_cell_predicts_where_a_clamped_tube_buckles_as_a_column() {
    let gaps: Vec<f64> = [7.0, 14.0]
        .iter()
        .map(|&turns| {
            let (predicted, finite) = (predicted_column_strain(turns), finite_column_strain(turns));
            println!(
                "{turns} turns: predicted eps {predicted:.6}, finite tube {finite:.6}, ratio {:.4}",
                finite / predicted
            );
            rel(finite, predicted)
        })
        .collect();
    assert!(gaps[0] < 0.14 && gaps[1] < 0.05, "{gaps:?}");
    assert!(gaps[1] < 0.5 * gaps[0], "{gaps:?}");
}
