// The draw of a lobe job: sampler_sample(alpha, wi, u) -> LobeSample is the generated call site
// of the case's sampler (ward_sample, ggx_sample_vndf, ...: src/reference/sampler.rs), or in the
// uber-kernel a switch over all of them (src/engine/gpu/compose.rs call_site).

fn lobe_sample_at(index: vec2<u32>) -> LobeSample {
    let u = rng_uniforms(params.seed, index);
    return sampler_sample(params.alpha, params.wi.xyz, u.xy);
}

fn draw(index: vec2<u32>) -> u32 {
    let s = lobe_sample_at(index);
    let reason = classify(s.wr, s.pdf_r);
    if (reason != 0u) {
        return BINS + reason - 1u;
    }
    return bin_of(s.wr);
}

// Writes (wr, reason code) of samples base .. base + count, for the per-sample check against f64.
@compute @workgroup_size(WG_SIZE)
fn directions(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let s = lobe_sample_at(add64(params.base, i));
    directions_out[i] = vec4<f32>(s.wr, f32(classify(s.wr, s.pdf_r)));
}

// Explicit uniforms for the stability suite: sample i uses explicit_u[i] (any u a caller can
// pass, 0 and 1 included) and writes (wr, reason code), then (h, pdf_r).
@group(0) @binding(3) var<storage, read> explicit_u: array<vec2<f32>>;

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

// Binning of explicit directions for the stability suite: direction i is packed in explicit_u
// as (x, y) at 2i and (z, unused) at 2i + 1; its bin is written to directions_out[i].x.
@compute @workgroup_size(WG_SIZE)
fn bin_explicit(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let w = vec3<f32>(explicit_u[2u * i], explicit_u[2u * i + 1u].x);
    directions_out[i] = vec4<f32>(f32(bin_of(w)), 0.0, 0.0, 0.0);
}
