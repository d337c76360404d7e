//! Plain WGSL: the files, in order, as they are (their lines keep their numbers in the
//! composition, `compose::Composed`). With `--define` they are naga_oil's (`#ifdef` shader defs).

use super::super::{CheckError, Setting};
use super::super::compose::Source;
use super::super::composition::{Call, Composition, Dialect, UserCode};
use super::front_end::FrontEnd;
use super::naga_oil::{NagaOil, foreign_directives};

/// The plain WGSL front end: what no other dialect claims.
pub(in crate::check) struct Wgsl;

impl FrontEnd for Wgsl {
    fn sniff(&self, _sources: &[Source]) -> bool {
        true
    }

    fn compose(&self, sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
        foreign_directives(sources)?;
        if !c.defines.is_empty() {
            // shader defs of plain files are naga_oil's (#ifdef); with none in the files they are unused
            return NagaOil.compose(sources, c);
        }
        if let Some((m, _)) = c.stubs.first() {
            return Err(CheckError::setting(Setting::Stub, format!("{m}: the files import nothing (no #import or import statement), so there is no module to stand in for")));
        }
        let files = sources.iter().map(|s| s.name.clone()).collect();
        Ok(UserCode { dialect: Dialect::Wgsl, parts: sources.to_vec(), origins: Vec::new(), files, decls: Vec::new(), renamed: Vec::new(), uniforms: Vec::new() })
    }

    /// The expression as it is: plain files import nothing, so a qualified name is an error.
    fn call(&self, code: &UserCode, call: Call, expr: &str, _root_text: &str) -> Result<String, CheckError> {
        if !expr.contains("::") {
            return Ok(expr.to_string());
        }
        Err(call.error(expr, format!("a qualified name (module::function) needs imports, and {} import nothing; name the function as it is declared", code.files.join(", "))))
    }
}
