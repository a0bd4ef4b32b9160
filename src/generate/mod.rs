//! Turning a place into particles: the geometry of grounds, surfaces and fills, tested on its
//! own without a GPU or a case file. The case file's reader and checker (`crate::case`) turns
//! what this module reports into messages that name the field and the fix; the solver imports
//! neither.

pub mod aabb;
pub mod fill;
pub mod footprint;
pub mod geotiff;
pub mod lattice;
pub mod mesh;
pub mod mesh_file;
pub mod polygon;
pub mod surface;
pub mod terrain;
pub mod triangle;
