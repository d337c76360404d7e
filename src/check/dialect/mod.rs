//! The front ends of `lobes check`, one module per dialect, each a `FrontEnd`: how its files
//! are told apart ([`sniff`]), composed into the WGSL that lobes' glue calls, and how a call
//! expression (`--sample`, `--pdf`, `--eval`) names their functions.
//!
//! - plain WGSL (`wgsl`): the files, in order, as they are;
//! - naga_oil (`naga_oil`): `#define_import_path`, `#import`, `#ifdef` shader defs, composed by
//!   naga_oil's `Composer` over the modules under the shader roots (`roots`);
//! - WESL (`wesl`): `import package::a::b;`, `@if` features, composed by the `wesl` crate
//!   (feature "wesl") with lobes' resolver (`wesl_resolver`) and conditional blocks
//!   ([`wesl_blocks`]);
//! - GLSL ([`glsl`]): naga's GLSL front end (Vulkan GLSL 440–460), after lobes' `#include`
//!   expansion, with errors at the user's file and line;
//! - SPIR-V ([`spirv`]): naga's SPIR-V front end, functions named by their debug names (`OpName`).
//!
//! GLSL and SPIR-V are translated to WGSL by naga (`translate`); where WGSL cannot spell a
//! function's name (a WGSL reserved word such as `saturate`, an overloaded GLSL function), the
//! names written are recorded as origins, so that `--rand` and call expressions name the
//! functions as the user's file does. Composing a tree is slow ([`stage`] says what is being
//! composed); `super::modules` keeps the trees composed and calls the front ends.
//!
//! A new dialect is a variant of [`Dialect`], a module here with its `FrontEnd`, its arm in
//! `Dialect::front_end` and its place in [`SNIFFED`].

pub(super) mod front_end;
mod gl_uniforms;
pub mod glsl;
pub(super) mod naga_oil;
pub mod out_params;
mod qualified;
pub(super) mod roots;
pub mod spirv;
pub mod stage;
mod translate;
pub(super) mod wesl;
pub mod wesl_blocks;
#[cfg(feature = "wesl")]
mod wesl_resolver;
pub(super) mod wgsl;

use super::CheckError;
use super::compose::Source;
use super::composition::Dialect;
use front_end::FrontEnd;

// A file's dialect decides how it is read, so the reading is the front ends' (here), not the
// type's (`compose`, below them).
impl Source {
    /// Reads a WGSL file, naming it by its path.
    pub fn read(path: &std::path::Path) -> Result<Self, CheckError> {
        if spirv::is_spirv(path) {
            return spirv::read(path);
        }
        let text = std::fs::read_to_string(path).map_err(|e| match std::fs::read(path) {
            Ok(b) if spirv::has_magic(&b) => CheckError::Input(format!("{}: a SPIR-V module: name it FILE.spv", path.display())),
            _ => CheckError::Input(format!("{}: cannot read the shader file: {e}", path.display())),
        })?;
        Ok(Self { name: path.display().to_string(), text })
    }
}

/// The dialects in the order they are asked whether the files are theirs: a SPIR-V module by its
/// `.spv` name, GLSL by its extension or a `#version` line, naga_oil by a directive, WESL by a
/// `.wesl` file or an `import …;` statement; plain WGSL claims what is left.
pub const SNIFFED: [Dialect; 5] = [Dialect::Spirv, Dialect::Glsl, Dialect::NagaOil, Dialect::Wesl, Dialect::Wgsl];

/// The dialect of the files, from their names and text ([`SNIFFED`]).
pub fn sniff(sources: &[Source]) -> Dialect {
    SNIFFED.into_iter().find(|d| d.front_end().sniff(sources)).unwrap_or(Dialect::Wgsl)
}

impl Dialect {
    /// The front end that reads files of this dialect.
    pub(in crate::check) fn front_end(self) -> &'static dyn FrontEnd {
        match self {
            Dialect::Wgsl => &wgsl::Wgsl,
            Dialect::NagaOil => &naga_oil::NagaOil,
            Dialect::Wesl => &wesl::Wesl,
            Dialect::Glsl => &glsl::Glsl,
            Dialect::Spirv => &spirv::Spirv,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dialects() {
        let s = |name: &str, text: &str| vec![Source { name: name.into(), text: text.into() }];
        assert_eq!(sniff(&s("a.wgsl", "fn f() {}")), Dialect::Wgsl);
        assert_eq!(sniff(&s("a.wgsl", "#import a::b::{c}\nfn f() {}")), Dialect::NagaOil);
        assert_eq!(sniff(&s("a.wgsl", "import package::maths::pi;\nfn f() {}")), Dialect::Wesl);
        assert_eq!(sniff(&s("a.wesl", "fn f() {}")), Dialect::Wesl);
        assert_eq!(sniff(&s("a.frag", "#import a::b\nvoid f() {}")), Dialect::Glsl);
        assert_eq!(sniff(&s("a.spv", "")), Dialect::Spirv);
    }
}
