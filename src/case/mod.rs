//! Case files (TOML): geometry, stiffness, boundary conditions, loading, discretisation.
//!
//! Every key is optional; a missing key takes the value of the thesis case (§4.1), so a
//! minimal case is a few lines. Unknown keys and bad values are rejected with the file,
//! line, key and what was expected.
//!
//! Reading goes in two passes: `raw` is the layout of the file (which keys exist and
//! their types, read by serde), `tables` checks the values table by table against their
//! physical and numerical ranges and fills in the defaults.

mod design;
mod error;
mod helices;
mod imperfection;
mod joints;
mod keys;
mod limits;
mod loads;
mod model_key;
mod motion;
mod overrides;
mod raw;
mod settings;
mod size;
mod tables;
mod target;

pub use design::DesignKey;
pub(crate) use error::plain_types;
pub use error::CaseError;
pub use helices::{Refused, HELICES_RANGE};
pub use imperfection::{Imperfection, ImperfectionShape, MAX_AMPLITUDE, SHAPES};
pub use keys::{keys_markdown, DefaultDoc, KeyDoc, RangeDoc, KEYS};
pub use limits::{
    num, LENGTH_RANGE, MAX_ELEMENTS_PER_TURN, MAX_JOINTS, MAX_LOAD, MAX_STEPS,
    MIN_ELEMENTS_PER_TURN, PITCH_RATIO, STEP_RANGE, STIFFNESS_RANGE, STIFFNESS_RATIO,
    TOLERANCE_RANGE, TURNS_RANGE,
};
pub use motion::{free_motion_of, FreeMotion};
pub use overrides::{set_key, settings_line, Setting};
pub use settings::{AccuracyTarget, Discretisation, Geometry, Loading};
pub use size::{available_memory, SizeEstimate, TooLarge, LONG_STEP_SECONDS};
pub use target::TargetError;

use crate::discretisation::discrete_model::DiscreteModel;
use crate::model::assembly::Assembly;
use crate::model::boundary::{BoundaryConditions, JointStiffness, Joints};
use crate::model::elasticity::Elasticity;
use crate::model::loading::{pressure_unit, Branch, Component, Control, LoadParameter, Loads};
use crate::model::stiffness::Stiffness;
use crate::solver::continuation::ContinuationSettings;
use raw::RawCase;
use std::path::Path;
use tables::Checker;

/// The case run by `spira` with no arguments: the thesis assembly of 8 helices.
pub const DEFAULT_CASE: &str = include_str!("../../cases/thesis-n8.toml");
/// Name of the default case in messages.
pub const DEFAULT_CASE_NAME: &str = "thesis-n8 (built in)";

/// A validated case.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Name shown in outputs (the file stem unless given).
    pub name: String,
    pub geometry: Geometry,
    /// Bending stiffnesses `B1`, `B2` about the directors `d1`, `d2` and torsional stiffness
    /// `B3` (N m²).
    pub stiffness: Stiffness,
    /// The elastic hypotheses of the rods (`[rod]`).
    pub rod: Elasticity,
    pub boundary: BoundaryConditions,
    pub loading: Loading,
    pub discretisation: Discretisation,
    pub solver: ContinuationSettings,
    /// A flaw of the natural state (`[imperfection]`); `None`: the perfect structure.
    pub imperfection: Option<Imperfection>,
}

impl Case {
    /// Reads and validates a case file.
    pub fn from_file(path: &Path) -> Result<Case, CaseError> {
        Case::from_file_with(path, &[])
    }

    /// Reads and validates a case file with `settings` (`--set key=value`) applied. The
    /// file is checked first as it is (its errors said as without settings); then the
    /// settings are applied to its document and the result is read by the same checks, an
    /// error of it said about the setting its key belongs to ([`CaseError::Set`]). The case
    /// keeps the file's name.
    pub fn from_file_with(path: &Path, settings: &[Setting]) -> Result<Case, CaseError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|reason| CaseError::Io {
            file: file.clone(),
            reason,
        })?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "case".into());
        Case::parse_with(&text, &file, &stem, settings)
    }

    /// Parses and validates case text with `settings` applied ([`Case::from_file_with`]).
    pub fn parse_with(
        text: &str,
        file: &str,
        stem: &str,
        settings: &[Setting],
    ) -> Result<Case, CaseError> {
        let plain = Case::parse(text, file, stem)?;
        if settings.is_empty() {
            return Ok(plain);
        }
        let patched = overrides::patched(text, file, &plain.name, settings)?;
        Case::parse(&patched, file, stem).map_err(|e| overrides::setting_error(file, settings, &e))
    }

    /// The built-in default case (thesis, n = 8).
    pub fn default_case() -> Case {
        Case::parse(DEFAULT_CASE, DEFAULT_CASE_NAME, "thesis-n8")
            .expect("the built-in case is valid")
    }

    /// Parses and validates case text; `file` names it in errors, `stem` is the name used
    /// when the case gives none. The tables are checked in the order of the file format, and
    /// the first error found is returned.
    pub fn parse(text: &str, file: &str, stem: &str) -> Result<Case, CaseError> {
        let raw = RawCase::from_text(text, file)?;
        let ck = Checker { file, text };
        let geometry = tables::geometry(&raw.geometry, &ck)?;
        let stiffness = tables::stiffness(&raw.stiffness, &geometry, &ck)?;
        let rod = tables::rod(&raw.rod, &ck)?;
        let boundary = BoundaryConditions {
            joints: joints::joints(&raw.boundary, &ck)?,
            ..tables::boundary(&raw.boundary)
        };
        let loading = loads::loading(&raw.loading, &geometry, stiffness.b1, &boundary, &ck)?;
        // the tip's height is free under a dead axial load
        tables::free_motion(&boundary, &geometry, loading.tip_height_held(), &ck)?;
        let mut discretisation = tables::discretisation(&raw.discretisation, &geometry, &ck)?;
        if let Some(why) = discretisation
            .cell
            .then(|| model_key::cell_loading_message(&loading, geometry.helices))
            .flatten()
        {
            return Err(CaseError::Invalid {
                file: file.to_string(),
                line: ck.line_of_key("model"),
                key: "discretisation.model".into(),
                message: why.into(),
            });
        }
        let tilted = loading.parameter == Component::Tilt || loading.hold.tilt != 0.0;
        if discretisation.cell && tilted && boundary.joints.slides() {
            return Err(CaseError::Invalid {
                file: file.to_string(),
                line: ck.line_of_key("joints"),
                key: "boundary.joints".into(),
                message: "expected pin, welded, elastic or none joints on a tilted cell (the bending cell does not carry sliding crossings), found \"sliding\"".into(),
            });
        }
        if !loading.parameter.keeps_cyclic_symmetry() || loading.hold.tilt != 0.0 {
            // a tilt is a wavenumber-1 load: the full model
            if discretisation.symmetric && !discretisation.symmetric_auto {
                return Err(CaseError::Invalid {
                    file: file.to_string(),
                    line: ck.line_of_key("symmetric"),
                    key: "discretisation.symmetric".into(),
                    message: "expected symmetric = false with a tilt (it breaks the cyclic symmetry), found true".into(),
                });
            }
            discretisation.symmetric = false;
            discretisation.symmetric_auto = false;
        }
        // a branch switched onto may break the symmetry: the automatic choice is then the
        // full model
        if discretisation.symmetric_auto && loading.branch == Branch::Switch {
            discretisation.symmetric = false;
        }
        let solver = tables::solver(&raw.solver, &ck)?;
        let imperfection = imperfection::imperfection(&raw.imperfection, &geometry, &ck)?;
        Ok(Case {
            name: raw.name.unwrap_or_else(|| stem.to_string()),
            geometry,
            stiffness,
            rod,
            boundary,
            loading,
            discretisation,
            solver,
            imperfection,
        })
    }

    /// The same case with `n` helices (what the explorer does when n changes).
    pub fn with_helices(&self, n: usize) -> Case {
        let mut c = self.clone();
        c.geometry.helices = n;
        if c.discretisation.cell {
            return c;
        }
        // the symmetric reduction needs n = 2m, m ≥ 2
        let has = n >= 4 && n % 2 == 0 && c.loads().keeps_cyclic_symmetry();
        c.discretisation.symmetric = if c.discretisation.symmetric_auto {
            has && c.loading.branch != Branch::Switch
        } else {
            c.discretisation.symmetric && has
        };
        c
    }

    /// The same case with `n` helices ([`Case::with_helices`]), refused by the limits the
    /// case reader puts on a file's `geometry.helices`: the number, the straight rod, the
    /// pin joints and the elements per turn.
    pub fn with_helices_checked(&self, n: usize) -> Result<Case, Refused> {
        let refuse = |key, message| Err(Refused { key, message });
        let count = i64::try_from(n).unwrap_or(i64::MAX);
        if let Some(m) = helices::helices_message(count) {
            return refuse("geometry.helices", m);
        }
        let case = self.with_helices(n);
        let g = &case.geometry;
        if case.discretisation.cell && n % 2 == 1 {
            return refuse(
                "geometry.helices",
                "the cell of an infinite tube needs n = 2m helices".to_string(),
            );
        }
        if let Some(m) = helices::straight_rod_message(g) {
            return refuse("geometry.helices", m);
        }
        if let Some(m) = helices::joints_message(g) {
            return refuse("geometry.helices", m);
        }
        if case.discretisation.accuracy.is_none() {
            if let Some(m) = helices::elements_message(g, case.discretisation.elements) {
                return refuse("discretisation.elements", m);
            }
        }
        Ok(case)
    }

    /// The same case with the design key `key` at `value` (the explorer's critical curve),
    /// refused as the case reader would refuse the key's value in a file.
    pub fn with_design(&self, key: DesignKey, value: f64) -> Result<Case, Refused> {
        let mut c = self.clone();
        let elements = c
            .discretisation
            .accuracy
            .is_none()
            .then_some(c.discretisation.elements);
        design::set_design(key, value, &mut c.geometry, &mut c.stiffness, elements)?;
        Ok(c)
    }

    /// The value of the design key `key` in this case.
    pub fn design_value(&self, key: DesignKey) -> f64 {
        key.value(&self.geometry, &self.stiffness)
    }

    /// The case as the explorer solves it interactively (a model no bigger than
    /// the scene): one symmetric pair standing for the assembly when it has the symmetry,
    /// its stability judged by the pair's Bloch blocks (the count of unstable directions at
    /// every step, the lowest eigenvalue and its wavenumber at every point of the path).
    /// Everything shown is still of the whole assembly.
    pub fn for_explorer(&self) -> Case {
        let mut c = self.clone();
        let n = c.geometry.helices;
        c.discretisation.symmetric |=
            !c.discretisation.cell && n >= 4 && n % 2 == 0 && c.loads().keeps_cyclic_symmetry();
        c
    }

    /// The same case with `component` stepped (the others held as the case holds them),
    /// to the case's own target when it steps that component already, else to a default
    /// one: ε = 0.5, twist 1 rad (0.01 rad per cell for a cell), tilt 0.5 rad, a pressure of
    /// one [`Case::parameter_unit`].
    /// A tilt solves the full model. `Err` says why the supports cannot carry it.
    pub fn with_stepped(&self, component: Component) -> Result<Case, String> {
        let l = &self.loading;
        if let Some((_, why)) = loads::combination_error(
            component,
            l.control,
            &l.hold,
            &self.geometry,
            &self.boundary,
        ) {
            return Err(why.to_string());
        }
        if self.discretisation.cell && component == Component::Tilt {
            return Err(
                "the cell is loaded by its axial strain, its twist and a radial pressure only"
                    .into(),
            );
        }
        let mut c = self.clone();
        if component != l.parameter {
            c.loading.parameter = component;
            c.loading.control = Control::Displacement;
            c.loading.target = match component {
                Component::Axial => 0.5,
                // a cell's twist is per cell: its lattice buckles from about 5e-4 rad
                Component::Twist if c.discretisation.cell => 0.01,
                Component::Twist => 1.0,
                Component::Tilt => 0.5,
                Component::Pressure => c.parameter_unit(),
            };
        }
        let n = c.geometry.helices;
        let symmetric = c.loads().keeps_cyclic_symmetry() && n >= 4 && n % 2 == 0;
        c.discretisation.symmetric = symmetric && !c.discretisation.cell;
        Ok(c)
    }

    /// The natural scale of the case's load parameter, in its own measure: 1 for `ε`,
    /// `P/Pcrit` and the angles (rad), `B1 a/c⁴` (N/m) for the radial pressure.
    pub fn parameter_unit(&self) -> f64 {
        match self.loading.parameter {
            Component::Pressure => {
                pressure_unit(self.stiffness.b1, self.geometry.radius, self.geometry.pitch)
            }
            _ => 1.0,
        }
    }

    /// The rigid motion that supports `bc` would leave free on the case's assembly, if any
    /// (the check the case reader refuses a file's `[boundary]` by).
    pub fn free_motion(&self, bc: &BoundaryConditions) -> Option<FreeMotion> {
        motion::free_motion_of(bc, &self.geometry, self.loading.tip_height_held())
    }

    /// The springs elastic joints get on this case: the file's, or `B1/L` about every axis
    /// (the bending stiffness of a rod over its length) when the file has none.
    pub fn joint_springs(&self) -> JointStiffness {
        match self.boundary.joints {
            Joints::Elastic(k) => k,
            _ => {
                let k = self.stiffness.b1 / self.geometry.length;
                JointStiffness {
                    scissor: k,
                    out_of_plane: k,
                }
            }
        }
    }

    /// The size of the case's problem, estimated from its mesh without building it.
    pub fn size_estimate(&self) -> SizeEstimate {
        SizeEstimate::of(&self.geometry, &self.discretisation)
    }

    /// Whether the case's cell is bent (its tilt stepped or held away from zero): the model
    /// is then the bending cell of the tube ([`Assembly::bending_cell`]).
    pub fn bends_cell(&self) -> bool {
        self.discretisation.cell
            && (self.loading.parameter == Component::Tilt || self.loading.hold.tilt != 0.0)
    }

    /// The discrete model of the case.
    pub fn model(&self) -> DiscreteModel {
        let g = &self.geometry;
        let full = Assembly::new(g.helices, g.radius, g.pitch, g.length);
        let mut elements = self.discretisation.elements;
        let assembly = if self.discretisation.cell && self.bends_cell() {
            // the bending cell's rods span two cells: the cell's mesh twice
            elements *= 2;
            Assembly::bending_cell(g.helices, g.radius, g.pitch)
                .expect("validated: a bent cell's helices make a tube of m >= 2")
        } else if self.discretisation.cell {
            Assembly::tube_cell(g.helices, g.radius, g.pitch)
                .expect("validated: the case's helices make a tube")
        } else if self.discretisation.symmetric {
            full.symmetric_pair()
                .expect("validated: the case has the symmetry")
        } else {
            full
        };
        DiscreteModel::with_hypotheses(
            assembly,
            self.stiffness,
            elements,
            self.discretisation.order,
            self.rod,
            self.discretisation.reference,
        )
        .with_sliding_joints(self.boundary.joints.slides())
    }

    /// What the case applies to the assembly: the component stepped under the case's
    /// control, the others held.
    pub fn loads(&self) -> Loads {
        Loads::compose(
            self.loading.parameter,
            self.loading.control,
            self.loading.hold,
        )
    }

    /// What the case's load parameter is.
    pub fn load_parameter(&self) -> LoadParameter {
        self.loads().parameter()
    }

    /// The output values of the load parameter: `steps` equal increments from 0 (exclusive)
    /// to `target`. The fraction is formed first so that the last value is `target` exactly.
    pub fn output_parameters(&self, target: f64, steps: usize) -> Vec<f64> {
        (1..=steps)
            .map(|k| target * (k as f64 / steps as f64))
            .collect()
    }

    /// Validates a target load parameter against the case: under displacement control a
    /// compression ratio `ε` the geometry admits (tip height `0 < h < L`), under load
    /// control a finite `P / Pcrit`. The error says which limit is crossed.
    pub fn check_target(&self, target: f64) -> Result<(), TargetError> {
        target::check_component_target(
            &self.geometry,
            self.stiffness.b1,
            self.loading.parameter,
            self.loading.control,
            target,
        )
    }
}
