//! The GPU passes over a user's sampler (`shaders/check/user_passes.wgsl`): weights, quadrature
//! of rectangles and the probe of the sample map; and its histogram, counted by `lobes run`'s
//! counting kernel drawing the user's sampler (`shaders/check/user_draw.wgsl`).

use super::compose::Composed;
use super::composition::Draw;
use super::glue::{GLUE, contract_glue, prepare};
use super::probe::Probe;
use super::{CheckError, Message, Setting, Settings, UserSampler, shaders};
use crate::reference::Invalid;
use crate::engine::gpu::library::{self, File};
use crate::engine::gpu::compose::grid_counting_kernel;
use crate::engine::gpu::layout::{N_REASONS, WG_SIZE, binding};
use crate::engine::gpu::precision::Precision;
use crate::engine::gpu::engine::Tiling;
use crate::engine::gpu::{Counting, Gpu, Strategy};
use crate::engine::job::SampleRange;
use crate::engine::gpu::dispatch::{Pass, Step};
use wgpu::util::DeviceExt;

/// Invocations per workgroup of every pass (`@workgroup_size(64)`).
const WG: u32 = 64;

/// The passes' uniform block, `lobes run`'s kernels' too.
pub(super) use crate::engine::gpu::params::Params;

/// What a pass writes, and where it is bound (`shaders/check/user_passes.wgsl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    /// `lobes_out`, vec4s.
    Values,
    /// `lobes_probes`, one [`Probe`] per item.
    Probes,
}

impl Output {
    fn binding(self) -> u32 {
        match self {
            Output::Values => binding::CHECK_OUT,
            Output::Probes => binding::CHECK_PROBES,
        }
    }
}

/// Quadrature rectangles per dispatch of `lobes_integrate_rects` or `lobes_integrate_pdf`: 2¹⁸,
/// whose buffers (8 MiB of input) stay under glibc's 32 MiB mmap threshold, so each call reuses
/// the heap the last one freed. At 2²⁰ each call's buffers were fresh pages from the kernel:
/// tests/check_sweep.rs's correct samplers spent 25 s of system time faulting them in (81 s of
/// wall time; 2¹⁸: 15 s, 77 s).
const RECTS_PER_CALL: usize = 1 << 18;

/// The compiled passes of one user sampler.
pub(super) struct Passes<'g> {
    gpu: &'g Gpu,
    module: wgpu::ShaderModule,
    /// GPU time of the passes run so far (timestamp queries; `None` without them).
    gpu_seconds: std::cell::Cell<Option<f64>>,
    /// Each entry point's pipeline, created at its first run (a quadrature runs one per round).
    pipelines: std::cell::RefCell<std::collections::HashMap<String, wgpu::ComputePipeline>>,
    /// The user's textures and tables on the GPU, by their binding in group 1, with the entry
    /// points that read each.
    resources: Vec<(u32, Vec<String>, GpuResource)>,
    /// Each entry point's group 1 (its layout is the pipeline's own), where it reads any.
    group1: std::cell::RefCell<std::collections::HashMap<String, Option<wgpu::BindGroup>>>,
    /// The sampler and the order of its --rand draws, from which the histogram's modules are
    /// composed.
    sampler: UserSampler,
    order: [u32; 4],
    /// The user's resources as the passes' composition read them, which the histogram's reuse.
    loaded: Vec<super::resources::Bound>,
    /// The histogram's kernel of each grid (rows, cols, bins a tile) and counting, made at its
    /// first use.
    histograms: std::cell::RefCell<std::collections::HashMap<HistogramKey, std::rc::Rc<HistogramKernel>>>,
}

/// A histogram kernel's grid: rows, columns, bins a tile, and its counting.
type HistogramKey = (u32, u32, u32, Counting);

/// `lobes run`'s counting kernel drawing the user's sampler ([`compose_histogram`]), compiled:
/// its sampling and fold pipelines, each with the bindings of group 0 it reads, and the
/// sampling's group 1 (the user's resources it reads).
struct HistogramKernel {
    /// Kept with its pipelines (and leaked with them on an abandoned device, as [`Passes`] is).
    _module: wgpu::ShaderModule,
    sample: (wgpu::ComputePipeline, Vec<u32>),
    fold: (wgpu::ComputePipeline, Vec<u32>),
    group1: Option<wgpu::BindGroup>,
}

/// The histogram kernel's storage buffers: a chunk's u32 counters per cell, the 64-bit totals
/// they are folded into, the slabs (CPU adapters) and the --rand draw counters.
struct HistogramBuffers {
    counts: wgpu::Buffer,
    totals: wgpu::Buffer,
    slabs: wgpu::Buffer,
    draws: wgpu::Buffer,
}

impl HistogramBuffers {
    /// Zeroed (as wgpu makes a buffer; the fold leaves the counters and slabs 0) for `cells`
    /// cells of `bins` bins counted as `counting` says.
    fn new(gpu: &Gpu, cells: u64, bins: u32, counting: Counting) -> Self {
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        Self {
            counts: gpu.buffer("check chunk counts", cells * 4, storage),
            totals: gpu.buffer("check totals", cells * 8, storage),
            slabs: gpu.buffer("check slabs", counting.slab_bytes(bins).max(4), wgpu::BufferUsages::STORAGE),
            draws: gpu.buffer("check draws", 8, storage),
        }
    }

    /// The buffer at `b` of group 0, the uniform block `uniform`.
    fn at<'a>(&'a self, b: u32, uniform: &'a wgpu::Buffer) -> Result<&'a wgpu::Buffer, CheckError> {
        match b {
            binding::PARAMS => Ok(uniform),
            binding::COUNTS => Ok(&self.counts),
            binding::TOTALS => Ok(&self.totals),
            binding::SLABS => Ok(&self.slabs),
            binding::DRAWS => Ok(&self.draws),
            b => Err(CheckError::Internal(format!("the histogram's kernel reads binding {b} of group 0, which lobes check does not bind"))),
        }
    }
}

/// A user's resource uploaded.
enum GpuResource {
    Texture(wgpu::TextureView),
    Buffer(wgpu::Buffer),
    Sampler(wgpu::Sampler),
}

impl GpuResource {
    fn upload(gpu: &Gpu, b: &super::resources::Bound) -> Self {
        use super::resources::Data;
        use wgpu::util::DeviceExt;
        match &*b.data {
            Data::Texture { width, height, texels } => {
                let desc = wgpu::TextureDescriptor {
                    label: Some(&b.name),
                    size: wgpu::Extent3d { width: *width, height: *height, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba32Float,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                };
                let t = gpu.device.create_texture_with_data(&gpu.queue, &desc, wgpu::util::TextureDataOrder::LayerMajor, bytemuck::cast_slice(texels));
                GpuResource::Texture(t.create_view(&Default::default()))
            }
            Data::Buffer { words, .. } => {
                let mut bytes = bytemuck::cast_slice::<u32, u8>(words).to_vec();
                bytes.resize(bytes.len().max(4), 0);
                GpuResource::Buffer(gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(&b.name), contents: &bytes, usage: wgpu::BufferUsages::STORAGE }))
            }
            Data::Sampler(f) => GpuResource::Sampler(sampler(gpu, &b.name, *f)),
        }
    }
    fn entry(&self, binding: u32) -> wgpu::BindGroupEntry<'_> {
        let resource = match self {
            GpuResource::Texture(v) => wgpu::BindingResource::TextureView(v),
            GpuResource::Buffer(b) => b.as_entire_binding(),
            GpuResource::Sampler(s) => wgpu::BindingResource::Sampler(s),
        };
        wgpu::BindGroupEntry { binding, resource }
    }
}

/// A user's sampler (`--sampler NAME=FILTER`): `filter` for magnification and minification,
/// nearest between mip levels, clamp-to-edge in every direction.
fn sampler(gpu: &Gpu, name: &str, filter: super::resources::Filter) -> wgpu::Sampler {
    let mode = match filter {
        super::resources::Filter::Linear => wgpu::FilterMode::Linear,
        super::resources::Filter::Nearest => wgpu::FilterMode::Nearest,
    };
    gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(name),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: mode,
        min_filter: mode,
        mipmap_filter: wgpu::MipmapFilterMode::Nearest,
        ..Default::default()
    })
}

/// Bad input where a pass reads a `--texture` (rgba32float: lobes keeps the image's precision)
/// through a `--sampler` and the adapter lacks wgpu's FLOAT32_FILTERABLE: wgpu's derived layout
/// marks a texture that a pass samples as filterable, which rgba32float is only with that
/// feature, so binding it would fail, whatever the sampler's filter.
fn unfilterable(gpu: &Gpu, bound: &[super::resources::Bound]) -> Result<(), CheckError> {
    use super::resources::Data;
    if gpu.float32_filterable() {
        return Ok(());
    }
    let reads = |b: &super::resources::Bound, other: &super::resources::Bound| b.entries.iter().any(|e| other.entries.contains(e));
    for s in bound.iter().filter(|b| matches!(*b.data, Data::Sampler(_))) {
        if let Some(t) = bound.iter().find(|t| matches!(*t.data, Data::Texture { .. }) && reads(t, s)) {
            return Err(CheckError::setting(Setting::Filter, format!(
                "{}: the sampler reads the texture `{}` (rgba32float) through it, and this adapter, {}, lacks wgpu's FLOAT32_FILTERABLE, without which wgpu binds no float32 texture to a pass that samples it (nearest or linear); lobes does not lower the image's precision: run the check on an adapter that has it (lavapipe and desktop Vulkan do), or give a stand-in module that reads the texture with textureLoad",
                s.name,
                t.name,
                gpu.adapter_name()
            )));
        }
    }
    Ok(())
}


/// What the histogram pass counted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Counted {
    /// Per cell: the bins, then the reasons of [`Invalid::ALL`].
    pub counts: Vec<u64>,
    /// Samples that drew more than the four numbers of the --rand queue, and the most draws one
    /// of them took (0 where none did).
    pub over_drawn: u64,
    pub most_draws: u32,
}

/// The most samples of one dispatch of the histogram and weights passes.
pub(super) const CHUNK: u64 = 1 << 26;

/// The histogram of `samples` samples of `sampler`: counts per bin, then per invalid reason.
/// Samples that drew more than the --rand queue's four numbers, counted on every sample, are bad
/// input ([`too_many_draws`]).
pub(super) fn histogram(passes: &Passes, params: &Params, sampler: &UserSampler, samples: u64) -> Result<Vec<u64>, CheckError> {
    let counted = passes.histogram(params, 0, samples, None)?;
    if counted.over_drawn > 0 {
        return Err(too_many_draws(sampler, counted.most_draws, counted.over_drawn, samples));
    }
    let total: u64 = counted.counts.iter().sum();
    if total != samples {
        return Err(CheckError::Internal(format!("{total} samples counted for {samples} drawn")));
    }
    Ok(counted.counts)
}

/// The error of a sampler of which `over` of `of` samples drew more than the queue's four
/// uniforms, one of them `most`.
pub(super) fn too_many_draws(sampler: &UserSampler, most: u32, over: u64, of: u64) -> CheckError {
    let message = format!(
        "{}: one sample drew {most} random numbers, and {over} of {of} samples drew more than four; lobes hands out four (u.x, u.y, u.z, u.w), so a sampler whose random functions are named draws at most four per sample",
        sampler.composition.rand.join(", ")
    );
    CheckError::setting(Setting::Rand, message)
}

/// The user's code, the glue and lobes' passes as one module, validated by naga (errors at the
/// user's file:line:column).
///
/// lobes' passes (`shaders/check/user_passes.wgsl`, `lobes::check`) are a naga_oil module like
/// the engine's: it imports the RNG, the uniform block and `lobes::user`, the user's files with
/// the glue, generated here. naga validates the whole composition; in the unit tests naga_oil
/// also builds each of lobes' files as its own root. The user's files are naga's to judge (alone
/// in `check_user`, then in the whole composition), since naga_oil refuses some valid WGSL (a
/// struct member whose name ends in a digit), so an error naga_oil finds in `lobes::user` itself
/// is left to naga.
pub fn compose(sampler: &UserSampler) -> Result<Composed, CheckError> {
    compose_ordered(sampler, default_order(sampler))
}

/// The order of the --rand draws that `sampler` declares (`--rand-order`), else u's own.
pub(super) fn default_order(sampler: &UserSampler) -> [u32; 4] {
    Draw::components(sampler.composition.rand_order.as_deref().unwrap_or(&[]))
}

/// [`compose`] with the --rand queue in the order `order` of u's components.
pub(super) fn compose_ordered(sampler: &UserSampler, order: [u32; 4]) -> Result<Composed, CheckError> {
    Ok(compose_roots(sampler, order, &["lobes::check"], vec![shaders::PASSES], &[])?.0)
}

/// The histogram's module: `lobes run`'s counting kernel over a `rows` × `cols` grid, tiles of
/// `tile_bins` of its bins a pass, counted as `counting` says, drawing the user's sampler
/// (`shaders/check/user_draw.wgsl`) where it draws a lobe, so that a user's samples are counted
/// as lobes' are.
pub(super) fn compose_histogram(sampler: &UserSampler, order: [u32; 4], (rows, cols, tile_bins): (u32, u32, u32), counting: Counting, loaded: &[super::resources::Bound]) -> Result<Validated, CheckError> {
    let kernel = grid_counting_kernel("lobes check's histogram", rows, cols, counting, tile_bins, Precision::F32Accurate);
    let mut files = kernel.files()?;
    files.push(shaders::DRAW);
    compose_roots(sampler, order, &kernel.roots, files, loaded)
}

/// A composition with naga's module and its validation.
pub(super) type Validated = (Composed, naga::Module, naga::valid::ModuleInfo);

/// The module of lobes' `roots` (from `chosen` and the built-in files) with the user's files and
/// glue as `lobes::user`, the domain's binning and the invalid reasons; the user's resources
/// read anew, but for those in `loaded` (another composition's of the same files).
fn compose_roots(sampler: &UserSampler, order: [u32; 4], roots: &[&str], mut chosen: Vec<File>, loaded: &[super::resources::Bound]) -> Result<Validated, CheckError> {
    let parts = prepare(sampler, order)?;
    let glue = contract_glue(sampler);
    let user: String = parts.iter().map(|s| format!("{}\n", s.text)).collect();
    let module = format!("#define_import_path lobes::user\n#import lobes::params::lobes_params\n{user}{glue}");
    let reasons = format!("#define_import_path lobes::invalid\n{}", Invalid::wgsl_consts("LOBES_REASON"));
    chosen.extend([File::generated(GLUE, module), shaders::domain_file(sampler.domain), File::generated("lobes::invalid", reasons)]);
    // lobes' files each a naga_oil root of its own (which refuses a name used without its
    // #import), as the engine's compositions are checked: in the unit tests, which compose the
    // passes and the histogram; a run validates the joined module (below, its errors at each
    // file's line) and saves the 40 ms this takes per composition
    #[cfg(test)]
    match library::validate_files(roots, &chosen) {
        Err(crate::engine::gpu::GpuError::Shader { what, .. }) if what == GLUE => {}
        other => other?,
    }
    let pieces = library::pieces(roots, &chosen)?;
    let own = lobes_own_names(&pieces);
    let mut c = Composed::default();
    for (path, text) in &pieces {
        if path == GLUE {
            for s in &parts {
                c.push(&s.name, &s.text);
            }
            c.push(GLUE, &glue);
        } else {
            c.push(path, &crate::embed::rename(text, |t| own.contains(&t).then(|| format!("lobes_{t}"))));
        }
    }
    let declared = move_resources(&mut c)?;
    let (module, info) = c.validate_with(naga::valid::Capabilities::default())?;
    bind_resources(&mut c, &module, &info, &sampler.composition.resources, &declared, loaded)?;
    Ok((c, module, info))
}

/// How a histogram of `bins` bins is counted on an adapter of `device` type with `limits`: in
/// tiles as [`Tiling::fit`] splits it, each counted as [`Counting::choose`] picks (`force`: a
/// strategy asked for), as `lobes run` counts its jobs.
pub(super) fn histogram_counting(device: wgpu::DeviceType, limits: &wgpu::Limits, bins: u32, force: Option<Strategy>) -> Result<(Tiling, Counting), CheckError> {
    let tiling = Tiling::fit(bins as u64, limits).ok_or_else(|| CheckError::setting(Setting::Bins, "this adapter's storage limits hold no histogram"))?;
    Ok((tiling, Counting::choose(device, limits, tiling.tile_bins as u32, force)))
}

/// The entry point that draws and counts in the histogram's module (`lobes::kernel`'s
/// `sample_histogram`, renamed as lobes' own names are, [`lobes_own_names`]).
const SAMPLE_ENTRY: &str = "lobes_sample_histogram";

/// The bindings of group 0 that `entry` of `module` reads or writes: those its pipeline's
/// derived layout holds, and so those its bind group must have.
fn group0_bindings(module: &naga::Module, info: &naga::valid::ModuleInfo, entry: &str) -> Vec<u32> {
    let Some(i) = module.entry_points.iter().position(|e| e.name == entry) else { return Vec::new() };
    let uses = info.get_entry_point(i);
    let bound = module.global_variables.iter().filter(|(h, _)| !uses[*h].is_empty());
    bound.filter_map(|(_, g)| g.binding.as_ref().filter(|b| b.group == 0).map(|b| b.binding)).collect()
}

/// Moves every resource the user's files declare to `@group(1)`, binding 0, 1, … in declaration
/// order, in `c`'s text (lobes' own are group 0; a renderer's `@group(0) @binding(0)` would
/// collide with them), and returns each one's name and binding as declared, for messages.
fn move_resources(c: &mut Composed) -> Result<Vec<(String, naga::ResourceBinding)>, CheckError> {
    // a text that does not parse is reported by the validation that follows
    let Ok(module) = naga::front::wgsl::parse_str(&c.text) else { return Ok(Vec::new()) };
    let users: Vec<_> = module.global_variables.iter().filter(|(_, g)| g.binding.is_some() && !g.name.as_deref().is_some_and(|n| n.starts_with("lobes_"))).collect();
    // from the last declaration up, so that the spans before each stay where they are
    for (k, (h, g)) in users.iter().enumerate().rev() {
        let range = module.global_variables.get_span(*h).to_range().ok_or_else(|| CheckError::Internal("a global without a span".into()))?;
        c.text = super::resources::rebind(&c.text, range, k as u32)
            .ok_or_else(|| CheckError::Internal(format!("no @group/@binding before `{}` in the composed text", g.name.as_deref().unwrap_or("?"))))?;
    }
    Ok(users.iter().map(|(_, g)| (g.name.clone().unwrap_or_default(), g.binding.expect("a binding"))).collect())
}

/// The renderer's resources that lobes' passes reach through the sampler, bound from the files
/// the user gave (`--texture`, `--buffer`; [`super::resources`]; already in group 1,
/// [`move_resources`]): each one's file read and held to its declaration, and recorded in
/// `c.bound` with its binding and the passes that read it. One without a file would have
/// nothing bound at dispatch (wgpu: "expects a BindGroup to be set"): bad input, named at its
/// declaration (with the group and binding it was `declared` with), before any GPU work.
/// Declared and never reached is fine.
fn bind_resources(c: &mut Composed, module: &naga::Module, info: &naga::valid::ModuleInfo, given: &[(String, super::resources::Resource)], declared: &[(String, naga::ResourceBinding)], loaded: &[super::resources::Bound]) -> Result<(), CheckError> {
    use super::resources;
    // by lobes' passes (a renderer's own entry points, where a file keeps them, bind their own)
    let passes: Vec<usize> = module.entry_points.iter().enumerate().filter(|(_, e)| e.name.starts_with("lobes_")).map(|(i, _)| i).collect();
    let readers = |h: naga::Handle<naga::GlobalVariable>| -> Vec<String> { passes.iter().filter(|&&i| !info.get_entry_point(i)[h].is_empty()).map(|&i| module.entry_points[i].name.clone()).collect() };
    let mut bound = Vec::new();
    for (h, g) in module.global_variables.iter().filter(|(_, g)| g.binding.is_some() && !g.name.as_deref().is_some_and(|n| n.starts_with("lobes_"))) {
        let entries = readers(h);
        if entries.is_empty() {
            continue;
        }
        let span = module.global_variables.get_span(h);
        let global = g.name.as_deref().unwrap_or("?");
        let Some((name, resource)) = given.iter().find(|(n, _)| resources::names(global, n)) else {
            let as_declared = declared.iter().find(|(n, _)| n == global).map(|(_, b)| *b).or(g.binding).expect("a binding");
            return Err(CheckError::Advised(unbound(c.diagnostic_at(span, &unbound_message(g, &as_declared, module)), g)));
        };
        // a file another composition of the same files read and held to this declaration is not read again
        let data = match loaded.iter().find(|b| &b.name == name) {
            Some(b) => b.data.clone(),
            None => {
                let data = resources::load(name, resource).map_err(|e| CheckError::setting(e.kind.into(), e.message))?;
                resources::fits(name, &data, g, module).map_err(|e| CheckError::Input(c.diagnostic_at(span, &e)))?;
                std::sync::Arc::new(data)
            }
        };
        let binding = g.binding.as_ref().expect("a binding").binding;
        bound.push(resources::Bound { name: name.clone(), binding, data, entries });
    }
    c.bound = bound;
    Ok(())
}

/// Why a reached resource of the user's has nothing bound (what to give: [`unbound`]); a
/// naga_oil name (`nameX_naga_oil_mod_X…X`) as the user's plain name and its module.
fn unbound_message(g: &naga::GlobalVariable, b: &naga::ResourceBinding, module: &naga::Module) -> String {
    let global = g.name.as_deref().unwrap_or("?");
    let (name, from) = match super::resources::undecorated(global) {
        Some((name, module)) => (name, format!(" of module {module}")),
        None => (global, String::new()),
    };
    format!(
        "`{name}`{from} (@group({}) @binding({}), {}) is a resource of the renderer that the sampler reads, and nothing is bound to it",
        b.group,
        b.binding,
        resource_kind(g, &module.types[g.ty].inner)
    )
}

/// `diagnostic` (of an unbound resource `g`) with how to mend it: bind its contents, or stand in
/// for its module.
fn unbound(diagnostic: String, g: &naga::GlobalVariable) -> Message {
    let global = g.name.as_deref().unwrap_or("?");
    let name = super::resources::undecorated(global).map_or(global, |(name, _)| name);
    Message::text(format!("{diagnostic}\n    help: bind its contents ("))
        .setting(Setting::Texture)
        .then(format!(" {name}=FILE.hdr for a texture_2d<f32>, "))
        .setting(Setting::Buffer)
        .then(format!(" {name}=FILE.npy for a storage array, "))
        .setting(Setting::Filter)
        .then(format!(" {name}=linear or nearest for a sampler), or give the test a stand-in without it ("))
        .setting(Setting::Stub)
        .then(" MODULE=FILE with a constant or a function in its place, e.g. a lookup table as a const array)")
}

/// What kind of resource a bound global is, for messages: "a storage buffer", "a texture", ….
fn resource_kind(g: &naga::GlobalVariable, inner: &naga::TypeInner) -> &'static str {
    match (g.space, inner) {
        (naga::AddressSpace::Storage { .. }, _) => "a storage buffer",
        (naga::AddressSpace::Uniform, _) => "a uniform buffer",
        (_, naga::TypeInner::Image { .. }) => "a texture",
        (_, naga::TypeInner::Sampler { comparison: true }) => "a sampler_comparison",
        (_, naga::TypeInner::Sampler { .. }) => "a sampler",
        (_, naga::TypeInner::AccelerationStructure { .. }) => "an acceleration structure",
        _ => "a resource",
    }
}

/// Whether the user's files may not use `name` at module scope: the `lobes_`/`LOBES_`/`Lobes`
/// prefix of the passes and of every name of lobes' own files in a composition
/// ([`lobes_own_names`]).
pub(super) fn reserved(name: &str) -> bool {
    name.starts_with("lobes_") || name.starts_with("LOBES_") || name.starts_with("Lobes")
}

/// The names lobes' own files (the passes, the RNG, the binning and what it imports) declare at
/// module scope without a reserved prefix, which the composition renames to `lobes_…` (an
/// α-renaming): a renderer's files hold `PI`, `Real` or `pcg4d` too (GLSL-PathTracer's RNG is a
/// `pcg4d`), and a composed check holds both.
fn lobes_own_names(pieces: &[(String, String)]) -> Vec<&str> {
    let own = pieces.iter().filter(|(path, _)| path != GLUE);
    own.flat_map(|(_, text)| crate::embed::declared(text)).filter(|n| !reserved(n)).collect()
}

impl Drop for Passes<'_> {
    /// On an abandoned device (a pass ran past the deadline or was stopped, and may still be
    /// running) the module and pipelines are leaked, not destroyed: a driver destroys a pipeline
    /// under the lock its queue holds while it runs a shader (lavapipe), so dropping one would
    /// hold the process as long as the shader runs, forever for a sampler that loops (as
    /// [`Gpu`]'s own drop keeps the device).
    fn drop(&mut self) {
        if self.gpu.abandoned().is_some() {
            std::mem::forget(std::mem::take(self.pipelines.get_mut()));
            std::mem::forget(std::mem::take(self.histograms.get_mut()));
            std::mem::forget(self.module.clone());
        }
    }
}

impl<'g> Passes<'g> {
    /// The passes of `sampler`, its --rand draws in the order it declares ([`compose`]).
    pub fn new(gpu: &'g Gpu, sampler: &UserSampler) -> Result<Self, CheckError> {
        Self::ordered(gpu, sampler, default_order(sampler))
    }

    /// The passes of `sampler` with its --rand draws in the order `order` ([`compose_ordered`]).
    pub fn ordered(gpu: &'g Gpu, sampler: &UserSampler, order: [u32; 4]) -> Result<Self, CheckError> {
        let composed = compose_ordered(sampler, order)?;
        // `composed` is already validated with its errors mapped to the user's files
        let module = gpu.module_unvalidated("lobes check", &composed.text)?;
        gpu.check_errors()?;
        unfilterable(gpu, &composed.bound)?;
        let resources = composed.bound.iter().map(|b| (b.binding, b.entries.clone(), GpuResource::upload(gpu, b))).collect();
        gpu.check_errors()?;
        let timed = std::cell::Cell::new(gpu.has_timestamps().then_some(0.0));
        Ok(Self { gpu, module, gpu_seconds: timed, pipelines: Default::default(), resources, group1: Default::default(), sampler: sampler.clone(), order, loaded: composed.bound.clone(), histograms: Default::default() })
    }

    /// Group 1 of `entry`'s pipeline: the user's resources it reads; `None` where it reads none.
    fn group1(&self, entry: &str, pipeline: &wgpu::ComputePipeline) -> Option<wgpu::BindGroup> {
        if let Some(g) = self.group1.borrow().get(entry) {
            return g.clone();
        }
        let entries: Vec<wgpu::BindGroupEntry> = self.resources.iter().filter(|(_, readers, _)| readers.iter().any(|r| r == entry)).map(|(k, _, r)| r.entry(*k)).collect();
        let g = (!entries.is_empty()).then(|| self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("check group 1"), layout: &pipeline.get_bind_group_layout(1), entries: &entries }));
        self.group1.borrow_mut().insert(entry.to_string(), g.clone());
        g
    }

    /// GPU time of the passes run so far, where the adapter has timestamp queries.
    pub fn gpu_seconds(&self) -> Option<f64> {
        self.gpu_seconds.get()
    }

    /// Runs `entry` over `invocations` invocations through the engine's dispatcher and reads back
    /// `out_bytes` of the buffer it writes, bound where `output` says.
    fn run(&self, entry: &str, params: &Params, input: &[[f32; 4]], invocations: u32, out_bytes: u64, output: Output) -> Result<Vec<u8>, CheckError> {
        let gpu = self.gpu;
        let pipeline = self.pipeline(entry)?;
        let uniform = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("check params"),
            contents: bytemuck::bytes_of(params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let out = gpu.buffer("check out", out_bytes, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let mut padded = bytemuck::cast_slice::<_, u8>(input).to_vec();
        padded.resize(padded.len().max(16), 0);
        let input_buf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("check in"),
            contents: &padded,
            usage: wgpu::BufferUsages::STORAGE,
        });
        let mut entries = vec![wgpu::BindGroupEntry { binding: binding::PARAMS, resource: uniform.as_entire_binding() }];
        if !input.is_empty() {
            entries.push(wgpu::BindGroupEntry { binding: binding::CHECK_IN, resource: input_buf.as_entire_binding() });
        }
        entries.push(wgpu::BindGroupEntry { binding: output.binding(), resource: out.as_entire_binding() });
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(entry), layout: &pipeline.get_bind_group_layout(0), entries: &entries });
        let step = Step { pipeline: &pipeline, groups: invocations.div_ceil(WG) as u64 };
        let group1 = self.group1(entry, &pipeline);
        let seconds = gpu.dispatch(&[Pass { label: entry, bind: &bind, offset: None, steps: vec![step], group1: group1.as_ref() }])?;
        self.gpu_seconds.set(self.gpu_seconds.get().zip(seconds).map(|(a, b)| a + b));
        Ok(gpu.read(&out, out_bytes)?)
    }

    /// Per rectangle (a0, a1, b0, b1) in hemisphere h and quadrant k, `(rect, [h, k, root])` (b
    /// measured from the axis k quarter turns from +x, `lobes_domain_point`; root 1 where the
    /// first coordinate is s = √a, `quadrature::Rect`): (∫pdf 5×5, ∫pdf 3×3, ∫eval 5×5, ∫eval
    /// 3×3), and whether the pdf's support has an edge there with its scale (1 or 0, the smallest
    /// pdf > 0 seen times the area, 0, 0; `lobes_support_edge`).
    pub fn integrate(&self, params: &Params, rects: &[([f32; 4], [f32; 3])]) -> Result<Vec<[[f32; 4]; 2]>, CheckError> {
        let mut out = Vec::with_capacity(rects.len());
        for chunk in rects.chunks(RECTS_PER_CALL) {
            let input: Vec<[f32; 4]> = chunk.iter().map(|r| r.0).chain(chunk.iter().map(|r| [r.1[0], r.1[1], r.1[2], 0.0])).collect();
            let p = Params { count: chunk.len() as u32, ..*params };
            let bytes = self.run("lobes_integrate_rects", &p, &input, chunk.len() as u32, chunk.len() as u64 * 32, Output::Values)?;
            let values: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
            let (rules, edges) = values.split_at(chunk.len());
            out.extend(rules.iter().zip(edges).map(|(r, e)| [*r, *e]));
        }
        Ok(out)
    }

    /// Per rectangle as [`Self::integrate`] reads it, ∫pdf by the 5 × 5 rule alone: the first
    /// number `integrate` gives, by the same arithmetic (`lobes_integrate_pdf`).
    pub fn integrate_pdf(&self, params: &Params, rects: &[([f32; 4], [f32; 3])]) -> Result<Vec<f32>, CheckError> {
        let mut out = Vec::with_capacity(rects.len());
        for chunk in rects.chunks(RECTS_PER_CALL) {
            let input: Vec<[f32; 4]> = chunk.iter().map(|r| r.0).chain(chunk.iter().map(|r| [r.1[0], r.1[1], r.1[2], 0.0])).collect();
            let p = Params { count: chunk.len() as u32, ..*params };
            let bytes = self.run("lobes_integrate_pdf", &p, &input, chunk.len() as u32, chunk.len().div_ceil(4) as u64 * 16, Output::Values)?;
            out.extend_from_slice(&bytemuck::cast_slice::<u8, f32>(&bytes)[..chunk.len()]);
        }
        Ok(out)
    }

    /// The probe of the sample map at each (u, wi).
    pub fn probe(&self, params: &Params, items: &[([f32; 4], [f32; 3])]) -> Result<Vec<Probe>, CheckError> {
        let input: Vec<[f32; 4]> = items.iter().flat_map(|(u, w)| [*u, [w[0], w[1], w[2], 0.0]]).collect();
        let p = Params { count: items.len() as u32, ..*params };
        let bytes = self.run("lobes_probe", &p, &input, items.len() as u32, (items.len() * size_of::<Probe>()) as u64, Output::Probes)?;
        Ok(bytes.chunks_exact(size_of::<Probe>()).map(bytemuck::pod_read_unaligned).collect())
    }

    /// (pdf(d), eval(d), 0, 0) at each point d (its xyz) for the incident direction of `params`.
    pub fn pdf_at(&self, params: &Params, points: &[[f32; 4]]) -> Result<Vec<[f32; 4]>, CheckError> {
        let p = Params { count: points.len() as u32, ..*params };
        let bytes = self.run("lobes_pdf_at", &p, points, points.len() as u32, points.len() as u64 * 16, Output::Values)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// The --rand draws at each (u, wi): 2 vec4s per item, (draws, reported pdf, 0, 0) and the
    /// share along u.x, u.y, u.z, u.w (user_passes.wgsl: lobes_draws).
    pub fn draws(&self, params: &Params, items: &[([f32; 4], [f32; 3])]) -> Result<Vec<[[f32; 4]; 2]>, CheckError> {
        let input: Vec<[f32; 4]> = items.iter().flat_map(|(u, w)| [*u, [w[0], w[1], w[2], 0.0]]).collect();
        let p = Params { count: items.len() as u32, ..*params };
        let bytes = self.run("lobes_draws", &p, &input, items.len() as u32, items.len() as u64 * 2 * 16, Output::Values)?;
        let flat: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        Ok(flat.chunks(2).map(|c| [c[0], c[1]]).collect())
    }

    /// Counts of samples `first .. first + count` per cell (the bins of the grid of `params`,
    /// then the reasons), and the --rand draws past the queue's four: by `lobes run`'s counting
    /// kernel ([`compose_histogram`]) in the counting [`Counting::choose`] picks for the adapter
    /// (`force` asks for a strategy, as tests do), in dispatches of at most [`CHUNK`] samples
    /// folded into 64-bit totals, and as `lobes run` does in tiles of bins where the totals of
    /// all of them do not fit one storage binding ([`Tiling::fit`]), each a pass over the samples.
    pub fn histogram(&self, params: &Params, first: u64, count: u64, force: Option<Strategy>) -> Result<Counted, CheckError> {
        let gpu = self.gpu;
        let bins = params.rows * params.cols;
        let (tiling, counting) = histogram_counting(gpu.info.device_type, &gpu.limits, bins, force)?;
        let tile_bins = tiling.tile_bins as u32;
        let kernel = self.histogram_kernel(params.rows, params.cols, tile_bins, counting)?;
        let cells = tile_bins as u64 + N_REASONS as u64;
        let mut counted = Counted { counts: vec![0; bins as usize + N_REASONS as usize], over_drawn: 0, most_draws: 0 };
        for tile in 0..tiling.tiles as u32 {
            let buffers = HistogramBuffers::new(gpu, cells, tile_bins, counting);
            let tile_first = tile * tile_bins;
            for chunk in (SampleRange { seed: 0, first, count }).chunks(CHUNK) {
                let p = Params { base: split(chunk.first), count: chunk.count as u32, tile_first, ..*params };
                let draws = self.count_chunk(&kernel, &buffers, &p, counting.groups(chunk.count), cells)?;
                // every tile draws every sample: the draws are the first tile's
                if tile == 0 {
                    (counted.over_drawn, counted.most_draws) = (counted.over_drawn + draws[0] as u64, counted.most_draws.max(draws[1]));
                }
            }
            let totals = gpu.read_u64(&buffers.totals, cells)?;
            let in_tile = (tile_bins as usize).min(bins as usize - tile_first as usize);
            counted.counts[tile_first as usize..][..in_tile].copy_from_slice(&totals[..in_tile]);
            // every tile counts the reasons alike
            counted.counts[bins as usize..].copy_from_slice(&totals[tile_bins as usize..]);
        }
        Ok(counted)
    }

    /// Counts one chunk of samples (`p`'s range, `groups` workgroups of the sampling) into
    /// `buffers`' totals; the --rand draw counters of the chunk, left 0.
    fn count_chunk(&self, kernel: &HistogramKernel, buffers: &HistogramBuffers, p: &Params, groups: u64, cells: u64) -> Result<[u32; 2], CheckError> {
        let gpu = self.gpu;
        let uniform = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("check params"), contents: bytemuck::bytes_of(p), usage: wgpu::BufferUsages::UNIFORM });
        let bind = |(pipeline, used): &(wgpu::ComputePipeline, Vec<u32>)| -> Result<wgpu::BindGroup, CheckError> {
            let entries = used.iter().map(|&b| Ok(wgpu::BindGroupEntry { binding: b, resource: buffers.at(b, &uniform)?.as_entire_binding() }));
            let entries: Vec<wgpu::BindGroupEntry> = entries.collect::<Result<_, CheckError>>()?;
            Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("check histogram"), layout: &pipeline.get_bind_group_layout(0), entries: &entries }))
        };
        let (sample_bind, fold_bind) = (bind(&kernel.sample)?, bind(&kernel.fold)?);
        let passes = [
            Pass { label: SAMPLE_ENTRY, bind: &sample_bind, offset: None, steps: vec![Step { pipeline: &kernel.sample.0, groups }], group1: kernel.group1.as_ref() },
            Pass { label: "lobes_fold", bind: &fold_bind, offset: None, steps: vec![Step { pipeline: &kernel.fold.0, groups: cells.div_ceil(WG_SIZE as u64) }], group1: None },
        ];
        let seconds = gpu.dispatch(&passes)?;
        self.gpu_seconds.set(self.gpu_seconds.get().zip(seconds).map(|(a, b)| a + b));
        let draws: [u32; 2] = bytemuck::pod_read_unaligned(&gpu.read(&buffers.draws, 8)?);
        gpu.clear(&buffers.draws);
        Ok(draws)
    }

    /// The histogram's kernel of a `rows` × `cols` grid counting tiles of `tile_bins` bins as
    /// `counting` says, composed and compiled at its first use.
    fn histogram_kernel(&self, rows: u32, cols: u32, tile_bins: u32, counting: Counting) -> Result<std::rc::Rc<HistogramKernel>, CheckError> {
        let key = (rows, cols, tile_bins, counting);
        if let Some(k) = self.histograms.borrow().get(&key) {
            return Ok(k.clone());
        }
        let (composed, naga_module, info) = compose_histogram(&self.sampler, self.order, (rows, cols, tile_bins), counting, &self.loaded)?;
        let module = self.gpu.module_unvalidated("lobes check's histogram", &composed.text)?;
        self.gpu.check_errors()?;
        let pipeline = |entry: &str| -> Result<(wgpu::ComputePipeline, Vec<u32>), CheckError> {
            Ok((self.gpu.pipeline(&module, None, entry, &[])?, group0_bindings(&naga_module, &info, entry)))
        };
        let (sample, fold) = (pipeline(SAMPLE_ENTRY)?, pipeline("lobes_fold")?);
        let read: Option<Vec<wgpu::BindGroupEntry>> = composed
            .bound
            .iter()
            .filter(|b| b.entries.iter().any(|e| e == SAMPLE_ENTRY))
            .map(|b| self.resources.iter().find(|(k, ..)| *k == b.binding).map(|(k, _, r)| r.entry(*k)))
            .collect();
        let read = read.ok_or_else(|| CheckError::Internal("the histogram reads a resource that no other pass reads".into()))?;
        let layout = sample.0.get_bind_group_layout(1);
        let group1 = (!read.is_empty()).then(|| self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("check histogram group 1"), layout: &layout, entries: &read }));
        let k = std::rc::Rc::new(HistogramKernel { _module: module, sample, fold, group1 });
        self.histograms.borrow_mut().insert(key, k.clone());
        Ok(k)
    }

    /// The pipeline of `entry`, made at its first use.
    fn pipeline(&self, entry: &str) -> Result<wgpu::ComputePipeline, CheckError> {
        if let Some(p) = self.pipelines.borrow().get(entry) {
            return Ok(p.clone());
        }
        let p = self.gpu.pipeline(&self.module, None, entry, &[])?;
        self.pipelines.borrow_mut().insert(entry.to_string(), p.clone());
        Ok(p)
    }

    /// Per-invocation weight sums of samples `first .. first + count` (user_passes.wgsl,
    /// `lobes_weights`): (Σw, Σw², max weight error, samples with eval > 0) and (Σ|w − w_pdf|,
    /// max weight error over its allowance, 0, 0).
    pub fn weights(&self, params: &Params, first: u64, count: u32) -> Result<Vec<[[f32; 4]; 2]>, CheckError> {
        let spt = 64u32;
        let p = Params { base: split(first), count, samples_per_thread: spt, ..*params };
        let n = count.div_ceil(spt);
        let bytes = self.run("lobes_weights", &p, &[], n, n as u64 * 32, Output::Values)?;
        let flat: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        Ok(flat.chunks(2).map(|c| [c[0], c[1]]).collect())
    }

    /// `entry` over `items` in calls of at most 2^20, one vec4 out per item.
    fn per_item(&self, entry: &str, params: &Params, items: &[[f32; 4]]) -> Result<Vec<[f32; 4]>, CheckError> {
        let mut out = Vec::with_capacity(items.len());
        for chunk in items.chunks(1 << 20) {
            let p = Params { count: chunk.len() as u32, ..*params };
            let bytes = self.run(entry, &p, chunk, chunk.len() as u32, chunk.len() as u64 * 16, Output::Values)?;
            out.extend_from_slice(bytemuck::cast_slice(&bytes));
        }
        Ok(out)
    }

    /// sample(wi, u) at each u, at the incident direction of `params` (the Jacobian's steps).
    pub fn map(&self, params: &Params, us: &[[f32; 4]]) -> Result<Vec<[f32; 4]>, CheckError> {
        self.per_item("lobes_map", params, us)
    }

    /// (pdf(d), the pdf's f32 conditioning at d) at each point d, at the incident direction of
    /// `params` (user_passes.wgsl, `lobes_conditioning_at`).
    pub fn conditioning(&self, params: &Params, points: &[[f32; 3]]) -> Result<Vec<[f32; 2]>, CheckError> {
        let items: Vec<[f32; 4]> = points.iter().map(|d| [d[0], d[1], d[2], 0.0]).collect();
        Ok(self.per_item("lobes_conditioning", params, &items)?.into_iter().map(|v| [v[0], v[1]]).collect())
    }
}

/// The order of the --rand queue (the component of u each draw takes) and a note for the
/// report: `--rand-order` as given, else what lobes' probe finds at 256 uniforms, with the queue
/// in call order: a draw along which the sample stays put over a run of its values (a share in
/// [0, 1), as the Jacobian check measures events on u.z and u.w) chooses an event and goes to
/// u.z, then u.w; the others move the direction and go to u.x, then u.y. (More than four draws
/// in one sample the histogram refuses, counted on every sample.)
pub(super) fn rand_order(passes: &Passes, params: &Params, sampler: &UserSampler, seed: u64) -> Result<([u32; 4], String), CheckError> {
    let wi = [params.wi[0], params.wi[1], params.wi[2]];
    let margin = 2.0 * super::jacobian::EPS as f64;
    let items: Vec<([f32; 4], [f32; 3])> = (0..256u64)
        .map(|i| (crate::reference::rng::uniforms(seed ^ 0x5851_f42d_4c95_7f2d, i).map(|x| (margin + (1.0 - 2.0 * margin) * x) as f32), wi))
        .collect();
    let out = passes.draws(params, &items)?;
    // the order of the queue's four; draws past them are counted on every sample of the
    // histogram, and refused there (`too_many_draws`)
    let most = out.iter().map(|o| o[0][0] as u32).max().unwrap_or(0).min(4);
    let names = sampler.composition.rand.join(", ");
    if most == 0 {
        return Err(CheckError::setting(Setting::Rand, format!(
            "{names}: no sample called {} (256 probed); name the functions the sampler draws its random numbers from",
            if sampler.composition.rand.len() == 1 { "it" } else { "them" }
        )));
    }
    if let Some(order) = &sampler.composition.rand_order {
        let c = Draw::components(order);
        return Ok((c, format!("; random draws {} (in the order given)", Draw::list(&c, most as usize))));
    }
    let mut kinds = Vec::new();
    for k in 0..most as usize {
        let valid = out.iter().filter(|o| o[0][1] > 0.0 && o[0][1].is_finite());
        let (smooth, event) = valid.fold((0, 0), |(s, e), o| match o[1][k] {
            x if x < 0.0 => (s + 1, e),
            x if x < 1.0 => (s, e + 1),
            _ => (s, e),
        });
        kinds.push(event > smooth);
    }
    let events = kinds.iter().filter(|&&e| e).count();
    if events == 0 || events > 2 || kinds.len() - events > 2 {
        // each draw named by what the probe found, not by the component it takes: a third
        // continuous draw takes u.z, and is no event for that
        let names: Vec<&str> = kinds.iter().zip(["x", "y", "z", "w"]).map(|(&e, c)| if e { "event" } else { c }).collect();
        return Ok((Draw::components(&[]), format!("; random draws {} in call order", names.join(","))));
    }
    let mut smooth = [Draw::X, Draw::Y].into_iter();
    let order: Vec<Draw> = kinds.iter().map(|&e| if e { Draw::Event } else { smooth.next().expect("at most two") }).collect();
    let c = Draw::components(&order);
    Ok((c, format!("; random draws {} (found by lobes' probe)", Draw::list(&c, most as usize))))
}

/// A 64-bit value as the (lo, hi) pair the kernels take.
pub(super) fn split(v: u64) -> [u32; 2] {
    [v as u32, (v >> 32) as u32]
}

/// Pointwise comparisons of the pdf (`pdf_consistency`, `jacobian`, `weights`) allow, on top of
/// their limit, this many times the pdf's f32 conditioning at the point: the largest relative
/// change of pdf(d) under a change of one component of d by 2⁻²³ |d|∞, measured on the GPU
/// (`lobes_conditioning_at` in shaders/check/user_passes.wgsl). A narrow lobe amplifies an ulp:
/// GGX's D(m) in the form α² / (π ((α² − 1) m.z² + 1)²) turns an ulp of m.z into ≈ 4/α² ulps of
/// D (0.4 % at α = 0.008), so a correct sampler and its pdf, the same f32 code compiled at two
/// call sites, differ by that much. A sampler's d carries a few ulps of rounding: 4 of them.
pub const CONDITIONING_ULPS: f64 = 4.0;

/// The passes' parameters of a check: the user's numbers, the incident direction, the seed and
/// the grid.
pub(super) fn params_of(sampler: &UserSampler, settings: &Settings) -> Params {
    let (rows, cols) = settings.grid(&sampler.domain);
    let wi = super::incident(settings.incident_theta, settings.incident_phi);
    let bounds = sampler.domain.uniform_bounds();
    Params {
        user: Params::user_numbers(&settings.params),
        wi: [wi[0], wi[1], wi[2], 0.0],
        bounds,
        seed: split(settings.seed),
        eps: super::jacobian::EPS,
        samples_per_thread: 1,
        rows,
        cols,
        ..bytemuck::Zeroable::zeroed()
    }
}

/// The sampler's passes, with the user's --rand draws (at most four) in the order lobes' probe
/// finds them unless --rand-order gave it, and the note on that order for the report.
pub(super) fn compose_passes<'g>(gpu: &'g Gpu, sampler: &UserSampler, settings: &Settings, params: &Params) -> Result<(Passes<'g>, String), CheckError> {
    let mut passes = Passes::new(gpu, sampler)?;
    let mut draws = String::new();
    if !sampler.composition.rand.is_empty() {
        let (order, note) = rand_order(&passes, params, sampler, settings.seed)?;
        if sampler.composition.rand_order.is_none() && order != Draw::components(&[]) {
            passes = Passes::ordered(gpu, sampler, order)?;
        }
        draws = note;
    }
    Ok((passes, draws))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weights pass's limits are the host's constants.
    #[test]
    fn weights_pass_constants_are_the_hosts() {
        let source = include_str!("../../shaders/check/user_passes.wgsl");
        let value = |name: &str| -> f64 {
            let line = source.lines().find(|l| l.starts_with(&format!("const {name}: f32 = "))).unwrap_or_else(|| panic!("{name}"));
            line.split('=').nth(1).unwrap().trim().trim_end_matches(';').parse().unwrap()
        };
        assert_eq!(value("LOBES_WEIGHT_LIMIT") as f32, crate::stats::weighted::WEIGHT_ERROR_LIMIT);
        assert_eq!(value("LOBES_CONDITIONING_ULPS"), super::CONDITIONING_ULPS);
    }

    fn sampler(text: &str) -> UserSampler {
        let sources = vec![super::super::Source { name: "t.wgsl".into(), text: text.into() }];
        UserSampler { sources, sample: "s".into(), pdf: "p".into(), eval: None, domain: super::super::Domain::Sphere, conventions: Default::default(), composition: Default::default() }
    }

    /// The user's lines keep their file's numbers in the composition, and valid WGSL that
    /// naga_oil would refuse as a module of its own (a struct member ending in a digit) composes.
    #[test]
    fn user_files_keep_their_lines_and_need_not_suit_naga_oil() {
        let text = "struct P { v0: f32 }\n\
                    fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> { let q = P(u.x); return vec4<f32>(wi, q.v0); }\n\
                    fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 { return 1.0; }\n";
        let c = compose(&sampler(text)).unwrap();
        let line = c.text.lines().position(|l| l.starts_with("fn s(")).unwrap() as u32 + 1;
        assert_eq!(c.locate(line, 1), "t.wgsl:2:1");
        for entry in ["fn lobes_weights(", "fn lobes_probe(", "fn lobes_rng_uniforms(", "fn lobes_user_sample("] {
            assert!(c.text.contains(entry), "{entry}");
        }
    }

    /// `lobes_integrate_pdf` gives the first number of `lobes_integrate_rects` bit for bit (the
    /// sensitivity of ∫pdf to an ulp subtracts the one from the other): a pdf with an eval, on
    /// rectangles in both hemispheres, every quadrant, in a and in s = √a, wide and narrow.
    #[test]
    fn the_pdf_pass_repeats_the_quadrature_pass_bit_for_bit() {
        let text = "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> { return vec4<f32>(0.0, 0.0, 1.0, 1.0); }\n\
                    fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {\n\
                        let a2 = params[0].x * params[0].x; let h = normalize(wi + d); let t = (a2 - 1.0) * h.z * h.z + 1.0;\n\
                        return max(h.z, 0.0) * a2 / (3.14159265 * t * t) / (4.0 * abs(dot(wi, h)) + 1e-3); }\n\
                    fn e(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 { return exp(-d.x * d.y); }\n";
        let mut s = sampler(text);
        s.eval = Some("e".into());
        let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
        let passes = Passes::new(&gpu, &s).unwrap();
        let wi = crate::check::incident(40.0, 20.0);
        let params = Params { user: [[0.05, 0.0, 0.0, 0.0], [0.0; 4], [0.0; 4], [0.0; 4]], wi: [wi[0], wi[1], wi[2], 0.0], ..bytemuck::Zeroable::zeroed() };
        let mut rects = Vec::new();
        for i in 0..4096u32 {
            let (x, y) = ((i % 64) as f32 / 64.0, (i / 64) as f32 / 64.0);
            let w = if i % 3 == 0 { 1e-4 } else { 1.0 / 64.0 };
            rects.push(([x, x + w, -0.78 + 1.5 * y, -0.78 + 1.5 * y + w], [if i % 2 == 0 { 1.0 } else { -1.0 }, (i % 4) as f32, (i % 5 == 0) as u32 as f32]));
        }
        let full = passes.integrate(&params, &rects).unwrap();
        let pdf = passes.integrate_pdf(&params, &rects).unwrap();
        assert!(full.iter().any(|r| r[0][0] > 0.0) && full.iter().any(|r| r[0][2] != 0.0));
        let differ = full.iter().zip(&pdf).filter(|(f, p)| f[0][0].to_bits() != p.to_bits()).count();
        assert_eq!(differ, 0, "{differ} of {} rectangles' ∫pdf differ", rects.len());
    }

    /// The histogram counts alike in per-invocation slabs (CPU adapters) and in workgroup
    /// atomics (GPUs), bit for bit, on whatever adapter wgpu finds (lavapipe in CI), and over
    /// several dispatches as over their ranges apart: a sampler that spreads over the sphere's
    /// bins and sends known shares of u to each invalid reason.
    /// Uniform over the sphere, with 1 % of its samples outside the domain (|d| = 2) and 1 %
    /// rejected (pdf 0).
    const SPREAD: &str = "fn s(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {\n\
                              let z = 2.0 * u.x - 1.0; let r = sqrt(max(1.0 - z * z, 0.0)); let phi = 6.2831853 * u.y;\n\
                              let d = vec3<f32>(r * cos(phi), r * sin(phi), z);\n\
                              if (u.z < 0.01) { return vec4<f32>(2.0 * d, 1.0); }\n\
                              if (u.z < 0.02) { return vec4<f32>(d, 0.0); }\n\
                              return vec4<f32>(d, 0.25 / 3.14159265); }\n\
                          fn p(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 { return 0.25 / 3.14159265; }\n";

    #[test]
    fn histogram_slabs_count_as_atomics() {
        let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
        let passes = Passes::new(&gpu, &sampler(SPREAD)).unwrap();
        let (rows, cols) = (32, 64);
        let params = Params { wi: [0.0, 0.0, 1.0, 0.0], seed: [7, 0], rows, cols, ..bytemuck::Zeroable::zeroed() };
        for (first, count) in [(0u64, 1_000_003u64), (5_000_000_000, 77)] {
            let atomics = passes.histogram(&params, first, count, Some(Strategy::Atomics)).unwrap().counts;
            let slabs = passes.histogram(&params, first, count, Some(Strategy::Slabs)).unwrap().counts;
            assert_eq!(atomics.len(), (rows * cols) as usize + Invalid::COUNT);
            assert_eq!(atomics.iter().sum::<u64>(), count);
            assert!(atomics == slabs, "slabs and atomics counted samples {first}.. differently");
        }
        // over more than one dispatch, the counts of its two ranges summed
        let whole = passes.histogram(&params, 3, CHUNK + 77, None).unwrap().counts;
        let (a, b) = (passes.histogram(&params, 3, CHUNK, None).unwrap().counts, passes.histogram(&params, CHUNK + 3, 77, None).unwrap().counts);
        assert!(whole.iter().zip(a.iter().zip(&b)).all(|(w, (a, b))| *w == a + b), "the chunks of one histogram count as their ranges apart");
        // about 1 % each outside the domain and with pdf 0 (10 000 ± 100)
        let counts = passes.histogram(&params, 0, 1_000_003, Some(Strategy::Slabs)).unwrap().counts;
        let bins = (rows * cols) as usize;
        let (outside, zero) = (counts[bins + Invalid::OutsideDomain.index()], counts[bins + Invalid::ZeroPdf.index()]);
        assert!((9_500..10_500).contains(&outside) && (9_500..10_500).contains(&zero), "{outside} {zero}");
    }

    /// A grid whose 64-bit totals do not fit one storage binding is counted in tiles, each a
    /// pass over the samples, as `lobes run` counts its jobs: on an adapter that binds 8 KiB,
    /// 32 × 64 bins in three tiles, counted bit for bit as in one pass, the reasons and the
    /// --rand draws once.
    #[test]
    fn a_grid_too_large_for_one_binding_is_counted_in_tiles() {
        let whole = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
        let small = Gpu::with_limits(|l| wgpu::Limits { max_storage_buffer_binding_size: 8192, ..l }).unwrap();
        let (rows, cols) = (32, 64);
        assert_eq!(histogram_counting(small.info.device_type, &small.limits, rows * cols, None).unwrap().0.tiles, 3);
        let params = Params { wi: [0.0, 0.0, 1.0, 0.0], seed: [3, 0], rows, cols, ..bytemuck::Zeroable::zeroed() };
        let one = Passes::new(&whole, &sampler(SPREAD)).unwrap().histogram(&params, 11, 300_001, None).unwrap();
        let tiled = Passes::new(&small, &sampler(SPREAD)).unwrap().histogram(&params, 11, 300_001, None).unwrap();
        assert_eq!(tiled.counts.iter().sum::<u64>(), 300_001);
        assert!(one == tiled, "the tiles count as one pass does");
    }
}
