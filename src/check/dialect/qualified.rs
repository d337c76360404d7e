//! Call expressions over a composed tree's modules (naga_oil's and WESL's): a name qualified by
//! its module (`ggx::pdf`, `package::sampling::ggx::pdf`, an `#import … as` alias's
//! `alias::pdf`), or a name the sampler's file imports, replaced by the name the composition
//! gave it.

use super::super::CheckError;
use super::super::composition::UserCode;
use crate::wgsl_tokens::{Kind, Token, paths, tokens, try_replace};

/// `expr` (a call expression of --sample, --pdf or --eval) with each qualified name
/// `module::item` as the user wrote it replaced by that item's name in the composed text, and
/// each name the file imports by that name ([`imported`]) likewise. A module path matches an
/// import's full path or its last segments; `aliases` are (alias, module path). A name no
/// imported module holds is an error naming the imported items.
pub(super) fn resolve(code: &UserCode, flag: &str, expr: &str, root_text: &str, aliases: &[(String, String)]) -> Result<String, CheckError> {
    let mut previous: Option<Token> = None;
    try_replace(expr, paths(expr), |t| {
        let member = previous.is_some_and(|p| p.is("."));
        previous = Some(*t);
        match t.kind {
            Kind::Ident if !member => Ok(imported(code, t.text, root_text).map(str::to_string)),
            Kind::Path => qualified(code, flag, expr, &t.segments(), aliases).map(Some),
            _ => Ok(None),
        }
    })
}

/// The composed name of the item `segments` names (`[module…, item]`).
fn qualified(code: &UserCode, flag: &str, expr: &str, segments: &[&str], aliases: &[(String, String)]) -> Result<String, CheckError> {
    let (item, module) = segments.split_last().expect("a path has two segments or more");
    let (path, module) = (segments.join("::"), module.join("::"));
    let module = aliases.iter().find(|(a, _)| *a == module).map_or(module.as_str(), |(_, m)| m.as_str());
    let matches = |p: &str| p == module || p.ends_with(&format!("::{module}")) || format!("package::{module}") == p;
    if let Some((name, _, _)) = code.origins.iter().find(|(_, p, it)| it == item && matches(p)) {
        return Ok(name.clone());
    }
    let known: Vec<String> = code.origins.iter().map(|(_, p, it)| format!("{p}::{it}")).collect();
    Err(CheckError::Input(format!(
        "{flag} '{expr}': no item `{item}` of a module `{module}` among what the sampler's file imports{} (imported: {}); name an item of a module the file imports, as its import names it",
        crate::suggest::did_you_mean(&path, known.iter().map(String::as_str)),
        if known.is_empty() { "nothing".to_string() } else { known.join(", ") }
    )))
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
