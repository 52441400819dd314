//! How an assembly is loaded (docs/theory.md §3, docs/loads.md): everything applied to it
//! as functions of the load parameter ([`Loads`]), made of the tip support's motions and
//! loads axis by axis, the loads along the rods, and what the load parameter is; a tube's
//! four load components (axial, twist, tilt, radial pressure), one stepped and the others
//! held, compose it.

mod components;
mod line;
mod parameter;
mod support;

pub use components::{AxialHeld, Component, Held};
pub use line::{pressure_unit, LineLoad};
pub use parameter::{Branch, Control, Driven, LoadParameter};
pub use support::{AxisLoad, Ramp, SupportAxis, TipSupport};

/// Everything applied to an assembly, as functions of the load parameter: the tip support
/// axis by axis and the loads along the rods. The base is held where the rods' end
/// conditions say.
///
/// Built only by the constructors below, which make what the discretisation applies: the
/// tip support's z (driven, held, or free or loaded by a dead load), its twist and tilt as
/// prescribed motions (held or driven), uniform dead loads and a radial pressure along the
/// rods; its other axes are held.
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

    /// Whether the tip support tilts (its turn about x is a motion that is not zero).
    pub fn tilts(&self) -> bool {
        matches!(self.tip.axis(SupportAxis::RotX), AxisLoad::Motion(r) if r != Ramp::ZERO)
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
