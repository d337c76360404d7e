//! A stand-in for a renderer that embeds its WGSL shaders and tests its samplers with lobes from
//! its own `cargo test` (see `tests/sampler.rs` and lobes' `docs/testing-your-own-sampler.md`).

/// The renderer's diffuse lobe (`diffuse_sample`, `diffuse_pdf`, `diffuse_eval`), as it is
/// compiled into the renderer: the tests check this very text.
pub fn diffuse_wgsl() -> &'static str {
    include_str!("../shaders/diffuse.wgsl")
}
