//! Generated volumes: the realistic default (a 3D Shepp–Logan head phantom in Hounsfield
//! units), a sparse CT-angiography-like vessel tree, a dense MR-like head for benchmarks, the
//! scene LeapView is compared with its peers on, and
//! tiny analytic volumes whose every voxel the renderer tests can predict.
//!
//! Everything here is deterministic: the same arguments (and seed) give bit-identical samples on
//! every platform and thread count. Randomness comes from [`rng`], a local SplitMix64, and
//! per-voxel noise is a hash of the voxel index, so that slabs can be filled in parallel.
//!
//! Edges are anti-aliased the way a scanner's partial-volume effect blurs them: a voxel on a
//! boundary gets the fraction of its volume inside the object, approximated from the signed
//! distance `d` of its centre to the surface as `clamp(0.5 − d / voxel, 0, 1)` (exact for a plane
//! parallel to a voxel face).

pub mod analytic;
pub mod dense_head;
pub mod peer_scene;
pub mod rng;
pub mod shepp_logan;
pub mod vessels;

pub use analytic::{Axis, checkerboard, constant, ramp, slab_x, sphere};
pub use dense_head::dense_head;
pub use peer_scene::peer_scene;
pub use shepp_logan::shepp_logan;
pub use vessels::vessel_tree;

use super::error::VolumeError;

/// Partial-volume coverage of a voxel whose centre lies at signed distance `d` from a surface
/// (negative inside), for voxels `voxel` long: `clamp(0.5 − d / voxel, 0, 1)`.
pub(crate) fn coverage(d: f64, voxel: f64) -> f64 {
    (0.5 - d / voxel).clamp(0.0, 1.0)
}

/// `n³` samples of `scalar_type` as a `Vec` length; refuses a zero `n` and sizes past the
/// loaders' limits (`limits::check_dims`) before anything is allocated.
pub(crate) fn cube_len(
    n: u32,
    scalar_type: super::samples::ScalarType,
) -> Result<usize, VolumeError> {
    let (dims, _) = super::limits::check_dims([n as u64; 3], scalar_type)?;
    Ok(dims.iter().map(|&d| d as usize).product())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_is_a_clamped_ramp() {
        assert_eq!(coverage(-2.0, 1.0), 1.0);
        assert_eq!(coverage(0.0, 2.0), 0.5);
        assert_eq!(coverage(0.25, 1.0), 0.25);
        assert_eq!(coverage(3.0, 1.0), 0.0);
    }
}

#[cfg(test)]
mod limit_tests {
    use super::*;

    #[test]
    fn absurd_sizes_are_refused_before_allocating() {
        assert!(matches!(
            shepp_logan(100_000),
            Err(VolumeError::DimensionTooLarge { .. })
        ));
        assert!(matches!(
            vessel_tree(4096, 1),
            Err(VolumeError::TooLarge { .. })
        ));
        assert!(matches!(
            constant([60_000, 60_000, 60_000], [1.0; 3], 0.0),
            Err(VolumeError::TooLarge { .. })
        ));
    }
}
