//! Thin wgpu layer, no physics: adapter choice, shader composition, compute kernels with
//! reflected bindings, buffer helpers.

pub mod buffers;
pub mod context;
pub mod kernel;
pub mod shader;

pub use context::{AdapterChoice, GpuContext};
pub use kernel::Kernel;
