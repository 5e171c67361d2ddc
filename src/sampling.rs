//! The sample grid along a ray, shared by every strategy so that leaping never changes which
//! samples are taken (DESIGN.md, "Conventions").
//!
//! A ray inside the volume runs from `t = 0` (entry) to `t = L` (exit), in millimetres. It is cut
//! into `n = ceil(L / Δt)` segments `[kΔt, min((k+1)Δt, L)]`; segment `k` is represented by one
//! sample at `t_k = min((k + offset)·Δt, L)` with weight `w_k = min(Δt, L − kΔt) / Δt`. The
//! weight scales the opacity correction, `α' = 1 − (1 − α)^(w_k·Δt/d₀)`, so a ray through a
//! homogeneous region composites exactly `1 − (1 − α)^(L/d₀)` whatever the step. Only the last
//! segment can be partial. The WGSL ray loop (`shaders/march/`) implements the same rule.

/// The samples of one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleGrid {
    /// Path length inside the volume, millimetres.
    pub length_mm: f64,
    /// Step between samples, millimetres.
    pub step_mm: f64,
    /// Offset of the first sample within its segment, in steps, in `[0, 1)`.
    pub offset: f64,
}

/// One sample of a [`SampleGrid`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSample {
    /// Segment index.
    pub index: u64,
    /// Distance from the entry point, millimetres.
    pub t_mm: f64,
    /// Length of the segment the sample represents, as a fraction of the step (in `(0, 1]`).
    pub weight: f64,
}

impl SampleGrid {
    /// Number of segments (and samples); zero for an empty or degenerate path.
    pub fn count(&self) -> u64 {
        if !(self.length_mm > 0.0 && self.step_mm > 0.0) {
            return 0;
        }
        (self.length_mm / self.step_mm).ceil() as u64
    }

    /// Sample `k` (`k < count()`).
    pub fn sample(&self, k: u64) -> GridSample {
        let start = k as f64 * self.step_mm;
        GridSample {
            index: k,
            t_mm: ((k as f64 + self.offset) * self.step_mm).min(self.length_mm),
            weight: ((self.length_mm - start).min(self.step_mm) / self.step_mm).clamp(0.0, 1.0),
        }
    }

    /// All samples, front to back.
    pub fn samples(&self) -> impl Iterator<Item = GridSample> + '_ {
        (0..self.count()).map(|k| self.sample(k))
    }
}

/// Extinction per `d₀` of an opacity `alpha` per `d₀`: `−ln(1 − α)`, infinite for α ≥ 1 (callers
/// cap it to what their tables hold).
pub(crate) fn extinction(alpha: f64) -> f64 {
    -(1.0 - alpha.clamp(0.0, 1.0)).ln()
}

/// Opacity of a sample of weight `weight` (fraction of a step), for a transfer-function opacity
/// `alpha` defined per `d0` and a step of `step_over_d0` units of `d0`.
pub(crate) fn corrected_opacity(alpha: f64, step_over_d0: f64, weight: f64) -> f64 {
    let alpha = alpha.clamp(0.0, 1.0);
    if alpha >= 1.0 {
        return 1.0;
    }
    1.0 - (1.0 - alpha).powf(step_over_d0 * weight)
}

/// The jittered first-sample offset of pixel `(x, y)` in [0, 1): an integer hash (the
/// "lowbias32" finaliser) of the pixel, the same on the GPU (`pixel_jitter` in
/// `shaders/shared/common.wgsl`) bit for bit, so the CPU reference can follow it. Stable from frame to
/// frame: a still image does not shimmer.
fn pixel_jitter(x: u32, y: u32) -> f64 {
    let mut h = x
        .wrapping_mul(1973)
        .wrapping_add(y.wrapping_mul(9277))
        .wrapping_add(26699);
    h = (h ^ (h >> 16)).wrapping_mul(0x7feb_352d);
    h = (h ^ (h >> 15)).wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    f64::from(h >> 8) / 16_777_216.0
}

/// The first-sample offset of pixel `(x, y)` with jitter: its [`pixel_jitter`] rotated by
/// `sample_offset − ½` (mod 1), so the default offset ½ gives the hash itself and progressive
/// refinement's offsets rotate every pixel's start alike.
pub(crate) fn jittered_offset(x: u32, y: u32, sample_offset: f64) -> f64 {
    (pixel_jitter(x, y) + (sample_offset - 0.5)).rem_euclid(1.0)
}

/// The point of the unit square the shadow rays of pixel `(x, y)` take on the light's disc
/// in a frame whose light sample is `sample`: two hashes of the pixel (the second of the
/// mirrored, shifted pixel) rotated by it (mod 1), as `light_point` in
/// shaders/shared/shadow.wgsl.
pub(crate) fn pixel_light_point(x: u32, y: u32, sample: [f64; 2]) -> [f64; 2] {
    let h = [
        pixel_jitter(x, y),
        pixel_jitter(y.wrapping_add(1013), x.wrapping_add(4099)),
    ];
    std::array::from_fn(|i| (h[i] + (sample[i] - 0.5)).rem_euclid(1.0))
}

/// The light sample of refinement frame `k`: ½, ½ first, then the R2 sequence (additive
/// recurrence by the plastic number's powers), whose every prefix covers the square evenly, so
/// the mean of any number of frames has sampled the light's disc evenly.
pub fn light_sample(k: u32) -> [f64; 2] {
    const A: [f64; 2] = [0.754_877_666_246_692_7, 0.569_840_290_998_053_2];
    A.map(|a| (0.5 + a * f64::from(k)).fract())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_the_path_length() {
        for (length, step) in [(10.0, 3.0), (9.0, 3.0), (0.1, 4.0), (7.3, 0.125)] {
            let grid = SampleGrid {
                length_mm: length,
                step_mm: step,
                offset: 0.5,
            };
            let total: f64 = grid.samples().map(|s| s.weight * step).sum();
            assert!((total - length).abs() < 1e-9, "{length} {step}: {total}");
            assert!(grid.samples().all(|s| s.t_mm <= length && s.t_mm >= 0.0));
        }
    }

    #[test]
    fn homogeneous_slab_composites_to_the_analytic_opacity() {
        let (alpha, d0, length) = (0.3, 1.0, 10.0);
        for step in [0.125, 0.5, 1.0, 3.0, 4.0] {
            let grid = SampleGrid {
                length_mm: length,
                step_mm: step,
                offset: 0.5,
            };
            let transmittance: f64 = grid
                .samples()
                .map(|s| 1.0 - corrected_opacity(alpha, step / d0, s.weight))
                .product();
            let expected = (1.0_f64 - alpha).powf(length / d0);
            assert!((transmittance - expected).abs() < 1e-12, "step {step}");
        }
    }

    #[test]
    fn degenerate_paths_have_no_samples() {
        for (l, s) in [(0.0, 1.0), (-1.0, 1.0), (1.0, 0.0), (f64::NAN, 1.0)] {
            let grid = SampleGrid {
                length_mm: l,
                step_mm: s,
                offset: 0.5,
            };
            assert_eq!(grid.count(), 0);
        }
    }

    #[test]
    fn pixel_jitter_is_stable_and_spread_over_the_step() {
        assert_eq!(pixel_jitter(3, 7), pixel_jitter(3, 7));
        let values: Vec<f64> = (0..64)
            .flat_map(|y| (0..64).map(move |x| pixel_jitter(x, y)))
            .collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        // Each tenth of [0, 1) gets about a tenth of 4096 pixels (±30 %).
        for d in 0..10 {
            let n = values.iter().filter(|v| (**v * 10.0) as usize == d).count();
            assert!((287..=533).contains(&n), "decile {d}: {n}");
        }
    }
}
