//! Experiments on top of the engines: the numerically hard cases ([`stress`], and the light
//! samplers' in [`light_stress`]) and accuracy
//! against time ([`tradeoff`]).

pub mod light_stress;
pub mod stress;
pub mod tradeoff;
