//! The GPU engine: WGSL kernels (composed from `shaders/`) run through wgpu.

pub mod compose;
pub mod context;
pub mod effects;
pub mod engine;
pub mod weighted;

pub use context::{Gpu, GpuError};
pub use engine::{Chunking, GpuEngine, GpuRun};
