//! The cell of the infinite tube (docs/theory.md §8) against numbers that do not come from
//! it: the uniform helix of the pinned lattice (Love's force, and the pantograph's under
//! pressure), Euler's and Greenhill's bands of an infinite straight rod, and a ring of
//! cells closed on itself.

use spira::discretisation::cell::default_elements;
use spira::discretisation::discrete_model::{DiscreteModel, End};
use spira::discretisation::shape::Order;
use spira::model::assembly::Assembly;
use spira::model::boundary::BoundaryConditions;
use spira::model::elasticity::Reference;
use spira::model::loading::{AxialHeld, Component, Control, Held, Loads};
use spira::model::love::LoveHelix;
use spira::model::stiffness::Stiffness;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;

/// The thesis helices (§4.1): a0 = 0.06 m, b0 = 0.025 m, B = 1, C = 2 N m².
const A0: f64 = 0.06;
const B0: f64 = 0.025;
const STIFFNESS: Stiffness = Stiffness {
    b1: 1.0,
    b2: 1.0,
    b3: 2.0,
};

/// The cell of the thesis tube of `n` helices at its default mesh, solved under `loads`
/// from the natural state up to `target`.
fn solved_cell(n: usize, cells: usize, loads: Loads, target: f64) -> Simulation {
    let assembly = Assembly::tube_cells(n, A0, B0, cells).expect("a tube cell");
    let elements = cells * default_elements(n);
    let model = DiscreteModel::new(assembly, STIFFNESS, elements, Order::Quadratic);
    let x = model.natural_state();
    let bc = BoundaryConditions::default();
    let mut sim = Simulation::with_loads(model, bc, loads, x, ContinuationSettings::default())
        .expect("the natural state solves");
    sim.advance_to(target).expect("the cell follows the load");
    sim
}

fn love(length: f64, eps: f64) -> LoveHelix {
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
