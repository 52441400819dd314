//! The tip support, axis by axis: what each of its translations and rotations does as a
//! function of the load parameter, and the rotation of a support that turns.

use super::components::AxialHeld;
use crate::model::quaternion::{self, Quat};

/// An axis of the tip support (docs/theory.md §3): its three translations and its three rotations
/// about axes through the tip's centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SupportAxis {
    X,
    Y,
    /// Along the tube's axis: the axial load.
    Z,
    /// Tilt about x (rad).
    RotX,
    /// Tilt about y (rad).
    RotY,
    /// Twist about the tube's axis (rad).
    RotZ,
}

impl SupportAxis {
    /// Every axis, in the order of [`TipSupport`]'s table.
    pub const ALL: [SupportAxis; 6] = [
        SupportAxis::X,
        SupportAxis::Y,
        SupportAxis::Z,
        SupportAxis::RotX,
        SupportAxis::RotY,
        SupportAxis::RotZ,
    ];

    fn index(self) -> usize {
        self as usize
    }
}

/// A value affine in the load parameter `λ`: `at_zero + per_unit λ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ramp {
    pub at_zero: f64,
    pub per_unit: f64,
}

impl Ramp {
    /// Zero at every `λ`: a held motion, or no force.
    pub const ZERO: Ramp = Ramp {
        at_zero: 0.0,
        per_unit: 0.0,
    };
    /// The load parameter itself.
    pub const PARAMETER: Ramp = Ramp {
        at_zero: 0.0,
        per_unit: 1.0,
    };

    /// The value at `lambda`.
    pub fn at(self, lambda: f64) -> f64 {
        self.at_zero + self.per_unit * lambda
    }

    /// `d(value)/dλ` at `lambda`.
    pub fn rate(self, _lambda: f64) -> f64 {
        self.per_unit
    }

    /// Whether the value moves with `λ`.
    pub fn is_driven(self) -> bool {
        self.per_unit != 0.0
    }
}

/// What one axis of the tip support does, in the axis's own measure: along z the motion is
/// the compression ratio `ε` (tip height `h = h0 (1 − ε)`) and the force the compressive
/// dead load on every rod's tip over the Euler load, `P/Pcrit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AxisLoad {
    /// The support's motion along the axis prescribed: held where it is ([`Ramp::ZERO`]) or
    /// driven by the load parameter.
    Motion(Ramp),
    /// A dead force (or moment) on every rod's tip along the axis: none ([`Ramp::ZERO`], the
    /// axis free) or driven by the load parameter.
    Force(Ramp),
}

impl AxisLoad {
    /// The axial component held at this axis load's value at `λ = 0`.
    pub(super) fn held_axial(self) -> AxialHeld {
        match self {
            AxisLoad::Motion(r) => AxialHeld::Ratio(r.at_zero),
            AxisLoad::Force(r) => AxialHeld::Load(r.at_zero),
        }
    }

    /// The prescribed value and its rate `d/dλ` at `lambda`, in the axis's measure.
    pub fn ramp(self) -> Ramp {
        match self {
            AxisLoad::Motion(r) | AxisLoad::Force(r) => r,
        }
    }
}

/// The tip support, axis by axis (rapier's generic joint with per-axis masks is the model):
/// each of x, y, z, θx, θy, θz is held, free, driven by the load parameter or carries a
/// dead load. How each rod's tip is attached to the support (which of its translations and
/// rotations the support holds) is the rods' [`crate::model::boundary::EndCondition`]; this
/// is the support's own motion and the loads on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipSupport {
    axes: [AxisLoad; 6],
}

impl TipSupport {
    /// A support held in place along every axis.
    pub const HELD: TipSupport = TipSupport {
        axes: [AxisLoad::Motion(Ramp::ZERO); 6],
    };

    /// What `axis` does.
    pub fn axis(&self, axis: SupportAxis) -> AxisLoad {
        self.axes[axis.index()]
    }

    /// The same support with `axis` doing `load`.
    pub fn with(mut self, axis: SupportAxis, load: AxisLoad) -> TipSupport {
        self.axes[axis.index()] = load;
        self
    }
}

impl TipSupport {
    /// The support's rotation at `lambda`: the twist `φ` about the tube's axis (z) followed
    /// by the tilt `θ` about the x axis through the tip's centre, `q_s = q_x(θ) ∘ q_z(φ)`,
    /// and its rate `d q_s/dλ`, when both are prescribed motions (a rotation under a
    /// moment is not a motion of the support that the loads prescribe: identity).
    pub fn rotation(&self, lambda: f64) -> (Quat, Quat) {
        let angle = |axis| match self.axis(axis) {
            AxisLoad::Motion(r) => (r.at(lambda), r.rate(lambda)),
            AxisLoad::Force(_) => (0.0, 0.0),
        };
        let (phi, dphi) = angle(SupportAxis::RotZ);
        let (theta, dtheta) = angle(SupportAxis::RotX);
        let half = |a: f64| (0.5 * a).sin_cos();
        let ((sz, cz), (sx, cx)) = (half(phi), half(theta));
        let qz = Quat::new(0.0, 0.0, sz, cz);
        let qx = Quat::new(sx, 0.0, 0.0, cx);
        let dqz = Quat::new(0.0, 0.0, 0.5 * cz, -0.5 * sz) * dphi;
        let dqx = Quat::new(0.5 * cx, 0.0, 0.0, -0.5 * sx) * dtheta;
        let q = quaternion::mul(&qx, &qz);
        let dq = quaternion::mul(&dqx, &qz) + quaternion::mul(&qx, &dqz);
        (q, dq)
    }

    /// Whether the support turns (or is held turned) at some `λ`: its twist or tilt is a
    /// prescribed motion that is not zero.
    pub fn turns(&self) -> bool {
        [SupportAxis::RotX, SupportAxis::RotY, SupportAxis::RotZ]
            .iter()
            .any(|&a| matches!(self.axis(a), AxisLoad::Motion(r) if r != Ramp::ZERO))
    }
}
