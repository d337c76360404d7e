//! `lobes wgsl MODULE...`: lobes' WGSL for a renderer, in one of four forms: plain WGSL with
//! every name prefixed ([`embed::wgsl_with`]), naga_oil modules (`--naga-oil`,
//! [`Module::naga_oil_source`]), the WESL package (`--wesl`, [`Module::wesl_source`]) or GLSL 450
//! (`--glsl`, [`embed::glsl`]); on stdout,
//! or one file per module in `--out-dir`.

use super::{emit, usage};
use crate::embed::{self, DiscreteBindings, Module};
use crate::scene::suggest::did_you_mean;
use anyhow::Context;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Clone, Args)]
pub struct WgslArgs {
    /// Modules to print, with the modules they use (--list names them: ggx, fresnel, rng, …).
    #[arg(required_unless_present = "list", value_name = "MODULE")]
    pub modules: Vec<String>,
    /// List every module: its files, its API (each name with one line on it) and the modules it
    /// needs.
    #[arg(long, exclusive = true)]
    pub list: bool,
    /// The files as naga_oil modules (`#define_import_path lobes::ggx`, `#import`s, short
    /// names), each after those it imports, for a renderer that composes with naga_oil (Bevy
    /// 0.19 and earlier); without it, plain WGSL with every name prefixed `lobes_`.
    #[arg(long, conflicts_with = "wesl")]
    pub naga_oil: bool,
    /// The WESL package `lobes` (`import lobes::ggx::ggx_sample_vndf;`, Bevy 0.20 and the
    /// `wesl` crate): one `NAME.wesl` per module, so it needs --out-dir.
    #[arg(long, requires = "out_dir")]
    pub wesl: bool,
    /// The modules as GLSL 450 (naga's GLSL back end), for `#include` in a `#version 450` shader:
    /// the plain WGSL's functions and names (`lobes_`), one text (with --out-dir: lobes.glsl).
    #[arg(long, conflicts_with_all = ["naga_oil", "wesl"])]
    pub glsl: bool,
    /// Write one file per module into DIR (created if missing): NAME.wgsl (plain or naga_oil)
    /// or NAME.wesl, and NAME/internal.wgsl or .wesl for a naga_oil or WESL module's internal
    /// helpers; the plain files do not overlap, so include each once, in any order.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// The bind group of the discrete module's two storage buffers (default 0).
    #[arg(long, value_name = "G")]
    pub group: Option<u32>,
    /// The binding of the discrete module's table (`discrete_f`); its aliases
    /// (`discrete_u`) take B + 1 (default 3, so 3 and 4).
    #[arg(long, value_name = "B")]
    pub binding: Option<u32>,
}

/// The form of the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Form {
    Plain,
    NagaOil,
    Wesl,
    Glsl,
}

pub fn run(args: &WgslArgs) -> anyhow::Result<()> {
    if args.list {
        return emit(&Module::ALL.iter().map(|m| format!("## {}\n\n{}\n\n", m.name(), m.description())).collect::<String>());
    }
    let modules = parse(&args.modules)?;
    let resolved = embed::resolve(&modules);
    let bindings = bindings(args, &resolved)?;
    let form = match (args.naga_oil, args.wesl, args.glsl) {
        (true, _, _) => Form::NagaOil,
        (_, true, _) => Form::Wesl,
        (_, _, true) => Form::Glsl,
        _ => Form::Plain,
    };
    let glsl = || embed::glsl(&modules, bindings).context("writing lobes' WGSL as GLSL");
    let Some(dir) = &args.out_dir else {
        return emit(&match form {
            Form::Plain => embed::wgsl_with(&modules, bindings),
            Form::Glsl => glsl()?,
            _ => embed::naga_oil_modules(&modules)
                .into_iter()
                .map(|m| format!("// ==== naga_oil module {} ====\n{}\n", m.import_path, naga_oil_text(&m, bindings).trim_end()))
                .collect(),
        });
    };
    let files: Vec<(String, String)> = match form {
        Form::Plain => resolved.iter().map(|&m| (format!("{}.wgsl", m.name()), plain_file(m, bindings))).collect(),
        Form::Glsl => vec![("lobes.glsl".to_string(), glsl()?)],
        Form::NagaOil => embed::naga_oil_modules(&modules).into_iter().map(|m| (m.file_name("wgsl"), naga_oil_text(&m, bindings))).collect(),
        Form::Wesl => embed::wesl_files(&modules)
            .into_iter()
            .map(|(name, text)| {
                let text = if name == "discrete.wesl" { bindings.apply(text) } else { text.to_string() };
                (name, text)
            })
            .collect(),
    };
    std::fs::create_dir_all(dir).with_context(|| format!("--out-dir {}: cannot create the folder", dir.display()))?;
    for (name, contents) in &files {
        let path = dir.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).with_context(|| format!("--out-dir: cannot create {}", parent.display()))?;
        }
        crate::atomic::write_atomic(&path, contents.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
    }
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    let plural = if files.len() == 1 { "" } else { "s" };
    crate::console::say(format_args!("wrote {} file{plural} to {}: {}", files.len(), dir.display(), names.join(", ")));
    Ok(())
}

/// The naga_oil text of `m` (a module's API or its internal helpers), with the discrete
/// module's buffers at `bindings`.
fn naga_oil_text(m: &embed::NagaOilModule, bindings: DiscreteBindings) -> String {
    if m.module == Module::Discrete && !m.internal { bindings.apply(m.source) } else { m.source.to_string() }
}

/// One module's plain file of `--out-dir`: a header naming the files it needs, then its text
/// (the same text [`embed::wgsl_with`] writes for it).
fn plain_file(m: Module, bindings: DiscreteBindings) -> String {
    let needs: Vec<String> = embed::resolve(&[m]).into_iter().filter(|&d| d != m).map(|d| format!("{}.wgsl", d.name())).collect();
    let needs = if needs.is_empty() { "nothing else".to_string() } else { needs.join(", ") };
    let body = embed::module_wgsl(m, bindings);
    format!(
        "// lobes {} plain WGSL module {} (lobes wgsl --out-dir): needs {needs}, each included once;\n\
         // every name lobes defines starts with lobes_, Lobes or LOBES_.\n{body}",
        env!("CARGO_PKG_VERSION"),
        m.name()
    )
}

/// The discrete module's bindings from --group and --binding, which only it has.
fn bindings(args: &WgslArgs, resolved: &[Module]) -> anyhow::Result<DiscreteBindings> {
    let default = DiscreteBindings::default();
    if args.group.is_none() && args.binding.is_none() {
        return Ok(default);
    }
    if !resolved.contains(&Module::Discrete) {
        return Err(usage("--group/--binding place the discrete module's storage buffers, and no module asked for has resources: add discrete, or drop them"));
    }
    let table = args.binding.unwrap_or(default.table);
    let alias = table.checked_add(1).ok_or_else(|| usage(format!("--binding {table}: the aliases take binding B + 1, past u32")))?;
    Ok(DiscreteBindings { group: args.group.unwrap_or(default.group), table, alias })
}

/// The modules named, or a usage error that lists them and suggests the closest.
fn parse(names: &[String]) -> anyhow::Result<Vec<Module>> {
    let mut known: Vec<&str> = Module::ALL.iter().map(|m| m.name()).collect();
    known.sort();
    names
        .iter()
        .map(|n| {
            Module::from_name(n).ok_or_else(|| usage(format!("unknown module '{n}'{}; the modules are: {}", did_you_mean(n, known.iter().copied()), known.join(", "))))
        })
        .collect()
}
