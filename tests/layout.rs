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
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let relative = path.strip_prefix(src).unwrap();
            let first = relative.components().next().unwrap().as_os_str().to_string_lossy().into_owned();
            let module = first.trim_end_matches(".rs").to_string();
            if module == "lib" || module == "main" {
                continue;
            }
            let imports = imported_modules(&strip_comments(&std::fs::read_to_string(&path).unwrap()));
            graph.entry(module.clone()).or_default().extend(imports.into_iter().filter(|m| *m != module));
        }
    }
    graph
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
