//! Opening a volume file: picks the reader by file name and wraps errors with the path.

use std::path::Path;

use super::error::{LoadError, VolumeError};
use super::raw::RawParams;
use super::samples::{ScalarType, ValueMapping};
use super::{decode, dicom, metaimage, model::Volume, nifti, nrrd, raw, tiff, zarr};

/// How to open a file beyond what its name tells.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Layout of a headerless raw file; required for raw files, ignored otherwise.
    pub raw: Option<RawParams>,
    /// Where to report how much of the samples was read, and to look for a cancellation.
    pub progress: Option<std::sync::Arc<super::progress::LoadProgress>>,
    /// The user's orientation, in place of the header's (or of none), in the file's index frame.
    pub orientation: Option<super::orientation::Orientation>,
    /// Which DICOM series of a folder to open (`--series`); the default is the image series
    /// with the most slices, or the one holding the file named.
    pub series: Option<super::dicom::SeriesChoice>,
    /// Which volume of a file holding several (a 4-D NIfTI), counted from 0; the first by
    /// default.
    pub volume: Option<u32>,
    /// Which channel of an image holding several (an OME-Zarr `c` axis), counted from 0; the
    /// first by default.
    pub channel: Option<u32>,
    /// The memory an OME-Zarr store's or a TIFF stack's samples may take (`--ram-budget`): one
    /// larger is read brick by brick as the view needs them, its cache of decoded chunks within
    /// this. Half the available memory by default.
    pub ram_budget: Option<u64>,
}

/// The readers, as chosen from a file name and the options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Nrrd,
    Nifti,
    Raw,
    Dicom,
    MetaImage,
    Tiff,
}

/// Loads a NRRD (`.nrrd`, `.nhdr`), NIfTI-1 (`.nii`, `.nii.gz`), MetaImage (`.mha`, `.mhd`),
/// DICOM (a folder, any file of a series, a DICOMDIR, a multi-frame file: see
/// [`super::dicom`]) or raw volume. Raw layout parameters in `options` make any file read as raw.
/// The volume is named after the file (and the DICOM series).
///
/// The orientation in `options` replaces the header's. A file whose orientation is mirrored comes
/// back [`Volume::unmirrored`]: reversed along i, so that no render shows the patient's mirror
/// image.
///
/// Errors name the file last; no header, however corrupt, makes this allocate more than the file
/// can hold or than the machine's memory ([`super::limits::max_volume_bytes`]).
pub fn load_volume(path: &Path, options: &LoadOptions) -> Result<Volume, LoadError> {
    load(path, options)
        .map(|v| match options.orientation {
            Some(o) => v.with_user_orientation(o),
            None => v,
        })
        .map(|v| from_file(v, path))
        .map_err(|problem| LoadError {
            path: path.to_path_buf(),
            problem,
        })
}

/// A volume read from the file at `path` as every loader hands it out: unmirrored, the path in
/// its provenance.
fn from_file(volume: Volume, path: &Path) -> Volume {
    let v = volume.unmirrored();
    let mut provenance = v.provenance().clone();
    provenance.path = Some(path.to_path_buf());
    v.with_provenance(provenance)
}

/// The file's name, which a volume read from it is called.
fn name_of(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// What a volume file's header says, read without its samples: enough to tell a label volume
/// from an image.
#[derive(Clone, Debug, PartialEq)]
pub struct HeaderFacts {
    /// Samples along x, y, z.
    pub dims: [u64; 3],
    /// Whether every stored value maps to a whole number (integer samples, and a whole slope
    /// and intercept).
    pub whole: bool,
    /// A NIfTI header's intent says label map (`NIFTI_INTENT_LABEL`).
    pub label_intent: bool,
    /// A NRRD header describes segments (Slicer's `Segment0_…` fields) or holds layers.
    pub segments: bool,
}

impl HeaderFacts {
    pub(crate) fn new(dims: [u64; 3], scalar_type: ScalarType, mapping: ValueMapping) -> Self {
        let integer = !matches!(scalar_type, ScalarType::F32 | ScalarType::F64);
        let whole = |v: f64| v.is_finite() && v.fract() == 0.0;
        Self {
            dims,
            whole: integer && whole(mapping.slope) && whole(mapping.intercept),
            label_intent: false,
            segments: false,
        }
    }

    pub(crate) fn with_label_intent(self, label_intent: bool) -> Self {
        Self {
            label_intent,
            ..self
        }
    }

    pub(crate) fn with_segments(self, segments: bool) -> Self {
        Self { segments, ..self }
    }
}

/// The header facts of a NRRD, NIfTI or MetaImage file (by its name); `None` for another
/// format or a header that does not read.
pub fn header_facts(path: &Path) -> Option<HeaderFacts> {
    let facts = match format_of(&name_of(path), &LoadOptions::default(), || false) {
        Ok(Format::Nrrd) => nrrd::header_facts(path),
        Ok(Format::Nifti) => nifti::header_facts(path),
        Ok(Format::MetaImage) => metaimage::header_facts(path),
        _ => return None,
    };
    facts
        .map_err(|e| log::debug!("{}: {e}", path.display()))
        .ok()
}

/// The layers of a label file, each a volume of the file's grid: a NRRD file's interleaved
/// layers (the first axis of a 4-D `.seg.nrrd`), else the one volume [`load_volume`] reads;
/// mirrored files come back unmirrored as there.
pub fn load_layers(path: &Path) -> Result<Vec<Volume>, LoadError> {
    let name = name_of(path);
    let nrrd = matches!(
        format_of(&name, &LoadOptions::default(), || false),
        Ok(Format::Nrrd)
    );
    if !nrrd || !path.is_file() {
        return load_volume(path, &LoadOptions::default()).map(|v| vec![v]);
    }
    let layers = nrrd::read_nrrd_layers(path, name).map_err(|problem| LoadError {
        path: path.to_path_buf(),
        problem,
    })?;
    Ok(layers.into_iter().map(|v| from_file(v, path)).collect())
}

fn load(path: &Path, options: &LoadOptions) -> Result<Volume, VolumeError> {
    let name = name_of(path);
    let progress = options.progress.as_deref();
    // An http(s)://, s3://, gs:// or az:// address is a remote OME-Zarr store.
    if zarr::is_remote(path) {
        return zarr::load(path, name, options);
    }
    // A folder is an OME-Zarr store, a stack of TIFF slices, else a DICOM series (or several).
    if options.raw.is_none() && std::fs::metadata(path).is_ok_and(|m| m.is_dir()) {
        if zarr::is_store(path) {
            return zarr::load(path, name, options);
        }
        if let Some(files) = tiff::stack_files(path) {
            return tiff::load_folder(&files, name, options);
        }
        return dicom::load(path, options.series.as_ref(), progress);
    }
    // A missing file, a folder or an empty file is reported as such whatever its name.
    decode::open_file(path)?;
    let sniff = || dicom::scan::looks_like_dicom(path);
    match (format_of(&name, options, sniff)?, &options.raw) {
        (Format::Raw, Some(params)) => raw::read_raw(path, name, params, progress),
        (Format::Raw, None) => Err(VolumeError::RawNeedsParams),
        (Format::Nrrd, _) => nrrd::read_nrrd(path, name, progress),
        (Format::Nifti, _) => nifti::read_nifti(path, name, options.volume, progress),
        (Format::MetaImage, _) => metaimage::read_metaimage(path, name, progress),
        (Format::Dicom, _) => dicom::load(path, options.series.as_ref(), progress),
        (Format::Tiff, _) => tiff::load_file(path, name, options),
    }
}

/// The reader for a file: by its name, else (no known extension) DICOM when it starts like
/// DICOM (`sniff`), as scanners' files often have no extension.
fn format_of(
    name: &str,
    options: &LoadOptions,
    sniff: impl FnOnce() -> bool,
) -> Result<Format, VolumeError> {
    let lower = name.to_ascii_lowercase();
    let has = |suffix: &str| lower.ends_with(suffix);
    if options.raw.is_some() || has(".raw") {
        Ok(Format::Raw)
    } else if has(".nrrd") || has(".nhdr") {
        Ok(Format::Nrrd)
    } else if has(".nii") || has(".nii.gz") {
        Ok(Format::Nifti)
    } else if has(".mha") || has(".mhd") {
        Ok(Format::MetaImage)
    } else if tiff::is_tiff_name(&lower) {
        Ok(Format::Tiff)
    } else if has(".dcm") || has(".dicom") || has(".ima") || lower == "dicomdir" || sniff() {
        Ok(Format::Dicom)
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
    use crate::volume::samples::ScalarType;

    #[test]
    fn formats_follow_the_name_unless_raw_parameters_are_given() {
        let none = LoadOptions::default();
        let no = || false;
        let raw = LoadOptions {
            raw: Some(RawParams {
                dims: [1, 1, 1],
                scalar_type: ScalarType::U8,
                spacing_mm: [1.0; 3],
                big_endian: false,
            }),
            ..LoadOptions::default()
        };
        assert_eq!(format_of("a.NRRD", &none, no).ok(), Some(Format::Nrrd));
        assert_eq!(format_of("a.nhdr", &none, no).ok(), Some(Format::Nrrd));
        assert_eq!(format_of("a.nii", &none, no).ok(), Some(Format::Nifti));
        assert_eq!(format_of("a.Nii.Gz", &none, no).ok(), Some(Format::Nifti));
        assert_eq!(format_of("a.raw", &none, no).ok(), Some(Format::Raw));
        assert_eq!(format_of("a.nrrd", &raw, no).ok(), Some(Format::Raw));
        assert_eq!(format_of("scan.img", &raw, no).ok(), Some(Format::Raw));
        let r = format_of("scan.img", &none, no);
        assert!(
            matches!(r, Err(VolumeError::UnknownFormat { ref extension }) if extension == ".img")
        );
        assert_eq!(format_of("a.MHA", &none, no).ok(), Some(Format::MetaImage));
        assert_eq!(format_of("IM0001.dcm", &none, no).ok(), Some(Format::Dicom));
        assert_eq!(format_of("DICOMDIR", &none, no).ok(), Some(Format::Dicom));
        assert_eq!(
            format_of("IM0001", &none, || true).ok(),
            Some(Format::Dicom)
        );
        let r = format_of("scan", &none, no);
        assert!(
            matches!(r, Err(VolumeError::UnknownFormat { ref extension }) if extension.is_empty())
        );
    }
}
