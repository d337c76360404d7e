// Shared microfacet helpers; CPU twin: src/reference/microfacet.rs.

// normalize(ax wx, ay wy, wz): w stretched to the alpha = 1 configuration (Heitz 2018, listing 1).
fn stretch(a: vec2<f32>, w: vec3<f32>) -> vec3<f32> {
    return normalize(vec3<f32>(a * w.xy, w.z));
}
