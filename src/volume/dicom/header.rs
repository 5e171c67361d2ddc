//! What LeapView takes from one DICOM image frame, as plain values: no dicom-rs type appears
//! here, so series assembly ([`super::series`], [`super::geometry`]) is pure, unit-tested and
//! fuzzed over arbitrary tag values. [`super::tags`] fills these from a file.

/// How one frame's pixels are stored (PS3.3 C.7.6.3, image pixel module).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelFormat {
    /// `BitsAllocated`: 8, 16 or 32 (1 for bit masks, which are not read).
    pub bits_allocated: u16,
    /// `BitsStored`: the bits of each sample that hold its value.
    pub bits_stored: u16,
    /// `HighBit`: the most significant stored bit (usually `bits_stored - 1`).
    pub high_bit: u16,
    /// `PixelRepresentation` 1: two's complement samples.
    pub signed: bool,
    /// `SamplesPerPixel`: 1 for grey images.
    pub samples_per_pixel: u16,
    /// `PhotometricInterpretation` MONOCHROME1: the lowest value is shown white.
    pub monochrome1: bool,
}

/// `RescaleSlope` and `RescaleIntercept` (or an RT dose grid's `DoseGridScaling`): data units are
/// `stored * slope + intercept` (Hounsfield units for CT).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rescale {
    /// Multiplier.
    pub slope: f64,
    /// Offset.
    pub intercept: f64,
}

impl Rescale {
    /// No rescaling.
    pub const IDENTITY: Self = Self {
        slope: 1.0,
        intercept: 0.0,
    };
}

/// The facts of a series that a person reads: shown by `leapview info` and in the window.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesFacts {
    /// `SeriesInstanceUID`.
    pub uid: String,
    /// `SeriesNumber`, where given.
    pub number: Option<i64>,
    /// `Modality` (CT, MR, RTDOSE, …).
    pub modality: String,
    /// `SeriesDescription`.
    pub description: String,
    /// `SeriesDate`, else `StudyDate`, as written (YYYYMMDD).
    pub date: String,
    /// `FrameOfReferenceUID`.
    pub frame_of_reference: String,
    /// `SOPClassUID` of the series' objects.
    pub sop_class: String,
}

/// One frame of a DICOM image: a slice of a classic series, or one frame of a multi-frame
/// (enhanced CT/MR, RT dose) object.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameHeader {
    /// Index of the file in the scan's file list.
    pub file: usize,
    /// Frame within the file (0 for single-frame files).
    pub frame: u32,
    /// How messages name the frame: the file's name, and the frame where the file has several.
    pub label: String,
    /// `NumberOfFrames` of the file (1 for single-frame files).
    pub frames_in_file: u32,
    /// The series the frame belongs to.
    pub series: SeriesFacts,
    /// `Rows`: the image height.
    pub rows: u32,
    /// `Columns`: the image width.
    pub columns: u32,
    /// `ImageOrientationPatient`: the direction of a row (increasing column index), then of a
    /// column (increasing row index), as unit vectors in the patient frame (LPS).
    pub orientation: Option<[f64; 6]>,
    /// `ImagePositionPatient`: the centre of the first transmitted voxel, in mm (LPS).
    pub position: Option<[f64; 3]>,
    /// `PixelSpacing`: the spacing between rows, then between columns, in mm.
    pub pixel_spacing: Option<[f64; 2]>,
    /// `SliceThickness`, in mm.
    pub slice_thickness: Option<f64>,
    /// `SpacingBetweenSlices`, in mm.
    pub spacing_between_slices: Option<f64>,
    /// How the pixels are stored.
    pub pixel: PixelFormat,
    /// The map to data units.
    pub rescale: Rescale,
    /// `WindowCenter`, `WindowWidth` (the first pair), in data units.
    pub window: Option<[f64; 2]>,
    /// `InstanceNumber`, for messages only: never used to order slices.
    pub instance_number: Option<i64>,
    /// `SOPInstanceUID`: one object, however many files hold a copy of it.
    pub instance_uid: String,
    /// The file's transfer syntax UID.
    pub transfer_syntax: String,
}

impl FrameHeader {
    /// The window as its lowest and highest value in data units: `centre ∓ width / 2`.
    pub fn window_range(&self) -> Option<[f64; 2]> {
        let [centre, width] = self.window?;
        (centre.is_finite() && width.is_finite() && width > 0.0)
            .then(|| [centre - width / 2.0, centre + width / 2.0])
    }
}
