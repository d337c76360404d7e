//! WESL's conditional blocks, `@if(expr) { … } @elif(expr) { … } @else { … }`, resolved before
//! the `wesl` crate (0.4) reads a module.
//!
//! The WESL specification (ConditionalTranslation.md) puts `@if` on single syntax nodes, with
//! `@elif`/`@else` among its "possible future extensions": each decorates the next sibling of an
//! `@if`/`@elif` node and is kept only where every earlier condition of the chain is false.
//! wesl-rs 0.5 added blocks: an `@if`/`@elif`/`@else` before `{ … }`, at module scope or in a
//! function, is *flattened* — the block's items become its parent's, with no scope of their own
//! (wesl-rs PR #237 "Blocks preceded by `@if` are flattened", its spec tests
//! `condcomp-flatten.json`; wesl-spec issue #158). Bevy's main branch relies on them (module-scope
//! bind groups under `@if(BINDLESS) { … } @else { … }`), and `wesl` 0.4, the last release that
//! builds on rustc 1.95, cannot parse a block at module scope and scopes one in a function.
//!
//! [`resolve`] evaluates every chain that has a block with the features given, flattening the
//! chosen block and blanking the others; members of such a chain that decorate single nodes are
//! rewritten so that 0.4 keeps or drops them alike. Chains without a block are left to the
//! crate. Removed text becomes spaces, newlines kept, so every line keeps its number and, but
//! for a rewritten `@elif`/`@else` before a single node, every character its column.

use std::collections::HashMap;

/// A malformed conditional attribute: the byte it starts at, and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockError {
    pub at: usize,
    pub message: String,
}

/// What the translate-time expressions allow (ConditionalTranslation.md, "Definitions").
const EXPRESSIONS: &str =
    "a translate-time expression is a feature name, true, false, !, &&, || and parentheses, e.g. @if(BINDLESS && !MESHLET)";

/// One `@if`, `@elif` or `@else` attribute and what it decorates.
#[derive(Debug, Clone)]
struct Member {
    kind: Kind,
    /// The attribute's text: from `@` to its closing `)` (or the end of `else`).
    attr: (usize, usize),
    /// The condition (`@if`, `@elif`), already evaluated.
    value: bool,
    /// The block it decorates: its `{` and its matching `}`.
    block: Option<(usize, usize)>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    If,
    Elif,
    Else,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::If => "@if",
            Kind::Elif => "@elif",
            Kind::Else => "@else",
        }
    }
}

/// `text` with its conditional blocks resolved under `features` (a feature not named is false,
/// as the `wesl` crate's default); unchanged where it has none.
pub fn resolve(text: &str, features: &HashMap<String, bool>) -> Result<String, BlockError> {
    if !text.contains('@') {
        return Ok(text.to_string());
    }
    let chains = chains(text, features)?;
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    for chain in chains.iter().filter(|c| c.iter().any(|m| m.block.is_some())) {
        edits.extend(chain_edits(text, chain));
    }
    Ok(apply(text, edits))
}

/// The edits of one chain: the first member whose condition holds (an `@else` always does) is
/// kept, the others removed.
fn chain_edits(text: &str, chain: &[Member]) -> Vec<(usize, usize, String)> {
    let chosen = chain.iter().position(|m| m.kind == Kind::Else || m.value);
    let mut edits = Vec::new();
    for (i, m) in chain.iter().enumerate() {
        let keep = chosen == Some(i);
        match (m.block, keep) {
            // flattened: the attribute and the braces go, the items stay
            (Some((open, close)), true) => {
                edits.push(blank(text, m.attr.0, open + 1));
                edits.push(blank(text, close, close + 1));
            }
            (Some((_, close)), false) => edits.push(blank(text, m.attr.0, close + 1)),
            // a single node: 0.4 decides an `@if` itself, with the same features
            (None, _) if m.kind == Kind::If => {}
            (None, true) => edits.push(blank(text, m.attr.0, m.attr.1)),
            (None, false) => {
                let width = m.attr.1 - m.attr.0;
                edits.push((m.attr.0, m.attr.1, format!("{:<width$}", "@if(false)")));
            }
        }
    }
    edits
}

/// An edit replacing `text[start..end]` by spaces, its newlines kept.
fn blank(text: &str, start: usize, end: usize) -> (usize, usize, String) {
    let spaces = text[start..end].chars().map(|c| if c == '\n' || c == '\r' { c } else { ' ' }).collect();
    (start, end, spaces)
}

/// `text` with `edits` applied; an edit inside another's range (a chain nested in a removed
/// block) is dropped.
fn apply(text: &str, mut edits: Vec<(usize, usize, String)>) -> String {
    edits.sort_by_key(|e| (e.0, std::cmp::Reverse(e.1)));
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (start, end, with) in edits {
        if start < at {
            continue;
        }
        out.push_str(&text[at..start]);
        out.push_str(&with);
        at = end;
    }
    out.push_str(&text[at..]);
    out
}

/// The chains of conditional attributes of `text`, in order. A chain is an `@if` and the
/// `@elif`/`@else` after it among the same siblings (the same nesting of braces, parentheses
/// and brackets).
fn chains(text: &str, features: &HashMap<String, bool>) -> Result<Vec<Vec<Member>>, BlockError> {
    let b = text.as_bytes();
    let mut chains: Vec<Vec<Member>> = Vec::new();
    // per nesting level: the chain its siblings continue (an index into `chains`)
    let mut open: Vec<Option<usize>> = vec![None];
    let mut i = 0;
    while i < b.len() {
        if let Some(end) = comment_end(b, i) {
            i = end;
            continue;
        }
        match b[i] {
            b'{' | b'(' | b'[' => open.push(None),
            b'}' | b')' | b']' if open.len() > 1 => {
                open.pop();
            }
            b'@' => {
                if let Some(m) = attribute(text, i, features)? {
                    i = m.attr.1;
                    add(text, &mut chains, open.last_mut().expect("the module level"), m)?;
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
    Ok(chains)
}

/// `m` added to its level's chain: an `@if` starts one, `@elif`/`@else` continue the open one.
/// A block's end is known, so a chain whose block is not followed by `@elif`/`@else` ends there
/// (a single node's end is the `wesl` crate's to find).
fn add(text: &str, chains: &mut Vec<Vec<Member>>, level: &mut Option<usize>, m: Member) -> Result<(), BlockError> {
    let ends = m.block.is_some_and(|(_, close)| !continued(text, close + 1));
    if m.kind == Kind::If {
        chains.push(vec![m]);
        *level = (!ends).then_some(chains.len() - 1);
        return Ok(());
    }
    let what = m.kind.name();
    let Some(chain) = level.map(|c| &mut chains[c]) else {
        return Err(BlockError {
            at: m.attr.0,
            message: format!("{what} without an @if before it: {what} decorates the next sibling of an @if or @elif (as `@if(A) {{ … }} {what} {{ … }}`)"),
        });
    };
    if chain.last().is_some_and(|l| l.kind == Kind::Else) {
        return Err(BlockError { at: m.attr.0, message: format!("{what} after an @else: the @else ends its chain; start a new one with @if") });
    }
    chain.push(m);
    if ends {
        *level = None;
    }
    Ok(())
}

/// Whether the next token from `at` on is an `@elif` or `@else` attribute.
fn continued(text: &str, at: usize) -> bool {
    let b = text.as_bytes();
    let i = skip_blank(b, at);
    if b.get(i) != Some(&b'@') {
        return false;
    }
    let name = &text[skip_blank(b, i + 1)..];
    ["elif", "else"].iter().any(|k| name.strip_prefix(k).is_some_and(|r| !r.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_')))
}

/// Where a comment that starts at `i` ends (WGSL: `//` to the line's end, `/* */` nested).
fn comment_end(b: &[u8], i: usize) -> Option<usize> {
    if b[i..].starts_with(b"//") {
        return Some(b[i..].iter().position(|&c| c == b'\n').map_or(b.len(), |n| i + n));
    }
    if !b[i..].starts_with(b"/*") {
        return None;
    }
    let (mut depth, mut j) = (0usize, i);
    while j < b.len() {
        if b[j..].starts_with(b"/*") {
            depth += 1;
            j += 2;
        } else if b[j..].starts_with(b"*/") {
            depth -= 1;
            j += 2;
            if depth == 0 {
                return Some(j);
            }
        } else {
            j += 1;
        }
    }
    Some(b.len())
}

/// The index of the first byte after `i` that is not blank space or a comment.
fn skip_blank(b: &[u8], mut i: usize) -> usize {
    while i < b.len() {
        if let Some(end) = comment_end(b, i) {
            i = end;
        } else if b[i].is_ascii_whitespace() {
            i += 1;
        } else {
            break;
        }
    }
    i
}

/// The conditional attribute at `at` (a `@`), or `None` for any other attribute.
fn attribute(text: &str, at: usize, features: &HashMap<String, bool>) -> Result<Option<Member>, BlockError> {
    let b = text.as_bytes();
    let name_at = skip_blank(b, at + 1);
    let name_end = name_at + b[name_at..].iter().take_while(|c| c.is_ascii_alphanumeric() || **c == b'_').count();
    let kind = match &text[name_at..name_end] {
        "if" => Kind::If,
        "elif" => Kind::Elif,
        "else" => Kind::Else,
        _ => return Ok(None),
    };
    let after = skip_blank(b, name_end);
    let (value, end) = match kind {
        Kind::Else if b.get(after) == Some(&b'(') => {
            return Err(BlockError { at, message: "@else takes no condition: write @else, or @elif(expr) for another condition".into() });
        }
        Kind::Else => (true, name_end),
        _ => condition(text, at, kind, after, features)?,
    };
    let next = skip_blank(b, end);
    let block = if b.get(next) == Some(&b'{') { Some((next, matching_brace(text, next, kind, at)?)) } else { None };
    Ok(Some(Member { kind, attr: (at, end), value, block }))
}

/// The condition of `@if`/`@elif` whose `(` is at `open`: its value, and the byte after `)`.
fn condition(text: &str, at: usize, kind: Kind, open: usize, features: &HashMap<String, bool>) -> Result<(bool, usize), BlockError> {
    let b = text.as_bytes();
    let what = kind.name();
    if b.get(open) != Some(&b'(') {
        return Err(BlockError { at, message: format!("{what} needs a condition in parentheses: {what}(FEATURE); {EXPRESSIONS}") });
    }
    let mut depth = 0;
    let close = (open..b.len()).find(|&j| {
        match b[j] {
            b'(' => depth += 1,
            b')' => depth -= 1,
            _ => {}
        }
        depth == 0
    });
    let Some(close) = close else {
        return Err(BlockError { at, message: format!("{what}( has no closing parenthesis; {EXPRESSIONS}") });
    };
    let expr = &text[open + 1..close];
    let value = Expr::new(expr, features)
        .parse()
        .map_err(|why| BlockError { at, message: format!("{what}({}): {why}; {EXPRESSIONS}", expr.trim()) })?;
    Ok((value, close + 1))
}

/// The `}` that closes the block whose `{` is at `open`, comments skipped.
fn matching_brace(text: &str, open: usize, kind: Kind, at: usize) -> Result<usize, BlockError> {
    let b = text.as_bytes();
    let (mut depth, mut j) = (0i32, open);
    while j < b.len() {
        if let Some(end) = comment_end(b, j) {
            j = end;
            continue;
        }
        match b[j] {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return Ok(j);
                }
            }
            _ => {}
        }
        j += 1;
    }
    Err(BlockError { at, message: format!("the block of this {} has no closing `}}`", kind.name()) })
}

/// A translate-time expression, parsed and evaluated at once: `||` over `&&` over `!` over a
/// feature, `true`, `false` or a parenthesized expression.
struct Expr<'a> {
    tokens: Vec<&'a str>,
    at: usize,
    features: &'a HashMap<String, bool>,
}

impl<'a> Expr<'a> {
    fn new(text: &'a str, features: &'a HashMap<String, bool>) -> Self {
        let mut tokens = Vec::new();
        let mut rest = text.trim_start();
        while !rest.is_empty() {
            let n = if rest.starts_with("&&") || rest.starts_with("||") {
                2
            } else {
                let word = rest.bytes().take_while(|c| c.is_ascii_alphanumeric() || *c == b'_').count();
                word.max(rest.chars().next().map_or(1, char::len_utf8))
            };
            tokens.push(&rest[..n]);
            rest = rest[n..].trim_start();
        }
        Expr { tokens, at: 0, features }
    }

    fn parse(mut self) -> Result<bool, String> {
        if self.tokens.is_empty() {
            return Err("an empty condition".into());
        }
        let v = self.or()?;
        match self.tokens.get(self.at) {
            None => Ok(v),
            Some(t) => Err(format!("`{t}` is not allowed here")),
        }
    }

    fn or(&mut self) -> Result<bool, String> {
        let mut v = self.and()?;
        while self.eat("||") {
            v |= self.and()?;
        }
        Ok(v)
    }

    fn and(&mut self) -> Result<bool, String> {
        let mut v = self.not()?;
        while self.eat("&&") {
            v &= self.not()?;
        }
        Ok(v)
    }

    fn not(&mut self) -> Result<bool, String> {
        if self.eat("!") {
            return Ok(!self.not()?);
        }
        let Some(&t) = self.tokens.get(self.at) else { return Err("the condition ends too early".into()) };
        self.at += 1;
        match t {
            "(" => {
                let v = self.or()?;
                if self.eat(")") { Ok(v) } else { Err("a `(` without its `)`".into()) }
            }
            "true" => Ok(true),
            "false" => Ok(false),
            _ if t.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') => Ok(self.features.get(t).copied().unwrap_or(false)),
            _ => Err(format!("`{t}` is not allowed here")),
        }
    }

    fn eat(&mut self, token: &str) -> bool {
        let hit = self.tokens.get(self.at) == Some(&token);
        self.at += usize::from(hit);
        hit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on(names: &[&str]) -> HashMap<String, bool> {
        names.iter().map(|n| (n.to_string(), true)).collect()
    }

    /// The text without blank space, for comparing with the spec tests' expected WGSL.
    fn squeeze(s: &str) -> String {
        s.split_whitespace().collect::<Vec<_>>().join(" ")
    }

    /// wesl-rs's spec tests `condcomp-flatten.json` (module and function scope), in our words.
    #[test]
    fn blocks_flatten_as_wesl_rs_does() {
        let cases = [
            ("fn f() {} @if(A) { const_assert true; fn foo() {} struct bar { x: u32 } }", &["A"][..], "fn f() {} const_assert true; fn foo() {} struct bar { x: u32 }"),
            ("fn f() {} @if(A) { fn foo() {} }", &[][..], "fn f() {}"),
            ("@if(A) { const foo: u32 = 0; } @elif(B) { const bar: u32 = 0; }", &["B"][..], "const bar: u32 = 0;"),
            ("@if(A) { const foo: u32 = 0; } @elif(B) { const bar: u32 = 0; }", &["A", "B"][..], "const foo: u32 = 0;"),
            ("@if(A) { const a = 0; } @elif(B) { const b = 0; } @else { const c = 0; }", &[][..], "const c = 0;"),
            ("@if(A) { @if(B) { fn x() {} } @else { fn y() {} } } @else { fn z() {} }", &["A"][..], "fn y() {}"),
            ("@if(A) { @if(B) { fn x() {} } @else { fn y() {} } } @else { fn z() {} }", &["B"][..], "fn z() {}"),
            ("fn f() { @if(A) { let x = 1; } @else { let x = 2; } let y = x; }", &[][..], "fn f() { let x = 2; let y = x; }"),
            ("fn f() { @if(!A && (B || false)) { let x = 1; } }", &["B"][..], "fn f() { let x = 1; }"),
        ];
        for (src, features, want) in cases {
            let out = resolve(src, &on(features)).unwrap();
            assert_eq!(squeeze(&out), want, "{src} with {features:?}");
            assert_eq!(out.len(), src.len(), "{src}: the columns are kept");
        }
    }

    /// A chain of single nodes is the crate's; one with a block has its single members rewritten.
    #[test]
    fn single_nodes_are_left_or_rewritten() {
        let src = "@if(A) const a = 1;\n@else const a = 2;\n";
        assert_eq!(resolve(src, &on(&[])).unwrap(), src);
        let src = "@if(A) const a = 1;\n@elif(BB) { const a = 2; }\n@else const a = 3;\n";
        let out = resolve(src, &on(&["BB"])).unwrap();
        assert_eq!(out.lines().nth(2), Some("@if(false) const a = 3;"));
        assert_eq!(out.lines().nth(1).map(str::trim), Some("const a = 2;"));
        assert_eq!(out.lines().count(), 3);
    }

    #[test]
    fn comments_and_other_attributes_are_no_conditions() {
        let src = "// @if(A) {\n/* @else { /* nested */ } */\n@group(0) @binding(1) var<uniform> u: f32;\n@if(A) { const b = 1; } // }\n";
        let out = resolve(src, &on(&[])).unwrap();
        assert!(out.starts_with("// @if(A) {\n/* @else"), "{out}");
        assert!(!out.contains("const b"), "{out}");
        assert_eq!(out.lines().count(), src.lines().count());
    }

    #[test]
    fn malformed_conditions_say_what_and_where() {
        let err = |src: &str| resolve(src, &on(&[])).unwrap_err();
        let e = err("const a = 1;\n@if(A +) { const b = 2; }");
        assert_eq!((e.at, e.message.starts_with("@if(A +): `+` is not allowed here")), (13, true), "{e:?}");
        assert!(e.message.contains(EXPRESSIONS));
        assert!(err("@else { }").message.starts_with("@else without an @if before it"));
        assert!(err("@if(A) x; @else y; @else z;").message.starts_with("@else after an @else"));
        assert!(err("@if(A) { } fn f() {} @else { }").message.starts_with("@else without an @if before it"));
        assert!(err("@if A { }").message.starts_with("@if needs a condition in parentheses"));
        assert!(err("@if(A { }").message.contains("no closing parenthesis"));
        assert!(err("@if(A) { const b = 1;").message.contains("no closing `}`"));
        assert!(err("@if() { }").message.contains("an empty condition"));
        assert!(err("@else(A) { }").message.starts_with("@else takes no condition"));
    }
}
