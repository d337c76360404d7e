//! The `lobes` namespace of the embedded WGSL: every module-scope name a module defines gets a
//! prefix on export (`ggx_sample_vndf` → `lobes_ggx_sample_vndf`, `PI` → `LOBES_PI`,
//! `LobeSample` → `LobesLobeSample`), by rewriting identifier tokens of the WGSL text.
//!
//! WGSL has no namespaces, and a renderer's shader is one module with its own `PI`, `sample` or
//! `stretch`; so what [`super::wgsl`] returns renames whatever it defines. The library files
//! keep their short names (they are naga_oil modules, and naga_oil namespaces by import path):
//! the rename is done on the exported text, token by token (`crate::wgsl_tokens`): comments are
//! copied unchanged, an identifier is renamed only as a whole token and only where it can name a
//! module-scope declaration (not after `.`, a member or swizzle, nor after `@`, an attribute).
//! Renaming every occurrence of a name is an α-renaming, so the code stays the same; `tests` in
//! `super` parse both texts with naga and compare their IR with the names mapped.

use crate::wgsl_tokens::{Kind, Token, replace, tokens};

/// The exported name of `name` under `prefix` (`"lobes"`, or `"lobes_lights"` for a discrete
/// table named `lights`): `SHOUTING` constants get `PREFIX_`, `CamelCase` types `Prefix`
/// (the prefix in camel case), everything else `prefix_`.
///
/// ```
/// # use lobes::embed::prefixed;
/// assert_eq!(prefixed("lobes", "ggx_sample_vndf"), "lobes_ggx_sample_vndf");
/// assert_eq!(prefixed("lobes", "PI"), "LOBES_PI");
/// assert_eq!(prefixed("lobes", "LobeSample"), "LobesLobeSample");
/// assert_eq!(prefixed("lobes_lights", "DiscreteInfo"), "LobesLightsDiscreteInfo");
/// ```
pub fn prefixed(prefix: &str, name: &str) -> String {
    let first_upper = name.starts_with(|c: char| c.is_ascii_uppercase());
    if first_upper && !name.chars().any(|c| c.is_ascii_lowercase()) {
        format!("{}_{name}", prefix.to_ascii_uppercase())
    } else if first_upper {
        let camel: String = prefix.split('_').map(|w| w[..1].to_ascii_uppercase() + &w[1..]).collect();
        format!("{camel}{name}")
    } else {
        format!("{prefix}_{name}")
    }
}

/// `source` with every identifier token `t` that can name a module-scope declaration replaced by
/// `rename(t)` where that is `Some`; comments (`//` and nested `/* */`), literals, members and
/// swizzles (after `.`) and attributes (after `@`) are left as they are.
pub(crate) fn rename(source: &str, rename: impl Fn(&str) -> Option<String>) -> String {
    let mut previous: Option<Token> = None;
    replace(source, tokens(source), |t| {
        let member_or_attribute = previous.is_some_and(|p| p.is(".") || p.is("@"));
        previous = Some(*t);
        (t.kind == Kind::Ident && !member_or_attribute).then(|| rename(t.text)).flatten()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_whole_identifier_tokens_outside_comments_are_renamed() {
        let map = |t: &str| (t == "PI" || t == "wr" || t == "e").then(|| format!("X{t}"));
        let src = "// PI in a comment\nconst PI = 1.0e18; /* PI /* nested PI */ PI */ fn f(s: S) -> f32 { return s.wr + PI + PIE + wr; }\n@e fn g() {}";
        let out = rename(src, map);
        assert_eq!(out, "// PI in a comment\nconst XPI = 1.0e18; /* PI /* nested PI */ PI */ fn f(s: S) -> f32 { return s.wr + XPI + PIE + Xwr; }\n@e fn g() {}");
    }

    #[test]
    fn a_member_after_white_space_is_still_a_member() {
        let out = rename("let x = s .  wr;", |t| (t == "wr").then(|| "lobes_wr".into()));
        assert_eq!(out, "let x = s .  wr;");
    }
}
