//! wgsph: GPU weakly-compressible SPH for fluid–solid interaction, on wgpu/WGSL.

pub mod bench;
pub mod body;
pub mod case;
pub mod checkpoint;
pub mod decomposition;
pub mod eos;
pub mod generate;
pub mod gpu;
pub mod grid;
pub mod hydrograph;
pub mod kernel;
pub mod lagrangian;
#[cfg(test)]
mod layers;
pub mod layout;
pub mod logging;
pub mod output;
pub mod particles;
pub mod plot;
pub mod probe_reach;
pub mod progress;
pub mod ranks;
pub mod reference;
pub mod resume;
pub mod run;
pub mod scenario;
pub mod sph;
pub mod surface;
#[cfg(test)]
mod twins;
pub mod validation;
