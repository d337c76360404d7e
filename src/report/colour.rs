//! Colour scales of the heat maps: how a value becomes a colour.
//!
//! - [`Scale::Sequential`]: viridis-like, from `min(0, min v)` to `max v`. When every value
//!   is `>= 0` and `max / min_positive > 1e3`, it switches to `log10(1 + v/p)` with `p` the
//!   smallest positive value (for integer counts `p = 1`, i.e. plain `log10(1 + v)`).
//! - [`Mapping::counts`]: for counts and expected counts drawn on one scale, `log10(1 + v/p)`
//!   with `p` fixed at [`COUNT_FLOOR`] (a tenth of one count) rather than the smallest value, so
//!   that an expected tail of 1e-300 does not stretch the scale over 300 empty decades.
//! - [`Scale::Diverging`]: blue-white-red, symmetric in `[-L, L]` with `L = max |v|`
//!   (at least a tiny positive number), so 0 is white.
//!
//! Non-finite values (NaN, ±inf) get [`NAN_GREY`] and are ignored when fitting the scale; an
//! all-zero or empty set of values fits without dividing by zero.

use image::Rgb;

/// How cell values map to colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Non-negative values such as counts: viridis-like, log-scaled when the range is wide.
    Sequential,
    /// Signed values such as residuals: blue-white-red, symmetric around 0.
    Diverging,
}

/// Colour of NaN / infinite / missing values; absent from both colormaps.
pub const NAN_GREY: Rgb<u8> = Rgb([128, 128, 128]);

/// Colour of cells a map marks (a residual where the expected count is below 0: the pdf is
/// negative there); absent from both colormaps and far from grey.
pub const MARKED: Rgb<u8> = Rgb([230, 0, 200]);

/// Above this max / min-positive ratio a sequential scale goes logarithmic.
const LOG_RATIO: f64 = 1e3;

/// Viridis sampled at t = 0, 1/8, …, 1.
pub(crate) const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 82, 139],
    [44, 114, 142],
    [33, 145, 140],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Blue → white → red (ColorBrewer RdBu, reversed) at t = 0, 1/4, …, 1.
pub(crate) const BLUE_WHITE_RED: [[u8; 3]; 5] = [
    [5, 48, 97],
    [67, 147, 195],
    [247, 247, 247],
    [214, 96, 77],
    [103, 0, 31],
];

/// The floor of a log count scale ([`Mapping::counts`]): a tenth of one count. Expected counts
/// far below it are as good as zero (no bin holds a tenth of a sample), while a bin expecting
/// about one count stands clearly above an empty one.
pub const COUNT_FLOOR: f64 = 0.1;

/// Maps finite values to `t ∈ [0, 1]` along the colormap, and back for tick labels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mapping {
    /// `t = (v - lo) / (hi - lo)`, with `hi > lo`.
    Linear { lo: f64, hi: f64 },
    /// `t = ln(1 + v/p) / ln(1 + hi/p)`, `p` the smallest positive value, `hi > 0`.
    Log { p: f64, hi: f64 },
    /// `t = (1 + v/lim) / 2`, with `lim > 0`.
    Symmetric { lim: f64 },
}

impl Mapping {
    /// Chooses the mapping for `values` (non-finite ones ignored).
    pub fn fit(scale: Scale, values: &[f64]) -> Self {
        let s = Stats::of(values);
        match scale {
            Scale::Diverging => Mapping::Symmetric {
                lim: s.max_abs.max(f64::MIN_POSITIVE),
            },
            Scale::Sequential => match s.min_pos {
                Some(p) if s.min >= 0.0 && s.max / p > LOG_RATIO => Mapping::Log { p, hi: s.max },
                _ => Self::linear(s.min.min(0.0), s.max),
            },
        }
    }

    /// The scale of counts and expected counts drawn side by side (fit it to both): logarithmic
    /// from [`COUNT_FLOOR`] when the largest value exceeds `LOG_RATIO` floors, else linear from 0.
    pub fn counts(values: &[f64]) -> Self {
        let s = Stats::of(values);
        if s.min >= 0.0 && s.max / COUNT_FLOOR > LOG_RATIO {
            Mapping::Log { p: COUNT_FLOOR, hi: s.max }
        } else {
            Self::linear(s.min.min(0.0), s.max)
        }
    }

    /// A linear mapping over `[lo, hi]`, widened to `[lo, lo + 1]` when empty.
    fn linear(lo: f64, hi: f64) -> Self {
        let hi = if hi > lo { hi } else { lo + 1.0 };
        Mapping::Linear { lo, hi }
    }

    /// Position of finite `v` along the colormap, clamped to `[0, 1]`.
    pub fn unit(&self, v: f64) -> f64 {
        let t = match *self {
            Mapping::Linear { lo, hi } => (v - lo) / (hi - lo),
            Mapping::Log { p, hi } => log_ratio(v, p) / log_ratio(hi, p),
            Mapping::Symmetric { lim } => 0.5 + 0.5 * v / lim,
        };
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }

    /// The value at colormap position `t` (inverse of [`Mapping::unit`]).
    pub fn value_at(&self, t: f64) -> f64 {
        match *self {
            Mapping::Linear { lo, hi } => lo + t * (hi - lo),
            Mapping::Log { hi, .. } if t >= 1.0 => hi,
            Mapping::Log { p, hi } => p * (t * log_ratio(hi, p)).exp_m1(),
            Mapping::Symmetric { lim } => (2.0 * t - 1.0) * lim,
        }
    }

    /// Whether the scale is logarithmic (the colour bar says so).
    pub fn is_log(&self) -> bool {
        matches!(self, Mapping::Log { .. })
    }
}

/// `ln(1 + v/p)`, robust when `v/p` overflows.
fn log_ratio(v: f64, p: f64) -> f64 {
    let r = v.max(0.0) / p;
    if r.is_finite() {
        r.ln_1p()
    } else {
        v.ln() - p.ln()
    }
}

/// Range statistics over the finite values.
struct Stats {
    min: f64,
    max: f64,
    max_abs: f64,
    min_pos: Option<f64>,
}

impl Stats {
    /// Statistics of the finite entries of `values`; all zero when there are none.
    fn of(values: &[f64]) -> Self {
        let finite = || values.iter().copied().filter(|v| v.is_finite());
        let min = finite().fold(f64::INFINITY, f64::min);
        let max = finite().fold(f64::NEG_INFINITY, f64::max);
        let min_pos = finite()
            .filter(|&v| v > 0.0)
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.min(v))));
        let (min, max) = if min <= max { (min, max) } else { (0.0, 0.0) };
        Stats {
            min,
            max,
            max_abs: min.abs().max(max.abs()),
            min_pos,
        }
    }
}

/// Colour at position `t ∈ [0, 1]` of the scale's colormap.
pub fn colour(scale: Scale, t: f64) -> Rgb<u8> {
    match scale {
        Scale::Sequential => lerp_table(&VIRIDIS, t),
        Scale::Diverging => lerp_table(&BLUE_WHITE_RED, t),
    }
}

/// Piecewise-linear interpolation in an evenly spaced colour table; `t = 1` gives the last
/// entry exactly.
fn lerp_table(table: &[[u8; 3]], t: f64) -> Rgb<u8> {
    let x = t.clamp(0.0, 1.0) * (table.len() - 1) as f64;
    let i = (x.floor() as usize).min(table.len() - 2);
    let f = x - i as f64;
    let (a, b) = (table[i], table[i + 1]);
    let mix = |k: usize| (a[k] as f64 + (b[k] as f64 - a[k] as f64) * f).round() as u8;
    Rgb([mix(0), mix(1), mix(2)])
}

/// Colour of one value: its place on the scale, or grey when it is not finite.
pub fn value_colour(scale: Scale, mapping: &Mapping, v: f64) -> Rgb<u8> {
    if v.is_finite() {
        colour(scale, mapping.unit(v))
    } else {
        NAN_GREY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_or_constant_range_is_widened() {
        assert_eq!(
            Mapping::fit(Scale::Sequential, &[0.0; 4]),
            Mapping::Linear { lo: 0.0, hi: 1.0 }
        );
        assert_eq!(
            Mapping::fit(Scale::Sequential, &[f64::NAN]),
            Mapping::Linear { lo: 0.0, hi: 1.0 }
        );
    }

    #[test]
    fn a_count_scale_starts_at_its_floor_whatever_the_smallest_value() {
        // an expected tail of 4.9e-319 beside 1e5 counts: the middle of the scale is
        // p(√(1 + hi/p) − 1) with p = 0.1 (t = ½ of ln(1 + v/p)/ln(1 + hi/p)), about 99.9
        let m = Mapping::counts(&[0.0, 4.9e-319, 3.0, 1e5]);
        assert_eq!(m, Mapping::Log { p: 0.1, hi: 1e5 });
        let mid = 0.1 * ((1.0f64 + 1e6).sqrt() - 1.0);
        assert!((m.value_at(0.5) - mid).abs() < 1e-9 * mid, "{}", m.value_at(0.5));
        // one count sits at ln 11 / ln(1 + 1e6) of the way up, well clear of an empty bin
        assert!((m.unit(1.0) - 11f64.ln() / 1_000_001f64.ln()).abs() < 1e-12);
        assert_eq!(m.unit(0.0), 0.0);
        // few counts: linear from 0
        assert_eq!(Mapping::counts(&[0.5, 40.0]), Mapping::Linear { lo: 0.0, hi: 40.0 });
    }
}
