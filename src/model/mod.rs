//! The continuum model (docs/theory.md §1–§3, §6–§7): rotations, helices, assemblies and their
//! symmetry, boundary conditions, loading, stiffness and Love's closed-form helices.

pub mod assembly;
pub mod boundary;
pub mod cell;
pub mod elasticity;
pub mod helix;
pub mod loading;
pub mod love;
pub mod pantograph;
pub mod quaternion;
pub mod stiffness;
pub mod symmetry;
