#define_import_path lobes::lobe_kernel
#import lobes::math::Real
#import lobes::job::{WG_SIZE, sampler_sample, lobe_alpha, lobe_wi, lobe_eta}
#import lobes::params::lobes_params
#import lobes::bindings::directions_out
#import lobes::rng::{rng_uniforms, add64}
#import lobes::reflect::LobeSample
#import lobes::histogram::{classify, classify_scattered, bin_of}

// The draw of a lobe job: sampler_sample(alpha, wi, u) -> LobeSample is the generated call site
// of the case's sampler in `lobes::job` (ward_sample, ggx_sample_vndf, ...: src/reference/sampler.rs),
// or in the uber-kernel a switch over all of them (src/engine/gpu/compose.rs call_site);
// lobe_alpha() and lobe_wi(), also generated in `lobes::job`, are the job's alpha and incident
// direction in the kernel's precision (Real: the f32 kernels read them from params, the f64
// kernels have them as f64 constants). The entry points draw and explicit_samples are in
// shaders/passes/lobe_draw.wgsl.

// The sample of the f32 uniforms u (the RNG's, exact in either precision): u.xy draw h, u.z a
// dielectric's event.
fn lobe_sample_u(u: vec3<f32>) -> LobeSample {
    return sampler_sample(lobe_alpha(), lobe_wi(), vec3<Real>(u));
}

// 0 for a valid sample, else its reason code: a reflection's (classify), or a dielectric's
// (lobe_eta() != 0), whose samples leave on either side (classify_scattered). A dielectric
// sample's event is read from its h, on wi's side: a reflection keeps the sign of wi.h in wr.h
// (wr.h = wi.h), a refraction turns it (wt.h = -cos th_t).
fn lobe_classify(s: LobeSample) -> u32 {
    if (lobe_eta() != 0.0) {
        let wi = lobe_wi();
        return classify_scattered(wi, s.wr, s.pdf_r, dot(wi, s.h) * dot(s.wr, s.h) >= 0.0);
    }
    return classify(s.wr, s.pdf_r);
}

fn lobe_sample_at(index: vec2<u32>) -> LobeSample {
    return lobe_sample_u(rng_uniforms(lobes_params.seed, index).xyz);
}

// Writes (wr, reason code) of samples base .. base + count, for the per-sample check against f64.
@compute @workgroup_size(WG_SIZE)
fn directions(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= lobes_params.count) {
        return;
    }
    let s = lobe_sample_at(add64(lobes_params.base, i));
    directions_out[i] = vec4<f32>(vec3<f32>(s.wr), f32(lobe_classify(s)));
}

// The per-sample passes' input, one element per sample (ExplicitInput in
// src/engine/gpu/params.rs, whose layout a test checks against this one): explicit uniforms u.xyz
// for the stability suite and the f64 angle check (explicit_samples,
// shaders/passes/lobe_draw.wgsl), or explicit directions for bin_explicit.
struct ExplicitInput {
    xyz: vec3<f32>,
    unused: f32,
}

@group(0) @binding(3) var<storage, read> explicit_u: array<ExplicitInput>;

// Binning of explicit directions for the stability suite: direction i is explicit_u[i].xyz; its
// bin is written to directions_out[i].x.
@compute @workgroup_size(WG_SIZE)
fn bin_explicit(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= lobes_params.count) {
        return;
    }
    directions_out[i] = vec4<f32>(f32(bin_of(vec3<Real>(explicit_u[i].xyz))), 0.0, 0.0, 0.0);
}
