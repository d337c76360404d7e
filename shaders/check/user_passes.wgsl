#define_import_path lobes::check
#import lobes::rng::{rng_uniforms, add64}
#import lobes::params::lobes_params
#import lobes::domain::{lobes_domain_point, lobes_domain_coordinates}
#import lobes::user::{lobes_user_sample, lobes_user_pdf, lobes_user_eval, lobes_user_draws}

// The passes that judge a user's WGSL sampler (CPU side: src/check/). They call the user's
// functions through three wrappers of `lobes::user`, the module that the composing host
// generates from the user's files (src/check/gpu.rs):
//   fn lobes_user_sample(wi: vec3<f32>, u: vec4<f32>) -> vec4<f32>   // (d, pdf the sampler reports)
//   fn lobes_user_pdf(wi: vec3<f32>, d: vec3<f32>) -> f32
//   fn lobes_user_eval(wi: vec3<f32>, d: vec3<f32>) -> f32           // 0 when the user gave none
// and fn lobes_user_draws() -> u32, the draws the last sample took from the queue of the user's
// --rand functions. `lobes::domain` (domain_sphere.wgsl or domain_plane.wgsl, as the sampler's
// domain says) maps quadrature coordinates to points. The histogram is not here: `lobes run`'s
// counting kernel (shaders/passes/kernel.wgsl) counts it, drawing the user's sampler through
// shaders/check/user_draw.wgsl. Every name here starts with `lobes_` so that it cannot collide
// with the user's own.

@group(0) @binding(1) var<storage, read> lobes_in: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> lobes_out: array<vec4<f32>>;

// x > 0 and finite, read from the bits (not relying on NaN comparing false, which fast-math
// lowerings may not keep).
fn lobes_positive(x: f32) -> bool {
    let bits = bitcast<u32>(x);
    return (bits & 0x7f800000u) != 0x7f800000u && x > 0.0;
}

// 5- and 3-point Gauss–Legendre nodes and weights on [−1, 1] (Abramowitz & Stegun 25.4.30),
// the pair the f64 quadrature (src/stats/expected.rs) uses: the 5-point rule at 0 .. 5, the
// 3-point rule at 5 .. 8.
const LOBES_GL_X = array<f32, 8>(-0.906179845938664, -0.538469310105683, 0.0, 0.538469310105683, 0.906179845938664,
                                 -0.774596669241483, 0.0, 0.774596669241483);
const LOBES_GL_W = array<f32, 8>(0.236926885056189, 0.478628670499367, 0.568888888888889, 0.478628670499367, 0.236926885056189,
                                 0.555555555555556, 0.888888888888889, 0.555555555555556);

// (∫ pdf, ∫ eval) over the rectangle of centre c and half-widths hw in hemisphere h and quadrant
// `quadrant` (lobes_domain_point) by the tensor
// rule of nodes first .. first + n of LOBES_GL_*, without the area factor ha hb. Where `root`,
// the first coordinate is s = √a (a part at a pole, src/check/quadrature.rs: Rect): the node's
// a is s², its weight times da/ds = 2s.
fn lobes_rule(first: u32, n: u32, c: vec2<f32>, hw: vec2<f32>, h: f32, quadrant: u32, root: bool, wi: vec3<f32>, seen: ptr<function, vec3<f32>>) -> vec2<f32> {
    var sum = vec2<f32>(0.0);
    for (var j = first; j < first + n; j++) {
        for (var k = first; k < first + n; k++) {
            var a = c.x + hw.x * LOBES_GL_X[j];
            var w = LOBES_GL_W[j] * LOBES_GL_W[k];
            if (root) {
                w *= 2.0 * a;
                a *= a;
            }
            let d = lobes_domain_point(a, c.y + hw.y * LOBES_GL_X[k], h, quadrant);
            let p = lobes_user_pdf(wi, d);
            lobes_seen(seen, p);
            sum += w * vec2<f32>(p, lobes_user_eval(wi, d));
        }
    }
    return sum;
}

// A quadrature rectangle: centre c and half-widths hw of its (a, b) ranges, b measured from the
// axis of its quadrant (lobes_domain_point), in hemisphere h, its first coordinate s = √a where
// `root` (src/check/quadrature.rs: Rect).
struct LobesRect {
    c: vec2<f32>,
    hw: vec2<f32>,
    h: f32,
    quadrant: u32,
    root: bool,
}

// Rectangle i of lobes_in: (a0, a1, b0, b1) at i, its hemisphere sign, quadrant and root flag at
// lobes_in[count + i].xyz.
fn lobes_rect(i: u32) -> LobesRect {
    let r = lobes_in[i];
    let more = lobes_in[lobes_params.count + i];
    return LobesRect(0.5 * vec2<f32>(r.y + r.x, r.w + r.z), 0.5 * vec2<f32>(r.y - r.x, r.w - r.z), more.x, u32(more.y), more.z != 0.0);
}

// Rectangle i of lobes_in (lobes_rect) integrated with the 5 × 5 and the 3 × 3 tensor
// Gauss–Legendre rules: (∫ pdf by 5 × 5, by 3 × 3, ∫ eval by 5 × 5, by 3 × 3). A pdf that is
// NaN, infinite or negative at a node is returned as such: the host reports it.
@compute @workgroup_size(64)
fn lobes_integrate_rects(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    let q = lobes_rect(i);
    let wi = lobes_params.wi.xyz;
    var seen = vec3<f32>(0.0, 0.0, 3.4e38);
    let r5 = lobes_rule(0u, 5u, q.c, q.hw, q.h, q.quadrant, q.root, wi, &seen);
    let r3 = lobes_rule(5u, 3u, q.c, q.hw, q.h, q.quadrant, q.root, wi, &seen);
    lobes_out[i] = vec4<f32>(r5.x, r3.x, r5.y, r3.y) * (q.hw.x * q.hw.y);
    lobes_out[lobes_params.count + i] = lobes_support_edge(seen, q.c, q.hw, q.h, q.quadrant, q.root, wi);
}

// Rectangle i of lobes_in (lobes_rect), ∫ pdf by the 5 × 5 rule alone, four rectangles to a
// vec4 of lobes_out: the first number of lobes_integrate_rects' by the very same arithmetic, for
// the sums over fixed parts at moved inputs (src/check/quadrature.rs: sensitivity), where only
// the differences of those numbers count.
@compute @workgroup_size(64)
fn lobes_integrate_pdf(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    let q = lobes_rect(i);
    var seen = vec3<f32>(0.0, 0.0, 3.4e38);
    let r5 = lobes_rule(0u, 5u, q.c, q.hw, q.h, q.quadrant, q.root, lobes_params.wi.xyz, &seen);
    lobes_out[i / 4u][i % 4u] = r5.x * (q.hw.x * q.hw.y);
}

// What the pdf's values at a rectangle's points say of its support: (any 0, any > 0, the
// smallest value > 0) so far, updated with the value p (z starts at the largest f32).
fn lobes_seen(seen: ptr<function, vec3<f32>>, p: f32) {
    if (p == 0.0) {
        (*seen).x = 1.0;
    }
    if (lobes_positive(p)) {
        (*seen).y = 1.0;
        (*seen).z = min((*seen).z, p);
    }
}

// Whether the pdf's support has an edge in the rectangle (lobes_integrate_rects), from `seen` at
// its 5 × 5 and 3 × 3 nodes and here at its four corners and the midpoints of its sides: (1 where
// the pdf is 0 at some of them and > 0 at others, else 0; the smallest value > 0 times the
// rectangle's area (in a, or in s with da/ds = 2s at the larger s): the scale of the jump's
// mass there, 0, 0). The Gauss–Legendre nodes stay 4.7 % of the width inside: a support's corner
// beyond them is seen by the corners, taken 10⁻³ of the width inside, off the domain's own edges
// (a pole, the horizon, where a pdf is often 0 by its convention, d.z ≤ 0).
fn lobes_support_edge(seen_nodes: vec3<f32>, c: vec2<f32>, hw: vec2<f32>, h: f32, quadrant: u32, root: bool, wi: vec3<f32>) -> vec4<f32> {
    var seen = seen_nodes;
    for (var j = 0; j < 3; j++) {
        for (var k = 0; k < 3; k++) {
            if (j == 1 && k == 1) {
                continue;
            }
            var a = c.x + 0.999 * hw.x * f32(j - 1);
            if (root) {
                a *= a;
            }
            lobes_seen(&seen, lobes_user_pdf(wi, lobes_domain_point(a, c.y + 0.999 * hw.y * f32(k - 1), h, quadrant)));
        }
    }
    var area = 4.0 * hw.x * hw.y;
    if (root) {
        area *= 2.0 * (c.x + hw.x);
    }
    return vec4<f32>(seen.x * seen.y, seen.z * area, 0.0, 0.0);
}

// Whether sample s is valid and lands on d0: within 1e-6 relative, the tolerance of "moves d"
// in src/check/jacobian.rs (a sampler that chooses an event gives the same bits throughout it).
fn lobes_same(s: vec4<f32>, d0: vec3<f32>) -> bool {
    let p0 = lobes_domain_coordinates(d0);
    let diff = lobes_domain_coordinates(s.xyz) - p0;
    let scale = max(length(p0), 1.0);
    return lobes_positive(s.w) && length(diff) <= 1e-6 * scale;
}

// u with component `axis` set to t.
fn lobes_at(u: vec4<f32>, axis: u32, t: f32) -> vec4<f32> {
    var v = u;
    v[axis] = t;
    return v;
}

// Nodes of the coarse scan of lobes_share, and the smallest share of an event it reports (the
// finite-difference step's 2⁻¹²: below it d is taken to move with the axis).
const LOBES_SCAN: u32 = 256u;
const LOBES_MIN_SHARE: f32 = 1.0 / 4096.0;

// The point where the sample stops landing on d0 between t_in (it does) and t_out (it does
// not), by bisection to f32 resolution (2⁻²⁴ from a cell of 2⁻⁸: 16 halvings, 18 at most).
fn lobes_transition(wi: vec3<f32>, u: vec4<f32>, axis: u32, d0: vec3<f32>, t_in: f32, t_out: f32) -> f32 {
    var a = t_in;
    var b = t_out;
    for (var k = 0u; k < 18u; k++) {
        let m = 0.5 * (a + b);
        if (m == a || m == b) {
            break;
        }
        if (lobes_same(lobes_user_sample(wi, lobes_at(u, axis, m)), d0)) {
            a = m;
        } else {
            b = m;
        }
    }
    return 0.5 * (a + b);
}

// The share of t ∈ [0, 1) for which sample(u with component `axis` = t) is valid and lands on
// d0 = sample(u): 1 where d does not depend on that component, the probability of the event the
// sampler chose at u where it chooses one with it, and −1 where d moves with it (the run of t
// around u[axis] that lands on d0 is shorter than LOBES_MIN_SHARE, or d is not constant along
// it). A coarse scan at t = j/256 and at u[axis] itself, each change between neighbouring nodes
// bisected; a run narrower than 2⁻⁸ between two nodes is not seen unless it holds u[axis] (at
// most 2⁻⁸ of share misread).
fn lobes_share(wi: vec3<f32>, u: vec4<f32>, axis: u32, d0: vec3<f32>) -> f32 {
    let t0 = u[axis];
    let step = 1.0 / f32(LOBES_SCAN);
    var share = 0.0;
    // the run of nodes landing on d0 that holds t0 (its length and ends), and where the current
    // run began (−1: none)
    var own = 0.0;
    var own_lo = t0;
    var own_hi = t0;
    var start = -1.0;
    // whether any node missed d0 (else the share is exactly 1, whatever the sums round to)
    var missed = false;
    var a = 0.0;
    var sa = lobes_same(lobes_user_sample(wi, lobes_at(u, axis, a)), d0);
    if (sa) {
        start = 0.0;
    }
    var j = 1u;
    var split = false;
    loop {
        // the next node: t0 inside the cell, else the cell's end (the last one at 1 − 2⁻²⁴, its
        // width counted to 1)
        var b = f32(j) * step;
        var at_t0 = false;
        if (!split && a < t0 && t0 < b) {
            b = t0;
            at_t0 = true;
            split = true;
        }
        let end = b;
        if (j == LOBES_SCAN && !at_t0) {
            b = 1.0 - 1.0 / 16777216.0;
        }
        let sb = lobes_same(lobes_user_sample(wi, lobes_at(u, axis, b)), d0);
        missed = missed || !sa || !sb;
        if (sa && sb) {
            share += end - a;
        } else if (sa) {
            let t = lobes_transition(wi, u, axis, d0, a, b);
            share += t - a;
            if (start <= t0 && t0 <= t) {
                own = t - start;
                own_lo = start;
                own_hi = t;
            }
            start = -1.0;
        } else if (sb) {
            let t = lobes_transition(wi, u, axis, d0, b, a);
            share += end - t;
            start = t;
        }
        a = end;
        sa = sb;
        if (!at_t0) {
            if (j == LOBES_SCAN) {
                break;
            }
            j++;
        }
    }
    if (sa && start <= t0) {
        own = 1.0 - start;
        own_lo = start;
        own_hi = 1.0;
    }
    if (!missed) {
        return 1.0;
    }
    if (own < LOBES_MIN_SHARE) {
        return -1.0;
    }
    // An event leaves d exactly as it is across its run; a draw that moves d by less than 10⁻⁶
    // per 2⁻¹² (a narrow lobe's azimuth, a small jitter) makes a run of the same length, along
    // which d moves by up to 10⁻⁶: look at d nine tenths of the way to the run's farther end
    // (at least 2⁻¹⁴ from t0), where such a draw has moved it by far more than an ulp.
    var far = own_hi - 0.1 * (own_hi - t0);
    if (t0 - own_lo > own_hi - t0) {
        far = own_lo + 0.1 * (t0 - own_lo);
    }
    if (any(lobes_user_sample(wi, lobes_at(u, axis, min(far, 1.0 - 1.0 / 16777216.0))).xyz != d0)) {
        return -1.0;
    }
    return share;
}

// One probed sample and the map around it (Probe in src/check/probe.rs, whose layout a test
// holds to this one).
struct LobesProbe {
    // sample(u): (d, the pdf the sampler reported)
    sample: vec4<f32>,
    // sample(u ± eps along u.x), then along u.y: +x, −x, +y, −y
    neighbours: array<vec4<f32>, 4>,
    // lobes_share along u.z and along u.w at d
    share_z: f32,
    share_w: f32,
    // the pdf and eval functions at d, and |d|
    pdf: f32,
    eval: f32,
    length: f32,
    _pad: array<f32, 3>,
}

// The probes, one per item (the probe pass's output buffer).
@group(0) @binding(5) var<storage, read_write> lobes_probes: array<LobesProbe>;

// The sample map around item i of lobes_in = (u, wi): a LobesProbe. The host differentiates in
// f64 (src/check/jacobian.rs) and classifies (src/check/hard.rs).
@compute @workgroup_size(64)
fn lobes_probe(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    let u = lobes_in[2u * i];
    let wi = lobes_in[2u * i + 1u].xyz;
    let e = lobes_params.eps;
    let s = lobes_user_sample(wi, u);
    let px = lobes_user_sample(wi, u + vec4<f32>(e, 0.0, 0.0, 0.0));
    let mx = lobes_user_sample(wi, u - vec4<f32>(e, 0.0, 0.0, 0.0));
    let py = lobes_user_sample(wi, u + vec4<f32>(0.0, e, 0.0, 0.0));
    let my = lobes_user_sample(wi, u - vec4<f32>(0.0, e, 0.0, 0.0));
    let share_z = lobes_share(wi, u, 2u, s.xyz);
    let share_w = lobes_share(wi, u, 3u, s.xyz);
    let neighbours = array<vec4<f32>, 4>(px, mx, py, my);
    let pad = array<f32, 3>(0.0, 0.0, 0.0);
    lobes_probes[i] = LobesProbe(s, neighbours, share_z, share_w, lobes_user_pdf(wi, s.xyz), lobes_user_eval(wi, s.xyz), length(s.xyz), pad);
}

// (pdf(d), eval(d), 0, 0) at the points d = lobes_in[i].xyz, for the incident direction of the
// uniforms: where pdf_values looks for the worst value (src/check/mod.rs).
@compute @workgroup_size(64)
fn lobes_pdf_at(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    let d = lobes_in[i].xyz;
    let wi = lobes_params.wi.xyz;
    lobes_out[i] = vec4<f32>(lobes_user_pdf(wi, d), lobes_user_eval(wi, d), 0.0, 0.0);
}

// The user's --rand draws at item i of lobes_in = (u, wi) (src/check/gpu.rs: rand_order): per
// item 2 vec4s,
//   0: (draws one sample took, its reported pdf, 0, 0)
//   1: lobes_share along u.x, u.y, u.z, u.w (−1 where d moves with it: a smooth coordinate)
@compute @workgroup_size(64)
fn lobes_draws(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    let u = lobes_in[2u * i];
    let wi = lobes_in[2u * i + 1u].xyz;
    let s = lobes_user_sample(wi, u);
    let n = lobes_user_draws();
    lobes_out[2u * i] = vec4<f32>(f32(n), s.w, 0.0, 0.0);
    lobes_out[2u * i + 1u] = vec4<f32>(lobes_share(wi, u, 0u, s.xyz), lobes_share(wi, u, 1u, s.xyz), lobes_share(wi, u, 2u, s.xyz), lobes_share(wi, u, 3u, s.xyz));
}

// Limits of the weights pass, the host's constants: LOBES_WEIGHT_LIMIT is
// crate::stats::weighted::WEIGHT_ERROR_LIMIT and LOBES_CONDITIONING_ULPS is
// check::CONDITIONING_ULPS (src/check/gpu.rs holds them equal in a test).
const LOBES_WEIGHT_LIMIT: f32 = 1e-3;
const LOBES_CONDITIONING_ULPS: f32 = 4.0;

// The f32 conditioning of the pdf at d: the largest relative change of pdf(d) when one
// component of d moves by 2⁻²³ |d|∞ (about an ulp of a unit vector's largest component), with
// pdf = pdf(d) > 0. A narrow lobe amplifies it: GGX's D(m) at α turns an ulp of m.z into ≈ 4/α²
// ulps of D, so a correct sampler and its pdf, the same f32 formula evaluated twice, may differ
// by that much (docs/testing-your-own-sampler.md, "f32 conditioning").
fn lobes_conditioning_at(wi: vec3<f32>, d: vec3<f32>, pdf: f32) -> f32 {
    let delta = 1.1920929e-7 * max(max(abs(d.x), abs(d.y)), abs(d.z));
    var k = 0.0;
    for (var c = 0u; c < 6u; c++) {
        var e = vec3<f32>(0.0);
        e[c / 2u] = select(-delta, delta, (c & 1u) == 0u);
        let q = lobes_user_pdf(wi, d + e);
        // a pdf that is NaN or ∞ next to d: d is not resolved (the pdf_values check judges it)
        k = max(k, select(1e30, abs(q - pdf) / pdf, lobes_positive(q) || q == 0.0));
    }
    return k;
}

// Estimator weights of samples base + (gid · samples_per_thread + k): per invocation two vec4s,
//   (Σ w, Σ w², the largest |w − w_pdf| / w_pdf, number of samples with eval > 0)
//   (Σ |w − w_pdf| over the samples within their allowance, the largest |w − w_pdf| / w_pdf
//    over its allowance, 0, 0)
// where w = eval(d) / (the reported pdf) is the weight a renderer computes from the sampler alone
// and w_pdf = eval(d) / pdf(d) the one from the pdf function. The allowance is LOBES_WEIGHT_LIMIT
// plus LOBES_CONDITIONING_ULPS times the pdf's f32 conditioning at d (computed only where the
// error exceeds the limit). Invalid samples weigh 0.
@compute @workgroup_size(64)
fn lobes_weights(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let t = gid.x + gid.y * nwg.x * 64u;
    let first = t * lobes_params.samples_per_thread;
    if (first >= lobes_params.count) {
        return;
    }
    let wi = lobes_params.wi.xyz;
    var acc = vec4<f32>(0.0);
    var err = vec4<f32>(0.0);
    for (var k = 0u; k < lobes_params.samples_per_thread; k++) {
        let local = first + k;
        if (local < lobes_params.count) {
            let s = lobes_user_sample(wi, rng_uniforms(lobes_params.seed, add64(lobes_params.base, local)));
            let e = lobes_user_eval(wi, s.xyz);
            let pdf = lobes_user_pdf(wi, s.xyz);
            if (e > 0.0 && lobes_positive(s.w) && lobes_positive(pdf)) {
                let w = e / s.w;
                let w_pdf = e / pdf;
                let rel = abs(w - w_pdf) / w_pdf;
                acc += vec4<f32>(w, w * w, 0.0, 1.0);
                acc.z = max(acc.z, rel);
                var judged = rel / LOBES_WEIGHT_LIMIT;
                if (judged > 1.0) {
                    judged = rel / (LOBES_WEIGHT_LIMIT + LOBES_CONDITIONING_ULPS * lobes_conditioning_at(wi, s.xyz, pdf));
                }
                // only an error within its allowance is f32's; a larger one is the sampler's
                err.x += select(0.0, abs(w - w_pdf), judged <= 1.0);
                err.y = max(err.y, judged);
            }
        }
    }
    lobes_out[2u * t] = acc;
    lobes_out[2u * t + 1u] = err;
}

// The sample map at the host's own uniforms (the Jacobian's steps, src/check/jacobian.rs):
// item i of lobes_in is u, and lobes_out[i] = sample(wi, u) at the incident lobes_params.wi.
@compute @workgroup_size(64)
fn lobes_map(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    lobes_out[i] = lobes_user_sample(lobes_params.wi.xyz, lobes_in[i]);
}

// At a d where the pdf is 0 (outside its support by the pdf function): infinite (1e30) where a
// component of d moved by LOBES_CONDITIONING_ULPS ulps (the rounding a sampler's d carries) gives
// a pdf > 0, the support's edge being within d's own rounding; 0 farther out.
fn lobes_edge_within_rounding(wi: vec3<f32>, d: vec3<f32>) -> f32 {
    let delta = LOBES_CONDITIONING_ULPS * 1.1920929e-7 * max(max(abs(d.x), abs(d.y)), abs(d.z));
    for (var c = 0u; c < 6u; c++) {
        var e = vec3<f32>(0.0);
        e[c / 2u] = select(-delta, delta, (c & 1u) == 0u);
        if (lobes_positive(lobes_user_pdf(wi, d + e))) {
            return 1e30;
        }
    }
    return 0.0;
}

// The pdf's f32 conditioning at the host's points: item i of lobes_in is d, and lobes_out[i] =
// (pdf(d), its conditioning, 0, 0) at the incident lobes_params.wi: lobes_conditioning_at where
// pdf(d) > 0, lobes_edge_within_rounding where it is 0, and 0 where it is not finite or < 0.
@compute @workgroup_size(64)
fn lobes_conditioning(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= lobes_params.count) {
        return;
    }
    let wi = lobes_params.wi.xyz;
    let d = lobes_in[i].xyz;
    let pdf = lobes_user_pdf(wi, d);
    var k = 0.0;
    if (lobes_positive(pdf)) {
        k = lobes_conditioning_at(wi, d, pdf);
    } else if (pdf == 0.0) {
        k = lobes_edge_within_rounding(wi, d);
    }
    lobes_out[i] = vec4<f32>(pdf, k, 0.0, 0.0);
}
