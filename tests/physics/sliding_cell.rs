//! Sliding crossings on the cell of the infinite tube (docs/joints.md, docs/theory.md §8)
//! against numbers that do not come from the sliding cell: Love's helix of the compressed
//! lattice, the pinned cell at the same loads (a sliding crossing at the tube's symmetric
//! states is a pin whose force is normal to both rods), and the interlacing of a constraint
//! released.

use spira::discretisation::constraints::Role;
use spira::discretisation::discrete_model::End;
use spira::model::boundary::Joints;
use spira::model::loading::{AxialHeld, Component, Control, Held, Loads};
use spira::simulation::cell::CellJudge;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;

use crate::cell::{love, solved_cells as solved};

/// The largest force (N) carried by a sliding cell's joints and their largest slip (m).
fn joint_force_and_slip(sim: &Simulation) -> (f64, f64) {
    let (model, system, x) = (sim.model(), sim.system(), sim.state());
    assert!(!model.slides.is_empty(), "the cell's crossings slide");
    let mut force: f64 = 0.0;
    let mut slip: f64 = 0.0;
    for (k, &joint) in model.slides.iter().enumerate() {
        let row = system.slide_row(k);
        force = force.max((0..3).map(|i| x[row + i].powi(2)).sum::<f64>().sqrt());
        for side in 0..2 {
            slip = slip.max((x[model.slide_dof(k, side)] - model.assembly.joints[joint].s).abs());
        }
    }
    (force, slip)
}

/// The largest difference (m, and 1 on the quaternions) between the rods' unknowns of two
/// states of the same cell (the sliding one's contacts after them).
fn rods_apart(a: &Simulation, b: &Simulation) -> f64 {
    let rods = a.model().n_primal.min(b.model().n_primal);
    let (xa, xb) = (a.state(), b.state());
    (0..rods).fold(0.0, |d: f64, i| d.max((xa[i] - xb[i]).abs()))
}

/// Compressed or stretched by ε, the sliding cell's rods are Love's helix with c = c0,
/// b = b0 (1 − ε) (the cell holds its material points and its screw's turn): each carries
/// Love's axial force to 1e-8, the joints no force (≤ 1e-9 of Love's force: rounding, as
/// the pinned joint's, printed) and the contact no slip (≤ 1e-12 m; the gauge holds the
/// cell's one contact), and the state is the pinned cell's
/// to 1e-10, for n = 2, 8, 64.
#[test]
fn the_compressed_sliding_cell_is_loves_helix_with_free_crossings() {
    for n in [2, 8, 64] {
        for eps in [0.3, 0.1, -0.3] {
            let axial = || Loads::axial(Control::Displacement);
            let settings = ContinuationSettings::default;
            let sliding = solved(n, 1, Joints::Sliding, axial(), eps, settings());
            let pinned = solved(n, 1, Joints::Pin, axial(), eps, settings());
            assert!((sliding.compression_ratio() - eps).abs() < 1e-12);
            let f = love(sliding.model().length(), eps).force();
            let (force, slip) = joint_force_and_slip(&sliding);
            let apart = rods_apart(&sliding, &pinned);
            for rod in 0..2 {
                let (tip, _) =
                    sliding
                        .system()
                        .reaction(sliding.model(), sliding.state(), rod, End::Tip);
                let rel = (tip[2] - f).abs() / f.abs();
                println!(
                    "n = {n}, eps = {eps}, rod {rod}: fz {:.12} Love {f:.12} rel {rel:.2e}; joint force {force:.2e} N, slip {slip:.2e} m, from the pinned cell {apart:.2e}",
                    tip[2]
                );
                assert!(
                    rel < 1e-8,
                    "n = {n}, eps = {eps}, rod {rod}: {} vs {f}",
                    tip[2]
                );
            }
            let pin = pin_force(&pinned);
            let pin = pin.iter().map(|v| v * v).sum::<f64>().sqrt();
            println!("  pinned joint force {pin:.2e} N");
            assert!(
                force <= 1e-9 * f.abs(),
                "n = {n}, eps = {eps}: joint force {force}"
            );
            assert!(slip <= 1e-12, "n = {n}, eps = {eps}: slip {slip}");
            assert!(
                apart <= 1e-10,
                "n = {n}, eps = {eps}: {apart} from the pinned cell"
            );
        }
    }
}

/// A sliding crossing is a pin with its two arc lengths released, so at the same state
/// (the uniform helix, ε = 0.3) the sliding cell's lowest eigenvalue over (p, k) is at most
/// the pinned cell's (interlacing), for n = 2, 8, 64; both are printed.
#[test]
fn sliding_crossings_lower_the_cells_lowest_eigenvalue() {
    let eps = 0.3;
    for n in [2, 8, 64] {
        let axial = || Loads::axial(Control::Displacement);
        let settings = ContinuationSettings::default;
        let mut lowest = Vec::new();
        for joints in [Joints::Pin, Joints::Sliding] {
            let sim = solved(n, 1, joints, axial(), eps, settings());
            let mut judge = CellJudge::new(sim.model(), sim.system(), 33).expect("a cell");
            let d = judge.dispersion(sim.model(), sim.system(), sim.state());
            let (value, p, k) = d.lowest().expect("every block converges");
            println!("n = {n}, {joints:?}: lowest {value:.9} at p = {p}, k = {k:.4}");
            lowest.push(value);
        }
        assert!(
            lowest[1] <= lowest[0] + 1e-9 * lowest[0].abs(),
            "n = {n}: sliding {} above pinned {}",
            lowest[1],
            lowest[0]
        );
    }
}

/// The force (N) the pinned cell's joint carries: its three rows' multipliers.
fn pin_force(sim: &Simulation) -> [f64; 3] {
    let system = sim.system();
    let rows: Vec<usize> = system
        .linear
        .iter()
        .enumerate()
        .filter(|(_, c)| matches!(c.role, Role::Joint(_)))
        .map(|(i, _)| system.linear_row(i))
        .collect();
    assert_eq!(rows.len(), 3, "one pin joint of three rows");
    std::array::from_fn(|i| sim.state()[rows[i]])
}

/// Pressed by q at a held ε and twisted by φ per cell at a held ε, the sliding cell keeps
/// the rotation by π about the crossing's radial line, so its contact does not slip and its
/// joint carries the pinned joint's force, which is radial (normal to both rods): its state
/// is the pinned cell's to 1e-10, its joint force the pinned one's to 1e-8 of the rods'
/// axial force (zero under pressure, where the mirror also holds), for n = 2, 8, 64.
#[test]
fn the_pressed_and_twisted_sliding_cell_is_the_pinned_cell() {
    let eps = 0.3;
    let held = Held {
        axial: AxialHeld::Ratio(eps),
        ..Held::NATURAL
    };
    let settings = || ContinuationSettings {
        track_stability: false,
        lowest_eigenvalue: false,
        ..ContinuationSettings::default()
    };
    for (n, phi) in [(2, 0.2), (8, 0.01), (64, 1e-5)] {
        for (component, target) in [(Component::Pressure, 1500.0), (Component::Twist, phi)] {
            let control = if component == Component::Pressure {
                Control::Force
            } else {
                Control::Displacement
            };
            let loads = || Loads::compose(component, control, held);
            let sliding = solved(n, 1, Joints::Sliding, loads(), target, settings());
            let pinned = solved(n, 1, Joints::Pin, loads(), target, settings());
            let (force, slip) = joint_force_and_slip(&sliding);
            let apart = rods_apart(&sliding, &pinned);
            let pin = pin_force(&pinned);
            let row = sliding.system().slide_row(0);
            let slide: Vec<f64> = (0..3).map(|i| sliding.state()[row + i]).collect();
            let (fz, _) = pinned
                .system()
                .reaction(pinned.model(), pinned.state(), 0, End::Tip);
            let gap = (0..3).fold(0.0, |d: f64, i| d.max((slide[i] - pin[i]).abs()));
            println!("n = {n}, {component:?} {target}: from the pinned cell {apart:.2e}, slip {slip:.2e} m, joint force {force:.3e} N, pinned {pin:?}, sliding {slide:?} ({gap:.1e}), fz {:.6}", fz[2]);
            assert!(apart <= 1e-10, "n = {n}, {component:?}: {apart}");
            assert!(gap <= 1e-8 * fz[2].abs(), "n = {n}, {component:?}: {gap}");
            if component == Component::Pressure {
                assert!(force <= 1e-10 * fz[2].abs(), "n = {n}: {force}");
            }
        }
    }
}

/// At k = 2πj/N the sliding cell's spectrum is that of N sliding cells closed on
/// themselves (the check of `cell.rs`, with the rods' own turning held out of the metric
/// where the contacts' rows hold it at points): n = 8, ε = 0.3, N = 3. (The left rod of a
/// ring of N ≡ 0 mod m cells ends in its own sector, so that both rods move alone in the
/// blocks (p, 0), four motions that the contacts' two rows and the rigid gauge's rows,
/// kept at p = 0 only, do not hold at p ≠ 0.)
#[test]
fn the_sliding_cells_spectrum_at_k_2pi_j_over_n_is_that_of_a_ring_of_n_cells() {
    let (n, eps, cells) = (8, 0.3, 3);
    let axial = || Loads::axial(Control::Displacement);
    let cell = solved(
        n,
        1,
        Joints::Sliding,
        axial(),
        eps,
        ContinuationSettings::default(),
    );
    let ring = solved(
        n,
        cells,
        Joints::Sliding,
        axial(),
        eps,
        ContinuationSettings::default(),
    );
    let mut on_cell = CellJudge::new(cell.model(), cell.system(), 9).expect("a cell");
    crate::cell::ring_against_cell(&cell, &mut on_cell, &ring, cells);
    // a left rod moves alone in the blocks (p, 2πp/m), which no ring of cells reaches on
    // its own: the mirror y ↦ −y, which swaps the rods, gives them the spectrum of the
    // right rod's blocks (p, 0)
    let m = n / 2;
    for p in 1..m {
        let left = 2.0 * std::f64::consts::PI * p as f64 / m as f64;
        let [a, b] = [0.0, left].map(|k| {
            on_cell
                .lowest_at(cell.model(), cell.system(), cell.state(), p, k)
                .expect("converges")
        });
        let rel = (a - b).abs() / a.abs();
        println!("p = {p}: (p, 0) {a:.12} (p, 2πp/m) {b:.12} rel {rel:.1e}");
        assert!(rel < 1e-8, "p = {p}: {a} vs {b}");
    }
}

/// With sliding crossings the block (0, ψ) holds, besides the path's states, a motion of no
/// energy and no metric: every rod translating rigidly, the right and the left rods with
/// opposite circular polarisations in the cell's frame, their difference at each crossing
/// along the tube's surface (the contacts slide). Its gauge row holds it, as the rigid
/// translation's in (1, ψ): the shipped case runs to ε = 0.3 with no critical point on its
/// sampled phases (without the row the count there flickered between 0 and 2 from step to
/// step), and the map's bands of p = 0 and p = 1 are each one band about ψ = π/4.
#[test]
fn the_sliding_cells_translations_along_the_surface_are_held() {
    let case = spira::case::Case::from_file(std::path::Path::new("cases/cell-n8-sliding.toml"))
        .expect("the shipped case reads");
    let targets = case.output_parameters(case.loading.target, 30);
    let outcome = spira::run::run_path(&case, &targets, |_, _| {}).expect("the path runs");
    assert!(outcome.error.is_none());
    assert!(outcome.critical.is_empty(), "{:?}", outcome.critical.len());
    let last = &outcome.dispersion.last().expect("points").dispersion;
    let quarter = std::f64::consts::FRAC_PI_4;
    for p in [0, 1] {
        let bands = last.unstable_bands(p);
        println!("p = {p}: {bands:?}");
        assert_eq!(bands.len(), 1, "p = {p}: {bands:?}");
        assert!(bands[0].0 < quarter && quarter < bands[0].1, "{bands:?}");
    }
}
