//! The layers of `src/` import downwards only: no two top-level modules import each other.
//!
//! A module's imports are the `crate::` paths in its files' code (`use crate::a::…`,
//! `use crate::{a::…, b}` and inline `crate::a::f()`), comments and doc links left out.
//! (`src/lib.rs` lists the layers in order.)

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The code of a Rust file without its comments: lines that start with `//` (doc comments and
/// doc links among them) are dropped, and a trailing ` // …` is cut (rustfmt puts a space
/// before it, which a `"// …"` in a string of generated WGSL does not have).
fn strip_comments(text: &str) -> String {
    text.lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .map(|line| line.find(" //").map_or(line, |i| &line[..i]))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The top-level modules named by the `crate::` paths of `code`.
fn imported_modules(code: &str) -> BTreeSet<String> {
    let ident = |s: &str| s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect::<String>();
    let mut found = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let after = code[i + "crate::".len()..].trim_start();
        if let Some(group) = after.strip_prefix('{') {
            // `crate::{a::x, b, c::{y, z}}`: the first name of each item at depth 1
            let mut depth = 1;
            let mut item_start = true;
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 1 => break,
                    '}' => depth -= 1,
                    ',' if depth == 1 => item_start = true,
                    c if item_start && !c.is_whitespace() => {
                        found.insert(ident(&group[j..]));
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            found.insert(ident(after));
        }
    }
    found.retain(|m| !m.is_empty() && m != "self");
    found
}

/// Which top-level module imports which, over the files of `src/`.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for path in rust_files(src) {
        let relative = path.strip_prefix(src).unwrap();
        let first = relative.components().next().unwrap().as_os_str().to_string_lossy().into_owned();
        let module = first.trim_end_matches(".rs").to_string();
        if module == "lib" || module == "main" {
            continue;
        }
        let imports = imported_modules(&strip_comments(&std::fs::read_to_string(&path).unwrap()));
        graph.entry(module.clone()).or_default().extend(imports.into_iter().filter(|m| *m != module));
    }
    graph
}

/// The `.rs` files under `dir`, in every folder.
fn rust_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let (mut files, mut stack) = (Vec::new(), vec![dir.to_path_buf()]);
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files
}

/// The pairs (a, b), a < b, of modules that import each other.
fn mutual_imports(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<(String, String)> {
    let mut pairs = Vec::new();
    for (a, targets) in graph {
        for b in targets {
            if a < b && graph.get(b).is_some_and(|t| t.contains(a)) {
                pairs.push((a.clone(), b.clone()));
            }
        }
    }
    pairs
}

#[test]
fn no_two_top_level_modules_import_each_other() {
    let graph = module_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    // the walk found the layers (a sanity check of the walk itself)
    for (module, imports) in [("engine", "reference"), ("run", "engine"), ("report", "run")] {
        assert!(graph[module].contains(imports), "{module} should import {imports}: {graph:?}");
    }
    let cycles = mutual_imports(&graph);
    assert!(cycles.is_empty(), "top-level modules that import each other: {cycles:?}\nall imports: {graph:#?}");
}

#[test]
fn the_parser_sees_every_form_of_import_and_no_comment() {
    let code = strip_comments(
        "use crate::engine::job::Job;\n\
         use crate::{stats::chi2, report, scene::{Case, Scene}};\n\
         /// [`crate::cli`] is a doc link\n\
         // use crate::check; commented out\n\
         let x = 1; // crate::embed in a trailing comment\n\
         fn f() { let s = \"// not a comment\"; crate::run::judge(s); }\n\
         fn g() -> crate::reference::Lobe { todo!() }\n",
    );
    let found: Vec<String> = imported_modules(&code).into_iter().collect();
    assert_eq!(found, ["engine", "reference", "report", "run", "scene", "stats"]);

    let graph: BTreeMap<String, BTreeSet<String>> = [
        ("a".to_string(), BTreeSet::from(["b".to_string()])),
        ("b".to_string(), BTreeSet::from(["a".to_string(), "c".to_string()])),
        ("c".to_string(), BTreeSet::new()),
    ]
    .into();
    assert_eq!(mutual_imports(&graph), [("a".to_string(), "b".to_string())]);
}

// ---- the submodules: no circle among the children of any module ----

/// The code of a Rust file with its comments (line, block, doc) and the contents of its string
/// and char literals blanked, newlines kept: what is left is only tokens the compiler reads as
/// code, so a `crate::` or a `{` in a string of generated WGSL counts for nothing.
fn code_of(text: &str) -> String {
    let s: Vec<char> = text.chars().collect();
    let blank = |out: &mut String, chars: &[char]| out.extend(chars.iter().map(|&c| if c == '\n' { '\n' } else { ' ' }));
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let (mut out, mut i) = (String::new(), 0);
    while i < s.len() {
        let start_of_token = i == 0 || !ident(s[i - 1]);
        let rest = &s[i..];
        let end = if rest.starts_with(&['/', '/']) {
            rest.iter().position(|&c| c == '\n').unwrap_or(rest.len())
        } else if rest.starts_with(&['/', '*']) {
            let (mut depth, mut j) = (1, 2);
            while j < rest.len() && depth > 0 {
                if rest[j..].starts_with(&['/', '*']) {
                    (depth, j) = (depth + 1, j + 2);
                } else if rest[j..].starts_with(&['*', '/']) {
                    (depth, j) = (depth - 1, j + 2);
                } else {
                    j += 1;
                }
            }
            j
        } else if let Some(open) = raw_string_opening(rest).filter(|_| start_of_token) {
            // r"…", r#"…"#, br"…": ends at the quote followed by as many hashes
            let hashes = rest[..open].iter().filter(|&&c| c == '#').count();
            let close = |j: &usize| rest[*j] == '"' && rest[*j + 1..].iter().take(hashes).filter(|&&c| c == '#').count() == hashes;
            (open..rest.len()).find(close).map_or(rest.len(), |j| j + 1 + hashes)
        } else if rest[0] == '"' || (start_of_token && rest.starts_with(&['b', '"'])) {
            let mut j = rest.iter().position(|&c| c == '"').unwrap() + 1;
            while j < rest.len() && rest[j] != '"' {
                j += if rest[j] == '\\' { 2 } else { 1 };
            }
            j + 1
        } else if rest[0] == '\'' && (rest.get(1) == Some(&'\\') || rest.get(2) == Some(&'\'')) {
            // a char literal ('x', '\n', '\u{7f}'), not a lifetime ('a)
            2 + rest[2..].iter().position(|&c| c == '\'').unwrap_or(rest.len() - 2) + 1
        } else {
            out.push(s[i]);
            i += 1;
            continue;
        };
        let end = end.min(rest.len());
        blank(&mut out, &rest[..end]);
        i += end;
    }
    out
}

/// Where the contents of a raw string start, if `rest` opens one (`r"`, `r#"`, `br##"`, …).
fn raw_string_opening(rest: &[char]) -> Option<usize> {
    let after_r = match rest {
        ['r', ..] => 1,
        ['b', 'r', ..] => 2,
        _ => return None,
    };
    let hashes = rest[after_r..].iter().take_while(|&&c| c == '#').count();
    (rest.get(after_r + hashes) == Some(&'"')).then_some(after_r + hashes + 1)
}

/// The tokens of code (from [`code_of`]): identifiers and keywords, `::`, and single punctuation.
fn tokens(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut chars = code.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        if c.is_alphanumeric() || c == '_' {
            let mut end = i + c.len_utf8();
            while let Some(&(j, d)) = chars.peek().filter(|(_, d)| d.is_alphanumeric() || *d == '_') {
                end = j + d.len_utf8();
                chars.next();
            }
            out.push(code[i..end].to_string());
        } else if c == ':' && chars.peek().is_some_and(|&(_, d)| d == ':') {
            chars.next();
            out.push("::".to_string());
        } else if !c.is_whitespace() {
            out.push(c.to_string());
        }
    }
    out
}

/// One path a file names: its segments as written (`super`, `crate`, `self` kept), the name it
/// is known by where it is a `use` (`as` renames it; `None` for a glob and for inline paths),
/// the inline modules (`mod tests { … }`) it sits in, and whether it is a `use` at the top of
/// its file (which the module's other files may reach through `super::NAME`).
#[derive(Debug, PartialEq)]
struct NamedPath {
    segments: Vec<String>,
    alias: Option<String>,
    inline: Vec<String>,
    top_use: bool,
}

/// Every path `code`'s tokens name: each leaf of each `use` tree (`use a::{b, c::{d as e}}`
/// gives `a::b` and `a::c::d`), and the inline paths that start with `crate::`, `super::` or
/// `self::` (`crate::run::judge(…)`, `super::Settings`).
fn named_paths(tokens: &[String]) -> Vec<NamedPath> {
    let (mut found, mut inline, mut depth, mut i) = (Vec::new(), Vec::<(String, usize)>::new(), 0, 0);
    let inline_names = |inline: &[(String, usize)]| inline.iter().map(|(name, _)| name.clone()).collect::<Vec<_>>();
    while i < tokens.len() {
        let t = tokens[i].as_str();
        match t {
            "{" => depth += 1,
            "}" => {
                depth -= 1;
                if inline.last().is_some_and(|&(_, d)| d == depth) {
                    inline.pop();
                }
            }
            "mod" if tokens.get(i + 2).is_some_and(|t| t == "{") => inline.push((tokens[i + 1].clone(), depth)),
            "use" => {
                let mut leaves = Vec::new();
                i = use_tree(tokens, i + 1, &mut Vec::new(), &mut leaves);
                let top_use = depth == 0;
                found.extend(leaves.into_iter().map(|(segments, alias)| NamedPath { segments, alias, inline: inline_names(&inline), top_use }));
                continue;
            }
            // a path after `::` continues one; after `in`, it is a visibility (`pub(in crate::check)`), not a use
            "crate" | "super" | "self" if tokens.get(i + 1).is_some_and(|t| t == "::") && (i == 0 || !["::", "in"].contains(&tokens[i - 1].as_str())) => {
                let mut segments = vec![t.to_string()];
                i += 1;
                while tokens.get(i).is_some_and(|t| t == "::") && tokens.get(i + 1).is_some_and(|t| t.chars().all(|c| c.is_alphanumeric() || c == '_')) {
                    segments.push(tokens[i + 1].clone());
                    i += 2;
                }
                found.push(NamedPath { segments, alias: None, inline: inline_names(&inline), top_use: false });
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    found
}

/// Reads the `use` tree that starts at `tokens[i]` under the path `prefix`, pushing each leaf
/// (its segments and the name it brings in) onto `leaves`; returns where the tree ends.
fn use_tree(tokens: &[String], mut i: usize, prefix: &mut Vec<String>, leaves: &mut Vec<(Vec<String>, Option<String>)>) -> usize {
    let depth = prefix.len();
    loop {
        match tokens.get(i).map(String::as_str) {
            Some("{") => {
                i += 1;
                while tokens.get(i).is_some_and(|t| t != "}") {
                    i = use_tree(tokens, i, prefix, leaves);
                    if tokens.get(i).is_some_and(|t| t == ",") {
                        i += 1;
                    }
                }
                i += 1;
                break;
            }
            Some("*") => {
                leaves.push((prefix.clone(), None));
                i += 1;
                break;
            }
            Some(name) if name.chars().all(|c| c.is_alphanumeric() || c == '_') => {
                prefix.push(name.to_string());
                i += 1;
                if tokens.get(i).is_some_and(|t| t == "::") {
                    i += 1;
                    continue;
                }
                let mut segments = prefix.clone();
                let mut alias = segments.last().cloned();
                if tokens.get(i).is_some_and(|t| t == "as") {
                    alias = tokens.get(i + 1).cloned();
                    i += 2;
                }
                if segments.last().is_some_and(|s| s == "self") {
                    segments.pop();
                    if alias.as_deref() == Some("self") {
                        alias = segments.last().cloned();
                    }
                }
                leaves.push((segments, alias));
                break;
            }
            _ => break,
        }
    }
    prefix.truncate(depth);
    if depth == 0 && tokens.get(i).is_some_and(|t| t == ";") {
        i += 1;
    }
    i
}

/// The node that stands for a module's own file (its `mod.rs`) among its children.
const OWN_FILE: &str = "mod.rs";

/// The modules of `src/` (`src/a/b.rs` and `src/a/b/mod.rs` are `a::b`), each with the paths
/// its file names; `lib.rs` and `main.rs` are left out (the crate root only lists the layers).
fn crate_files(src: &Path) -> BTreeMap<Vec<String>, Vec<NamedPath>> {
    let mut files = BTreeMap::new();
    for path in rust_files(src) {
        let relative = path.strip_prefix(src).unwrap();
        if relative == Path::new("lib.rs") || relative == Path::new("main.rs") {
            continue;
        }
        let mut module: Vec<String> = relative.with_extension("").iter().map(|c| c.to_string_lossy().into_owned()).collect();
        if module.last().is_some_and(|m| m == "mod") {
            module.pop();
        }
        let text = std::fs::read_to_string(&path).unwrap();
        files.insert(module, named_paths(&tokens(&code_of(&text))));
    }
    files
}

/// The absolute path (without `crate`) that `path`, named in the file of `module`, stands for;
/// `None` for another crate's path (`std::…`, `wgpu::…`) or a name the file brought in itself.
fn absolute(module: &[String], path: &NamedPath, modules: &BTreeSet<Vec<String>>) -> Option<Vec<String>> {
    let mut here: Vec<String> = module.iter().chain(&path.inline).cloned().collect();
    let segments = &path.segments;
    match segments.first()?.as_str() {
        "crate" => Some(segments[1..].to_vec()),
        "self" => Some(here.into_iter().chain(segments[1..].iter().cloned()).collect()),
        "super" => {
            let supers = segments.iter().take_while(|s| *s == "super").count();
            here.truncate(here.len().checked_sub(supers)?);
            Some(here.into_iter().chain(segments[supers..].iter().cloned()).collect())
        }
        first => {
            here.push(first.to_string());
            modules.contains(&here).then(|| module.iter().chain(&path.inline).chain(segments).cloned().collect())
        }
    }
}

/// The module an absolute path leads to: its longest prefix that is a module, followed through
/// the `use`s at the top of that module's file (`super::Composition` in `check/gpu.rs` leads to
/// `check::modules`, where `check/mod.rs` brings `Composition` in from).
fn target(path: &[String], modules: &BTreeSet<Vec<String>>, uses: &BTreeMap<(Vec<String>, String), Vec<String>>) -> Vec<String> {
    let mut path = path.to_vec();
    for _ in 0..16 {
        let k = (0..=path.len()).rev().find(|&k| modules.contains(&path[..k]) || k == 0).unwrap();
        match path.get(k).and_then(|name| uses.get(&(path[..k].to_vec(), name.clone()))) {
            Some(to) => path = to.iter().chain(&path[k + 1..]).cloned().collect(),
            None => return path[..k].to_vec(),
        }
    }
    panic!("a circle of `use`s through {path:?}")
}

/// For each module with children, which of its children imports which: `a::b::c` naming
/// `crate::a::b::d::f` is the edge c → d among the children of `a::b`; a child naming its
/// parent's own items (`super::Settings`, defined in `check/mod.rs`) is child → [`OWN_FILE`],
/// and the parent's file naming a child's is [`OWN_FILE`] → child.
fn submodule_graphs(src: &Path) -> BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> {
    let files = crate_files(src);
    let modules: BTreeSet<Vec<String>> = files.keys().cloned().chain([vec![]]).collect();
    let mut uses = BTreeMap::new();
    for (module, paths) in &files {
        for path in paths.iter().filter(|p| p.top_use && p.inline.is_empty()) {
            if let (Some(alias), Some(to)) = (&path.alias, absolute(module, path, &modules)) {
                uses.insert((module.clone(), alias.clone()), to);
            }
        }
    }
    let mut graphs: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (module, paths) in &files {
        for path in paths {
            let Some(to) = absolute(module, path, &modules).map(|p| target(&p, &modules, &uses)) else { continue };
            let k = module.iter().zip(&to).take_while(|(a, b)| a == b).count();
            let from = module.get(k).map_or(OWN_FILE, String::as_str);
            let to_child = to.get(k).map_or(OWN_FILE, String::as_str);
            if from != to_child {
                graphs.entry(module[..k].to_vec()).or_default().entry(from.to_string()).or_default().insert(to_child.to_string());
            }
        }
    }
    graphs
}

/// The circles of `graph`: each strongly connected set of two or more nodes, as one circle
/// through it from its first node (`["compose", "counting", "dispatch", "compose"]`).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    let reach = |from: &String| {
        let (mut seen, mut stack) = (BTreeSet::new(), vec![from.clone()]);
        while let Some(n) = stack.pop() {
            for m in graph.get(&n).into_iter().flatten() {
                if seen.insert(m.clone()) {
                    stack.push(m.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&String, BTreeSet<String>> = graph.keys().map(|n| (n, reach(n))).collect();
    let mut placed = BTreeSet::new();
    let mut found = Vec::new();
    for (n, from_n) in &reached {
        if placed.contains(*n) || !from_n.contains(*n) {
            continue;
        }
        let set: BTreeSet<&String> = from_n.iter().filter(|m| reached.get(m).is_some_and(|r| r.contains(*n))).collect();
        placed.extend(set.iter().map(|m| (*m).clone()));
        // the shortest way round from n, breadth first inside the set
        let mut back: BTreeMap<&String, &String> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([*n]);
        'search: while let Some(a) = queue.pop_front() {
            for b in graph.get(a).into_iter().flatten().filter(|b| set.contains(b)) {
                if b == *n {
                    let mut circle = vec![b.clone(), a.clone()];
                    while let Some(&p) = back.get(circle.last().unwrap()) {
                        circle.push(p.clone());
                    }
                    circle.reverse();
                    found.push(circle);
                    break 'search;
                }
                if b != *n && !back.contains_key(b) {
                    back.insert(b, a);
                    queue.push_back(b);
                }
            }
        }
    }
    found
}

/// Every circle among the children of a module, as `"engine::gpu: compose → counting → …"`.
fn submodule_circles(src: &Path) -> Vec<String> {
    let mut found = Vec::new();
    for (parent, graph) in submodule_graphs(src) {
        for circle in circles(&graph) {
            found.push(format!("{}: {}", if parent.is_empty() { "crate".to_string() } else { parent.join("::") }, circle.join(" → ")));
        }
    }
    found
}

#[test]
fn no_submodule_imports_a_module_that_imports_it_back() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graphs = submodule_graphs(&src);
    // the walk and the resolution of `use`s found the edges (a check of the test itself)
    let gpu = &graphs[&vec!["engine".to_string(), "gpu".to_string()]];
    assert!(gpu["engine"].contains("dispatch") && gpu["dispatch"].contains("context"), "{gpu:#?}");
    // `super::SampleReturns` in check/gpu.rs is `check::composition`'s, through check/mod.rs
    assert!(graphs[&vec!["check".to_string()]]["gpu"].contains("composition"));
    let found = submodule_circles(&src);
    assert!(found.is_empty(), "circles among submodules (an import that closes one moves the shared piece down a layer): {found:#?}");
}

#[test]
fn the_submodule_parser_resolves_paths_and_skips_strings_and_inline_modules() {
    let code = code_of(
        "use super::{a::{self, X}, b::Y as Z};\n\
         /* crate::c::hidden /* nested */ */ let s = r#\"crate::d::f \"{\"#; let c = '{';\n\
         fn f<'a>(x: &'a str) { crate::e::g(super::super::h::I); }\n\
         pub(in crate::m) fn v() {}\n\
         #[cfg(test)]\nmod tests { use super::*; use super::super::j::K; }\n",
    );
    let paths = named_paths(&tokens(&code));
    let seen: Vec<(String, Option<&str>, String)> =
        paths.iter().map(|p| (p.segments.join("::"), p.alias.as_deref(), p.inline.join("::"))).collect();
    let own = |s: &str, a: Option<&'static str>, m: &str| (s.to_string(), a, m.to_string());
    assert_eq!(
        seen,
        [
            own("super::a", Some("a"), ""),
            own("super::a::X", Some("X"), ""),
            own("super::b::Y", Some("Z"), ""),
            own("crate::e::g", None, ""),
            own("super::super::h::I", None, ""),
            own("super", None, "tests"),
            own("super::super::j::K", Some("K"), "tests"),
        ]
    );
    // inside `mod tests` of m/n.rs, `super` is m::n and `super::super` is m
    let modules: BTreeSet<Vec<String>> = [vec![], vec!["m".to_string()], vec!["m".to_string(), "n".to_string()]].into();
    let m_n = ["m".to_string(), "n".to_string()];
    assert_eq!(absolute(&m_n, &paths[5], &modules).unwrap(), m_n);
    assert_eq!(absolute(&m_n, &paths[6], &modules).unwrap(), ["m", "j", "K"]);
    assert_eq!(absolute(&m_n, &paths[0], &modules).unwrap(), ["m", "a"]);
    // a name brought in by a parent's `use` leads to where it came from
    let uses = BTreeMap::from([((vec!["m".to_string()], "Z".to_string()), vec!["m".to_string(), "n".to_string(), "Y".to_string()])]);
    assert_eq!(target(&["m".to_string(), "Z".to_string()], &modules, &uses), m_n);

    let graph: BTreeMap<String, BTreeSet<String>> = [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")]
        .iter()
        .map(|(a, b)| (a.to_string(), BTreeSet::from([b.to_string()])))
        .collect();
    assert_eq!(circles(&graph), [["a", "b", "c", "a"]]);
}

/// Every file of tests/ is a module of the one test binary (tests/main.rs, with Cargo.toml's
/// `autotests = false`): a file it did not name would never be compiled, its tests never run.
#[test]
fn every_test_file_is_a_module_of_the_test_binary() {
    let tests = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let main = std::fs::read_to_string(tests.join("main.rs")).unwrap();
    let declared: BTreeSet<&str> = main.lines().filter_map(|l| l.strip_prefix("mod ")?.strip_suffix(';')).collect();
    let mut files = BTreeSet::new();
    for entry in std::fs::read_dir(&tests).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let module = if path.is_dir() { path.join("mod.rs").is_file() } else { path.extension().is_some_and(|e| e == "rs") && name != "main" };
        if module {
            files.insert(name);
        }
    }
    let missing: Vec<&String> = files.iter().filter(|f| !declared.contains(f.as_str())).collect();
    assert!(missing.is_empty(), "tests/main.rs does not name {missing:?}: add `mod NAME;` there, or their tests never run");
    assert!(declared.len() > 40 && declared.iter().all(|d| files.contains(*d)), "tests/main.rs names {declared:?}; tests/ has {files:?}");
}
