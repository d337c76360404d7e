// A piecewise-constant 2-D distribution on the unit square, as a renderer samples an environment
// map or a light's emission texture: a plane sampler for `lobes check --domain plane
// --bounds 0,0,1,1`. The cell of row r (along y) and column c (along x) has probability
// w[r][c] / Σw, uniform inside the cell, so the density is p(x, y) = w[r][c] · ROWS · COLS / Σw
// (pbrt-v4 §A.5, PiecewiseConstant2D). Sampling: the row by inverting the CDF of the row sums
// with u.x, the column within the row with u.y, and the offsets in the cell from what is left of
// each uniform. One row and one cell have zero weight and must never be sampled.

const ENV_ROWS: u32 = 4u;
const ENV_COLS: u32 = 8u;
const ENV_W = array<f32, 32>(
    1.0, 2.0, 3.0, 4.0, 4.0, 3.0, 2.0, 1.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    8.0, 0.5, 0.5, 0.0, 1.0, 6.0, 0.5, 0.5,
    2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 9.0,
);

fn env_weight(r: u32, c: u32) -> f32 {
    return ENV_W[r * ENV_COLS + c];
}

fn env_row_sum(r: u32) -> f32 {
    var s = 0.0;
    for (var c = 0u; c < ENV_COLS; c++) {
        s += env_weight(r, c);
    }
    return s;
}

fn env_total() -> f32 {
    var s = 0.0;
    for (var r = 0u; r < ENV_ROWS; r++) {
        s += env_row_sum(r);
    }
    return s;
}

fn env_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {
    // the row: the first whose cumulative sum exceeds u.x Σw (u.x = 1: the last non-empty row)
    let total = env_total();
    let target_r = u.x * total;
    var r = 0u;
    var below = 0.0;
    for (var i = 0u; i < ENV_ROWS; i++) {
        let s = env_row_sum(i);
        if (s > 0.0) {
            r = i;
            if (target_r < below + s) {
                break;
            }
            below += s;
        }
    }
    // (a u.x of exactly 1 ends past the last row: the loop left `below` at Σw of the rows before r)
    let row = env_row_sum(r);
    below = min(below, total - row);
    let fy = clamp((target_r - below) / row, 0.0, 1.0);
    // the column within the row, the same way with u.y
    let target_c = u.y * row;
    var c = 0u;
    var left = 0.0;
    for (var j = 0u; j < ENV_COLS; j++) {
        let w = env_weight(r, j);
        if (w > 0.0) {
            c = j;
            if (target_c < left + w) {
                break;
            }
            left += w;
        }
    }
    let w = env_weight(r, c);
    left = min(left, row - w);
    let fx = clamp((target_c - left) / w, 0.0, 1.0);
    let p = vec2<f32>((f32(c) + fx) / f32(ENV_COLS), (f32(r) + fy) / f32(ENV_ROWS));
    return vec4<f32>(p, 0.0, w * f32(ENV_ROWS * ENV_COLS) / total);
}

fn env_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {
    if (any(d.xy < vec2<f32>(0.0)) || any(d.xy > vec2<f32>(1.0))) {
        return 0.0;
    }
    let c = min(u32(d.x * f32(ENV_COLS)), ENV_COLS - 1u);
    let r = min(u32(d.y * f32(ENV_ROWS)), ENV_ROWS - 1u);
    return env_weight(r, c) * f32(ENV_ROWS * ENV_COLS) / env_total();
}
