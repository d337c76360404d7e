//! lobes' integration tests, one module per file of tests/, built as one test binary (Cargo.toml:
//! `autotests = false`, `[[test]] integration`): one link instead of one per file, and libtest
//! spreads every test over the cores instead of running the files one after another. Run one
//! file's tests by its module: `cargo test --release --test integration check_sweep::`.
//! tests/layout.rs holds that every file here is a module below.

mod common;
mod reference_quadrature;

mod adversarial_frontend;
mod adversarial_parsers;
mod adversarial_runtime;
mod adversarial_stats;
mod bad_input;
mod batch_outputs;
mod check;
mod check_builtin;
mod check_conventions;
mod check_glsl;
mod check_lights;
mod check_repository;
mod check_sweep;
mod check_wesl;
mod cli_tutorial;
mod cli_wgsl;
mod counting;
mod dielectric;
mod dielectric_gpu;
mod dielectric_weighted;
mod docs_commands;
mod effects;
mod embed;
mod family;
mod fault_injection;
mod features;
mod gpu_histogram;
mod hangs;
mod html_report;
mod layout;
mod lights;
mod limits;
mod microfacet_identities;
mod pipeline_cache;
mod power;
mod reference_monte_carlo;
mod reference_normalization;
mod reference_properties;
mod reference_sweep;
mod renderer_example;
mod rotated_anisotropy;
mod run_outcomes;
mod scene_batch;
mod schema;
mod shards;
mod stress;
mod tradeoff;
mod user_scene;
