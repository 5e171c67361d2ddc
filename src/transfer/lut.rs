//! Baking a transfer function into the RGBA lookup table the GPU samples.
//!
//! The table spans the volume's normalisation range (the value range in data units): entry `i`
//! holds the transfer function at `range.min + i / (N - 1) * range.width()`, so a normalised
//! sample value `s` in `[0, 1]` reads it at texel coordinate `s * (N - 1) + 0.5`. Colours are
//! straight (not premultiplied); the fourth channel is the **optical depth of one step**,
//! `−ln(1 − α)·Δt/d₀`, so a sample's opacity is `1 − exp(−depth·w)` with `w` the share of a step
//! it stands for (1 except on a path's last segment). Storing the corrected opacity instead
//! rounds `1 − (1 − α)^(Δt/d₀)` to exactly 1 in f32 at large steps, after which a short last
//! segment can no longer be scaled back (a 100-voxel step made every short path opaque).

use super::TransferFunction;
use crate::volume::ValueRange;

/// Number of entries in the lookup table: about one Hounsfield unit per entry over a CT range,
/// sixteen per level of an 8-bit volume.
pub const LUT_SIZE: usize = 4096;

/// Optical depth stored for an opacity of exactly 1: `exp(−depth·w)` is 0 in f32 for any last
/// segment longer than 1 % of a step, and it fits a 16-bit float table.
pub const MAX_OPTICAL_DEPTH: f64 = 1.0e4;

/// Optical depth of a step of `step_over_d0` units of `d₀` through a value whose opacity per
/// `d₀` is `alpha`.
fn optical_depth(alpha: f64, step_over_d0: f64) -> f64 {
    (crate::sampling::extinction(alpha) * step_over_d0).min(MAX_OPTICAL_DEPTH)
}

/// Largest finite value of a 16-bit float, the format of the lookup table on the GPU.
const F16_MAX: f64 = 65504.0;

/// The power of two the table's depths are multiplied by before they are stored as 16-bit floats
/// (the shader multiplies them back): the largest that keeps the deepest entry finite, so the
/// smallest depths stay normal numbers (f16 is normal from 2⁻¹⁴ on: a 5·10⁻⁷ depth stored as
/// it is would lose 5 % to the subnormal spacing of 6·10⁻⁸). 1 for a table without depth.
pub(crate) fn f16_depth_scale(table: &[[f32; 4]]) -> f32 {
    let deepest = table.iter().map(|e| f64::from(e[3])).fold(0.0, f64::max);
    if deepest.is_nan() || deepest <= 0.0 {
        return 1.0;
    }
    // 2^⌊log2(F16_MAX / deepest)⌋, within f32's exponents.
    let exponent = (F16_MAX / deepest).log2().floor().clamp(-100.0, 100.0) as i32;
    2f32.powi(exponent)
}

/// The table for `tf` over `range` with the optical depth of a step of `step_over_d0` (the ray
/// step divided by the smallest voxel spacing).
pub fn bake(tf: &TransferFunction, range: ValueRange, step_over_d0: f64) -> Vec<[f32; 4]> {
    (0..LUT_SIZE)
        .map(|i| {
            let value = range.denormalize(i as f64 / (LUT_SIZE - 1) as f64);
            let [r, g, b] = tf.color_at(value, range);
            let depth = optical_depth(tf.opacity_at(value, range), step_over_d0);
            [r as f32, g as f32, b as f32, depth as f32]
        })
        .collect()
}

/// The table a slice view colours by (`LUT_SIZE` entries over `range`, as [`bake`]): the
/// straight colour and the opacity per `d₀` of each value, as the transfer function gives them.
pub(crate) fn slice_colours(tf: &TransferFunction, range: ValueRange) -> Vec<[f32; 4]> {
    (0..LUT_SIZE)
        .map(|i| {
            let value = range.denormalize(i as f64 / (LUT_SIZE - 1) as f64);
            let [r, g, b] = tf.color_at(value, range);
            let a = tf.opacity_at(value, range);
            [r as f32, g as f32, b as f32, a as f32]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slice_colours_hold_the_transfer_functions_colour_and_opacity_at_each_entry() {
        let tf = crate::transfer::presets::preset("ct-bone").expect("preset");
        let range = ValueRange {
            min: -1024.0,
            max: 3071.0,
        };
        let table = slice_colours(&tf, range);
        assert_eq!(table.len(), LUT_SIZE);
        for i in [0, 1000, 1400, 2047, 4095] {
            let value = range.denormalize(i as f64 / (LUT_SIZE - 1) as f64);
            let [r, g, b] = tf.color_at(value, range);
            let want = [r, g, b, tf.opacity_at(value, range)];
            for (got, want) in table[i].iter().zip(want) {
                assert!((f64::from(*got) - want).abs() < 1e-6, "entry {i}");
            }
        }
        // The preset hides air and shows bone.
        assert_eq!(table[0][3], 0.0);
        assert!(table[LUT_SIZE - 1][3] > 0.0);
    }

    #[test]
    fn the_depth_scale_keeps_the_deepest_entry_finite_and_faint_ones_normal() {
        let faint = vec![[1.0, 1.0, 1.0, 5e-7]; 4];
        let s = f16_depth_scale(&faint);
        // A power of two, the deepest entry as large as f16 allows (above half its maximum).
        assert_eq!(s.log2().fract(), 0.0);
        let stored = 5e-7 * f64::from(s);
        assert!(stored <= F16_MAX && stored > F16_MAX / 2.0, "{stored}");
        let deep = vec![[0.0; 4], [1.0, 1.0, 1.0, MAX_OPTICAL_DEPTH as f32]];
        assert_eq!(f16_depth_scale(&deep), 4.0);
        assert_eq!(f16_depth_scale(&[[0.0; 4]]), 1.0);
    }

    #[test]
    fn end_entries_hit_the_range_ends_and_depth_is_per_step() {
        let tf = TransferFunction::grey_ramp();
        let range = ValueRange {
            min: 0.0,
            max: 255.0,
        };
        let lut = bake(&tf, range, 2.0);
        assert_eq!(lut.len(), LUT_SIZE);
        assert_eq!(lut[0], [0.0, 0.0, 0.0, 0.0]);
        assert_eq!(lut[LUT_SIZE - 1], [1.0, 1.0, 1.0, MAX_OPTICAL_DEPTH as f32]);
        let mid = (LUT_SIZE - 1) as f64 / 2.0;
        let i = mid.floor() as usize;
        let a = i as f64 / (LUT_SIZE - 1) as f64;
        // Two steps of opacity a: 1 − exp(−depth) = 1 − (1 − a)².
        let expected = 1.0 - (1.0 - a).powi(2);
        assert!((1.0 - (-(lut[i][3] as f64)).exp() - expected).abs() < 1e-6);
    }
}
