//! Physics checks of the core against numbers that do not come from spira: the analytic
//! helix of docs/theory.md §2, the joint list of thesis §3.2, finite differences, Love's
//! helical equilibria (docs/theory.md §6), the thesis's qualitative findings, and invariance.

#![allow(clippy::needless_range_loop)] // the checks index components as the equations do

use nalgebra::Vector3;
use spira::case::Case;
use spira::discretisation::discrete_model::{DiscreteModel, End, Reference};
use spira::discretisation::element;
use spira::discretisation::shape::Order;
use spira::discretisation::system::System;
use spira::model::assembly::Assembly;
use spira::model::boundary::BoundaryConditions;
use spira::model::elasticity::{Elasticity, Energy, Ribbon, StressFree};
use spira::model::helix::{Chirality, Helix};
use spira::model::loading::Control;
use spira::model::loading::Loads;
use spira::model::quaternion;
use spira::model::stiffness::Stiffness;
use spira::simulation::Simulation;
use spira::solver::continuation::ContinuationSettings;
use std::f64::consts::PI;

const A: f64 = 0.06;
const B: f64 = 0.025;

fn c() -> f64 {
    A.hypot(B)
}

fn thesis(n: usize) -> Case {
    Case::from_file(std::path::Path::new(&format!("cases/thesis-n{n}.toml"))).unwrap()
}

// ---------------------------------------------------------------- geometry

/// The 8 thesis helices (§3.2): right-handed at 0, π/2, π, −π/2; left-handed at
/// 0, −π/2, π, π/2 (thesis eqs. 3.15–3.30).
fn thesis_helices() -> Vec<Helix> {
    let h = |chirality, base_angle| Helix {
        radius: A,
        pitch: B,
        chirality,
        base_angle,
    };
    let mut v: Vec<Helix> = [0.0, PI / 2.0, PI, -PI / 2.0]
        .iter()
        .map(|&t| h(Chirality::Right, t))
        .collect();
    v.extend(
        [0.0, -PI / 2.0, PI, PI / 2.0]
            .iter()
            .map(|&t| h(Chirality::Left, t)),
    );
    v
}

/// Directors of docs/theory.md §2 written out component by component (right-handed) and
/// their mirror (left-handed).
fn analytic_directors(h: &Helix, s: f64) -> [Vector3<f64>; 3] {
    let (a, b, c) = (A, B, c());
    let phi = s / c + h.base_angle;
    let (sp, cp) = phi.sin_cos();
    match h.chirality {
        Chirality::Right => [
            Vector3::new(-(b / c) * sp, (b / c) * cp, -a / c),
            Vector3::new(-cp, -sp, 0.0),
            Vector3::new(-(a / c) * sp, (a / c) * cp, b / c),
        ],
        Chirality::Left => {
            let d2 = Vector3::new(-cp, sp, 0.0);
            let d3 = Vector3::new(-(a / c) * sp, -(a / c) * cp, b / c);
            [d2.cross(&d3), d2, d3]
        }
    }
}

#[test]
fn quaternion_fields_reproduce_the_directors_of_all_thesis_helices() {
    let length = 7.0 * PI * c();
    let s: Vec<f64> = (0..=400).map(|k| length * k as f64 / 400.0).collect();
    for h in thesis_helices() {
        let field = h.quaternion_field(&s);
        for (k, q) in field.iter().enumerate() {
            assert!((q.norm() - 1.0).abs() < 1e-14);
            let r = quaternion::rotation(q);
            let d = analytic_directors(&h, s[k]);
            for i in 0..3 {
                assert!(
                    (r.column(i) - d[i]).norm() < 1e-12,
                    "{:?} at s = {}: d{} off by {:e}",
                    h,
                    s[k],
                    i + 1,
                    (r.column(i) - d[i]).norm()
                );
            }
            // the centreline's tangent is d3
            let dr = (h.position(s[k] + 1e-6) - h.position(s[k] - 1e-6)) / 2e-6;
            assert!((dr - d[2]).norm() < 1e-8);
            // continuity: neighbours differ by the small rotation of one sample
            if k > 0 {
                assert!(
                    (q - field[k - 1]).norm() < 0.1,
                    "jump in the field at s = {}",
                    s[k]
                );
            }
        }
    }
}

#[test]
fn natural_curvatures_come_out_of_the_quaternion_field() {
    // (κ1, κ2, Ω) = 2 Im(q̄ q'), with q' by central differences of the analytic field
    let (c, ds) = (c(), 1e-6);
    for h in thesis_helices() {
        let expected = Vector3::new(-A / (c * c), 0.0, h.chirality.sign() * B / (c * c));
        assert!((h.natural_curvature() - expected).norm() < 1e-14);
        for k in 0..20 {
            let s = 0.05 + 0.07 * k as f64;
            let q = h.quaternion(s, None);
            let qp = h.quaternion(s + ds, Some(&q));
            let qm = h.quaternion(s - ds, Some(&q));
            let u = quaternion::darboux(&q, &((qp - qm) / (2.0 * ds)));
            assert!(
                (u - expected).norm() < 1e-7,
                "{:?}: {u:?} vs {expected:?}",
                h
            );
            // and d_i' = u × d_i in the body frame: d3' = κ2 d1 − κ1 d2 ... check d3'.d1 = κ2
            let d = analytic_directors(&h, s);
            let dp = analytic_directors(&h, s + ds);
            let dm = analytic_directors(&h, s - ds);
            let d3p = (dp[2] - dm[2]) / (2.0 * ds);
            let d2p = (dp[1] - dm[1]) / (2.0 * ds);
            let d1p = (dp[0] - dm[0]) / (2.0 * ds);
            assert!((d2p.dot(&d[2]) - expected[0]).abs() < 1e-6, "κ1 = d2'·d3");
            assert!((d3p.dot(&d[0]) - expected[1]).abs() < 1e-6, "κ2 = d3'·d1");
            assert!((d1p.dot(&d[1]) - expected[2]).abs() < 1e-6, "Ω = d1'·d2");
        }
    }
}

#[test]
fn joint_list_for_eight_helices_equals_thesis_section_3_2() {
    // thesis §3.2: crossing of right helix i with left helix j at s/c = offset + kπ,
    // rows: right θ0 = 0, π/2, π, −π/2; columns: left θ0 = 0, −π/2, π, π/2
    let q = PI / 4.0;
    let table = [
        [0.0, q, 2.0 * q, 3.0 * q],
        [3.0 * q, 0.0, q, 2.0 * q],
        [2.0 * q, 3.0 * q, 0.0, q],
        [q, 2.0 * q, 3.0 * q, 0.0],
    ];
    let thesis = thesis_helices();
    let length = 7.0 * PI * c();
    let asm = Assembly::new(8, A, B, length);
    let same_angle =
        |a: f64, b: f64| ((a - b).rem_euclid(2.0 * PI)).min((b - a).rem_euclid(2.0 * PI)) < 1e-12;
    let find = |h: &Helix| {
        asm.rods
            .iter()
            .position(|r| r.chirality == h.chirality && same_angle(r.base_angle, h.base_angle))
            .expect("thesis helix present in the assembly")
    };
    let mut expected_count = 0;
    for i in 0..4 {
        for j in 0..4 {
            let (ri, lj) = (find(&thesis[i]), find(&thesis[4 + j]));
            let mut expected: Vec<f64> = (0..8)
                .map(|k| (table[i][j] + k as f64 * PI) * c())
                .filter(|&s| s <= length * (1.0 + 1e-12))
                .collect();
            expected_count += expected.len();
            let mut got: Vec<f64> = asm
                .joints
                .iter()
                .filter(|jt| jt.right == ri && jt.left == lj)
                .map(|jt| jt.s)
                .collect();
            got.sort_by(f64::total_cmp);
            expected.sort_by(f64::total_cmp);
            assert_eq!(got.len(), expected.len(), "right {i} / left {j}");
            for (g, e) in got.iter().zip(&expected) {
                assert!((g - e).abs() < 1e-12, "right {i} / left {j}: {g} vs {e}");
                // the two rods really meet there
                let (pr, pl) = (asm.rods[ri].position(*g), asm.rods[lj].position(*g));
                assert!((pr - pl).norm() < 1e-12);
            }
        }
    }
    assert_eq!(asm.joints.len(), expected_count);
    // every rod meets a joint every π/4 in s/c: 29 arc lengths on [0, 7π c]
    for id in 0..8 {
        assert_eq!(asm.joint_arc_lengths(id).len(), 29);
    }
}

// ---------------------------------------------------------------- derivatives

fn fd_check(f: impl Fn(&[f64]) -> f64, x: &[f64], grad: &[f64], tol: f64, what: &str) {
    for i in 0..x.len() {
        let h = 1e-6 * (1.0 + x[i].abs());
        let mut xp = x.to_vec();
        let mut xm = x.to_vec();
        xp[i] += h;
        xm[i] -= h;
        let fd = (f(&xp) - f(&xm)) / (2.0 * h);
        let scale = 1.0 + grad[i].abs();
        assert!(
            (fd - grad[i]).abs() < tol * scale,
            "{what}: component {i}: analytic {} vs finite difference {fd}",
            grad[i]
        );
    }
}

#[test]
fn energy_density_and_tangent_derivatives_match_finite_differences() {
    let st = Stiffness {
        b1: 1.0,
        b2: 1.3,
        b3: 2.0,
    };
    let nat = Vector3::new(-12.0, 0.5, 5.0);
    let x0 = [0.3, -0.5, 0.7, 0.4, 2.0, -1.0, 3.0, 0.5];
    let w = |x: &[f64]| {
        element::energy_density(
            &[x[0], x[1], x[2], x[3]],
            &[x[4], x[5], x[6], x[7]],
            &st,
            &nat,
        )
        .0
    };
    let (_, g, h) = element::energy_density(
        &[x0[0], x0[1], x0[2], x0[3]],
        &[x0[4], x0[5], x0[6], x0[7]],
        &st,
        &nat,
    );
    fd_check(w, &x0, &g, 1e-6, "∂W");
    for a in 0..8 {
        let ga = |x: &[f64]| {
            element::energy_density(
                &[x[0], x[1], x[2], x[3]],
                &[x[4], x[5], x[6], x[7]],
                &st,
                &nat,
            )
            .1[a]
        };
        fd_check(ga, &x0, &h[a], 1e-5, "∂²W");
    }
    // Sadowsky's ribbon, at a point where the regularisation matters (κ1 ≈ η) and at one
    // where it does not
    for (ribbon, p) in [
        (RIBBON, [x0[4], x0[5], x0[6], x0[7]]),
        (
            Ribbon {
                width: 0.5,
                thickness: 0.3,
            },
            [0.1, 0.4, -0.3, 0.2],
        ),
    ] {
        let sadowsky = Elasticity {
            stress_free: StressFree::Straight,
            energy: Energy::Sadowsky(ribbon),
        };
        let zero = Vector3::zeros();
        let at = |x: &[f64]| {
            element::strain_energy_density(
                &[x[0], x[1], x[2], x[3]],
                &[x[4], x[5], x[6], x[7]],
                &st,
                &sadowsky,
                &zero,
            )
        };
        let y0 = [x0[0], x0[1], x0[2], x0[3], p[0], p[1], p[2], p[3]];
        let (w0, g, h) = at(&y0);
        // the density of the regularised ribbon, written out here (elasticity.rs docs)
        let u = element::curvature(&[y0[0], y0[1], y0[2], y0[3]], &p);
        let eta2 = 60.0 * (ribbon.thickness / (ribbon.width * ribbon.width)).powi(2);
        let expected = 0.5
            * st.b1
            * (u[0].powi(2) + 2.0 * u[2].powi(2) + u[2].powi(4) / (u[0].powi(2) + eta2))
            + 0.5 * st.b2 * u[1].powi(2);
        assert!(
            (w0 - expected).abs() < 1e-12 * expected,
            "{w0} vs {expected}"
        );
        fd_check(|x: &[f64]| at(x).0, &y0, &g, 1e-6, "Sadowsky ∂W");
        for a in 0..8 {
            fd_check(|x: &[f64]| at(x).1[a], &y0, &h[a], 1e-5, "Sadowsky ∂²W");
        }
    }
    let q0 = [0.3, -0.5, 0.7, 0.4];
    let (_, gt, ht) = element::tangent(&q0);
    for j in 0..3 {
        fd_check(
            |q: &[f64]| element::tangent(&[q[0], q[1], q[2], q[3]]).0[j],
            &q0,
            &gt[j],
            1e-7,
            "∂d3",
        );
        for k in 0..4 {
            fd_check(
                |q: &[f64]| element::tangent(&[q[0], q[1], q[2], q[3]]).1[j][k],
                &q0,
                &ht[j][k],
                1e-6,
                "∂²d3",
            );
        }
    }
    // the tangent is that of the normalised rotation
    let t = element::tangent(&q0).0;
    let r = quaternion::rotation(&q0.into());
    assert!((Vector3::from(t) - r.column(2)).norm() < 1e-14);
}

/// The three elastic hypotheses: Kirchhoff rods stress-free when helical
/// and when straight, and Sadowsky ribbons (20 mm wide, 0.2 mm thick: η = 3.9 1/m, a
/// quarter of the thesis helix's curvature).
fn hypotheses() -> [Elasticity; 3] {
    [
        Elasticity::default(),
        Elasticity {
            stress_free: StressFree::Straight,
            energy: Energy::Kirchhoff,
        },
        Elasticity {
            stress_free: StressFree::Straight,
            energy: Energy::Sadowsky(RIBBON),
        },
    ]
}

const RIBBON: Ribbon = Ribbon {
    width: 0.02,
    thickness: 2e-4,
};

/// Small model with joints, both orders, a perturbed state and random multipliers, for
/// every hypothesis.
fn perturbed_systems(order: Order) -> Vec<(DiscreteModel, System, Vec<f64>)> {
    hypotheses()
        .into_iter()
        .map(|h| perturbed_system(order, h))
        .collect()
}

fn perturbed_system(order: Order, elasticity: Elasticity) -> (DiscreteModel, System, Vec<f64>) {
    let asm = Assembly::new(2, A, B, 2.0 * PI * c());
    let model = DiscreteModel::with_hypotheses(
        asm,
        Stiffness {
            b1: 1.0,
            b2: 1.5,
            b3: 2.0,
        },
        4,
        order,
        elasticity,
        Reference::Discrete,
    );
    let bc = BoundaryConditions::default();
    let x0 = model.natural_state();
    let sys = System::new(&model, bc, &x0, &Loads::axial(Control::Displacement), 0.0);
    let mut x = x0;
    x.resize(sys.n, 0.0);
    for (i, v) in x.iter_mut().enumerate() {
        let noise = ((i * 7919 + 13) % 1009) as f64 / 1009.0 - 0.5;
        if i < model.n_primal {
            *v += 0.02 * noise;
        } else {
            *v = 3.0 * noise;
        }
    }
    (model, sys, x)
}

#[test]
fn global_residual_is_the_gradient_of_the_lagrangian() {
    for order in [Order::Linear, Order::Quadratic] {
        for (model, sys, x) in perturbed_systems(order) {
            let mut r = vec![0.0; sys.n];
            sys.residual(&model, &x, &mut r);
            // L = E + Σ multiplier · constraint value (the constraint rows of the residual)
            let lagrangian = |y: &[f64]| {
                let mut ry = vec![0.0; sys.n];
                let e = sys.residual(&model, y, &mut ry).energy;
                e + (model.n_primal..sys.n).map(|k| y[k] * ry[k]).sum::<f64>()
            };
            fd_check(lagrangian, &x, &r, 1e-6, "∇L");
        }
    }
}

/// `∂R/∂x_j` at `x` by central differences of step 1e-6.
fn residual_derivative(model: &DiscreteModel, sys: &System, x: &[f64], j: usize) -> Vec<f64> {
    let h = 1e-6;
    let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
    xp[j] += h;
    xm[j] -= h;
    let (mut rp, mut rm) = (vec![0.0; sys.n], vec![0.0; sys.n]);
    sys.residual(model, &xp, &mut rp);
    sys.residual(model, &xm, &mut rm);
    (0..sys.n).map(|i| (rp[i] - rm[i]) / (2.0 * h)).collect()
}

#[test]
fn kkt_matrix_is_the_jacobian_of_the_residual() {
    for order in [Order::Linear, Order::Quadratic] {
        for (model, sys, x) in perturbed_systems(order) {
            let mut r = vec![0.0; sys.n];
            let mut values = sys.new_values();
            sys.evaluate(&model, &x, &mut r, &mut values);
            let m = sys.matrix(&values);
            let mut dense = vec![vec![0.0; sys.n]; sys.n];
            let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
            for j in 0..sys.n {
                for p in cp[j]..cp[j + 1] {
                    dense[ri[p]][j] += m.val()[p];
                }
            }
            for j in 0..sys.n {
                let column = residual_derivative(&model, &sys, &x, j);
                for i in 0..sys.n {
                    let fd = column[i];
                    assert!(
                        (fd - dense[i][j]).abs() < 1e-5 * (1.0 + fd.abs()),
                        "{order:?}: K[{i}][{j}] = {} vs finite difference {fd}",
                        dense[i][j]
                    );
                    // symmetric, as the Hessian of a Lagrangian must be
                    assert!((dense[i][j] - dense[j][i]).abs() < 1e-9 * (1.0 + dense[i][j].abs()));
                }
            }
        }
    }
}

// ---------------------------------------------------------------- Love's helices

/// Axial force F (tension positive) and axial couple M on the tip of a rod held as a
/// perfect helix (a, b) whose natural helix is (a0, b0): docs/theory.md §6, derived there from
/// the balance laws n' = 0, m' + d3 × n = 0 with n = F e_z.
fn love(a0: f64, b0: f64, a: f64, b: f64, bend: f64, twist: f64, chi: f64) -> (f64, f64) {
    let (c0, c) = (a0.hypot(b0), a.hypot(b));
    let (k0, t0) = (a0 / (c0 * c0), b0 / (c0 * c0));
    let (k, t) = (a / (c * c), b / (c * c));
    let f = (twist * (t - t0) * a - bend * (k - k0) * b) / (a * c);
    let m = chi * (bend * (k - k0) * a + twist * (t - t0) * b) / c;
    (f, m)
}

#[test]
fn love_check_value() {
    let a = (0.065f64.powi(2) - 0.0125f64.powi(2)).sqrt();
    assert!((a - 0.0637868).abs() < 5e-8);
    let (f, _) = love(0.06, 0.025, a, 0.0125, 1.0, 2.0, 1.0);
    assert!((f - -93.73536).abs() < 1e-4, "F = {f}");
}

/// Love's F and M for a rod stress-free when straight (`K0 = τ0 = 0`), docs/theory.md §7.
fn love_straight(a: f64, b: f64, bend: f64, twist: f64, chi: f64) -> (f64, f64) {
    let c = a.hypot(b);
    let (k, t) = (a / (c * c), b / (c * c));
    (
        (twist * t * a - bend * k * b) / (a * c),
        chi * (bend * k * a + twist * t * b) / c,
    )
}

/// docs/theory.md §7: a uniform helix of arc length `length` (m), height `h` and Frenet frame
/// turned by `phi` about its axis has `c = L/φ`, `b = h/φ`, `a = √(c² − b²)` and energy
/// `E(h, φ) = L W(a/c², b/c²)`; the axial force on the tip is `∂E/∂h` (tension positive)
/// and the axial couple `χ ∂E/∂φ` (a left-handed helix turns the other way). Derivatives by
/// Richardson-extrapolated central differences of the closed form (error ~1e-12).
fn helix_wrench_from_energy(
    length: f64,
    a: f64,
    b: f64,
    w: impl Fn(f64, f64) -> f64,
    chi: f64,
) -> (f64, f64) {
    let energy = |h: f64, phi: f64| {
        let (c, b) = (length / phi, h / phi);
        let a = (c * c - b * b).sqrt();
        length * w(a / (c * c), b / (c * c))
    };
    let c = a.hypot(b);
    let (h, phi) = (length * b / c, length / c);
    let derivative = |f: &dyn Fn(f64) -> f64, x: f64| {
        let d = |step: f64| (f(x + step) - f(x - step)) / (2.0 * step);
        let step = 1e-3 * x;
        (4.0 * d(step / 2.0) - d(step)) / 3.0
    };
    let force = derivative(&|h| energy(h, phi), h);
    let couple = chi * derivative(&|phi| energy(h, phi), phi);
    (force, couple)
}

/// An energy density `W(κ, τ)` of a uniform helix (J/m).
type Density<'a> = dyn Fn(f64, f64) -> f64 + 'a;

#[test]
fn differentiating_the_energy_of_a_uniform_helix_gives_loves_formula() {
    // docs/theory.md §7: "for Kirchhoff's W this reproduces Love's formula of §6 (check it)"
    let length = 7.0 * PI * c();
    let (k0, t0) = (A / (c() * c()), B / (c() * c()));
    let natural = move |k: f64, t: f64| 0.5 * (k - k0).powi(2) + 0.5 * 2.0 * (t - t0).powi(2);
    let straight = |k: f64, t: f64| 0.5 * k * k + 0.5 * 2.0 * t * t;
    for b in [0.0125, 0.04] {
        let a = (c() * c() - b * b).sqrt();
        for chi in [1.0, -1.0] {
            let pairs: [(&Density, (f64, f64)); 2] = [
                (&natural, love(A, B, a, b, 1.0, 2.0, chi)),
                (&straight, love_straight(a, b, 1.0, 2.0, chi)),
            ];
            for (w, love) in pairs {
                let (f, m) = helix_wrench_from_energy(length, a, b, w, chi);
                assert!(
                    (f - love.0).abs() < 1e-8 * love.0.abs(),
                    "F {f} vs {}",
                    love.0
                );
                assert!(
                    (m - love.1).abs() < 1e-8 * love.1.abs(),
                    "M {m} vs {}",
                    love.1
                );
            }
        }
    }
}

/// The regularised Sadowsky density of a uniform helix (κ2 = 0), written out from its
/// definition (src/model/elasticity.rs): `½ D [κ² + 2τ² + τ⁴/(κ² + η²)]`, η² = 60 t²/w⁴.
fn sadowsky_w(d: f64, ribbon: Ribbon) -> impl Fn(f64, f64) -> f64 {
    let eta2 = 60.0 * ribbon.thickness.powi(2) / ribbon.width.powi(4);
    move |k: f64, t: f64| 0.5 * d * (k * k + 2.0 * t * t + t.powi(4) / (k * k + eta2))
}

/// Elements per rod for the closed-form checks. Force and couple errors fall as h⁴; the
/// couple, a small difference of a bending and a twisting term, is the harder one:
/// 4e-5 relative at 96 elements, 2.6e-6 at 192, 1.9e-7 at 384 (b = 0.0125).
const LOVE_ELEMENTS: usize = 384;

/// Holds both ends of each rod (right-handed rod 0, left-handed rod 1, no joints) of the
/// hypotheses `elasticity` on a perfect helix of pitch parameter `b` with the same length
/// and number of turns, and compares the reactions with the closed form `closed(a, b, χ)`
/// (axial force, axial couple).
fn check_perfect_helix(
    b: f64,
    elasticity: Elasticity,
    closed: impl Fn(f64, f64, f64) -> (f64, f64),
) {
    let length = 7.0 * PI * c();
    let asm = Assembly::new(2, A, B, length);
    let model = DiscreteModel::with_hypotheses(
        asm,
        Stiffness {
            b1: 1.0,
            b2: 1.0,
            b3: 2.0,
        },
        LOVE_ELEMENTS,
        Order::Quadratic,
        elasticity,
        Reference::Discrete,
    );
    let a = (c() * c() - b * b).sqrt(); // same c: same arc length per turn
    let targets: Vec<Helix> = model
        .rods
        .iter()
        .map(|r| Helix {
            radius: a,
            pitch: b,
            ..r.helix
        })
        .collect();
    let sim = Simulation::held_on_helices(model, a, b, ContinuationSettings::default())
        .expect("perfect helix equilibrium converges");
    let lp = sim.load_point(0);
    for (rod, target) in lp.reactions.iter().zip(&targets) {
        let chi = target.chirality.sign();
        let (f, m) = closed(a, b, chi);
        let force = Vector3::from(rod.tip.force);
        let tip = target.position(length);
        // moment about the helix axis: the couple plus the moment of the tip force
        let moment =
            Vector3::from(rod.tip.moment) + Vector3::new(tip[0], tip[1], 0.0).cross(&force);
        let tol = 1e-6 * f.abs();
        let what = format!("{:?} b = {b}, {}", target.chirality, elasticity.describe());
        assert!(
            (force[2] - f).abs() < tol,
            "{what}: Fz = {} vs closed form {f}",
            force[2]
        );
        assert!(
            force[0].abs() < tol && force[1].abs() < tol,
            "{what}: lateral force {force:?}"
        );
        assert!(
            (moment[2] - m).abs() < 1e-6 * m.abs(),
            "{what}: Mz = {} vs closed form {m}",
            moment[2]
        );
        assert!(
            moment[0].abs() < tol * a && moment[1].abs() < tol * a,
            "{what}: lateral moment {moment:?}"
        );
        // the base carries the opposite wrench
        assert!((rod.base.force[2] + f).abs() < tol);
    }
    // and the solution is that helix: curvatures constant and equal to its own
    let snap = sim.snapshot();
    let cc = a.hypot(b);
    for (shape, target) in snap.rods.iter().zip(&targets) {
        let expected = [-a / (cc * cc), 0.0, target.chirality.sign() * b / (cc * cc)];
        for node in &shape.nodes {
            let p = target.position(node.s);
            assert!((Vector3::from(node.position) - p).norm() < 1e-6 * length);
            for k in 0..3 {
                assert!(
                    (node.curvature[k] - expected[k]).abs() < 1e-3 * (1.0 / cc),
                    "curvature {k} at s = {}",
                    node.s
                );
            }
        }
    }
}

fn check_all_hypotheses(b: f64) {
    let [helix, straight, sadowsky] = hypotheses();
    check_perfect_helix(b, helix, |a, b, chi| love(A, B, a, b, 1.0, 2.0, chi));
    check_perfect_helix(b, straight, |a, b, chi| love_straight(a, b, 1.0, 2.0, chi));
    let length = 7.0 * PI * c();
    check_perfect_helix(b, sadowsky, |a, b, chi| {
        helix_wrench_from_energy(length, a, b, sadowsky_w(1.0, RIBBON), chi)
    });
}

#[test]
fn perfect_helix_in_compression_is_held_by_the_closed_form_axial_force_and_couple() {
    check_all_hypotheses(0.0125);
}

#[test]
fn perfect_helix_in_extension_is_held_by_the_closed_form_axial_force_and_couple() {
    check_all_hypotheses(0.04);
}

/// Rods stress-free when straight, assembled on the thesis helices (n = 8, clamped): the
/// state at ε = 0 is solved, and it is the helices themselves, each rod held by Love's F
/// and M with K0 = τ0 = 0 (the joints carry nothing: every rod is in equilibrium on its
/// own), with the energy n L ½ (B K² + C τ²) of the prestress.
#[test]
fn rods_stress_free_when_straight_are_prestressed_at_rest() {
    let mut case = thesis(8);
    case.rod.stress_free = StressFree::Straight;
    case.discretisation.symmetric = true;
    let sim = Simulation::from_case(&case).unwrap();
    let lp = sim.load_point(0);
    assert_eq!(lp.compression_ratio, 0.0);
    let (a, b) = (A, B);
    let (k, t) = (a / (c() * c()), b / (c() * c()));
    let length = case.geometry.length;
    let expected = 8.0 * length * 0.5 * (k * k + 2.0 * t * t);
    assert!(
        (lp.energy - expected).abs() < 1e-5 * expected,
        "energy {} J vs {expected} J",
        lp.energy
    );
    let snapshot = sim.snapshot();
    for r in &lp.reactions {
        let (f, m) = love_straight(a, b, 1.0, 2.0, r.chirality.sign());
        let force = Vector3::from(r.tip.force);
        assert!(
            (force[2] - f).abs() < 1e-5 * f.abs(),
            "rod {}: Fz {} vs {f}",
            r.rod,
            force[2]
        );
        // lateral forces are a discretisation error of the thesis mesh (56 quadratic
        // elements: 6e-5 of F; it falls as h⁴, below 1e-6 at 384 elements in the
        // perfect-helix checks)
        assert!(
            force.xy().norm() < 1e-4 * f.abs(),
            "rod {}: {force:?}",
            r.rod
        );
        let tip = snapshot.rods[r.rod].nodes.last().unwrap().position;
        let mz = r.tip.moment[2] + (tip[0] * force[1] - tip[1] * force[0]);
        // the couple, like the lateral force, to the discretisation error of the mesh
        // (2.4e-5 here)
        assert!(
            (mz - m).abs() < 1e-4 * m.abs(),
            "rod {}: Mz {mz} vs {m}",
            r.rod
        );
    }
    // the stability of the prestressed state is reported like any other (what it is, is
    // in the README's comparison; tests/physics/symmetry.rs checks the pair's count against the
    // full model's)
    assert!(lp.stability.is_some());
}

// ---------------------------------------------------------------- thesis cases

fn reaction_norm_at_rest(case: &Case, elements: usize) -> f64 {
    let mut case = case.clone();
    case.discretisation.elements = elements;
    let sim = Simulation::from_case(&case).unwrap();
    sim.load_point(0)
        .reactions
        .iter()
        .map(|r| Vector3::from(r.tip.force).norm())
        .fold(0.0, f64::max)
}

#[test]
fn with_the_continuums_curvature_the_natural_state_carries_a_force_that_falls_at_fourth_order() {
    // the thesis's discretisation (`discretisation.reference = "continuum"`): the
    // interpolated helix is not exactly stress-free; the force at rest is a discretisation
    // error and must vanish like h^4 for quadratic elements
    for n in [1, 8] {
        let mut case = thesis(n);
        case.discretisation.reference = Reference::Continuum;
        let pcrit = spira::model::stiffness::euler_load(1.0, case.geometry.length);
        let sim = Simulation::from_case(&case).unwrap();
        let lp = sim.load_point(0);
        assert_eq!(lp.compression_ratio, 0.0);
        for k in 0..3 {
            assert!(
                lp.load[k].abs() < 1e-4,
                "n = {n}: averaged load {:?} at eps = 0",
                lp.load
            );
        }
        let (f1, f2) = (
            reaction_norm_at_rest(&case, 56),
            reaction_norm_at_rest(&case, 112),
        );
        assert!(f1 < 5e-3 * pcrit, "n = {n}: {f1} N at rest");
        let order = (f1 / f2).log2();
        assert!(order > 3.7, "n = {n}: force at rest falls at order {order}");
    }
}

/// With the reference curvatures of the discrete natural configuration (the
/// default), the natural state is an exact equilibrium: every rod's reactions below
/// 1e-10 Pcrit (moments below 1e-10 Pcrit L) and the energy below 1e-12 J, at every mesh
/// and order, for every support the supports table offers, and for the symmetric pair.
#[test]
fn helices_stress_free_in_their_discrete_configuration_carry_nothing_at_rest() {
    use spira::model::boundary::{EndCondition, Rotation, Translation};
    let supports = [
        BoundaryConditions::default(),
        BoundaryConditions {
            tip: EndCondition {
                translation: Translation::Slide,
                rotation: Rotation::Clamped,
            },
            ..Default::default()
        },
        BoundaryConditions {
            base: EndCondition {
                translation: Translation::Radial,
                rotation: Rotation::Free,
            },
            ..Default::default()
        },
    ];
    let mut checked = 0;
    for (n, symmetric) in [(1, false), (2, false), (8, false), (8, true)] {
        for order in [Order::Linear, Order::Quadratic] {
            for elements in [7, 24, 56, 97] {
                for bc in supports {
                    let mut case = thesis(n);
                    assert_eq!(case.discretisation.reference, Reference::Discrete);
                    case.discretisation.order = order;
                    case.discretisation.elements = elements;
                    case.discretisation.symmetric = symmetric;
                    case.boundary = bc;
                    let length = case.geometry.length;
                    let pcrit = spira::model::stiffness::euler_load(case.stiffness.b1, length);
                    let sim = Simulation::from_case(&case).unwrap();
                    let lp = sim.load_point(0);
                    let what = format!("n = {n} ({symmetric}), {order:?} x {elements}, {bc:?}");
                    assert_eq!(lp.compression_ratio, 0.0, "{what}");
                    assert!(lp.energy.abs() < 1e-12, "{what}: energy {} J", lp.energy);
                    for r in &lp.reactions {
                        for end in [r.tip, r.base] {
                            let f = Vector3::from(end.force).norm();
                            let m = Vector3::from(end.moment).norm();
                            assert!(f < 1e-10 * pcrit, "{what}: rod {} force {f} N", r.rod);
                            assert!(
                                m < 1e-10 * pcrit * length,
                                "{what}: rod {} moment {m} N m",
                                r.rod
                            );
                        }
                    }
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 4 * 2 * 4 * 3);
}

/// Along a path of `steps` equal steps to the case's target: at every output step the
/// energy stored and the work done by the supports on the tips, `Σ_rods ∫ Fz dz` by the
/// trapezoid rule over the output steps (the bases do not move and the clamped tips do
/// not turn, so no other support works).
fn energy_and_work(case: &Case, steps: usize) -> Vec<(f64, f64)> {
    let mut sim = Simulation::from_case(case).unwrap();
    let mut previous = sim.load_point(0);
    let fz =
        |p: &spira::results::LoadPoint| p.reactions.iter().map(|r| r.tip.force[2]).sum::<f64>();
    let mut work = 0.0;
    let mut out = Vec::new();
    for k in 1..=steps {
        sim.advance_to(case.loading.target * k as f64 / steps as f64)
            .unwrap();
        let lp = sim.load_point(k);
        work += 0.5 * (fz(&previous) + fz(&lp)) * (lp.height - previous.height);
        out.push((lp.energy, work));
        previous = lp;
    }
    out
}

/// Energy stored = work done by the supports, to the accuracy of the quadrature
/// of the work. n = 8, thesis mesh, clamped, compressed to ε = 0.5 in 100 equal steps (the
/// symmetric pair: the same equilibria as the full model, tests/physics/symmetry.rs).
///
/// The trapezoid rule's own error is `O(Δε²)` times the change of the stiffness: at the
/// first step (ε = 0.005) it is 2.7e-4 of the energy, because Fz(ε) stiffens from the
/// start (it is the same with the continuum's reference curvatures, prestress and all:
/// the 2.7e-4 is this quadrature error, not the prestress). So the test checks
/// that the difference is that error — it falls as `Δε²` when the steps are halved — and
/// that the work with it removed (Richardson's extrapolation of the trapezoid rule on 100
/// and 200 steps) equals the energy to 1e-6 relative at every one of the 100 steps.
#[test]
fn energy_stored_is_the_work_of_the_supports_along_a_hundred_step_path() {
    let mut case = thesis(8);
    case.discretisation.symmetric = true;
    case.solver.lowest_eigenvalue = false;
    let (coarse, fine) = (energy_and_work(&case, 100), energy_and_work(&case, 200));
    for (k, &(energy, work)) in coarse.iter().enumerate() {
        let (energy_fine, work_fine) = fine[2 * k + 1];
        // the same state, to the Newton tolerance (about 1e-9 of the energy)
        assert!(
            (energy - energy_fine).abs() < 1e-7 * energy,
            "step {k}: same state"
        );
        let richardson = work_fine + (work_fine - work) / 3.0;
        let rel = (energy - richardson).abs() / energy;
        assert!(
            rel < 1e-6,
            "step {}: energy {energy} J, work {richardson} J ({rel:e})",
            k + 1
        );
        let order = ((energy - work) / (energy_fine - work_fine)).log2();
        if k < 20 {
            // where the quadrature error is well above the Newton tolerance's floor
            assert!((order - 2.0).abs() < 0.1, "step {}: order {order}", k + 1);
        }
    }
}

#[test]
fn eight_helices_share_the_load_equally_with_no_sideways_force() {
    let mut case = thesis(8);
    case.loading.target = 0.3;
    let mut sim = Simulation::from_case(&case).unwrap();
    sim.advance_to(0.3).unwrap();
    let lp = sim.load_point(1);
    assert!(
        lp.load[0].abs() < 1e-8 && lp.load[1].abs() < 1e-8,
        "{:?}",
        lp.load
    );
    // thesis fig. 4.19: almost linear, Fz/(n Pcrit) ≈ −3 at eps = 0.3
    assert!(lp.load[2] < -2.8 && lp.load[2] > -3.3, "{:?}", lp.load);
    let fz0 = lp.reactions[0].tip.force[2];
    for r in &lp.reactions {
        assert!(
            (r.tip.force[2] - fz0).abs() < 1e-6 * fz0.abs(),
            "rod {}: {} vs {fz0}",
            r.rod,
            r.tip.force[2]
        );
        let (f0, f) = (
            Vector3::from(lp.reactions[0].tip.force).norm(),
            Vector3::from(r.tip.force).norm(),
        );
        assert!((f - f0).abs() < 1e-6 * f0);
    }
}

#[test]
fn a_single_helix_bows_sideways_under_clamped_compression() {
    let case = thesis(1);
    let mut sim = Simulation::from_case(&case).unwrap();
    sim.advance_to(0.5).unwrap();
    let lp = sim.load_point(1);
    // thesis fig. 4.17: Fx reaches about 0.3 Pcrit by eps = 0.5
    assert!(
        lp.load[0].abs() > 0.2 && lp.load[0].abs() < 0.4,
        "{:?}",
        lp.load
    );
    // curvatures far from constant (thesis fig. 4.4)
    let k1: Vec<f64> = sim.snapshot().rods[0]
        .nodes
        .iter()
        .map(|n| n.curvature[0])
        .collect();
    let (lo, hi) = k1
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(hi - lo > 0.2 * lo.abs());
}

#[test]
fn rotating_the_assembly_about_its_axis_changes_no_force_magnitude_or_curvature() {
    for n in [1, 4] {
        let case = thesis(n);
        let g = case.geometry;
        let base = Assembly::new(n, g.radius, g.pitch, g.length);
        let solve = |asm: Assembly| {
            let model = DiscreteModel::new(asm, case.stiffness, 24, Order::Quadratic);
            let mut sim = Simulation::new(model, case.boundary, case.solver).unwrap();
            sim.advance_to(0.3).unwrap();
            (sim.load_point(1), sim.snapshot())
        };
        let (lp0, s0) = solve(base.clone());
        let (lp1, s1) = solve(base.rotated(0.7));
        for (r0, r1) in lp0.reactions.iter().zip(&lp1.reactions) {
            let (f0, f1) = (Vector3::from(r0.tip.force), Vector3::from(r1.tip.force));
            assert!((f0.norm() - f1.norm()).abs() < 1e-8 * f0.norm(), "n = {n}");
            assert!((f0[2] - f1[2]).abs() < 1e-8 * f0.norm());
            let (m0, m1) = (Vector3::from(r0.tip.moment), Vector3::from(r1.tip.moment));
            assert!((m0.norm() - m1.norm()).abs() < 1e-8 * m0.norm().max(1e-3));
        }
        for (a, b) in s0.rods.iter().zip(&s1.rods) {
            for (na, nb) in a.nodes.iter().zip(&b.nodes) {
                for k in 0..3 {
                    assert!((na.curvature[k] - nb.curvature[k]).abs() < 1e-7, "n = {n}");
                }
            }
        }
    }
}

#[test]
fn tip_reactions_balance_base_reactions_and_joint_forces_cancel_in_the_sum() {
    // overall equilibrium of the assembly: Σ (F_tip + F_base) = 0
    let mut sim = Simulation::from_case(&thesis(4)).unwrap();
    sim.advance_to(0.2).unwrap();
    let lp = sim.load_point(1);
    let mut total = Vector3::zeros();
    for r in &lp.reactions {
        total += Vector3::from(r.tip.force) + Vector3::from(r.base.force);
    }
    assert!(total.norm() < 1e-8, "{total:?}");
    let _ = End::Tip;
}

// ---------------------------------------------------------------- run-time changes

#[test]
fn releasing_the_base_hinge_mid_path_reaches_the_state_of_a_path_released_from_the_start() {
    // an elastic, conservative problem: where the equilibrium is stable and unique, the
    // state at ε under given conditions does not depend on the path that led there (with
    // sliding tips it is not unique: the helix buckles sideways, as Haringx found)
    use spira::model::boundary::{EndCondition, Rotation, Translation};
    let hinge = BoundaryConditions {
        base: EndCondition {
            translation: Translation::Fixed,
            rotation: Rotation::Free,
        },
        ..Default::default()
    };
    let mut case = thesis(1);
    case.discretisation.elements = 24;
    let mut changed = Simulation::from_case(&case).unwrap();
    changed.advance_to(0.1).unwrap();
    changed.set_boundary_conditions(hinge).unwrap();
    changed.advance_to(0.2).unwrap();
    case.boundary = hinge;
    let mut from_start = Simulation::from_case(&case).unwrap();
    from_start.advance_to(0.2).unwrap();
    assert_eq!(changed.stability().map(|s| s.unstable_directions), Some(0));
    assert_eq!(
        from_start.stability().map(|s| s.unstable_directions),
        Some(0)
    );
    let (a, b) = (changed.load_point(1), from_start.load_point(1));
    for k in 0..3 {
        assert!((a.reactions[0].tip.force[k] - b.reactions[0].tip.force[k]).abs() < 1e-7);
        assert!((a.reactions[0].tip.moment[k] - b.reactions[0].tip.moment[k]).abs() < 1e-7);
    }
    // the free base carries no moment
    let m = Vector3::from(a.reactions[0].base.moment).norm();
    assert!(m < 1e-9, "{m}");
}

#[test]
fn switching_between_displacement_and_load_control_keeps_the_state() {
    let mut case = thesis(1);
    case.discretisation.elements = 24;
    let mut sim = Simulation::from_case(&case).unwrap();
    sim.advance_to(0.2).unwrap();
    let before = sim.load_point(1);
    sim.set_control(Control::Force).unwrap();
    // the load parameter is the compressive force over Pcrit; the state is unchanged
    assert!((sim.parameter() + before.load[2]).abs() < 1e-9);
    let after = sim.load_point(1);
    assert!((after.compression_ratio - 0.2).abs() < 1e-9);
    for k in 0..3 {
        assert!((after.load[k] - before.load[k]).abs() < 1e-8);
    }
    // more load, then back to displacement control at the new state
    let p = sim.parameter();
    sim.advance_to(p * 1.1).unwrap();
    assert!(sim.compression_ratio() > 0.2);
    sim.set_control(Control::Displacement).unwrap();
    assert!((sim.parameter() - sim.compression_ratio()).abs() < 1e-12);
    assert!((-sim.load_point(2).load[2] - p * 1.1).abs() < 1e-7);
}

// ---------------------------------------------------------------- loads along the rods

/// A straight rod (Euler's column of cases/euler-clamped.toml) clamped at both ends, its tip
/// free along the axis, under a uniform dead line load `q` (N/m) across it.
fn rod_under_line_load(order: &str) -> (Case, Loads) {
    let text = format!(
        "[geometry]\nhelices = 1\nradius = 0.0\npitch = 1.0\nlength = 1.0\n\
         [stiffness]\nb1 = 1.0\nb2 = 1.0\nb3 = 2.0\n\
         [loading]\ncontrol = \"force\"\n\
         [discretisation]\nelements = 32\norder = \"{order}\"\n"
    );
    let case = Case::parse(&text, "line-load.toml", "line-load").unwrap();
    let loads = Loads::line_load([1.0, 0.0, 0.0]);
    (case, loads)
}

#[test]
fn residual_and_kkt_matrix_are_the_derivatives_of_the_lagrangian_with_a_line_load() {
    for order in ["linear", "quadratic"] {
        let (case, loads) = rod_under_line_load(order);
        let model = case.model();
        let x0 = model.natural_state();
        let mut sys = System::new(&model, case.boundary, &x0, &loads, 0.0);
        sys.set_parameter(0.7);
        let mut x = x0;
        x.resize(sys.n, 0.0);
        for (i, v) in x.iter_mut().enumerate() {
            let noise = ((i * 7919 + 13) % 1009) as f64 / 1009.0 - 0.5;
            *v += if i < model.n_primal { 0.02 } else { 3.0 } * noise;
        }
        let mut r = vec![0.0; sys.n];
        sys.residual(&model, &x, &mut r);
        // L = E + V (the line load's potential) + Σ multiplier · constraint value
        let lagrangian = |y: &[f64]| {
            let mut ry = vec![0.0; sys.n];
            let e = sys.residual(&model, y, &mut ry);
            e.energy + e.potential + (model.n_primal..sys.n).map(|k| y[k] * ry[k]).sum::<f64>()
        };
        fd_check(lagrangian, &x, &r, 1e-6, "∇L with a line load");
        // the KKT matrix against central differences of the residual
        let mut values = sys.new_values();
        sys.evaluate(&model, &x, &mut r, &mut values);
        let m = sys.matrix(&values);
        let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
        for j in 0..model.n_primal {
            let differences = residual_derivative(&model, &sys, &x, j);
            let mut column = vec![0.0; sys.n];
            for p in cp[j]..cp[j + 1] {
                column[ri[p]] += m.val()[p];
            }
            for i in 0..sys.n {
                let fd = differences[i];
                assert!(
                    (fd - column[i]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "{order}: K[{i}][{j}] = {} vs finite difference {fd}",
                    column[i]
                );
            }
        }
        // ∂R/∂λ against a central difference in λ
        let mut d = vec![0.0; sys.n];
        sys.load_derivative(&model, &x, 0.7, &mut d);
        let (mut rp, mut rm) = (vec![0.0; sys.n], vec![0.0; sys.n]);
        sys.set_parameter(0.7 + 1e-6);
        sys.residual(&model, &x, &mut rp);
        sys.set_parameter(0.7 - 1e-6);
        sys.residual(&model, &x, &mut rm);
        for i in 0..sys.n {
            let fd = (rp[i] - rm[i]) / 2e-6;
            assert!(
                (fd - d[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "∂R/∂λ[{i}]: {} vs {fd}",
                d[i]
            );
        }
    }
}

#[test]
fn a_clamped_rod_under_a_small_line_load_bends_as_the_linear_beam_of_the_textbook() {
    // Euler–Bernoulli beam clamped at both ends under a uniform load q: each support carries
    // q L/2 and a moment q L²/12, the midspan deflects by q L⁴/(384 B) (the axial motion
    // left free, inextensibility adds nothing at first order). q L³/B = 1e-3: the large-
    // deformation terms are of relative order (w/L)² ~ 1e-11.
    let (case, loads) = rod_under_line_load("quadratic");
    let model = case.model();
    let x = model.natural_state();
    let (l, b, q) = (1.0, 1.0, 1e-3);
    let mut sim = Simulation::with_loads(model, case.boundary, loads, x, case.solver).unwrap();
    sim.advance_to(q).unwrap();
    assert_eq!(sim.load_parameter().symbol(), "q");
    let point = sim.load_point(1);
    let r = &point.reactions[0];
    for (end, reaction) in [("base", r.base), ("tip", r.tip)] {
        let f = reaction.force;
        assert!((f[0] + q * l / 2.0).abs() < 1e-12, "{end} force {f:?}");
        assert!(
            f[1].abs() < 1e-12 && f[2].abs() < 1e-12,
            "{end} force {f:?}"
        );
        let m = reaction.moment;
        let expected = q * l * l / 12.0;
        assert!(
            (m[1].abs() - expected).abs() < 1e-6 * expected,
            "{end} moment {m:?}"
        );
    }
    // the two fixed-end moments are opposite (the load's moment balances the end shears')
    assert!((r.base.moment[1] + r.tip.moment[1]).abs() < 1e-12);
    let shape = sim.snapshot();
    let mid = shape.rods[0]
        .nodes
        .iter()
        .find(|n| (n.s_over_l - 0.5).abs() < 1e-12)
        .expect("a node at midspan");
    let expected = q * l.powi(4) / (384.0 * b);
    assert!(
        (mid.position[0] - expected).abs() < 1e-4 * expected,
        "midspan deflection {} against q L⁴/384B = {expected}",
        mid.position[0]
    );
}
