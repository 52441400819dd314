//! The cell of the infinite tube (docs/theory.md §8) against closed forms: the uniform helix
//! of the pinned lattice, Euler's and Greenhill's bands of a straight rod, and a ring of
//! cells closed on itself.

use spira::discretisation::discrete_model::DiscreteModel;
use spira::discretisation::discrete_model::End;
use spira::discretisation::shape::Order;
use spira::model::assembly::Assembly;
use spira::model::boundary::BoundaryConditions;
use spira::model::loading::{Control, Loads};
use spira::model::love::LoveHelix;
use spira::model::stiffness::Stiffness;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;

const A0: f64 = 0.06;
const B0: f64 = 0.025;
const STIFFNESS: Stiffness = Stiffness {
    b1: 1.0,
    b2: 1.0,
    b3: 2.0,
};

#[test]
fn probe() {
    for n in [2, 8, 64] {
        for elements in [8, 16, 32] {
            let model = DiscreteModel::new(
                Assembly::tube_cell(n, A0, B0).unwrap(),
                STIFFNESS,
                elements,
                Order::Quadratic,
            );
            let x = model.natural_state();
            let mut sim = Simulation::with_loads(
                model,
                BoundaryConditions::default(),
                Loads::axial(Control::Displacement),
                x,
                ContinuationSettings::default(),
            )
            .unwrap();
            sim.advance_to(0.5).unwrap();
            let (f, _) = sim.system().reaction(sim.model(), sim.state(), 0, End::Tip);
            let (f1, _) = sim.system().reaction(sim.model(), sim.state(), 1, End::Tip);
            let love = LoveHelix {
                radius0: A0,
                pitch0: B0,
                length: sim.model().length(),
                stiffness: STIFFNESS,
                pitch: B0 * 0.5,
                elasticity: Default::default(),
                reference: spira::model::elasticity::Reference::Discrete,
            };
            println!(
                "n {n} el {elements}: fz {} {} love {} rel {:e} stab {:?}",
                f[2],
                f1[2],
                love.force(),
                (f[2] - love.force()).abs() / love.force().abs(),
                sim.stability()
            );
        }
    }
}
