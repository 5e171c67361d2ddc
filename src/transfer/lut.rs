//! Baking a transfer function into the RGBA lookup table the GPU samples.
//!
//! The table spans the volume's normalisation range (the value range in data units): entry `i`
//! holds the transfer function at `range.min + i / (N - 1) * range.width()`, so a normalised
//! sample value `s` in `[0, 1]` reads it at texel coordinate `s * (N - 1) + 0.5`. Colours are
//! straight (not premultiplied); alpha is already corrected for the ray step, so the ray loop
//! needs no `pow` except on a path's last, partial segment.

use super::TransferFunction;
use crate::sampling::corrected_opacity;
use crate::volume::ValueRange;

/// Number of entries in the lookup table: about one Hounsfield unit per entry over a CT range,
/// sixteen per level of an 8-bit volume.
pub const LUT_SIZE: usize = 4096;

/// The table for `tf` over `range` with the opacity corrected for a step of `step_over_d0`
/// (the ray step divided by the smallest voxel spacing).
pub fn bake(tf: &TransferFunction, range: ValueRange, step_over_d0: f64) -> Vec<[f32; 4]> {
    (0..LUT_SIZE)
        .map(|i| {
            let value = range.denormalize(i as f64 / (LUT_SIZE - 1) as f64);
            let [r, g, b] = tf.color_at(value, range);
            let alpha = corrected_opacity(tf.opacity_at(value, range), step_over_d0, 1.0);
            [r as f32, g as f32, b as f32, alpha as f32]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn end_entries_hit_the_range_ends_and_opacity_is_step_corrected() {
        let tf = TransferFunction::grey_ramp();
        let range = ValueRange {
            min: 0.0,
            max: 255.0,
        };
        let lut = bake(&tf, range, 2.0);
        assert_eq!(lut.len(), LUT_SIZE);
        assert_eq!(lut[0], [0.0, 0.0, 0.0, 0.0]);
        assert_eq!(lut[LUT_SIZE - 1], [1.0, 1.0, 1.0, 1.0]);
        let mid = (LUT_SIZE - 1) as f64 / 2.0;
        let i = mid.floor() as usize;
        let a = i as f64 / (LUT_SIZE - 1) as f64;
        let expected = 1.0 - (1.0 - a).powi(2);
        assert!((lut[i][3] as f64 - expected).abs() < 1e-6);
    }
}
