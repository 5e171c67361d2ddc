//! Trilinear interpolation of a volume at a world position, with the texture unit's
//! clamp-to-edge rule, in f64.

use glam::DVec3;

use crate::volume::Volume;

/// The value in data units at world position `p` (millimetres), interpolated between the eight
/// nearest voxel centres; positions beyond the outermost centres take the edge values (as
/// clamp-to-edge texture addressing does). `None` when any voxel with a non-zero weight is NaN or
/// infinite: such samples are transparent.
pub fn sample_trilinear(volume: &Volume, p: DVec3) -> Option<f64> {
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
    let mut sum = 0.0;
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
        let v = volume.value(idx[0], idx[1], idx[2]);
        if !v.is_finite() {
            return None;
        }
        sum += w * v;
    }
    Some(sum)
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
    fn nan_neighbours_make_the_sample_missing_only_when_weighted() {
        let v = Volume::new(
            "t",
            [3, 1, 1],
            [1.0; 3],
            Samples::F32(vec![1.0, 2.0, f32::NAN]),
            ValueMapping::IDENTITY,
        )
        .expect("valid");
        assert_eq!(sample_trilinear(&v, DVec3::new(0.5, 0.0, 0.0)), Some(1.5));
        assert_eq!(sample_trilinear(&v, DVec3::new(1.0, 0.0, 0.0)), Some(2.0));
        assert_eq!(sample_trilinear(&v, DVec3::new(1.5, 0.0, 0.0)), None);
    }
}
