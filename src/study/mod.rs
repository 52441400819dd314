//! Speed against accuracy: work-precision studies and meshes chosen for a target
//! accuracy.
//!
//! A **study** ([`ladder`]) solves one [`Subject`] on a ladder of meshes (elements per rod,
//! doubling) for each element order, times every solve (best of several runs after a
//! warm-up) and measures its error against a reference:
//!
//! - the **response** at the final load: the axial reaction `Fz/(n Pcrit)` under
//!   displacement control (`ε` under load control, where the load is prescribed), or the
//!   tip force of Love's helix (N);
//! - the **curvature** profiles `(κ1, κ2, Ω)` (1/m) of every rod, in the max norm over the
//!   vertices of the coarsest mesh (common to every mesh of a doubling ladder; values
//!   recovered from the Barlow points, `fields::recovered_curvature`), relative to
//!   the largest reference curvature;
//! - the **critical load** parameter of the first critical point, when there is one.
//!
//! The reference is a closed form where the subject has one (Love's helix, docs/theory.md §6),
//! otherwise Richardson's extrapolation of the two finest quadratic solutions with the
//! theoretical order of each measure ([`Measure::theoretical_order`]).
//!
//! An **accuracy-driven mesh** ([`accuracy`]: [`choose_mesh`], [`resolve_accuracy`]) solves
//! two coarse meshes per element order, estimates the error constant from their difference
//! and the known order, and picks the element order and number of elements that meet the
//! target at the least predicted time.
//!
//! Nothing here prints, formats tables or writes files: `output::precision` and
//! the faces (CLI, explorer) do.

pub mod accuracy;
pub mod ladder;
pub mod subject;

pub use accuracy::{
    choose_mesh, choose_mesh_with, resolve_accuracy, resolve_accuracy_with, AccuracyError,
    MeshChoice, Pilot, ACCURACY_FLOOR, MAX_ELEMENTS, SAFETY,
};
pub use ladder::{
    measured, run_study, run_study_with, Ladder, Reference, Rung, RungFinished, RungResult, Study,
    StudyError,
};

pub use subject::{sample_curvature, Measure, Probes, Subject, Values, ORDERS};
