//! The arithmetic of a kernel ([`Precision`]), chosen when its module is composed
//! (`compose::math_module`, `compose::f64_draw`): the math module of the f32 kernels (`shaders/math/f32.wgsl`, or the approximations of
//! `shaders/math/f32_fast.wgsl` under the same names), and for f64 the draw of `shaders/math/f64.wgsl` in
//! place of `shaders/passes/lobe_draw.wgsl`. `lobes tradeoff` compares the three.
//!
//! - `f32-accurate`: the kernels `lobes run` judges;
//! - `f32-fast`: `math_log`, `math_exp`, `math_sin`, `math_cos`, `math_atan2` and `neg_ln` are
//!   bit tricks and low-order polynomials (errors 1e-4 to 1.5e-3);
//! - `f64`: `shaders/math/f64.wgsl` (f64 samplers, f64 binning, its own f64 sin/cos/atan2/exp/ln;
//!   plus `shaders/math/f64_beckmann.wgsl`, f64 erfc and erf⁻¹, for Beckmann), with the job's α and
//!   ωi as f64 constants (the kernel's uniform block carries them in f32 only).

use serde::Serialize;

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
}

/// An f64 literal that round-trips (17 significant digits).
pub(crate) fn lit(x: f64) -> String {
    format!("{x:.16e}lf")
}

/// Straight-line WGSL for `shaders/math/f64_beckmann.wgsl`'s erfc (no loops: llvmpipe ends a
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_round_trip() {
        for x in [0.3, 1.0 / 3.0, std::f64::consts::FRAC_1_SQRT_2, 1e-7, 1e-300] {
            let s = lit(x);
            assert_eq!(s[..s.len() - 2].parse::<f64>().unwrap(), x);
        }
    }
}
