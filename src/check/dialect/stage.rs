//! What this process is composing now ([`composing`]), for a message about where the time went.

/// What this process is composing now, for a message about where the time went
/// ([`composing`]); `None` between compositions.
static COMPOSING: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Sets [`COMPOSING`] to a stage of a composition until it is dropped, then back to the stage
/// it was in (the stage around it, or none).
pub(in crate::check) struct Stage(Option<String>);

impl Stage {
    pub(in crate::check) fn enter(what: String) -> Stage {
        Stage(COMPOSING.lock().unwrap_or_else(|p| p.into_inner()).replace(what))
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        *COMPOSING.lock().unwrap_or_else(|p| p.into_inner()) = self.0.take();
    }
}

/// What the composition in progress in this process is doing, as a phrase that follows "while
/// lobes was": "composing diffuse.wgsl and the 1000 naga_oil modules it imports (under
/// shaders) with naga_oil's Composer", "reading diffuse.wgsl and the modules it imports under
/// the shader roots (shaders), and composing them"; `None` when nothing is being composed
/// (plain WGSL is not). `lobes check` composes on a thread of its own and says with this where
/// the time went when `--timeout` runs out, or a signal comes, first: naga_oil's time grows
/// faster than N² in the depth N of a chain of imports (each module is parsed against a header
/// holding every module below it; 1000 modules take about 5 s), and nothing stops it midway.
/// The command line composes one sampler at a time; a library composing on several threads
/// sees the latest stage of any of them.
pub fn composing() -> Option<String> {
    COMPOSING.lock().unwrap_or_else(|p| p.into_inner()).clone()
}
