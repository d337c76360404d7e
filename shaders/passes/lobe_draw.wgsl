#define_import_path lobes::draw
#import lobes::job::{BINS, WG_SIZE, sampler_sample}
#import lobes::bindings::{params, directions_out}
#import lobes::histogram::{classify, bin_of}
#import lobes::lobe_kernel::{explicit_u, lobe_sample_at}

// The f32 draw of a lobe job (shaders/math/f64.wgsl has the f64 one, discrete_draw.wgsl a
// discrete job's): `draw`, which the counting kernel (shaders/passes/kernel.wgsl) calls, and
// the per-sample entry point of the stability suite.

fn draw(index: vec2<u32>) -> u32 {
    let s = lobe_sample_at(index);
    let reason = classify(s.wr, s.pdf_r);
    if (reason != 0u) {
        return BINS + reason - 1u;
    }
    return bin_of(s.wr);
}

// Sample i uses explicit_u[i] (shaders/passes/lobe_kernel.wgsl; any u a caller can pass, 0 and 1
// included) and writes (wr, reason code), then (h, pdf_r).
@compute @workgroup_size(WG_SIZE)
fn explicit_samples(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let s = sampler_sample(params.alpha, params.wi.xyz, explicit_u[i]);
    directions_out[2u * i] = vec4<f32>(s.wr, f32(classify(s.wr, s.pdf_r)));
    directions_out[2u * i + 1u] = vec4<f32>(s.h, s.pdf_r);
}
