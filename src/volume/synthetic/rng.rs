//! Deterministic randomness for the generated volumes: a SplitMix64 stream for shapes, and
//! stateless per-voxel noise hashed from (seed, voxel index) so that parallel filling gives the
//! same samples as serial filling.
//!
//! SplitMix64 is Steele, Lea & Flood, "Fast splittable pseudorandom number generators" (OOPSLA
//! 2014); its output function is also a good 64-bit integer hash, used here for noise.

/// A SplitMix64 generator: tiny, fast, and statistically good enough for shapes and noise.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// The SplitMix64 output function: a bijective 64-bit mix.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl SplitMix64 {
    /// A generator whose stream is determined by `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN_GAMMA);
        mix64(self.state)
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// `true` with probability `p`.
    pub(crate) fn chance(&mut self, p: f64) -> bool {
        self.next_f64() < p
    }
}

/// Zero-mean noise of unit standard deviation at voxel `index` for stream `seed`, bounded by
/// [`UNIT_NOISE_BOUND`]: the sum of three uniform variables (Irwin–Hall, close to Gaussian but
/// with hard limits, so tests can bound it exactly).
pub(crate) fn unit_noise(seed: u64, index: u64) -> f64 {
    let h = mix64(index ^ mix64(seed));
    let third = |shift: u32| ((h >> shift) & 0x1F_FFFF) as f64 / 0x1F_FFFF as f64 - 0.5;
    // Each term has variance 1/12; three of them 1/4, so doubling gives unit variance.
    2.0 * (third(0) + third(21) + third(42))
}

/// The largest magnitude [`unit_noise`] can take: 2 · 3 · 0.5.
pub const UNIT_NOISE_BOUND: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_is_reproducible_and_seed_dependent() {
        let a: Vec<u64> = {
            let mut r = SplitMix64::new(7);
            (0..4).map(|_| r.next_u64()).collect()
        };
        let b: Vec<u64> = {
            let mut r = SplitMix64::new(7);
            (0..4).map(|_| r.next_u64()).collect()
        };
        let mut c = SplitMix64::new(8);
        assert_eq!(a, b);
        assert_ne!(a[0], c.next_u64());
    }

    #[test]
    fn uniform_values_stay_in_range_with_the_right_mean() {
        let mut r = SplitMix64::new(1);
        let n = 100_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let x = r.range(-2.0, 6.0);
            assert!((-2.0..6.0).contains(&x));
            sum += x;
        }
        // Standard error of the mean of U(-2, 6): (8 / √12) / √n ≈ 0.0073; 5 of them.
        assert!((sum / n as f64 - 2.0).abs() < 0.037);
    }

    #[test]
    fn unit_noise_has_unit_variance_and_stays_bounded() {
        let n = 200_000u64;
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for i in 0..n {
            let x = unit_noise(3, i);
            assert!(x.abs() <= UNIT_NOISE_BOUND);
            sum += x;
            sum_sq += x * x;
        }
        let mean = sum / n as f64;
        let var = sum_sq / n as f64 - mean * mean;
        // Standard error of the mean is 1/√n ≈ 0.0022, of the variance about √(2/n)·0.95 ≈ 0.003
        // (Irwin–Hall kurtosis is below the Gaussian's); allow 5 of each.
        assert!(mean.abs() < 0.011, "mean {mean}");
        assert!((var - 1.0).abs() < 0.016, "variance {var}");
        assert_ne!(unit_noise(3, 0), unit_noise(4, 0));
    }
}
