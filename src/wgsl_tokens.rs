//! WGSL's tokens, as lobes' rewrites of WGSL text read them: names, `::` paths, numbers and
//! punctuation, each with its byte offset, line and column; white space and comments (`//` to the
//! end of the line, `/* … */` nested) are skipped, so that a rewrite copies them as they are.
//!
//! One lexer for every front end and text rule that looks at WGSL words: the embedded library's
//! namespace (`embed::namespace`), the library's imports (`engine::gpu::library`), and `lobes
//! check`'s dialects (`check::dialect`, `check::compose`). It knows no keywords and no grammar; a
//! caller that needs them asks the token's text. (The lowest layer: it imports nothing, and
//! `build.rs` compiles it in with `embed::namespace`.)

/// What a token is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A name: a letter or `_`, then letters, digits and `_` (Unicode letters and digits too,
    /// as WGSL's identifiers allow).
    Ident,
    /// A name followed by `::` and a name, any number of times (`package::a::b`, `ggx::pdf`);
    /// only from [`paths`].
    Path,
    /// A numeric literal with its suffix: `1`, `1u`, `0x1Fu`, `1.5`, `.5`, `1e-3f`, `0x1p-3f`.
    Number,
    /// `::`, or any other one character that is not white space.
    Punct,
}

/// One token of a text: what it is, its text, and where it starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Token<'a> {
    pub kind: Kind,
    pub text: &'a str,
    /// The byte offset of its first character.
    pub start: usize,
    /// Its line, 1-based.
    pub line: usize,
    /// Its column, 1-based, in bytes (as naga's `SourceLocation` counts).
    pub column: usize,
}

impl<'a> Token<'a> {
    /// The byte offset just past its last character.
    pub fn end(&self) -> usize {
        self.start + self.text.len()
    }

    /// Whether it is the punctuation `p` (`"("`, `"::"`, `"@"`).
    pub fn is(&self, p: &str) -> bool {
        self.kind == Kind::Punct && self.text == p
    }

    /// Whether it is the name `name` (a keyword too: the lexer does not tell them apart).
    pub fn is_name(&self, name: &str) -> bool {
        self.kind == Kind::Ident && self.text == name
    }

    /// The segments of a [`Kind::Path`] (`["package", "a", "b"]`), or of a name alone.
    pub fn segments(&self) -> Vec<&'a str> {
        tokens(self.text).filter(|t| t.kind == Kind::Ident).map(|t| t.text).collect()
    }
}

/// The tokens of `text`, in order.
pub fn tokens(text: &str) -> Tokens<'_> {
    Tokens { text, at: 0, line: 1, line_start: 0 }
}

/// The tokens of `text`, with each `name :: name :: …` joined into one [`Kind::Path`] token
/// (white space and comments between its parts belong to its text).
pub fn paths(text: &str) -> impl Iterator<Item = Token<'_>> {
    let mut inner = tokens(text);
    std::iter::from_fn(move || {
        let mut token = inner.next()?;
        while token.kind == Kind::Ident || token.kind == Kind::Path {
            // `::` then a name: part of the path; else the path ends here
            let mut ahead = inner.clone();
            let (Some(sep), Some(name)) = (ahead.next(), ahead.next()) else { break };
            if !(sep.is("::") && name.kind == Kind::Ident) {
                break;
            }
            inner = ahead;
            token = Token { kind: Kind::Path, text: &text[token.start..name.end()], ..token };
        }
        Some(token)
    })
}

/// `text` with each token for which `f` gives a text replaced by it; everything else (white
/// space, comments, the other tokens) kept as it is.
pub fn replace<'a>(text: &'a str, tokens: impl Iterator<Item = Token<'a>>, mut f: impl FnMut(&Token<'a>) -> Option<String>) -> String {
    let never: Result<String, std::convert::Infallible> = try_replace(text, tokens, |t| Ok(f(t)));
    match never {
        Ok(out) => out,
    }
}

/// [`replace`] where `f` may refuse: its first error.
pub fn try_replace<'a, E>(text: &'a str, tokens: impl Iterator<Item = Token<'a>>, mut f: impl FnMut(&Token<'a>) -> Result<Option<String>, E>) -> Result<String, E> {
    let mut out = String::with_capacity(text.len());
    let mut copied = 0;
    for token in tokens {
        if let Some(new) = f(&token)? {
            out.push_str(&text[copied..token.start]);
            out.push_str(&new);
            copied = token.end();
        }
    }
    out.push_str(&text[copied..]);
    Ok(out)
}

/// The 1-based line and column (in bytes, as naga counts) of byte `at` of `text`.
pub fn line_col(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map_or(before.len(), |n| before.len() - n - 1) + 1;
    (line, col)
}

/// The iterator of [`tokens`]: where it is in the text, and the line it is on.
#[derive(Debug, Clone)]
pub struct Tokens<'a> {
    text: &'a str,
    at: usize,
    line: usize,
    /// The byte offset of the current line's first character.
    line_start: usize,
}

impl<'a> Tokens<'a> {
    /// Moves past white space and comments, counting the lines.
    fn skip_blank(&mut self) {
        let rest = &self.text[self.at..];
        let skipped = if rest.starts_with("//") {
            rest.find('\n').unwrap_or(rest.len())
        } else if rest.starts_with("/*") {
            block_comment(rest)
        } else {
            rest.find(|c: char| !c.is_whitespace()).unwrap_or(rest.len())
        };
        for (i, _) in rest[..skipped].match_indices('\n') {
            self.line += 1;
            self.line_start = self.at + i + 1;
        }
        self.at += skipped;
    }

    /// Whether the text at the current offset is white space or a comment.
    fn at_blank(&self) -> bool {
        let rest = &self.text[self.at..];
        rest.starts_with("//") || rest.starts_with("/*") || rest.starts_with(char::is_whitespace)
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = Token<'a>;

    fn next(&mut self) -> Option<Token<'a>> {
        while self.at < self.text.len() && self.at_blank() {
            self.skip_blank();
        }
        let rest = &self.text[self.at..];
        let first = rest.chars().next()?;
        let (kind, len) = if first.is_ascii_digit() || (first == '.' && rest[1..].starts_with(|c: char| c.is_ascii_digit())) {
            (Kind::Number, number(rest))
        } else if first.is_alphabetic() || first == '_' {
            (Kind::Ident, rest.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(rest.len()))
        } else if rest.starts_with("::") {
            (Kind::Punct, 2)
        } else {
            (Kind::Punct, first.len_utf8())
        };
        let token = Token { kind, text: &rest[..len], start: self.at, line: self.line, column: self.at - self.line_start + 1 };
        self.at += len;
        Some(token)
    }
}

/// The length of the block comment that `rest` starts with (nested ones inside it; to the end
/// of the text where it is not closed).
fn block_comment(rest: &str) -> usize {
    let (mut depth, mut i) = (0, 0);
    while i < rest.len() {
        if rest[i..].starts_with("/*") {
            (depth, i) = (depth + 1, i + 2);
        } else if rest[i..].starts_with("*/") {
            (depth, i) = (depth - 1, i + 2);
            if depth == 0 {
                return i;
            }
        } else {
            i += rest[i..].chars().next().map_or(1, char::len_utf8);
        }
    }
    rest.len()
}

/// The length of the number that `rest` starts with: digits, letters (hex digits, the
/// exponent's `e`/`p`, the suffix), `_` and `.`, and the exponent's sign (after `e` in a decimal
/// number, after `p` in a hexadecimal one).
fn number(rest: &str) -> usize {
    let b = rest.as_bytes();
    let hex = b.len() > 1 && b[0] == b'0' && (b[1] == b'x' || b[1] == b'X');
    let exponent = |c: u8| if hex { c == b'p' || c == b'P' } else { c == b'e' || c == b'E' };
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let signed = (c == b'+' || c == b'-') && i > 0 && exponent(b[i - 1]) && b.get(i + 1).is_some_and(u8::is_ascii_digit);
        if !(c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || signed) {
            break;
        }
        i += 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts(text: &str) -> Vec<(Kind, &str)> {
        tokens(text).map(|t| (t.kind, t.text)).collect()
    }

    #[test]
    fn comments_line_and_nested_block_are_skipped() {
        let text = "a // b c\n/* d /* e */ f */ g /* unclosed";
        assert_eq!(texts(text), [(Kind::Ident, "a"), (Kind::Ident, "g")]);
        let g = tokens(text).nth(1).unwrap();
        assert_eq!((g.start, g.line, g.column), (27, 2, 19));
    }

    #[test]
    fn numbers_keep_their_suffixes_and_exponents() {
        let found = texts("1u 0x1Fu 1e-3f 2.5 .5h 1.0e18 0x1p-3f 0x1e-3 7i a-1");
        let numbers: Vec<&str> = found.iter().filter(|(k, _)| *k == Kind::Number).map(|(_, t)| *t).collect();
        // 0x1e-3 is 0x1e minus 3: a hexadecimal number's exponent is `p`
        assert_eq!(numbers, ["1u", "0x1Fu", "1e-3f", "2.5", ".5h", "1.0e18", "0x1p-3f", "0x1e", "3", "7i", "1"]);
        assert_eq!(texts("v2.x")[..2], [(Kind::Ident, "v2"), (Kind::Punct, ".")]);
    }

    #[test]
    fn paths_join_names_and_nothing_else() {
        let found: Vec<(Kind, &str)> = paths("package::a::b(x) + ggx :: pdf + a:: 1 + s.t::").map(|t| (t.kind, t.text)).collect();
        assert_eq!(
            found,
            [
                (Kind::Path, "package::a::b"),
                (Kind::Punct, "("),
                (Kind::Ident, "x"),
                (Kind::Punct, ")"),
                (Kind::Punct, "+"),
                (Kind::Path, "ggx :: pdf"),
                (Kind::Punct, "+"),
                (Kind::Ident, "a"),
                (Kind::Punct, "::"),
                (Kind::Number, "1"),
                (Kind::Punct, "+"),
                (Kind::Ident, "s"),
                (Kind::Punct, "."),
                (Kind::Ident, "t"),
                (Kind::Punct, "::"),
            ]
        );
        assert_eq!(paths("ggx :: pdf").next().unwrap().segments(), ["ggx", "pdf"]);
    }

    #[test]
    fn unicode_names_and_attributes() {
        assert_eq!(texts("fn würfel_2(x: f32)"), [
            (Kind::Ident, "fn"),
            (Kind::Ident, "würfel_2"),
            (Kind::Punct, "("),
            (Kind::Ident, "x"),
            (Kind::Punct, ":"),
            (Kind::Ident, "f32"),
            (Kind::Punct, ")")
        ]);
        let attribute: Vec<&str> = tokens("@group(0) @binding(1) var").map(|t| t.text).collect();
        assert_eq!(attribute, ["@", "group", "(", "0", ")", "@", "binding", "(", "1", ")", "var"]);
        // the column of a token after a multi-byte character counts bytes
        assert_eq!(tokens("é x").nth(1).unwrap().column, 4);
    }

    #[test]
    fn replace_keeps_what_it_does_not_touch() {
        let text = "let PI = 1.0; // PI\n/* PI */ return PI2 + PI;";
        let out = replace(text, tokens(text), |t| t.is_name("PI").then(|| "LOBES_PI".to_string()));
        assert_eq!(out, "let LOBES_PI = 1.0; // PI\n/* PI */ return PI2 + LOBES_PI;");
        let refused: Result<String, &str> = try_replace(text, tokens(text), |t| if t.is_name("return") { Err("no") } else { Ok(None) });
        assert_eq!(refused, Err("no"));
        assert_eq!(line_col("ab\ncd", 4), (2, 2));
    }
}
