#define_import_path lobes::quadrature
#import lobes::job::{ROWS, COLS, N_NODES, sampler_pdf}
#import lobes::reflect::PI

// The expected histogram on the GPU in f32, for `lobes tradeoff`: one invocation per bin of a
// ROWS x COLS grid (rows uniform in cos th over [-1, 1], columns uniform in phi over [-pi, pi),
// as shaders/lib/histogram.wgsl), each integrating p(wr) over its bin by the fixed N_NODES x N_NODES
// Gauss-Legendre product rule in (cos th, phi), where the solid-angle element is d cos th d phi
// (the same rule as src/experiments/tradeoff/quadrature.rs fixed_probabilities in f64). The
// generated `lobes::job` (src/experiments/tradeoff/quadrature.rs) holds ROWS, COLS, N_NODES and
// `sampler_pdf(a, wi, wr) -> f32`, the call site of the sampler's density (src/reference/sampler.rs).

struct QuadParams {
    alpha: vec2<f32>,
    _pad: vec2<f32>,
    wi: vec4<f32>,
}

@group(0) @binding(0) var<uniform> qp: QuadParams;
// (node on [-1, 1], weight), N_NODES of them
@group(0) @binding(1) var<storage, read> gl_nodes: array<vec2<f32>>;
@group(0) @binding(2) var<storage, read_write> probabilities: array<f32>;

@compute @workgroup_size(64)
fn quadrature(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let bin = gid.x + gid.y * nwg.x * 64u;
    if (bin >= ROWS * COLS) {
        return;
    }
    let row = bin / COLS;
    let col = bin % COLS;
    // Centres and half-widths straight from the bin index (z edges are exact in f32 for even
    // ROWS; phi edges formed as -pi + 2 pi c / COLS would carry an error of ~1 ulp of pi, 5e-6 of
    // a 128-column bin's width, into its mass).
    let hz = 1.0 / f32(ROWS);
    let cz = -1.0 + (2.0 * f32(row) + 1.0) * hz;
    if (cz + hz <= 0.0) {
        probabilities[bin] = 0.0; // p(wr) = 0 below the horizon
        return;
    }
    let hp = PI / f32(COLS);
    let cp = -PI + (2.0 * f32(col) + 1.0) * hp;
    var sum = 0.0;
    for (var i = 0u; i < N_NODES; i++) {
        let z = cz + hz * gl_nodes[i].x;
        let s = sqrt(max(1.0 - z * z, 0.0));
        var row_sum = 0.0;
        for (var j = 0u; j < N_NODES; j++) {
            let phi = cp + hp * gl_nodes[j].x;
            let w = vec3<f32>(s * cos(phi), s * sin(phi), z);
            row_sum += gl_nodes[j].y * sampler_pdf(qp.alpha, qp.wi.xyz, w);
        }
        sum += gl_nodes[i].y * row_sum;
    }
    probabilities[bin] = sum * hz * hp;
}
