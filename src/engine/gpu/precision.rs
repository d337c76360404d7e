//! The arithmetic of a kernel ([`Precision`]), chosen when its module is composed: the samplers,
//! the binning and the passes are written once over the WGSL type `Real`, and the precision picks
//! the math modules that declare it (`lobes::math` and `lobes::erf`, [`super::library`]).
//! `lobes tradeoff` compares the three.
//!
//! - `f32-accurate`: `shaders/math/f32.wgsl` (the WGSL builtins) and `erf_f32.wgsl`; the kernels
//!   `lobes run` judges;
//! - `f32-fast`: `shaders/math/f32_fast.wgsl`, where `math_log`, `math_exp`, `math_sin`,
//!   `math_cos`, `math_atan2` and `neg_ln` are bit tricks and low-order polynomials (errors 1e-4
//!   to 1.5e-3), and `erf_f32.wgsl`;
//! - `f64`: `shaders/math/f64.wgsl` (f64 sin/cos/atan2/exp/ln series: SPIR-V has these for 16- and
//!   32-bit floats only) and `erf_f64.wgsl` (f64 erfc and erf⁻¹), with the job's α and ωi as f64
//!   constants (the kernel's uniform block carries them in f32 only).

/// The arithmetic of a sampling kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "check", derive(serde::Serialize), serde(rename_all = "kebab-case"))]
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

    /// The WGSL scalar type of `Real` in the precision's kernels.
    pub fn scalar(self) -> &'static str {
        match self {
            Precision::F32Fast | Precision::F32Accurate => "f32",
            Precision::F64 => "f64",
        }
    }

    /// Parses `f32-fast`, `f32-accurate` or `f64`.
    pub fn parse(s: &str) -> Option<Precision> {
        Precision::ALL.into_iter().find(|p| p.name() == s.trim())
    }
}

/// An f64 literal that round-trips (17 significant digits).
#[cfg(feature = "check")]
pub(crate) fn lit(x: f64) -> String {
    format!("{x:.16e}lf")
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

    /// `shaders/math/erf_f64.wgsl`'s straight-line erfc: the series' coefficients are
    /// c_n = 2ⁿ / (1·3·5···(2n+1)) (A&S 7.1.6), formed by c_n = c_{n−1}·2/(2n+1) in f64, highest
    /// first, and the continued fraction's numerators are n/2 from 32 down to 1 (A&S 7.1.14).
    #[test]
    fn the_straight_line_erfc_has_the_series_coefficients() {
        let src = include_str!("../../../shaders/math/erf_f64.wgsl");
        let body = |name: &str| src.split(&format!("fn {name}(")).nth(1).unwrap().split("\n}").next().unwrap().to_string();
        // the number after the last ` + ` (or ` = `, or ` / ` for `k = z + 16.0 / k;`)
        let last = |l: &str, sep: &str| -> f64 { l.rsplit_once(sep).unwrap().1.trim_end_matches(';').trim().parse().unwrap() };
        let series: Vec<f64> =
            body("erf_series_sum").lines().filter(|l| l.contains("s = s * z2 + ") || l.contains("var s")).map(|l| last(l, if l.contains(" + ") { " + " } else { " = " })).collect();
        let mut c = vec![1.0f64];
        for n in 1..48 {
            c.push(c[n - 1] * 2.0 / (2 * n + 1) as f64);
        }
        c.reverse();
        assert_eq!(series, c);
        let levels: Vec<f64> = body("erfc_cf_denominator").lines().filter(|l| l.contains("k = z + ")).map(|l| last(&l.replace(" / k;", ""), " + ")).collect();
        assert_eq!(levels, (1..=32).rev().map(|n| 0.5 * n as f64).collect::<Vec<_>>());
    }
}
