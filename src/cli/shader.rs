//! `lobes shader SCENE [--case NAME]`: the composed WGSL that `lobes run` compiles for each
//! case, once per distinct module, with the override constants its pipelines are made with.

use super::{OutputArgs, emit, emit_json, usage};
use crate::engine::gpu::{Counting, GpuEngine};
use crate::engine::gpu::effects::{self, PipelineSource};
use crate::scene::Entry;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Clone, Args)]
pub struct ShaderArgs {
    /// Scene file (TOML); without it, the embedded scenes/all-lobes.toml.
    pub scene: Option<PathBuf>,
    /// Print only this case's module.
    #[arg(long)]
    pub case: Option<String>,
    #[command(flatten)]
    pub output: OutputArgs,
}

pub fn run(args: &ShaderArgs) -> anyhow::Result<()> {
    let scene = super::run::load_scene(args.scene.as_ref())?;
    let entries: Vec<Entry> = scene.entries().map(|(e, _)| e).filter(|e| args.case.as_ref().is_none_or(|n| e.name() == n)).collect();
    if let (Some(name), true) = (&args.case, entries.is_empty()) {
        let names: Vec<&str> = scene.entries().map(|(e, _)| e.name()).collect();
        return Err(usage(format!("--case {name}: no such case in {}; its cases are: {}", scene.file, names.join(", "))));
    }
    // The module depends on the adapter's device type and limits (its counting, the workgroup
    // storage, the storage binding size):
    // use the adapter `lobes run` would use, or wgpu's default limits without one.
    let engine = GpuEngine::open().map_err(|e| crate::console::say(format_args!("lobes: note: {e}\nlobes: note: composing for wgpu's default limits"))).ok();
    let (device, limits) = engine.as_ref().map_or((wgpu::DeviceType::Other, wgpu::Limits::default()), |e| (e.gpu.info.device_type, e.gpu.limits.clone()));
    let mut modules: Vec<(PipelineSource, Vec<&str>)> = Vec::new();
    for entry in entries {
        let ms = match entry {
            Entry::Lobe(case) => {
                let (counting, tile) = match &engine {
                    Some(e) => {
                        let tile = e.tiling(&case.job).map_or(case.job.bins() as u64, |t| t.tile_bins) as u32;
                        (e.counting(tile), tile)
                    }
                    None => default_counting(case.job.bins() as u32),
                };
                vec![effects::case_module(&case.job, case.effects.as_ref(), counting, tile)]
            }
            // a user's sampler: its files, the glue and `lobes check`'s passes, and the
            // histogram's module (each one for every incident angle and params, which are
            // uniforms)
            Entry::User(case) => {
                let (rows, cols) = case.settings.grid(&case.sampler.domain);
                let histogram = case.sampler.composed_histogram(device, &limits, rows, cols)?;
                [case.sampler.composed()?, histogram].map(|source| PipelineSource { source, constants: Vec::new() }).into()
            }
        };
        for m in ms {
            match modules.iter_mut().find(|(k, _)| *k == m) {
                Some((_, names)) => names.push(entry.name()),
                None => modules.push((m, vec![entry.name()])),
            }
        }
    }
    if args.output.json {
        let list: Vec<serde_json::Value> = modules
            .iter()
            .map(|(m, names)| {
                let constants: serde_json::Map<String, serde_json::Value> = m.constants.iter().map(|(k, v)| (k.to_string(), (*v).into())).collect();
                serde_json::json!({"cases": names, "constants": constants, "source": m.source})
            })
            .collect();
        return emit_json(&serde_json::json!({"scene": scene.file, "modules": list}));
    }
    let mut text = String::new();
    for (m, names) in &modules {
        let constants: Vec<String> = m.constants.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        text += &format!(
            "// ==== lobes module for case(s) {}; pipeline constants: {}\n",
            names.join(", "),
            if constants.is_empty() { "none".to_string() } else { constants.join(", ") }
        );
        text += &m.source;
        text += "\n";
    }
    emit(&text)
}

/// The counting of `tile` bins on an adapter with wgpu's default limits (none found), and the
/// tile.
fn default_counting(tile: u32) -> (Counting, u32) {
    (Counting::atomics(wgpu::Limits::default().max_compute_workgroup_storage_size / 4, tile), tile)
}
