//! The discretisation: rod meshes, quaternion elements and the global KKT system.

pub mod element;
pub mod mesh;
pub mod system;
