//! Errors from building and loading volumes. Every message says what is wrong in words a user can
//! act on; [`LoadError`] adds the file, last.

use std::path::PathBuf;

/// What is wrong with a volume or its file, independent of where it came from.
#[derive(Debug, thiserror::Error)]
pub enum VolumeError {
    /// A dimension is zero.
    #[error("the volume has a zero dimension ({dims:?})")]
    ZeroDimension {
        /// The offending dimensions.
        dims: [u32; 3],
    },
    /// The number of samples does not match the dimensions.
    #[error("the dimensions {dims:?} need {expected} samples but {actual} were given")]
    SampleCountMismatch {
        /// Dimensions as declared.
        dims: [u32; 3],
        /// Samples the dimensions call for.
        expected: u64,
        /// Samples present.
        actual: u64,
    },
    /// A spacing is zero, negative or not finite.
    #[error("voxel spacing must be positive and finite, got {spacing_mm:?} mm")]
    BadSpacing {
        /// The offending spacing.
        spacing_mm: [f64; 3],
    },
    /// The value mapping would destroy or corrupt the data.
    #[error("the value scaling (slope {slope}, intercept {intercept}) is not usable")]
    BadValueMapping {
        /// Slope as given.
        slope: f64,
        /// Intercept as given.
        intercept: f64,
    },
}

/// A volume file that could not be loaded: the problem, then the path.
#[derive(Debug, thiserror::Error)]
#[error("{problem}: {}", path.display())]
pub struct LoadError {
    /// The file that was being read.
    pub path: PathBuf,
    /// What went wrong.
    pub problem: VolumeError,
}
