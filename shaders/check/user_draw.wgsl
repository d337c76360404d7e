#define_import_path lobes::draw
#import lobes::params::lobes_params
#import lobes::rng::rng_uniforms
#import lobes::domain::{LOBES_DOMAIN_OUTSIDE, lobes_domain_cell}
#import lobes::user::{lobes_user_sample, lobes_user_draws}
#import lobes::invalid::{LOBES_REASON_NON_FINITE_POINT, LOBES_REASON_OUTSIDE_DOMAIN, LOBES_REASON_NON_FINITE_PDF, LOBES_REASON_ZERO_PDF}

// The draw of `lobes check`'s histogram: a user's sampler in the place of a built-in lobe's
// (shaders/passes/lobe_draw.wgsl), so that `lobes run`'s counting kernel (shaders/passes/kernel.wgsl,
// with the counting module src/engine/gpu/counting.rs chooses) counts a user's samples as it
// counts lobes'. src/check/gpu.rs composes it with the user's files (`lobes::user`) and the
// domain's binning (`lobes::domain`), a module per grid.

// The --rand draws past the queue's four: how many samples drew more than four numbers, and the
// most one sample drew (src/check/gpu.rs: Counted). Counted on every sample, not on a probe: a
// lobe of a mixture that draws a fifth number in 0.2 % of its samples is found at any seed.
@group(0) @binding(10) var<storage, read_write> lobes_draw_counts: array<atomic<u32>, 2>;

// The cell of sample `index`: its bin, or rows · cols + reason − 1 (the counting kernel's
// convention, the reasons' codes those of `lobes::invalid`, src/reference/invalid.rs).
fn draw(index: vec2<u32>) -> u32 {
    let s = lobes_user_sample(lobes_params.wi.xyz, rng_uniforms(lobes_params.seed, index));
    let n = lobes_user_draws();
    if (n > 4u) {
        atomicAdd(&lobes_draw_counts[0], 1u);
        atomicMax(&lobes_draw_counts[1], n);
    }
    return lobes_cell(s);
}

fn lobes_finite3(d: vec3<f32>) -> bool {
    let b = bitcast<vec3<u32>>(d) & vec3<u32>(0x7f800000u);
    return all(b != vec3<u32>(0x7f800000u));
}

// The cell of a sample (d, reported pdf): its bin (the domain's, lobes_domain_cell), or
// rows · cols + reason − 1 (a user's sampler has no refracted_near_side, whose cell stays 0). A
// rejection, pdf exactly 0 at any finite d, (0, 0, 0) among them, is `zero_pdf`.
fn lobes_cell(s: vec4<f32>) -> u32 {
    let bins = lobes_params.rows * lobes_params.cols;
    if (!lobes_finite3(s.xyz)) {
        return bins + LOBES_REASON_NON_FINITE_POINT - 1u;
    }
    // pdf exactly 0 at a finite point, (0, 0, 0) or any other: the rejection the contract allows,
    // whatever the point (as the hard cases read it), not a point outside the domain
    if (s.w == 0.0) {
        return bins + LOBES_REASON_ZERO_PDF - 1u;
    }
    let cell = lobes_domain_cell(s.xyz);
    if (cell == LOBES_DOMAIN_OUTSIDE) {
        return bins + LOBES_REASON_OUTSIDE_DOMAIN - 1u;
    }
    let bits = bitcast<u32>(s.w);
    if ((bits & 0x7f800000u) == 0x7f800000u) {
        return bins + LOBES_REASON_NON_FINITE_PDF - 1u;
    }
    if (!(s.w > 0.0)) {
        return bins + LOBES_REASON_ZERO_PDF - 1u;
    }
    return cell;
}
