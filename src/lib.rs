//! wgsph: GPU weakly-compressible SPH for fluid–solid interaction, on wgpu/WGSL.

pub mod gpu;
pub mod layout;
pub mod scenario;
pub mod sph;
pub mod output;
pub mod run;
pub mod reference;
pub mod case;
