//! Errors from building and loading volumes, the DICOM reader's among them ([`dicom`]). Every
//! message says what is wrong in words a user can act on; [`LoadError`] adds the file, last.

pub mod dicom;
pub mod zarr;

use std::path::PathBuf;

use crate::volume::samples::ScalarType;

/// What is wrong with a volume or its file, independent of where it came from.
#[derive(Debug, thiserror::Error)]
pub enum VolumeError {
    /// A dimension is zero.
    #[error("the volume has a zero dimension ({})", fmt_dims(.dims))]
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

    /// A DICOM file, folder or series that cannot be read.
    #[error(transparent)]
    Dicom(dicom::DicomError),
    /// An OME-Zarr store that cannot be read.
    #[error(transparent)]
    Zarr(zarr::ZarrError),

    /// The file does not exist.
    #[error("no such file")]
    NotFound,
    /// The path names a directory, not a file.
    #[error("this is a folder, not a volume file")]
    IsDirectory,
    /// The file holds no bytes at all.
    #[error("the file is empty")]
    EmptyFile,
    /// The path names a pipe, a device or a socket: reading one can block forever or never end.
    #[error("this is a {kind}, not a regular file; only files are opened")]
    NotRegularFile {
        /// What it is (`named pipe`, `device`, `socket`, `special file`).
        kind: &'static str,
    },
    /// The operating system refused or failed a read.
    #[error("could not read the file ({source})")]
    Io {
        /// The underlying error.
        #[from]
        source: std::io::Error,
    },
    /// A detached header names a data file that is a pipe, a device or a socket.
    #[error("the data file '{name}' that the header names is a {kind}, not a regular file")]
    DataFileNotRegular {
        /// The data file as the header names it.
        name: String,
        /// What it is.
        kind: &'static str,
    },
    /// A detached header names a data file that cannot be read.
    #[error("cannot read the data file '{name}' that the header names ({source})")]
    DataFileUnreadable {
        /// The data file as the header names it.
        name: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file name does not tell a supported format.
    #[error(
        "unrecognised volume file type '{extension}'; LeapView reads .nrrd, .nhdr, .nii, \
         .nii.gz, .mha, .mhd, .tif/.tiff (stacks, OME-TIFF), DICOM files and folders, \
         OME-Zarr stores and folders of TIFF slices, and raw files given with --dims X,Y,Z \
         --type T"
    )]
    UnknownFormat {
        /// The file's extension as written (may be empty).
        extension: String,
    },
    /// A raw file was given without its layout.
    #[error(
        "a raw file has no header: pass its layout with --dims X,Y,Z --type T (and --spacing, \
         --big-endian where needed)"
    )]
    RawNeedsParams,
    /// The file is not of the format its name promises, or its header cannot be parsed.
    #[error("not a valid {format} file: {reason}")]
    BadHeader {
        /// `NRRD` or `NIfTI-1`.
        format: &'static str,
        /// What is wrong, in words.
        reason: String,
    },
    /// A required header field is absent.
    #[error("the {format} header has no '{field}' field, which is required{why}")]
    MissingField {
        /// `NRRD` or `NIfTI-1`.
        format: &'static str,
        /// The field's name.
        field: &'static str,
        /// Why it is required, starting with a separator (may be empty).
        why: &'static str,
    },
    /// A header field holds a value that cannot be used.
    #[error("the {format} header field '{field}' is '{value}'; {expected}")]
    BadField {
        /// `NRRD` or `NIfTI-1`.
        format: &'static str,
        /// The field's name.
        field: String,
        /// The value as written.
        value: String,
        /// What it should be, as a clause ("it must be …").
        expected: String,
    },
    /// The sample type is unknown or not one LeapView stores.
    #[error(
        "unsupported sample type '{name}'; LeapView reads uint8, int8, uint16, int16, uint32, \
         int32, float and double samples"
    )]
    UnsupportedType {
        /// The type as the file names it.
        name: String,
    },
    /// The data encoding is unknown or not one LeapView decodes.
    #[error("unsupported encoding '{name}'; LeapView reads raw and gzip-compressed data")]
    UnsupportedEncoding {
        /// The encoding as the file names it.
        name: String,
    },
    /// The file is not a 3-D volume.
    #[error("the file holds {dimension}-D data; LeapView reads 3-D volumes{hint}")]
    UnsupportedDimension {
        /// The number of axes in the file.
        dimension: String,
        /// What would be accepted, starting with a separator (may be empty).
        hint: &'static str,
    },
    /// The load's admission check (the GPU's limits) refused the volume's shape before its
    /// samples were read.
    #[error("{reason} (refused before reading its samples)")]
    NotAdmitted {
        /// Why.
        reason: String,
    },
    /// The volume asked for is past the file's last.
    #[error("there is no volume {asked}: the file holds {count} (--volume 1 to {count})")]
    NoSuchVolume {
        /// The volume asked for, counted from 1.
        asked: u64,
        /// How many the file holds.
        count: u64,
    },
    /// One axis is longer than LeapView accepts.
    #[error(
        "the header declares {} samples, more than {max} along one axis",
        fmt_dims_u64(.dims)
    )]
    DimensionTooLarge {
        /// The dimensions as declared.
        dims: [u64; 3],
        /// The per-axis limit.
        max: u32,
    },
    /// The volume would need more memory than the machine has.
    #[error(
        "the header declares {} {scalar_type} samples ({}), more than this machine's {} of memory",
        fmt_dims(.dims), fmt_bytes(*.declared_bytes), fmt_bytes(*.limit_bytes)
    )]
    TooLarge {
        /// The dimensions as declared.
        dims: [u32; 3],
        /// The stored type.
        scalar_type: ScalarType,
        /// Bytes the samples would take.
        declared_bytes: u64,
        /// The limit.
        limit_bytes: u64,
    },
    /// The data ends before the declared number of samples.
    #[error(
        "the header declares {} {scalar_type} samples ({}) but the data holds only {}",
        fmt_dims(.dims), fmt_bytes_pair(*.declared_bytes, *.found_bytes).0,
        fmt_bytes_pair(*.declared_bytes, *.found_bytes).1
    )]
    DataTooShort {
        /// The dimensions as declared.
        dims: [u32; 3],
        /// The stored type.
        scalar_type: ScalarType,
        /// Bytes the samples need.
        declared_bytes: u64,
        /// Bytes of sample data present (decompressed where the data are compressed).
        found_bytes: u64,
    },
    /// The data holds more bytes than the declared samples.
    #[error(
        "the header declares {} {scalar_type} samples ({}) but the data holds more ({}); \
         the header's sizes or type are probably wrong",
        fmt_dims(.dims), fmt_bytes_pair(*.declared_bytes, *.found_bytes).0,
        fmt_found_more(*.declared_bytes, *.found_bytes, *.exact)
    )]
    DataTooLong {
        /// The dimensions as declared.
        dims: [u32; 3],
        /// The stored type.
        scalar_type: ScalarType,
        /// Bytes the samples need.
        declared_bytes: u64,
        /// Bytes of sample data seen (all of them when `exact`, else a lower bound).
        found_bytes: u64,
        /// Whether `found_bytes` is the whole data or only what was read before stopping.
        exact: bool,
    },
    /// Compressed data too small to expand to the declared size (deflate expands at most 1032:1).
    #[error(
        "the header declares {} {scalar_type} samples ({}) but {} of gzip data can expand to at \
         most {}",
        fmt_dims(.dims), fmt_bytes(*.declared_bytes), fmt_bytes(*.compressed_bytes),
        fmt_bytes(*.max_bytes)
    )]
    CompressedDataTooSmall {
        /// The dimensions as declared.
        dims: [u32; 3],
        /// The stored type.
        scalar_type: ScalarType,
        /// Bytes the samples need (plus any bytes to skip after decompression).
        declared_bytes: u64,
        /// Bytes of compressed data in the file.
        compressed_bytes: u64,
        /// The most those bytes can expand to.
        max_bytes: u64,
    },
    /// A raw file's size does not match the layout given for it.
    #[error(
        "a raw {} {scalar_type} volume needs {expected_bytes} bytes ({}) but the file holds \
         {found_bytes} bytes ({}); check --dims and --type",
        fmt_dims(.dims), fmt_bytes(*.expected_bytes), fmt_bytes(*.found_bytes)
    )]
    RawSizeMismatch {
        /// Dimensions given.
        dims: [u32; 3],
        /// Type given.
        scalar_type: ScalarType,
        /// Bytes the layout calls for.
        expected_bytes: u64,
        /// Bytes in the file.
        found_bytes: u64,
    },
    /// The user cancelled the load.
    #[error("loading was cancelled")]
    Cancelled,
    /// The samples would take more memory than this machine has available.
    #[error(
        "the volume's samples need {} but this machine has {} of memory available",
        fmt_bytes(*.bytes),
        fmt_bytes(*.available)
    )]
    NotEnoughMemory {
        /// Bytes the samples take.
        bytes: u64,
        /// Bytes the system reports as available.
        available: u64,
    },
    /// Something that needs every sample in memory was asked of a volume read from its store
    /// brick by brick.
    #[error(
        "{needs} needs the whole volume in memory, but {name} is read from its store brick by \
         brick (it does not fit this machine's memory)"
    )]
    Streamed {
        /// The volume's path (else its name).
        name: String,
        /// What needed the samples.
        needs: &'static str,
    },
    /// The samples passed every limit but this machine could not provide the memory.
    #[error("not enough memory to hold the volume's samples ({})", fmt_bytes(*.bytes))]
    OutOfMemory {
        /// Bytes that were asked for.
        bytes: u64,
    },
    /// A zlib stream (MetaImage `CompressedData`) cannot be decompressed.
    #[error("the zlib-compressed data is corrupt ({reason})")]
    CorruptZlib {
        /// What the decompressor reported.
        reason: String,
    },
    /// The gzip stream cannot be decompressed.
    #[error("the gzip-compressed data is corrupt ({reason})")]
    CorruptGzip {
        /// What the decompressor reported.
        reason: String,
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

/// `256×256×113`.
pub(crate) fn fmt_dims(dims: &[u32; 3]) -> String {
    format!("{}×{}×{}", dims[0], dims[1], dims[2])
}

fn fmt_dims_u64(dims: &[u64; 3]) -> String {
    format!("{}×{}×{}", dims[0], dims[1], dims[2])
}

pub(crate) use crate::text::bytes as fmt_bytes;

/// Two byte counts that are compared in one message: rounded when the rounding tells them apart,
/// exact otherwise (so "14.8 MB but only 14.8 MB" never appears).
fn fmt_bytes_pair(a: u64, b: u64) -> (String, String) {
    let (fa, fb) = (fmt_bytes(a), fmt_bytes(b));
    if fa != fb || a == b {
        (fa, fb)
    } else {
        (format!("{a} bytes"), format!("{b} bytes"))
    }
}

/// The found size of a [`VolumeError::DataTooLong`], as a lower bound unless it is `exact`.
fn fmt_found_more(declared: u64, found: u64, exact: bool) -> String {
    let found = fmt_bytes_pair(declared, found).1;
    if exact {
        found
    } else {
        format!("at least {found}")
    }
}

impl From<dicom::DicomError> for VolumeError {
    fn from(e: dicom::DicomError) -> Self {
        match e {
            dicom::DicomError::Cancelled => Self::Cancelled,
            e => Self::Dicom(e),
        }
    }
}

impl From<zarr::ZarrError> for VolumeError {
    fn from(e: zarr::ZarrError) -> Self {
        Self::Zarr(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_read_at_a_glance() {
        assert_eq!(fmt_bytes(0), "0 bytes");
        assert_eq!(fmt_bytes(999), "999 bytes");
        assert_eq!(fmt_bytes(1_200), "1.2 kB");
        // 256 × 256 × 113 × 2 bytes, the CT head of data/README.md.
        assert_eq!(fmt_bytes(256 * 256 * 113 * 2), "14.8 MB");
        assert_eq!(fmt_bytes(999_999), "1.0 MB");
        assert_eq!(fmt_bytes(8 << 30), "8.6 GB");
    }

    #[test]
    fn near_equal_sizes_are_shown_exactly() {
        let e = VolumeError::DataTooShort {
            dims: [256, 256, 113],
            scalar_type: ScalarType::U16,
            declared_bytes: 14_811_136,
            found_bytes: 14_811_135,
        };
        let text = e.to_string();
        assert!(text.contains("14811136 bytes"), "{text}");
        assert!(text.contains("only 14811135 bytes"), "{text}");
        assert!(text.contains("256×256×113 uint16"), "{text}");
    }
}
