//! Weighted histograms: per cell the sum of the estimator weights w = f cos θr / p(ωr), as
//! exact 64-bit fixed-point integers (the layout of `shaders/passes/weighted.wgsl`, its GPU twin), and
//! what they estimate: the directional albedo, its standard error, and the weak white furnace.

use serde::{Deserialize, Serialize};

/// Weights are summed as multiples of 2⁻²⁰ (each rounded to the nearest).
pub const WEIGHT_SCALE: f64 = (1u64 << 20) as f64;
/// Squared weights are summed as multiples of 2⁻¹⁶ (they only feed the standard error; a
/// square below 2⁴⁶ times 2¹⁶ stays below 2⁶⁴).
pub const SQUARE_SCALE: f64 = 65536.0;
/// A weight is summed only when it is finite and below 2²³; others are counted as overflows.
pub const WEIGHT_LIMIT: f64 = (1u64 << 23) as f64;

/// The raw result of a weighted run, exactly as summed (shards add exactly).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct WeightedSums {
    /// Σ w per bin, in units of 2⁻²⁰.
    pub bins: Vec<u64>,
    /// Σ w per invalid reason (the order of [`crate::reference::Invalid::ALL`]), in units of 2⁻²⁰.
    pub invalid: [u64; crate::reference::Invalid::COUNT],
    /// Σ w² over the bins' samples, in units of 2⁻¹⁶.
    pub squares_bins: u64,
    /// Σ w² over all samples whose weight was summed, in units of 2⁻¹⁶.
    pub squares_all: u64,
    /// Samples whose weight was not summed: not finite, negative, or ≥ 2²³.
    pub overflow: u64,
    /// Σ w² over the samples of the bins below the horizon (the first half: rows are even in
    /// number, from cos θ = −1 up), in units of 2⁻¹⁶: a rough dielectric's other side.
    #[serde(default)]
    pub squares_lower: u64,
    /// Per bin, the largest relative difference between a sample's weight and
    /// eval · cos θr / pdf formed independently (0 for an empty bin).
    pub max_error: Vec<f32>,
}

/// A fixed-point weight as the kernels round it.
pub fn to_fixed(w: f64, scale: f64) -> u64 {
    (w * scale).round() as u64
}

impl WeightedSums {
    pub fn zeros(bins: usize) -> Self {
        Self {
            bins: vec![0; bins],
            invalid: [0; crate::reference::Invalid::COUNT],
            squares_bins: 0,
            squares_all: 0,
            overflow: 0,
            squares_lower: 0,
            max_error: vec![0.0; bins],
        }
    }

    /// Adds one sample's weight in cell `cell` (a bin, or `bins + reason − 1`), as the kernel does.
    pub fn record(&mut self, cell: usize, w: f64) {
        if (0.0..WEIGHT_LIMIT).contains(&w) {
            let n = self.bins.len();
            let slot = if cell < n { &mut self.bins[cell] } else { &mut self.invalid[cell - n] };
            *slot += to_fixed(w, WEIGHT_SCALE);
            let sq = to_fixed(w * w, SQUARE_SCALE);
            self.squares_all += sq;
            if cell < n {
                self.squares_bins += sq;
            }
            if cell < n / 2 {
                self.squares_lower += sq;
            }
        } else {
            self.overflow += 1;
        }
    }

    /// Adds another run's sums (shards of one run add exactly; the error is the larger).
    pub fn add(&mut self, other: &WeightedSums) {
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            *a += b;
        }
        for (a, b) in self.invalid.iter_mut().zip(&other.invalid) {
            *a += b;
        }
        self.squares_bins += other.squares_bins;
        self.squares_all += other.squares_all;
        self.overflow += other.overflow;
        self.squares_lower += other.squares_lower;
        for (a, b) in self.max_error.iter_mut().zip(&other.max_error) {
            *a = a.max(*b);
        }
    }

    /// The estimate of ∫ over bin i of f cos θr dωr from `n` samples.
    pub fn bin_albedo(&self, i: usize, n: u64) -> f64 {
        self.bins[i] as f64 / WEIGHT_SCALE / n as f64
    }

    /// Σ w / N over the bins: the directional albedo (the hemisphere's ∫ f cos θr dωr).
    pub fn albedo(&self, n: u64) -> f64 {
        self.bins.iter().map(|&b| b as u128).sum::<u128>() as f64 / WEIGHT_SCALE / n as f64
    }

    /// Σ w / N over the bins of one hemisphere, `lower` (z < 0) or upper: a rough dielectric's
    /// reflected or transmitted albedo.
    pub fn hemisphere_albedo(&self, n: u64, lower: bool) -> f64 {
        let half = self.bins.len() / 2;
        let bins = if lower { &self.bins[..half] } else { &self.bins[half..] };
        bins.iter().map(|&b| b as u128).sum::<u128>() as f64 / WEIGHT_SCALE / n as f64
    }

    /// The standard error of [`hemisphere_albedo`](Self::hemisphere_albedo).
    pub fn hemisphere_std_error(&self, n: u64, lower: bool) -> f64 {
        let squares = if lower { self.squares_lower } else { self.squares_bins - self.squares_lower };
        mean_std_error(self.hemisphere_albedo(n, lower), squares, n)
    }

    /// Σ w / N over every sample, the reflections below the horizon included with |cos θr|:
    /// the whole sphere's ∫ f |cos θr| dωr (the weak white furnace).
    pub fn sphere_total(&self, n: u64) -> f64 {
        let below: u128 = self.invalid.iter().map(|&b| b as u128).sum();
        self.albedo(n) + below as f64 / WEIGHT_SCALE / n as f64
    }

    /// The standard error √((E(w²) − E(w)²) / N) of the albedo (`hemisphere`: samples below
    /// the horizon weigh 0) or of the sphere total.
    pub fn std_error(&self, n: u64, hemisphere: bool) -> f64 {
        let (mean, squares) = if hemisphere { (self.albedo(n), self.squares_bins) } else { (self.sphere_total(n), self.squares_all) };
        mean_std_error(mean, squares, n)
    }

    /// The largest per-bin weight difference.
    pub fn max_weight_error(&self) -> f32 {
        self.max_error.iter().copied().fold(0.0, f32::max)
    }
}

/// √((E(w²) − E(w)²) / N) from the mean E(w) and Σ w² in units of 2⁻¹⁶.
fn mean_std_error(mean: f64, squares: u64, n: u64) -> f64 {
    let second = squares as f64 / SQUARE_SCALE / n as f64;
    ((second - mean * mean).max(0.0) / n as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_sums_are_exact_and_order_free() {
        let mut a = WeightedSums::zeros(2);
        let mut b = WeightedSums::zeros(2);
        let ws = [0.25, 1.5, 3.0e6, 1e-7, 7.0];
        for (i, &w) in ws.iter().enumerate() {
            a.record(i % 2, w);
        }
        for (i, &w) in ws.iter().enumerate().rev() {
            b.record(i % 2, w);
        }
        assert_eq!(a, b);
        assert_eq!(a.bins[1], to_fixed(1.5, WEIGHT_SCALE) + to_fixed(1e-7, WEIGHT_SCALE));
        assert_eq!(a.bins[0], to_fixed(0.25, WEIGHT_SCALE) + to_fixed(3.0e6, WEIGHT_SCALE) + to_fixed(7.0, WEIGHT_SCALE));
        a.record(0, f64::NAN);
        a.record(0, 1e9);
        assert_eq!(a.overflow, 2);
    }

    #[test]
    fn constant_weights_have_no_error() {
        let mut s = WeightedSums::zeros(1);
        for _ in 0..1000 {
            s.record(0, 0.75);
        }
        assert_eq!(s.albedo(1000), 0.75);
        assert_eq!(s.std_error(1000, true), 0.0);
    }
}

/// One albedo's z-test: Σ w / N over some bins against the f64 quadrature of f |cos θo| over them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct AlbedoTest {
    /// Σ w / N over the bins of one side.
    pub albedo: f64,
    pub std_error: f64,
    /// ∫ over the same bins of f |cos θo| by f64 quadrature (the sum of the per-bin integrals).
    pub reference: f64,
    /// (albedo − reference) / reference.
    pub relative_error: f64,
    /// (albedo − reference) / std_error, and its two-sided p-value.
    pub z: f64,
    pub p_value: f64,
}

impl AlbedoTest {
    pub fn new(albedo: f64, std_error: f64, reference: f64) -> Self {
        let (z, p_value) = two_sided(albedo - reference, std_error, reference);
        Self { albedo, std_error, reference, relative_error: (albedo - reference) / reference, z, p_value }
    }
}

/// The verdict on a weighted histogram.
#[derive(Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct AlbedoCheck {
    /// Σ w / N over the bins on the incident side (for a rough dielectric, the reflected albedo)
    /// against ∫ over the incident hemisphere of f |cos θr| by f64 quadrature (the sum of the
    /// per-bin integrals); its fields sit at the top level of the JSON.
    #[serde(flatten)]
    pub reflected: AlbedoTest,
    /// A rough dielectric's transmitted albedo: the bins across the surface, tested like the
    /// reflected one (`None` for a reflection lobe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmitted: Option<AlbedoTest>,
    /// Σ w / N over every sample (reflections below the horizon, a dielectric's wrong-side
    /// samples, with |cos θr|).
    pub sphere_total: f64,
    pub sphere_std_error: f64,
    /// The closed form of the sphere total, where the effects have one (the weak white furnace).
    pub furnace: Option<f64>,
    pub furnace_p_value: Option<f64>,
    /// Largest per-bin relative difference between the sampler's weight and eval·cos/pdf.
    pub max_weight_error: f32,
    pub weight_error_limit: f32,
    /// Samples whose weight was not summed (not finite or ≥ 2²³).
    pub overflow: u64,
    /// Per-case significance of the two z-tests.
    pub significance: f64,
    pub passed: bool,
    /// Per bin, the quadrature of f cos θr (for the heat map and the JSON).
    #[serde(skip)]
    pub reference_bins: Vec<f64>,
}

impl std::fmt::Debug for AlbedoCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "albedo {:.6} ± {:.1e} vs {:.6} (rel {:+.1e}, p {:.3e}); {}sphere {:.6} ± {:.1e} vs furnace {:?} (p {:?}); weight error {:.1e}; overflow {}; {}",
            self.reflected.albedo,
            self.reflected.std_error,
            self.reflected.reference,
            self.reflected.relative_error,
            self.reflected.p_value,
            self.transmitted.as_ref().map_or(String::new(), |t| format!(
                "transmitted {:.6} ± {:.1e} vs {:.6} (rel {:+.1e}, p {:.3e}); ",
                t.albedo, t.std_error, t.reference, t.relative_error, t.p_value
            )),
            self.sphere_total,
            self.sphere_std_error,
            self.furnace,
            self.furnace_p_value,
            self.max_weight_error,
            self.overflow,
            if self.passed { "pass" } else { "FAIL" }
        )
    }
}

/// The largest per-bin weight difference accepted in f32 (issue 5: 1e-3).
pub const WEIGHT_ERROR_LIMIT: f32 = 1e-3;

/// The relative accuracy of an f32 weight summed in fixed point: the z-tests add it to the
/// statistical error, so that a constant weight (zero variance) is not failed for rounding.
pub const F32_FLOOR: f64 = 1e-6;

/// z = diff / σ and its two-sided p-value, with σ² = std_error² + (F32_FLOOR · value)².
pub fn two_sided(diff: f64, std_error: f64, value: f64) -> (f64, f64) {
    let sigma = std_error.hypot(F32_FLOOR * value.abs());
    if diff == 0.0 {
        return (0.0, 1.0);
    }
    let z = diff / sigma;
    (z, libm::erfc(z.abs() / std::f64::consts::SQRT_2))
}

