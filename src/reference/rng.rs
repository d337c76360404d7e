//! Counter-based random numbers: the CPU twin of `shaders/lib/rng.wgsl`.
//!
//! Sample `i` of a run with seed `s` draws its uniforms from `pcg4d(i_lo, i_hi, s_lo, s_hi)`,
//! the 4D PCG hash of Jarzynski & Olano, "Hash Functions for GPU Rendering" (JCGT 9(3), 2020),
//! listing "pcg4d". Only 32-bit integer operations are used, so the GPU and the CPU produce the
//! same bits for the same `(seed, index)`: any GPU sample can be regenerated here from its index.

/// The pcg4d hash (Jarzynski & Olano 2020), wrapping 32-bit arithmetic.
pub fn pcg4d(v: [u32; 4]) -> [u32; 4] {
    let mut v = v.map(|x| x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    mix(&mut v);
    for x in &mut v {
        *x ^= *x >> 16;
    }
    mix(&mut v);
    v
}

fn mix(v: &mut [u32; 4]) {
    v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[3]));
    v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
    v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    v[3] = v[3].wrapping_add(v[1].wrapping_mul(v[2]));
}

/// Maps 32 random bits to a uniform in [0, 1 − 2⁻²⁴]: the top 24 bits times 2⁻²⁴.
/// Exact in f32 and f64, so the GPU and the CPU see the same number.
pub fn to_unit(bits: u32) -> f64 {
    f64::from(bits >> 8) * (1.0 / 16_777_216.0)
}

/// The four uniforms of sample `index` in the run keyed by `seed`.
///
/// ```
/// let u = lobes::reference::rng::uniforms(7, 123);
/// assert!(u.iter().all(|&x| (0.0..1.0).contains(&x)));
/// assert_eq!(u, lobes::reference::rng::uniforms(7, 123));
/// ```
pub fn uniforms(seed: u64, index: u64) -> [f64; 4] {
    pcg4d([index as u32, (index >> 32) as u32, seed as u32, (seed >> 32) as u32]).map(to_unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniforms_are_on_the_24_bit_grid_and_fill_it() {
        let n = 1 << 16;
        let mut mean = [0.0; 4];
        for i in 0..n {
            for (m, u) in mean.iter_mut().zip(uniforms(1, i)) {
                assert_eq!((u * 16_777_216.0).fract(), 0.0);
                *m += u / n as f64;
            }
        }
        // Mean of U[0,1) has standard error 1/sqrt(12 n) ≈ 0.0011 at n = 2^16.
        for m in mean {
            assert!((m - 0.5).abs() < 0.006, "mean {m}");
        }
    }

    #[test]
    fn high_index_bits_and_seed_change_the_stream() {
        assert_ne!(uniforms(1, 5), uniforms(1, 5 + (1 << 32)));
        assert_ne!(uniforms(1, 5), uniforms(2, 5));
        assert_ne!(uniforms(1, 5), uniforms(1 + (1 << 32), 5));
    }
}
