//! `out` and `inout` parameters in call expressions. naga turns a GLSL `out float pdf` (and an
//! `inout State s`) into a `ptr<function, f32>` parameter, which a WGSL expression cannot pass:
//! it has no variable to point at. A call expression passes such a parameter as GLSL does, by
//! naming a variable: `vec4(SampleGgx(wi, p0, u.xy, pdf), pdf)`. Each bare name at a pointer
//! parameter that is not one of lobes' names nor a name of the module is a variable that lobes
//! declares before the expression (`var pdf: f32;`, zero as GLSL leaves it undefined) and passes
//! by pointer (`&pdf`); any other argument there (`wi`, `p0 * 2.0`) is passed through a pointer
//! to a copy, as GLSL's `inout` copies it in. The expression may be preceded by statements,
//! `;`-separated (`s.roughness = p0; SampleBsdf(s, wi); vec4(s.L, s.pdf)`): the variables are
//! declared before the first.
//!
//! A SPIR-V module passes every parameter by pointer, and lobes calls such a function `NAME`
//! through a wrapper that takes values ([`super::spirv`]); a call that names a variable at a
//! parameter calls `NAME_pointers`, the module's own, instead.

use super::super::CheckError;
use super::super::composition::Call;

/// A function of the translation with pointer parameters: the name a call expression uses, the
/// function called, and per parameter the pointee's type where it is a pointer.
#[derive(Debug, Clone, PartialEq)]
struct Signature {
    name: String,
    target: String,
    params: Vec<Option<String>>,
}

/// lobes' names in call expressions (`rng` is already a pointer and is passed as it is).
fn is_lobes_name(w: &str) -> bool {
    matches!(w, "wi" | "u" | "d" | "p" | "params" | "rng") || w.strip_prefix('p').is_some_and(|n| n.parse::<u32>().is_ok_and(|n| n < 16))
}

/// The parameters of a one-line `fn NAME(a: T, b: ptr<function, U>) -> R {` as naga writes it.
fn parameters(line: &str) -> Option<(String, Vec<Option<String>>)> {
    let rest = line.strip_prefix("fn ")?;
    let (name, rest) = rest.split_once('(')?;
    let (args, _) = rest.rsplit_once(')')?;
    let params = split_top(args, ',').into_iter().filter(|p| !p.trim().is_empty());
    let types = params.map(|p| p.split_once(':').map(|(_, t)| t.trim()).and_then(|t| t.strip_prefix("ptr<function, ")).and_then(|t| t.strip_suffix('>')).map(str::to_string));
    Some((name.trim().to_string(), types.collect()))
}

/// The functions of `text` (naga's WGSL) that take pointers, under the names calls use.
fn signatures(text: &str) -> Vec<Signature> {
    let all: Vec<(String, Vec<Option<String>>)> = text.lines().filter_map(parameters).collect();
    let mut out = Vec::new();
    for (name, params) in &all {
        if params.iter().all(Option::is_none) {
            continue;
        }
        out.push(Signature { name: name.clone(), target: name.clone(), params: params.clone() });
        // SPIR-V: NAME is the wrapper taking values of NAME_pointers
        if let Some(base) = name.strip_suffix("_pointers").filter(|b| all.iter().any(|(n, _)| n == b)) {
            out.push(Signature { name: base.to_string(), target: name.clone(), params: params.clone() });
        }
    }
    out
}

/// The names declared at module scope in `text` (naga's WGSL): not variables of a call.
fn module_names(text: &str) -> Vec<String> {
    let heads = ["fn ", "const ", "var<private> ", "var<workgroup> ", "struct ", "alias ", "override "];
    text.lines()
        .filter_map(|l| heads.iter().find_map(|h| l.strip_prefix(h)))
        .filter_map(|r| r.split(|c: char| !(c.is_alphanumeric() || c == '_')).next())
        .map(str::to_string)
        .collect()
}

/// `s` split at each `sep` outside (), [] and a type's <…> (`array<f32, 4>`, `vec2<f32>`).
fn split_top(s: &str, sep: char) -> Vec<&str> {
    let (mut parts, mut open, mut start, mut word) = (Vec::new(), Vec::new(), 0, String::new());
    for (i, ch) in s.char_indices() {
        match ch {
            '(' | '[' => open.push(ch),
            '<' if ["vec2", "vec3", "vec4", "array", "ptr", "atomic"].contains(&word.as_str()) || (word.len() == 6 && word.starts_with("mat")) => open.push(ch),
            ')' | ']' | '>' if open.last() == Some(&match ch { ')' => '(', ']' => '[', _ => '<' }) => {
                open.pop();
            }
            c if c == sep && open.is_empty() => {
                parts.push(&s[start..i]);
                start = i + ch.len_utf8();
            }
            _ => {}
        }
        if ch.is_alphanumeric() || ch == '_' {
            word.push(ch);
        } else if !ch.is_whitespace() {
            word.clear();
        }
    }
    parts.push(&s[start..]);
    parts
}

/// The rewriting of one call expression: the variables declared so far and the module's names.
struct Rewrite {
    call: Call,
    signatures: Vec<Signature>,
    module: Vec<String>,
    /// `var …;` lines, in order, and the variables' (name, type).
    declared: Vec<String>,
    variables: Vec<(String, String)>,
    copies: usize,
}

impl Rewrite {
    /// `expr` with each call of a function taking pointers passing them.
    fn expression(&mut self, expr: &str) -> Result<String, CheckError> {
        let mut out = String::new();
        let mut rest = expr;
        while let Some((at, name)) = next_call(rest, &self.signatures) {
            out.push_str(&rest[..at]);
            let open = at + name.len() + rest[at + name.len()..].find('(').unwrap_or(0);
            let close = closing(rest, open).ok_or_else(|| self.call.error(expr, format!("`{name}(` is not closed")))?;
            out.push_str(&self.call(&name, &rest[open + 1..close])?);
            rest = &rest[close + 1..];
        }
        out.push_str(rest);
        Ok(out)
    }

    fn call(&mut self, name: &str, args: &str) -> Result<String, CheckError> {
        let args: Vec<&str> = split_top(args, ',').into_iter().map(str::trim).filter(|a| !a.is_empty()).collect();
        let sig = self.signatures.iter().find(|s| s.name == name).cloned().expect("a signature");
        let fresh = |a: &str, me: &Self| super::super::composition::is_name(a) && !is_lobes_name(a) && !me.module.iter().any(|m| m == a);
        let names_variable = args.iter().zip(&sig.params).any(|(a, p)| p.is_some() && fresh(a, self));
        if sig.target != sig.name && !names_variable {
            // SPIR-V's wrapper taking values serves a call that passes values
            let args: Vec<String> = args.iter().map(|a| self.expression(a)).collect::<Result<_, _>>()?;
            return Ok(format!("{name}({})", args.join(", ")));
        }
        if args.len() != sig.params.len() {
            // naga's message about the call names the count
            return Ok(format!("{}({})", sig.target, args.join(", ")));
        }
        let mut passed = Vec::new();
        for (a, p) in args.iter().zip(&sig.params) {
            let Some(ty) = p else {
                passed.push(self.expression(a)?);
                continue;
            };
            passed.push(match *a {
                a if a.starts_with('&') || a == "rng" => a.to_string(),
                a if fresh(a, self) => {
                    self.variable(a, ty)?;
                    format!("&{a}")
                }
                a => {
                    let value = self.expression(a)?;
                    let copy = format!("lobes_arg{}", self.copies);
                    self.copies += 1;
                    self.declared.push(format!("var {copy}: {ty} = {value};"));
                    format!("&{copy}")
                }
            });
        }
        Ok(format!("{}({})", sig.target, passed.join(", ")))
    }

    /// Declares the variable `name` of type `ty` (once; another type is an error).
    fn variable(&mut self, name: &str, ty: &str) -> Result<(), CheckError> {
        match self.variables.iter().find(|(n, _)| n == name) {
            Some((_, t)) if t == ty => Ok(()),
            Some((_, t)) => Err(CheckError::Setting {
                setting: self.call.setting(),
                message: format!("the variable `{name}` is passed to an out/inout parameter of type {t} and to one of type {ty}; give each its own name"),
            }),
            None => {
                self.variables.push((name.to_string(), ty.to_string()));
                self.declared.push(format!("var {name}: {ty};"));
                Ok(())
            }
        }
    }
}

/// The first call in `s` of a function in `signatures`: its offset and name.
fn next_call(s: &str, signatures: &[Signature]) -> Option<(usize, String)> {
    let mut i = 0;
    let bytes = s.as_bytes();
    while i < bytes.len() {
        let c = bytes[i] as char;
        if !(c.is_ascii_alphabetic() || c == '_') || (i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_' || bytes[i - 1] == b'.')) {
            i += 1;
            continue;
        }
        let end = s[i..].find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).map_or(s.len(), |e| i + e);
        let word = &s[i..end];
        if s[end..].trim_start().starts_with('(') && signatures.iter().any(|sig| sig.name == word) {
            return Some((i, word.to_string()));
        }
        i = end;
    }
    None
}

/// The offset of the `)` that closes the `(` at `open`.
pub(crate) fn closing(s: &str, open: usize) -> Option<usize> {
    let mut depth = 0;
    for (i, ch) in s[open..].char_indices() {
        match ch {
            '(' => depth += 1,
            ')' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + i);
                }
            }
            _ => {}
        }
    }
    None
}

/// The `call` expression `expr` over the translation `text`, with its out and inout
/// arguments passed by pointer and the variables they name declared first: `var …; … ; EXPR`.
/// An expression that calls no function taking pointers is returned as it is.
pub(crate) fn rewrite(call: Call, expr: &str, text: &str) -> Result<String, CheckError> {
    let signatures = signatures(text);
    if signatures.is_empty() || split_top(expr, ';').iter().all(|s| next_call(s, &signatures).is_none()) {
        return Ok(expr.to_string());
    }
    let mut r = Rewrite { call, signatures, module: module_names(text), declared: Vec::new(), variables: Vec::new(), copies: 0 };
    let statements: Vec<String> = split_top(expr, ';').into_iter().map(|s| r.expression(s.trim())).collect::<Result<_, _>>()?;
    let statements: Vec<String> = statements.into_iter().filter(|s| !s.is_empty()).collect();
    Ok(r.declared.into_iter().chain(statements.iter().map(|s| format!("{s};"))).collect::<Vec<_>>().join(" ").trim_end_matches(';').to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GLSL: &str = "struct State {\n    a: f32,\n}\n\nfn sample_(V: vec3<f32>, u: vec2<f32>, pdf: ptr<function, f32>) -> vec3<f32> {\n}\n\
        fn step_(s: ptr<function, State>, V_1: vec3<f32>) {\n}\n\
        fn pdf_(V: vec3<f32>) -> f32 {\n}\n";

    #[test]
    fn a_named_out_argument_is_a_variable_declared_first() {
        let e = rewrite(Call::Sample, "vec4(sample_(wi, u.xy, pdf), pdf)", GLSL).unwrap();
        assert_eq!(e, "var pdf: f32; vec4(sample_(wi, u.xy, &pdf), pdf)");
        // an expression without such calls is left alone
        assert_eq!(rewrite(Call::Pdf, "pdf_(wi) * 2.0", GLSL).unwrap(), "pdf_(wi) * 2.0");
    }

    #[test]
    fn statements_and_inout_structs_and_copies() {
        let e = rewrite(Call::Sample, "s.a = p0; step_(s, wi); vec4(s.a)", GLSL).unwrap();
        assert_eq!(e, "var s: State; s.a = p0; step_(&s, wi); vec4(s.a)");
        // a value at a pointer parameter goes through a copy
        let e = rewrite(Call::Sample, "sample_(wi, u.xy, p0 * 2.0)", GLSL).unwrap();
        assert_eq!(e, "var lobes_arg0: f32 = p0 * 2.0; sample_(wi, u.xy, &lobes_arg0)");
    }

    #[test]
    fn spirv_wrappers_are_bypassed_only_for_variables() {
        let text = "fn f_pointers(V: ptr<function, vec3<f32>>, pdf: ptr<function, f32>) -> vec3<f32> {\n}\nfn f(V: vec3<f32>, pdf: f32) -> vec3<f32> {\n}\n";
        assert_eq!(rewrite(Call::Sample, "f(wi, 1.0)", text).unwrap(), "f(wi, 1.0)");
        let e = rewrite(Call::Sample, "vec4(f(wi, q), q)", text).unwrap();
        assert_eq!(e, "var lobes_arg0: vec3<f32> = wi; var q: f32; vec4(f_pointers(&lobes_arg0, &q), q)");
    }

    #[test]
    fn one_variable_of_two_types_is_refused() {
        let text = "fn f(a: ptr<function, f32>, b: ptr<function, vec3<f32>>) -> f32 {\n}\n";
        let e = rewrite(Call::Pdf, "f(x, x)", text).unwrap_err().to_string();
        assert!(e.contains("`x` is passed to an out/inout parameter of type f32 and to one of type vec3<f32>"), "{e}");
    }

    #[test]
    fn commas_inside_types_do_not_split() {
        assert_eq!(split_top("array<f32, 4>(1.0, 2.0, 3.0, 4.0), vec2<f32>(a, b), x < y", ','), vec!["array<f32, 4>(1.0, 2.0, 3.0, 4.0)", " vec2<f32>(a, b)", " x < y"]);
    }
}
