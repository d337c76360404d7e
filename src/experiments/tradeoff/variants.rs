//! The kernel precisions that `lobes tradeoff` compares, as rewrites of the composed WGSL
//! (installed with [`GpuEngine::rewrite`](crate::engine::gpu::GpuEngine::rewrite)). The rewriting
//! happens here and nowhere else:
//!
//! - `f32-accurate`: the kernels as composed (`shaders/*.wgsl`), unchanged;
//! - `f32-fast`: every call of `log`, `exp`, `sin`, `cos`, `atan2` and `neg_ln` in the composed
//!   module is renamed to its `fast_*` twin of `shaders/fastmath.wgsl` (bit tricks and low-order
//!   polynomials, errors 1e-4 to 1.5e-3), which is appended;
//! - `f64`: `shaders/f64.wgsl` (f64 samplers, f64 binning, its own f64 sin/cos/atan2/exp/ln;
//!   plus `shaders/f64_beckmann.wgsl`, f64 erfc and erf⁻¹, for Beckmann) is appended and replaces the composed `draw` and `explicit_samples`, with the job's α and ωi
//!   baked in as f64 constants (the kernel's uniform block carries them in f32 only).

use crate::engine::gpu::compose;
use crate::engine::gpu::engine::Rewrite;
use crate::engine::job::Job;
use crate::reference::{LobeKind, sampler};
use serde::Serialize;
use std::sync::Arc;

pub const FASTMATH: &str = include_str!("../../../shaders/fastmath.wgsl");
pub const F64: &str = include_str!("../../../shaders/f64.wgsl");
pub const F64_BECKMANN: &str = include_str!("../../../shaders/f64_beckmann.wgsl");

/// The arithmetic of a sampling kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    /// f32 with cheap approximations of ln, exp, sin, cos and atan2.
    F32Fast,
    /// f32 with the builtin functions (the kernels `lobes run` judges).
    F32Accurate,
    /// f64 throughout (needs SHADER_F64).
    F64,
}

impl Precision {
    pub const ALL: [Precision; 3] = [Precision::F32Fast, Precision::F32Accurate, Precision::F64];

    pub fn name(self) -> &'static str {
        match self {
            Precision::F32Fast => "f32-fast",
            Precision::F32Accurate => "f32-accurate",
            Precision::F64 => "f64",
        }
    }

    /// Parses `f32-fast`, `f32-accurate` or `f64`.
    pub fn parse(s: &str) -> Option<Precision> {
        Precision::ALL.into_iter().find(|p| p.name() == s.trim())
    }

    /// The engine rewrite for this precision (`None` for f32-accurate).
    pub fn rewrite(self) -> Option<Rewrite> {
        match self {
            Precision::F32Accurate => None,
            Precision::F32Fast => Some(Arc::new(|_job: &Job, src: String| fast(&src))),
            Precision::F64 => Some(Arc::new(|job: &Job, src: String| f64_kernel(job, &src))),
        }
    }
}

/// The builtins that `f32-fast` replaces (`neg_ln` is lobes' own accurate −ln u).
pub const FAST_REPLACED: [&str; 6] = ["log", "exp", "sin", "cos", "atan2", "neg_ln"];

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// Renames each call `name(` (a whole identifier followed by `(`, not a definition `fn name(`)
/// to `to(`.
pub fn rename_calls(src: &str, name: &str, to: &str) -> String {
    let bytes = src.as_bytes();
    let pat = format!("{name}(");
    let mut out = String::with_capacity(src.len() + 256);
    let mut last = 0;
    for (i, _) in src.match_indices(&pat) {
        let whole = i == 0 || !is_ident(bytes[i - 1]);
        let definition = src[..i].trim_end().ends_with("fn") && src[..i].trim_end().len() < src[..i].len();
        if whole && !definition {
            out.push_str(&src[last..i]);
            out.push_str(to);
            out.push('(');
            last = i + pat.len();
        }
    }
    out.push_str(&src[last..]);
    out
}

/// The `f32-fast` module: calls renamed to `fast_*`, `shaders/fastmath.wgsl` appended.
pub fn fast(src: &str) -> String {
    let mut s = src.to_string();
    for name in FAST_REPLACED {
        s = rename_calls(&s, name, &format!("fast_{name}"));
    }
    s.push('\n');
    s.push_str(FASTMATH);
    s
}

/// An f64 literal that round-trips (17 significant digits).
fn lit(x: f64) -> String {
    format!("{x:.16e}lf")
}

/// Straight-line WGSL for `shaders/f64_beckmann.wgsl`'s erfc (no loops: llvmpipe ends a
/// shader's loops after 65535 iterations per invocation, counted over all loops together,
/// gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`). Relative errors against glibc's erfc, measured in f64 on
/// a 0.001 grid: 1.3e-12 below 2.5, 5e-15 above.
/// - `erf_series_sum64(z2)` = Σ_{n<48} (2 z²)ⁿ / (1·3·5···(2n+1)) by Horner in z², coefficients
///   2ⁿ/(2n+1)!! formed in f64 (A&S 7.1.6), used for z < 2.5;
/// - `erfc_cf_denominator64(z)` = z + (1/2)/(z + 1/(z + (3/2)/(z + …))) from 32 levels deep
///   (A&S 7.1.14), used for z ≥ 2.5.
pub fn erfc_straight_line() -> String {
    const TERMS: usize = 48;
    const LEVELS: usize = 32;
    let mut c = vec![1.0f64];
    for n in 1..TERMS {
        c.push(c[n - 1] * 2.0 / (2 * n + 1) as f64);
    }
    let mut out = String::from("\nfn erf_series_sum64(z2: f64) -> f64 {\n");
    out += &format!("    var s = {};\n", lit(c[TERMS - 1]));
    for k in (0..TERMS - 1).rev() {
        out += &format!("    s = s * z2 + {};\n", lit(c[k]));
    }
    out += "    return s;\n}\n\nfn erfc_cf_denominator64(z: f64) -> f64 {\n    var k = z;\n";
    for n in (1..=LEVELS).rev() {
        out += &format!("    k = z + {} / k;\n", lit(0.5 * n as f64));
    }
    out += "    return k;\n}\n";
    out
}

/// The `f64` module of a lobe job: the composed `draw` and `explicit_samples` renamed out of
/// the way (`*_f32`), `shaders/f64.wgsl` appended with the job's sampler, α and ωi in f64.
///
/// Panics for a job without an f64 sampler (the registry's `sample64`); callers check first.
pub fn f64_kernel(job: &Job, src: &str) -> String {
    let Job::Lobe { lobe, incident, .. } = job else { panic!("lobes tradeoff: f64 kernels exist for lobes only") };
    let spec = sampler::find(lobe.kind, lobe.method);
    let Some(sample64) = spec.wgsl.sample64 else { panic!("lobes tradeoff: no f64 sampler for {}", spec.name()) };
    // definitions start a line (comments may mention them too)
    let mut s = src.replacen("\nfn draw(", "\nfn draw_f32(", 1).replacen("\nfn explicit_samples(", "\nfn explicit_samples_f32(", 1);
    assert!(s.contains("\nfn draw_f32(") && s.contains("\nfn explicit_samples_f32("), "composed lobe kernel lacks draw/explicit_samples");
    s.push_str(&format!(
        "\n// f64 variant (lobes tradeoff): the job's alpha and incident direction in f64\n\
         const A64: vec2<f64> = vec2<f64>({}, {});\nconst WI64: vec3<f64> = vec3<f64>({}, {}, {});\n",
        lit(lobe.alpha_x),
        lit(lobe.alpha_y),
        lit(incident.x),
        lit(incident.y),
        lit(incident.z)
    ));
    s.push_str(&compose::call_site("sampler_sample64", "a: vec2<f64>, wi: vec3<f64>, u: vec2<f32>", "LobeSample64", &[spec], |_| {
        format!("{sample64}(a, wi, u)")
    }));
    s.push_str(F64);
    if lobe.kind == LobeKind::Beckmann {
        s.push_str(F64_BECKMANN);
        s.push_str(&erfc_straight_line());
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renames_calls_only() {
        let src = "fn neg_ln(u: f32) -> f32 { return -log(u); }\nlet a = neg_ln(x) + exp(y) + fast_exp(z) + exp2(w) + my_log(v);";
        let out = fast(src);
        let head = &out[..out.find("// Cheap").unwrap()];
        assert!(head.contains("fn neg_ln(u: f32)"), "{head}");
        assert!(head.contains("-fast_log(u)"));
        assert!(head.contains("fast_neg_ln(x) + fast_exp(y) + fast_exp(z) + exp2(w) + my_log(v)"), "{head}");
    }

    #[test]
    fn literals_round_trip() {
        for x in [0.3, 1.0 / 3.0, std::f64::consts::FRAC_1_SQRT_2, 1e-7, 1e-300] {
            let s = lit(x);
            assert_eq!(s[..s.len() - 2].parse::<f64>().unwrap(), x);
        }
    }
}
