//! `lobes wgsl MODULE...`: the WGSL of `lobes::embed` for a renderer, printed: the named
//! modules with everything they use, every name prefixed ([`embed::wgsl`]); or with
//! `--naga-oil` the same files as naga_oil modules ([`embed::naga_oil_modules`]).

use super::{emit, usage};
use crate::embed::{self, Module};
use crate::scene::suggest::did_you_mean;
use clap::Args;

#[derive(Debug, Clone, Args)]
pub struct WgslArgs {
    /// Modules to print, with the modules they use: rng, reflect, microfacet, ward, ggx,
    /// beckmann, fresnel, masking, discrete.
    #[arg(required = true, value_name = "MODULE")]
    pub modules: Vec<String>,
    /// Print the files as naga_oil modules (`#define_import_path lobes::ggx`, `#import`s,
    /// short names), each after those it imports, for a renderer that composes with naga_oil
    /// or Bevy; without it, one plain WGSL source with every name prefixed `lobes_`.
    #[arg(long)]
    pub naga_oil: bool,
}

pub fn run(args: &WgslArgs) -> anyhow::Result<()> {
    let modules = parse(&args.modules)?;
    if !args.naga_oil {
        return emit(&embed::wgsl(&modules));
    }
    let files: Vec<&str> = embed::resolve(&modules).iter().flat_map(|m| m.import_paths()).copied().collect();
    let text: String = embed::naga_oil_modules()
        .into_iter()
        .filter(|m| files.contains(&m.import_path))
        .map(|m| format!("// ==== naga_oil module {} ====\n{}\n", m.import_path, m.source.trim_end()))
        .collect();
    emit(&text)
}

/// The modules named, or a usage error that lists them and suggests the closest.
fn parse(names: &[String]) -> anyhow::Result<Vec<Module>> {
    let known: Vec<&str> = Module::ALL.iter().map(|m| m.name()).collect();
    names
        .iter()
        .map(|n| {
            Module::from_name(n).ok_or_else(|| usage(format!("unknown module '{n}'{}; the modules are: {}", did_you_mean(n, known.iter().copied()), known.join(", "))))
        })
        .collect()
}
