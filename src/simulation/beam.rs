//! The infinite tube as a beam (docs/theory.md §8): its effective stiffnesses per unit
//! length at a state of its cell, exact from the cell's constrained tangent.
//!
//! The cell's macroscopic loads `μ = (ε, φ, q)` — axial strain, twist per cell (rad) and
//! radial pressure (N/m) — enter its Lagrangian `L(X, μ)` (`X` the unknowns with the
//! multipliers). At an equilibrium `R = ∇_X L = 0` the reduced energy `Π(μ) = L(X(μ), μ)`
//! has `∂Π/∂μ_a = ∂L/∂μ_a` (the conjugate loads) and the Hessian
//! `S_ab = ∂²L/∂μ_a∂μ_b − (∂R/∂μ_a)ᵀ K⁻¹ (∂R/∂μ_b)`, `K` the KKT matrix: one factorisation,
//! three solves. The beam's stiffnesses are `S` in the tube's measures. The bending
//! stiffness comes from the cell's Bloch block of the translation across the axis
//! ([`bending_stiffness`]).

use crate::discretisation::cell::axis_weights;
use crate::discretisation::cell_blocks::CellBlocks;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::discretisation::pressure;
use crate::discretisation::support::arc_chord;
use crate::discretisation::support::Moving;
use crate::discretisation::system::System;
use crate::model::assembly::Assembly;
use crate::model::loading::{AxialHeld, Component, Control, Held, Loads};
use crate::model::quaternion::Quat;
use crate::model::symmetry::TurnZ;
use crate::solver::linear::{least_squares_multipliers, LinearError, SparseLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{c64, linalg::solvers::Solve, Mat};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// The tube's effective beam stiffnesses per unit length at a state of its cell. Strains
/// are increments on the current tube: `δh/h` axially, the twist per current length
/// `τ = φ/h` (rad/m); the force `F` is the whole tube's (tension positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamStiffness {
    /// The tube's axial strain `ε` (compression positive) and twist per length `τ` (rad/m).
    pub eps: f64,
    pub twist: f64,
    /// The tube's axial force `F` (N, tension positive), torque `T` (N m) and mean radius
    /// (m), from the conjugate loads `∂L/∂μ`.
    pub force: f64,
    pub torque: f64,
    pub radius: f64,
    /// The tube's rise per turn of its helices (m): `2π h/ψ`, `h` the cell's rise and `ψ`
    /// its screw's natural turn.
    pub turn_rise: f64,
    /// `EA = dF/d(δh/h)` (N), at held twist and pressure.
    pub axial: f64,
    /// `GJ = dT/dτ` (N m²), at held length and pressure.
    pub torsional: f64,
    /// `dT/d(δh/h) = dF/dτ` (N m): the extension–twist coupling.
    pub twist_coupling: f64,
    /// `−dq/dā` (N/m²) at held axial force and twist, `ā` the mean radius: the radial
    /// stiffness (at held length the radius of the pinned lattice is held to first order).
    pub radial: f64,
    /// `dā/d(δh/h)` (m) at held pressure and twist: the extension–radius coupling.
    pub radius_coupling: f64,
}

/// Why the stiffnesses of a state cannot be computed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum BeamError {
    #[error("the beam stiffnesses are those of a cell of an infinite tube (model = \"cell\")")]
    NotACell,
    #[error("the multipliers of the cell's state cannot be fitted (dependent constraints)")]
    Multipliers,
    #[error(transparent)]
    Linear(#[from] LinearError),
    #[error("the bending cell needs a tube of n = 2m helices with m ≥ 2")]
    NotABendingTube,
    #[error("the bending stiffness by curvature is computed on an untwisted tube (twist 0)")]
    Twisted,
    #[error("the bending stiffness by curvature is computed on the bending cell, which does not carry sliding crossings")]
    Sliding,
    #[error("the beam stiffnesses are those of the straight tube's cell, not of a bending cell")]
    Bending,
    #[error("the cell's reduced energy is flat along its {what}: no stiffness to invert")]
    Flat { what: &'static str },
}

/// The values `(ε, φ, q)` of the loads of `system` at its load parameter.
fn load_values(system: &System) -> (f64, f64, f64) {
    let (loads, lambda) = (system.loads(), system.parameter());
    let held = loads.held();
    let stepped = loads.stepped();
    let eps = match (stepped, held.axial) {
        (Some(Component::Axial), _) => lambda,
        (_, AxialHeld::Ratio(e)) => e,
        (_, AxialHeld::Load(_)) => 0.0,
    };
    let phi = if stepped == Some(Component::Twist) {
        lambda
    } else {
        held.twist
    };
    let q = if stepped == Some(Component::Pressure) {
        lambda
    } else {
        held.pressure
    };
    (eps, phi, q)
}

/// `∂²L/∂φ²` at `x`: the second rate of the rows that turn with the twist about the axis,
/// `ν (∂²a/∂φ²)·x` with `∂²(R_φ d)/∂φ² = −R_φ d` (`d` in the x–y plane) and
/// `∂²q_φ/∂φ² = −q_φ/4`.
fn twist_curvature(system: &System, x: &[f64]) -> f64 {
    system
        .linear
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let (count, factor) = match c.moving.as_ref()? {
                Moving::Position { .. } => (3, 1.0),
                Moving::Orientation { .. } => (4, 0.25),
                // a bent cell's axis turns with its tilt only
                Moving::Axis { .. } => return None,
            };
            let moving: f64 = c.terms[..count].iter().map(|&(d, a)| a * x[d]).sum();
            Some(-factor * x[system.linear_row(i)] * moving)
        })
        .sum()
}

/// The beam stiffnesses of the cell's state `x` (primal unknowns at least) under
/// `system`'s loads.
pub fn beam_stiffness(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
) -> Result<BeamStiffness, BeamError> {
    let cell = model.assembly.cell.as_ref().ok_or(BeamError::NotACell)?;
    if (cell.bending && model.rods.len() > 1) || system.loads().tilts() {
        return Err(BeamError::Bending);
    }
    let (eps, phi, q) = load_values(system);
    let held = Held {
        axial: AxialHeld::Ratio(eps),
        twist: phi,
        tilt: 0.0,
        pressure: q,
    };
    let primal = &x[..model.n_primal];
    let systems: Vec<(System, f64)> = [
        (Component::Axial, eps),
        (Component::Twist, phi),
        (Component::Pressure, q),
    ]
    .into_iter()
    .map(|(c, value)| {
        let loads = Loads::compose(c, Control::Displacement, held);
        (System::new(model, system.bc, primal, &loads, value), value)
    })
    .collect();
    // the same rows in the three systems: the multipliers fitted once, K once
    let first = &systems[0].0;
    let mut full = primal.to_vec();
    full.resize(first.n, 0.0);
    let (mut residual, mut kkt) = (vec![0.0; first.n], first.new_values());
    first.evaluate(model, &full, &mut residual, &mut kkt);
    let nu = least_squares_multipliers(first.pattern(), &kkt, &residual, model.n_primal)
        .ok_or(BeamError::Multipliers)?;
    full[model.n_primal..].copy_from_slice(&nu);
    first.evaluate(model, &full, &mut residual, &mut kkt);
    let mut lu = SparseLu::default();
    lu.factorize(first.matrix(&kkt))?;
    let rates: Vec<Vec<f64>> = systems
        .iter()
        .map(|(s, value)| {
            let mut d = vec![0.0; s.n];
            s.load_derivative(model, &full, *value, &mut d);
            d
        })
        .collect();
    let solved: Vec<Vec<f64>> = rates
        .iter()
        .map(|d| {
            let mut y = d.clone();
            lu.solve(&mut y);
            y
        })
        .collect();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
    let mut s = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            s[a][b] = -dot(&rates[a], &solved[b]);
        }
    }
    s[1][1] += twist_curvature(&systems[1].0, &full);
    // conjugate loads: ∂L/∂ε and ∂L/∂φ on the multiplier rows
    let conjugate = |d: &[f64]| dot(&d[model.n_primal..], &full[model.n_primal..]);
    let (q_eps, q_phi) = (conjugate(&rates[0]), conjugate(&rates[1]));
    let m = cell.m as f64;
    let h0 = model.height0();
    let h = h0 * (1.0 - eps);
    let total = model.length() * model.rods.len() as f64;
    let flat = |v: f64, what| {
        if v.abs() > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(BeamError::Flat { what })
        }
    };
    let s_qq = s[2][2];
    let s_ee = flat(s[0][0], "length")?;
    Ok(BeamStiffness {
        eps,
        twist: phi / h,
        force: -m * q_eps / h0,
        torque: m * q_phi,
        radius: pressure::mean_radius(model, &full),
        turn_rise: 2.0 * std::f64::consts::PI * h / cell.turns[0].abs(),
        axial: m * h * s_ee / (h0 * h0),
        torsional: m * h * s[1][1],
        twist_coupling: -m * h * s[0][1] / h0,
        radial: -total / flat(s_qq - s[2][0] * s[0][2] / s_ee, "radius")?,
        radius_coupling: -h * s[2][0] / (h0 * total),
    })
}

/// The energy `E(q)` (J) per cell of the tube's bending wave of axial wavenumber `q` (1/m)
/// at the cell's state `x` under `system`: the minimum of the quadratic form `uᴴHu` of the
/// Bloch block `H(p, k)` of the translation across the axis (`p = 1`, `k = ψ + q h`, `ψ`
/// the translation's phase, `h` the cell's rise) under the block's constraints and the
/// amplitude `A(u) = 1`, `A` the mean over the cell's vertices (weighted by arc length) of
/// the transverse displacement `(u_x − i u_y)/2` times `e^{−iqz}` (`z` the vertex's height):
/// the axis displaced by the wave `Re[(1, i) e^{iqz}]` (one KKT solve, the amplitude's
/// multiplier bordering the block). A bent beam's energy per length `(EI q⁴ + F q²)/2` for
/// this unit wave gives `E(q) = (2h/m)(EI q⁴ + F q²) + O(q⁶)` (`EI` and `F` the whole
/// tube's, tension positive; the real wave's energy per cell is `E/4`). `None` for a model
/// that is not a cell or a singular block.
pub fn bending_energy(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    wavenumber: f64,
) -> Option<f64> {
    let blocks = CellBlocks::new(model, system)?;
    let cell = blocks.cell();
    let h = cell_rise(model, system);
    let (p, k) = (
        cell.translation_wavenumber(),
        cell.translation_phase() + wavenumber * h,
    );
    let n = system.n;
    let (mut residual, mut kkt) = (vec![0.0; n], system.new_values());
    system.evaluate(model, x, &mut residual, &mut kkt);
    let mut values = vec![c64::new(0.0, 0.0); kkt.len()];
    blocks.hermitian_block(p, k, &kkt, &mut values);
    let pattern = system.pattern();
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let mut triplets = Vec::with_capacity(values.len() + 6 * n / 5 + n);
    let mut held = vec![false; n];
    for col in 0..n {
        for e in cp[col]..cp[col + 1] {
            if values[e] != c64::new(0.0, 0.0) {
                triplets.push(Triplet::new(ri[e], col, values[e]));
                held[ri[e]] = true;
            }
        }
    }
    // the gauge rows dropped from the block: their multipliers are zero
    for (i, _) in held
        .iter()
        .enumerate()
        .filter(|(i, h)| !**h && *i >= model.n_primal)
    {
        triplets.push(Triplet::new(i, i, c64::new(1.0, 0.0)));
    }
    // the amplitude row A(u) = Σ conj(a_i) u_i and its transpose
    let amplitude = axis_amplitude(model, x, wavenumber);
    for &(i, a) in &amplitude {
        triplets.push(Triplet::new(i, n, a));
        triplets.push(Triplet::new(n, i, a.conj()));
    }
    let matrix = SparseColMat::<usize, c64>::try_new_from_triplets(n + 1, n + 1, &triplets).ok()?;
    let lu = matrix.sp_lu().ok()?;
    let mut rhs = Mat::<c64>::zeros(n + 1, 1);
    rhs[(n, 0)] = c64::new(1.0, 0.0);
    let u = lu.solve(&rhs);
    // uᴴHu on the primal unknowns (the constraints hold, Cu = 0)
    let mut energy = c64::new(0.0, 0.0);
    for col in 0..model.n_primal {
        for e in cp[col]..cp[col + 1] {
            let row = ri[e];
            if row < model.n_primal {
                energy += u[(row, 0)].conj() * values[e] * u[(col, 0)];
            }
        }
    }
    energy.re.is_finite().then_some(energy.re)
}

/// The rise `h` (m) of the cell at the state of `system`.
fn cell_rise(model: &DiscreteModel, system: &System) -> f64 {
    model.height0() * (1.0 - load_values(system).0)
}

/// The coefficients `a_i` of the axis amplitude `A(u) = Σ conj(a_i) u_i` of a wave of
/// wavenumber `q` (1/m): the arc-length-weighted mean over the cell's vertices (each rod's
/// far vertex is another cell's near one, [`axis_weights`]) of `e^{−iqz}(u_x − i u_y)/2`.
fn axis_amplitude(model: &DiscreteModel, x: &[f64], wavenumber: f64) -> Vec<(usize, c64)> {
    let mut out = Vec::new();
    for (id, rod) in model.rods.iter().enumerate() {
        for (v, weight) in axis_weights(model, id) {
            let (sin, cos) = (wavenumber * x[rod.r_dof(v, 2)]).sin_cos();
            let phase = c64::new(cos, sin) * (0.5 * weight);
            out.push((rod.r_dof(v, 0), phase));
            out.push((rod.r_dof(v, 1), phase * c64::new(0.0, 1.0)))
        }
    }
    out
}

/// The tube's bending stiffness `EI` (N m²) and axial force `F` (N, tension positive) at
/// the cell's state `x` under `system`, from the bending wave's energy [`bending_energy`]:
/// the even part of `g(q) = m E(q)/(2h q²) = F + EI q² + O(q⁴)` (a torque adds odd powers
/// of `q`, Greenhill's `−T q`) at the wavenumbers `q_j = ±j δ/h`, `j = 1 …` [`FIT_POINTS`]
/// (`δ` = `step`, rad per cell), interpolated by a polynomial in `q²` read at 0: `F` its
/// value, `EI` its slope (error `O(δ^{2·FIT_POINTS})`).
pub fn bending_stiffness(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
    step: f64,
) -> Option<(f64, f64)> {
    let cell = model.assembly.cell.as_ref()?;
    let m = cell.m as f64;
    let h = cell_rise(model, system);
    let mut xs = [0.0; FIT_POINTS];
    let mut d = [0.0; FIT_POINTS];
    for j in 0..FIT_POINTS {
        let q = (j + 1) as f64 * step / h;
        let even = bending_energy(model, system, x, q)? + bending_energy(model, system, x, -q)?;
        xs[j] = q * q;
        d[j] = m * even / (4.0 * h * q * q);
    }
    // Newton's divided differences of g in X = q²
    for level in 1..FIT_POINTS {
        for j in (level..FIT_POINTS).rev() {
            d[j] = (d[j] - d[j - 1]) / (xs[j] - xs[j - level]);
        }
    }
    // the Newton form's value and slope at X = 0 by Horner's rule
    let (mut value, mut slope) = (0.0, 0.0);
    for j in (0..FIT_POINTS).rev() {
        slope = slope * (0.0 - xs[j]) + value;
        value = value * (0.0 - xs[j]) + d[j];
    }
    (slope.is_finite() && value.is_finite()).then_some((slope, value))
}

/// The wavenumbers of the fit of [`bending_stiffness`]: `q h = ±δ … ±5δ`.
pub const FIT_POINTS: usize = 5;

/// The phase step `δ` (rad per cell) of the fit of the bending wave's energy
/// ([`bending_stiffness`]): its truncation error at `q h ≤ 5δ = 0.1` is below `1e-9`
/// relative, its rounding below `1e-9` (cell-n8).
pub const BENDING_STEP: f64 = 0.02;
/// The tube's bending stiffness by imposed curvature at a state of its cell (the cell of
/// one right and one left rod, [`Assembly::tube_cell`]): the state carried onto the bending
/// cell of the same tube ([`Assembly::bending_cell`]: every rod over one axial period, two
/// cells), whose reduced energy `Π(θ)` at the tilt `θ` per bending cell (the tube's
/// curvature `κ = θ/H`, `H = 2h` the bending cell's rise) and the cell's held loads gives
/// the bending moment `M = ∂Π/∂θ` and `EI = dM/dκ = H ∂²Π/∂θ²` at `θ = 0`, exact from the
/// constrained tangent (one factorisation, one solve):
/// `∂²Π/∂θ² = ∂²L/∂θ² − (∂R/∂θ)ᵀ K⁻¹ (∂R/∂θ)`. The tube's axis, the arc-length mean of
/// its rods (as the bending wave's amplitude, [`bending_energy`]), keeps its length `H`
/// (the axial strain held). An untwisted state only
/// ([`BeamError::Twisted`] otherwise: the carrying of a twisted state is not checked), and
/// pinned, welded or elastic crossings ([`BeamError::Sliding`] with sliding ones).
pub fn bending_by_curvature(
    model: &DiscreteModel,
    system: &System,
    x: &[f64],
) -> Result<CurvatureBending, BeamError> {
    let cell = model.assembly.cell.as_ref().ok_or(BeamError::NotACell)?;
    if cell.bending || model.rods.len() != 2 {
        return Err(BeamError::NotACell);
    }
    let m = cell.m;
    let (eps, phi, q) = load_values(system);
    if phi != 0.0 {
        return Err(BeamError::Twisted);
    }
    if !model.slides.is_empty() {
        return Err(BeamError::Sliding);
    }
    let helix = model.assembly.rods[0];
    let assembly = Assembly::bending_cell(2 * m, helix.radius, helix.pitch)
        .map_err(|_| BeamError::NotABendingTube)?;
    let bent = DiscreteModel::with_hypotheses(
        assembly,
        model.stiffness,
        2 * model.requested_elements,
        model.order,
        model.elasticity,
        model.reference,
    );
    let primal = bending_state(model, &bent, x, phi);
    let held = Held {
        axial: AxialHeld::Ratio(eps),
        twist: 2.0 * phi,
        tilt: 0.0,
        pressure: q,
    };
    curvature_stiffness(&bent, system.bc, &primal, held)
}

/// `EI = H ∂²Π/∂θ²` (N m²) of a bending cell `bent` (its tilt at zero, the other loads at
/// `held`) at the state `x`: its primal unknowns, and optionally after them a guess of its
/// multipliers in the rows of the tilted system, which the fitted ones correct (a straight
/// rod's axial force is a multiplier no primal state fixes). Exact from the constrained
/// tangent, `∂²Π/∂θ² = ∂²L/∂θ² − (∂R/∂θ)ᵀ K⁻¹ (∂R/∂θ)` ([`bending_by_curvature`]).
pub fn curvature_stiffness(
    bent: &DiscreteModel,
    bc: crate::model::boundary::BoundaryConditions,
    x: &[f64],
    held: Held,
) -> Result<CurvatureBending, BeamError> {
    let cell = bent.assembly.cell.as_ref().ok_or(BeamError::NotACell)?;
    if !cell.bending {
        return Err(BeamError::NotACell);
    }
    if held.twist != 0.0 {
        return Err(BeamError::Twisted);
    }
    let held = Held { tilt: 0.0, ..held };
    let eps = match held.axial {
        AxialHeld::Ratio(e) => e,
        AxialHeld::Load(_) => 0.0,
    };
    let loads = Loads::compose(Component::Tilt, Control::Displacement, held);
    let sys = System::new(bent, bc, &x[..bent.n_primal], &loads, 0.0);
    let mut full = x.to_vec();
    full.resize(sys.n, 0.0);
    let (mut residual, mut kkt) = (vec![0.0; sys.n], sys.new_values());
    sys.evaluate(bent, &full, &mut residual, &mut kkt);
    let nu = least_squares_multipliers(sys.pattern(), &kkt, &residual, bent.n_primal)
        .ok_or(BeamError::Multipliers)?;
    for (value, correction) in full[bent.n_primal..].iter_mut().zip(&nu) {
        *value += correction;
    }
    sys.evaluate(bent, &full, &mut residual, &mut kkt);
    let mut lu = SparseLu::default();
    lu.factorize(sys.matrix(&kkt))?;
    let mut rate = vec![0.0; sys.n];
    sys.load_derivative(bent, &full, 0.0, &mut rate);
    let mut solved = rate.clone();
    lu.solve(&mut solved);
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
    let rise = bent.height0() * (1.0 - eps);
    let s = tilt_curvature(&sys, &full, 0.0, rise) - dot(&rate, &solved);
    Ok(CurvatureBending {
        stiffness: rise * s,
        moment: dot(&rate[bent.n_primal..], &full[bent.n_primal..]),
        residual: residual.iter().fold(0.0, |a: f64, v| a.max(v.abs())),
    })
}

/// The tube's bending by imposed curvature at a state ([`bending_by_curvature`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvatureBending {
    /// `EI = dM/dκ` (N m²) at `κ = 0`.
    pub stiffness: f64,
    /// The bending moment `M = ∂Π/∂θ` (N m) of the straight state: zero but for rounding.
    pub moment: f64,
    /// The largest residual of the carried state in the bending cell's equations (its
    /// equilibrium there: the Newton tolerance of the cell's state).
    pub residual: f64,
}

/// `∂²L/∂θ²` at `x`, `θ` the tilt of a cell's far ends at `theta`: on every moving row
/// `ν ∂²g/∂θ²`. A position row `g = a·(r − t) + …` with `a = R_s d` turning about x
/// (`∂a/∂θ = e_x × a`, `∂²a/∂θ² = (e_x·a) e_x − a`) and the far section's centre `t(θ)`
/// ([`crate::discretisation::support::SupportPose::of_cell`], `h` the rise of `system`'s cell): `a''·(r − t) − 2 a'·t' − a·t''`; an orientation row
/// `w·Im(conj(q_s ∘ q_ref) ∘ q)`: `q_s'' = −q_s/4`.
fn tilt_curvature(system: &System, x: &[f64], theta: f64, h: f64) -> f64 {
    let [f, g, df, dg, ddf, ddg] = arc_chord(theta);
    let t = Vector3::new(0.0, -h * f, h * g);
    let dt = Vector3::new(0.0, -h * df, h * dg);
    let ddt = Vector3::new(0.0, -h * ddf, h * ddg);
    let ex = Vector3::x();
    system
        .linear
        .iter()
        .enumerate()
        .filter_map(|(i, c)| {
            let nu = x[system.linear_row(i)];
            let g2 = match c.moving.as_ref()? {
                Moving::Position { .. } => {
                    let a = Vector3::new(c.terms[0].1, c.terms[1].1, c.terms[2].1);
                    let r = Vector3::new(x[c.terms[0].0], x[c.terms[1].0], x[c.terms[2].0]);
                    let da = ex.cross(&a);
                    let dda = ex * ex.dot(&a) - a;
                    dda.dot(&(r - t)) - 2.0 * da.dot(&dt) - a.dot(&ddt)
                }
                Moving::Orientation { .. } => {
                    let moving: f64 = c.terms[..4].iter().map(|&(d, a)| a * x[d]).sum();
                    -0.25 * moving
                }
                Moving::Axis { sections, .. } => {
                    // per vertex n = R_fθ e_y and t_f = f h (0, −F(fθ), G(fθ)):
                    // n' = f e_x × n, n'' = −f² n, t_f' = f² h (0, −F', G'), t_f'' = f³ h (…'')
                    sections
                        .iter()
                        .enumerate()
                        .map(|(k, &(f, w))| {
                            let (s, co) = (f * theta).sin_cos();
                            let a = Vector3::new(0.0, co, s);
                            let [u, v, du, dv, ddu, ddv] = arc_chord(f * theta);
                            let ts = Vector3::new(0.0, -u, v) * (f * h);
                            let dts = Vector3::new(0.0, -du, dv) * (f * f * h);
                            let ddts = Vector3::new(0.0, -ddu, ddv) * (f * f * f * h);
                            let da = ex.cross(&a) * f;
                            let dda = -a * (f * f);
                            let r = Vector3::new(
                                x[c.terms[3 * k].0],
                                x[c.terms[3 * k + 1].0],
                                x[c.terms[3 * k + 2].0],
                            );
                            w * (dda.dot(&(r - ts)) - 2.0 * da.dot(&dts) - a.dot(&ddts))
                        })
                        .sum()
                }
            };
            Some(nu * g2)
        })
        .sum()
}

/// The primal state of the bending cell `bent` carried from the state `x` of the tube's
/// cell `model` (mesh of `bent`'s rods: the cell's twice): right rod `R_j`'s segment `l`
/// (`l = 0, 1`) is the cell's right rod turned about the axis by `2πj/m + l (π/m + φ)` and
/// raised by `l h`, left rod `L_i`'s the cell's left rod turned by
/// `−2πi/m − l (π/m − φ)` (the screw twisted by `φ` per cell; `h` the cell's rise in `x`),
/// each quaternion `q_z ∘ q` with the sign that keeps the field continuous.
fn bending_state(model: &DiscreteModel, bent: &DiscreteModel, x: &[f64], phi: f64) -> Vec<f64> {
    let m = bent.assembly.cell.as_ref().map_or(1, |c| c.m);
    let mf = m as f64;
    let mut out = vec![0.0; bent.n_primal];
    let rise = {
        let rod = &model.rods[0];
        model.vertex(x, 0, rod.mesh.elements())[2] - model.vertex(x, 0, 0)[2]
    };
    for (id, rod) in bent.rods.iter().enumerate() {
        let (source, k) = if id < m { (0, id) } else { (1, id - m) };
        let src = &model.rods[source];
        let (elements, nodes) = (src.mesh.elements(), src.mesh.quaternion_nodes() - 1);
        let mut last: Option<Quat> = None;
        for l in 0..2 {
            let lf = l as f64;
            let angle = if source == 0 {
                2.0 * PI * k as f64 / mf + lf * (PI / mf + phi)
            } else {
                -2.0 * PI * k as f64 / mf - lf * (PI / mf - phi)
            };
            let turn = TurnZ::new(angle);
            for v in 0..=elements {
                let r = model.vertex(x, source, v);
                let p = turn.apply([r[0], r[1], r[2]]);
                for (c, value) in p.iter().enumerate() {
                    out[rod.r_dof(l * elements + v, c)] = *value;
                }
                out[rod.r_dof(l * elements + v, 2)] += lf * rise;
            }
            let mut segment: Vec<Quat> = (0..=nodes)
                .map(|node| turn.rotate(&model.quaternion(x, source, node)))
                .collect();
            if last.is_some_and(|q| q.dot(&segment[0]) < 0.0) {
                segment.iter_mut().for_each(|q| *q = -*q);
            }
            for (node, q) in segment.iter().enumerate() {
                for c in 0..4 {
                    out[rod.q_dof(l * nodes + node, c)] = q[c];
                }
            }
            last = segment.last().copied();
        }
    }
    out
}

/// The beam of a cell's state at one output step.
#[derive(Clone, Debug, PartialEq)]
pub struct StepBeam {
    pub step: usize,
    pub stiffness: BeamStiffness,
    /// `EI` (N m²) from the bending wave's energy, where its fits agree ([`bending_of`]).
    pub bending: Option<f64>,
    /// `EI` (N m²) by imposed curvature ([`bending_by_curvature`]).
    pub bending_curvature: Option<f64>,
    /// Why there is no `EI` by imposed curvature, where there is none.
    pub bending_curvature_refused: Option<String>,
}

/// `EI` (N m²) of the cell's state from [`bending_stiffness`]: the fit at `δ/2` once the
/// fits at `δ` and `δ/2` agree to [`BENDING_TOLERANCE`], `δ` halved from [`BENDING_STEP`] (the
/// fit holds only inside the radius of convergence of `g(q)`, which another mode of the
/// block near zero energy bounds), at most [`BENDING_HALVINGS`] times; `None` if they never
/// agree.
pub fn bending_of(model: &DiscreteModel, system: &System, x: &[f64]) -> Option<f64> {
    let mut step = BENDING_STEP;
    let mut coarse = bending_stiffness(model, system, x, step)?.0;
    for _ in 0..BENDING_HALVINGS {
        step *= 0.5;
        let fine = bending_stiffness(model, system, x, step)?.0;
        if (fine - coarse).abs() <= BENDING_TOLERANCE * fine.abs() {
            return Some(fine);
        }
        coarse = fine;
    }
    None
}

/// The relative agreement of the fits of `EI` at `δ` and `δ/2` that [`bending_of`] accepts.
pub const BENDING_TOLERANCE: f64 = 1e-6;

/// The halvings of the phase step that [`bending_of`] tries.
pub const BENDING_HALVINGS: usize = 4;

/// The length (in turns of the helices) at which a column of the tube with effective
/// length factor `factor` (Euler's: 1 pinned–pinned and clamped–sliding, 0.5 clamped–clamped,
/// 2 clamped–free) buckles at this state: `L = (π/K) √(EI/P)`, `P = −F` the compression
/// (`None` unless compressed and `EI` known).
pub fn column_turns(beam: &StepBeam, factor: f64) -> Option<f64> {
    let (ei, p) = (beam.bending?, -beam.stiffness.force);
    (p > 0.0 && ei > 0.0 && factor > 0.0)
        .then(|| std::f64::consts::PI / factor * (ei / p).sqrt() / beam.stiffness.turn_rise)
}
