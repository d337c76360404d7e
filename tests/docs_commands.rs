//! The documentation cannot rot: every shell line in a ```sh block of README.md,
//! CONTRIBUTING.md and docs/*.md is run with the built binary (or, where it cannot run here,
//! checked to be one of the forms listed below), `docs/scenes.md` holds exactly what
//! `lobes scene --template` prints, `lobes --help` lists the main commands before the tutorial's,
//! and every relative link points at a file. CONTRIBUTING.md ("Documentation commands are
//! tests") describes the block kinds to authors.
//!
//! Block kinds, by the fence's info string:
//! - `sh`: each line runs with bash in a temporary folder holding copies of `scenes/`,
//!   `examples/` and `tests/fixtures/repository/` (the renderer trees of
//!   docs/samplers-in-repositories.md), `lobes` first on PATH and `cargo run --release -- ARGS` run as `lobes ARGS`;
//!   one folder per page, lines in order. Exit 0, or the code of a trailing `# exit N`. Not run:
//!   `bash .ci/install &&` (apt; the rest of the line runs), `cargo test`, `cargo clippy`,
//!   `duplicates` (the suite and the tools), `cargo run --example NAME` (its code runs in
//!   tests/embed.rs, which must include examples/NAME.rs).
//! - `sh install`: platform install commands (and a private driver copy's set-up and use);
//!   nothing runs, each line must be one.
//! - `sh cluster`: scheduler scripts; `lobes` lines are run with `--help` appended (clap checks
//!   the subcommand and every flag and value before it prints the help), other lines must be
//!   scheduler commands.
//! - `sh dev`: development commands (cargo, duplicates, .ci scripts); nothing runs.
//!
//! Code blocks of docs/embedding.md run too (`the_embedding_pages_code_runs`): its `rust`
//! blocks are doctests of `lobes::embed` (the page is included there), and its `wgsl` imports
//! compile with the `wesl` crate against the files its `sh` line writes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const LOBES: &str = env!("CARGO_BIN_EXE_lobes");
/// The longest a documented command may take (the slowest, the README's main job at 10⁷
/// samples per case, takes ~15 s on two lavapipe cores).
const TIMEOUT: Duration = Duration::from_secs(300);
/// Pages other branches write, linked before they arrive.
const ARRIVING: [&str; 0] = [];

/// README.md, CONTRIBUTING.md and docs/*.md, as paths relative to the repository.
fn pages() -> Vec<String> {
    let mut docs: Vec<String> = std::fs::read_dir(Path::new(ROOT).join("docs"))
        .expect("docs/")
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".md"))
        .map(|n| format!("docs/{n}"))
        .collect();
    docs.sort();
    let mut all = vec!["README.md".to_string(), "CONTRIBUTING.md".to_string()];
    all.extend(docs);
    all
}

fn read(page: &str) -> String {
    std::fs::read_to_string(Path::new(ROOT).join(page)).unwrap_or_else(|e| panic!("{page}: {e}"))
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Run,
    Install,
    Cluster,
    Dev,
}

/// One logical line of a shell block: its 1-based line number in the page, the text (`\`
/// continuations joined) and the block's kind.
struct Line {
    number: usize,
    text: String,
    kind: Kind,
}

/// The shell lines of a page's fenced blocks; an unknown shell-like info string is an error.
fn shell_lines(page: &str, text: &str, errors: &mut Vec<String>) -> Vec<Line> {
    let mut out = Vec::new();
    // The open fence's backtick count and its kind (None: a block that is not a shell block).
    let mut block: Option<(usize, Option<Kind>)> = None;
    let mut pending: Option<Line> = None;
    for (i, raw) in text.lines().enumerate() {
        let number = i + 1;
        let trimmed = raw.trim();
        let ticks = trimmed.len() - trimmed.trim_start_matches('`').len();
        if ticks >= 3 {
            let info = &trimmed[ticks..];
            if let Some((open, _)) = block {
                if ticks >= open && info.trim().is_empty() {
                    block = None;
                    if let Some(p) = pending.take() {
                        errors.push(format!("{page}:{}: a `\\` continuation runs into the end of the block", p.number));
                    }
                }
                continue;
            }
            let info = info.trim();
            let first = info.split_whitespace().next().unwrap_or("");
            block = Some((ticks, match info {
                "sh" => Some(Kind::Run),
                "sh install" => Some(Kind::Install),
                "sh cluster" => Some(Kind::Cluster),
                "sh dev" => Some(Kind::Dev),
                _ if first == "sh" || ["bash", "shell", "console", "zsh", "sh-session", "shell-session", "shellsession"].contains(&first) => {
                    errors.push(format!("{page}:{number}: shell block ```{info}: use ```sh (run), ```sh install, ```sh cluster or ```sh dev"));
                    None
                }
                _ => None,
            }));
            continue;
        }
        let Some((_, Some(kind))) = block else { continue };
        let line = match pending.take() {
            Some(mut p) => {
                p.text.push(' ');
                p.text.push_str(trimmed);
                p
            }
            None => Line { number, text: trimmed.to_string(), kind },
        };
        if let Some(head) = line.text.strip_suffix('\\') {
            pending = Some(Line { text: head.trim_end().to_string(), ..line });
        } else if !line.text.is_empty() {
            out.push(line);
        }
    }
    out
}

/// The code a `# exit N` comment at the end of the line asks for (0 without one).
fn expected_exit(line: &str) -> i32 {
    line.rfind('#')
        .and_then(|at| line[at + 1..].trim().strip_prefix("exit "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or(0)
}

/// The line without leading `VAR=value` assignments (for recognising its command).
fn command_of(line: &str) -> &str {
    let mut rest = line.trim();
    while let Some((word, after)) = rest.split_once(' ') {
        if word.contains('=') && !word.starts_with('-') && !word.contains('(') {
            rest = after.trim_start();
        } else {
            break;
        }
    }
    rest
}

fn starts_with_word(line: &str, word: &str) -> bool {
    line == word || line.starts_with(&format!("{word} "))
}

/// Runs `script` with bash in `dir`, `lobes` first on PATH; None when it ran past the timeout.
fn bash(script: &str, dir: &Path, bin: &Path, env: &[(&str, &str)]) -> Option<Output> {
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let mut child = Command::new("bash")
        .arg("-c")
        .arg(script)
        .current_dir(dir)
        .env("PATH", path)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bash");
    // Read the pipes on threads so that a talkative command cannot fill them and stall.
    let mut stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut stdout, &mut v).ok();
        v
    });
    let err = std::thread::spawn(move || {
        let mut v = Vec::new();
        std::io::Read::read_to_end(&mut stderr, &mut v).ok();
        v
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > TIMEOUT {
            child.kill().ok();
            child.wait().ok();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Some(Output { status, stdout: out.join().unwrap(), stderr: err.join().unwrap() })
}

fn tail(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(8)..].join("\n    ")
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if entry.file_type().unwrap().is_dir() {
            if entry.file_name() != "target" {
                copy_tree(&src, &dst);
            }
        } else {
            std::fs::copy(&src, &dst).unwrap();
        }
    }
}

/// A folder with `lobes` in it, for PATH.
fn bin_dir(tmp: &Path) -> PathBuf {
    let bin = tmp.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(LOBES, bin.join("lobes")).unwrap();
    bin
}

/// A `cargo test --test NAME [MODULE::…]` names the one test binary, `integration`, and a module
/// of it that is a file of tests/ (tests/main.rs).
fn test_target_exists(cmd: &str) -> Result<(), String> {
    let Some(rest) = cmd.split("--test ").nth(1) else { return Ok(()) };
    let mut words = rest.split_whitespace();
    if words.next() != Some("integration") {
        return Err("the tests are one binary: `--test integration MODULE::` (tests/main.rs)".into());
    }
    match words.next().and_then(|w| w.split_once("::")) {
        Some((module, _)) if !Path::new(ROOT).join(format!("tests/{module}.rs")).is_file() => Err(format!("tests/{module}.rs does not exist")),
        _ => Ok(()),
    }
}

/// Checks a line of a `sh` block that is not run; Err(why) when it is no listed form.
fn not_run_form(cmd: &str) -> Option<Result<(), String>> {
    let cmd = command_of(cmd);
    if starts_with_word(cmd, "cargo test") {
        return Some(test_target_exists(cmd));
    }
    if ["cargo clippy", "duplicates"].iter().any(|w| starts_with_word(cmd, w)) {
        return Some(Ok(()));
    }
    if let Some(rest) = cmd.strip_prefix("cargo run").filter(|r| r.contains("--example ")) {
        let name = rest.split("--example ").nth(1).unwrap().split_whitespace().next().unwrap_or("");
        let file = format!("examples/{name}.rs");
        if !Path::new(ROOT).join(&file).is_file() {
            return Some(Err(format!("{file} does not exist")));
        }
        if !read("tests/embed.rs").contains(&format!("\"../{file}\"")) {
            return Some(Err(format!("tests/embed.rs does not include {file}, so nothing runs it")));
        }
        return Some(Ok(()));
    }
    if starts_with_word(cmd, "cargo") && !cmd.starts_with("cargo run --release -- ") {
        return Some(Err("a cargo command this test neither runs nor lists (`cargo run --release -- ARGS` runs as `lobes ARGS`)".into()));
    }
    None
}

#[test]
fn every_documented_command_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let bin = bin_dir(tmp.path());
    // The pages run on two threads (each in its own folder, its lines in order): a lobes process
    // spends much of its time in one-threaded work (start-up, the driver's shader compiler).
    let pages = pages();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut results: Vec<(usize, Vec<String>, usize)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..2)
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(page) = pages.get(i) else { break done };
                        let (errors, ran) = run_page(page, tmp.path(), &bin);
                        done.push((i, errors, ran));
                    }
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().unwrap()).collect()
    });
    results.sort_by_key(|r| r.0);
    let ran: usize = results.iter().map(|r| r.2).sum();
    let errors: Vec<String> = results.into_iter().flat_map(|r| r.1).collect();
    assert!(errors.is_empty(), "{} documented command(s) failed:\n{}", errors.len(), errors.join("\n"));
    assert!(ran >= 20, "only {ran} documented commands ran: are the pages there?");
}

/// Runs or checks every shell line of `page` in a folder of its own under `tmp`: the errors
/// found and the number of commands run.
fn run_page(page: &str, tmp: &Path, bin: &Path) -> (Vec<String>, usize) {
    let mut errors = Vec::new();
    let mut ran = 0;
    let lines = shell_lines(page, &read(page), &mut errors);
    let work = tmp.join(page.replace('/', "_"));
    copy_tree(&Path::new(ROOT).join("scenes"), &work.join("scenes"));
    copy_tree(&Path::new(ROOT).join("examples"), &work.join("examples"));
    copy_tree(&Path::new(ROOT).join("tests/fixtures/repository"), &work.join("tests/fixtures/repository"));
    for line in lines {
        let at = format!("{page}:{}", line.number);
        let text = line.text.as_str();
        if text.starts_with('#') && !text.starts_with("#SBATCH") && !text.starts_with("#!") {
            continue; // a comment line
        }
        match line.kind {
            Kind::Run => {
                let mut script = text.to_string();
                if let Some(rest) = script.strip_prefix("bash .ci/install && ") {
                    assert!(Path::new(ROOT).join(".ci/install").is_file(), "{at}: .ci/install is missing");
                    script = rest.to_string();
                }
                match not_run_form(&script) {
                    Some(Ok(())) => continue,
                    Some(Err(why)) => {
                        errors.push(format!("{at}: `{text}`: {why}"));
                        continue;
                    }
                    None => {}
                }
                let script = script.replace("cargo run --release -- ", "lobes ");
                let want = expected_exit(text);
                let started = Instant::now();
                ran += 1;
                match bash(&script, &work, bin, &[]) {
                    None => errors.push(format!("{at}: `{text}` ran past {} s", TIMEOUT.as_secs())),
                    Some(out) if out.status.code() != Some(want) => errors.push(format!(
                        "{at}: `{text}` exited with {:?}, expected {want} (annotate `# exit N` if meant)\n    {}",
                        out.status.code(),
                        tail(&out.stderr)
                    )),
                    Some(_) => eprintln!("{at}: ok in {:.1} s: {text}", started.elapsed().as_secs_f64()),
                }
            }
            Kind::Install => {
                let cmd = command_of(text);
                let cmd = cmd.strip_prefix("sudo ").unwrap_or(cmd);
                // docs/install-mesa.md: the backports opt-in, its undoing, and a private copy
                // of a driver for one process (extracted packages, the loader pointed at it)
                let install = ["apt-get", "apt", "dnf", "pacman", "brew", "winget"].iter().any(|w| starts_with_word(cmd, w))
                    || cmd.starts_with("cargo install ")
                    || cmd == "bash .ci/install"
                    || cmd.starts_with("bash .ci/install --")
                    || cmd.starts_with("rm /etc/apt/sources.list.d/")
                    || cmd.starts_with("for d in *.deb; do dpkg-deb -x ")
                    || (text.trim_start().starts_with("VK_DRIVER_FILES=") && cmd.starts_with("target/release/lobes "));
                if !install {
                    errors.push(format!("{at}: `{text}` in a ```sh install block is not an install command"));
                }
            }
            Kind::Dev => {
                let cmd = command_of(text);
                let cmd = cmd.strip_prefix("bash .ci/install && ").unwrap_or(cmd);
                let dev = starts_with_word(cmd, "cargo") || starts_with_word(cmd, "duplicates") || cmd.starts_with("bash .ci/");
                if !dev {
                    errors.push(format!("{at}: `{text}` in a ```sh dev block is not a development command"));
                }
            }
            Kind::Cluster => {
                if starts_with_word(text, "lobes") {
                    // The scheduler's variables at shard 0; the comment, if any, dropped.
                    let command = text.split(" #").next().unwrap().trim_end();
                    let env = [("SLURM_ARRAY_TASK_ID", "0"), ("JOB_COMPLETION_INDEX", "0")];
                    ran += 1;
                    match bash(&format!("{command} --help"), &work, bin, &env) {
                        Some(out) if out.status.success() && String::from_utf8_lossy(&out.stdout).contains("Usage: lobes ") => {}
                        out => errors.push(format!(
                            "{at}: `{text}`: clap rejects its arguments\n    {}",
                            out.map_or("timed out".into(), |o| tail(&o.stderr))
                        )),
                    }
                } else {
                    let scheduler = ["#!", "#SBATCH", "sbatch ", "jobid=$(sbatch ", "kubectl "].iter().any(|w| text.starts_with(w));
                    if !scheduler {
                        errors.push(format!("{at}: `{text}` in a ```sh cluster block is neither a lobes line nor a scheduler command"));
                    }
                }
            }
        }
    }
    (errors, ran)
}

/// The info strings of a page's fenced ```rust blocks and the lines of its ```LANG blocks.
fn code_blocks<'a>(text: &'a str, lang: &str) -> Vec<(&'a str, Vec<&'a str>)> {
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let Some(info) = line.trim().strip_prefix("```") else { continue };
        let body: Vec<&str> = lines.by_ref().take_while(|l| l.trim() != "```").collect();
        if info.split([',', ' ']).next() == Some(lang) {
            out.push((info, body));
        }
    }
    out
}

/// docs/embedding.md's code runs too, not only its shell lines: its ```rust blocks are doctests
/// (rustdoc compiles the page, which src/embed/mod.rs includes, and runs each block not marked
/// `no_run`; none may be `ignore`d), and each WESL import of its ```wgsl block compiles, with the
/// `wesl` crate as the page's build script uses it, in a shader beside the files the page's
/// `lobes wgsl --wesl --out-dir shaders/lobes …` line writes: `import package::lobes::…` from
/// that folder, `import lobes::…` from `embed::WESL_PACKAGE`; naga validates both.
#[test]
fn the_embedding_pages_code_runs() {
    let page = read("docs/embedding.md");
    let rust = code_blocks(&page, "rust");
    assert!(rust.len() >= 3, "docs/embedding.md's Rust blocks were not found");
    for (info, body) in &rust {
        assert!(!info.contains("ignore"), "docs/embedding.md: a ```{info} block is not compiled:\n{}", body.join("\n"));
    }
    let include = "#[doc = include_str!(\"../../docs/embedding.md\")]";
    assert!(read("src/embed/mod.rs").contains(include), "src/embed/mod.rs no longer includes docs/embedding.md as doctests ({include})");

    let mut errors = Vec::new();
    let write = shell_lines("docs/embedding.md", &page, &mut errors)
        .into_iter()
        .map(|l| l.text)
        .find(|t| t.starts_with("lobes wgsl --wesl --out-dir shaders/lobes "))
        .expect("docs/embedding.md writes the WESL package into shaders/lobes");
    assert!(errors.is_empty(), "{errors:?}");
    let tmp = tempfile::tempdir().unwrap();
    let bin = bin_dir(tmp.path());
    let out = bash(&write, tmp.path(), &bin, &[]).expect("lobes wgsl finishes");
    assert!(out.status.success(), "`{write}`: {}", tail(&out.stderr));
    let wgsl = code_blocks(&page, "wgsl");
    let [(_, block)] = wgsl.as_slice() else { panic!("docs/embedding.md: expected one ```wgsl block, found {}", wgsl.len()) };
    // every `import …;` of the block, in its code or in a comment that shows the other form
    let imports: Vec<String> =
        block.iter().flat_map(|l| l.split("import ").skip(1).filter_map(|rest| rest.split_once(';').map(|(path, _)| format!("import {path};")))).collect();
    assert!(imports.iter().any(|i| i.starts_with("import package::lobes::")) && imports.iter().any(|i| i.starts_with("import lobes::")), "{imports:?}");
    let kernel = "@group(0) @binding(0) var<storage, read_write> o: array<f32>;\n\
                  @compute @workgroup_size(1) fn main() { o[0] = ggx_sample_vndf(vec2(0.3), vec3(0.0, 0.0, 1.0), vec2(0.25, 0.5)).pdf_r; }\n";
    let shaders = tmp.path().join("shaders");
    for import in &imports {
        std::fs::write(shaders.join("main.wesl"), format!("{import}\n{kernel}")).unwrap();
        let mut compiler = wesl::Wesl::new(&shaders);
        compiler.add_package(&lobes::embed::WESL_PACKAGE);
        let compiled = compiler.compile(&"package::main".parse().unwrap()).unwrap_or_else(|e| panic!("docs/embedding.md: `{import}`: {e}"));
        lobes::embed::validate(&compiled.to_string()).unwrap_or_else(|e| panic!("docs/embedding.md: `{import}`: {e}"));
    }
}

/// The ```toml block after `<!-- lobes scene --template -->` in docs/scenes.md.
fn documented_template(page: &str) -> String {
    let mut lines = page.lines().skip_while(|l| l.trim() != "<!-- lobes scene --template -->").skip(1);
    assert_eq!(lines.next().map(str::trim), Some("```toml"), "docs/scenes.md: the template block must follow its marker");
    let mut block = String::new();
    for line in lines.by_ref() {
        if line.trim() == "```" {
            return block;
        }
        block.push_str(line);
        block.push('\n');
    }
    panic!("docs/scenes.md: the template block is not closed");
}

/// Each row of the scenes page's key table: the keys of its first cell and its default cell.
fn key_table(page: &str) -> Vec<(Vec<String>, String)> {
    page.lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let keys = cells[1].split(',').map(|k| k.trim().trim_matches('`').to_string()).collect();
            (keys, cells[3].to_string())
        })
        .collect()
}

#[test]
fn the_scenes_page_is_the_template() {
    let out = Command::new(LOBES).args(["scene", "--template"]).output().unwrap();
    assert!(out.status.success());
    let template = String::from_utf8(out.stdout).unwrap();
    let page = read("docs/scenes.md");
    assert_eq!(
        documented_template(&page),
        template,
        "docs/scenes.md's template block differs from `lobes scene --template`: paste the command's output there"
    );
    // Every key the template sets (or shows commented out) has a row in the table, and a
    // default the table states is the template's.
    let table = key_table(&page);
    let assignments: Vec<(String, String)> = template
        .lines()
        .map(|l| l.trim_start_matches('#').trim())
        .filter_map(|l| l.split_once(" = "))
        .filter(|(k, _)| k.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_'))
        .map(|(k, v)| (k.to_string(), v.split("  ").next().unwrap().trim().to_string()))
        .collect();
    assert!(assignments.len() >= 20, "the template's keys were not found: {assignments:?}");
    for (key, _) in &assignments {
        assert!(table.iter().any(|(keys, _)| keys.contains(key)), "docs/scenes.md: the key table has no row for `{key}`");
    }
    for (keys, default) in &table {
        let Some(stated) = default.strip_prefix('`').and_then(|d| d.split('`').next()) else { continue };
        for key in keys {
            assert!(
                assignments.iter().any(|(k, v)| k == key && v == stated),
                "docs/scenes.md: the table says `{key}` defaults to `{stated}`, the template does not"
            );
        }
    }
}

#[test]
fn help_lists_the_main_commands_before_the_tutorial() {
    let out = Command::new(LOBES).arg("--help").output().unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    let position = |name: &str| {
        help.lines().position(|l| l.trim_start().starts_with(&format!("{name} "))).unwrap_or_else(|| panic!("`{name}` is not in lobes --help:\n{help}"))
    };
    let first_tutorial = ["discrete", "pdf-convert", "sample"].map(position).into_iter().min().unwrap();
    for main in ["run", "check", "scene", "tradeoff", "stress", "bench", "merge", "shader"] {
        assert!(position(main) < first_tutorial, "lobes --help lists `{main}` after the tutorial's commands:\n{help}");
    }
}

#[test]
fn relative_links_point_at_files() {
    let mut errors = Vec::new();
    for page in pages() {
        let text = read(&page);
        let dir = Path::new(&page).parent().unwrap();
        for (i, line) in text.lines().enumerate() {
            let mut rest = line;
            while let Some(at) = rest.find("](") {
                let after = &rest[at + 2..];
                let Some(end) = after.find(')') else { break };
                let target = &after[..end];
                rest = &after[end..];
                if target.contains("://") || target.starts_with('#') || target.starts_with("mailto:") {
                    continue;
                }
                let file = target.split('#').next().unwrap();
                let path = normalize(&dir.join(file));
                if ARRIVING.contains(&path.as_str()) {
                    continue;
                }
                if !Path::new(ROOT).join(&path).exists() {
                    errors.push(format!("{page}:{}: link to {target}: {path} does not exist", i + 1));
                }
            }
        }
    }
    assert!(errors.is_empty(), "broken links:\n{}", errors.join("\n"));
}

/// `a/b/../c` as `a/c`, relative to the repository.
fn normalize(path: &Path) -> String {
    let mut parts: Vec<String> = Vec::new();
    for c in path.components() {
        match c {
            std::path::Component::ParentDir => {
                parts.pop();
            }
            std::path::Component::CurDir => {}
            c => parts.push(c.as_os_str().to_string_lossy().into_owned()),
        }
    }
    parts.join("/")
}

/// The block reader on a made-up page: kinds, joined continuations, line numbers, a longer
/// fence holding a shorter one, and a shell block under another name reported.
#[test]
fn the_block_reader_finds_every_shell_line() {
    let page = "text\n```sh\nlobes a \\\n  --b   # exit 1\n\n```\n````md\n```sh\nnot read\n```\n````\n```sh install\nsudo dnf install x\n```\n```bash\nlobes c\n```\n```toml\nx = 1\n```\n";
    let mut errors = Vec::new();
    let lines = shell_lines("p.md", page, &mut errors);
    let got: Vec<(usize, &str, Kind)> = lines.iter().map(|l| (l.number, l.text.as_str(), l.kind)).collect();
    assert_eq!(got, [(3, "lobes a --b   # exit 1", Kind::Run), (13, "sudo dnf install x", Kind::Install)]);
    assert_eq!(expected_exit(&lines[0].text), 1);
    assert_eq!(errors, ["p.md:15: shell block ```bash: use ```sh (run), ```sh install, ```sh cluster or ```sh dev"]);
    assert_eq!(command_of("CARGO_TARGET_DIR=$PWD/target cargo test --release"), "cargo test --release");
    assert_eq!(normalize(Path::new("docs/../scenes/./a.toml")), "scenes/a.toml");
}

#[test]
fn a_documented_test_command_names_a_module_that_exists() {
    assert!(test_target_exists("cargo test --release --test integration check_sweep:: -- --nocapture").is_ok());
    assert!(test_target_exists("cargo test --release --test integration tradeoff::f64_pairs").is_ok());
    assert!(test_target_exists("cargo test --release --lib").is_ok());
    assert!(test_target_exists("cargo test --release --test check_sweep").is_err());
    assert!(test_target_exists("cargo test --release --test integration no_such_file::").is_err());
}
