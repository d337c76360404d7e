//! Experiments on top of the engines: the numerically hard cases ([`stress`]) and accuracy
//! against time ([`tradeoff`]).

pub mod stress;
pub mod tradeoff;
