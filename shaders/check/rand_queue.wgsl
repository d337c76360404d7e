// The --rand queue of a user's sampler (src/check/glue.rs, after the constant
// LOBES_RAND_ORDER and the private lobes_rand_u and lobes_rand_next it declares): the user's
// random functions, their bodies replaced, take the sample's uniforms in turn.

// The next n uniforms of the queue u[LOBES_RAND_ORDER[0]], u[LOBES_RAND_ORDER[1]], …: the
// bodies of the user's --rand functions. Past the fourth it hands out a hash of u and the
// draw's index (never 0 for ever: a loop that redraws until it gets a nonzero number ends),
// and the host refuses a sampler that draws more (lobes_user_draws).
fn lobes_rand_take(n: u32) -> vec4<f32> {
    var r = vec4<f32>(0.0);
    for (var k = 0u; k < n; k++) {
        let i = lobes_rand_next + k;
        if (i < 4u) {
            r[k] = lobes_rand_u[LOBES_RAND_ORDER[i]];
        } else {
            r[k] = f32(lobes_pcg(i ^ lobes_rng_seed(lobes_rand_u)) >> 8u) / 16777216.0;
        }
    }
    lobes_rand_next += n;
    return r;
}
// PCG hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering"), and the state of
// `rng` from the bits of the uniforms: the same u gives the same draws.
fn lobes_pcg(v: u32) -> u32 {
    let s = v * 747796405u + 2891336453u;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}
fn lobes_rng_seed(u: vec4<f32>) -> u32 {
    let b = bitcast<vec4<u32>>(u);
    return lobes_pcg(b.x ^ lobes_pcg(b.y ^ lobes_pcg(b.z ^ lobes_pcg(b.w))));
}
