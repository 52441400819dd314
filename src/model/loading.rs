//! How an assembly is loaded (docs/theory.md §3): the control of the load parameter, what a path
//! does at a bifurcation, and the axial loading of the tips it sets.

use crate::model::quaternion::{self, Quat};
use serde::{Deserialize, Serialize};

/// What the load parameter `λ` prescribes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Control {
    /// Tip height prescribed: `λ = ε = (h0 − h)/h0`, the compression ratio.
    Displacement,
    /// Dead compressive load `P = λ Pcrit` on every tip, along −z.
    Force,
}

impl Control {
    pub fn name(self) -> &'static str {
        match self {
            Control::Displacement => "displacement",
            Control::Force => "force",
        }
    }
}

/// What a path does at its first bifurcation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Branch {
    /// Stay on the fundamental branch (critical points are only reported).
    Fundamental,
    /// Switch to the bifurcated branch along the critical mode.
    Switch,
    /// Switch along the opposite of the critical mode.
    SwitchNegative,
}

impl Branch {
    /// The direction (±1) along the critical mode in which the path leaves the fundamental
    /// branch, if it does.
    pub fn direction(self) -> Option<f64> {
        match self {
            Branch::Fundamental => None,
            Branch::Switch => Some(1.0),
            Branch::SwitchNegative => Some(-1.0),
        }
    }
}

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

/// A ramp's value at `lambda`, held from then on.
fn constant_at(r: Ramp, lambda: f64) -> Ramp {
    Ramp {
        at_zero: r.at(lambda),
        per_unit: 0.0,
    }
}

impl AxisLoad {
    /// The axial component held at this axis load's value at `λ = 0`.
    fn held_axial(self) -> AxialHeld {
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

/// A load distributed along every rod, per unit arc length: a dead one has its slot in the
/// element kernel ([`crate::discretisation::element::ElementLoad`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LineLoad {
    /// A dead force `f(λ) = ramp(λ) · direction` (N/m) of fixed direction, such as the rods'
    /// weight: potential `−∫ f·r ds`.
    Dead { direction: [f64; 3], ramp: Ramp },
    /// Radial pressure on the tube: a force `q(λ) = ramp(λ)` (N/m) per unit length of rod
    /// directed at the tube's axis from the rod's current point (inward for `q > 0`), a
    /// central field in x–y with potential `q ∫ ρ ds`, `ρ = √(x² + y²)`.
    Radial { ramp: Ramp },
}

impl LineLoad {
    /// The dead force per unit length (N/m) at `lambda` (zero for a radial load).
    pub fn force(&self, lambda: f64) -> [f64; 3] {
        match *self {
            LineLoad::Dead { direction, ramp } => direction.map(|d| d * ramp.at(lambda)),
            LineLoad::Radial { .. } => [0.0; 3],
        }
    }

    /// `d f/dλ` (N/m) at `lambda` of the dead force.
    pub fn rate(&self, lambda: f64) -> [f64; 3] {
        match *self {
            LineLoad::Dead { direction, ramp } => direction.map(|d| d * ramp.rate(lambda)),
            LineLoad::Radial { .. } => [0.0; 3],
        }
    }

    /// The radial pressure `q` (N/m, inward positive) and its rate `dq/dλ` at `lambda`.
    pub fn pressure(&self, lambda: f64) -> (f64, f64) {
        match *self {
            LineLoad::Radial { ramp } => (ramp.at(lambda), ramp.rate(lambda)),
            LineLoad::Dead { .. } => (0.0, 0.0),
        }
    }
}

/// What the load parameter `λ` drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Driven {
    /// An axis of the tip support, by its motion or by a dead load on it.
    Tip(SupportAxis),
    /// The loads along the rods.
    AlongRods,
    /// The held loads of a path stepped otherwise, brought from zero (`λ = 0`) to their
    /// values (`λ = 1`) before it starts.
    Held,
}

/// What the load parameter `λ` is: what it drives and whether by motion or force. The faces
/// print its symbol, unit and label instead of assuming `ε`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadParameter {
    pub driven: Driven,
    pub control: Control,
}

impl LoadParameter {
    /// The axial parameter of `control`: `ε` or `P/Pcrit`.
    pub fn axial(control: Control) -> LoadParameter {
        LoadParameter {
            driven: Driven::Tip(SupportAxis::Z),
            control,
        }
    }

    /// Its symbol on screen: `ε`, `P/Pcrit`, `θ`, `q` …
    pub fn symbol(&self) -> &'static str {
        use SupportAxis::*;
        match (self.driven, self.control) {
            (Driven::Tip(Z), Control::Displacement) => "ε",
            (Driven::Tip(Z), Control::Force) => "P/Pcrit",
            (Driven::Tip(X | Y), Control::Displacement) => "u",
            (Driven::Tip(X | Y), Control::Force) => "F",
            (Driven::Tip(RotZ), Control::Displacement) => "φ",
            (Driven::Tip(RotZ), Control::Force) => "T",
            (Driven::Tip(_), Control::Displacement) => "θ",
            (Driven::Tip(_), Control::Force) => "M",
            (Driven::AlongRods, _) => "q",
            (Driven::Held, _) => "s",
        }
    }

    /// The symbol of the motion of what it drives, which a load curve takes for its abscissa
    /// under either control: the compression ratio `ε` for the axial load (a dead load's
    /// curve is drawn against the motion it causes, not against itself).
    pub fn motion_symbol(&self) -> &'static str {
        use SupportAxis::*;
        match self.driven {
            Driven::Tip(Z) => "ε",
            Driven::AlongRods => "a",
            Driven::Held => "s",
            Driven::Tip(X | Y) => "u",
            Driven::Tip(RotZ) => "φ",
            Driven::Tip(RotX | RotY) => "θ",
        }
    }

    /// Its name in plain ASCII, for files and command lines: `eps`, `P/Pcrit`, `theta` …
    pub fn ascii(&self) -> &'static str {
        match self.symbol() {
            "ε" => "eps",
            "θ" => "theta",
            "φ" => "phi",
            other => other,
        }
    }

    /// Its unit (empty for a ratio).
    pub fn unit(&self) -> &'static str {
        use SupportAxis::*;
        match (self.driven, self.control) {
            (Driven::Tip(Z), _) => "",
            (Driven::Tip(X | Y), Control::Displacement) => "m",
            (Driven::Tip(X | Y), Control::Force) => "N",
            (Driven::Tip(_), Control::Displacement) => "rad",
            (Driven::Tip(_), Control::Force) => "N m",
            (Driven::AlongRods, _) => "N/m",
            (Driven::Held, _) => "",
        }
    }

    /// What it is, in words: `compression ratio`, `compressive tip load over Pcrit` …
    pub fn label(&self) -> &'static str {
        use SupportAxis::*;
        match (self.driven, self.control) {
            (Driven::Tip(Z), Control::Displacement) => "compression ratio",
            (Driven::Tip(Z), Control::Force) => "compressive tip load over Pcrit",
            (Driven::Tip(X | Y), Control::Displacement) => "lateral tip displacement",
            (Driven::Tip(X | Y), Control::Force) => "lateral tip force",
            (Driven::Tip(RotZ), Control::Displacement) => "twist angle",
            (Driven::Tip(RotZ), Control::Force) => "axial torque",
            (Driven::Tip(_), Control::Displacement) => "tilt angle",
            (Driven::Tip(_), Control::Force) => "bending moment",
            (Driven::AlongRods, _) => "line load",
            (Driven::Held, _) => "fraction of the held loads",
        }
    }
}

/// The natural scale of a radial line pressure on rods of bending stiffness `b1` (N m²)
/// wound as helices of radius `a` and pitch parameter `b` (m): `B1 a/c⁴` (N/m), the
/// pressure that changes their curvature `a/c²` by its own size (1 when it is not a
/// positive number, for rods on the axis).
pub fn pressure_unit(b1: f64, a: f64, b: f64) -> f64 {
    let c2 = a * a + b * b;
    let unit = b1 * a / (c2 * c2);
    if unit.is_finite() && unit > 0.0 {
        unit
    } else {
        1.0
    }
}

/// A component of the loading of the whole tube: one is stepped by the load parameter, the
/// others are held ([`Held`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Component {
    /// Along the axis: the compression ratio `ε` or the compressive tip load `P/Pcrit`.
    Axial,
    /// The tip support turned about the tube's axis by `φ` (rad).
    Twist,
    /// The tip support turned about the x axis through the tip's centre by `θ` (rad).
    Tilt,
    /// Radial pressure `q` (N/m, inward) on every rod.
    Pressure,
}

impl Component {
    /// Every component, in the order the explorer cycles through them.
    pub const ALL: [Component; 4] = [
        Component::Axial,
        Component::Twist,
        Component::Pressure,
        Component::Tilt,
    ];

    /// Its name in case files and on screen.
    pub fn name(self) -> &'static str {
        match self {
            Component::Axial => "axial",
            Component::Twist => "twist",
            Component::Tilt => "tilt",
            Component::Pressure => "pressure",
        }
    }

    /// Whether a load of this component keeps the tube's cyclic symmetry (the tilt is a
    /// wavenumber-1 load).
    pub fn keeps_cyclic_symmetry(self) -> bool {
        self != Component::Tilt
    }
}

/// The axial component when it is held: at a compression ratio, or under a dead load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AxialHeld {
    /// The tip height held at `h = h0 (1 − ε)`.
    Ratio(f64),
    /// A dead compressive load `P/Pcrit` on every tip (0: the tips free along the axis).
    Load(f64),
}

/// The values at which the components that are not stepped are held.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Held {
    pub axial: AxialHeld,
    /// Twist `φ` (rad).
    pub twist: f64,
    /// Tilt `θ` (rad).
    pub tilt: f64,
    /// Radial pressure `q` (N/m, inward).
    pub pressure: f64,
}

impl Held {
    /// Everything held where it is in the natural state, the tip height included (the
    /// thesis's support).
    pub const NATURAL: Held = Held {
        axial: AxialHeld::Ratio(0.0),
        twist: 0.0,
        tilt: 0.0,
        pressure: 0.0,
    };

    /// Whether every held value is that of the natural state (a free axial position
    /// included: it carries no load).
    pub fn is_natural(&self) -> bool {
        let axial = match self.axial {
            AxialHeld::Ratio(e) | AxialHeld::Load(e) => e,
        };
        axial == 0.0 && self.twist == 0.0 && self.tilt == 0.0 && self.pressure == 0.0
    }
}

/// Everything applied to an assembly, as functions of the load parameter: the tip support
/// axis by axis and the loads along the rods. The base is held where the rods' end
/// conditions say.
///
/// Built only by the constructors below, which make what the discretisation applies: the
/// tip support's z (driven, or free under a dead load) and uniform dead loads along the rods;
/// its other axes are held.
#[derive(Clone, Debug, PartialEq)]
pub struct Loads {
    tip: TipSupport,
    along_rods: Vec<LineLoad>,
    parameter: LoadParameter,
}

impl Loads {
    /// The tips pushed along the axis under `control` (the thesis's loading, docs/theory.md §3):
    /// the tip support's z driven by `λ = ε` or carrying the dead load `λ Pcrit` on every
    /// tip, every other axis held.
    pub fn axial(control: Control) -> Loads {
        let z = match control {
            Control::Displacement => AxisLoad::Motion(Ramp::PARAMETER),
            Control::Force => AxisLoad::Force(Ramp::PARAMETER),
        };
        Loads {
            tip: TipSupport::HELD.with(SupportAxis::Z, z),
            along_rods: Vec::new(),
            parameter: LoadParameter::axial(control),
        }
    }

    /// The tube loaded by its components: `stepped` driven by the load parameter under
    /// `control` (the angles of twist and tilt by their motion, the pressure by its value:
    /// `control` only chooses between `ε` and `P/Pcrit` for the axial component), the
    /// others held at `held`'s values.
    pub fn compose(stepped: Component, control: Control, held: Held) -> Loads {
        let constant = |v: f64| Ramp {
            at_zero: v,
            per_unit: 0.0,
        };
        let z = match (stepped, control, held.axial) {
            (Component::Axial, Control::Displacement, _) => AxisLoad::Motion(Ramp::PARAMETER),
            (Component::Axial, Control::Force, _) => AxisLoad::Force(Ramp::PARAMETER),
            (_, _, AxialHeld::Ratio(e)) => AxisLoad::Motion(constant(e)),
            (_, _, AxialHeld::Load(p)) => AxisLoad::Force(constant(p)),
        };
        let angle = |c: Component, value: f64| {
            AxisLoad::Motion(if stepped == c {
                Ramp::PARAMETER
            } else {
                constant(value)
            })
        };
        let tip = TipSupport::HELD
            .with(SupportAxis::Z, z)
            .with(SupportAxis::RotZ, angle(Component::Twist, held.twist))
            .with(SupportAxis::RotX, angle(Component::Tilt, held.tilt));
        let pressure = if stepped == Component::Pressure {
            Some(Ramp::PARAMETER)
        } else {
            (held.pressure != 0.0).then(|| constant(held.pressure))
        };
        let parameter = match stepped {
            Component::Axial => LoadParameter::axial(control),
            Component::Twist | Component::Tilt => LoadParameter {
                driven: Driven::Tip(if stepped == Component::Twist {
                    SupportAxis::RotZ
                } else {
                    SupportAxis::RotX
                }),
                control: Control::Displacement,
            },
            Component::Pressure => LoadParameter {
                driven: Driven::AlongRods,
                control: Control::Force,
            },
        };
        Loads {
            tip,
            along_rods: pressure
                .map(|ramp| LineLoad::Radial { ramp })
                .into_iter()
                .collect(),
            parameter,
        }
    }

    /// The component the load parameter steps (`None` for loads not made by
    /// [`Loads::compose`], such as a dead line load, or a preload).
    pub fn stepped(&self) -> Option<Component> {
        match self.parameter.driven {
            Driven::Tip(SupportAxis::Z) => Some(Component::Axial),
            Driven::Tip(SupportAxis::RotZ) => Some(Component::Twist),
            Driven::Tip(SupportAxis::RotX) => Some(Component::Tilt),
            Driven::AlongRods if self.is_radial() => Some(Component::Pressure),
            _ => None,
        }
    }

    fn is_radial(&self) -> bool {
        self.along_rods
            .iter()
            .any(|l| matches!(l, LineLoad::Radial { .. }))
    }

    /// The values the components are held at when not stepped (at `λ = 0` for the one
    /// stepped).
    pub fn held(&self) -> Held {
        let at_zero = |axis| self.tip.axis(axis).ramp().at_zero;
        Held {
            axial: self.tip.axis(SupportAxis::Z).held_axial(),
            twist: at_zero(SupportAxis::RotZ),
            tilt: at_zero(SupportAxis::RotX),
            pressure: self.pressure(0.0).0,
        }
    }

    /// The same loads with `component` stepped instead (under `control` for the axial
    /// one), the others held at their values at load parameter `lambda` (the current
    /// state's, so that the new path starts where the old one is).
    pub fn restepped(&self, component: Component, control: Control, lambda: f64) -> Loads {
        let at = |axis| self.tip.axis(axis).ramp().at(lambda);
        let held = Held {
            axial: match self.tip.axis(SupportAxis::Z) {
                AxisLoad::Motion(r) => AxisLoad::Motion(constant_at(r, lambda)),
                AxisLoad::Force(r) => AxisLoad::Force(constant_at(r, lambda)),
            }
            .held_axial(),
            twist: at(SupportAxis::RotZ),
            tilt: at(SupportAxis::RotX),
            pressure: self.pressure(lambda).0,
        };
        Loads::compose(component, control, held)
    }

    /// The loads that bring a path from the natural state to where `self` holds it at
    /// `λ = 0`: every held value scaled by the preload parameter (0 … 1), the stepped
    /// component at zero (`None` when nothing is held away from the natural state).
    pub fn preload(&self) -> Option<Loads> {
        let scaled = |r: Ramp| Ramp {
            at_zero: 0.0,
            per_unit: r.at_zero,
        };
        let mut tip = self.tip;
        for axis in SupportAxis::ALL {
            tip = tip.with(
                axis,
                match tip.axis(axis) {
                    AxisLoad::Motion(r) => AxisLoad::Motion(scaled(r)),
                    AxisLoad::Force(r) => AxisLoad::Force(scaled(r)),
                },
            );
        }
        let along_rods: Vec<LineLoad> = self
            .along_rods
            .iter()
            .map(|l| match *l {
                LineLoad::Dead { direction, ramp } => LineLoad::Dead {
                    direction,
                    ramp: scaled(ramp),
                },
                LineLoad::Radial { ramp } => LineLoad::Radial { ramp: scaled(ramp) },
            })
            .collect();
        let moves = SupportAxis::ALL
            .iter()
            .any(|&a| tip.axis(a).ramp().is_driven())
            || along_rods.iter().any(|l| match *l {
                LineLoad::Dead { ramp, .. } | LineLoad::Radial { ramp } => ramp.is_driven(),
            });
        moves.then_some(Loads {
            tip,
            along_rods,
            parameter: LoadParameter {
                driven: Driven::Held,
                control: Control::Displacement,
            },
        })
    }

    /// Whether the loads keep the tube's cyclic symmetry (no tilt).
    pub fn keeps_cyclic_symmetry(&self) -> bool {
        [
            SupportAxis::RotX,
            SupportAxis::RotY,
            SupportAxis::X,
            SupportAxis::Y,
        ]
        .iter()
        .all(|&a| self.tip.axis(a) == AxisLoad::Motion(Ramp::ZERO))
    }

    /// A uniform dead line load on every rod driven by the load parameter (`λ` the
    /// magnitude of `direction`'s force, N/m), the tip support held but for its z, free.
    pub fn line_load(direction: [f64; 3]) -> Loads {
        Loads {
            tip: TipSupport::HELD.with(SupportAxis::Z, AxisLoad::Force(Ramp::ZERO)),
            along_rods: vec![LineLoad::Dead {
                direction,
                ramp: Ramp::PARAMETER,
            }],
            parameter: LoadParameter {
                driven: Driven::AlongRods,
                control: Control::Force,
            },
        }
    }

    /// The same loads with the axial load parameter under `control`; loads whose parameter
    /// drives something else are kept as they are.
    pub fn with_axial_control(&self, control: Control) -> Loads {
        match self.parameter.driven {
            Driven::Tip(SupportAxis::Z) => Loads {
                along_rods: self.along_rods.clone(),
                ..Loads::compose(Component::Axial, control, self.held())
            },
            _ => self.clone(),
        }
    }

    /// The radial pressure `q` (N/m, inward) of the loads along the rods at `lambda`, and
    /// its rate `dq/dλ`.
    pub fn pressure(&self, lambda: f64) -> (f64, f64) {
        self.along_rods.iter().fold((0.0, 0.0), |(q, dq), l| {
            let (a, b) = l.pressure(lambda);
            (q + a, dq + b)
        })
    }

    /// The tip support.
    pub fn tip(&self) -> &TipSupport {
        &self.tip
    }

    /// The loads along every rod.
    pub fn along_rods(&self) -> &[LineLoad] {
        &self.along_rods
    }

    /// What the load parameter is.
    pub fn parameter(&self) -> LoadParameter {
        self.parameter
    }

    /// The control of the load parameter.
    pub fn control(&self) -> Control {
        self.parameter.control
    }
}
