//! The cropping box: an axis-aligned part of the volume that rays are limited to.
//!
//! It is kept in *box* coordinates (fractions of the volume's bounding box, the texture
//! coordinates the shaders use), so it survives changes of spacing and works the same on both
//! render paths and in the CPU reference. Rays are clipped to it exactly: every path intersects
//! the pixel's ray with the cropping box instead of the bounding box, and the sample grid starts
//! at that entry, so no sample lies outside it. Values are still interpolated (and gradients
//! estimated) from the whole volume, as VTK and Slicer do: a cut face shows the data there, not
//! the volume's edge.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::camera::Aabb;

/// Thinnest cropping box, as a fraction of the volume's extent, that [`CropBox::validate`]
/// accepts: thinner ones lose the ray's direction to f32 rounding in the slab test.
pub const MIN_CROP_FRACTION: f64 = 1e-4;

/// An axis-aligned box inside the volume, in box coordinates (`[0, 1]³` is the whole volume).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CropBox {
    /// Smallest corner (x, y, z), each in `[0, 1]`.
    pub min: [f64; 3],
    /// Largest corner (x, y, z), each in `[0, 1]` and above `min`.
    pub max: [f64; 3],
}

impl Default for CropBox {
    fn default() -> Self {
        Self::FULL
    }
}

/// What is wrong with a cropping box.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CropError {
    /// A corner is outside `[0, 1]` or not a number.
    #[error("the cropping box must lie inside the volume (0..1 on each axis), got {0:?} – {1:?}")]
    Outside([f64; 3], [f64; 3]),
    /// The box is empty or thinner than [`MIN_CROP_FRACTION`] on some axis.
    #[error(
        "the cropping box must be at least 1/10000 of the volume thick on each axis, got {0:?} – {1:?}"
    )]
    Empty([f64; 3], [f64; 3]),
    /// Voxel bounds given on the command line do not parse or lie outside the volume.
    #[error("cannot crop to voxels {0}: {1}")]
    Voxels(String, String),
}

impl CropBox {
    /// The whole volume.
    pub const FULL: Self = Self {
        min: [0.0; 3],
        max: [1.0; 3],
    };

    /// Whether the box is the whole volume (no cropping).
    pub(crate) fn is_full(&self) -> bool {
        *self == Self::FULL
    }

    /// Checks the corners.
    pub fn validate(&self) -> Result<(), CropError> {
        let inside = |v: &[f64; 3]| v.iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c));
        if !inside(&self.min) || !inside(&self.max) {
            return Err(CropError::Outside(self.min, self.max));
        }
        if (0..3).any(|a| self.max[a] - self.min[a] < MIN_CROP_FRACTION) {
            return Err(CropError::Empty(self.min, self.max));
        }
        Ok(())
    }

    /// The box that keeps voxel *edges* `lo[a]..hi[a]` of a volume of `dims` voxels (voxel `i`
    /// spans `[i, i + 1)`), so `0..dims` is the whole volume.
    pub fn from_voxels(dims: [u32; 3], lo: [f64; 3], hi: [f64; 3]) -> Self {
        let n = dims.map(|d| f64::from(d.max(1)));
        Self {
            min: [0, 1, 2].map(|a| lo[a] / n[a]),
            max: [0, 1, 2].map(|a| hi[a] / n[a]),
        }
    }

    /// Parses `x0:x1,y0:y1,z0:z1` (voxel edges, as [`CropBox::from_voxels`]) for a volume of
    /// `dims` voxels; the box must lie inside the volume.
    pub fn parse_voxels(text: &str, dims: [u32; 3]) -> Result<Self, CropError> {
        let fail = |why: &str| CropError::Voxels(text.to_string(), why.to_string());
        let axes: Vec<&str> = text.split(',').collect();
        if axes.len() != 3 {
            return Err(fail("expected three ranges x0:x1,y0:y1,z0:z1"));
        }
        let mut lo = [0.0; 3];
        let mut hi = [0.0; 3];
        for (a, range) in axes.iter().enumerate() {
            let (l, h) = range
                .split_once(':')
                .ok_or_else(|| fail("each range is lo:hi"))?;
            let parse = |s: &str| s.trim().parse::<f64>().map_err(|_| fail("not a number"));
            (lo[a], hi[a]) = (parse(l)?, parse(h)?);
            if !(0.0 <= lo[a] && lo[a] < hi[a] && hi[a] <= f64::from(dims[a])) {
                return Err(fail(&format!(
                    "needs 0 ≤ lo < hi ≤ {} on axis {}",
                    dims[a],
                    ["x", "y", "z"][a]
                )));
            }
        }
        let crop = Self::from_voxels(dims, lo, hi);
        crop.validate()?;
        Ok(crop)
    }

    /// The box in world millimetres, inside `bounds` (the volume's bounding box).
    pub fn world(&self, bounds: &Aabb) -> Aabb {
        let size = bounds.size();
        Aabb {
            min: bounds.min + DVec3::from_array(self.min) * size,
            max: bounds.min + DVec3::from_array(self.max) * size,
        }
    }

    /// Voxel edges the box spans along each axis (see [`CropBox::from_voxels`]).
    pub fn voxels(&self, dims: [u32; 3]) -> ([f64; 3], [f64; 3]) {
        let n = dims.map(f64::from);
        (
            [0, 1, 2].map(|a| self.min[a] * n[a]),
            [0, 1, 2].map(|a| self.max[a] * n[a]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_box_is_valid_and_world_is_the_bounds() {
        let bounds = Aabb::of_volume([10, 20, 30], [1.0, 0.5, 2.0]);
        assert!(CropBox::FULL.is_full());
        assert_eq!(CropBox::FULL.validate(), Ok(()));
        assert_eq!(CropBox::FULL.world(&bounds), bounds);
    }

    #[test]
    fn voxel_edges_map_to_world_edges() {
        let dims = [10, 20, 30];
        let bounds = Aabb::of_volume(dims, [1.0, 0.5, 2.0]);
        let crop = CropBox::from_voxels(dims, [2.0, 0.0, 10.0], [5.0, 20.0, 11.0]);
        let w = crop.world(&bounds);
        // Voxel i spans [(i − ½) s, (i + ½) s] around its centre i·s.
        assert!((w.min.x - 1.5).abs() < 1e-12 && (w.max.x - 4.5).abs() < 1e-12);
        assert!((w.min.y + 0.25).abs() < 1e-12 && (w.max.y - 9.75).abs() < 1e-12);
        assert!((w.min.z - 19.0).abs() < 1e-12 && (w.max.z - 21.0).abs() < 1e-12);
        let (lo, hi) = crop.voxels(dims);
        assert_eq!((lo, hi), ([2.0, 0.0, 10.0], [5.0, 20.0, 11.0]));
    }

    #[test]
    fn bad_boxes_are_refused() {
        let inverted = CropBox {
            min: [0.5, 0.0, 0.0],
            max: [0.4, 1.0, 1.0],
        };
        assert!(matches!(inverted.validate(), Err(CropError::Empty(..))));
        let outside = CropBox {
            min: [-0.1, 0.0, 0.0],
            max: [1.0; 3],
        };
        assert!(matches!(outside.validate(), Err(CropError::Outside(..))));
        let nan = CropBox {
            min: [f64::NAN, 0.0, 0.0],
            max: [1.0; 3],
        };
        assert!(nan.validate().is_err());
    }

    #[test]
    fn voxel_ranges_parse_and_bad_ones_say_why() {
        let dims = [64, 64, 32];
        let crop = CropBox::parse_voxels("0:32, 8:64, 0:32", dims).expect("valid");
        assert_eq!(crop.min, [0.0, 0.125, 0.0]);
        assert_eq!(crop.max, [0.5, 1.0, 1.0]);
        for bad in [
            "0:32,0:64",
            "0:65,0:64,0:32",
            "5:5,0:64,0:32",
            "a:3,0:64,0:32",
            "0-3,1:2,1:2",
        ] {
            let err = CropBox::parse_voxels(bad, dims).expect_err(bad);
            assert!(err.to_string().contains(bad), "{err}");
        }
    }
}
