#define_import_path lobes::reflect
#import lobes::math::Real
//! embed: reflect
//! The half vector → reflected direction change of variables, p(ωr) = p(h) / (4 |ωr·h|), and the
//! sample every lobe returns.

// The half-vector -> reflected-direction change of variables; CPU twin: src/reference/reflect.rs.
// wr = 2 (wi.h) h - wi and p(wr) = p(h) / (4 |wr.h|) (tutorial part 2; Walter et al. 2007, eq. 14).

/// π.
const PI: Real = 3.141592653589793;

/// What every sampler returns: the half vector `h`, the direction `wr` and its density `pdf_r`
/// per unit solid angle. A sample with `wr.z <= 0` (below the horizon) carries no energy.
struct LobeSample {
    h: vec3<Real>,
    wr: vec3<Real>,
    pdf_r: Real,
}

/// ωi reflected about the unit vector h: 2 (ωi·h) h − ωi.
fn reflect_about(wi: vec3<Real>, h: vec3<Real>) -> vec3<Real> {
    return 2.0 * dot(wi, h) * h - wi;
}

// Rotated anisotropy (CPU twin: src/reference/frame.rs): r = (cos, sin) of the angle from +x to
// the lobe's alpha_x axis about the normal. frame_to_local is R^-1 w, frame_to_world is R w; the
// generated call sites of a rotated lobe (src/engine/gpu/compose.rs call_site) turn what they
// pass to a sampler into its frame and what it returns back. p and f are unchanged: a rotation
// keeps solid angle, and reflection commutes with it.
/// w in the frame of a lobe rotated by r = (cos, sin) of its angle about the normal (R⁻¹ w).
fn frame_to_local(r: vec2<Real>, w: vec3<Real>) -> vec3<Real> {
    return vec3<Real>(r.x * w.x + r.y * w.y, r.x * w.y - r.y * w.x, w.z);
}

/// w from a rotated lobe's frame back (R w).
fn frame_to_world(r: vec2<Real>, w: vec3<Real>) -> vec3<Real> {
    return vec3<Real>(r.x * w.x - r.y * w.y, r.y * w.x + r.x * w.y, w.z);
}

/// A LobeSample's vectors into a rotated lobe's frame.
fn sample_to_local(r: vec2<Real>, s: LobeSample) -> LobeSample {
    return LobeSample(frame_to_local(r, s.h), frame_to_local(r, s.wr), s.pdf_r);
}

/// A LobeSample's vectors back from a rotated lobe's frame.
fn sample_to_world(r: vec2<Real>, s: LobeSample) -> LobeSample {
    return LobeSample(frame_to_world(r, s.h), frame_to_world(r, s.wr), s.pdf_r);
}

// A LobeSample with its reflected density, which is 0 for light from below the surface
// (wi.z < 0) and for reflections into it (wr.z <= 0), as in src/reference (Lobe::pdf_r).
/// A LobeSample with density `pdf_r`, 0 for ωi below the surface or ωr at or below the horizon.
fn lobe_sample(wi: vec3<Real>, h: vec3<Real>, wr: vec3<Real>, pdf_r: Real) -> LobeSample {
    return LobeSample(h, wr, select(pdf_r, 0.0, wi.z < 0.0 || wr.z <= 0.0));
}

/// A LobeSample from a half vector and its density p(h): p(wr) = p(h) / (4 |wr.h|).
fn reflect_sample(wi: vec3<Real>, h: vec3<Real>, pdf_h: Real) -> LobeSample {
    let wr = reflect_about(wi, h);
    return lobe_sample(wi, h, wr, pdf_h / (4.0 * abs(dot(wr, h))));
}

// The half vector of the reflection wi -> wr where both are counted (wi.z >= 0, wr.z > 0,
// wr != -wi, h above the horizon), else vec3(0): every density of wr is 0 there, as in
// src/reference (Lobe::pdf_r and reflect::half_vector).
/// The half vector of the reflection ωi → ωr, or vec3(0) where no density of ωr counts it.
fn reflection_half_vector(wi: vec3<Real>, wr: vec3<Real>) -> vec3<Real> {
    let s = wi + wr;
    if (wr.z <= 0.0 || wi.z < 0.0 || dot(s, s) == 0.0) {
        return vec3<Real>(0.0);
    }
    let h = normalize(s);
    return select(vec3<Real>(0.0), h, h.z > 0.0);
}

// Unit vector with polar tangent t and unit azimuth (c, s): cos = 1/sqrt(1+t^2), sin = t cos.
// Past t = 1e18 (t^2 would overflow f32) cos = 1/t and sin = 1, the same limit without inf.
/// The unit vector of polar tangent t and azimuth (cos, sin) = (c, s), finite for any t.
fn from_tan_theta(t: Real, c: Real, s: Real) -> vec3<Real> {
    var ct: Real;
    var st: Real;
    if (t > 1.0e18) {
        ct = 1.0 / t;
        st = 1.0;
    } else {
        ct = inverseSqrt(1.0 + t * t);
        st = t * ct;
    }
    return vec3<Real>(st * c, st * s, ct);
}
