//! Opening a volume file: picks the reader by file name and wraps errors with the path.

use std::path::Path;

use super::error::{LoadError, VolumeError};
use super::raw::RawParams;
use super::{Volume, decode, nifti, nrrd, raw};

/// How to open a file beyond what its name tells.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Layout of a headerless raw file; required for raw files, ignored otherwise.
    pub raw: Option<RawParams>,
    /// Where to report how much of the samples was read, and to look for a cancellation.
    pub progress: Option<std::sync::Arc<super::LoadProgress>>,
    /// The user's orientation, in place of the header's (or of none), in the file's index frame.
    pub orientation: Option<super::Orientation>,
}

/// The readers, as chosen from a file name and the options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Nrrd,
    Nifti,
    Raw,
}

/// Loads a NRRD (`.nrrd`, `.nhdr`), NIfTI-1 (`.nii`, `.nii.gz`) or raw volume. Raw layout
/// parameters in `options` make any file read as raw. The volume is named after the file.
///
/// The orientation in `options` replaces the header's. A file whose orientation is mirrored comes
/// back [`Volume::unmirrored`]: reversed along i, so that no render shows the patient's mirror
/// image.
///
/// Errors name the file last; no header, however corrupt, makes this allocate more than the file
/// can hold or than [`super::limits::MAX_VOLUME_BYTES`].
pub fn load_volume(path: &Path, options: &LoadOptions) -> Result<Volume, LoadError> {
    load(path, options)
        .map(|v| match options.orientation {
            Some(o) => v.with_user_orientation(o),
            None => v,
        })
        .map(Volume::unmirrored)
        .map_err(|problem| LoadError {
            path: path.to_path_buf(),
            problem,
        })
}

fn load(path: &Path, options: &LoadOptions) -> Result<Volume, VolumeError> {
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    // A missing file, a folder or an empty file is reported as such whatever its name.
    decode::open_file(path)?;
    let progress = options.progress.as_deref();
    match (format_of(&name, options)?, &options.raw) {
        (Format::Raw, Some(params)) => raw::read_raw(path, name, params, progress),
        (Format::Raw, None) => Err(VolumeError::RawNeedsParams),
        (Format::Nrrd, _) => nrrd::read_nrrd(path, name, progress),
        (Format::Nifti, _) => nifti::read_nifti(path, name, progress),
    }
}

fn format_of(name: &str, options: &LoadOptions) -> Result<Format, VolumeError> {
    let lower = name.to_ascii_lowercase();
    let has = |suffix: &str| lower.ends_with(suffix);
    if options.raw.is_some() || has(".raw") {
        Ok(Format::Raw)
    } else if has(".nrrd") || has(".nhdr") {
        Ok(Format::Nrrd)
    } else if has(".nii") || has(".nii.gz") {
        Ok(Format::Nifti)
    } else {
        let extension = match lower.rsplit_once('.') {
            Some((_, ext)) if !lower.starts_with('.') || lower.matches('.').count() > 1 => {
                format!(".{ext}")
            }
            _ => String::new(),
        };
        Err(VolumeError::UnknownFormat { extension })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::ScalarType;

    #[test]
    fn formats_follow_the_name_unless_raw_parameters_are_given() {
        let none = LoadOptions::default();
        let raw = LoadOptions {
            raw: Some(RawParams {
                dims: [1, 1, 1],
                scalar_type: ScalarType::U8,
                spacing_mm: [1.0; 3],
                big_endian: false,
            }),
            ..LoadOptions::default()
        };
        assert_eq!(format_of("a.NRRD", &none).ok(), Some(Format::Nrrd));
        assert_eq!(format_of("a.nhdr", &none).ok(), Some(Format::Nrrd));
        assert_eq!(format_of("a.nii", &none).ok(), Some(Format::Nifti));
        assert_eq!(format_of("a.Nii.Gz", &none).ok(), Some(Format::Nifti));
        assert_eq!(format_of("a.raw", &none).ok(), Some(Format::Raw));
        assert_eq!(format_of("a.nrrd", &raw).ok(), Some(Format::Raw));
        assert_eq!(format_of("scan.img", &raw).ok(), Some(Format::Raw));
        let r = format_of("scan.img", &none);
        assert!(
            matches!(r, Err(VolumeError::UnknownFormat { ref extension }) if extension == ".img")
        );
        let r = format_of("scan", &none);
        assert!(
            matches!(r, Err(VolumeError::UnknownFormat { ref extension }) if extension.is_empty())
        );
    }
}
