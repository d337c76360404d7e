//! Why a check could not be run, as opposed to a check that ran and failed.

use super::{Message, Setting};
use crate::engine::gpu::GpuError;

/// Why a check could not be run (as opposed to a check that ran and failed).
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// Bad input: a flag, a file, a function name.
    #[error("{0}")]
    Input(String),
    /// Bad input whose message names the settings that would mend it (the command line shows
    /// each by its flag, a scene by its key).
    #[error("{0}")]
    Advised(Message),
    /// The user's WGSL does not parse or validate; the message points at file:line:column.
    #[error("{0}")]
    Wgsl(String),
    /// The device failed (lost, out of memory, readback).
    #[error("the GPU failed: {0}")]
    Device(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A setting of [`super::Settings`] out of its range, named by its [`Setting`] (the command line
    /// says its flag, a scene its key).
    #[error("{}: {message}", setting.key())]
    Setting { setting: Setting, message: String },
    /// A fault of lobes itself.
    #[error("internal error in lobes check: {0}")]
    Internal(String),
    /// The expected histogram is not accurate enough to judge by (the quadrature of the pdf did
    /// not converge, [`super::quadrature::Integrals::converged`]): no verdict, neither pass nor fail
    /// (exit 3, as `lobes run`'s unconverged reference); the message may name settings.
    #[error("{0}")]
    NoVerdict(Message),
}

impl CheckError {
    /// A setting's error: `message` says what is wrong with its value.
    pub fn setting(setting: Setting, message: impl Into<String>) -> Self {
        CheckError::Setting { setting, message: message.into() }
    }

    /// Whether the error is the user's input (exit code 2) rather than a failure to run (1).
    pub fn is_input(&self) -> bool {
        matches!(self, CheckError::Input(_) | CheckError::Advised(_) | CheckError::Wgsl(_) | CheckError::Setting { .. })
    }
}
