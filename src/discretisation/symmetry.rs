//! The symmetric pair and the full assembly it stands for (docs/theory.md §7): a state of the
//! pair expanded to the state of every rod, and the Bloch blocks of its KKT matrix.

use super::constraints::Role;
use super::discrete_model::DiscreteModel;
use super::system::System;
use crate::model::quaternion::Quat;
use crate::model::symmetry::TurnZ;
use faer::c64;
use std::f64::consts::PI;

/// Expands the state `x` of a symmetric pair (in `pair_system`'s layout) to the state of
/// the full model in `full_system`'s layout: every rod is the image of one rod of the pair
/// turned about z; support and pin-joint multipliers are zero (they do not enter the
/// Hessian); a welded joint's multipliers, a moment in the right rod's frame, are those of the
/// pair's joint at the same arc length (where it holds all three components); a sliding
/// joint's contacts are at the arc lengths of the pair's joint at the same arc length, and
/// its force (which enters the Hessian) is that joint's turned with the right rod.
/// `out` has the length of the full system's unknowns.
pub fn expand_state(
    pair: &DiscreteModel,
    pair_system: &System,
    x: &[f64],
    full: &DiscreteModel,
    full_system: &System,
    out: &mut [f64],
) {
    let sym = pair
        .assembly
        .symmetry
        .expect("expand_state needs a symmetric pair");
    out.iter_mut().for_each(|v| *v = 0.0);
    for (k, rod) in full.rods.iter().enumerate() {
        let (src, angle) = sym.image(k);
        let from = &pair.rods[src];
        let turn = TurnZ::new(angle);
        for node in 0..rod.mesh.quaternion_nodes() {
            let q = pair.quaternion(x, src, node);
            let q = turn.rotate(&q);
            for c in 0..4 {
                out[rod.q_dof(node, c)] = q[c];
            }
            out[full_system.unit_row(k, node)] = x[pair_system.unit_row(src, node)];
        }
        for v in 0..=rod.mesh.elements() {
            let r = turn.apply([
                x[from.r_dof(v, 0)],
                x[from.r_dof(v, 1)],
                x[from.r_dof(v, 2)],
            ]);
            for c in 0..3 {
                out[rod.r_dof(v, c)] = r[c];
            }
        }
        for e in 0..rod.mesh.elements() {
            let row = pair_system.compat_row(src, e);
            let l = turn.apply([x[row], x[row + 1], x[row + 2]]);
            let full_row = full_system.compat_row(k, e);
            out[full_row..full_row + 3].copy_from_slice(&l);
        }
    }
    let tol = 1e-9 * pair.length();
    // a sliding joint of right rod R_a is the image, turned by 2πa/m, of the pair's joint at
    // the same arc length: the same contacts' arc lengths, its force turned
    for (k, slide) in full_system.slides.iter().enumerate() {
        let joint = &full.assembly.joints[slide.joint];
        let Some(source) = pair_slide(pair, joint.s) else {
            continue;
        };
        for side in 0..2 {
            out[full.slide_dof(k, side)] = x[pair.slide_dof(source, side)];
        }
        let (_, angle) = sym.image(joint.right);
        let from = pair_system.slide_row(source);
        let nu = TurnZ::new(angle).apply([x[from], x[from + 1], x[from + 2]]);
        let row = full_system.slide_row(k);
        out[row..row + 3].copy_from_slice(&nu);
    }
    for (i, rot) in full_system.rotations.iter().enumerate() {
        let s = full.assembly.joints[rot.joint].s;
        let source = pair_system.rotations.iter().enumerate().find(|(_, r)| {
            (pair.assembly.joints[r.joint].s - s).abs() <= tol && r.rows() == rot.rows()
        });
        if let (Some((k, _)), 3) = (source, rot.rows()) {
            // the natural relative rotations of the two may differ in sign (the quaternion
            // fields are continuous along each rod, not across images): so may the rows
            let same = rot
                .deviation(out)
                .dot(&pair_system.rotations[k].deviation(x));
            let sign = if same < 0.0 { -1.0 } else { 1.0 };
            let row = full_system.rotation_row(i);
            for (o, nu) in out[row..row + 3]
                .iter_mut()
                .zip(pair_system.rotation_multipliers(x, k))
            {
                *o = sign * nu;
            }
        }
    }
}

/// The sliding joint of the pair (index into its model's sliding joints) at arc length
/// `s` (m): every crossing of the whole assembly is the image of the pair's joint at its arc
/// length (the right rod `R_0` meets each image of `L_0` at arc lengths of its own).
fn pair_slide(pair: &DiscreteModel, s: f64) -> Option<usize> {
    let tol = 1e-9 * pair.length();
    pair.slides
        .iter()
        .position(|&j| (pair.assembly.joints[j].s - s).abs() <= tol)
}

/// The Bloch (Fourier) blocks of the KKT matrix of a symmetric assembly (docs/theory.md §7).
///
/// With every sector's unknowns in its own rotated frame, the full KKT matrix at a
/// symmetric state is block-circulant, and the discrete Fourier transform over the `m`
/// sectors splits it into one Hermitian block per wavenumber `p = 0 … m − 1`, each of the
/// size of the pair: the pair's own KKT matrix, except that a joint tying the pair to the
/// image of its left rod in sector `r` carries the phase `e^{2πipr/m}` on its coupling
/// entries (row of the joint's multiplier × the left rod's positions; for a welded or elastic
/// joint also its rows and the right rod's quaternion × the left rod's quaternion; for a
/// sliding joint its rows and the left contact's arc length × the left rod's unknowns of the
/// window) and the conjugate phase on their transposes. Blocks `p` and `m − p` are conjugate (same spectrum); `p = 0`
/// (the pair itself) and `p = m/2` are real. Every block is stored in the pair's pattern:
/// the complex ones with complex entries, factorised as `LDLᴴ`.
#[derive(Clone, Debug)]
pub struct BlochBlocks {
    /// Sectors `m`.
    pub m: usize,
    /// For each stored entry of the pair's KKT pattern: the sector its coupling reaches and
    /// the sign of its phase, for the joints that tie the pair to another sector.
    phase: Vec<Option<(f64, usize)>>,
}

impl BlochBlocks {
    /// The blocks of a symmetric pair's system (`None` for a model without the symmetry).
    pub fn new(pair: &DiscreteModel, system: &System) -> Option<BlochBlocks> {
        let sym = pair.assembly.symmetry?;
        let m = sym.m;
        let entry = |row: usize, col: usize| system.entry(row, col);
        let left = &pair.rods[1];
        let left_dofs = left.q_offset..left.r_offset + 3 * (left.mesh.elements() + 1);
        let mut phase = vec![None; system.nnz()];
        for (i, c) in system.linear.iter().enumerate() {
            let Role::Joint(j) = c.role else { continue };
            let turn = pair.assembly.joints[j].left_turn;
            let r = (turn * m as f64 / (2.0 * PI)).round().rem_euclid(m as f64) as usize;
            if r == 0 {
                continue;
            }
            let row = system.linear_row(i);
            for &(d, _) in c.terms.iter().filter(|(d, _)| left_dofs.contains(d)) {
                phase[entry(row, d)] = Some((1.0, r));
                phase[entry(d, row)] = Some((-1.0, r));
            }
        }
        // a welded or elastic joint couples the right rod's quaternion (and its rows) to
        // the image's: the same phases on those entries
        for (i, rot) in system.rotations.iter().enumerate() {
            let turn = pair.assembly.joints[rot.joint].left_turn;
            let r = (turn * m as f64 / (2.0 * PI)).round().rem_euclid(m as f64) as usize;
            if r == 0 {
                continue;
            }
            let first = system.rotation_row(i);
            let rows = (first..first + rot.rows()).chain(rot.dofs[..4].iter().copied());
            for row in rows {
                for &d in &rot.dofs[4..] {
                    phase[entry(row, d)] = Some((1.0, r));
                    phase[entry(d, row)] = Some((-1.0, r));
                }
            }
        }
        // a sliding joint's multipliers and both contacts' arc lengths are unknowns of the
        // right rod's sector: its rows and the left contact's arc length couple to the
        // image's positions and quaternions in the window (`ν · ∂r_L`, `ν · ∂²r_L/∂s∂q`);
        // the terms `ν · ∂²r_L/∂q∂q` are of the image alone and take no phase
        for (k, slide) in system.slides.iter().enumerate() {
            let r = (slide.turn * m as f64 / (2.0 * PI))
                .round()
                .rem_euclid(m as f64) as usize;
            if r == 0 {
                continue;
            }
            for (row, d) in slide.image_entries(pair, system.slide_row(k)) {
                phase[entry(row, d)] = Some((1.0, r));
                phase[entry(d, row)] = Some((-1.0, r));
            }
        }
        Some(BlochBlocks { m, phase })
    }

    /// The wavenumbers whose blocks are distinct: `0 ..= m/2` (`p` and `m − p` conjugate).
    pub fn wavenumbers(&self) -> std::ops::RangeInclusive<usize> {
        0..=self.m / 2
    }

    /// Whether block `p` is real (`p = 0`, or `p = m/2`).
    pub fn is_real(&self, p: usize) -> bool {
        p == 0 || 2 * p == self.m
    }

    /// How many wavenumbers block `p` stands for: 1 if real, 2 (`p` and `m − p`) if not.
    pub fn multiplicity(&self, p: usize) -> usize {
        if self.is_real(p) {
            1
        } else {
            2
        }
    }

    /// The phase angle `2π p r / m` (rad) of a coupling to sector `r`.
    fn angle(&self, p: usize, r: usize) -> f64 {
        phase_angle(self.m, p, r)
    }

    /// The real block `p` (`p = 0` or `m/2`) in the pair's pattern, from the pair's KKT
    /// values `pair` (`e^{iπr} = ±1`).
    pub fn real_block(&self, p: usize, pair: &[f64], out: &mut [f64]) {
        debug_assert!(self.is_real(p));
        for (k, (v, phase)) in pair.iter().zip(&self.phase).enumerate() {
            out[k] = match phase {
                Some((_, r)) if (p * r) % self.m != 0 => -v,
                _ => *v,
            };
        }
    }

    /// The complex Hermitian block `p` (`0 < p < m/2`) itself, in the pair's pattern, from
    /// the pair's KKT values `pair`: each phased coupling times `e^{±2πipr/m}`.
    pub fn hermitian_block(&self, p: usize, pair: &[f64], out: &mut [c64]) {
        for ((o, &v), phase) in out.iter_mut().zip(pair).zip(&self.phase) {
            *o = match *phase {
                None => c64::new(v, 0.0),
                Some((sign, r)) => {
                    let (sin, cos) = (sign * self.angle(p, r)).sin_cos();
                    c64::new(v * cos, v * sin)
                }
            };
        }
    }
}

/// The phase angle `2π p r / m` (rad) of wavenumber `p` in sector `r` of `m`.
fn phase_angle(m: usize, p: usize, r: usize) -> f64 {
    2.0 * PI * (p * r % m) as f64 / m as f64
}

/// The real mode of the full assembly `full` (its primal unknowns) that an eigenvector `v`
/// of Bloch block `p` of the symmetric pair `pair` stands for: over the pair's primal
/// unknowns for a real block, real then imaginary parts for a complex one. In sector `r`
/// (the rods turned by `2πr/m` from the pair's) the mode is `Re(v e^{2πipr/m})` in the
/// sector's rotated frame — the Bloch form whose phases the blocks carry —, turned into the
/// global frame; the result has unit (Euclidean) norm, as the engine's critical modes.
pub fn assembly_mode(pair: &DiscreteModel, p: usize, v: &[f64], full: &DiscreteModel) -> Vec<f64> {
    let sym = pair
        .assembly
        .symmetry
        .expect("an assembly mode needs a symmetric pair");
    let (m, np) = (sym.m, pair.n_primal);
    let (re, im) = if v.len() >= 2 * np {
        (&v[..np], &v[np..2 * np])
    } else {
        (&v[..np], &[][..])
    };
    let at = |i: usize, c: f64, s: f64| {
        let imag = im.get(i).copied().unwrap_or(0.0);
        re[i] * c - imag * s
    };
    let mut out = vec![0.0; full.n_primal];
    for (k, rod) in full.rods.iter().enumerate() {
        let (src, angle) = sym.image(k);
        let from = &pair.rods[src];
        let r = (angle * m as f64 / (2.0 * PI)).round().rem_euclid(m as f64) as usize;
        let (s, c) = phase_angle(m, p, r).sin_cos();
        let turn = TurnZ::new(angle);
        for node in 0..rod.mesh.quaternion_nodes() {
            let [a, b, cc, d] = [0, 1, 2, 3].map(|k| at(from.q_dof(node, k), c, s));
            let dq = turn.rotate(&Quat::new(a, b, cc, d));
            for k in 0..4 {
                out[rod.q_dof(node, k)] = dq[k];
            }
        }
        for vtx in 0..=rod.mesh.elements() {
            let dr = turn.apply([0, 1, 2].map(|k| at(from.r_dof(vtx, k), c, s)));
            for k in 0..3 {
                out[rod.r_dof(vtx, k)] = dr[k];
            }
        }
    }
    // the contacts' arc lengths of a sliding joint are of its right rod's sector
    for (k, &joint) in full.slides.iter().enumerate() {
        let joint = &full.assembly.joints[joint];
        let Some(source) = pair_slide(pair, joint.s) else {
            continue;
        };
        let (_, angle) = sym.image(joint.right);
        let r = (angle * m as f64 / (2.0 * PI)).round().rem_euclid(m as f64) as usize;
        let (s, c) = phase_angle(m, p, r).sin_cos();
        for side in 0..2 {
            out[full.slide_dof(k, side)] = at(pair.slide_dof(source, side), c, s);
        }
    }
    let norm = out.iter().map(|u| u * u).sum::<f64>().sqrt();
    if norm > 0.0 {
        out.iter_mut().for_each(|u| *u /= norm);
    }
    out
}
