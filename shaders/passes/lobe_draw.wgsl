#define_import_path lobes::draw
#import lobes::math::{Real, f32_pair}
#import lobes::job::{BINS, WG_SIZE}
#import lobes::params::lobes_params
#import lobes::bindings::directions_out
#import lobes::histogram::bin_of
#import lobes::lobe_kernel::{explicit_u, lobe_classify, lobe_sample_at, lobe_sample_u}

// The draw of a lobe job in the kernel's precision (Real, lobes::math: f32, or f64 for
// `lobes tradeoff`; discrete_draw.wgsl has a discrete job's): `draw`, which the counting kernel
// (shaders/passes/kernel.wgsl) calls, and the per-sample entry point of the stability suite and of
// the f64 angle check.

fn draw(index: vec2<u32>) -> u32 {
    let s = lobe_sample_at(index);
    let reason = lobe_classify(s);
    return select(bin_of(s.wr), BINS + reason - 1u, reason != 0u);
}

// Sample i uses the uniforms explicit_u[i].xyz (shaders/passes/lobe_kernel.wgsl; any u a caller
// can pass, 0 and 1 included; u.z chooses a dielectric's event as in lobe_sample_at) and writes (wr_hi, reason code), (h, pdf_r) and (wr_lo, 0): wr as an f32 pair
// (lobes::math's f32_pair; wr_lo is 0 in the f32 kernels), with which the f64 kernels' wr comes
// back to ~2^-48.
@compute @workgroup_size(WG_SIZE)
fn explicit_samples(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= lobes_params.count) {
        return;
    }
    let s = lobe_sample_u(explicit_u[i].xyz);
    let wr = f32_pair(s.wr);
    directions_out[3u * i] = vec4<f32>(wr[0], f32(lobe_classify(s)));
    directions_out[3u * i + 1u] = vec4<f32>(vec3<f32>(s.h), f32(s.pdf_r));
    directions_out[3u * i + 2u] = vec4<f32>(wr[1], 0.0);
}
