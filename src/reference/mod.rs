//! The f64 reference: every sampler, pdf and BRDF value the GPU kernels are judged against.
//!
//! Conventions: local frame with the normal on +z; ωi is the given incident direction and ωr
//! the sampled one, both pointing away from the surface; every sampler takes its uniforms
//! explicitly (u ∈ [0, 1], 1 included), so any sample can be reproduced one at a time.

pub mod beckmann;
pub mod dielectric;
pub mod discrete;
pub mod effects;
pub mod frame;
pub mod invalid;
pub mod light;
mod lobe;
pub mod fresnel;
pub mod ggx;
pub mod masking;
pub mod microfacet;
pub mod reflect;
pub mod rng;
pub mod sampler;
pub mod ward;

pub use invalid::{ByReason, Invalid};
pub use lobe::{Lobe, LobeSample};
pub use sampler::{LobeKind, Method, SAMPLERS};
