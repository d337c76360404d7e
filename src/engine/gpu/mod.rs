//! The GPU engine: WGSL kernels (composed from `shaders/`) run through wgpu.

pub mod compose;
pub mod context;
pub mod counting;
pub mod dispatch;
pub mod effects;
pub mod engine;
pub mod layout;
pub mod library;
pub mod params;
pub mod pipeline_cache;
pub mod precision;
pub mod stack;
pub mod weighted;

pub use context::{Gpu, GpuError};
pub use counting::{Counting, Strategy};
pub use dispatch::Chunking;
pub use engine::{GpuEngine, GpuRun};
pub use weighted::WeightedRun;
