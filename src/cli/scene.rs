//! `lobes scene --template`: a commented scene with every key and its default
//! ([`crate::scene::template`]); `lobes scene SCENE`: the cases a scene makes, its sweeps
//! expanded, one name per line (the names `lobes run --case` matches).

use super::emit;
use super::run::load_scene;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Clone, Args)]
pub struct SceneArgs {
    /// Scene file (TOML), or - to read it from standard input: checks it and prints its case
    /// names, one per line.
    #[arg(required_unless_present = "template", conflicts_with = "template")]
    pub scene: Option<PathBuf>,
    /// Print a scene with every key, its default and what it allows, as comments.
    #[arg(long)]
    pub template: bool,
}

pub fn run(args: &SceneArgs) -> anyhow::Result<()> {
    if args.template {
        return emit(&crate::scene::template::template());
    }
    let scene = load_scene(args.scene.as_ref())?;
    emit(&scene.entries().map(|(e, _)| format!("{}\n", e.name())).collect::<String>())
}
