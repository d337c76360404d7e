//! Call expressions over a composed tree's modules (naga_oil's and WESL's): a name qualified by
//! its module (`ggx::pdf`, `package::sampling::ggx::pdf`, an `#import … as` alias's
//! `alias::pdf`), or a name the sampler's file imports (by that name, or as an `#import a::b::c
//! as name` alias of an item), replaced by the name the composition gave it.

use super::super::CheckError;
use super::super::composition::{Call, UserCode};
use crate::wgsl_tokens::{Kind, Token, paths, tokens, try_replace};

/// `expr` (a call expression of --sample, --pdf or --eval) with each qualified name
/// `module::item` as the user wrote it replaced by that item's name in the composed text, and
/// each name the file imports by that name ([`imported`]) likewise. A module path matches an
/// import's full path or its last segments; `aliases` are (alias, module path). A name no
/// imported module holds is an error naming the imported items.
pub(super) fn resolve(code: &UserCode, call: Call, expr: &str, root_text: &str, aliases: &[(String, String)]) -> Result<String, CheckError> {
    let mut previous: Option<Token> = None;
    try_replace(expr, paths(expr), |t| {
        let member = previous.is_some_and(|p| p.is("."));
        previous = Some(*t);
        match t.kind {
            Kind::Ident if !member => Ok(imported(code, t.text, root_text).or_else(|| item_alias(code, t.text, aliases)).map(str::to_string)),
            Kind::Path => qualified(code, call, expr, &t.segments(), aliases).map(Some),
            _ => Ok(None),
        }
    })
}

/// The composed name of the item `segments` names (`[module…, item]`).
fn qualified(code: &UserCode, call: Call, expr: &str, segments: &[&str], aliases: &[(String, String)]) -> Result<String, CheckError> {
    let (item, module) = segments.split_last().expect("a path has two segments or more");
    let (path, module) = (segments.join("::"), module.join("::"));
    let module = aliases.iter().find(|(a, _)| *a == module).map_or(module.as_str(), |(_, m)| m.as_str());
    let matches = |p: &str| p == module || p.ends_with(&format!("::{module}")) || format!("package::{module}") == p;
    if let Some((name, _, _)) = code.origins.iter().find(|(_, p, it)| it == item && matches(p)) {
        return Ok(name.clone());
    }
    let known: Vec<String> = code.origins.iter().map(|(_, p, it)| format!("{p}::{it}")).collect();
    Err(call.error(
        expr,
        format!(
            "no item `{item}` of a module `{module}` among what the sampler's file imports{} (imported: {}); name an item of a module the file imports, as its import names it",
            crate::suggest::did_you_mean(&path, known.iter().map(String::as_str)),
            if known.is_empty() { "nothing".to_string() } else { known.join(", ") }
        ),
    ))
}

/// The composed name of the item an `#import a::b::item as name` names (Bevy's
/// `tonemapping_luminance as luminance`): `aliases` holds (name, `a::b::item`).
fn item_alias<'a>(code: &'a UserCode, name: &str, aliases: &[(String, String)]) -> Option<&'a str> {
    let (_, target) = aliases.iter().find(|(a, _)| a == name)?;
    let (module, item) = target.rsplit_once("::")?;
    code.origins.iter().find(|(_, p, it)| it == item && p == module).map(|(composed, _, _)| composed.as_str())
}

/// The composed name of `name` where the sampler's file imports it by that name (naga_oil's
/// `#import a::b::{name}`, WESL's `import package::a::name;`): an expression names it as the
/// file does. `None` where no import line names it, or two modules hold an item of that name.
fn imported<'a>(code: &'a UserCode, name: &str, root_text: &str) -> Option<&'a str> {
    let import = |l: &str| l.starts_with("#import ") || l.starts_with("import ");
    let imports = root_text.lines().map(str::trim_start).any(|l| import(l) && tokens(l).any(|t| t.is_name(name)));
    let mut held = code.origins.iter().filter(|(_, _, item)| item == name).map(|(composed, _, _)| composed.as_str());
    let first = held.next()?;
    (imports && held.all(|c| c == first)).then_some(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::compose::Source;
    use crate::check::composition::Dialect;

    /// Bevy's `#import bevy_core_pipeline::tonemapping::tonemapping_luminance as luminance`: a
    /// call expression says `luminance(…)`, as the file does; a member `.luminance` stays.
    #[test]
    fn an_item_imported_under_an_alias_is_named_by_the_alias() {
        let sources = [Source { name: "brdf.wgsl".into(), text: String::new() }];
        let origins = vec![("tonemapping_luminanceX_mod_X".to_string(), "bevy_core_pipeline::tonemapping".to_string(), "tonemapping_luminance".to_string())];
        let code = UserCode::tree(Dialect::NagaOil, &sources, "naga_oil", String::new(), origins);
        let aliases = [("luminance".to_string(), "bevy_core_pipeline::tonemapping::tonemapping_luminance".to_string())];
        let root = "#import bevy_core_pipeline::tonemapping::tonemapping_luminance as luminance\n";
        let out = resolve(&code, Call::Pdf, "1.0 - luminance(c) + s.luminance", root, &aliases).unwrap();
        assert_eq!(out, "1.0 - tonemapping_luminanceX_mod_X(c) + s.luminance");
    }
}
