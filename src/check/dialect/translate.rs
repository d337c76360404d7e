//! Samplers in languages other than WGSL, read by naga's own front ends into a naga module and
//! written out as WGSL ([`to_wgsl`]), which `lobes check` then composes with its glue as it does
//! a composed WGSL tree; the names the translation could not keep ([`Translation::origins`])
//! and how a call expression reaches them ([`call_names`]). The GLSL and SPIR-V front ends
//! ([`super::glsl`], [`super::spirv`]) share it.

use super::super::{CheckError, Setting};
use super::super::compose::Source;
use super::super::composition::{Call, Composition, Dialect, Origin, UserCode};
use crate::wgsl_tokens::{Kind, tokens, try_replace};

/// The user's files (GLSL, or a SPIR-V module) as the one WGSL part `text` they translate to,
/// with the origins of the names it changed; a `--stub` is refused (there are no modules).
pub(super) fn translated(dialect: Dialect, sources: &[Source], c: &Composition, make: impl FnOnce() -> Result<Translation, CheckError>) -> Result<UserCode, CheckError> {
    let files: Vec<String> = sources.iter().map(|s| s.name.clone()).collect();
    if let Some((m, _)) = c.stubs.first() {
        return Err(CheckError::setting(Setting::Stub, format!("{m}: {} has no modules to stand in for ({} reads the files as they are)", files.join(", "), dialect.name())));
    }
    let Translation { text, origins, uniforms } = make()?;
    let name = format!("<{} translated to WGSL by naga's {} front end>", files.join(", "), dialect.name());
    Ok(UserCode { dialect, parts: vec![Source { name, text }], origins, files, decls: Vec::new(), renamed: Vec::new(), uniforms })
}

/// A module read from another language, as WGSL: its text and where renamed functions came from.
pub(super) struct Translation {
    pub text: String,
    /// (name in `text`, the file, name in the file) of each function WGSL could not name as the
    /// file does, and of every overload of an overloaded name.
    pub origins: Vec<Origin>,
    /// OpenGL's loose uniforms made module variables (GLSL only, [`super::gl_uniforms`]): each
    /// one's name and `file:line`.
    pub uniforms: Vec<(String, String)>,
}

/// `module` (from `file`, without its entry points: lobes calls the functions) validated and
/// written as WGSL. `locate` turns a validation error into a message at the user's file.
pub(super) fn to_wgsl(mut module: naga::Module, file: &str, locate: impl Fn(&naga::WithSpan<naga::valid::ValidationError>) -> String) -> Result<Translation, CheckError> {
    module.entry_points.clear();
    super::super::call_graph::callees_first(&mut module);
    let caps = naga::valid::Capabilities::all();
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps).validate(&module).map_err(|e| CheckError::Wgsl(locate(&e)))?;
    let text = free_writer_names(&super::super::compose::write_wgsl(&module, caps)?);
    // naga's WGSL writer writes the functions in the module's order, each on a line `fn NAME(`
    let written: Vec<&str> = text.lines().filter_map(|l| l.strip_prefix("fn ")).filter_map(|l| l.split_once('(')).map(|(n, _)| n).collect();
    if written.len() != module.functions.len() {
        return Err(CheckError::Internal(format!("{file}: {} functions translated, {} written", module.functions.len(), written.len())));
    }
    let names: Vec<&str> = module.functions.iter().map(|(_, f)| f.name.as_deref().unwrap_or("")).collect();
    let mut origins = Vec::new();
    for (i, (&name, &w)) in names.iter().zip(&written).enumerate() {
        let overloaded = names.iter().enumerate().any(|(j, &n)| j != i && n == name);
        if !name.is_empty() && (w != name || overloaded) {
            origins.push((w.to_string(), file.to_string(), name.to_string()));
        }
    }
    Ok(Translation { text, origins, uniforms: Vec::new() })
}

/// The `switch` cases of `module` that fall through into the next (naga's GLSL front end marks
/// every case that does not end in `break` so) made plain cases where they end in a jump
/// (`return`, `break`, `continue`, `discard`), since WGSL has no fall-through; the first that
/// falls through with statements of its own (WGSL cannot write it): its span and function.
pub(super) fn fall_through(module: &mut naga::Module) -> Option<(naga::Span, String)> {
    let mut found = None;
    for (_, f) in module.functions.iter_mut() {
        let name = f.name.clone().unwrap_or_default();
        if let Some(span) = cases(&mut f.body).filter(|_| found.is_none()) {
            found = Some((span, name));
        }
    }
    found
}

/// [`fall_through`] in one block, its nested blocks included.
fn cases(block: &mut naga::Block) -> Option<naga::Span> {
    use naga::Statement as S;
    let mut found = None;
    let spans: Vec<naga::Span> = block.span_iter().map(|(_, s)| *s).collect();
    for (statement, span) in block.iter_mut().zip(spans) {
        let inner = match statement {
            S::Block(b) => cases(b),
            S::If { accept, reject, .. } => cases(accept).or(cases(reject)),
            S::Loop { body, continuing, .. } => cases(body).or(cases(continuing)),
            S::Switch { cases: list, .. } => {
                let mut bad = None;
                for c in list.iter_mut().filter(|c| c.fall_through && !c.body.is_empty()) {
                    c.fall_through = !ends_in_jump(&c.body);
                    bad = bad.or(c.fall_through.then_some(span));
                }
                list.iter_mut().map(|c| cases(&mut c.body)).fold(bad, Option::or)
            }
            _ => None,
        };
        found = found.or(inner);
    }
    found
}

/// Whether `block` ends in a jump on every path (`return`, `break`, `continue`, `discard`).
fn ends_in_jump(block: &naga::Block) -> bool {
    use naga::Statement as S;
    match block.last() {
        Some(S::Return { .. } | S::Break | S::Continue | S::Kill) => true,
        Some(S::Block(b)) => ends_in_jump(b),
        Some(S::If { accept, reject, .. }) => ends_in_jump(accept) && ends_in_jump(reject),
        _ => false,
    }
}

/// A call expression over a translation's functions as the user's files name them
/// ([`call_names`]), with its out and inout arguments passed as WGSL passes them
/// ([`super::out_params`]).
pub(super) fn call(code: &UserCode, call: Call, expr: &str) -> Result<String, CheckError> {
    let named = call_names(call, expr, &code.origins)?;
    super::out_params::rewrite(call, &named, &code.parts[0].text)
}

/// A call expression (`--sample`, `--pdf`, `--eval`) over the functions as the user's file names
/// them, with each name that the translation wrote differently replaced by the name written. An
/// overloaded name is an error naming the translation's names of its overloads.
pub(super) fn call_names(call: Call, expr: &str, origins: &[Origin]) -> Result<String, CheckError> {
    try_replace(expr, tokens(expr).filter(|t| t.kind == Kind::Ident), |t| {
        let word = t.text;
        let written: Vec<&str> = origins.iter().filter(|o| o.2 == word).map(|o| o.0.as_str()).collect();
        match written[..] {
            [] => Ok(None),
            [w] => Ok(Some(w.to_string())),
            _ => Err(call.error(
                expr,
                format!(
                    "`{word}` is overloaded in {}; in the translation its overloads are {} (in the order declared): call the one you mean by that name",
                    origins.iter().find(|o| o.2 == word).map_or("", |o| o.1.as_str()),
                    written.iter().map(|w| format!("`{w}`")).collect::<Vec<_>>().join(", ")
                ),
            )),
        }
    })
}

/// naga's WGSL writer names the values it binds `_eN`, from the expression's index, whatever
/// names the module holds: written again after naga reads them back as named values, two would
/// be `_e8` in one function. The translation's are renamed `_glslN`.
fn free_writer_names(text: &str) -> String {
    let index = |t: &str| t.strip_prefix("_e").filter(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit())).map(str::to_string);
    crate::wgsl_tokens::replace(text, tokens(text), |t| index(t.text).filter(|_| t.kind == Kind::Ident).map(|n| format!("_glsl{n}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn call_names_follow_the_translation() {
        let origins = vec![
            ("saturate_".to_string(), "a.glsl".to_string(), "saturate".to_string()),
            ("rnd".to_string(), "a.glsl".to_string(), "rnd".to_string()),
            ("rnd_1".to_string(), "a.glsl".to_string(), "rnd".to_string()),
        ];
        assert_eq!(call_names(Call::Pdf, "saturate(d.z) * p0 + saturated", &origins).unwrap(), "saturate_(d.z) * p0 + saturated");
        let e = call_names(Call::Sample, "f(wi, rnd(u.x))", &origins).unwrap_err().to_string();
        assert!(e.contains("`rnd` is overloaded in a.glsl") && e.contains("`rnd`, `rnd_1`"), "{e}");
    }

    #[test]
    fn writer_names_are_freed_outside_numbers_and_longer_names() {
        assert_eq!(free_writer_names("let _e8 = _e12 + _e + x_e3 + 1e3;"), "let _glsl8 = _glsl12 + _e + x_e3 + 1e3;");
    }
}
