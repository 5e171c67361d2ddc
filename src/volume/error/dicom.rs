//! What can go wrong in reading a DICOM series, in words that name the file or the series.

/// A DICOM folder, file or series LeapView cannot make a volume of.
#[derive(Debug, thiserror::Error)]
pub enum DicomError {
    /// Nothing under the path is a DICOM image.
    #[error("no DICOM image here ({skipped})")]
    NoImage {
        /// What was found instead, counted (`3 files that are not DICOM, 1 DICOMDIR`).
        skipped: String,
    },
    /// The one file the user named is DICOM but not an image volume.
    #[error("'{file}' is {what}, not an image LeapView can show as a volume")]
    NotAnImage {
        /// The file.
        file: String,
        /// What it is (`a DICOM segmentation (SEG)`, `a structured report`).
        what: String,
    },
    /// `--series` names no series of the folder.
    #[error("there is no series {asked} here; the series are {available}")]
    NoSuchSeries {
        /// The number or UID asked for.
        asked: String,
        /// The series' numbers, for the message.
        available: String,
    },
    /// A file could not be read as DICOM at all.
    #[error("cannot read '{file}' as DICOM ({reason})")]
    Unreadable {
        /// The file.
        file: String,
        /// What dicom-rs said.
        reason: String,
    },
    /// The file's transfer syntax names a codec LeapView has no decoder for.
    #[error("'{file}' uses the transfer syntax {name} ({uid}), which LeapView cannot decode")]
    UnsupportedTransferSyntax {
        /// The file.
        file: String,
        /// The transfer syntax UID.
        uid: String,
        /// Its name, or `an unknown transfer syntax`.
        name: String,
    },
    /// The pixel data could not be decoded (a corrupt or cut-short codestream).
    #[error("cannot decode the pixels of '{file}' ({reason})")]
    Decode {
        /// The file.
        file: String,
        /// What the decoder said.
        reason: String,
    },
    /// The pixel data is shorter than rows × columns × frames call for.
    #[error(
        "the pixel data of '{file}' holds {found} bytes, but {rows} rows x {columns} columns x \
         {frames} frames of {bytes_per_sample} bytes need {needed} (a truncated file?)"
    )]
    PixelDataTooShort {
        /// The file.
        file: String,
        /// Rows of one frame.
        rows: u32,
        /// Columns of one frame.
        columns: u32,
        /// Frames in the file.
        frames: u32,
        /// Bytes per sample.
        bytes_per_sample: u32,
        /// Bytes the header calls for.
        needed: u64,
        /// Bytes present.
        found: u64,
    },
    /// A header field holds a value no image can have.
    #[error("'{file}': {field} is {value}; {expected}")]
    BadField {
        /// The file.
        file: String,
        /// The DICOM attribute.
        field: &'static str,
        /// Its value as read.
        value: String,
        /// What it should be.
        expected: &'static str,
    },
    /// The pixels are of a kind LeapView does not show.
    #[error("'{file}': {why}")]
    Unsupported {
        /// The file.
        file: String,
        /// What kind, and what is shown instead.
        why: String,
    },
    /// The series' geometry cannot be made a regular volume.
    #[error("the series cannot be assembled: {reason}")]
    Geometry {
        /// Why, naming the slices concerned.
        reason: String,
    },
    /// The user cancelled the load.
    #[error("loading was cancelled")]
    Cancelled,
}
