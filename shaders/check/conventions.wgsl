// The conventions a user's sampler declares (CPU side: src/check/conventions.rs), between the
// contract wrappers `lobes_contract_sample/pdf/eval` (the user's functions, called in the user's
// frame and measure) and lobes' passes (shaders/check/user_passes.wgsl), which work in lobes'
// frame (normal +z) and per solid angle. Appended to the generated module `lobes::user` after
// the constants LOBES_Y_UP, LOBES_PROJECTED and LOBES_REFLECTION_ONLY.

// A direction between lobes' frame and the user's: with the normal along +y the user's (x, y, z)
// is lobes' (x, z, y), its own inverse (θ from the normal and φ from +x towards the third axis
// are the same numbers in both frames; the swap is a reflection, |det| = 1, so densities and
// Jacobians are unchanged).
fn lobes_frame(v: vec3<f32>) -> vec3<f32> {
    if (LOBES_Y_UP) {
        return v.xzy;
    }
    return v;
}

// Per solid angle from the user's measure: a density per projected solid angle |cos θ| dσ is
// |d.z| times as much per solid angle (an eval, f per projected solid angle, likewise).
fn lobes_measure(value: f32, d: vec3<f32>) -> f32 {
    if (LOBES_PROJECTED) {
        return value * abs(d.z);
    }
    return value;
}

// Whether d is outside what a reflection-only sampler may return: a finite d with d.z ≤ 0. A d
// that is NaN or infinite is not a direction under the surface but a bug, and stays one (read
// from the bits, as user_passes.wgsl's lobes_finite3: NaN compares false under fast-math too).
fn lobes_below(d: vec3<f32>) -> bool {
    let b = bitcast<vec3<u32>>(d) & vec3<u32>(0x7f800000u);
    return LOBES_REFLECTION_ONLY && all(b != vec3<u32>(0x7f800000u)) && d.z <= 0.0;
}

fn lobes_user_sample(wi: vec3<f32>, u: vec4<f32>) -> vec4<f32> {
    let s = lobes_contract_sample(lobes_frame(wi), u);
    let d = lobes_frame(s.xyz);
    if (lobes_below(d)) {
        // a rejection whatever pdf the sampler reported
        return vec4<f32>(d, 0.0);
    }
    return vec4<f32>(d, lobes_measure(s.w, d));
}

fn lobes_user_pdf(wi: vec3<f32>, d: vec3<f32>) -> f32 {
    if (lobes_below(d)) {
        return 0.0;
    }
    return lobes_measure(lobes_contract_pdf(lobes_frame(wi), lobes_frame(d)), d);
}

fn lobes_user_eval(wi: vec3<f32>, d: vec3<f32>) -> f32 {
    if (lobes_below(d)) {
        return 0.0;
    }
    return lobes_measure(lobes_contract_eval(lobes_frame(wi), lobes_frame(d)), d);
}
