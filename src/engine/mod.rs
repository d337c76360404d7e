//! The engines that draw and histogram samples: a [`job::Job`] says what to draw; the
//! [`gpu`] engine runs it in WGSL through wgpu, the [`cpu`] engine draws the very same samples
//! with the f64 reference on all cores.

pub mod cpu;
pub mod gpu;
pub mod job;
