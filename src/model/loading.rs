//! How an assembly is loaded (docs/theory.md §3): the control of the load parameter, what a path
//! does at a bifurcation, and the axial loading of the tips it sets.

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

impl AxisLoad {
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

/// A load distributed along every rod, per unit arc length: its slot in the element kernel
/// is [`crate::discretisation::element::ElementLoad`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LineLoad {
    /// A dead force `f(λ) = ramp(λ) · direction` (N/m) of fixed direction, such as the rods'
    /// weight: potential `−∫ f·r ds`.
    Dead { direction: [f64; 3], ramp: Ramp },
}

impl LineLoad {
    /// The force per unit length (N/m) at `lambda`.
    pub fn force(&self, lambda: f64) -> [f64; 3] {
        match *self {
            LineLoad::Dead { direction, ramp } => direction.map(|d| d * ramp.at(lambda)),
        }
    }

    /// `d f/dλ` (N/m) at `lambda`.
    pub fn rate(&self, lambda: f64) -> [f64; 3] {
        match *self {
            LineLoad::Dead { direction, ramp } => direction.map(|d| d * ramp.rate(lambda)),
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
        }
    }

    /// The symbol of the motion of what it drives, which a load curve takes for its abscissa
    /// under either control: the compression ratio `ε` for the axial load (a dead load's
    /// curve is drawn against the motion it causes, not against itself).
    pub fn motion_symbol(&self) -> &'static str {
        use SupportAxis::*;
        match self.driven {
            Driven::Tip(Z) | Driven::AlongRods => "ε",
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
        }
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
                ..Loads::axial(control)
            },
            _ => self.clone(),
        }
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
