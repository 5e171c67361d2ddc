//! Trilinear interpolation of a volume at a world position, with the texture unit's
//! clamp-to-edge rule, in f64.

use glam::DVec3;

use crate::volume::Volume;

/// The value in data units at world position `p` (millimetres), interpolated between the eight
/// nearest voxel centres; positions beyond the outermost centres take the edge values (as
/// clamp-to-edge texture addressing does). Where some of the eight are NaN or infinite, the
/// finite ones' weights are renormalised (a non-finite voxel takes no finite neighbour with it),
/// and `None` (transparent) where they weigh less than half: the shaders' `sample_finite`.
pub fn sample_trilinear(volume: &Volume, p: DVec3) -> Option<f64> {
    let (sum, weight) = corners(volume, p, |i, j, k| {
        let v = volume.value(i, j, k);
        v.is_finite().then_some(DVec3::splat(v))
    });
    (weight >= 0.5).then(|| sum.x / weight)
}

/// A colour volume's own colour at `p` (each channel's 8 bits as 0–1), interpolated as the
/// texture unit blends it; `None` for grey volumes.
pub(crate) fn sample_colour(volume: &Volume, p: DVec3) -> Option<DVec3> {
    let colour = volume.colour()?;
    let (sum, _) = corners(volume, p, |i, j, k| {
        let [r, g, b] = colour.rgb8(volume.index(i, j, k));
        Some(DVec3::new(f64::from(r), f64::from(g), f64::from(b)) / 255.0)
    });
    Some(sum)
}

/// The weighted sum of `at` over the eight voxels around `p` that give a value, and their
/// total weight.
pub(super) fn corners(
    volume: &Volume,
    p: DVec3,
    at: impl Fn(u32, u32, u32) -> Option<DVec3>,
) -> (DVec3, f64) {
    let dims = volume.dims();
    let spacing = volume.spacing_mm();
    // Continuous voxel coordinates: voxel centre i sits at i * spacing.
    let mut lo = [0u32; 3];
    let mut hi = [0u32; 3];
    let mut frac = [0.0f64; 3];
    for a in 0..3 {
        let n = dims[a];
        let x = (p[a] / spacing[a]).clamp(0.0, (n - 1) as f64);
        let base = x.floor();
        lo[a] = base as u32;
        hi[a] = (lo[a] + 1).min(n - 1);
        frac[a] = x - base;
    }
    let (mut sum, mut total) = (DVec3::ZERO, 0.0);
    for corner in 0..8u32 {
        let pick = |a: usize| corner >> a & 1 == 1;
        let mut w = 1.0;
        let mut idx = [0u32; 3];
        for a in 0..3 {
            if pick(a) {
                w *= frac[a];
                idx[a] = hi[a];
            } else {
                w *= 1.0 - frac[a];
                idx[a] = lo[a];
            }
        }
        if w == 0.0 {
            continue;
        }
        if let Some(v) = at(idx[0], idx[1], idx[2]) {
            sum += w * v;
            total += w;
        }
    }
    (sum, total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::{Samples, ValueMapping};

    #[test]
    fn interpolates_between_centres_and_clamps_at_edges() {
        let v = Volume::new(
            "t",
            [2, 1, 1],
            [2.0, 1.0, 1.0],
            Samples::F32(vec![10.0, 20.0]),
            ValueMapping::IDENTITY,
        )
        .expect("valid");
        assert_eq!(sample_trilinear(&v, DVec3::new(0.0, 0.0, 0.0)), Some(10.0));
        assert_eq!(sample_trilinear(&v, DVec3::new(1.0, 0.0, 0.0)), Some(15.0));
        assert_eq!(
            sample_trilinear(&v, DVec3::new(-0.9, 0.3, -0.4)),
            Some(10.0)
        );
        assert_eq!(sample_trilinear(&v, DVec3::new(2.9, 0.0, 0.0)), Some(20.0));
    }

    #[test]
    fn nan_neighbours_leave_the_finite_ones_their_values() {
        let v = Volume::new(
            "t",
            [4, 1, 1],
            [1.0; 3],
            Samples::F32(vec![1.0, 2.0, f32::NAN, 4.0]),
            ValueMapping::IDENTITY,
        )
        .expect("valid");
        assert_eq!(sample_trilinear(&v, DVec3::new(0.5, 0.0, 0.0)), Some(1.5));
        assert_eq!(sample_trilinear(&v, DVec3::new(1.0, 0.0, 0.0)), Some(2.0));
        // Nearer the finite voxel: its value alone, not dragged towards or erased by NaN.
        assert_eq!(sample_trilinear(&v, DVec3::new(1.25, 0.0, 0.0)), Some(2.0));
        assert_eq!(sample_trilinear(&v, DVec3::new(2.75, 0.0, 0.0)), Some(4.0));
        // Nearer the NaN voxel: missing.
        assert_eq!(sample_trilinear(&v, DVec3::new(1.75, 0.0, 0.0)), None);
        assert_eq!(sample_trilinear(&v, DVec3::new(2.0, 0.0, 0.0)), None);
    }
}
