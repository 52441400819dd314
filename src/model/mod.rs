//! The continuum model: rotations, helices, assemblies, boundary conditions.

pub mod assembly;
pub mod boundary;
pub mod helix;
pub mod quaternion;
