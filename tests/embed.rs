//! `lobes::embed` used the way a renderer uses it: the composed WGSL inside kernels of our own,
//! checked on the GPU against the f64 reference; and the two examples, whose code is compiled
//! into this test and run here. GPU tests: they need a wgpu adapter (lavapipe in CI) and fail
//! without one.

#[path = "../examples/dfg_lut.rs"]
#[allow(dead_code)]
mod dfg_lut;
#[path = "../examples/end_to_end.rs"]
#[allow(dead_code)]
mod end_to_end;

use glam::DVec3;
use lobes::embed::{self, DISCRETE_INFO_WGSL, DiscreteBindings, DiscreteBuffers, DiscreteTable, Module};
use lobes::engine::gpu::{Gpu, GpuEngine};
use lobes::engine::job::{DiscreteMethod, Job, SampleRange};
use lobes::reference::discrete::Distribution;
use lobes::reference::{Lobe, reflect, rng};
use wgpu::util::DeviceExt;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"))
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

/// Runs `entry` of `source` over `invocations` threads (workgroups of 64) with the given bind
/// groups and returns the contents of `out`.
fn dispatch(gpu: &Gpu, source: &str, entry: &str, layouts: &[&wgpu::BindGroupLayout], groups: &[&wgpu::BindGroup], invocations: u32, out: &wgpu::Buffer) -> Vec<u8> {
    embed::validate(source).unwrap_or_else(|e| panic!("{e}"));
    let d = &gpu.device;
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(entry), source: wgpu::ShaderSource::Wgsl(source.into()) });
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: None, bind_group_layouts: &layouts, immediate_size: 0 });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(&layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    let size = out.size();
    let read = d.create_buffer(&wgpu::BufferDescriptor { label: None, size, usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST, mapped_at_creation: false });
    let mut encoder = d.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, *g, &[]);
        }
        pass.dispatch_workgroups(invocations.div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(out, 0, &read, 0, size);
    gpu.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    read.map_async(wgpu::MapMode::Read, 0..size, move |r| tx.send(r).unwrap());
    d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    rx.recv().unwrap().unwrap();
    let bytes = read.get_mapped_range(0..size).unwrap().to_vec();
    read.unmap();
    bytes
}

const SAMPLERS: &str = r#"
struct TestParams {
    wi: vec4<f32>,
    a: vec4<f32>,
    seed: vec4<u32>,
}
@group(0) @binding(0) var<uniform> tp: TestParams;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

// Per sample and sampler k: (wr, the sampler's pdf_r), then (the pdf function at wr, eval at wr).
fn put(i: u32, k: u32, s: LobesLobeSample, pdf: f32, f: f32) {
    results[12u * i + 2u * k] = vec4<f32>(s.wr, s.pdf_r);
    results[12u * i + 2u * k + 1u] = vec4<f32>(pdf, f, 0.0, 0.0);
}

@compute @workgroup_size(64)
fn sample_all(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&results) / 12u) {
        return;
    }
    let u = lobes_rng_uniforms(tp.seed.xy, vec2<u32>(i, 0u)).xy;
    let a = tp.a.xy;
    let wi = tp.wi.xyz;
    var s = lobes_ward_sample(a, wi, u);
    put(i, 0u, s, lobes_ward_pdf(a, wi, s.wr), lobes_ward_eval(a, wi, s.wr));
    s = lobes_beckmann_sample_ndf(a, wi, u);
    put(i, 1u, s, lobes_beckmann_pdf_ndf(a, wi, s.wr), lobes_beckmann_eval(a, wi, s.wr));
    s = lobes_beckmann_sample_vndf(a, wi, u);
    put(i, 2u, s, lobes_beckmann_pdf_vndf(a, wi, s.wr), lobes_beckmann_eval(a, wi, s.wr));
    s = lobes_ggx_sample_ndf(a, wi, u);
    put(i, 3u, s, lobes_ggx_pdf_ndf(a, wi, s.wr), lobes_ggx_eval(a, wi, s.wr));
    s = lobes_ggx_sample_vndf(a, wi, u);
    put(i, 4u, s, lobes_ggx_pdf_vndf(a, wi, s.wr), lobes_ggx_eval(a, wi, s.wr));
    s = lobes_ggx_sample_bounded(a, wi, u);
    put(i, 5u, s, lobes_ggx_pdf_bounded(a, wi, s.wr), lobes_ggx_eval(a, wi, s.wr));
}
"#;

/// Relative difference, with values below 1e-30 (f32 underflow) counted as equal.
fn rel(gpu: f64, cpu: f64) -> f64 {
    let d = (gpu - cpu).abs();
    if d < 1e-30 { 0.0 } else { d / cpu.abs() }
}

/// Every embedded sampler, driven by the embedded RNG inside our own kernel, draws the f64
/// reference's directions from the same uniforms, and the embedded pdf and BRDF functions
/// agree with the sampler's own density and with the f64 reference at the GPU's directions
/// (relative error below 1e-4; f32 gives about 1e-5).
#[test]
fn embedded_samplers_densities_and_brdfs_match_the_f64_reference() {
    let gpu = gpu();
    let source = embed::wgsl(&[Module::Rng, Module::Ward, Module::Beckmann, Module::Ggx]) + SAMPLERS;
    let n: u32 = 4096;
    let kernels = lobes::reference::SAMPLERS;
    let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[uniform_entry(0), storage_entry(1, false)],
    });
    let mut failures = Vec::new();
    for (case, &(ax, ay, theta, phi)) in [(0.05, 0.05, 30.0, 0.0), (0.3, 0.3, 60.0, 0.0), (1.0, 1.0, 80.0, 0.0), (0.2, 0.6, 45.0, 30.0)].iter().enumerate() {
        let wi: DVec3 = reflect::spherical(f64::to_radians(theta), f64::to_radians(phi));
        let seed = 40 + case as u64;
        let mut params = [0u32; 12];
        for (k, x) in [wi.x as f32, wi.y as f32, wi.z as f32, 0.0, ax as f32, ay as f32, 0.0, 0.0].into_iter().enumerate() {
            params[k] = x.to_bits();
        }
        params[8] = seed as u32;
        params[9] = (seed >> 32) as u32;
        let uniform = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents: bytemuck::cast_slice(&params), usage: wgpu::BufferUsages::UNIFORM });
        let out = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: n as u64 * 12 * 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }, wgpu::BindGroupEntry { binding: 1, resource: out.as_entire_binding() }],
        });
        let bytes = dispatch(&gpu, &source, "sample_all", &[&layout], &[&group], n, &out);
        let res: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        for (k, &(kind, method)) in kernels.iter().enumerate() {
            let lobe = Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 };
            let (mut compared, mut mismatches, mut max_angle, mut worst_pdf, mut worst_eval, mut worst_self) = (0, 0, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for i in 0..n as usize {
                let [x, y, z, pdf_s] = res[12 * i + 2 * k];
                let [pdf_fn, eval_fn, _, _] = res[12 * i + 2 * k + 1];
                let u = rng::uniforms(seed, i as u64);
                let reference = lobe.sample(wi, [u[0], u[1]]);
                let wr = DVec3::new(x as f64, y as f64, z as f64);
                let gpu_valid = wr.is_finite() && wr.z > 0.0 && pdf_s.is_finite() && pdf_s > 0.0;
                if gpu_valid != reference.invalid.is_none() {
                    mismatches += 1;
                    continue;
                }
                if !gpu_valid {
                    continue;
                }
                compared += 1;
                max_angle = max_angle.max(lobes::run::compare::angle_between(wr.normalize(), reference.omega_r));
                // the pdf function against the sampler's own density, both on the GPU, and both
                // functions against f64 at the GPU's direction
                let wr64 = wr.normalize();
                worst_self = worst_self.max(rel(pdf_fn as f64, pdf_s as f64));
                worst_pdf = worst_pdf.max(rel(pdf_fn as f64, lobe.pdf_r(wi, wr64)));
                worst_eval = worst_eval.max(rel(eval_fn as f64, lobe.eval(wi, wr64)));
            }
            let what = format!("{kind:?} {method:?} α=({ax},{ay}) θi={theta}°");
            println!(
                "{what}: {compared} compared, {mismatches} validity mismatches, max angle {max_angle:.2e} rad, \
                 max relative error: pdf fn vs sampler {worst_self:.1e}, pdf vs f64 {worst_pdf:.1e}, eval vs f64 {worst_eval:.1e}"
            );
            if compared < n as usize / 4 || mismatches > 2 || max_angle > 1e-4 || worst_self > 1e-4 || worst_pdf > 1e-4 || worst_eval > 1e-4 {
                failures.push(format!(
                    "{what}: compared {compared}, mismatches {mismatches}, max angle {max_angle:.2e}, worst relative error: pdf fn vs sampler {worst_self:.2e}, pdf vs f64 {worst_pdf:.2e}, eval vs f64 {worst_eval:.2e}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

const DISCRETE_KERNEL: &str = r#"
@group(0) @binding(0) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(1) var<uniform> info: LobesDiscreteInfo;
@group(0) @binding(2) var<uniform> run: vec4<u32>; // seed lo, seed hi, samples, method (0 cdf, 1 alias, 2 two-level cdf)

@compute @workgroup_size(64)
fn draw_discrete(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= run.z) {
        return;
    }
    let u = lobes_rng_uniforms(run.xy, vec2<u32>(gid.x, 0u));
    var k: u32;
    if (run.w == 0u) {
        k = lobes_discrete_sample_cdf(u.x, info.n_items, info.last_positive);
    } else if (run.w == 1u) {
        k = lobes_discrete_sample_alias(u.xy, info.n_items);
    } else {
        k = lobes_discrete_sample_cdf_blocks(u.xy, info.n_items, info.last_positive);
    }
    atomicAdd(&counts[k], 1u);
}
"#;

/// A discrete distribution uploaded with `DiscreteBuffers` at bindings of our choosing, sampled
/// in our own kernel, gives exactly the histogram of lobes' own χ²-tested kernel.
#[test]
fn embedded_discrete_sampling_counts_exactly_like_the_engine() {
    let gpu = gpu();
    let mut engine = GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    let short = Distribution::new(&[0.0, 15.0, 5.0, 0.0, 25.0, 5.0, 10.0, 15.0, 5.0, 5.0, 10.0, 0.0]).unwrap();
    // longer than one block of the CDF: the two-level layout; weights 0..9, every 7th zero
    let long_weights: Vec<f64> = (0..embed::BLOCK as u64 * 2 + 123).map(|i| if i % 7 == 3 { 0.0 } else { (rng::pcg4d([i as u32, 5, 0, 0])[0] % 10) as f64 }).collect();
    let long = Distribution::new(&long_weights).unwrap();
    let bindings = DiscreteBindings { group: 1, table: 0, alias: 1 };
    let source = embed::wgsl_with(&[Module::Rng, Module::Discrete], bindings) + DISCRETE_INFO_WGSL + DISCRETE_KERNEL;
    assert!(source.contains("@group(1) @binding(1) var<storage, read> lobes_discrete_u"));
    let samples: u32 = 1 << 20;
    let seed: u64 = 0x1234_5678_9abc;
    let d = &gpu.device;
    let own = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[storage_entry(0, false), uniform_entry(1), uniform_entry(2)],
    });
    let tables = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &DiscreteBuffers::layout_entries(bindings, wgpu::ShaderStages::COMPUTE),
    });
    for (dist, method) in [(&short, DiscreteMethod::Cdf), (&short, DiscreteMethod::Alias), (&long, DiscreteMethod::Cdf), (&long, DiscreteMethod::Alias)] {
        let buffers = match method {
            DiscreteMethod::Cdf => DiscreteBuffers::cdf(d, dist),
            DiscreteMethod::Alias => DiscreteBuffers::alias(d, dist),
        };
        let table = DiscreteTable::new(dist, method);
        assert_eq!(buffers.info, table.info);
        assert_eq!(table.two_level(), method == DiscreteMethod::Cdf && dist.len() > embed::BLOCK);
        let counts = d.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: dist.len() as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let info = d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents: bytemuck::bytes_of(&buffers.info), usage: wgpu::BufferUsages::UNIFORM });
        let which = match method {
            DiscreteMethod::Alias => 1,
            DiscreteMethod::Cdf if table.two_level() => 2,
            DiscreteMethod::Cdf => 0,
        };
        let run = [seed as u32, (seed >> 32) as u32, samples, which];
        let run = d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents: bytemuck::cast_slice(&run), usage: wgpu::BufferUsages::UNIFORM });
        let g0 = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &own,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: counts.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: info.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: run.as_entire_binding() },
            ],
        });
        let g1 = d.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &tables, entries: &buffers.bind_group_entries(bindings) });
        let bytes = dispatch(&gpu, &source, "draw_discrete", &[&own, &tables], &[&g0, &g1], samples, &counts);
        let mine: Vec<u64> = bytemuck::cast_slice::<u8, u32>(&bytes).iter().map(|&c| c as u64).collect();
        let job = Job::Discrete { dist: (*dist).clone(), method };
        let theirs = engine.histogram(&job, SampleRange::whole(seed, samples as u64), &mut |_| {}).unwrap().counts;
        println!("{method:?}, {} items: {:?}", dist.len(), &mine[..12]);
        assert_eq!(mine, theirs.bins, "{method:?}, {} items: embedded sampling differs from the engine's", dist.len());
        assert_eq!(mine.iter().sum::<u64>(), samples as u64);
        for (i, w) in dist.weights().iter().enumerate() {
            if *w == 0.0 {
                assert_eq!(mine[i], 0, "{method:?}: zero-weight item {i} drawn");
            }
        }
    }
}

const TWO_TABLES_KERNEL: &str = r#"
@group(0) @binding(0) var<storage, read_write> counts: array<atomic<u32>>; // lights, then texels
@group(0) @binding(1) var<uniform> lights_info: LobesDiscreteInfo;
@group(0) @binding(2) var<uniform> texels_info: LobesDiscreteInfo;
@group(0) @binding(3) var<uniform> run: array<vec4<u32>, 2>; // per table: seed lo, seed hi, samples

@compute @workgroup_size(64)
fn draw_two(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= run[0].z) {
        return;
    }
    let light = lobes_lights_sample_alias(lobes_rng_uniforms(run[0].xy, vec2<u32>(gid.x, 0u)).xy, lights_info.n_items);
    atomicAdd(&counts[light], 1u);
    let u = lobes_rng_uniforms(run[1].xy, vec2<u32>(gid.x, 0u)).xy;
    let texel = lobes_texels_sample_cdf_blocks(u, texels_info.n_items, texels_info.last_positive);
    atomicAdd(&counts[lights_info.n_items + texel], 1u);
}
"#;

/// Two discrete tables in one kernel, each generated under a name and bindings of its own
/// (`discrete_table_wgsl`): an alias table of lights and a two-level CDF of texels, both
/// sampled by every invocation, give exactly the histograms of lobes' own χ²-tested kernel.
#[test]
fn two_embedded_discrete_tables_in_one_kernel_count_exactly_like_the_engine() {
    let gpu = gpu();
    let mut engine = GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    let lights = Distribution::new(&[3.0, 0.0, 1.0, 7.0, 2.0]).unwrap();
    let texel_weights: Vec<f64> = (0..embed::BLOCK as u64 + 77).map(|i| if i % 5 == 1 { 0.0 } else { (1 + rng::pcg4d([i as u32, 9, 0, 0])[0] % 7) as f64 }).collect();
    let texels = Distribution::new(&texel_weights).unwrap();
    let (at_lights, at_texels) = (DiscreteBindings { group: 1, table: 0, alias: 1 }, DiscreteBindings { group: 1, table: 2, alias: 3 });
    let source = embed::wgsl(&[Module::Rng])
        + &embed::discrete_table_wgsl("lights", at_lights)
        + &embed::discrete_table_wgsl("texels", at_texels)
        + DISCRETE_INFO_WGSL
        + TWO_TABLES_KERNEL;
    let d = &gpu.device;
    let (light_buffers, texel_buffers) = (DiscreteBuffers::alias(d, &lights), DiscreteBuffers::cdf(d, &texels));
    assert!(DiscreteTable::cdf(&texels).two_level());
    let samples: u32 = 1 << 19;
    let seeds: [u64; 2] = [0xfeed_0001, 0x5eed_0002_0003];
    let own = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[storage_entry(0, false), uniform_entry(1), uniform_entry(2), uniform_entry(3)],
    });
    let entries: Vec<wgpu::BindGroupLayoutEntry> = [DiscreteBuffers::layout_entries(at_lights, wgpu::ShaderStages::COMPUTE), DiscreteBuffers::layout_entries(at_texels, wgpu::ShaderStages::COMPUTE)].concat();
    let tables = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &entries });
    let n = lights.len() + texels.len();
    let counts = d.create_buffer(&wgpu::BufferDescriptor { label: None, size: n as u64 * 4, usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC, mapped_at_creation: false });
    let uniform = |bytes: &[u8]| d.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents: bytes, usage: wgpu::BufferUsages::UNIFORM });
    let (lights_info, texels_info) = (uniform(bytemuck::bytes_of(&light_buffers.info)), uniform(bytemuck::bytes_of(&texel_buffers.info)));
    let run = uniform(bytemuck::cast_slice(&[seeds[0] as u32, (seeds[0] >> 32) as u32, samples, 0, seeds[1] as u32, (seeds[1] >> 32) as u32, samples, 0]));
    let g0 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &own,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: counts.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: lights_info.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: texels_info.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: run.as_entire_binding() },
        ],
    });
    let entries = [light_buffers.bind_group_entries(at_lights), texel_buffers.bind_group_entries(at_texels)].concat();
    let g1 = d.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &tables, entries: &entries });
    let bytes = dispatch(&gpu, &source, "draw_two", &[&own, &tables], &[&g0, &g1], samples, &counts);
    let mine: Vec<u64> = bytemuck::cast_slice::<u8, u32>(&bytes).iter().map(|&c| c as u64).collect();
    for (k, (dist, method, range)) in [(&lights, DiscreteMethod::Alias, 0..lights.len()), (&texels, DiscreteMethod::Cdf, lights.len()..n)].into_iter().enumerate() {
        let job = Job::Discrete { dist: dist.clone(), method };
        let theirs = engine.histogram(&job, SampleRange::whole(seeds[k], samples as u64), &mut |_| {}).unwrap().counts;
        assert_eq!(mine[range.clone()], theirs.bins[..], "{method:?} table of {} items differs from the engine's", dist.len());
        assert_eq!(mine[range].iter().sum::<u64>(), samples as u64);
    }
}

const TERMS_KERNEL: &str = r#"
@group(0) @binding(0) var<storage, read_write> terms: array<f32>;
const N: u32 = 257u;

// Row r, column i: a Fresnel or masking term at c = i / 256 (exact in f32).
@compute @workgroup_size(64)
fn terms_all(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= N) {
        return;
    }
    let c = f32(i) / 256.0;
    terms[0u * N + i] = lobes_fresnel_schlick(c, 0.04);
    terms[1u * N + i] = lobes_fresnel_dielectric(c, 1.5);
    terms[2u * N + i] = lobes_fresnel_dielectric(c, 0.5);
    terms[3u * N + i] = lobes_fresnel_conductor(c, 0.25, 3.0);
    terms[4u * N + i] = lobes_fresnel_conductor(c, 1.5, 0.0);
    terms[5u * N + i] = lobes_masking_separable(c, 1.0 - c);
    terms[6u * N + i] = lobes_masking_height_correlated(c, 1.0 - c);
}
"#;

/// The exported Fresnel and masking terms, in a kernel of our own, agree with the f64 reference
/// at 257 angles within 2·10⁻⁶ (f32 rounding), and with identities the reference does not use:
/// a conductor with k = 0 is the dielectric of the same η, and the height-correlated G2 is
/// 1 / (1 + Λi + Λr) with Λ = 1/G1 − 1 (Heitz 2014, eq. 99).
#[test]
fn embedded_fresnel_and_masking_match_the_f64_reference() {
    use lobes::reference::{fresnel, masking::Masking};
    let gpu = gpu();
    let source = embed::wgsl(&[Module::Fresnel, Module::Masking]) + TERMS_KERNEL;
    let n = 257usize;
    let d = &gpu.device;
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &[storage_entry(0, false)] });
    let out = d.create_buffer(&wgpu::BufferDescriptor { label: None, size: 7 * n as u64 * 4, usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC, mapped_at_creation: false });
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &layout, entries: &[wgpu::BindGroupEntry { binding: 0, resource: out.as_entire_binding() }] });
    let bytes = dispatch(&gpu, &source, "terms_all", &[&layout], &[&group], n as u32, &out);
    let terms: &[f32] = bytemuck::cast_slice(&bytes);
    let f0 = 0.04f32 as f64;
    let lambda = |g: f64| 1.0 / g - 1.0;
    type Term<'a> = Box<dyn Fn(f64) -> f64 + 'a>;
    let rows: [(&str, Term); 7] = [
        ("schlick F0 0.04", Box::new(|c| fresnel::schlick(c, f0))),
        ("dielectric η 1.5", Box::new(|c| fresnel::dielectric(c, 1.5))),
        ("dielectric η 0.5 (total internal reflection)", Box::new(|c| fresnel::dielectric(c, 0.5))),
        ("conductor 0.25 + 3i", Box::new(|c| fresnel::conductor(c, 0.25, 3.0))),
        ("conductor 1.5 + 0i = dielectric 1.5", Box::new(|c| fresnel::dielectric(c, 1.5))),
        ("separable", Box::new(|c| Masking::Separable.g(c, 1.0 - c))),
        ("height-correlated = 1/(1 + Λi + Λr)", Box::new(|c| if c <= 0.0 || c >= 1.0 { 0.0 } else { 1.0 / (1.0 + lambda(c) + lambda(1.0 - c)) })),
    ];
    let mut failures = Vec::new();
    for (r, (what, reference)) in rows.iter().enumerate() {
        let worst = (0..n).map(|i| (terms[r * n + i] as f64 - reference(i as f64 / 256.0)).abs()).fold(0.0, f64::max);
        println!("{what}: max |GPU - f64| = {worst:.2e}");
        if worst > 2e-6 {
            failures.push(format!("{what}: {worst:.2e}"));
        }
    }
    assert!(terms[2 * n] == 1.0 && terms[3 * n + 256] > 0.0, "grazing dielectric from inside reflects all; a conductor reflects at normal incidence");
    assert!(failures.is_empty(), "{failures:#?}");
}

/// examples/dfg_lut.rs: the DFG table from lobes' GGX sampler embedded in the example's own
/// kernel agrees with the f64 quadrature within the example's documented tolerance, and its
/// files have the documented layout.
#[test]
fn dfg_lut_example_matches_the_f64_quadrature() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("dfg");
    let _ = std::fs::remove_dir_all(&dir);
    let report = dfg_lut::run(&dir).unwrap_or_else(|e| panic!("dfg_lut example (GPU tests need a wgpu adapter): {e:#}"));
    println!("{}: max |GPU - f64| = {:.3e}", report.adapter, report.max_error);
    assert!(report.max_error <= dfg_lut::TOLERANCE, "max error {} > {}", report.max_error, dfg_lut::TOLERANCE);
    let raw = std::fs::read(dir.join("dfg.f32")).unwrap();
    assert_eq!(raw.len(), 32 * 32 * 2 * 4);
    let at = |j: usize, i: usize, c: usize| {
        let k = 4 * (2 * (32 * j + i) + c);
        f32::from_le_bytes(raw[k..k + 4].try_into().unwrap())
    };
    assert_eq!(at(5, 7, 1), report.lut[5 * 32 + 7][1]);
    // a near-mirror at normal incidence reflects everything: A ≈ 1, B ≈ 0
    assert!((at(0, 31, 0) - 1.0).abs() < 1e-3 && at(0, 31, 1) < 1e-3, "{} {}", at(0, 31, 0), at(0, 31, 1));
    // energy: A + B is the single-scattering albedo, in (0, 1]
    for t in &report.lut {
        assert!(t[0] > 0.0 && t[1] >= 0.0 && t[0] + t[1] <= 1.0 + 1e-3, "{t:?}");
    }
    let (shape, npy) = lobes::report::npy::decode::<f32>(&std::fs::read(dir.join("dfg.npy")).unwrap()).unwrap();
    assert_eq!(shape, [32, 32, 2]);
    assert_eq!(npy[2 * (32 * 5 + 7) + 1], at(5, 7, 1), "dfg.npy[5, 7, 1] is dfg.f32's value there");
    assert_eq!(npy, report.lut.iter().flatten().copied().collect::<Vec<f32>>());
    let png = image::open(dir.join("dfg.png")).unwrap();
    assert_eq!((png.width(), png.height()), (32, 32));
}

/// examples/end_to_end.rs: the library driven end to end passes its χ² tests.
#[test]
fn end_to_end_example_passes() {
    let mut engine = GpuEngine::open().unwrap_or_else(|e| panic!("GPU tests need a wgpu adapter: {e}"));
    let verdicts = end_to_end::run(&mut engine, 1_000_000, 3).unwrap();
    assert_eq!(verdicts.len(), 2);
    for v in &verdicts {
        println!("{}: chi2 {:.1}/{} p = {:.4}", v.name, v.chi2, v.dof, v.p_value);
        assert!(v.passed, "{}: p = {}", v.name, v.p_value);
    }
    assert!(verdicts[0].max_angle_rad.unwrap() < 1e-4);
}

/// The renderer's own kernel of the consumer tests: 2²⁰ GGX VNDF samples (α 0.3, θi 60°) drawn
/// with lobes' RNG, each thread's sums of the estimator weight f cos θr / p and of its square.
/// `RNG`, `SAMPLE` and `EVAL` are replaced by the names each form gives lobes' functions; the
/// renderer's usual names (PI, saturate, D_GGX, fresnel_schlick, rand_f, pcg4d), which lobes'
/// files also define or import, are the renderer's own and are used, with no effect on the sum.
const ALBEDO_KERNEL: &str = r#"
const PI: f32 = 3.14159265;
fn saturate(x: f32) -> f32 { return clamp(x, 0.0, 1.0); }
fn D_GGX(a: f32, nh: f32) -> f32 { let d = nh * nh * (a * a - 1.0) + 1.0; return a * a / (PI * d * d); }
fn fresnel_schlick(c: f32, f0: f32) -> f32 { return f0 + (1.0 - f0) * pow(1.0 - c, 5.0); }
fn pcg4d(v: vec4<u32>) -> vec4<u32> { return v * 1664525u + vec4<u32>(1013904223u); }
fn rand_f(state: ptr<function, u32>) -> f32 { *state = *state * 747796405u + 2891336453u; return f32(*state >> 8u) / 16777216.0; }

@group(0) @binding(0) var<storage, read_write> sums: array<vec2<f32>>;
const PER_THREAD: u32 = 64u;

@compute @workgroup_size(64)
fn albedo(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&sums)) {
        return;
    }
    let a = vec2<f32>(0.3, 0.3);
    let wi = vec3<f32>(0.8660254, 0.0, 0.5);
    var state = i;
    // the renderer's functions, which must stay its own: 0 and 1 here
    let zero = (D_GGX(0.5, 1.0) + rand_f(&state) + f32(pcg4d(vec4<u32>(i)).x)) * 0.0;
    let one = saturate(fresnel_schlick(1.0, 1.0));
    var s1 = 0.0;
    var s2 = 0.0;
    for (var k = 0u; k < PER_THREAD; k++) {
        let u = RNG(vec2<u32>(11u, 0u), vec2<u32>(i * PER_THREAD + k, 0u));
        let s = SAMPLE(a, wi, u.xy);
        var w = 0.0;
        if (s.wr.z > 0.0 && s.pdf_r > 0.0) {
            w = EVAL(a, wi, s.wr) * s.wr.z / s.pdf_r * one + zero;
        }
        s1 += w;
        s2 += w * w;
    }
    sums[i] = vec2<f32>(s1, s2);
}
"#;

/// Threads of [`ALBEDO_KERNEL`] (2¹⁴ × 64 = 2²⁰ samples).
const ALBEDO_THREADS: u32 = 1 << 14;

/// The albedo of the consumer kernel `source` run on the GPU: the mean weight and its standard
/// error, over 2²⁰ samples.
fn consumer_albedo(gpu: &Gpu, source: &str) -> (f64, f64) {
    let d = &gpu.device;
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &[storage_entry(0, false)] });
    let out = d.create_buffer(&wgpu::BufferDescriptor { label: None, size: ALBEDO_THREADS as u64 * 8, usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC, mapped_at_creation: false });
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &layout, entries: &[wgpu::BindGroupEntry { binding: 0, resource: out.as_entire_binding() }] });
    let bytes = dispatch(gpu, source, "albedo", &[&layout], &[&group], ALBEDO_THREADS, &out);
    let sums: &[[f32; 2]] = bytemuck::cast_slice(&bytes);
    let n = (ALBEDO_THREADS * 64) as f64;
    let (s1, s2) = sums.iter().fold((0.0, 0.0), |(a, b), s| (a + s[0] as f64, b + s[1] as f64));
    let mean = s1 / n;
    (mean, ((s2 / n - mean * mean) / (n - 1.0)).sqrt())
}

/// The f64 albedo `lobes run` judges the same lobe against: the quadrature of f |cos θr| over
/// its grid's bins (run::compare::albedo_check), f = D G2 / (4 cos θi cos θr), G2 height-correlated.
fn run_albedo() -> f64 {
    use lobes::reference::{LobeKind, Method, effects::Effects, fresnel::Fresnel, masking::Masking};
    use lobes::stats::{expected, histogram::SphereGrid};
    let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
    let wi = DVec3::new(0.8660254f32 as f64, 0.0, 0.5);
    let wi = wi / wi.length();
    let effects = Effects { fresnel: Fresnel::None, masking: Masking::HeightCorrelated };
    let f_cos = |w: DVec3| effects.eval(&lobe, wi, w) * w.z;
    expected::probabilities(&f_cos, SphereGrid { rows: 32, cols: 64 }, 0.3, &expected::Quadrature::default()).probabilities.iter().sum()
}

/// A consumer's albedo within 4 standard errors of the f64 one (p ≈ 6·10⁻⁵ for a correct
/// sampler), and the standard error small enough that the test can tell (VNDF weights are
/// G2/G1 ≤ 1).
fn assert_albedo(what: &str, (mean, se): (f64, f64), reference: f64) {
    let z = (mean - reference) / se;
    println!("{what}: albedo {mean:.6} ± {se:.2e}, f64 {reference:.6}, z = {z:+.2}");
    assert!(se < 1e-3, "{what}: standard error {se}");
    assert!(z.abs() < 4.0, "{what}: albedo {mean} ± {se} against the f64 {reference} (z = {z:.2})");
}

/// Plain concatenation: lobes' prefixed text, then the renderer's shader with its own PI,
/// saturate, D_GGX, fresnel_schlick, rand_f and pcg4d.
#[test]
fn a_plain_concatenation_consumer_matches_the_f64_albedo() {
    let kernel = ALBEDO_KERNEL.replace("RNG(", "lobes_rng_uniforms(").replace("SAMPLE(", "lobes_ggx_sample_vndf(").replace("EVAL(", "lobes_ggx_eval(");
    let source = embed::wgsl(&[Module::Rng, Module::Ggx, Module::Fresnel]) + &kernel;
    let gpu = gpu();
    let reference = run_albedo();
    assert_albedo("plain WGSL", consumer_albedo(&gpu, &source), reference);
    // the same check rejects a sampler whose density is 1 % off
    let broken = "fn broken(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobesLobeSample {\n\
                  var s = lobes_ggx_sample_vndf(a, wi, u);\n    s.pdf_r *= 1.01;\n    return s;\n}\n";
    let source = embed::wgsl(&[Module::Rng, Module::Ggx]) + broken + &kernel.replace("lobes_ggx_sample_vndf(", "broken(");
    let (mean, se) = consumer_albedo(&gpu, &source);
    let z = (mean - reference) / se;
    println!("pdf 1 % high: albedo {mean:.6} ± {se:.2e}, z = {z:+.1}");
    assert!(z.abs() > 4.0, "a 1 % density error passed: z = {z}");
}

/// The `wesl` crate (0.4) compiles `shader`, which imports lobes' package (`import
/// lobes::ggx::…;`), with its own resolver and mangler.
fn wesl_compile(shader: &str) -> String {
    use wesl::syntax::PathOrigin;
    let root = wesl::ModulePath::new(PathOrigin::Absolute, vec!["renderer".into()]);
    let mut local = wesl::VirtualResolver::new();
    local.add_module(root.clone(), shader.to_string().into());
    let mut packages = wesl::PkgResolver::new();
    packages.add_package(&embed::WESL_PACKAGE);
    let mut router = wesl::Router::new();
    router.mount_resolver(wesl::ModulePath::new(PathOrigin::Absolute, vec![]), local);
    router.mount_fallback_resolver(packages);
    wesl::Wesl::new("").set_custom_resolver(router).compile(&root).unwrap_or_else(|e| panic!("{e}")).to_string()
}

/// WESL: the renderer's shader imports lobes' package (`import lobes::ggx::…;`), the `wesl`
/// crate (0.4) compiles it, and wgpu runs the result; a density 1 % high fails.
#[test]
fn a_wesl_consumer_matches_the_f64_albedo() {
    let shader = |sampler: &str, extra: &str| {
        String::from("import lobes::ggx::{ggx_sample_vndf, ggx_eval};\nimport lobes::rng::rng_uniforms;\nimport lobes::reflect::LobeSample;\n")
            + extra
            + &ALBEDO_KERNEL.replace("RNG(", "rng_uniforms(").replace("SAMPLE(", &format!("{sampler}(")).replace("EVAL(", "ggx_eval(")
    };
    let gpu = gpu();
    let reference = run_albedo();
    let compiled = wesl_compile(&shader("ggx_sample_vndf", ""));
    assert!(compiled.contains("fn saturate(") && compiled.contains("const PI"), "the renderer's names stay its own:\n{compiled}");
    assert_albedo("WESL (wesl 0.4)", consumer_albedo(&gpu, &compiled), reference);
    let broken = "fn broken(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample {\n\
                  var s = ggx_sample_vndf(a, wi, u);\n    s.pdf_r *= 1.01;\n    return s;\n}\n";
    let (mean, se) = consumer_albedo(&gpu, &wesl_compile(&shader("broken", broken)));
    let z = (mean - reference) / se;
    println!("WESL, pdf 1 % high: albedo {mean:.6} ± {se:.2e}, z = {z:+.1}");
    assert!(z.abs() > 4.0, "a 1 % density error passed: z = {z}");
}

/// The renderer's shader for the naga_oil consumers: imports of lobes' naga_oil modules, then
/// [`ALBEDO_KERNEL`] with the short names; `sampler` is the sampling function it calls.
fn naga_oil_shader(sampler: &str, extra: &str) -> String {
    String::from("#import lobes::ggx::{ggx_sample_vndf, ggx_eval}\n#import lobes::rng::rng_uniforms\n")
        + extra
        + &ALBEDO_KERNEL.replace("RNG(", "rng_uniforms(").replace("SAMPLE(", &format!("{sampler}(")).replace("EVAL(", "ggx_eval(")
}

/// A sampler of the naga_oil consumer's own whose density is 1 % high (`LobeSample` is lobes').
const BROKEN_NAGA_OIL: &str = "#import lobes::reflect::LobeSample\n\
                               fn broken(a: vec2<f32>, wi: vec3<f32>, u: vec2<f32>) -> LobeSample {\n\
                               var s = ggx_sample_vndf(a, wi, u);\n    s.pdf_r *= 1.01;\n    return s;\n}\n";

/// naga_oil 0.23 (on naga 30) composes `shader` with lobes' naga_oil modules; naga 30 validates
/// the module and writes it back as WGSL (its `wgsl-out` backend), which wgpu runs.
fn naga_oil_023_wgsl(shader: &str) -> String {
    use naga_oil::compose::{Composer, NagaModuleDescriptor};
    let mut composer = Composer::default();
    embed::add_naga_oil_modules(&mut composer, &[Module::Rng, Module::Ggx]).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
    let module = composer
        .make_naga_module(NagaModuleDescriptor { source: shader, file_path: "renderer.wgsl", ..Default::default() })
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
    assert!(module.entry_points.iter().any(|e| e.name == "albedo"));
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default()).validate(&module).unwrap_or_else(|e| panic!("{e:?}"));
    naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty()).unwrap()
}

/// naga_oil (0.23, on naga 30): the renderer's shader imports lobes' naga_oil modules
/// (`#import lobes::ggx::…`) beside its own names; the composed module, validated and written as
/// WGSL by naga, runs on the GPU and matches the f64 albedo; a density 1 % high does not.
#[test]
fn a_naga_oil_consumer_matches_the_f64_albedo() {
    let gpu = gpu();
    let reference = run_albedo();
    let composed = naga_oil_023_wgsl(&naga_oil_shader("ggx_sample_vndf", ""));
    assert!(composed.contains("fn fresnel_schlick(") && composed.contains("fn D_GGX("), "the renderer's names stay its own:\n{composed}");
    assert_albedo("naga_oil 0.23", consumer_albedo(&gpu, &composed), reference);
    let (mean, se) = consumer_albedo(&gpu, &naga_oil_023_wgsl(&naga_oil_shader("broken", BROKEN_NAGA_OIL)));
    let z = (mean - reference) / se;
    println!("naga_oil 0.23, pdf 1 % high: albedo {mean:.6} ± {se:.2e}, z = {z:+.1}");
    assert!(z.abs() > 4.0, "a 1 % density error passed: z = {z}");
}

/// naga_oil 0.22 (Bevy 0.19's, on naga 29) composes `shader` with the same texts
/// ([`embed::naga_oil_modules`]; `NagaOilModule::descriptor` is naga_oil 0.23's type); naga 29
/// validates the module and writes it as WGSL, which wgpu 30 runs.
fn naga_oil_022_wgsl(shader: &str) -> String {
    use naga_oil_022::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
    let mut composer = Composer::default();
    for m in embed::naga_oil_modules(&[Module::Rng, Module::Ggx]) {
        let descriptor = ComposableModuleDescriptor { source: m.source, file_path: &m.import_path, ..Default::default() };
        if let Err(e) = composer.add_composable_module(descriptor) {
            panic!("{}", e.emit_to_string(&composer));
        }
    }
    let module = composer
        .make_naga_module(NagaModuleDescriptor { source: shader, file_path: "renderer.wgsl", ..Default::default() })
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
    assert!(module.entry_points.iter().any(|e| e.name == "albedo"));
    let info = naga_29::valid::Validator::new(naga_29::valid::ValidationFlags::all(), naga_29::valid::Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{e:?}"));
    naga_29::back::wgsl::write_string(&module, &info, naga_29::back::wgsl::WriterFlags::empty()).unwrap()
}

/// naga_oil 0.22 (what Bevy 0.19 composes with): lobes' naga_oil texts compose beside the
/// renderer's own names, naga 29 validates them, and the dispatch of its WGSL matches the f64
/// albedo; a density 1 % high does not.
#[test]
fn a_naga_oil_022_consumer_matches_the_f64_albedo() {
    let gpu = gpu();
    let reference = run_albedo();
    let composed = naga_oil_022_wgsl(&naga_oil_shader("ggx_sample_vndf", ""));
    assert!(composed.contains("fn fresnel_schlick(") && composed.contains("fn D_GGX("), "the renderer's names stay its own:\n{composed}");
    assert_albedo("naga_oil 0.22", consumer_albedo(&gpu, &composed), reference);
    let (mean, se) = consumer_albedo(&gpu, &naga_oil_022_wgsl(&naga_oil_shader("broken", BROKEN_NAGA_OIL)));
    let z = (mean - reference) / se;
    println!("naga_oil 0.22, pdf 1 % high: albedo {mean:.6} ± {se:.2e}, z = {z:+.1}");
    assert!(z.abs() > 4.0, "a 1 % density error passed: z = {z}");
}

/// Every built-in light (the light registry) through the WESL package and the naga_oil modules:
/// a renderer's shader importing the light's sample and pdf functions by their short names
/// (`import lobes::sphere_light::{…};`, `#import lobes::sphere_light::{…}`) composes, and naga
/// validates the result (the helpers in `NAME::internal` and `lobes::light` come along).
#[test]
fn every_light_composes_through_wesl_and_naga_oil() {
    use lobes::reference::light::registry::LIGHTS;
    for l in &LIGHTS {
        let f = |call: &str| call.split('(').next().unwrap().to_string();
        let (sample, pdf) = (f(l.sample), f(l.pdf));
        let body = format!(
            "@group(0) @binding(0) var<storage, read_write> o: array<vec4<f32>>;\n\
             @compute @workgroup_size(1) fn main() {{\n    var params: array<vec4<f32>, 4>;\n    params[0] = o[0];\n    params[1] = o[1];\n    params[2] = o[2];\n    \
             let u = o[3].xy;\n    let s = {};\n    let d = s.d;\n    o[4] = vec4<f32>(s.d, {});\n}}\n",
            l.sample, l.pdf
        );
        let wesl = wesl_compile(&format!("import lobes::{}::{{{sample}, {pdf}}};\n{body}", l.module_name()));
        embed::validate(&wesl).unwrap_or_else(|e| panic!("{} (WESL): {e}\n{wesl}", l.name));
        use naga_oil::compose::{Composer, NagaModuleDescriptor};
        let mut composer = Composer::default();
        let module = Module::from_name(l.module_name()).unwrap();
        embed::add_naga_oil_modules(&mut composer, &[module]).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
        let shader = format!("#import lobes::{}::{{{sample}, {pdf}}}\n{body}", l.module_name());
        composer
            .make_naga_module(NagaModuleDescriptor { source: &shader, file_path: "renderer.wgsl", ..Default::default() })
            .unwrap_or_else(|e| panic!("{} (naga_oil): {}", l.name, e.emit_to_string(&composer)));
    }
}
