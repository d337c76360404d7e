//! A SPIR-V module (`.spv`, from glslc, glslangValidator, `dxc -spirv`, `slangc -target spirv`)
//! through naga's SPIR-V front end (`spv-in`), translated to WGSL when the file is read
//! (`read`); its functions are named by their debug names (`OpName`), a glslang name's
//! signature (`sample_ggx(vf3;f1;`) dropped. A module without debug names (compiled with `-g0`
//! or stripped) has no names to call.

use super::super::{CheckError, Setting};
use super::super::compose::Source;
use super::super::composition::{Call, Composition, Dialect, UserCode};
use super::front_end::FrontEnd;
use super::translate::{Translation, fall_through, to_wgsl, translated};
use std::path::Path;

/// The SPIR-V front end (the module is translated when it is read: [`read`]).
pub(in crate::check) struct Spirv;

impl FrontEnd for Spirv {
    fn sniff(&self, sources: &[Source]) -> bool {
        sources.iter().any(|s| is_spirv(Path::new(&s.name)))
    }
    fn compose(&self, sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
        translated(Dialect::Spirv, sources, c, || {
            if sources.len() > 1 {
                let files: Vec<&str> = sources.iter().map(|s| s.name.as_str()).collect();
                return Err(CheckError::Input(format!("{}: give one SPIR-V module alone (it is a whole program; link several with spirv-link first)", files.join(", "))));
            }
            if !c.defines.is_empty() {
                return Err(CheckError::setting(Setting::Define, "a SPIR-V module is already compiled; give the defines to the compiler that made it"));
            }
            Ok(Translation { text: sources[0].text.clone(), origins: Vec::new(), uniforms: Vec::new() })
        })
    }
    fn call(&self, code: &UserCode, call: Call, expr: &str, _root_text: &str) -> Result<String, CheckError> {
        super::translate::call(code, call, expr)
    }
}

/// SPIR-V's first word (the SPIR-V specification, 2.3 "Physical Layout").
const MAGIC: u32 = 0x0723_0203;

/// Whether the file is a SPIR-V module: by its `.spv` name.
pub(crate) fn is_spirv(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()) == Some("spv")
}

/// Whether `bytes` start with SPIR-V's magic number (either byte order).
pub(crate) fn has_magic(bytes: &[u8]) -> bool {
    bytes.get(..4).is_some_and(|b| [MAGIC.to_le_bytes(), MAGIC.to_be_bytes()].contains(&[b[0], b[1], b[2], b[3]]))
}

/// The module in `path`, as WGSL: a [`Source`] named by the path.
pub(crate) fn read(path: &Path) -> Result<Source, CheckError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| CheckError::Input(format!("{name}: cannot read the SPIR-V module: {e}")))?;
    from_bytes(&name, &bytes)
}

/// A SPIR-V module's bytes as WGSL, named `name` in messages.
pub fn from_bytes(name: &str, bytes: &[u8]) -> Result<Source, CheckError> {
    if !bytes.len().is_multiple_of(4) || !has_magic(bytes) {
        return Err(CheckError::Input(format!(
            "{name}: not a SPIR-V module ({} bytes, first word {}; a module is 32-bit words starting with 0x07230203)",
            bytes.len(),
            bytes.get(..4).map_or("missing".to_string(), |b| format!("0x{:08x}", u32::from_le_bytes([b[0], b[1], b[2], b[3]])))
        )));
    }
    // naga reads little-endian words; a big-endian module's words are swapped first
    let words: Vec<u8> = if bytes[..4] == MAGIC.to_be_bytes() { bytes.chunks(4).flat_map(|w| [w[3], w[2], w[1], w[0]]).collect() } else { bytes.to_vec() };
    let options = naga::front::spv::Options { adjust_coordinate_space: false, strict_capabilities: false, block_ctx_dump_prefix: None };
    let mut module = crate::engine::gpu::stack::with_big_stack(|| naga::front::spv::parse_u8_slice(&words, &options))
        .map_err(|e| {
            // naga 30 reads no OpLine where glslang's -g puts them (wgpu issue 4532)
            let hint = if e.to_string().contains("instruction Line") { "; compile without -g (OpName, the names lobes needs, is written without it)" } else { "" };
            CheckError::Input(format!("{name}: naga's SPIR-V front end cannot read it: {e}{hint}"))
        })?;
    // a function whose parameters are pointers (glslang and DXC pass every parameter so) is
    // renamed NAME_pointers, and NAME becomes a wrapper that takes values (`by_value`)
    let by_pointer = |f: &naga::Function, types: &naga::UniqueArena<naga::Type>| {
        f.arguments.iter().any(|a| matches!(types[a.ty].inner, naga::TypeInner::Pointer { space: naga::AddressSpace::Function, .. }))
    };
    let mut wrapped = Vec::new();
    for (_, f) in module.functions.iter_mut() {
        f.name = f.name.take().map(|n| debug_name(&n).to_string());
        if let Some(n) = &f.name
            && by_pointer(f, &module.types)
        {
            wrapped.push(n.clone());
            f.name = Some(format!("{n}_pointers"));
        }
    }
    if module.functions.iter().all(|(_, f)| f.name.is_none()) && !module.functions.is_empty() {
        return Err(CheckError::Input(format!(
            "{name}: the module has no debug names (OpName), so lobes cannot find its functions; compile it with debug information (glslc -g, glslangValidator -g, dxc -Zi, slangc -g)"
        )));
    }
    if let Some((_, f)) = fall_through(&mut module) {
        return Err(CheckError::Input(format!("{name}: in `{f}`, a `switch` case falls through into the next one, which WGSL (what lobes runs) cannot express; end each case that has statements with `break` or `return` in the source")));
    }
    let t = to_wgsl(module, name, |e| format!("{name}: error: naga translated the module into one it does not accept: {}", e.as_inner()))?;
    let wrappers: Vec<String> = wrapped.iter().filter_map(|n| by_value(&t.text, n)).collect();
    Ok(Source { name: name.to_string(), text: format!("{}\n{}", t.text, wrappers.join("\n")) })
}

/// `fn NAME(a: T, b: U) -> R`, calling `NAME_pointers` (written in `text` with parameters
/// `ptr<function, T>`) with pointers to copies of its values: a call expression passes values.
fn by_value(text: &str, name: &str) -> Option<String> {
    let line = text.lines().find(|l| l.starts_with(&format!("fn {name}_pointers(")))?;
    let (args, rest) = line[line.find('(')? + 1..].rsplit_once(')')?;
    let result = rest.trim().trim_end_matches('{').trim();
    // the parameters: split at the commas outside <…>
    let (mut params, mut depth, mut start) = (Vec::new(), 0i32, 0);
    for (i, ch) in args.char_indices() {
        match ch {
            '<' => depth += 1,
            '>' => depth -= 1,
            ',' if depth == 0 => {
                params.push(args[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    params.push(args[start..].trim());
    params.retain(|p| !p.is_empty());
    let (mut signature, mut copies, mut call) = (Vec::new(), String::new(), Vec::new());
    for p in params {
        let (arg, ty) = p.split_once(':')?;
        let (arg, ty) = (arg.trim(), ty.trim());
        match ty.strip_prefix("ptr<function, ").and_then(|t| t.strip_suffix('>')) {
            Some(inner) => {
                signature.push(format!("{arg}: {inner}"));
                copies.push_str(&format!("    var {arg}_value = {arg};\n"));
                call.push(format!("&{arg}_value"));
            }
            None => {
                signature.push(p.to_string());
                call.push(arg.to_string());
            }
        }
    }
    let call = format!("{name}_pointers({})", call.join(", "));
    let body = if result.is_empty() { format!("    {call};\n") } else { format!("    return {call};\n") };
    Some(format!("// {name} taking values (the module passes its parameters as pointers)\nfn {name}({}) {result} {{\n{copies}{body}}}\n", signature.join(", ")))
}

/// A function's debug name without glslang's signature: `sample_ggx(vf3;f1;` is `sample_ggx`.
fn debug_name(name: &str) -> &str {
    name.split_once('(').map_or(name, |(n, _)| n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debug_names_lose_glslangs_signature() {
        assert_eq!(debug_name("sample_ggx(vf3;f1;"), "sample_ggx");
        assert_eq!(debug_name("ggx_pdf"), "ggx_pdf");
    }

    #[test]
    fn pointer_parameters_get_a_wrapper_taking_values() {
        let text = "fn pdf_pointers(V: ptr<function, vec3<f32>>, a: ptr<function, f32>, n: u32) -> f32 {\n    return 1f;\n}\n";
        let w = by_value(text, "pdf").unwrap();
        assert!(w.contains("fn pdf(V: vec3<f32>, a: f32, n: u32) -> f32 {") && w.contains("return pdf_pointers(&V_value, &a_value, n);"), "{w}");
        naga::front::wgsl::parse_str(&format!("{text}{w}")).unwrap();
    }

    #[test]
    fn what_is_not_spirv_is_refused() {
        let e = from_bytes("a.spv", b"fn f() {}\n\n\n").unwrap_err().to_string();
        assert!(e.contains("a.spv: not a SPIR-V module") && e.contains("0x07230203"), "{e}");
    }
}
