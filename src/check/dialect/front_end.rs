//! What each dialect's module provides ([`FrontEnd`]), and so what a new dialect is: one file
//! with an implementation of it (`super::Dialect::front_end` lists them).

use super::super::CheckError;
use super::super::compose::Source;
use super::super::composition::{Call, Composition, UserCode};

/// One dialect's front end: how its files are told apart, composed into the WGSL that lobes'
/// glue calls, and how a call expression (`--sample`, `--pdf`, `--eval`) names their functions.
pub(in crate::check) trait FrontEnd: Sync {
    /// Whether `sources` are written in this dialect (the dialects are asked in the order of
    /// `super::SNIFFED`; plain WGSL, asked last, claims every file).
    fn sniff(&self, sources: &[Source]) -> bool;

    /// The files composed: one WGSL part, or (plain WGSL) the files as they are, with where the
    /// names of their modules came from.
    fn compose(&self, sources: &[Source], c: &Composition) -> Result<UserCode, CheckError>;

    /// `expr` with each name as the user's files name it (`ggx::pdf`, an import's alias, a GLSL
    /// function WGSL cannot spell) replaced by its name in `code`'s composed text; `root_text` is
    /// the sampler's file.
    fn call(&self, code: &UserCode, call: Call, expr: &str, root_text: &str) -> Result<String, CheckError>;
}
