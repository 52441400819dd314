//! The discretisation (docs/theory.md §5): shape functions and quadrature, quaternion rod
//! elements, meshes, the discrete model and its unknowns, the constraints, the global KKT
//! system, what a discrete state says (reactions, shapes), and the symmetric pair.

pub mod bulk;
pub mod cell;
pub mod cell_blocks;
pub mod constraints;
pub mod discrete_model;
pub mod element;
pub mod fields;
pub mod joint_fields;
pub mod joint_rotation;
pub mod mesh;
pub mod mirror;
pub mod pressure;
mod reactions;
pub mod shape;
pub mod slide;
pub mod support;
pub mod symmetry;
pub mod system;
