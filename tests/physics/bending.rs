//! The infinite tube bent (docs/theory.md §8): the bending cell — every rod over one axial
//! period, its far ends the image of its near ends under the turn by the tilt `θ` about a
//! transverse axis through the centre of curvature — against the circular arc of a straight
//! rod, the mirror symmetry `θ → −θ`, the work of its bending moment, the straight tube's
//! cell, and the bending stiffness of the Bloch branch.

use spira::discretisation::cell::default_elements;
use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::shape::Order;
use spira::model::assembly::Assembly;
use spira::model::boundary::BoundaryConditions;
use spira::model::loading::{AxialHeld, Component, Control, Held, Loads};
use spira::model::stiffness::Stiffness;
use spira::results::LoadPoint;
use spira::simulation::beam::{
    beam_stiffness, bending_by_curvature, bending_of, bending_stiffness, curvature_stiffness,
};
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;
use spira::solver::newton::NewtonSettings;

use crate::{A0, B0, STIFFNESS};

/// Continuation without the stability of the path, Newton converged to 1e-12 (the checks
/// at 1e-9 are then not the solver's tolerance).
fn equilibrium_only() -> ContinuationSettings {
    let defaults = ContinuationSettings::default();
    ContinuationSettings {
        track_stability: false,
        lowest_eigenvalue: false,
        newton: NewtonSettings {
            tolerance: 1e-12,
            ..defaults.newton
        },
        ..defaults
    }
}

fn held(eps: f64) -> Held {
    Held {
        axial: AxialHeld::Ratio(eps),
        ..Held::NATURAL
    }
}

/// `assembly` meshed by `elements` per rod, at its natural state under `stepped` (the
/// others held at `held`), ready to follow its load.
fn start(assembly: Assembly, elements: usize, stepped: Component, held: Held) -> Simulation {
    let model = DiscreteModel::new(assembly, STIFFNESS, elements, Order::Quadratic);
    let x = model.natural_state();
    let loads = Loads::compose(stepped, Control::Displacement, held);
    Simulation::with_loads(
        model,
        BoundaryConditions::default(),
        loads,
        x,
        equilibrium_only(),
    )
    .expect("the natural state solves")
}

/// The points of `sim` at the load parameters `targets`, in order.
fn path(sim: &mut Simulation, targets: &[f64]) -> Vec<LoadPoint> {
    targets
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            sim.advance_to(t).expect("the cell follows its tilt");
            sim.load_point(i)
        })
        .collect()
}

/// The bending cell of the thesis tube of `n` helices, at the cell's default mesh (its rods
/// span two cells).
fn bending_cell(n: usize, eps: f64) -> Simulation {
    let assembly = Assembly::bending_cell(n, A0, B0).expect("a bending cell");
    start(
        assembly,
        2 * default_elements(n),
        Component::Tilt,
        held(eps),
    )
}

/// A straight rod as a one-rod cell bent by the tilt θ over its length ℓ is an arc of a
/// circle at any θ: M = B θ/ℓ (B = 1.3 N m², ℓ = 0.7 m), to 1e-9, up to θ = 2 rad (64
/// elements: the discrete arc's moment is off by O((θ/N)⁴), 4e-9 at θ = 1 with 16).
/// The straight cell of the thesis tube of `n` helices compressed to `eps`.
fn straight_cell(n: usize, eps: f64) -> Simulation {
    let mut straight = start(
        Assembly::tube_cell(n, A0, B0).expect("a tube cell"),
        default_elements(n),
        Component::Axial,
        Held::NATURAL,
    );
    straight
        .advance_to(eps)
        .expect("the cell follows its strain");
    straight
}

#[test]
fn a_straight_rod_bent_carries_b_kappa() {
    let length = 0.7;
    let b = 1.3;
    let model = DiscreteModel::new(
        Assembly::straight_cell(length, 0.0).expect("a straight cell"),
        Stiffness {
            b1: b,
            b2: b,
            b3: 2.0,
        },
        64,
        Order::Quadratic,
    );
    let x = model.natural_state();
    let loads = Loads::compose(Component::Tilt, Control::Displacement, Held::NATURAL);
    let mut sim = Simulation::with_loads(
        model,
        BoundaryConditions::default(),
        loads,
        x,
        equilibrium_only(),
    )
    .expect("the natural state solves");
    let targets = [0.25, 0.5, 1.0, 2.0];
    for p in path(&mut sim, &targets) {
        let theta = p.support.tilt;
        let exact = b * theta / length;
        let error = (p.support.bending_moment - exact).abs() / exact;
        println!(
            "theta {theta}: M {:.12e}, B kappa {exact:.12e}, error {error:.2e}",
            p.support.bending_moment
        );
        assert!(
            error < 1e-9,
            "M = {} against {exact}",
            p.support.bending_moment
        );
    }
}

/// The tube of 8 helices bent either way, at rest and compressed (ε = 0.25, where the
/// lateral load holding its crossing rings on the bent axis works too): M(−θ) = −M(θ) to
/// 1e-10 (the half-turn about the x axis through a crossing maps the tube onto itself and
/// θ onto −θ), and the energy of the bending cell is the work of its moment,
/// Π(θ) − Π(0) = ∫ M dθ (Simpson, 8 steps to θ = 0.2 rad), to 1e-8.
#[test]
fn the_bent_tube_is_symmetric_and_its_moment_is_the_energys_rate() {
    let n = 8;
    let step = 0.025;
    let targets: Vec<f64> = (1..=8).map(|k| k as f64 * step).collect();
    for eps in [0.0, 0.25] {
        let mut up = bending_cell(n, eps);
        let first = up.load_point(0);
        let mut ups = vec![first];
        ups.extend(path(&mut up, &targets));
        let negative: Vec<f64> = targets.iter().map(|t| -t).collect();
        let mut down = bending_cell(n, eps);
        let downs = path(&mut down, &negative);
        let scale = ups
            .iter()
            .map(|p| p.support.bending_moment.abs())
            .fold(0.0, f64::max);
        for (u, d) in ups[1..].iter().zip(&downs) {
            let (mu, md) = (u.support.bending_moment, d.support.bending_moment);
            println!(
                "eps {eps}, theta {:.3}: M {mu:.12e}, M(-theta) {md:.12e}",
                u.support.tilt
            );
            assert!((mu + md).abs() < 1e-10 * scale, "M(θ) = {mu}, M(−θ) = {md}");
        }
        let moments: Vec<f64> = ups.iter().map(|p| p.support.bending_moment).collect();
        let work = crate::simpson(&moments, step);
        let energy = ups[8].energy - ups[0].energy;
        let error = (energy - work).abs() / energy;
        println!(
            "eps {eps}: energy {energy:.12e} J, work of M {work:.12e} J, relative {error:.2e}"
        );
        assert!(error < 1e-8);
    }
}

/// Bent by a tilt of 1e-7 rad, the bending cell of 8 helices at ε = 0 and 0.5 has the
/// straight cell's state: its energy is that of its 2m = 8 cells and its rods' axial force
/// that of the straight cell's m sectors, to 1e-9.
#[test]
fn a_slightly_bent_cell_is_the_straight_cell() {
    let n = 8;
    let m = (n / 2) as f64;
    for eps in [0.0, 0.5] {
        let mut bent = bending_cell(n, eps);
        let p = path(&mut bent, &[1e-7]).remove(0);
        let straight = straight_cell(n, eps);
        let q = straight.load_point(0);
        // the straight cell's energy is reported for one rise of the tube (m cells)
        let (e_bent, e_cell) = (p.energy, 2.0 * q.energy);
        let fz = |p: &LoadPoint| p.reactions.iter().map(|r| r.tip.force[2]).sum::<f64>();
        let (f_bent, f_cell) = (fz(&p), m * fz(&q));
        println!("eps {eps}: energy {e_bent:.12e} / {e_cell:.12e} J, axial force {f_bent:.12e} / {f_cell:.12e} N");
        if eps > 0.0 {
            // the straight cell's energy and force, against the bent cell's
            assert!((e_bent - e_cell).abs() < 1e-9 * e_cell.abs());
            assert!((f_bent - f_cell).abs() < 1e-9 * f_cell.abs());
        } else {
            assert!(e_bent.abs() < 1e-9 && f_bent.abs() < 1e-9 && e_cell.abs() < 1e-12);
        }
    }
}

/// EI by imposed curvature (exact from the bending cell's constrained tangent) against the
/// whole bent solves, (M(δ) − M(−δ))/(2δ/H) at δ = 1e-3 rad (to 1e-6), and against the
/// long-wave limit of the bending wave's energy in the straight cell's Bloch block
/// (`bending_of`), at rest and compressed to ε = 0.5: both hold the tube's axis through
/// the centres of its crossing rings, with the lateral load on every ring alike, and agree
/// to 1e-6 (measured 3e-10).
#[test]
fn the_bending_stiffness_by_curvature() {
    let n = 8;
    for eps in [0.0, 0.5] {
        let straight = straight_cell(n, eps);
        let (model, system, x) = (straight.model(), straight.system(), straight.state());
        let clock = std::time::Instant::now();
        let curvature = bending_by_curvature(model, system, x).expect("EI by curvature");
        let took = clock.elapsed();
        let stiffness = beam_stiffness(model, system, x).expect("the stiffnesses");
        let branch = bending_of(model, system, x).expect("the bending wave's EI");
        let delta = 1e-3;
        let moment = |theta: f64| {
            let mut bent = bending_cell(n, eps);
            let clock = std::time::Instant::now();
            let m = path(&mut bent, &[theta]).remove(0).support.bending_moment;
            println!("  one bent solve to theta = {theta}: {:?}", clock.elapsed());
            m
        };
        let rise = model.height0() * 2.0 * (1.0 - eps);
        let solves = (moment(delta) - moment(-delta)) / (2.0 * delta / rise);
        let ei = curvature.stiffness;
        println!(
            "eps {eps}: EI by curvature {ei:.10} N m², by bent solves {solves:.10}, Bloch branch {branch:.10} ({:.1e}), F {:.4} N, M(0) {:.1e}, residual {:.1e}, EI by curvature in {took:?}",
            (branch - ei) / ei,
            stiffness.force,
            curvature.moment,
            curvature.residual
        );
        assert!((solves - ei).abs() < 1e-6 * ei);
        assert!(curvature.moment.abs() < 1e-9 * ei / rise);
        assert!((branch - ei).abs() < 1e-6 * ei, "{branch} {ei}");
    }
}

/// Under an axial force the two measures of EI — the bending wave's long-wave limit and
/// the imposed curvature — agree to 1e-6 (measured below 1e-9) for the tubes of 8 and 4
/// helices at ε = 0.25 and 0.5, where the tube's compression works on the held axis's
/// length (F κ² h² against EI κ²: the axis through the crossing rings, every ring loaded
/// alike, in both).
#[test]
fn the_two_bending_stiffnesses_agree_under_load() {
    for n in [8, 4] {
        for eps in [0.25, 0.5] {
            let straight = straight_cell(n, eps);
            let (model, system, x) = (straight.model(), straight.system(), straight.state());
            let curvature = bending_by_curvature(model, system, x)
                .expect("EI by curvature")
                .stiffness;
            let branch = bending_of(model, system, x).expect("the bending wave's EI");
            let force = beam_stiffness(model, system, x)
                .expect("the stiffnesses")
                .force;
            let rel = (branch - curvature).abs() / curvature;
            println!(
                "n {n}, eps {eps}: F {force:.6} N, EI by curvature {curvature:.10}, bending wave {branch:.10} ({rel:.1e})"
            );
            assert!(rel < 1e-6, "n {n}, eps {eps}: {branch} vs {curvature}");
        }
    }
}

/// A straight rod (B1 = B2 = B) as a one-rod cell of length ℓ = 1 m carrying an axial
/// force, compressed (P > 0) or stretched, to 1e-9. From the bending wave's energy
/// `B q⁴ − P q²` (its amplitude the mean along the rod; the fit at δ = 0.04): EI = B. By
/// imposed curvature with the rod's axis held at its near end: the lateral load `P κ` a
/// bent rod under an axial force needs then falls on one point per cell, and the rod
/// between bends as a beam under periodic point loads. Its deflection at the loads,
/// `w = (1/ℓ) Σ_j 1/(B k_j⁴ − P k_j²)` (`k_j = q + 2πj/ℓ`), makes the energy per length
/// `D/(1 + D S)` with `D = B q⁴ − P q²` and `S = Σ_{j≠0}` of the same terms, so that
/// EI = B − P² S₀, `S₀ = 2 Σ_{j≥1} 1/(k_j² (B k_j² − P))` at `k_j = 2πj/ℓ` — the axis's
/// definition enters at the order P² (docs/theory.md §8).
#[test]
fn a_straight_rod_under_axial_force_has_ei_b_or_its_point_held_closed_form() {
    for (b, c, p) in [
        (1.0, 2.0, 0.0),
        (1.0, 2.0, 3.0),
        (1.3, 2.0, 2.0),
        (2.0, 1.0, -5.0),
    ] {
        let (model, system, x, _) = crate::cell::straight_rod(b, c, p, 0.0);
        let (wave, force) = bending_stiffness(&model, &system, &x, 0.04).expect("the fit");
        // the tilted system's multipliers: every element's force −p e_z, the rest fitted
        let loads = Loads::compose(Component::Tilt, Control::Displacement, Held::NATURAL);
        let tilted = spira::discretisation::system::System::new(
            &model,
            BoundaryConditions::default(),
            &x[..model.n_primal],
            &loads,
            0.0,
        );
        let mut guess = x[..model.n_primal].to_vec();
        guess.resize(tilted.n, 0.0);
        for e in 0..model.rods[0].mesh.elements() {
            guess[tilted.compat_row(0, e) + 2] = -p;
        }
        let bent =
            curvature_stiffness(&model, BoundaryConditions::default(), &guess, Held::NATURAL)
                .expect("EI by curvature");
        let length = model.length();
        let s0: f64 = (1..200_000)
            .map(|j| {
                let k = 2.0 * std::f64::consts::PI * j as f64 / length;
                2.0 / (k * k * (b * k * k - p))
            })
            .sum();
        let point_held = b - p * p * s0;
        println!(
            "B {b} B3 {c} P {p}: EI by curvature {:.12} (closed form {point_held:.12}, residual {:.1e}), bending wave {wave:.12}, F {force:.9}",
            bent.stiffness, bent.residual
        );
        assert!(
            (bent.stiffness - point_held).abs() < 1e-9 * b,
            "{} vs {point_held}",
            bent.stiffness
        );
        assert!((wave - b).abs() < 1e-9 * b, "{wave} vs {b}");
        assert!(
            (force + p).abs() < 1e-9 * b.max(p.abs()),
            "F {force} vs {}",
            -p
        );
        assert!(bent.residual < 1e-9 * b.max(p.abs()));
    }
}
